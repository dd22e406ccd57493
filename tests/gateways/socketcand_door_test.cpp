// SocketcandDoor (socketcand_door.hpp): a raw TCP client thread against the door, driven by
// Scheduler + PacedRunner::run_for on the test thread. Expected elements are written out by
// hand from socketcand's doc/protocol.md and python-can 4.1's client (tools-and-formats.md §2.3).
#include "pbvbus/gateways/socketcand_door.hpp"

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

/// One recv() of up to 256 bytes, as python-can reads `< hi >` and `< ok >` (waits up to a
/// generous bound for something to arrive).
std::string recv_once(int fd) {
  pollfd p{fd, POLLIN, 0};
  if (::poll(&p, 1, 10'000) <= 0) return "(nothing)";
  char buf[256];
  const ssize_t n = ::recv(fd, buf, sizeof buf, 0);
  return n > 0 ? std::string(buf, static_cast<std::size_t>(n)) : "(closed)";
}

SocketcandDoor::Options ephemeral(std::chrono::milliseconds hold = 100ms) {
  SocketcandDoor::Options o;
  o.port = 0;
  o.raw_hold = hold;
  return o;
}

TEST(SocketcandDoor, HandshakeSendAndRawFrames) {
  Rig rig;
  SocketcandDoor door(rig.runner, rig.hub, ephemeral());
  ASSERT_EQ(door.open(), "");
  ASSERT_NE(door.port(), 0);
  std::vector<std::string> got;
  std::thread client([&] {
    const int fd = connect_tcp(door.port());
    if (fd < 0) return;
    got.push_back(recv_once(fd));  // "< hi >"
    write_all(fd, "< open can0 >");
    got.push_back(recv_once(fd));  // "< ok >"
    write_all(fd, "< rawmode >");
    got.push_back(recv_once(fd));  // "< ok >"
    write_all(fd, "< send 205 2 aa bb >< send 18FF0001 1 7 >");
    // The test's frame at virtual time 23.424242 s: " < frame 123 23.424242 42 >" (27 bytes).
    got.push_back(read_n(fd, 27));
    ::close(fd);
  });
  EXPECT_TRUE(rig.run_until([&] { return rig.seen.size() == 2; }));
  EXPECT_EQ(rig.seen, (std::vector<CanFrame>{frame(0x205, false, {0xAA, 0xBB}),
                                              frame(0x18FF0001, true, {0x07})}));
  // 23.424242 s = 23 * 3 636 000 000 + 424 242 * 3636 ticks.
  rig.hub.send(rig.me, frame(0x123, false, {0x42}),
               23 * bus::kTicksPerSecond + 424'242 * bus::kTicksPerUs);
  EXPECT_TRUE(rig.run_until([&] { return door.stats().clients == 0; }));
  client.join();
  const std::vector<std::string> want{"< hi >", "< ok >", "< ok >",
                                      " < frame 123 23.424242 42 >"};
  EXPECT_EQ(got, want);
  const auto s = door.stats();
  EXPECT_EQ(s.clients_total, 1u);
  EXPECT_EQ(s.elements, 4u);
  EXPECT_EQ(s.frames_in, 2u);
  EXPECT_EQ(s.frames_out, 1u);
  EXPECT_EQ(s.errors, 0u);
  EXPECT_EQ(rig.hub.ports(), 1u);
}

TEST(SocketcandDoor, FramesWaitForRawModeAndThenForTheClientToReadItsOk) {
  Rig rig;
  // A hold far beyond the test's duration: only the client's next element releases the frame.
  SocketcandDoor door(rig.runner, rig.hub, ephemeral(60s));
  ASSERT_EQ(door.open(), "");
  std::vector<std::string> got;
  std::atomic<int> step{0};
  const auto wait_step = [&](int n) {  // bounded, so a failed test cannot hang the client
    const auto end = std::chrono::steady_clock::now() + 10s;
    while (step < n && std::chrono::steady_clock::now() < end) std::this_thread::sleep_for(1ms);
  };
  std::thread client([&] {
    const int fd = connect_tcp(door.port());
    got.push_back(recv_once(fd));
    write_all(fd, "< open can0 >");
    got.push_back(recv_once(fd));
    step = 1;  // BCM mode: the test now sends a frame, which must not come
    wait_step(2);
    write_all(fd, "< rawmode >");
    wait_step(3);                  // the test has queued a frame behind the `< ok >`
    got.push_back(recv_once(fd));  // still exactly "< ok >"
    write_all(fd, "< echo >");
    // " < frame 181 0.000000 01 >" (26) then "< echo >" (8).
    got.push_back(read_n(fd, 26 + 8));
    ::close(fd);
  });
  EXPECT_TRUE(rig.run_until([&] { return step == 1 && door.stats().elements == 1; }));
  rig.hub.send(rig.me, frame(0x181, false, {0x01}), 0);  // BCM mode: not sent
  step = 2;
  EXPECT_TRUE(rig.run_until([&] { return door.stats().elements == 2; }));
  rig.hub.send(rig.me, frame(0x181, false, {0x01}), 0);  // raw mode: held behind the `< ok >`
  rig.runner.run_for(5 * bus::kTicksPerMs);               // time to write it, were it not held
  step = 3;
  EXPECT_TRUE(rig.run_until([&] { return door.stats().clients == 0; }));
  client.join();
  const std::vector<std::string> want{"< hi >", "< ok >", "< ok >",
                                      " < frame 181 0.000000 01 >< echo >"};
  EXPECT_EQ(got, want);
  EXPECT_EQ(door.stats().frames_out, 1u);
}

TEST(SocketcandDoor, GarbageIsAnsweredThenRepeatedGarbageCloses) {
  Rig rig;
  SocketcandDoor door(rig.runner, rig.hub, ephemeral());
  ASSERT_EQ(door.open(), "");
  std::string first;
  bool eof = false;
  std::thread client([&] {
    const int fd = connect_tcp(door.port());
    recv_once(fd);  // "< hi >"
    write_all(fd, "hello\n");
    first = read_n(fd, 36);  // "< error garbage outside an element >", counted below
    // 8 errors in a row close: 1 so far; 7 unknown commands make 8.
    write_all(fd, "< a >< b >< c >< d >< e >< f >< g >");
    read_n(fd, 100'000, &eof);  // their 7 errors, then EOF
    ::close(fd);
  });
  EXPECT_TRUE(rig.run_until([&] { return door.stats().closed_bad == 1; }));
  client.join();
  // "< error " (8) + "garbage outside an element" (7+1+7+1+2+1+7 = 26) + " >" (2) = 36.
  EXPECT_EQ(first, "< error garbage outside an element >");
  EXPECT_TRUE(eof);
  EXPECT_EQ(door.stats().errors, 8u);
  EXPECT_EQ(door.stats().clients, 0u);
  EXPECT_EQ(rig.hub.ports(), 1u);
}

TEST(SocketcandDoor, EightErrorsInARowCloseEvenWhenTheyArriveInOneWrite) {
  // Everything in one write, so in one read of the door: a 10 000-character element (39 errors
  // by the 256-character rule) then `< echo >`. The client gets exactly 8 error answers, no
  // echo, then EOF.
  Rig rig;
  SocketcandDoor door(rig.runner, rig.hub, ephemeral());
  ASSERT_EQ(door.open(), "");
  std::string got;
  bool eof = false;
  std::thread client([&] {
    const int fd = connect_tcp(door.port());
    recv_once(fd);  // "< hi >"
    write_all(fd, "<" + std::string(10'000, 'x') + "> < echo >");
    got = read_n(fd, 100'000, &eof);
    ::close(fd);
  });
  EXPECT_TRUE(rig.run_until([&] { return door.stats().closed_bad == 1; }));
  client.join();
  std::string want;
  for (int i = 0; i < socketcand::kMaxConsecutiveErrors; ++i) want += "< error element too long >";
  EXPECT_EQ(got, want);
  EXPECT_TRUE(eof);
  EXPECT_EQ(door.stats().errors, 8u);
  EXPECT_EQ(door.stats().clients, 0u);
}

TEST(SocketcandDoor, ClientThatNeverReadsCannotStallTheBus) {
  Rig rig;
  SocketcandDoor door(rig.runner, rig.hub, ephemeral(0ms));
  ASSERT_EQ(door.open(), "");
  can_test::StalledClient client(door.port(), "< open can0 >< rawmode >");
  EXPECT_TRUE(rig.run_until([&] { return door.stats().elements == 2; }));
  can_test::expect_flood_absorbed(rig, door);  // the stalled client delays nothing
  client.release();
}

TEST(SocketcandDoor, OpenReportsAPortInUseInsteadOfThrowing) {
  Rig rig;
  SocketcandDoor first(rig.runner, rig.hub, ephemeral());
  ASSERT_EQ(first.open(), "");
  SocketcandDoor::Options o = ephemeral();
  o.port = first.port();
  SocketcandDoor second(rig.runner, rig.hub, o);
  EXPECT_NE(second.open().find("listen on 127.0.0.1:"), std::string::npos);
}

}  // namespace
}  // namespace pbvbus::gateways
