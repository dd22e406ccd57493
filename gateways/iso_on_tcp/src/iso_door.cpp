#include "pbvbus/iso_on_tcp/iso_door.hpp"

#include <algorithm>
#include <array>
#include <boost/asio/ip/tcp.hpp>
#include <boost/asio/steady_timer.hpp>
#include <boost/asio/write.hpp>
#include <list>
#include <vector>

#include "pbvbus/tcp_door/tcp_accept.hpp"
#include "pbvbus/tcp_door/throttled_log.hpp"

namespace pbvbus::iso_on_tcp {

namespace asio = boost::asio;
using asio::ip::tcp;
using Clock = std::chrono::steady_clock;

namespace {
/// Octets taken per read wake-up of one connection.
constexpr std::size_t kReadChunk = 4096;
/// Octets handed to the session at a time, so that the output can be looked at in between: at
/// most 8 jobs (31 octets is the shortest Read Var), i.e. 8 answers of at most one PDU each.
constexpr std::size_t kFeedSlice = 256;
}  // namespace

struct IsoOnTcpDoor::Impl : std::enable_shared_from_this<IsoOnTcpDoor::Impl> {
  struct Link;
  using Links = std::list<std::shared_ptr<Link>>;

  Impl(asio::io_context& i, S7Router& r, IsoDoorOptions o)
      : io(i),
        router(r),
        opt(std::move(o)),
        acceptor(i),
        backoff(i, "iso_on_tcp", opt.log),
        complaints(opt.log) {}

  void listen();
  void accept_next();
  void take(tcp::socket s);
  void shut();

  asio::io_context& io;
  S7Router& router;
  IsoDoorOptions opt;
  tcp::acceptor acceptor;
  gateways::tcp_accept::AcceptBackoff backoff;
  gateways::ThrottledLog complaints;
  std::string who = "iso_on_tcp";
  std::uint16_t port = 0;
  IsoDoorStats stats;
  std::uint64_t next_id = 0;
  bool shut_down = false;
  Links links;
};

/// One TCP connection: its socket, its session and its output.
struct IsoOnTcpDoor::Impl::Link : std::enable_shared_from_this<Link> {
  Link(Impl* d, tcp::socket s, std::uint64_t id_)
      : door(d), sock(std::move(s)), idle(d->io), id(id_) {}

  void start();
  void read_more();
  void consume();
  std::size_t unsent() const { return out.size() + flying.size(); }
  void on_finish(SessionEnd e, const std::string& why);
  void queue_out(std::span<const std::uint8_t> octets);
  void write_out();
  void maybe_close();
  void watch_idle(Clock::time_point at);
  void drop(std::uint64_t IsoDoorStats::*counter, const std::string& why);
  void detach(bool from_hook = true);
  std::string peer() const;

