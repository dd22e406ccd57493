#pragma once
// What the ISO-on-TCP door tests share: a door with a LocalCpuRouter (one CPU at rack 0 slot 2)
// on an io_context run by a thread of its own, and a blocking TCP client. Assertions on the CPU's
// memory run on the door's thread (on_io), the only thread that may touch it.
#include <arpa/inet.h>
#include <netinet/in.h>
#include <netinet/tcp.h>
#include <sys/socket.h>
#include <sys/time.h>
#include <unistd.h>

#include <boost/asio/executor_work_guard.hpp>
#include <boost/asio/io_context.hpp>
#include <boost/asio/post.hpp>
#include <cerrno>
#include <cstdint>
#include <functional>
#include <future>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include "pbvbus/iso_on_tcp/iso_door.hpp"
#include "pbvbus/iso_on_tcp/local_cpu_router.hpp"

namespace pbvbus::iso_on_tcp::test {

using Bytes = std::vector<std::uint8_t>;

/// A door on an ephemeral loopback port, its io_context on a thread, one CPU at rack 0 slot 2
/// (AmQ 1/1, PDU 240, as the §3.4 exchange) with DB1 of 64 octets.
class DoorFixture {
 public:
  /// `route_via` (built on this->router by the caller, e.g. a wrapper) replaces the router the
  /// door sees; the default is `router` itself.
  explicit DoorFixture(
      IsoDoorOptions opt = {}, s7::SetupCommunication limits = {1, 1, 240},
      std::function<S7Router&(LocalCpuRouter&, boost::asio::io_context&)> route_via = {}) {
    memory.create_db(1, 64);
    LocalCpu cpu;
    cpu.rack = 0;
    cpu.slot = 2;
    cpu.memory = &memory;
    cpu.info = &info;
    cpu.limits = limits;
    router.add(cpu);
    opt.address = "127.0.0.1";
    opt.port = 0;
    if (!opt.log) opt.log = [this](const std::string& l) { log.push_back(l); };
    door = std::make_unique<IsoOnTcpDoor>(io, route_via ? route_via(router, io) : router,
                                          std::move(opt));
    port = door->port();
    thread = std::thread([this] { io.run(); });
  }
  ~DoorFixture() {
    on_io([this] { door.reset(); });
    work.reset();
    io.stop();
    thread.join();
  }
  /// Runs `fn` on the door's thread and waits for it.
  template <class F>
  auto on_io(F fn) -> decltype(fn()) {
    std::packaged_task<decltype(fn())()> task(std::move(fn));
    auto f = task.get_future();
    boost::asio::post(io, [&task] { task(); });
    return f.get();
  }
  IsoDoorStats stats() {
    return on_io([this] { return door->stats(); });
  }

  s7cpu::CpuMemory memory;
  s7cpu::CpuInfo info;
  LocalCpuRouter router;
  std::vector<std::string> log;  // written on the door's thread; read through on_io
  boost::asio::io_context io;
  boost::asio::executor_work_guard<boost::asio::io_context::executor_type> work =
      boost::asio::make_work_guard(io);
  std::unique_ptr<IsoOnTcpDoor> door;
  std::uint16_t port = 0;
  std::thread thread;
};

/// A blocking loopback client. Reads give up after 20 s so that a broken door fails the test
/// instead of hanging it (never reached when the door works; nothing is timed).
class Client {
 public:
  explicit Client(std::uint16_t port) {
    fd_ = ::socket(AF_INET, SOCK_STREAM | SOCK_CLOEXEC, 0);
    sockaddr_in sa{};
    sa.sin_family = AF_INET;
    sa.sin_port = htons(port);
    sa.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    timeval tv{20, 0};
    ::setsockopt(fd_, SOL_SOCKET, SO_RCVTIMEO, &tv, sizeof tv);
    ::setsockopt(fd_, SOL_SOCKET, SO_SNDTIMEO, &tv, sizeof tv);
    const int one = 1;
    ::setsockopt(fd_, IPPROTO_TCP, TCP_NODELAY, &one, sizeof one);
    connected_ = ::connect(fd_, reinterpret_cast<sockaddr*>(&sa), sizeof sa) == 0;
  }
  ~Client() {
    if (fd_ >= 0) ::close(fd_);
  }
  Client(const Client&) = delete;
  Client& operator=(const Client&) = delete;

