#include "door_stream.hpp"

#include <arpa/inet.h>
#include <netinet/in.h>
#include <netinet/tcp.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>

#include "pbvbus/bus/paced_runner.hpp"

namespace pbvbus::gateways::door_stream {

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
  if (::bind(fd, reinterpret_cast<sockaddr*>(&sa), sizeof sa) != 0 || ::listen(fd, tcp_accept::kListenBacklog) != 0) {
    err = errno_text("listen on " + address + ":" + std::to_string(port));
    ::close(fd);
    return -1;
  }
  socklen_t len = sizeof sa;
  ::getsockname(fd, reinterpret_cast<sockaddr*>(&sa), &len);
  bound = ntohs(sa.sin_port);
  return fd;
}

TcpListener::TcpListener(boost::asio::io_context& io, int fd, std::string who, DoorLog log,
                         OnAccept on_accept)
    : m_sd(io, fd), m_on_accept(std::move(on_accept)), m_backoff(io, std::move(who), std::move(log)) {
  start_accept();
}

void TcpListener::start_accept() {
  std::weak_ptr<bool> alive = m_alive;
  m_sd.async_wait(Descriptor::wait_read, [this, alive](const boost::system::error_code& ec) {
    if (ec || alive.expired()) return;
    for (;;) {
      const int fd = ::accept4(m_sd.native_handle(), nullptr, nullptr,
                               SOCK_NONBLOCK | SOCK_CLOEXEC);
      if (fd < 0) {
        if (errno == EINTR || errno == ECONNABORTED) continue;
        if (errno == EAGAIN || errno == EWOULDBLOCK) break;
        // EMFILE & co.: the connection stays pending and the listener readable; waiting for
        // readability again would spin. Pause, then try again (tcp_accept.hpp).
        m_backoff.failed(errno, [this] { start_accept(); });
        return;
      }
      m_backoff.succeeded();
      const int one = 1;
      ::setsockopt(fd, IPPROTO_TCP, TCP_NODELAY, &one, sizeof one);
      tcp_accept::cap_send_buffer(fd);
      const bool taken = m_on_accept(fd, m_accepted + 1);
      if (alive.expired()) return;  // the door closed from inside on_accept
      if (taken) {
        ++m_accepted;
      } else {
        ::close(fd);  // refused (the door's client limit): the client sees EOF at once
        ++m_refused;
      }
    }
    start_accept();
  });
}

void start_read(const std::shared_ptr<Stream>& stream, bus::PacedRunner& runner) {
  std::weak_ptr<Stream> w = stream;
  stream->sd.async_wait(Descriptor::wait_read, [w, &runner](const boost::system::error_code& ec) {
    auto s = w.lock();
    if (!s || ec || s->closed) return;
    std::string bytes;
    bool gone = false;
    char buf[4096];
    // Read what is there, but at most 64 KiB per wake-up, so one flooding client cannot hold
    // the loop (the rest stays readable for the next turn).
    while (bytes.size() < kMaxReadPerWake) {
      const ssize_t n = ::read(s->fd, buf, sizeof buf);
      if (n > 0) {
        bytes.append(buf, static_cast<std::size_t>(n));
        continue;
      }
      if (n < 0 && errno == EINTR) continue;
      if (n < 0 && (errno == EAGAIN || errno == EWOULDBLOCK)) break;
      gone = true;  // EOF or an error: the peer is gone (a pty cannot get here: the door holds it)
      break;
    }
    if (!bytes.empty()) {
      runner.post([w, b = std::move(bytes)](bus::Ticks now) {
        if (auto p = w.lock(); p && !p->closed) p->received(b, now);
      });
    }
    if (gone) {
      runner.post([w](bus::Ticks) {
        if (auto p = w.lock(); p && !p->closed) p->gone();
      });
      return;
    }
    start_read(s, runner);
  });
}

bool queue(Stream& s, std::string_view text, std::size_t max_output, bus::PacedRunner& runner) {
  if (s.out.size() + text.size() > max_output) {
    ++s.dropped;
    return false;
  }
  s.out.append(text);
  if (!s.write_armed && s.may_write()) flush(s, runner);
  return true;
}

void flush(Stream& s, bus::PacedRunner& runner) {
  std::size_t done = 0;
  bool broken = false;
  while (done < s.out.size()) {
    const ssize_t n = s.is_socket ? ::send(s.fd, s.out.data() + done, s.out.size() - done,
                                           MSG_NOSIGNAL | MSG_DONTWAIT)
                                  : ::write(s.fd, s.out.data() + done, s.out.size() - done);
    if (n > 0) {
      done += static_cast<std::size_t>(n);
      continue;
    }
    if (n < 0 && errno == EINTR) continue;
    if (n < 0 && (errno == EAGAIN || errno == EWOULDBLOCK)) break;
    broken = true;
    break;
  }
  s.out.erase(0, done);
  std::weak_ptr<Stream> w = s.weak_from_this();
  if (broken) {
    s.out.clear();
    if (s.is_socket) {
      // Not from here (we may be inside the hub's delivery): close on the next turn.
      runner.post([w](bus::Ticks) {
        if (auto p = w.lock(); p && !p->closed) p->gone();
      });
    }
    return;
  }
  if (!s.out.empty() && !s.write_armed) {
    s.write_armed = true;
    s.sd.async_wait(Descriptor::wait_write, [w, &runner](const boost::system::error_code& ec) {
      auto p = w.lock();
      if (!p || ec || p->closed) return;
      p->write_armed = false;
      if (p->may_write()) flush(*p, runner);
    });
  }
}

void close(Stream& s) {
  s.closed = true;
  boost::system::error_code ec;
  s.sd.cancel(ec);
  s.sd.close(ec);
}

}  // namespace pbvbus::gateways::door_stream