  Impl* door;  // null once the link is closed: handlers still queued then do nothing
  tcp::socket sock;
  asio::steady_timer idle;
  std::uint64_t id;
  Links::iterator pos;
  std::unique_ptr<IsoSession> session;
  std::array<std::uint8_t, kReadChunk> in{};
  std::size_t in_at = 0;             // octets of `in` handed to the session
  std::size_t in_end = 0;            // octets of `in` read
  bool paused = false;               // reading stopped: too much output waits (flow control)
  std::vector<std::uint8_t> out;     // waiting for the socket
  std::vector<std::uint8_t> flying;  // handed to async_write
  bool writing = false;
  bool finishing = false;  // the session ended: close once the output is out
  bool peer_eof = false;
  Clock::time_point last_progress{};
  std::uint64_t progress = 0;  // CC sent + jobs seen: what the idle timeout watches
};

void IsoOnTcpDoor::Impl::listen() {
  const tcp::endpoint ep(asio::ip::make_address(opt.address), opt.port);
  acceptor.open(ep.protocol());
  acceptor.set_option(tcp::acceptor::reuse_address(true));
  acceptor.bind(ep);
  acceptor.listen(gateways::tcp_accept::kListenBacklog);
  port = acceptor.local_endpoint().port();
  who = "iso_on_tcp " + opt.address + ":" + std::to_string(port);
  backoff.set_who(who);
  accept_next();
}

void IsoOnTcpDoor::Impl::accept_next() {
  std::weak_ptr<Impl> w = shared_from_this();
  acceptor.async_accept([w](const boost::system::error_code& ec, tcp::socket s) {
    const auto d = w.lock();
    if (!d || d->shut_down || ec == asio::error::operation_aborted) return;
    if (ec) {
      // Out of descriptors & co.: the connection stays in the backlog; pause, then retry
      // (tcp_accept.hpp), instead of failing at once forever.
      ++d->stats.accept_pauses;
      d->backoff.failed(ec.value(), [w] {
        if (const auto p = w.lock(); p && !p->shut_down) p->accept_next();
      });
      return;
    }
    d->backoff.succeeded();
    d->take(std::move(s));
    if (!d->shut_down) d->accept_next();
  });
}

void IsoOnTcpDoor::Impl::take(tcp::socket s) {
  if (links.size() >= opt.max_clients) {
    ++stats.clients_refused;
    boost::system::error_code ec;
    const auto ep = s.remote_endpoint(ec);
    complaints(who + ": refused a client " +
               (ec ? std::string("(peer unknown)")
                   : ep.address().to_string() + ":" + std::to_string(ep.port())) +
               ": " + std::to_string(links.size()) + " connections open (max_clients)");
    s.close(ec);
    return;
  }
  auto link = std::make_shared<Link>(this, std::move(s), ++next_id);
  links.push_back(link);
  link->pos = std::prev(links.end());
  ++stats.clients_accepted;
  stats.clients_now = links.size();
  link->start();
}

void IsoOnTcpDoor::Impl::shut() {
  if (shut_down) return;
  shut_down = true;
  boost::system::error_code ec;
  acceptor.close(ec);
  for (auto& l : links) l->detach(false);
  links.clear();
  stats.clients_now = 0;
}

void IsoOnTcpDoor::Impl::Link::start() {
  boost::system::error_code ec;
  sock.set_option(tcp::no_delay(true), ec);  // request/answer: Nagle would only delay
  sock.set_option(asio::socket_base::send_buffer_size(gateways::tcp_accept::kKernelSendBuffer), ec);
  sock.non_blocking(true, ec);
  // The hooks hold the link weakly: a channel that answers later may still call into a session
  // whose link has gone (its destruction is posted, detach()).
  std::weak_ptr<Link> w = weak_from_this();
  IsoSession::Hooks hooks;
  hooks.send = [w](std::span<const std::uint8_t> o) {
    if (const auto l = w.lock(); l && l->door) l->queue_out(o);
  };
  hooks.finish = [w](SessionEnd e, const std::string& why) {
    if (const auto l = w.lock(); l && l->door) l->on_finish(e, why);
  };
  hooks.capture = [w](const PduRecord& r) {
    const auto l = w.lock();
    if (!l || !l->door) return;
    Impl* d = l->door;
    if (r.direction == PduDirection::FromClient)
      ++d->stats.jobs;
    else
      ++d->stats.answers;
    if (d->opt.capture) d->opt.capture(r);
  };
  // COTP references are 16 bits and non-zero on our side.
  const auto ref = static_cast<std::uint16_t>((id - 1) % 0xFFFF + 1);
  session =
      std::make_unique<IsoSession>(door->router, door->opt.session, std::move(hooks), id, ref);
  last_progress = Clock::now();
  if (door->opt.idle_timeout.count() > 0) watch_idle(last_progress + door->opt.idle_timeout);
  read_more();
}

std::string IsoOnTcpDoor::Impl::Link::peer() const {
  boost::system::error_code ec;
  const auto ep = sock.remote_endpoint(ec);
  return ec ? std::string("(peer unknown)")
            : ep.address().to_string() + ":" + std::to_string(ep.port());
}

void IsoOnTcpDoor::Impl::Link::read_more() {
  sock.async_read_some(asio::buffer(in), [self = shared_from_this()](
                                             const boost::system::error_code& ec, std::size_t n) {
    if (!self->door) return;
    if (ec) {
      if (ec == asio::error::eof && (self->writing || !self->out.empty())) {
        self->peer_eof = true;  // half-closed after its last job: send what is owed, then close
        return;
      }
      self->drop(nullptr, "");  // the client left (EOF, reset)
      return;
    }
    self->in_at = 0;
    self->in_end = n;
    self->consume();
  });
}

void IsoOnTcpDoor::Impl::Link::consume() {
  // Flow control: while more than a quarter of max_output waits for the client, the door stops
  // taking its input (TCP then holds the client back); it goes on when the output has drained.
  // A client that never reads thus costs at most max_output, and the idle watch closes it.
  while (in_at < in_end) {
    if (unsent() >= door->opt.max_output / 4) {
      paused = true;
      return;
    }
    const std::size_t n = std::min(kFeedSlice, in_end - in_at);
    session->feed(std::span<const std::uint8_t>(in.data() + in_at, n));
    if (!door) return;
    in_at += n;
    const std::uint64_t now_progress = session->jobs() + (session->connected() ? 1 : 0);
    if (now_progress != progress) {
      if (progress == 0 && session->connected()) ++door->stats.connects;
      progress = now_progress;
      last_progress = Clock::now();
    }
    if (finishing) {
      maybe_close();
      return;
    }
  }
  paused = false;
  read_more();
}

void IsoOnTcpDoor::Impl::Link::on_finish(SessionEnd e, const std::string& why) {
  if (!door) return;
  finishing = true;
  auto& st = door->stats;
  bool log = true;
  switch (e) {
    case SessionEnd::ClientDisconnect:
      ++st.disconnects;
      log = false;
      break;
    case SessionEnd::Refused:
      ++st.connects_refused;
      break;
    case SessionEnd::ChannelClosed:
      ++st.routes_closed;
      break;
    case SessionEnd::QueueFull:
      ++st.closed_queue_full;
      break;
    case SessionEnd::Garbage:
    case SessionEnd::NoAnswer:
      ++st.closed_garbage;
      break;
  }
  if (log)
    door->complaints(door->who + ": connection " + std::to_string(id) + " from " + peer() +
                     " closed (" + to_string(e) + "): " + why);
  // The session's last octets (DR, DC, ER) are queued already: close once they are out. The end
  // may come outside any read (the route broke, a later answer was empty), so not only consume()
  // looks at `finishing`.
  maybe_close();
}

void IsoOnTcpDoor::Impl::Link::queue_out(std::span<const std::uint8_t> octets) {
  if (!door) return;
  if (unsent() + octets.size() > door->opt.max_output) {
    drop(&IsoDoorStats::closed_stalled,
         "more than " + std::to_string(door->opt.max_output) +
             " octets of answers wait for a client that does not read");
    return;
  }
  out.insert(out.end(), octets.begin(), octets.end());
  write_out();
}

void IsoOnTcpDoor::Impl::Link::write_out() {
  if (!door || writing || out.empty()) return;
  // What the kernel takes at once goes now (non-blocking socket); the rest with async_write.
  boost::system::error_code ec;
  const std::size_t n = sock.write_some(asio::buffer(out), ec);
  if (ec && ec != asio::error::would_block && ec != asio::error::try_again) {
    drop(nullptr, "");
    return;
  }
  out.erase(out.begin(), out.begin() + static_cast<std::ptrdiff_t>(n));
  if (out.empty()) {
    if (finishing || peer_eof) maybe_close();
    return;
  }
  flying.swap(out);
  writing = true;
  asio::async_write(sock, asio::buffer(flying),
                    [self = shared_from_this()](const boost::system::error_code& wec, std::size_t) {
                      self->writing = false;
                      if (!self->door) return;
                      if (wec) {
                        self->drop(nullptr, "");
                        return;
                      }
                      self->flying.clear();
                      self->write_out();
                      if (self->door && !self->writing && self->out.empty() &&
                          (self->finishing || self->peer_eof))
                        self->maybe_close();
                      if (self->door && self->paused && !self->finishing &&
                          self->unsent() < self->door->opt.max_output / 4)
                        self->consume();
                    });
}

void IsoOnTcpDoor::Impl::Link::maybe_close() {
  if (!door || writing || !out.empty()) return;
  drop(nullptr, "");
}

void IsoOnTcpDoor::Impl::Link::watch_idle(Clock::time_point at) {
  idle.expires_at(at);
  idle.async_wait([self = shared_from_this()](const boost::system::error_code& ec) {
    if (ec || !self->door) return;
    const auto deadline = self->last_progress + self->door->opt.idle_timeout;
    if (Clock::now() < deadline) {
      self->watch_idle(deadline);
      return;
    }
    const auto ms = std::to_string(self->door->opt.idle_timeout.count());
    if (self->paused)
      self->drop(&IsoDoorStats::closed_stalled, std::to_string(self->unsent()) +
                                                    " octets of answers unread for " + ms +
                                                    " ms: the client does not read");
    else
      self->drop(&IsoDoorStats::closed_idle, "no CR or S7 job for " + ms + " ms (half-open)");
  });
}

void IsoOnTcpDoor::Impl::Link::drop(std::uint64_t IsoDoorStats::*counter, const std::string& why) {
  if (!door) return;
  Impl* d = door;
  if (counter) {
    ++(d->stats.*counter);
    d->complaints(d->who + ": connection " + std::to_string(id) + " from " + peer() +
                  " closed: " + why);
  }
  const auto keep = shared_from_this();  // the list holds the other reference
  detach();
  d->links.erase(pos);
  d->stats.clients_now = d->links.size();
}

void IsoOnTcpDoor::Impl::Link::detach(bool from_hook) {
  boost::system::error_code ec;
  idle.cancel();
  sock.close(ec);
  // The session owns the channel: ending it ends the route (the CPU's connection resource is
  // free again). A close may come from inside the session's own hooks (feed() still on the
  // stack), so then it is destroyed on the next turn; when the door shuts, at once.
  if (from_hook && session)
    asio::post(door->io, [s = std::shared_ptr<IsoSession>(std::move(session))] {});
  else
    session.reset();
  door = nullptr;
}

IsoOnTcpDoor::IsoOnTcpDoor(asio::io_context& io, S7Router& router, IsoDoorOptions opt)
    : m(std::make_shared<Impl>(io, router, std::move(opt))) {
  m->listen();
}

IsoOnTcpDoor::~IsoOnTcpDoor() {
  m->shut();
}

std::uint16_t IsoOnTcpDoor::port() const {
  return m->port;
}
const IsoDoorStats& IsoOnTcpDoor::stats() const {
  return m->stats;
}
void IsoOnTcpDoor::close() {
  m->shut();
}

}  // namespace pbvbus::iso_on_tcp
