// Gateways in a running Simulation (gateway_node.hpp): the outputs ownership (a served master
// runs no test program), the report part "gateways", and one Modbus TCP exchange through the
// real door on the paced runner's io_context with exact bytes.
#include <arpa/inet.h>
#include <gtest/gtest.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <array>
#include <atomic>
#include <fstream>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "pbvbus/bus/paced_runner.hpp"
#include "pbvbus/gateways/modbus_map.hpp"
#include "pbvbus/simulation/report.hpp"
#include "pbvbus/scenario/scenario.hpp"
#include "pbvbus/simulation/simulation.hpp"
#include "pbvbus/reports/run_report.hpp"

namespace pbvbus::tools {
namespace {

constexpr bus::Ticks kMs = bus::kTicksPerMs;
const std::string kFile = std::string(PBVBUS_SOURCE_DIR) + "/examples/gw-run.textproto";

// Two masters on two lines, each with a compact PBVB0A01 station (2 octets in, 2 out) at
// address 3; the gateway serves master 1 only. Slave 3 on line A shows the constant
// 42330 = 0xA55A (10 * 4096 + 5 * 256 + 5 * 16 + 10) big-endian in its two input octets.
std::string scenario(const std::string& gateway) {
  return R"(name: "gw-run"
duration: "500ms"
line { name: "A" }
line { name: "B" }
dp_master { address: 1 line: "A" }
dp_slave { address: 3 line: "A" gsd: "gsd/PBVB0A01.gsd" master: 1
  io { module_index: 0 constant { value: 42330 } } }
dp_master { address: 1 line: "B" }
dp_slave { address: 3 line: "B" gsd: "gsd/PBVB0A01.gsd" master: 1 }
)" + gateway;
}

ScenarioPlan plan_of(const std::string& text) {
  auto r = parse_scenario(text, kFile);
  if (!r.ok()) ADD_FAILURE() << r.errors[0].str();
  return *r.plan;
}

const DpSlaveView* slave_view(const Report& r, const std::string& line) {
  for (const auto& v : r.dp_slaves)
    if (v.line == line && v.address == 3) return &v;
  return nullptr;
}

TEST(GatewayRun, AServedMasterWritesNoOutputsAndTheReportShowsTheGateway) {
  Simulation sim(plan_of(scenario(R"(gateway { name: "gw" line: "A" master: 1
  modbus_tcp { listen: "127.0.0.1:0" } can { socketcand { listen: "127.0.0.1:0" } } }
)")));
  EXPECT_TRUE(sim.has_external_attachments());
  sim.start();
  sim.run_until(500 * kMs);
  const Report r = sim.report(1.0);
  const DpSlaveView* a = slave_view(r, "A");
  const DpSlaveView* b = slave_view(r, "B");
  ASSERT_NE(a, nullptr);
  ASSERT_NE(b, nullptr);
  // Both in data exchange; line A's outputs are what no client wrote: 0. Line B's master runs
  // its COUNT program: every output octet = its token count mod 256 at its last write (the
  // test would fail only if that count were a multiple of 256 exactly then).
  EXPECT_EQ(a->state, "Data_Exch");
  EXPECT_EQ(b->state, "Data_Exch");
  EXPECT_EQ(a->outputs, (std::vector<std::uint8_t>{0x00, 0x00}));
  EXPECT_NE(b->outputs, (std::vector<std::uint8_t>{0x00, 0x00}));
  EXPECT_EQ(a->inputs, (std::vector<std::uint8_t>{0xA5, 0x5A}));
  ASSERT_EQ(r.gateways.size(), 1u);
  const GatewayReport& g = r.gateways[0];
  EXPECT_EQ(g.name, "gw");
  EXPECT_EQ(g.served, "dp_master 1 on A");
  ASSERT_TRUE(g.modbus);
  EXPECT_EQ(g.modbus->requests, 0u);
  ASSERT_TRUE(g.can);
  // No door was opened (a fast run): the doors are not in the report, the CAN core ran.
  EXPECT_TRUE(g.doors.empty());
  EXPECT_GT(g.can->tpdo, 0u);
  std::ostringstream js;
  write_json(r, js);
  EXPECT_NE(js.str().find(",\"gateways\":[{\"name\":\"gw\",\"served\":\"dp_master 1 on A\",\"modbus\":{\"requests\":0,"),
            std::string::npos);
}

/// Connects to 127.0.0.1:port, sends `req`, reads `n` octets (blocking, on a test thread).
std::vector<std::uint8_t> exchange(std::uint16_t port, const std::vector<std::uint8_t>& req,
                                   std::size_t n) {
  const int s = ::socket(AF_INET, SOCK_STREAM, 0);
  sockaddr_in a{};
  a.sin_family = AF_INET;
  a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  a.sin_port = htons(port);
  std::vector<std::uint8_t> out;
  timeval tv{20, 0};  // an upper bound only
  ::setsockopt(s, SOL_SOCKET, SO_RCVTIMEO, &tv, sizeof tv);
  if (::connect(s, reinterpret_cast<sockaddr*>(&a), sizeof a) == 0 &&
      ::send(s, req.data(), req.size(), 0) == static_cast<ssize_t>(req.size())) {
    std::array<std::uint8_t, 300> buf{};
    while (out.size() < n) {
      const ssize_t k = ::recv(s, buf.data(), buf.size(), 0);
      if (k <= 0) break;
      out.insert(out.end(), buf.begin(), buf.begin() + k);
    }
  }
  ::close(s);
  return out;
}

TEST(GatewayRun, ModbusTcpReadThroughThePacedRun) {
  Simulation sim(plan_of(scenario(R"(gateway { name: "gw" line: "A" master: 1
  modbus_tcp { listen: "127.0.0.1:0" } }
)")));
  sim.start();
  bus::PacedRunner& runner = sim.paced_runner(bus::Speed{1, 1});
  const auto lines = sim.gateway(0).door_lines();
  ASSERT_EQ(lines.size(), 1u);
  ASSERT_EQ(lines[0].rfind("gateway gw: modbus_tcp on 127.0.0.1:", 0), 0u) << lines[0];
  const auto port = static_cast<std::uint16_t>(std::stoi(lines[0].substr(lines[0].rfind(':') + 1)));
  // Let the master bring slave 3 into data exchange first (virtual time, no client yet).
  runner.run_for(200 * kMs);
  // FC04, unit 3, input register 0, quantity 1 (MBAP: transaction 00 07, protocol 00 00,
  // length 00 06 = unit + 5 PDU octets):
  //   request  00 07 00 00 00 06 | 03 | 04 00 00 00 01
  // Response: length = unit + FC + byte count + 2 octets = 5; register 0 = input octets 0, 1
  // high byte first = A5 5A (the constant 42330 = 0xA55A):
  //   response 00 07 00 00 00 05 | 03 | 04 02 A5 5A
  std::vector<std::uint8_t> got;
  std::atomic<bool> done{false};
  std::thread client([&] {
    got = exchange(port, {0x00, 0x07, 0x00, 0x00, 0x00, 0x06, 0x03, 0x04, 0x00, 0x00, 0x00, 0x01}, 11);
    done = true;
  });
  // The door answers on the bus thread (this one) while the runner runs; at most 20 s of
  // slices (an upper bound for the client, not a timing assertion).
  for (int i = 0; i < 200 && !done; ++i) runner.run_for(100 * kMs);
  client.join();
  EXPECT_EQ(got, (std::vector<std::uint8_t>{0x00, 0x07, 0x00, 0x00, 0x00, 0x05, 0x03, 0x04, 0x02,
                                            0xA5, 0x5A}));
  const Report r = sim.report(1.0);
  ASSERT_EQ(r.gateways.size(), 1u);
  ASSERT_EQ(r.gateways[0].doors.size(), 1u);
  EXPECT_EQ(r.gateways[0].doors[0].kind, "modbus_tcp");
  EXPECT_EQ(r.gateways[0].doors[0].clients_total, 1u);
  EXPECT_EQ(r.gateways[0].doors[0].requests, 1u);
  EXPECT_EQ(r.gateways[0].doors[0].exceptions, 0u);
  EXPECT_EQ(r.gateways[0].modbus->requests, 1u);
}

TEST(GatewayRun, TheReportShowsRefusedEvictedAndAcceptPausesApartFromClosedBad) {
  GatewayReport g;
  g.name = "gw";
  g.served = "dp_master 1 on L";
  GatewayDoorReport quiet;
  quiet.kind = "socketcand";
  quiet.where = "127.0.0.1:29536";
  quiet.clients_total = 2;
  GatewayDoorReport busy;
  busy.kind = "modbus_tcp";
  busy.where = "127.0.0.1:1502";
  busy.clients_total = 40;
  busy.clients = 32;
  busy.clients_closed_bad = 1;
  busy.clients_evicted = 8;
  busy.accept_pauses = 3;
  g.doors = {quiet, busy};
  std::ostringstream text, json;
  write_gateways_text({g}, text);
  // Text: the new counters only when they happened.
  EXPECT_NE(text.str().find("socketcand 127.0.0.1:29536: 2 clients (0 now, 0 closed bad), "),
            std::string::npos)
      << text.str();
  EXPECT_NE(text.str().find("modbus_tcp 127.0.0.1:1502: 40 clients (32 now, 1 closed bad, 8 "
                            "evicted, 3 accept pauses), "),
            std::string::npos)
      << text.str();
  // JSON: always, each on its own.
  write_gateways_json({g}, json);
  EXPECT_NE(json.str().find("\"clients_closed_bad\":1,\"clients_refused\":0,\"clients_evicted\":8,"
                            "\"accept_pauses\":3,"),
            std::string::npos)
      << json.str();
}

TEST(GatewayRun, ARedundantSystemsGatewayOwnsItsOutputs) {
  // examples/switched-io.textproto (switched stations 3..6 of "H-DP 1", one-sided slaves 10 on
  // DP_A and 11 on DP_B) with a gateway on the system and Quantum-style standby units.
  std::ifstream f(std::string(PBVBUS_SOURCE_DIR) + "/examples/switched-io.textproto");
  const std::string text{std::istreambuf_iterator<char>(f), std::istreambuf_iterator<char>()};
  auto r = parse_scenario(text + R"(gateway { name: "red" redundant_master_system: "H-DP 1"
  modbus_tcp { listen: "127.0.0.1:0" } modbus { standby_units: true } }
)", std::string(PBVBUS_SOURCE_DIR) + "/examples/switched-io.textproto");
  ASSERT_TRUE(r.ok()) << r.errors[0].str();
  SimulationOptions o;
  o.duration = 900 * kMs;  // before the first fault (1 s)
  Simulation sim(*r.plan, o);
  sim.start();
  sim.run_until(900 * kMs);
  const Report rep = sim.report(1.0);
  ASSERT_EQ(rep.gateways.size(), 1u);
  EXPECT_EQ(rep.gateways[0].served, "redundant_master_system \"H-DP 1\"");
  // The system's program is off: every switched station's backplane outputs are still 0.
  ASSERT_EQ(rep.redundancy.size(), 1u);
  ASSERT_EQ(rep.redundancy[0].stations.size(), 4u);
  for (const auto& st : rep.redundancy[0].stations) {
    EXPECT_FALSE(st.outputs.empty());
    EXPECT_EQ(st.outputs, std::vector<std::uint8_t>(st.outputs.size(), 0)) << int(st.address);
  }
  // Units: 3..6, 10, 11 and the standby views 128 + 3..6 of the switched stations.
  std::vector<int> units;
  for (const auto& u : sim.gateway(0).modbus_map().units()) units.push_back(u.unit);
  EXPECT_EQ(units, (std::vector<int>{3, 4, 5, 6, 10, 11, 131, 132, 133, 134}));
}

TEST(GatewayRun, AGatewayOnAnHSystemIsReadOnly) {
  // examples/h-system.textproto: "H-DP 1" is driven by the simulated CPU pair, whose program
  // owns the outputs: the system's masters keep their (switched-off) program state, and the
  // source (RedundantSource with the HSystemModel) refuses writes: every unit is read-only.
  const std::string file = std::string(PBVBUS_SOURCE_DIR) + "/examples/h-system.textproto";
  std::ifstream f(file);
  const std::string text{std::istreambuf_iterator<char>(f), std::istreambuf_iterator<char>()};
  auto r = parse_scenario(text + R"(gateway { name: "h" redundant_master_system: "H-DP 1"
  modbus_tcp { listen: "127.0.0.1:0" } }
)", file);
  ASSERT_TRUE(r.ok()) << r.errors[0].str();
  const GatewayPlan& g = r.plan->gateways[0];
  EXPECT_GE(g.h_system, 0);
  for (const auto& m : r.plan->dp_masters) EXPECT_FALSE(m.gateway_outputs);
  SimulationOptions o;
  o.duration = 100 * kMs;
  Simulation sim(*r.plan, o);
  sim.start();
  sim.run_until(100 * kMs);
  const auto units = sim.gateway(0).modbus_map().units();
  ASSERT_FALSE(units.empty());
  for (const auto& u : units) EXPECT_FALSE(u.writable) << int(u.unit);
}

}  // namespace
}  // namespace pbvbus::tools
