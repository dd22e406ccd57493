#include "pbvbus/gateways/slcan_door.hpp"

#include <arpa/inet.h>
#include <fcntl.h>
#include <netinet/in.h>
#include <netinet/tcp.h>
#include <sys/socket.h>
#include <termios.h>
#include <unistd.h>

#include <boost/asio/io_context.hpp>
#include <boost/asio/posix/stream_descriptor.hpp>
#include <cerrno>
#include <cstring>
#include <vector>

#include "pbvbus/bus/paced_runner.hpp"

namespace pbvbus::gateways {

namespace {

using Descriptor = boost::asio::posix::stream_descriptor;

/// SO_SNDBUF of accepted connections (the kernel doubles it for its bookkeeping).
constexpr int kKernelSendBuffer = 32 * 1024;

std::string errno_text(const char* what) { return std::string(what) + ": " + std::strerror(errno); }

/// A non-blocking TCP listener on address:port. Returns the fd or -1 with `err` set.
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
    err = errno_text(("listen on " + address + ":" + std::to_string(port)).c_str());
    ::close(fd);
    return -1;
  }
  socklen_t len = sizeof sa;
  ::getsockname(fd, reinterpret_cast<sockaddr*>(&sa), &len);
  bound = ntohs(sa.sin_port);
  return fd;
}

}  // namespace

struct SlcanDoor::Link : std::enable_shared_from_this<SlcanDoor::Link> {
  Link(SlcanDoor& d, boost::asio::io_context& io, int fd_, bool sock, std::string serial)
      : door(&d), fd(fd_), is_socket(sock), sd(io, fd_), session(std::move(serial)) {}
  SlcanDoor* door;
  int fd;
  bool is_socket;
  Descriptor sd;  // owns fd
  slcan::SlcanSession session;
  std::uint64_t key = 0;
  CanHub::PortId port = 0;
  std::string out;
  bool write_armed = false;
  bool closed = false;
  std::uint64_t frames_out = 0;
  std::uint64_t dropped = 0;
};

struct SlcanDoor::Listener {
  Listener(boost::asio::io_context& io, int fd) : sd(io, fd) {}
  Descriptor sd;
  std::uint64_t accepted = 0;
};

SlcanDoor::SlcanDoor(bus::PacedRunner& runner, CanHub& hub, Options options)
    : m_runner(runner), m_hub(hub), m_opt(std::move(options)) {}

SlcanDoor::~SlcanDoor() { close(); }

std::string SlcanDoor::open() {
  if (!m_links.empty() || m_listener) return "slcan door: already open";
  if (m_opt.pty) {
    const int master = ::posix_openpt(O_RDWR | O_NOCTTY | O_CLOEXEC);
    if (master < 0) return errno_text("posix_openpt");
    char name[128];
    if (::grantpt(master) != 0 || ::unlockpt(master) != 0 ||
        ::ptsname_r(master, name, sizeof name) != 0) {
      const std::string e = errno_text("pty setup");
      ::close(master);
      return e;
    }
    // Keep the slave side open ourselves (no EIO while no client holds it) and make it raw:
    // no echo, no CR/LF mapping — SLCAN lines end in '\r'.
    m_pty_slave = ::open(name, O_RDWR | O_NOCTTY | O_CLOEXEC | O_NONBLOCK);
    termios tio{};
    if (m_pty_slave < 0 || ::tcgetattr(m_pty_slave, &tio) != 0) {
      const std::string e = errno_text("open pty slave");
      if (m_pty_slave >= 0) ::close(m_pty_slave);
      m_pty_slave = -1;
      ::close(master);
      return e;
    }
    ::cfmakeraw(&tio);
    ::tcsetattr(m_pty_slave, TCSANOW, &tio);
    const int fl = ::fcntl(master, F_GETFL);
    ::fcntl(master, F_SETFL, fl | O_NONBLOCK);
    m_pty_path = name;
    if (!m_opt.pty_link.empty()) {
      ::unlink(m_opt.pty_link.c_str());
      if (::symlink(name, m_opt.pty_link.c_str()) != 0) {
        const std::string e = errno_text(("symlink " + m_opt.pty_link).c_str());
        ::close(master);
        close();
        return e;
      }
    }
    start_read(add_link(master, false, m_opt.name + ":pty"));
  }
  if (m_opt.tcp) {
    std::string err;
    const int fd = listen_tcp(m_opt.tcp_address, m_opt.tcp_port, m_port, err);
    if (fd < 0) {
      close();
      return "slcan door: " + err;
    }
    m_listener = std::make_unique<Listener>(m_runner.io_context(), fd);
    start_accept();
  }
  return {};
}

