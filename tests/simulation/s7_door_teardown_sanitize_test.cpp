// Tear-down of a paced run with an S7 door routed to an H-system while a client is connected
// (simulation.hpp, s7_door_node.hpp): the client's S7 session lives on the H model
// (h_s7_session.hpp: "the model must outlive its sessions"), so the run closes its doors'
// connections before the H-systems go. Under ASan (sanitize_simulation) a wrong order shows as a
// use after free when the session releases its connection in the destroyed model.
#include <arpa/inet.h>
#include <gtest/gtest.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "pbvbus/bus/paced_runner.hpp"
#include "pbvbus/scenario/scenario.hpp"
#include "pbvbus/simulation/simulation.hpp"

namespace pbvbus::tools {
namespace {

constexpr bus::Ticks kMs = bus::kTicksPerMs;

const std::string kText = R"(name: "s7-door-teardown"
h_system {
  name: "H-CPU"
  cpu { cpu0 { power_on: "0s" } cpu1 { power_on: "0s" } }
  work_memory_db_kb: 100
}
s7_door { name: "S7" listen: "127.0.0.1:0" route { rack: 0 slot: 3 h_system: "H-CPU" } }
)";

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
  timeval tv{5, 0};  // an upper bound only
  ::setsockopt(s, SOL_SOCKET, SO_RCVTIMEO, &tv, sizeof tv);
  return s;
}

// Runs the simulation in steps of 20 ms until the client has something to read (at most 1 s of
// virtual time; the door answers within one step), then reads one TPKT.
std::vector<std::uint8_t> read_tpkt(int fd);
std::vector<std::uint8_t> answer_of(bus::PacedRunner& runner, int fd) {
  for (int i = 0; i < 50; ++i) {
    runner.run_for(20 * kMs);
    pollfd p{fd, POLLIN, 0};
    if (::poll(&p, 1, 0) == 1) return read_tpkt(fd);
  }
  return {};
}

// One TPKT (RFC 1006: 03 00, a 16-bit length that counts the header), read whole.
std::vector<std::uint8_t> read_tpkt(int fd) {
  std::vector<std::uint8_t> b(4);
  std::size_t got = 0;
  while (got < b.size()) {
    const ssize_t k = ::recv(fd, b.data() + got, b.size() - got, 0);
    if (k <= 0) return {};
    got += static_cast<std::size_t>(k);
    if (got == 4) b.resize(static_cast<std::size_t>(b[2]) << 8 | b[3]);
  }
  return b;
}

TEST(S7DoorTeardown, AClientOnAnHSystemRouteIsClosedBeforeTheModelGoes) {
  auto loaded = parse_scenario(kText, "s7-door-teardown.textproto");
  ASSERT_TRUE(loaded.ok()) << loaded.errors[0].str();
  int fd = -1;
  {
    auto sim = std::make_unique<Simulation>(*loaded.plan);
    sim->start();
    bus::PacedRunner& runner = sim->paced_runner(bus::Speed{1, 1});
    fd = connect_to(sim->s7_door(0).port());
    ASSERT_GE(fd, 0);
    // COTP CR (ISO 8073 / RFC 1006, docs/iso-on-tcp.md): TPKT length 22; LI 17 = CR E0,
    // dst-ref 00 00, src-ref 00 01, class 0, TPDU size C0 01 0A (1024), calling TSAP C1 02 01 00,
    // called TSAP C2 02 01 03 (PG, rack 0 slot 3: 0 x 32 + 3).
    const std::uint8_t cr[] = {0x03, 0x00, 0x00, 0x16, 0x11, 0xE0, 0x00, 0x00, 0x00, 0x01, 0x00,
                               0xC0, 0x01, 0x0A, 0xC1, 0x02, 0x01, 0x00, 0xC2, 0x02, 0x01, 0x03};
    ASSERT_EQ(::send(fd, cr, sizeof cr, 0), static_cast<ssize_t>(sizeof cr));
    const std::vector<std::uint8_t> cc = answer_of(runner, fd);
    ASSERT_GE(cc.size(), 6u);
    EXPECT_EQ(cc[5], 0xD0);  // CC: the route to the H CPU is open, its session exists
    // S7 Setup Communication in a DT (TPKT length 25: 02 F0 80, then the 18-octet PDU of
    // docs/s7.md), so the session has answered once before the end.
    const std::uint8_t setup[] = {0x03, 0x00, 0x00, 0x19, 0x02, 0xF0, 0x80, 0x32, 0x01,
                                  0x00, 0x00, 0x00, 0x00, 0x00, 0x08, 0x00, 0x00, 0xF0,
                                  0x00, 0x00, 0x01, 0x00, 0x01, 0x01, 0xE0};
    ASSERT_EQ(::send(fd, setup, sizeof setup, 0), static_cast<ssize_t>(sizeof setup));
    const std::vector<std::uint8_t> answer = answer_of(runner, fd);
    ASSERT_GE(answer.size(), 9u);
    EXPECT_EQ(answer[7], 0x32);  // an S7 PDU
    EXPECT_EQ(answer[8], 0x03);  // Ack_Data
    sim.reset();  // the door's connection (and its H session) first, then the H model
  }
  // The door closed its end: the client reads end of file (or a reset), not a hang.
  char buf[256];
  ssize_t k = 0;
  while ((k = ::recv(fd, buf, sizeof buf, 0)) > 0) {
  }
  EXPECT_LE(k, 0);
  ::close(fd);
}

}  // namespace
}  // namespace pbvbus::tools