  bool connected() const { return connected_; }
  int fd() const { return fd_; }
  bool send(const Bytes& b) {
    std::size_t done = 0;
    while (done < b.size()) {
      const ssize_t n = ::send(fd_, b.data() + done, b.size() - done, MSG_NOSIGNAL);
      if (n <= 0) return false;
      done += static_cast<std::size_t>(n);
    }
    return true;
  }
  /// Exactly n octets, or fewer if the door closed (or the 20 s guard ran out).
  Bytes recv(std::size_t n) {
    Bytes b(n);
    std::size_t got = 0;
    while (got < n) {
      const ssize_t r = ::recv(fd_, b.data() + got, n - got, 0);
      if (r < 0 && errno == EINTR) continue;
      if (r <= 0) break;
      got += static_cast<std::size_t>(r);
    }
    b.resize(got);
    return b;
  }
  /// One whole TPKT (empty if the door closed first).
  Bytes recv_tpkt() {
    Bytes h = recv(4);
    if (h.size() < 4) return {};
    const std::size_t len = (std::size_t{h[2]} << 8) | h[3];
    if (len < 4) return h;
    Bytes rest = recv(len - 4);
    h.insert(h.end(), rest.begin(), rest.end());
    return h;
  }
  /// True when the door has closed the connection (EOF or reset), after reading and dropping
  /// whatever it sent before.
  bool closed_by_door() {
    std::uint8_t buf[4096];
    for (;;) {
      const ssize_t r = ::recv(fd_, buf, sizeof buf, 0);
      if (r > 0) continue;
      if (r < 0 && errno == EINTR) continue;
      return r == 0 || (r < 0 && (errno == ECONNRESET || errno == EPIPE));
    }
  }
  void shutdown_write() { ::shutdown(fd_, SHUT_WR); }

 private:
  int fd_ = -1;
  bool connected_ = false;
};

// Hand-worked octets (tools-and-formats.md §3.4, protocol-facts.md §H.4).

/// CR to rack 0 slot 2: TPDU size 2^10, calling TSAP 01 00 (PG), called 01 02.
inline const Bytes kCr = {0x03, 0x00, 0x00, 0x16, 0x11, 0xE0, 0x00, 0x00, 0x00, 0x01, 0x00,
                          0xC0, 0x01, 0x0A, 0xC1, 0x02, 0x01, 0x00, 0xC2, 0x02, 0x01, 0x02};
/// The CC of connection 1 (the door's reference 00 01): the CR's three parameters echoed.
inline const Bytes kCc = {0x03, 0x00, 0x00, 0x16, 0x11, 0xD0, 0x00, 0x01, 0x00, 0x01, 0x00,
                          0xC0, 0x01, 0x0A, 0xC1, 0x02, 0x01, 0x00, 0xC2, 0x02, 0x01, 0x02};
/// Setup Communication: AmQ 1/1, PDU 480; the CPU (PDU 240) answers 240.
inline const Bytes kSetupReq = {0x03, 0x00, 0x00, 0x19, 0x02, 0xF0, 0x80, 0x32, 0x01,
                                0x00, 0x00, 0x00, 0x00, 0x00, 0x08, 0x00, 0x00, 0xF0,
                                0x00, 0x00, 0x01, 0x00, 0x01, 0x01, 0xE0};
inline const Bytes kSetupResp = {0x03, 0x00, 0x00, 0x1B, 0x02, 0xF0, 0x80, 0x32, 0x03,
                                 0x00, 0x00, 0x00, 0x00, 0x00, 0x08, 0x00, 0x00, 0x00,
                                 0x00, 0xF0, 0x00, 0x00, 0x01, 0x00, 0x01, 0x00, 0xF0};

/// TPKT + DT around an S7 PDU.
inline Bytes tpkt_dt(const Bytes& pdu) {
  const std::size_t len = 7 + pdu.size();
  Bytes b = {0x03, 0x00, static_cast<std::uint8_t>(len >> 8), static_cast<std::uint8_t>(len), 0x02,
             0xF0, 0x80};
  b.insert(b.end(), pdu.begin(), pdu.end());
  return b;
}

/// Read Var of DB1.DBB0, `count` bytes, PDU reference `ref` (the layout of §H.4's example).
inline Bytes read_db1(std::uint16_t ref, std::uint8_t count) {
  const auto hi = static_cast<std::uint8_t>(ref >> 8);
  const auto lo = static_cast<std::uint8_t>(ref);
  return tpkt_dt({0x32, 0x01, 0x00, 0x00, hi,   lo,    0x00, 0x0E, 0x00, 0x00, 0x04, 0x01,
                  0x12, 0x0A, 0x10, 0x02, 0x00, count, 0x00, 0x01, 0x84, 0x00, 0x00, 0x00});
}

/// §H.4's example: DB1.DBB0, 10 bytes.
inline Bytes read_db1_10(std::uint16_t ref = 1) {
  return read_db1(ref, 10);
}

/// kCc with the door's reference of another connection (octets 8..9).
inline Bytes cc_with_ref(std::uint16_t ref) {
  Bytes cc = kCc;
  cc[8] = static_cast<std::uint8_t>(ref >> 8);
  cc[9] = static_cast<std::uint8_t>(ref);
  return cc;
}

/// CR, CC (whatever the door's reference) and Setup Communication on a fresh client.
inline bool open_s7(Client& c) {
  if (!c.send(kCr)) return false;
  const Bytes cc = c.recv_tpkt();
  if (cc.size() != kCc.size() ||
      cc != cc_with_ref(static_cast<std::uint16_t>((cc[8] << 8) | cc[9])))
    return false;
  return c.send(kSetupReq) && c.recv_tpkt() == kSetupResp;
}

}  // namespace pbvbus::iso_on_tcp::test
