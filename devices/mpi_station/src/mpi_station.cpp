// An MPI station on a line (mpi_station.hpp; docs/mpi.md "MPI stations on a line").
#include "pbvbus/mpi_station/mpi_station.hpp"

#include <algorithm>
#include <utility>

namespace pbvbus::mpi_station {

std::string_view to_string(EventKind k) {
  switch (k) {
    case EventKind::Accepted: return "accepted";
    case EventKind::Connected: return "connected";
    case EventKind::Refused: return "refused";
    case EventKind::Reply: return "reply";
    case EventKind::Broken: return "broken";
    case EventKind::Closed: return "closed";
  }
  return "?";
}

std::string_view to_string(EndReason r) {
  switch (r) {
    case EndReason::None: return "none";
    case EndReason::Local: return "local";
    case EndReason::ByPeer: return "by peer";
    case EndReason::PeerReconnected: return "peer reconnected";
    case EndReason::ConnectTimeout: return "connect timeout";
    case EndReason::AckTimeout: return "ack timeout";
    case EndReason::PeerGone: return "peer gone";
    case EndReason::PeerRefused: return "peer refused";
    case EndReason::SequenceError: return "sequence error";
    case EndReason::PeerLeftRing: return "peer left the token ring";
    case EndReason::TokenLost: return "token lost";
    case EndReason::PowerLoss: return "power loss";
    case EndReason::Refused: return "refused by the session factory";
    case EndReason::SessionEnded: return "session ended";
  }
  return "?";
}

namespace {

constexpr std::uint8_t kMaxSap = 63;  // §B.2: SAPs 0..63

EndReason from_mpi(mpi::Reason r) {
  switch (r) {
    case mpi::Reason::None: return EndReason::None;
    case mpi::Reason::Local: return EndReason::Local;
    case mpi::Reason::ByPeer: return EndReason::ByPeer;
    case mpi::Reason::PeerReconnected: return EndReason::PeerReconnected;
    case mpi::Reason::ConnectTimeout: return EndReason::ConnectTimeout;
    case mpi::Reason::AckTimeout: return EndReason::AckTimeout;
    case mpi::Reason::PeerGone: return EndReason::PeerGone;
    case mpi::Reason::PeerRefused: return EndReason::PeerRefused;
    case mpi::Reason::SequenceError: return EndReason::SequenceError;
  }
  return EndReason::None;
}

void to_fdl_reply(mpi::FdlReply r, fdl::Reply& reply) {
  switch (r) {
    case mpi::FdlReply::Ack: reply.short_ack(); return;
    case mpi::FdlReply::NoResources: reply.status_only(fdl::ResponseStatus::RR); return;
    case mpi::FdlReply::SapNotActivated: reply.status_only(fdl::ResponseStatus::RS); return;
    case mpi::FdlReply::UserError: reply.status_only(fdl::ResponseStatus::UE); return;
  }
}

}  // namespace

// --- the port the ActiveStation sees ---------------------------------------------------------

/// Forwards everything to the station's own port, except the timer: the MAC's deadline is kept
/// and the station arms the earlier of it and its own deadlines.
class MpiStation::Port final : public bus::DevicePort {
 public:
  explicit Port(MpiStation& s) : s_(s) {}
  bus::Ticks now() const override { return s_.port().now(); }
  bus::Baud baud() const override { return s_.port().baud(); }
  void transmit(bus::Ticks start, std::span<const std::uint8_t> bytes) override {
    s_.port().transmit(start, bytes);
  }
  void set_timer(bus::Ticks at) override {
    s_.mac_timer_ = at;
    s_.rearm();
  }
  bool receiving() const override { return s_.port().receiving(); }
  void receive_filter_changed() override { s_.port().receive_filter_changed(); }
  bool medium_fault() const override { return s_.port().medium_fault(); }

