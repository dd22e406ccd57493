// SlcanDoor (slcan_door.hpp): a raw client (a thread with a TCP socket or the pty opened like a
// serial port) against the door, driven by Scheduler + PacedRunner::run_for on the test thread.
// Expected bytes are the Lawicel replies written out by hand (tools-and-formats.md §2.2).
#include "pbvbus/gateways/slcan_door.hpp"

#include <fcntl.h>
#include <poll.h>
#include <unistd.h>

#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <string>
#include <thread>
#include <vector>

#include "can_door_test_support.hpp"

namespace pbvbus::gateways {
namespace {

using namespace std::chrono_literals;
using namespace can_test;  // frame(), connect_tcp, write_all, read_n, Rig

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
  can_test::StalledClient client(door.port(), "O\r");  // a small receive window, never read
  EXPECT_TRUE(rig.run_until([&] { return door.stats().lines == 1; }));
  // 100 000 frames of 8 bytes, 22 characters per line: 2.2 MB, yet all 100 bursts run on time.
  can_test::expect_flood_absorbed(rig, door);
  client.release();
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
