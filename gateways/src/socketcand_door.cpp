#include "pbvbus/gateways/socketcand_door.hpp"

#include <boost/asio/steady_timer.hpp>
#include <vector>

#include "door_stream.hpp"
#include "pbvbus/tcp_door/throttled_log.hpp"
#include "pbvbus/bus/paced_runner.hpp"

namespace pbvbus::gateways {

struct SocketcandDoor::Link : door_stream::Stream {
  Link(SocketcandDoor& d, boost::asio::io_context& io, int fd_, std::string channel)
      : Stream(io, fd_, true), door(&d), hold_timer(io), session(std::move(channel)) {}
  void received(const std::string& bytes, bus::Ticks now) override {
    door->on_bytes(*this, bytes, now);
  }
  void gone() override { door->drop_link(*this); }
  bool may_write() const override { return !holding; }
  SocketcandDoor* door;
  boost::asio::steady_timer hold_timer;
  socketcand::SocketcandSession session;
  std::uint64_t key = 0;
  CanHub::PortId port = 0;
  bool holding = false;  // after the rawmode `< ok >`: queue, do not write yet
};

struct SocketcandDoor::Listener : door_stream::TcpListener {
  Listener(boost::asio::io_context& io, int fd, const std::string& name, const DoorLog& log,
           OnAccept on_accept)
      : TcpListener(io, fd, name, log, std::move(on_accept)), who(name), refusals(log) {}
  std::string who;  // starts each logged line: "socketcand HOST:PORT"
  ThrottledLog refusals;
};

SocketcandDoor::SocketcandDoor(bus::PacedRunner& runner, CanHub& hub, Options options)
    : m_runner(runner), m_hub(hub), m_opt(std::move(options)) {}

SocketcandDoor::~SocketcandDoor() { close(); }

std::string SocketcandDoor::open() {
  if (m_listener) return "socketcand door: already open";
  std::string err;
  const int fd = door_stream::listen_tcp(m_opt.address, m_opt.port, m_port, err);
  if (fd < 0) {
    m_port = 0;
    return "socketcand door: " + err;
  }
  m_listener = std::make_unique<Listener>(
      m_runner.io_context(), fd, m_opt.name + " " + m_opt.address + ":" + std::to_string(m_port),
      m_opt.log, [this](int conn, std::uint64_t n) { return accept_link(conn, n); });
  return {};
}

void SocketcandDoor::close() {
  const Stats now = stats();
  for (auto& [key, l] : m_links) {
    m_hub.remove_port(l->port);
    l->hold_timer.cancel();
    door_stream::close(*l);
  }
  m_links.clear();
  m_closed = now;
  m_closed.clients = 0;
  m_listener.reset();
  m_port = 0;
}

SocketcandDoor::Stats SocketcandDoor::stats() const {
  Stats s = m_closed;
  for (const auto& [key, l] : m_links) {
    const auto& ss = l->session.stats();
    ++s.clients;
    s.elements += ss.elements;
    s.frames_in += ss.frames_in;
    s.errors += ss.errors;
    s.frames_out += l->frames_out;
    s.dropped += l->dropped;
  }
  if (m_listener) {
    s.clients_total = m_closed.clients_total + m_listener->accepted();
    s.refused = m_closed.refused + m_listener->refused();
    s.accept_pauses = m_closed.accept_pauses + m_listener->backoff().pauses();
  }
  return s;
}

bool SocketcandDoor::accept_link(int fd, std::uint64_t n) {
  if (m_links.size() >= m_opt.max_clients) {
    m_listener->refusals(m_listener->who + ": refused a client: " +
                         std::to_string(m_links.size()) + " connections open (max_clients)");
    return false;
  }
  auto l = std::make_shared<Link>(*this, m_runner.io_context(), fd, m_opt.channel);
  l->key = m_next_link++;
  std::weak_ptr<Link> w = l;
  l->port = m_hub.add_port(m_opt.name + ":" + std::to_string(n),
                           [w](const CanFrame& f, bus::Ticks now) {
                             if (auto p = w.lock()) p->door->on_hub_frame(*p, f, now);
                           });
  m_links.emplace(l->key, l);
  emit(*l, socketcand::SocketcandSession::greeting(), false);  // `< hi >`, alone
  door_stream::start_read(l, m_runner);
  return true;
}

void SocketcandDoor::on_bytes(Link& l, const std::string& bytes, bus::Ticks now) {
  // The client wrote again, so it has read what came before: held frames may go now.
  if (l.holding) release_hold(l);
  const auto before = l.session.mode();
  std::vector<std::string> replies;
  std::vector<CanFrame> to_bus;
  l.session.feed(bytes, replies, to_bus);
  for (const std::string& r : replies) emit(l, r, false);
  if (before != socketcand::SocketcandSession::Mode::Raw &&
      l.session.mode() == socketcand::SocketcandSession::Mode::Raw && m_opt.raw_hold.count() > 0) {
    l.holding = true;
    l.hold_timer.expires_after(m_opt.raw_hold);
    std::weak_ptr<Link> w = std::static_pointer_cast<Link>(l.shared_from_this());
    l.hold_timer.async_wait([w](const boost::system::error_code& ec) {
      if (ec) return;
      if (auto p = w.lock(); p && !p->closed && p->holding) p->door->release_hold(*p);
    });
  }
  for (const CanFrame& f : to_bus) m_hub.send(l.port, f, now);
  if (l.session.wants_close()) {
    ++m_closed.closed_bad;
    drop_link(l);
  }
}

void SocketcandDoor::release_hold(Link& l) {
  l.holding = false;
  l.hold_timer.cancel();
  if (!l.write_armed) door_stream::flush(l, m_runner);
}

void SocketcandDoor::on_hub_frame(Link& l, const CanFrame& f, bus::Ticks now) {
  if (l.closed) return;
  if (auto text = l.session.frame_to_client(f, now)) emit(l, *text, true);
}

void SocketcandDoor::emit(Link& l, std::string_view s, bool frame) {
  // While holding (Link::may_write() false) the text is queued, not written.
  if (door_stream::queue(l, s, m_opt.max_output, m_runner) && frame) ++l.frames_out;
}

void SocketcandDoor::drop_link(Link& l) {
  auto it = m_links.find(l.key);
  if (it == m_links.end()) return;
  const std::shared_ptr<Link> keep = it->second;  // alive until we return
  const auto& ss = l.session.stats();
  m_closed.elements += ss.elements;
  m_closed.frames_in += ss.frames_in;
  m_closed.errors += ss.errors;
  m_closed.frames_out += l.frames_out;
  m_closed.dropped += l.dropped;
  m_hub.remove_port(l.port);
  l.hold_timer.cancel();
  door_stream::close(l);
  m_links.erase(it);
}

}  // namespace pbvbus::gateways
