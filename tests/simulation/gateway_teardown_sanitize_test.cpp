// Tear-down of a paced run with gateways (gateway_node.hpp, simulation.hpp): every door open,
// clients still connected (a Modbus TCP client mid-request, an SLCAN client with its channel
// open, a socketcand client in raw mode), then the Simulation is destroyed. The doors must go
// before the io_context and the master systems they read; under ASan (sanitize_tools) a wrong
// order shows as a use after free. Also: a door that cannot open (its port taken) fails
// paced_runner() with a message naming the gateway and the door.
#include <arpa/inet.h>
#include <gtest/gtest.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <memory>
#include <stdexcept>
#include <string>

#include "pbvbus/bus/paced_runner.hpp"
#include "pbvbus/scenario/scenario.hpp"
#include "pbvbus/simulation/simulation.hpp"

namespace pbvbus::tools {
namespace {

constexpr bus::Ticks kMs = bus::kTicksPerMs;
const std::string kFile = std::string(PBVBUS_SOURCE_DIR) + "/examples/gw-teardown.textproto";

std::string scenario(const std::string& modbus_listen) {
  return R"(name: "gw-teardown"
line { name: "A" }
dp_master { address: 1 line: "A" }
dp_slave { address: 3 line: "A" gsd: "gsd/PBVB0A01.gsd" master: 1 }
gateway { name: "gw" line: "A" master: 1
  modbus_tcp { listen: ")" + modbus_listen + R"(" }
  can { slcan_tcp { listen: "127.0.0.1:0" } socketcand { listen: "127.0.0.1:0" } } }
)";
}

int connect_to(std::uint16_t port) {
  const int s = ::socket(AF_INET, SOCK_STREAM, 0);
  sockaddr_in a{};
  a.sin_family = AF_INET;
  a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  a.sin_port = htons(port);
  if (::connect(s, reinterpret_cast<sockaddr*>(&a), sizeof a) != 0) {
    ::close(s);
    return -1;
  }
  return s;
}

std::uint16_t port_of(const std::string& door_line) {
  return static_cast<std::uint16_t>(std::stoi(door_line.substr(door_line.rfind(':') + 1)));
}

TEST(GatewayTeardown, DoorsWithConnectedClientsGoBeforeTheRunner) {
  auto loaded = parse_scenario(scenario("127.0.0.1:0"), kFile);
  ASSERT_TRUE(loaded.ok()) << loaded.errors[0].str();
  int fds[3] = {-1, -1, -1};
  {
    auto sim = std::make_unique<Simulation>(*loaded.plan);
    sim->start();
    bus::PacedRunner& runner = sim->paced_runner(bus::Speed{1, 1});
    const auto lines = sim->gateway(0).door_lines();
    ASSERT_EQ(lines.size(), 3u);  // modbus_tcp, slcan (tcp), socketcand
    for (int i = 0; i < 3; ++i) {
      fds[i] = connect_to(port_of(lines[static_cast<std::size_t>(i)]));
      ASSERT_GE(fds[i], 0) << lines[static_cast<std::size_t>(i)];
    }
    // Half a Modbus request (an MBAP header without its PDU), an SLCAN open, a socketcand
    // open + rawmode: each door has a connection in a state of its own when the end comes.
    const unsigned char half[] = {0x00, 0x01, 0x00, 0x00, 0x00, 0x06, 0x03};
    ASSERT_EQ(::send(fds[0], half, sizeof half, 0), static_cast<ssize_t>(sizeof half));
    ASSERT_EQ(::send(fds[1], "O\r", 2, 0), 2);
    const std::string sc = "< open can0 >< rawmode >";
    ASSERT_EQ(::send(fds[2], sc.data(), sc.size(), 0), static_cast<ssize_t>(sc.size()));
    runner.run_for(300 * kMs);
    const Report r = sim->report(1.0);
    ASSERT_EQ(r.gateways.size(), 1u);
    ASSERT_EQ(r.gateways[0].doors.size(), 3u);
    EXPECT_EQ(r.gateways[0].doors[0].clients, 1u);
    EXPECT_EQ(r.gateways[0].doors[1].clients, 1u);
    EXPECT_EQ(r.gateways[0].doors[2].clients, 1u);
    sim.reset();  // doors, then the runner and its io_context, then the scheduler
  }
  // The doors closed their ends: each client reads end of file (or a reset), not a hang.
  for (int fd : fds) {
    timeval tv{5, 0};  // an upper bound only
    ::setsockopt(fd, SOL_SOCKET, SO_RCVTIMEO, &tv, sizeof tv);
    char buf[4096];
    ssize_t k = 0;
    while ((k = ::recv(fd, buf, sizeof buf, 0)) > 0) {
    }
    EXPECT_LE(k, 0);
    ::close(fd);
  }
}

TEST(GatewayTeardown, ADoorThatCannotOpenFailsTheRunWithItsName) {
  // Take a port, then ask the gateway for it.
  const int s = ::socket(AF_INET, SOCK_STREAM, 0);
  sockaddr_in a{};
  a.sin_family = AF_INET;
  a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  socklen_t len = sizeof a;
  ASSERT_EQ(::bind(s, reinterpret_cast<sockaddr*>(&a), sizeof a), 0);
  ASSERT_EQ(::listen(s, 1), 0);
  ASSERT_EQ(::getsockname(s, reinterpret_cast<sockaddr*>(&a), &len), 0);
  const std::string taken = "127.0.0.1:" + std::to_string(ntohs(a.sin_port));
  auto loaded = parse_scenario(scenario(taken), kFile);
  ASSERT_TRUE(loaded.ok()) << loaded.errors[0].str();
  Simulation sim(*loaded.plan);
  sim.start();
  try {
    sim.paced_runner(bus::Speed{1, 1});
    ADD_FAILURE() << "paced_runner() opened a door on a taken port";
  } catch (const std::runtime_error& e) {
    EXPECT_EQ(std::string(e.what()).rfind("gateway \"gw\": modbus_tcp on " + taken + ": ", 0), 0u)
        << e.what();
  }
  ::close(s);
}

}  // namespace
}  // namespace pbvbus::tools
