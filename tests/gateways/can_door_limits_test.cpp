// The CAN TCP doors (SLCAN over TCP, socketcand) against a hostile crowd: a client limit (one
// more client is accepted and closed at once, counted and logged; a freed place serves the
// next), and descriptor exhaustion (accept() failing with EMFILE: the door pauses instead of
// spinning, logs once per episode, and serves the clients that waited once descriptors are
// free). Raw client sockets on 127.0.0.1; the bus is Scheduler + PacedRunner on the test thread.
#include <gtest/gtest.h>
#include <poll.h>
#include <unistd.h>

#include <chrono>
#include <string>
#include <vector>

#include "can_door_test_support.hpp"
#include "descriptor_squeeze.hpp"
#include "pbvbus/gateways/slcan_door.hpp"
#include "pbvbus/gateways/socketcand_door.hpp"

namespace pbvbus::gateways {
namespace {

using namespace std::chrono_literals;
using namespace can_test;

/// Lines a door logged.
struct LogLines {
  std::vector<std::string> lines;
  DoorLog sink() {
    return [this](const std::string& l) { lines.push_back(l); };
  }
  std::size_t count(const std::string& part) const {
    std::size_t n = 0;
    for (const auto& l : lines) n += l.find(part) != std::string::npos ? 1 : 0;
    return n;
  }
};

/// True if the peer closed `fd` without sending anything (EOF within a generous bound).
bool closed_without_a_word(int fd) {
  bool eof = false;
  const std::string got = read_n(fd, 1, &eof);
  return eof && got.empty();
}

SocketcandDoor::Options socketcand_options(std::size_t max_clients, LogLines& log) {
  SocketcandDoor::Options o;
  o.port = 0;
  o.max_clients = max_clients;
  o.log = log.sink();
  return o;
}

TEST(CanDoorLimits, SocketcandRefusesTheClientBeyondTheLimitAndServesTheNextOnceOneLeaves) {
  Rig rig;
  LogLines log;
  SocketcandDoor door(rig.runner, rig.hub, socketcand_options(2, log));
  ASSERT_EQ(door.open(), "");
  const int a = connect_tcp(door.port());
  const int b = connect_tcp(door.port());
  ASSERT_TRUE(rig.run_until([&] { return door.stats().clients == 2; }));
  const int c = connect_tcp(door.port());  // one too many
  ASSERT_TRUE(rig.run_until([&] { return door.stats().refused == 1; }));
  EXPECT_TRUE(closed_without_a_word(c));  // not even `< hi >`
  EXPECT_EQ(read_n(a, 6), "< hi >");
  EXPECT_EQ(read_n(b, 6), "< hi >");
  EXPECT_EQ(door.stats().clients_total, 2u);
  EXPECT_EQ(log.count("refused a client: 2 connections open (max_clients)"), 1u);
  // A leaves: the next client is served.
  ::close(a);
  ASSERT_TRUE(rig.run_until([&] { return door.stats().clients == 1; }));
  const int d = connect_tcp(door.port());
  ASSERT_TRUE(rig.run_until([&] { return door.stats().clients == 2; }));
  EXPECT_EQ(read_n(d, 6), "< hi >");
  EXPECT_EQ(door.stats().refused, 1u);
  EXPECT_EQ(door.stats().clients_total, 3u);
  for (int fd : {b, c, d}) ::close(fd);
}

TEST(CanDoorLimits, SlcanTcpRefusesTheClientBeyondTheLimitThePtyDoesNotCount) {
  Rig rig;
  LogLines log;
  SlcanDoor::Options o;
  o.pty = true;  // one link more in the door, not a TCP client
  o.tcp_port = 0;
  o.max_clients = 1;
  o.log = log.sink();
  SlcanDoor door(rig.runner, rig.hub, o);
  ASSERT_EQ(door.open(), "");
  const int a = connect_tcp(door.port());
  ASSERT_TRUE(rig.run_until([&] { return door.stats().clients == 2; }));  // the pty and A
  const int b = connect_tcp(door.port());
  ASSERT_TRUE(rig.run_until([&] { return door.stats().refused == 1; }));
  EXPECT_TRUE(closed_without_a_word(b));
  // A is served: `V` -> `V1013\r`.
  write_all(a, "V\r");
  std::string got;
  ASSERT_TRUE(rig.run_until([&] {
    pollfd p{a, POLLIN, 0};
    if (::poll(&p, 1, 0) == 1) got += read_n(a, 6);
    return got.size() >= 6;
  }));
  EXPECT_EQ(got, "V1013\r");
  EXPECT_EQ(log.count("refused a client: 1 connections open (max_clients)"), 1u);
  ::close(a);
  ::close(b);
}

TEST(CanDoorLimits, OutOfDescriptorsTheDoorPausesInsteadOfSpinningAndServesTheWaitingClientsLater) {
  Rig rig;
  LogLines log;
  SocketcandDoor door(rig.runner, rig.hub, socketcand_options(32, log));
  ASSERT_EQ(door.open(), "");
  rig.runner.run_for(5 * bus::kTicksPerMs);  // the io_context and its timers are set up
  int waiting[2] = {-1, -1};
  {
    test::DescriptorSqueeze squeeze;
    ASSERT_TRUE(squeeze.ok);
    squeeze.release(2);  // just enough for the two clients' own sockets
    for (int& fd : waiting) fd = connect_tcp(door.port());  // in the backlog: connect succeeds
    ASSERT_GE(waiting[0], 0);
    ASSERT_GE(waiting[1], 0);
    // One second of bus time (paced: about one of wall time) with both accept()s failing. A
    // door waiting for readability again would wake at once, forever: a whole core. Paused, it
    // retries every 100 ms. Measured on the loaded 2-core build machine: spinning took about
    // half of the wall time, pausing 0.5 ms; the bound (a tenth) is generous both ways.
    const auto cpu0 = test::thread_cpu();
    const auto wall0 = std::chrono::steady_clock::now();
    rig.runner.run_for(1000 * bus::kTicksPerMs);
    const auto cpu = test::thread_cpu() - cpu0;
    const auto wall = std::chrono::steady_clock::now() - wall0;
    EXPECT_LT(cpu, wall / 10) << "cpu " << cpu.count() << " ns in " << wall.count() << " ns";
    EXPECT_EQ(door.stats().clients, 0u);
    EXPECT_GE(door.stats().accept_pauses, 3u);  // ~10: one per 100 ms
    EXPECT_EQ(log.count("accept failed: Too many open files"), 1u);  // once per episode
  }
  // Descriptors are free again: the clients that waited in the backlog are served.
  ASSERT_TRUE(rig.run_until([&] { return door.stats().clients == 2; }));
  EXPECT_EQ(read_n(waiting[0], 6), "< hi >");
  EXPECT_EQ(read_n(waiting[1], 6), "< hi >");
  EXPECT_EQ(log.count("accepting again"), 1u);
  EXPECT_EQ(log.count("accept failed"), 1u);
  for (int fd : waiting) ::close(fd);
}

}  // namespace
}  // namespace pbvbus::gateways
