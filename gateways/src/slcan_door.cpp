#include "pbvbus/gateways/slcan_door.hpp"

#include "pbvbus/bus/pty.hpp"

#include <fcntl.h>
#include <termios.h>
#include <unistd.h>

#include <cerrno>
#include <vector>

#include "door_stream.hpp"
#include "pbvbus/tcp_door/throttled_log.hpp"
#include "pbvbus/bus/paced_runner.hpp"

namespace pbvbus::gateways {

using door_stream::errno_text;

struct SlcanDoor::Link : door_stream::Stream {
  Link(SlcanDoor& d, boost::asio::io_context& io, int fd_, bool sock, std::string serial)
      : Stream(io, fd_, sock), door(&d), session(std::move(serial)) {}
  void received(const std::string& bytes, bus::Ticks now) override {
    door->on_bytes(*this, bytes, now);
  }
  void gone() override { door->drop_link(*this); }
  SlcanDoor* door;
  slcan::SlcanSession session;
  std::uint64_t key = 0;
  CanHub::PortId port = 0;
};

struct SlcanDoor::Listener : door_stream::TcpListener {
  Listener(boost::asio::io_context& io, int fd, const std::string& name, const DoorLog& log,
           OnAccept on_accept)
      : TcpListener(io, fd, name, log, std::move(on_accept)), who(name), refusals(log) {}
  std::string who;  // starts each logged line: "slcan HOST:PORT"
  ThrottledLog refusals;
};

SlcanDoor::SlcanDoor(bus::PacedRunner& runner, CanHub& hub, Options options)
    : m_runner(runner), m_hub(hub), m_opt(std::move(options)) {}

SlcanDoor::~SlcanDoor() { close(); }

std::string SlcanDoor::open() {
  if (!m_links.empty() || m_listener) return "slcan door: already open";
  if (m_opt.pty) {
    // The slave side stays open (no EIO while no client holds it) and raw: SLCAN lines end in
    // '\r', which must not be mapped.
    bus::Pty pty;
    try {
      pty = bus::open_pty();
    } catch (const std::system_error& e) {
      return std::string("slcan door: ") + e.what();
    }
    const int master = pty.master;
    m_pty_slave = pty.slave;
    m_pty_path = pty.path;
    if (!m_opt.pty_link.empty()) {
      const std::string e = bus::make_pty_link(pty.path, m_opt.pty_link);
      if (!e.empty()) {
        ::close(master);
        close();
        return "slcan door: " + e;
      }
    }
    door_stream::start_read(add_link(master, false, m_opt.name + ":pty"), m_runner);
  }
  if (m_opt.tcp) {
    std::string err;
    const int fd = door_stream::listen_tcp(m_opt.tcp_address, m_opt.tcp_port, m_port, err);
    if (fd < 0) {
      close();
      return "slcan door: " + err;
    }
    m_listener = std::make_unique<Listener>(
        m_runner.io_context(), fd, m_opt.name + " " + m_opt.tcp_address + ":" + std::to_string(m_port),
        m_opt.log, [this](int conn, std::uint64_t n) { return accept_tcp(conn, n); });
  }
  return {};
}

void SlcanDoor::close() {
  for (auto& [key, l] : m_links) {
    m_hub.remove_port(l->port);
    door_stream::close(*l);
  }
  // Fold the counters of the links being closed, so stats() stays complete.
  const Stats now = stats();
  m_links.clear();
  m_closed = now;
  m_closed.clients = 0;
  m_listener.reset();
  if (m_pty_slave >= 0) ::close(m_pty_slave);
  m_pty_slave = -1;
  if (!m_opt.pty_link.empty() && !m_pty_path.empty()) {
    char target[256];
    const ssize_t n = ::readlink(m_opt.pty_link.c_str(), target, sizeof target - 1);
    if (n > 0 && std::string(target, static_cast<std::size_t>(n)) == m_pty_path)
      ::unlink(m_opt.pty_link.c_str());
  }
  m_pty_path.clear();
  m_port = 0;
}

SlcanDoor::Stats SlcanDoor::stats() const {
  Stats s = m_closed;
  for (const auto& [key, l] : m_links) {
    const auto& ss = l->session.stats();
    ++s.clients;
    s.lines += ss.lines;
    s.frames_in += ss.frames_in;
    s.errors += ss.errors;
    s.overlong += ss.overlong;
    s.frames_out += l->frames_out;
    s.dropped += l->dropped;
  }
  if (m_listener) {
    s.clients_total = m_closed.clients_total + m_listener->accepted();
    s.refused = m_closed.refused + m_listener->refused();
    s.accept_pauses = m_closed.accept_pauses + m_listener->backoff().pauses();
  }
  // The pty is one client for as long as the door has it (the report said "0 clients (1 now)").
  if (m_pty_slave >= 0) ++s.clients_total;
  return s;
}

bool SlcanDoor::accept_tcp(int fd, std::uint64_t n) {
  std::size_t open = 0;
  for (const auto& [key, l] : m_links) open += l->is_socket ? 1 : 0;
  if (open >= m_opt.max_clients) {
    m_listener->refusals(m_listener->who + ": refused a client: " + std::to_string(open) +
                         " connections open (max_clients)");
    return false;
  }
  door_stream::start_read(add_link(fd, true, m_opt.name + ":tcp:" + std::to_string(n)), m_runner);
  return true;
}

std::shared_ptr<SlcanDoor::Link> SlcanDoor::add_link(int fd, bool is_socket, std::string name) {
  auto l = std::make_shared<Link>(*this, m_runner.io_context(), fd, is_socket, m_opt.serial);
  l->key = m_next_link++;
  std::weak_ptr<Link> w = l;
  l->port = m_hub.add_port(std::move(name), [w](const CanFrame& f, bus::Ticks now) {
    if (auto p = w.lock()) p->door->on_hub_frame(*p, f, now);
  });
  m_links.emplace(l->key, l);
  return l;
}

void SlcanDoor::on_bytes(Link& l, const std::string& bytes, bus::Ticks now) {
  std::string reply;
  std::vector<CanFrame> to_bus;
  l.session.feed(bytes, reply, to_bus);
  if (!reply.empty()) emit(l, reply, false);
  for (const CanFrame& f : to_bus) m_hub.send(l.port, f, now);
}

void SlcanDoor::on_hub_frame(Link& l, const CanFrame& f, bus::Ticks now) {
  if (l.closed) return;
  if (auto line = l.session.frame_to_host(f, now)) emit(l, *line, true);
}

void SlcanDoor::emit(Link& l, std::string_view s, bool frame) {
  if (!door_stream::queue(l, s, m_opt.max_output, m_runner)) {
    if (frame) l.session.note_overrun();  // the client's `F` shows a data overrun
    return;
  }
  if (frame) ++l.frames_out;
}

void SlcanDoor::drop_link(Link& l) {
  auto it = m_links.find(l.key);
  if (it == m_links.end()) return;
  const std::shared_ptr<Link> keep = it->second;  // alive until we return
  const auto& ss = l.session.stats();
  m_closed.lines += ss.lines;
  m_closed.frames_in += ss.frames_in;
  m_closed.errors += ss.errors;
  m_closed.overlong += ss.overlong;
  m_closed.frames_out += l.frames_out;
  m_closed.dropped += l.dropped;
  m_hub.remove_port(l.port);
  door_stream::close(l);
  m_links.erase(it);
}

}  // namespace pbvbus::gateways
