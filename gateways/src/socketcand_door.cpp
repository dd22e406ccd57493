#include "pbvbus/gateways/socketcand_door.hpp"

#include <arpa/inet.h>
#include <netinet/in.h>
#include <netinet/tcp.h>
#include <sys/socket.h>
#include <unistd.h>

#include <boost/asio/io_context.hpp>
#include <boost/asio/posix/stream_descriptor.hpp>
#include <boost/asio/steady_timer.hpp>
#include <cerrno>
#include <cstring>
#include <vector>

#include "pbvbus/bus/paced_runner.hpp"

namespace pbvbus::gateways {

namespace {

using Descriptor = boost::asio::posix::stream_descriptor;

/// SO_SNDBUF of accepted connections (see slcan_door.cpp: autotuning hoards megabytes).
constexpr int kKernelSendBuffer = 32 * 1024;

std::string errno_text(const std::string& what) { return what + ": " + std::strerror(errno); }

int listen_tcp(const std::string& address, std::uint16_t port, std::uint16_t& bound,
               std::string& err) {
  sockaddr_in sa{};
  sa.sin_family = AF_INET;
  sa.sin_port = htons(port);
  if (::inet_pton(AF_INET, address.c_str(), &sa.sin_addr) != 1) {
    err = "not an IPv4 address: " + address;
    return -1;
  }
  const int fd = ::socket(AF_INET, SOCK_STREAM | SOCK_NONBLOCK | SOCK_CLOEXEC, 0);
  if (fd < 0) {
    err = errno_text("socket");
    return -1;
  }
  const int one = 1;
  ::setsockopt(fd, SOL_SOCKET, SO_REUSEADDR, &one, sizeof one);
  if (::bind(fd, reinterpret_cast<sockaddr*>(&sa), sizeof sa) != 0 || ::listen(fd, 16) != 0) {
    err = errno_text("listen on " + address + ":" + std::to_string(port));
    ::close(fd);
    return -1;
  }
  socklen_t len = sizeof sa;
  ::getsockname(fd, reinterpret_cast<sockaddr*>(&sa), &len);
  bound = ntohs(sa.sin_port);
  return fd;
}

}  // namespace

struct SocketcandDoor::Link : std::enable_shared_from_this<SocketcandDoor::Link> {
  Link(SocketcandDoor& d, boost::asio::io_context& io, int fd_, std::string channel)
      : door(&d), fd(fd_), sd(io, fd_), hold_timer(io), session(std::move(channel)) {}
  SocketcandDoor* door;
  int fd;
  Descriptor sd;  // owns fd
  boost::asio::steady_timer hold_timer;
  socketcand::SocketcandSession session;
  std::uint64_t key = 0;
  CanHub::PortId port = 0;
  std::string out;
  bool write_armed = false;
  bool holding = false;  // after the rawmode `< ok >`: queue, do not write yet
  bool closed = false;
  std::uint64_t frames_out = 0;
  std::uint64_t dropped = 0;
};

struct SocketcandDoor::Listener {
  Listener(boost::asio::io_context& io, int fd) : sd(io, fd) {}
  Descriptor sd;
  std::uint64_t accepted = 0;
};

SocketcandDoor::SocketcandDoor(bus::PacedRunner& runner, CanHub& hub, Options options)
    : m_runner(runner), m_hub(hub), m_opt(std::move(options)) {}

SocketcandDoor::~SocketcandDoor() { close(); }

std::string SocketcandDoor::open() {
  if (m_listener) return "socketcand door: already open";
  std::string err;
  const int fd = listen_tcp(m_opt.address, m_opt.port, m_port, err);
  if (fd < 0) {
    m_port = 0;
    return "socketcand door: " + err;
  }
  m_listener = std::make_unique<Listener>(m_runner.io_context(), fd);
  start_accept();
  return {};
}

void SocketcandDoor::close() {
  const Stats now = stats();
  for (auto& [key, l] : m_links) {
    m_hub.remove_port(l->port);
    l->closed = true;
    boost::system::error_code ec;
    l->hold_timer.cancel();
    l->sd.cancel(ec);
    l->sd.close(ec);
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
  if (m_listener) s.clients_total = m_closed.clients_total + m_listener->accepted;
  return s;
}

void SocketcandDoor::start_accept() {
  std::weak_ptr<bool> alive = m_alive;
  m_listener->sd.async_wait(Descriptor::wait_read,
                            [this, alive](const boost::system::error_code& ec) {
    if (ec || alive.expired() || !m_listener) return;
    for (;;) {
      const int fd = ::accept4(m_listener->sd.native_handle(), nullptr, nullptr,
                               SOCK_NONBLOCK | SOCK_CLOEXEC);
      if (fd < 0) {
        if (errno == EINTR || errno == ECONNABORTED) continue;
        break;  // EAGAIN: no more; EMFILE & co.: try again on the next readiness
      }
      const int one = 1;
      ::setsockopt(fd, IPPROTO_TCP, TCP_NODELAY, &one, sizeof one);
      const int sndbuf = kKernelSendBuffer;
      ::setsockopt(fd, SOL_SOCKET, SO_SNDBUF, &sndbuf, sizeof sndbuf);
      ++m_listener->accepted;
      auto l = std::make_shared<Link>(*this, m_runner.io_context(), fd, m_opt.channel);
      l->key = m_next_link++;
      std::weak_ptr<Link> w = l;
      l->port = m_hub.add_port(m_opt.name + ":" + std::to_string(m_listener->accepted),
                               [w](const CanFrame& f, bus::Ticks now) {
                                 if (auto p = w.lock()) p->door->on_hub_frame(*p, f, now);
                               });
      m_links.emplace(l->key, l);
      emit(*l, socketcand::SocketcandSession::greeting(), false);  // `< hi >`, alone
      start_read(l);
    }
    start_accept();
  });
}

void SocketcandDoor::start_read(const std::shared_ptr<Link>& link) {
  std::weak_ptr<Link> w = link;
  link->sd.async_wait(Descriptor::wait_read, [w](const boost::system::error_code& ec) {
    auto l = w.lock();
    if (!l || ec || l->closed) return;
    std::string bytes;
    bool gone = false;
    char buf[4096];
    while (bytes.size() < 64 * 1024) {  // at most 64 KiB per wake-up: no client holds the loop
      const ssize_t n = ::read(l->fd, buf, sizeof buf);
      if (n > 0) {
        bytes.append(buf, static_cast<std::size_t>(n));
        continue;
      }
      if (n < 0 && errno == EINTR) continue;
      if (n < 0 && (errno == EAGAIN || errno == EWOULDBLOCK)) break;
      gone = true;  // EOF or an error
      break;
    }
    bus::PacedRunner& runner = l->door->m_runner;
    if (!bytes.empty()) {
      runner.post([w, b = std::move(bytes)](bus::Ticks now) {
        if (auto p = w.lock(); p && !p->closed) p->door->on_bytes(*p, b, now);
      });
    }
    if (gone) {
      runner.post([w](bus::Ticks) {
        if (auto p = w.lock(); p && !p->closed) p->door->drop_link(*p);
      });
      return;
    }
    l->door->start_read(l);
  });
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
    std::weak_ptr<Link> w = l.weak_from_this();
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
  if (!l.write_armed) flush(l);
}

void SocketcandDoor::on_hub_frame(Link& l, const CanFrame& f, bus::Ticks now) {
  if (l.closed) return;
  if (auto text = l.session.frame_to_client(f, now)) emit(l, *text, true);
}

void SocketcandDoor::emit(Link& l, std::string_view s, bool frame) {
  if (l.out.size() + s.size() > m_opt.max_output) {
    ++l.dropped;
    return;
  }
  if (frame) ++l.frames_out;
  l.out.append(s);
  if (!l.write_armed && !l.holding) flush(l);
}

void SocketcandDoor::flush(Link& l) {
  std::size_t done = 0;
  bool broken = false;
  while (done < l.out.size()) {
    const ssize_t n =
        ::send(l.fd, l.out.data() + done, l.out.size() - done, MSG_NOSIGNAL | MSG_DONTWAIT);
    if (n > 0) {
      done += static_cast<std::size_t>(n);
      continue;
    }
    if (n < 0 && errno == EINTR) continue;
    if (n < 0 && (errno == EAGAIN || errno == EWOULDBLOCK)) break;
    broken = true;
    break;
  }
  l.out.erase(0, done);
  std::weak_ptr<Link> w = l.weak_from_this();
  if (broken) {
    l.out.clear();
    // Not from here (we may be inside the hub's delivery): close on the next turn.
    m_runner.post([w](bus::Ticks) {
      if (auto p = w.lock(); p && !p->closed) p->door->drop_link(*p);
    });
    return;
  }
  if (!l.out.empty() && !l.write_armed) {
    l.write_armed = true;
    l.sd.async_wait(Descriptor::wait_write, [w](const boost::system::error_code& ec) {
      auto p = w.lock();
      if (!p || ec || p->closed) return;
      p->write_armed = false;
      if (!p->holding) p->door->flush(*p);
    });
  }
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
  l.closed = true;
  boost::system::error_code ec;
  l.hold_timer.cancel();
  l.sd.cancel(ec);
  l.sd.close(ec);
  m_links.erase(it);
}

}  // namespace pbvbus::gateways