void SlcanDoor::close() {
  for (auto& [key, l] : m_links) {
    m_hub.remove_port(l->port);
    l->closed = true;
    boost::system::error_code ec;
    l->sd.cancel(ec);
    l->sd.close(ec);
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
  if (m_listener) s.clients_total = m_closed.clients_total + m_listener->accepted;
  // The pty is one client for as long as the door has it (the report said "0 clients (1 now)").
  if (m_pty_slave >= 0) ++s.clients_total;
  return s;
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

void SlcanDoor::start_read(const std::shared_ptr<Link>& link) {
  std::weak_ptr<Link> w = link;
  link->sd.async_wait(Descriptor::wait_read, [w](const boost::system::error_code& ec) {
    auto l = w.lock();
    if (!l || ec || l->closed) return;
    std::string bytes;
    bool gone = false;
    char buf[4096];
    // Read what is there, but at most 64 KiB per wake-up, so one flooding client cannot hold
    // the loop (the rest stays readable for the next turn).
    while (bytes.size() < 64 * 1024) {
      const ssize_t n = ::read(l->fd, buf, sizeof buf);
      if (n > 0) {
        bytes.append(buf, static_cast<std::size_t>(n));
        continue;
      }
      if (n < 0 && errno == EINTR) continue;
      if (n < 0 && (errno == EAGAIN || errno == EWOULDBLOCK)) break;
      gone = true;  // EOF or an error: the peer is gone (a pty cannot get here: we hold it)
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
  if (l.out.size() + s.size() > m_opt.max_output) {
    ++l.dropped;
    if (frame) l.session.note_overrun();
    return;
  }
  if (frame) ++l.frames_out;
  l.out.append(s);
  if (!l.write_armed) flush(l);
}

void SlcanDoor::flush(Link& l) {
  std::size_t done = 0;
  bool broken = false;
  while (done < l.out.size()) {
    const ssize_t n = l.is_socket ? ::send(l.fd, l.out.data() + done, l.out.size() - done,
                                           MSG_NOSIGNAL | MSG_DONTWAIT)
                                  : ::write(l.fd, l.out.data() + done, l.out.size() - done);
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
  if (broken) {
    l.out.clear();
    if (l.is_socket) {
      // Not from here (we may be inside the hub's delivery): close on the next turn.
      std::weak_ptr<Link> w = l.weak_from_this();
      m_runner.post([w](bus::Ticks) {
        if (auto p = w.lock(); p && !p->closed) p->door->drop_link(*p);
      });
    }
    return;
  }
  if (!l.out.empty() && !l.write_armed) {
    l.write_armed = true;
    std::weak_ptr<Link> w = l.weak_from_this();
    l.sd.async_wait(Descriptor::wait_write, [w](const boost::system::error_code& ec) {
      auto p = w.lock();
      if (!p || ec || p->closed) return;
      p->write_armed = false;
      p->door->flush(*p);
    });
  }
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
  l.closed = true;
  boost::system::error_code ec;
  l.sd.cancel(ec);
  l.sd.close(ec);
  m_links.erase(it);
}

void SlcanDoor::start_accept() {
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
      // A fixed kernel send buffer: autotuned, Linux lets a stalled loopback client hoard
      // megabytes of stale frames before the door's own bound (and drop count) applies.
      const int sndbuf = kKernelSendBuffer;
      ::setsockopt(fd, SOL_SOCKET, SO_SNDBUF, &sndbuf, sizeof sndbuf);
      ++m_listener->accepted;
      start_read(add_link(fd, true, m_opt.name + ":tcp:" + std::to_string(m_listener->accepted)));
    }
    start_accept();
  });
}

}  // namespace pbvbus::gateways
