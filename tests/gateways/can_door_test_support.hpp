#pragma once
// What the CAN door tests share: the frame() builder, a raw TCP client's helpers (connect,
// write everything, read n octets within a generous wall-clock bound) and the Rig: a Scheduler +
// PacedRunner driven on the test thread, a CanHub and the test's own recording port.
// Wall-clock waits here are only upper bounds for a client to finish, never assertions.
#include <arpa/inet.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <chrono>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <string>
#include <thread>
#include <vector>

#include "pbvbus/bus/paced_runner.hpp"
#include "pbvbus/bus/scheduler.hpp"
#include "pbvbus/gateways/can_frame.hpp"

namespace pbvbus::gateways::can_test {

/// A frame with `data.size()` as its DLC.
inline CanFrame frame(std::uint32_t id, bool ext, std::vector<std::uint8_t> data) {
  CanFrame f;
  f.id = id;
  f.extended = ext;
  f.dlc = static_cast<std::uint8_t>(data.size());
  for (std::size_t i = 0; i < data.size(); ++i) f.data[i] = data[i];
  return f;
}

/// A blocking loopback TCP connection to `port` (with SO_RCVBUF `rcvbuf` if > 0), -1 if refused.
inline int connect_tcp(std::uint16_t port, int rcvbuf = 0) {
  const int fd = ::socket(AF_INET, SOCK_STREAM | SOCK_CLOEXEC, 0);
  if (rcvbuf > 0) ::setsockopt(fd, SOL_SOCKET, SO_RCVBUF, &rcvbuf, sizeof rcvbuf);
  sockaddr_in sa{};
  sa.sin_family = AF_INET;
  sa.sin_port = htons(port);
  sa.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  if (::connect(fd, reinterpret_cast<sockaddr*>(&sa), sizeof sa) != 0) {
    ::close(fd);
    return -1;
  }
  return fd;
}

/// Writes all of `s` (stops at an error). A socket is written with MSG_NOSIGNAL, so a door that
/// closed the connection gives an error, not SIGPIPE; a pty (ENOTSOCK) with write().
inline void write_all(int fd, const std::string& s) {
  std::size_t done = 0;
  while (done < s.size()) {
    ssize_t n = ::send(fd, s.data() + done, s.size() - done, MSG_NOSIGNAL);
    if (n < 0 && errno == ENOTSOCK) n = ::write(fd, s.data() + done, s.size() - done);
    if (n <= 0) return;
    done += static_cast<std::size_t>(n);
  }
}

/// Reads until `want` octets arrived, EOF (then *eof = true) or a generous bound (10 s).
inline std::string read_n(int fd, std::size_t want, bool* eof = nullptr) {
  using namespace std::chrono_literals;
  std::string got;
  const auto end = std::chrono::steady_clock::now() + 10s;
  while (got.size() < want && std::chrono::steady_clock::now() < end) {
    pollfd p{fd, POLLIN, 0};
    if (::poll(&p, 1, 50) <= 0) continue;
    char buf[512];
    const ssize_t n = ::read(fd, buf, std::min(sizeof buf, want - got.size()));
    if (n <= 0) {
      if (eof) *eof = true;
      break;
    }
    got.append(buf, static_cast<std::size_t>(n));
  }
  return got;
}

/// The bus on the test thread: Scheduler + PacedRunner, the hub, and the test's port `me`, which
/// records every frame in `seen` and then calls `on_frame` if set.
struct Rig {
  bus::Scheduler sched;
  bus::PacedRunner runner{sched};
  CanHub hub;
  std::vector<CanFrame> seen;  // what the test's own port received
  std::function<void(const CanFrame&, bus::Ticks)> on_frame;
  CanHub::PortId me = hub.add_port("test", [this](const CanFrame& f, bus::Ticks now) {
    seen.push_back(f);
    if (on_frame) on_frame(f, now);
  });

  /// Runs the bus in 2 ms steps until `done` (checked between steps) or a generous wall bound.
  bool run_until(const std::function<bool()>& done,
                 std::chrono::seconds limit = std::chrono::seconds(10)) {
    const auto end = std::chrono::steady_clock::now() + limit;
    while (!done()) {
      if (std::chrono::steady_clock::now() > end) return false;
      runner.run_for(2 * bus::kTicksPerMs);
    }
    return true;
  }

  /// Sends `f` from the test port `per_event` times in each of `events` scheduler events, 1 ms
  /// apart from now + 1 ms, and runs the bus for `events` ms of virtual time. Returns how many
  /// of the events ran (all of them, on time, unless something delayed the bus).
  int flood(const CanFrame& f, int events, int per_event) {
    int ticks = 0;
    std::function<void()> burst = [&] {
      ++ticks;
      for (int i = 0; i < per_event; ++i) hub.send(me, f, sched.now());
      if (ticks < events) sched.schedule(sched.now() + bus::kTicksPerMs, burst);
    };
    sched.schedule(sched.now() + bus::kTicksPerMs, burst);
    runner.run_for(events * bus::kTicksPerMs);
    return ticks;
  }
};

/// With a client that never reads connected to `door`: 100 events, 1 ms apart, each sending
/// 1000 frames of 8 bytes — 100 000 frames, far beyond the 64 KiB queue and the socket buffers.
/// Every burst must run on time (virtual 100 ms later, all 100 ran) and the door must account
/// for every frame: queued to the client or dropped, and some dropped.
template <class Door>
void expect_flood_absorbed(Rig& rig, const Door& door) {
  const bus::Ticks t0 = rig.sched.now();
  EXPECT_EQ(rig.flood(frame(0x123, false, {1, 2, 3, 4, 5, 6, 7, 8}), 100, 1000), 100);
  EXPECT_EQ(rig.sched.now(), t0 + 100 * bus::kTicksPerMs);
  const auto s = door.stats();
  EXPECT_EQ(s.frames_out + s.dropped, 100'000u);
  EXPECT_GT(s.dropped, 0u);
}

/// A client thread that connects with a small receive window (4 KiB), writes `hello` and then
/// never reads until release() (which closes and joins).
class StalledClient {
 public:
  StalledClient(std::uint16_t port, std::string hello)
      : m_thread([this, port, h = std::move(hello)] {
          const int fd = connect_tcp(port, 4096);
          if (fd < 0) return;
          write_all(fd, h);
          while (!m_release) std::this_thread::sleep_for(std::chrono::milliseconds(5));
          ::close(fd);
        }) {}
  ~StalledClient() { release(); }
  void release() {
    m_release = true;
    if (m_thread.joinable()) m_thread.join();
  }

 private:
  std::atomic<bool> m_release{false};
  std::thread m_thread;
};

}  // namespace pbvbus::gateways::can_test
