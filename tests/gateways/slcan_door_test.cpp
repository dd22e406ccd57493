// SlcanDoor (slcan_door.hpp): a raw client (a thread with a TCP socket or the pty opened like a
// serial port) against the door, driven by Scheduler + PacedRunner::run_for on the test thread.
// Expected bytes are the Lawicel replies written out by hand (tools-and-formats.md §2.2).
#include "pbvbus/gateways/slcan_door.hpp"

#include <arpa/inet.h>
#include <fcntl.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <functional>
#include <string>
#include <thread>
#include <vector>

#include "pbvbus/bus/paced_runner.hpp"
#include "pbvbus/bus/scheduler.hpp"

namespace pbvbus::gateways {
namespace {

using namespace std::chrono_literals;

int connect_tcp(std::uint16_t port, int rcvbuf = 0) {
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

void write_all(int fd, const std::string& s) {
  std::size_t done = 0;
  while (done < s.size()) {
    const ssize_t n = ::write(fd, s.data() + done, s.size() - done);
    if (n <= 0) return;
    done += static_cast<std::size_t>(n);
  }
}

/// Reads until `want` bytes arrived or `limit` (a generous upper bound) passed.
std::string read_n(int fd, std::size_t want, std::chrono::milliseconds limit = 10s) {
  std::string got;
  const auto end = std::chrono::steady_clock::now() + limit;
  while (got.size() < want && std::chrono::steady_clock::now() < end) {
    pollfd p{fd, POLLIN, 0};
    if (::poll(&p, 1, 50) <= 0) continue;
    char buf[512];
    const ssize_t n = ::read(fd, buf, std::min(sizeof buf, want - got.size()));
    if (n <= 0) break;
    got.append(buf, static_cast<std::size_t>(n));
  }
  return got;
}

struct Rig {
  bus::Scheduler sched;
  bus::PacedRunner runner{sched};
  CanHub hub;
  std::vector<CanFrame> seen;  // what the test's own port received
  CanHub::PortId me = hub.add_port("test", [this](const CanFrame& f, bus::Ticks) { seen.push_back(f); });

  /// Runs the bus in 2 ms steps until `done` (checked between steps) or a generous wall bound.
  bool run_until(const std::function<bool()>& done, std::chrono::seconds limit = 10s) {
    const auto end = std::chrono::steady_clock::now() + limit;
    while (!done()) {
      if (std::chrono::steady_clock::now() > end) return false;
      runner.run_for(2 * bus::kTicksPerMs);
    }
    return true;
  }
};

SlcanDoor::Options tcp_only(std::uint16_t port = 0) {
  SlcanDoor::Options o;
  o.pty = false;
  o.tcp_port = port;
  return o;
}

SlcanDoor::Options pty_only(const std::string& link) {
  SlcanDoor::Options o;
  o.tcp = false;
  o.pty_link = link;
  return o;
}

CanFrame frame(std::uint32_t id, bool ext, std::vector<std::uint8_t> data) {
  CanFrame f;
  f.id = id;
  f.extended = ext;
  f.dlc = static_cast<std::uint8_t>(data.size());
  for (std::size_t i = 0; i < data.size(); ++i) f.data[i] = data[i];
  return f;
}

TEST(SlcanDoor, TcpClientOpensSendsAndReceives) {
  Rig rig;
  SlcanDoor door(rig.runner, rig.hub, tcp_only());
  ASSERT_EQ(door.open(), "");
  ASSERT_NE(door.port(), 0);
  std::string got;
  std::thread client([&] {
    const int fd = connect_tcp(door.port());
    if (fd < 0) return;
    write_all(fd, "C\rS6\rO\rO\rt2052AABB\r");
    // Replies: C, S6, O, O -> "\r" each (4 bytes); the send -> "z\r" (2); then the test's
    // frame 0x123 [42] -> "t123" "1" "42" "\r" (8). 4 + 2 + 8 = 14.
    got = read_n(fd, 14);
    ::close(fd);
  });
  EXPECT_TRUE(rig.run_until([&] { return !rig.seen.empty(); }));
  EXPECT_EQ(rig.seen, std::vector<CanFrame>{frame(0x205, false, {0xAA, 0xBB})});
  EXPECT_EQ(rig.hub.ports(), 2u);  // the test and the connection
  rig.hub.send(rig.me, frame(0x123, false, {0x42}), rig.sched.now());
  EXPECT_TRUE(rig.run_until([&] { return door.stats().clients == 0; }));  // the client hung up
  client.join();
  EXPECT_EQ(got, "\r\r\r\rz\rt123142\r");
  EXPECT_EQ(rig.hub.ports(), 1u);  // its port went with it
  const auto s = door.stats();
  EXPECT_EQ(s.clients_total, 1u);
  EXPECT_EQ(s.lines, 5u);
  EXPECT_EQ(s.frames_in, 1u);
  EXPECT_EQ(s.frames_out, 1u);
  EXPECT_EQ(s.errors, 0u);
}

TEST(SlcanDoor, PtyClientWithLinkTimestampsAndClosedChannel) {
  Rig rig;
  const std::string link = ::testing::TempDir() + "slcan_door_ttyCAN0";
  SlcanDoor door(rig.runner, rig.hub, pty_only(link));
  const std::string err = door.open();
  if (err.find("posix_openpt") != std::string::npos) GTEST_SKIP() << "no ptys here: " << err;
  ASSERT_EQ(err, "");
  ASSERT_FALSE(door.pty_path().empty());
  const int fd = ::open(link.c_str(), O_RDWR | O_NOCTTY | O_CLOEXEC);
  ASSERT_GE(fd, 0) << "the symlink must lead to the pty";
  // Closed: a frame from the bus is not sent; the host's frame is refused.
  rig.hub.send(rig.me, frame(0x181, false, {0x01}), rig.sched.now());
  write_all(fd, "t1811FF\rZ1\rO\r");
  EXPECT_TRUE(rig.run_until([&] { return door.stats().lines == 3; }));
  // Open with timestamps: a frame at virtual time T ends with %04X of (T in ms) mod 60000.
  bus::Ticks at = -1;
  rig.sched.schedule(rig.sched.now() + bus::kTicksPerMs, [&] {
    at = rig.sched.now();
    rig.hub.send(rig.me, frame(0x18FF0001, true, {0xAB}), at);
  });
  EXPECT_TRUE(rig.run_until([&] { return door.stats().frames_out == 1; }));
  char ts[8];
  std::snprintf(ts, sizeof ts, "%04X", static_cast<unsigned>((at / bus::kTicksPerMs) % 60000));
  // "\a" (refused send), "\r" (Z1), "\r" (O), then "T" "18FF0001" "1" "AB" ts "\r".
  const std::string want = std::string("\a\r\rT18FF00011AB") + ts + "\r";
  EXPECT_EQ(read_n(fd, want.size()), want);
  ::close(fd);
  EXPECT_EQ(door.stats().errors, 1u);
  EXPECT_EQ(door.stats().clients, 1u);  // the pty stays, whoever has it open
  door.close();
  EXPECT_NE(::access(link.c_str(), F_OK), 0) << "close() removes the link";
}

TEST(SlcanDoor, TooLongLineIsAnsweredWithBellAndCounted) {
  Rig rig;
  SlcanDoor door(rig.runner, rig.hub, tcp_only());
  ASSERT_EQ(door.open(), "");
  std::string got;
  std::thread client([&] {
    const int fd = connect_tcp(door.port());
    if (fd < 0) return;
    write_all(fd, std::string(100, 'A') + "\rV\r");
    got = read_n(fd, 7);  // "\a" + "V1013\r"
    ::close(fd);
  });
  EXPECT_TRUE(rig.run_until([&] { return door.stats().lines == 2; }));
  client.join();
  EXPECT_EQ(got, "\aV1013\r");
  EXPECT_EQ(door.stats().overlong, 1u);
  EXPECT_EQ(door.stats().errors, 1u);
}

TEST(SlcanDoor, ClientThatNeverReadsCannotStallTheBus) {
  Rig rig;
  SlcanDoor door(rig.runner, rig.hub, tcp_only());
  ASSERT_EQ(door.open(), "");
  std::atomic<bool> release{false};
  std::thread client([&] {
    const int fd = connect_tcp(door.port(), 4096);  // a small receive window, never read
    if (fd < 0) return;
    write_all(fd, "O\r");
    while (!release) std::this_thread::sleep_for(5ms);
    ::close(fd);
  });
  EXPECT_TRUE(rig.run_until([&] { return door.stats().lines == 1; }));
  // 100 events, 1 ms apart, each sending 1000 frames of 8 bytes (22 characters per line):
  // 100 000 frames, 2.2 MB, far beyond the 64 KiB queue and the socket buffers.
  int ticks = 0;
  const bus::Ticks t0 = rig.sched.now();
  const CanFrame f = frame(0x123, false, {1, 2, 3, 4, 5, 6, 7, 8});
  std::function<void()> burst = [&] {
    ++ticks;
    for (int i = 0; i < 1000; ++i) rig.hub.send(rig.me, f, rig.sched.now());
    if (ticks < 100) rig.sched.schedule(rig.sched.now() + bus::kTicksPerMs, burst);
  };
  rig.sched.schedule(t0 + bus::kTicksPerMs, burst);
  // Virtual 100 ms: all 100 bursts ran, on time, though the client reads nothing.
  rig.runner.run_for(100 * bus::kTicksPerMs);
  EXPECT_EQ(ticks, 100);
  EXPECT_EQ(rig.sched.now(), t0 + 100 * bus::kTicksPerMs);
  const auto s = door.stats();
  EXPECT_EQ(s.frames_out + s.dropped, 100'000u);
  EXPECT_GT(s.dropped, 0u);
  release = true;
  client.join();
}

TEST(SlcanDoor, TwoClientsHearEachOtherAndTheBus) {
  Rig rig;
  SlcanDoor door(rig.runner, rig.hub, tcp_only());
  ASSERT_EQ(door.open(), "");
  std::string a_got, b_got;
  std::atomic<int> opened{0};
  std::thread a([&] {
    const int fd = connect_tcp(door.port());
    write_all(fd, "O\r");
    a_got = read_n(fd, 1);  // "\r": the door has opened this channel
    ++opened;
    while (opened < 2) std::this_thread::sleep_for(1ms);
    write_all(fd, "t7000\r");
    a_got += read_n(fd, 2);  // "z\r" for the send
    ::close(fd);
  });
  std::thread b([&] {
    const int fd = connect_tcp(door.port());
    write_all(fd, "O\r");
    b_got = read_n(fd, 1);  // "\r" for O
    ++opened;
    b_got += read_n(fd, 6);  // A's frame "t7000\r"
    ::close(fd);
  });
  EXPECT_TRUE(rig.run_until([&] { return !rig.seen.empty(); }));
  a.join();
  b.join();
  EXPECT_EQ(a_got, "\rz\r");
  EXPECT_EQ(b_got, "\rt7000\r");
  EXPECT_EQ(rig.seen.at(0), frame(0x700, false, {}));
}

TEST(SlcanDoor, OpenReportsAPortInUseInsteadOfThrowing) {
  Rig rig;
  SlcanDoor first(rig.runner, rig.hub, tcp_only());
  ASSERT_EQ(first.open(), "");
  SlcanDoor second(rig.runner, rig.hub, tcp_only(first.port()));
  const std::string err = second.open();
  EXPECT_NE(err.find("listen on 127.0.0.1:"), std::string::npos) << err;
  EXPECT_EQ(second.port(), 0);
}

}  // namespace
}  // namespace pbvbus::gateways