 private:
  MpiStation& s_;
};

/// The MAC's user: forwards to the station.
class MpiStation::MacUser final : public fdl::InitiatorUser {
 public:
  explicit MacUser(MpiStation& s) : s_(s) {}
  bool next_request(fdl::Priority prio, bus::Ticks now, fdl::Request& out) override {
    return s_.next_request(prio, now, out);
  }
  void on_confirmation(const fdl::Confirmation& con) override { s_.on_confirmation(con); }
  void on_request(const fdl::Indication& ind, fdl::Reply& reply) override { s_.on_request(ind, reply); }
  void on_token(bus::Ticks now, bus::Ticks /*trr*/) override { s_.on_token(now); }

 private:
  MpiStation& s_;
};

MpiStation::MpiStation(const MpiStationConfig& config, S7SessionFactory* server)
    : config_(config),
      server_(server),
      port_(std::make_unique<Port>(*this)),
      user_(std::make_unique<MacUser>(*this)),
      mac_(config.address, config.bus, *user_),
      pool_(config.pool) {
  mac_.bind(*port_);
}

MpiStation::~MpiStation() = default;

bus::Ticks MpiStation::now() const { return bound() ? port().now() : 0; }

// --- lookups ---------------------------------------------------------------------------------

MpiStation::Client* MpiStation::client(Handle h) {
  for (Client& c : clients_)
    if (c.handle == h) return &c;
  return nullptr;
}

const MpiStation::Client* MpiStation::client(Handle h) const {
  for (const Client& c : clients_)
    if (c.handle == h) return &c;
  return nullptr;
}

MpiStation::Client* MpiStation::client_by_sap(std::uint8_t sap) {
  for (Client& c : clients_)
    if (c.conn.local_sap() == sap) return &c;
  return nullptr;
}

MpiStation::Served* MpiStation::served(std::uint8_t sap) {
  for (Served& s : served_)
    if (s.sap == sap) return &s;
  return nullptr;
}

std::optional<std::uint8_t> MpiStation::free_client_sap() const {
  const unsigned last = server_ ? static_cast<unsigned>(config_.pool.first_sap) - 1u : kMaxSap;
  for (unsigned sap = std::max<unsigned>(config_.client_first_sap, mpi::kConnectSap + 1u);
       sap <= last && sap <= kMaxSap; ++sap) {
    const bool used = std::any_of(clients_.begin(), clients_.end(),
                                  [&](const Client& c) { return c.conn.local_sap() == sap; });
    if (!used) return static_cast<std::uint8_t>(sap);
  }
  return std::nullopt;
}

// --- client role -----------------------------------------------------------------------------

std::optional<Handle> MpiStation::open(std::uint8_t cpu_address) {
  if (cpu_address > fdl::BusParams::kHsaMax || cpu_address == config_.address) return std::nullopt;
  const std::optional<std::uint8_t> sap = free_client_sap();
  if (!sap) return std::nullopt;
  const bus::Ticks t = now();
  const Handle h = next_handle_++;
  clients_.push_back(Client{h, mpi::Connection::initiator(cpu_address, *sap, config_.timing), {}, {}, false});
  clients_.back().conn.connect(t, out_);
  ++stats_.connects_opened;
  flush(t);
  rearm();
  deliver();
  return h;
}

mpi::RequestError MpiStation::submit(Handle h, std::span<const std::uint8_t> s7_pdu) {
  Client* c = client(h);
  if (!c || c->reported || c->conn.state() == mpi::State::Closed ||
      c->conn.state() == mpi::State::Disconnecting) {
    return mpi::RequestError::WrongState;
  }
  if (s7_pdu.empty()) return mpi::RequestError::EmptyData;
  if (s7_pdu.size() > mpi::kMaxDataLen) return mpi::RequestError::TooLong;
  c->pending.emplace_back(s7_pdu.begin(), s7_pdu.end());
  const bus::Ticks t = now();
  send_pending_client(t, *c);
  flush(t);
  rearm();
  deliver();
  return mpi::RequestError::None;
}

mpi::RequestError MpiStation::close(Handle h) {
  Client* c = client(h);
  if (!c || c->reported) return mpi::RequestError::WrongState;
  const bus::Ticks t = now();
  c->pending.clear();
  const mpi::RequestError e = c->conn.disconnect(t, out_);
  flush(t);
  rearm();
  deliver();
  return e;
}

mpi::State MpiStation::state(Handle h) const {
  const Client* c = client(h);
  return c ? c->conn.state() : mpi::State::Closed;
}

std::size_t MpiStation::queued(Handle h) const {
  const Client* c = client(h);
  return c ? c->pending.size() : 0;
}

void MpiStation::send_pending_client(bus::Ticks now, Client& c) {
  if (c.pending.empty() || c.conn.state() != mpi::State::Connected || c.conn.awaiting_data_ack()) return;
  if (c.conn.send_data(now, c.pending.front(), out_) == mpi::RequestError::None) {
    c.pending.pop_front();
    ++stats_.pdus_sent;
  }
}

void MpiStation::send_pending_served(bus::Ticks now, Served& s) {
  const mpi::Connection* conn = pool_.find(s.sap);
  if (s.pending.empty() || !conn || conn->state() != mpi::State::Connected || conn->awaiting_data_ack()) return;
  if (pool_.send_data(now, s.sap, s.pending.front(), out_) == mpi::RequestError::None) {
    s.pending.pop_front();
    ++stats_.pdus_sent;
  }
}

void MpiStation::answer_later(std::uint32_t serial, std::vector<std::uint8_t> answer) {
  auto it = std::find_if(served_.begin(), served_.end(), [&](const Served& s) { return s.serial == serial; });
  if (it == served_.end() || it->reported || !it->session || !powered_) {
    ++stats_.late_answers_dropped;  // the connection ended meanwhile: nobody to answer
    return;
  }
  Served& s = *it;
  if (s.held > 0) --s.held;
  const bus::Ticks t = now();
  if (answer.empty()) {
    no_answer(t, s);  // as for an answer given at once (the session ended meanwhile)
    flush(t);
    rearm();
    deliver();
    return;
  }
  if (answer.size() > mpi::kMaxDataLen) {
    ++stats_.answers_too_long;
    return;
  }
  ++stats_.answers_late;
  s.pending.push_back(std::move(answer));
  send_pending_served(t, s);
  // Inside a station call (the session answered from handle()) the outer flush takes the
  // frames; otherwise they are queued for the token here and the data ack's deadline armed.
  flush(t);
  rearm();
  deliver();
}

void MpiStation::no_answer(bus::Ticks now, Served& s) {
  ++stats_.answers_none;
  if (s.reported || !s.session || !s.session->ended()) return;
  // The session is kept until the connection is gone (it may be inside its own sink now).
  if (pool_.disconnect(now, s.sap, out_) != mpi::RequestError::None) return;
  s.reported = true;
  s.pending.clear();
  report_server_end(now, s.sap, s.peer, EndReason::SessionEnded);
}

void MpiStation::report_server_end(bus::Ticks now, std::uint8_t sap, std::uint8_t peer,
                                   EndReason reason) {
  StationEvent ev;
  ev.at = now;
  ev.kind = EventKind::Broken;
  ev.role = Role::Server;
  ev.local_sap = sap;
  ev.peer = peer;
  ev.reason = reason;
  count_end(ev.kind, ev.reason);
  emit(std::move(ev));
}

std::size_t MpiStation::held_jobs() const {
  std::size_t n = 0;
  for (const Served& s : served_) n += s.held;
  return n;
}

// --- events ----------------------------------------------------------------------------------

std::vector<StationEvent> MpiStation::take_events() { return std::exchange(events_, {}); }

void MpiStation::emit(StationEvent ev) { pending_events_.push_back(std::move(ev)); }

void MpiStation::deliver() {
  // Called at the end of every entry point, when no loop over the connections is running, so
  // a handler may call open/submit/close (which deliver their own events in turn).
  if (delivering_) return;
  delivering_ = true;
  while (!pending_events_.empty()) {
    std::vector<StationEvent> batch = std::exchange(pending_events_, {});
    for (StationEvent& ev : batch) {
      if (handler_) {
        handler_(ev);
      } else {
        events_.push_back(std::move(ev));
      }
    }
  }
  delivering_ = false;
}

void MpiStation::count_end(EventKind kind, EndReason reason) {
  if (kind == EventKind::Broken) ++stats_.broken[static_cast<std::size_t>(reason)];
  if (kind == EventKind::Closed) ++stats_.closed;
}

void MpiStation::flush(bus::Ticks now) {
  if (flushing_) return;  // the outer flush picks up what a handler produced
  flushing_ = true;
  while (!out_.frames.empty() || !out_.events.empty()) {
    mpi::Outbox batch;
    std::swap(batch, out_);
    for (mpi::Outgoing& f : batch.frames) {
      // Frames of connections we opened leave as SRD high, the others as SRD low (§H.3 trace).
      Client* c = client_by_sap(f.ssap);
      Tx tx{f, c != nullptr, c ? c->handle : 0};
      (tx.client ? tx_high_ : tx_low_).push_back(std::move(tx));
    }
    for (const mpi::Event& e : batch.events) {
      if (client_by_sap(e.local_sap)) {
        on_client_event(now, e);
      } else {
        on_server_event(now, e);
      }
    }
  }
  flushing_ = false;
  sweep();
}

void MpiStation::on_client_event(bus::Ticks now, const mpi::Event& e) {
  Client* c = client_by_sap(e.local_sap);
  StationEvent ev;
  ev.at = now;
  ev.role = Role::Client;
  ev.handle = c->handle;
  ev.local_sap = e.local_sap;
  ev.peer = e.peer;
  switch (e.kind) {
    case mpi::EventKind::ConnectIndication: return;  // a responder's event: not for clients
    case mpi::EventKind::Connected:
      ++stats_.connected;
      ev.kind = EventKind::Connected;
      emit(std::move(ev));
      send_pending_client(now, *c);
      return;
    case mpi::EventKind::ConnectRefused:
      ++stats_.refusals_received;
      c->reported = true;
      c->pending.clear();
      ev.kind = EventKind::Refused;
      ev.reason = from_mpi(e.reason);
      emit(std::move(ev));
      return;
    case mpi::EventKind::DataIndication:
      ++stats_.pdus_received;
      ev.kind = EventKind::Reply;
      ev.pdu = e.data;
      emit(std::move(ev));
      return;
    case mpi::EventKind::DataConfirm:
      send_pending_client(now, *c);
      return;
    case mpi::EventKind::Disconnected:
    case mpi::EventKind::Broken:
      if (c->reported) return;  // already reported (ring watch, refusal)
      c->reported = true;
      c->pending.clear();
      ev.kind = e.kind == mpi::EventKind::Broken ? EventKind::Broken : EventKind::Closed;
      ev.reason = from_mpi(e.reason);
      count_end(ev.kind, ev.reason);
      emit(std::move(ev));
      return;
  }
}

void MpiStation::on_server_event(bus::Ticks now, const mpi::Event& e) {
  StationEvent ev;
  ev.at = now;
  ev.role = Role::Server;
  ev.local_sap = e.local_sap;
  ev.peer = e.peer;
  switch (e.kind) {
    case mpi::EventKind::ConnectIndication: {
      ++stats_.connects_accepted;
      Served s;
      s.serial = next_serial_++;
      s.sap = e.local_sap;
      s.peer = e.peer;
      s.session = server_ ? server_->open(e.peer) : nullptr;
      const bool refused = !s.session;
      if (s.session) {
        s.session->on_late_answer(
            [this, serial = s.serial](std::vector<std::uint8_t> answer) { answer_later(serial, std::move(answer)); });
      }
      served_.push_back(std::move(s));
      ev.kind = EventKind::Accepted;
      emit(std::move(ev));
      if (refused && pool_.disconnect(now, e.local_sap, out_) == mpi::RequestError::None) {
        served(e.local_sap)->reported = true;
        report_server_end(now, e.local_sap, e.peer, EndReason::Refused);
      }
      return;
    }
    case mpi::EventKind::Connected:
      ++stats_.connected;
      ev.kind = EventKind::Connected;
      emit(std::move(ev));
      return;
    case mpi::EventKind::ConnectRefused: return;  // initiators only
    case mpi::EventKind::DataIndication: {
      ++stats_.pdus_received;
      Served* s = served(e.local_sap);
      if (!s || !s->session || s->reported) return;
      const bool holds = s->session->holds_jobs_now();
      std::vector<std::uint8_t> answer = s->session->handle(e.data);
      if (answer.empty()) {
        if (holds) {
          ++s->held;  // answered later through the sink (answer_later)
          ++stats_.answers_held;
        } else {
          no_answer(now, *s);
        }
        return;
      }
      if (answer.size() > mpi::kMaxDataLen) {
        ++stats_.answers_too_long;  // cannot go in one data message (docs/mpi.md)
        return;
      }
      s->pending.push_back(std::move(answer));
      send_pending_served(now, *s);
      return;
    }
    case mpi::EventKind::DataConfirm:
      if (Served* s = served(e.local_sap)) send_pending_served(now, *s);
      return;
    case mpi::EventKind::Disconnected:
    case mpi::EventKind::Broken: {
      auto it = std::find_if(served_.begin(), served_.end(), [&](const Served& s) { return s.sap == e.local_sap; });
      if (it == served_.end()) return;
      const bool reported = it->reported;
      served_.erase(it);  // the session ends with its connection
      if (reported) return;
      ev.kind = e.kind == mpi::EventKind::Broken ? EventKind::Broken : EventKind::Closed;
      ev.reason = from_mpi(e.reason);
      count_end(ev.kind, ev.reason);
      emit(std::move(ev));
      return;
    }
  }
}

void MpiStation::sweep() {
  // A client connection is forgotten once it is closed (its end has been reported) and has no
  // frame in the FDL layer's hands (the pool does the same for its own, mpi::ConnectionPool).
  std::erase_if(clients_, [](const Client& c) {
    return c.conn.state() == mpi::State::Closed && c.conn.unconfirmed_frames() == 0;
  });
}

// --- fdl::InitiatorUser ----------------------------------------------------------------------

bool MpiStation::next_request(fdl::Priority prio, bus::Ticks now, fdl::Request& out) {
  run_due(now);
  std::deque<Tx>& q = prio == fdl::Priority::High ? tx_high_ : tx_low_;
  if (q.empty() || in_flight_) return false;
  in_flight_ = std::move(q.front());
  q.pop_front();
  const mpi::Outgoing& f = in_flight_->frame;
  out.da = f.peer;
  out.fn = prio == fdl::Priority::High ? fdl::RequestFn::SrdHigh : fdl::RequestFn::SrdLow;
  out.dsap = f.dsap;
  out.ssap = f.ssap;
  const auto bytes = f.pdu.bytes();
  out.data.assign(bytes.begin(), bytes.end());
  out.tag = 0;
  ++stats_.frames_sent;
  return true;
}

void MpiStation::on_confirmation(const fdl::Confirmation& con) {
  if (!in_flight_) return;
  const Tx tx = std::move(*in_flight_);
  in_flight_.reset();
  mpi::FdlResult r = mpi::FdlResult::Delivered;
  if (con.result == fdl::Confirmation::Result::NoResponse) {
    r = mpi::FdlResult::NoAnswer;
    ++stats_.frames_unanswered;
  } else if (!con.short_ack && (con.status == fdl::ResponseStatus::UE || con.status == fdl::ResponseStatus::RR ||
                                con.status == fdl::ResponseStatus::RS)) {
    r = mpi::FdlResult::Refused;
    ++stats_.frames_refused;
  } else {
    ++stats_.frames_delivered;
  }
  if (tx.client) {
    if (Client* c = client(tx.handle)) c->conn.on_fdl_result(con.now, r, out_);
  } else {
    pool_.on_fdl_result(con.now, tx.frame.ssap, r, out_);
  }
  flush(con.now);
}

void MpiStation::on_request(const fdl::Indication& ind, fdl::Reply& reply) {
  if (ind.broadcast() || !ind.dsap || !ind.ssap) return;  // preset: RS, no MPI frame
  ++stats_.frames_received;
  const mpi::Received r{ind.sa, *ind.dsap, *ind.ssap, ind.data};
  mpi::FdlReply fr = mpi::FdlReply::SapNotActivated;
  if (r.dsap == mpi::kConnectSap) {
    if (server_) fr = pool_.on_frame(ind.now, r, out_);
  } else {
    Client* c = nullptr;
    for (Client& k : clients_) {
      if (k.conn.matches(r)) {
        c = &k;
        break;
      }
    }
    if (c) {
      fr = c->conn.on_frame(ind.now, r, out_);
    } else if (server_) {
      fr = pool_.on_frame(ind.now, r, out_);
    }
  }
  if (fr == mpi::FdlReply::NoResources) ++stats_.connects_refused;
  if (fr != mpi::FdlReply::Ack) ++stats_.replies_not_sc;
  to_fdl_reply(fr, reply);
  flush(ind.now);
}

void MpiStation::on_token(bus::Ticks now) { run_due(now); }

// --- ring watch and deadlines ----------------------------------------------------------------

void MpiStation::watch_one(bus::Ticks now, std::uint8_t peer, Watch& w) {
  if (mac_.las_contains(peer)) {
    w.seen = true;
    w.absent_since = bus::kNever;
    w.token_losses = mac_.stats().token_losses;
    return;
  }
  // Only a valid LAS of a station in the ring says who is missing (not while listening).
  const bool judge = mac_.las_valid() && mac_.state() != fdl::MacState::Listen_Token &&
                     mac_.state() != fdl::MacState::Offline;
  if (w.seen && judge && w.absent_since == bus::kNever) w.absent_since = now;
}

void MpiStation::watch_ring(bus::Ticks now) {
  for (Client& c : clients_) {
    if (c.reported || c.conn.state() == mpi::State::Closed) continue;
    watch_one(now, c.conn.peer(), c.watch);
  }
  for (Served& s : served_) {
    if (!s.reported) watch_one(now, s.peer, s.watch);
  }
}

void MpiStation::run_due(bus::Ticks now) {
  if (!powered_) return;
  watch_ring(now);
  for (Client& c : clients_) {
    if (c.conn.deadline() && *c.conn.deadline() <= now) c.conn.on_timer(now, out_);
  }
  if (const auto d = pool_.deadline(); d && *d <= now) pool_.on_timer(now, out_);
  flush(now);
  // Token loss: our station claimed the token since the peer was last seen and its ring still
  // holds nobody else (the line is dead, or we are cut off alone); otherwise the ring goes on
  // without the peer.
  auto reason_of = [&](const Watch& w) {
    return mac_.stats().token_losses > w.token_losses && alone_in_ring() ? EndReason::TokenLost
                                                                          : EndReason::PeerLeftRing;
  };
  auto expired = [&](const Watch& w) {
    return w.absent_since != bus::kNever && now >= w.absent_since + config_.peer_absent_timeout;
  };
  for (Client& c : clients_) {
    if (c.reported || !expired(c.watch)) continue;
    c.reported = true;
    c.pending.clear();
    StationEvent ev;
    ev.at = now;
    ev.kind = EventKind::Broken;
    ev.role = Role::Client;
    ev.handle = c.handle;
    ev.local_sap = c.conn.local_sap();
    ev.peer = c.conn.peer();
    ev.reason = reason_of(c.watch);
    count_end(ev.kind, ev.reason);
    emit(std::move(ev));
    // Tell the peer, in case it still holds the connection (it is released when the FDL layer
    // confirms, or broken when the peer does not answer; either is not reported again).
    if (c.conn.state() != mpi::State::Closed && c.conn.state() != mpi::State::Disconnecting) {
      c.conn.disconnect(now, out_);
    }
  }
  for (Served& s : served_) {
    if (s.reported || !expired(s.watch)) continue;
    s.reported = true;
    s.pending.clear();
    s.session.reset();
    StationEvent ev;
    ev.at = now;
    ev.kind = EventKind::Broken;
    ev.role = Role::Server;
    ev.local_sap = s.sap;
    ev.peer = s.peer;
    ev.reason = reason_of(s.watch);
    count_end(ev.kind, ev.reason);
    emit(std::move(ev));
    pool_.disconnect(now, s.sap, out_);
  }
  flush(now);
}

bool MpiStation::alone_in_ring() const {
  for (std::uint8_t a = 0; a < 127; ++a)
    if (a != mac_.address() && mac_.las_contains(a)) return false;
  return true;
}

bus::Ticks MpiStation::next_deadline() const {
  bus::Ticks at = bus::kNever;
  for (const Client& c : clients_) {
    if (c.conn.deadline()) at = std::min(at, *c.conn.deadline());
    if (!c.reported && c.watch.absent_since != bus::kNever)
      at = std::min(at, c.watch.absent_since + config_.peer_absent_timeout);
  }
  if (const auto d = pool_.deadline()) at = std::min(at, *d);
  for (const Served& s : served_) {
    if (!s.reported && s.watch.absent_since != bus::kNever)
      at = std::min(at, s.watch.absent_since + config_.peer_absent_timeout);
  }
  return at;
}

void MpiStation::rearm() {
  if (!bound() || !powered_) return;
  port().set_timer(std::min(mac_timer_, next_deadline()));
}

// --- bus::Device -----------------------------------------------------------------------------

void MpiStation::on_power_on(bus::Ticks now) {
  powered_ = true;
  mac_timer_ = bus::kNever;
  mac_.on_power_on(now);  // arms the MAC's timer through Port::set_timer
  rearm();
  deliver();
}

void MpiStation::on_power_off(bus::Ticks now) {
  mac_.on_power_off(now);
  powered_ = false;
  mac_timer_ = bus::kNever;
  // Every connection ends with the station: report each once, forget everything.
  for (Client& c : clients_) {
    if (c.reported || c.conn.state() == mpi::State::Closed) continue;
    StationEvent ev;
    ev.at = now;
    ev.kind = EventKind::Broken;
    ev.role = Role::Client;
    ev.handle = c.handle;
    ev.local_sap = c.conn.local_sap();
    ev.peer = c.conn.peer();
    ev.reason = EndReason::PowerLoss;
    count_end(ev.kind, ev.reason);
    emit(std::move(ev));
  }
  for (Served& s : served_) {
    if (s.reported) continue;
    StationEvent ev;
    ev.at = now;
    ev.kind = EventKind::Broken;
    ev.role = Role::Server;
    ev.local_sap = s.sap;
    ev.peer = s.peer;
    ev.reason = EndReason::PowerLoss;
    count_end(ev.kind, ev.reason);
    emit(std::move(ev));
  }
  clients_.clear();
  served_.clear();
  pool_ = mpi::ConnectionPool(config_.pool);
  tx_high_.clear();
  tx_low_.clear();
  in_flight_.reset();
  out_.clear();
  deliver();
}

void MpiStation::on_frame(const bus::RxFrame& frame) {
  if (!powered_) return;
  mac_.on_frame(frame);
  run_due(frame.end);
  rearm();
  deliver();
}

void MpiStation::on_timer(bus::Ticks now) {
  if (!powered_) return;
  if (mac_timer_ <= now) {
    mac_timer_ = bus::kNever;
    mac_.on_timer(now);  // re-requests its timer if it still needs one
  }
  run_due(now);
  rearm();
  deliver();
}

}  // namespace pbvbus::mpi_station
