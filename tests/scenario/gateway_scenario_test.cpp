// The scenario's `gateway` entries (scenario/proto/scenario.proto message Gateway,
// scenario/include/pbvbus/scenario/gateway_plan.hpp): what the loader plans from a valid entry, every
// check with its exact FILE:LINE:COLUMN message, and the outputs ownership (a served dp_master
// runs no test program).
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "pbvbus/scenario/scenario.hpp"

namespace pbvbus::tools {
namespace {

constexpr bus::Ticks kMs = bus::kTicksPerMs;

// GSD paths are relative to the scenario file: the name places it in examples/.
const std::string kFile = std::string(PBVBUS_SOURCE_DIR) + "/examples/gw.textproto";

// Positions are those of the field's name (or of the entry/message when the field is absent),
// counted by hand in the text below: e.g. `gateway { name: "g2" line: "A" master: 7` has
// `gateway { ` (10 columns), so `name` at 11, `line` at 11 + 11 = 22, `master` at 22 + 10 = 32.
//
// The DP system of dp-basic (slaves 3, 4, 5 on master 1), lines 1..13; a test appends its
// gateway entries from line 14 on.
const std::string kBase = R"(name: "gw"
duration: "1s"
line { name: "A" }
line { name: "B" }
dp_master { address: 1 line: "A" }
dp_slave { address: 3 line: "A" gsd: "gsd/PBVB0A01.gsd" master: 1 }
dp_slave {
  address: 4 line: "A" gsd: "gsd/PBVB0A02.gsd" master: 1
  modules: ["8DI DC24V", "8DO DC24V/0.5A", "2AO U/I 16 bit"]
}
dp_slave { address: 5 line: "A" gsd: "gsd/PBVB0A03.gsd" master: 1
  modules: ["8DI with process alarm", "8DO DC24V/0.5A", "2AI U/I consistent"] }
dp_master { address: 2 line: "B" }
)";

LoadResult load(const std::string& gateways) { return parse_scenario(kBase + gateways, kFile); }

std::vector<std::string> errors(const std::string& gateways) {
  std::vector<std::string> out;
  for (const auto& d : load(gateways).errors) {
    std::string s = d.str();
    // Strip the directory for readable expectations.
    if (s.rfind(kFile, 0) == 0) s = "gw.textproto" + s.substr(kFile.size());
    out.push_back(s);
  }
  return out;
}

TEST(GatewayScenario, AValidEntryIsPlanned) {
  const auto r = load(R"(gateway {
  name: "gw"
  line: "A" master: 1
  modbus_tcp { listen: "127.0.0.1:0" max_clients: 4 }
  modbus_rtu { link: "./ttyMB0" baud: 115200 parity: EVEN stop_bits: 1 }
  modbus_rtu { device: "/dev/ttyUSB0" }
  modbus {
    slave { address: 4 word_order: WORD_SWAP stale: VALUE stale_value: 65535
            module { module_index: 2 word_order: BYTE_SWAP } }
  }
  can {
    node { address: 5 node: 42 }
    tpdo_cycle: "50ms" heartbeat: "2s"
    slcan_pty { link: "./ttyCAN0" }
    slcan_tcp { listen: "127.0.0.1:20001" max_clients: 3 }
    socketcand { max_clients: 5 }
    socketcan { interface: "vcan0" }
  }
}
)");
  ASSERT_TRUE(r.ok()) << (r.errors.empty() ? "" : r.errors[0].str());
  const ScenarioPlan& p = *r.plan;
  ASSERT_EQ(p.gateways.size(), 1u);
  const GatewayPlan& g = p.gateways[0];
  EXPECT_EQ(g.name, "gw");
  EXPECT_EQ(g.served, "dp_master 1 on A");
  EXPECT_EQ(g.dp_master, 0);
  EXPECT_EQ(g.system, -1);
  EXPECT_EQ(g.h_system, -1);
  ASSERT_EQ(g.slaves.size(), 3u);
  EXPECT_EQ(p.dp_slaves[static_cast<std::size_t>(g.slaves[0])].address, 3);
  EXPECT_EQ(p.dp_slaves[static_cast<std::size_t>(g.slaves[2])].address, 5);
  ASSERT_TRUE(g.modbus_tcp);
  EXPECT_EQ(g.modbus_tcp->host, "127.0.0.1");
  EXPECT_EQ(g.modbus_tcp->port, 0);
  EXPECT_EQ(g.max_clients, 4u);
  ASSERT_EQ(g.modbus_rtu.size(), 2u);
  EXPECT_EQ(g.modbus_rtu[0].link, "./ttyMB0");
  EXPECT_EQ(g.modbus_rtu[0].baud, 115200u);
  EXPECT_EQ(g.modbus_rtu[0].parity, 'E');
  EXPECT_EQ(g.modbus_rtu[1].device, "/dev/ttyUSB0");
  EXPECT_EQ(g.modbus_rtu[1].baud, 19200u);  // the default
  EXPECT_EQ(g.modbus_rtu[1].parity, 'N');
  EXPECT_EQ(g.modbus_rtu[1].stop_bits, 1);
  ASSERT_EQ(g.modbus_slaves.size(), 1u);
  EXPECT_EQ(g.modbus_slaves[0].address, 4);
  EXPECT_EQ(g.modbus_slaves[0].order, GwWordOrder::WordSwap);
  EXPECT_EQ(g.modbus_slaves[0].stale, GwStale::Value);
  EXPECT_EQ(g.modbus_slaves[0].stale_value, 0xFFFF);
  ASSERT_EQ(g.modbus_slaves[0].modules.size(), 1u);
  EXPECT_EQ(g.modbus_slaves[0].modules[0].first, 2u);
  EXPECT_EQ(g.modbus_slaves[0].modules[0].second, GwWordOrder::ByteSwap);
  ASSERT_TRUE(g.can);
  ASSERT_EQ(g.can->nodes.size(), 1u);
  EXPECT_EQ(g.can->nodes[0], (std::pair<std::uint8_t, std::uint8_t>{5, 42}));
  EXPECT_EQ(g.can->tpdo_cycle, 50 * kMs);
  EXPECT_EQ(g.can->heartbeat, 2000 * kMs);
  EXPECT_EQ(g.can->slcan_pty, "./ttyCAN0");
  ASSERT_TRUE(g.can->slcan_tcp);
  EXPECT_EQ(g.can->slcan_tcp->str(), "127.0.0.1:20001");
  ASSERT_TRUE(g.can->socketcand);
  EXPECT_EQ(g.can->socketcand->str(), "127.0.0.1:29536");  // the default
  EXPECT_EQ(g.can->slcan_max_clients, 3u);
  EXPECT_EQ(g.can->socketcand_max_clients, 5u);
  EXPECT_EQ(g.can->socketcan, "vcan0");
  // Outputs ownership: master 1 is served, master 2 is not.
  EXPECT_TRUE(p.dp_masters[0].gateway_outputs);
  EXPECT_FALSE(p.dp_masters[1].gateway_outputs);
}

TEST(GatewayScenario, DefaultsOfTheDoors) {
  const auto r = load(R"(gateway { name: "g" line: "A" master: 1 modbus_tcp { } can { socketcand { } } }
)");
  ASSERT_TRUE(r.ok()) << (r.errors.empty() ? "" : r.errors[0].str());
  const GatewayPlan& g = r.plan->gateways[0];
  EXPECT_EQ(g.modbus_tcp->str(), "127.0.0.1:1502");
  EXPECT_EQ(g.can->tpdo_cycle, 100 * kMs);
  EXPECT_EQ(g.can->heartbeat, 1000 * kMs);
  EXPECT_FALSE(g.can->slcan_pty);
  EXPECT_EQ(g.max_clients, 0u);  // 0: the doors' own default (32)
  EXPECT_EQ(g.can->socketcand_max_clients, 0u);
}

TEST(GatewayScenario, TheMasterSystemMustExist) {
  EXPECT_EQ(errors(R"(gateway { name: "g1" line: "C" master: 1 modbus_tcp { listen: "127.0.0.1:0" } }
gateway { name: "g2" line: "A" master: 7 modbus_tcp { listen: "127.0.0.1:0" } }
gateway { name: "g3" redundant_master_system: "R" modbus_tcp { listen: "127.0.0.1:0" } }
gateway { name: "g4" modbus_tcp { listen: "127.0.0.1:0" } }
gateway { name: "g5" line: "A" modbus_tcp { listen: "127.0.0.1:0" } }
)"),
            (std::vector<std::string>{
                "gw.textproto:14:22: unknown line \"C\"",
                "gw.textproto:15:32: no dp_master 7 on line \"A\"",
                "gw.textproto:16:22: unknown redundant_master_system \"R\"",
                "gw.textproto:17:11: give the master system: line and master (a dp_master) or "
                "redundant_master_system",
                "gw.textproto:18:22: a gateway on a dp_master needs both line and master",
            }));
}

TEST(GatewayScenario, NamesAndDoors) {
  EXPECT_EQ(errors(R"(gateway { name: "g" line: "A" master: 1 modbus_tcp { listen: "127.0.0.1:0" } }
gateway { name: "g" line: "B" master: 2 can { } }
gateway { line: "B" master: 2 modbus_tcp { listen: "127.0.0.1:0" } }
gateway { name: "e" line: "B" master: 2 }
)"),
            (std::vector<std::string>{
                "gw.textproto:15:11: gateway \"g\" is defined twice",
                "gw.textproto:15:41: can needs a transport: slcan_pty, slcan_tcp, socketcand or "
                "socketcan",
                "gw.textproto:16:1: a gateway needs a name",
                "gw.textproto:17:1: gateway \"e\" has no door: add modbus_tcp, modbus_rtu or can",
            }));
}

TEST(GatewayScenario, ListenAddressesAndPorts) {
  EXPECT_EQ(errors(R"(gateway {
  name: "g" line: "A" master: 1
  modbus_tcp { listen: "localhost:1502" }
  can { slcan_tcp { listen: "127.0.0.1:70000" } socketcand { listen: "[::1]:1503" } }
}
gateway {
  name: "h" line: "B" master: 2
  modbus_tcp { listen: "0.0.0.0:1503" }
  can { slcan_tcp { } }
}
)"),
            (std::vector<std::string>{
                "gw.textproto:16:16: bad listen address \"localhost:1502\" (expected HOST:PORT with "
                "a numeric IPv4 address or [IPv6] and a port 0..65535, e.g. 127.0.0.1:1502)",
                "gw.textproto:17:21: bad listen address \"127.0.0.1:70000\" (expected HOST:PORT with "
                "a numeric IPv4 address or [IPv6] and a port 0..65535, e.g. 127.0.0.1:1502)",
                "gw.textproto:21:16: port 1503 is already used by gateway \"g\" (socketcand)",
                "gw.textproto:22:9: slcan_tcp needs listen (HOST:PORT)",
            }));
}

TEST(GatewayScenario, RtuPorts) {
  EXPECT_EQ(errors(R"(gateway {
  name: "g" line: "A" master: 1
  modbus_rtu { baud: 9600 }
  modbus_rtu { link: "./tty0" stop_bits: 3 }
  can { slcan_pty { link: "./tty0" } }
}
)"),
            (std::vector<std::string>{
                "gw.textproto:16:3: modbus_rtu needs a link (a pty) or a device",
                "gw.textproto:17:31: stop_bits must be 1 or 2",
                "gw.textproto:18:21: pty link \"./tty0\" is already used by gateway \"g\"",
            }));
}

TEST(GatewayScenario, ModbusOptions) {
  EXPECT_EQ(errors(R"(gateway {
  name: "g" line: "A" master: 1
  modbus_tcp { listen: "127.0.0.1:0" }
  modbus {
    standby_units: true
    slave { address: 9 }
    slave { address: 4 stale_value: 65536 module { module_index: 3 } }
    slave { address: 4 }
    slave { word_order: BYTE_SWAP }
  }
}
)"),
            (std::vector<std::string>{
                "gw.textproto:18:5: standby_units needs a redundant_master_system",
                "gw.textproto:19:13: address 9 is not a slave of dp_master 1 on A",
                "gw.textproto:20:24: stale_value 65536 is out of range 0..65535",
                "gw.textproto:20:52: module_index 3 is out of range: slave 4 has 3 modules (0..2)",
                "gw.textproto:21:13: options for slave 4 are given twice",
                "gw.textproto:22:5: a slave option needs its address",
            }));
}

TEST(GatewayScenario, CanNodes) {
  EXPECT_EQ(errors(R"(gateway {
  name: "g" line: "A" master: 1
  can {
    node { address: 4 node: 0 }
    node { address: 9 node: 10 }
    node { address: 3 node: 5 }
    tpdo_cycle: "0ms"
    heartbeat: "soon"
    socketcan { }
  }
}
)"),
            (std::vector<std::string>{
                "gw.textproto:17:23: node 0 is out of range 1..127",
                "gw.textproto:18:12: address 9 is not a slave of dp_master 1 on A",
                // slave 3 mapped to node 5, which is slave 5's own address (its default node)
                "gw.textproto:19:23: node 5 is used twice (slave 3 and slave 5)",
                "gw.textproto:20:5: must be longer than 0",
                "gw.textproto:21:5: bad duration \"soon\" (expected a number and a unit: ns, us, "
                "ms, s, min, h)",
                "gw.textproto:22:5: socketcan needs an interface, e.g. \"vcan0\"",
            }));
}

TEST(GatewayScenario, HeartbeatIsSixteenBitsOfMilliseconds) {
  EXPECT_EQ(errors(R"(gateway { name: "g" line: "A" master: 1 can { heartbeat: "66s" socketcand { } } }
gateway { name: "h" line: "B" master: 2 can { heartbeat: "1500us" socketcand { listen: "127.0.0.1:0" } } }
)"),
            (std::vector<std::string>{
                // `gateway { name: "g" line: "A" master: 1 can { ` = 10 + 10 + 10 + 10 + 6 = 46 columns
                "gw.textproto:14:47: heartbeat must be whole milliseconds up to 65535ms (object "
                "0x1017 is 16 bits)",
                "gw.textproto:15:47: heartbeat must be whole milliseconds up to 65535ms (object "
                "0x1017 is 16 bits)",
            }));
}

TEST(GatewayScenario, ASideOfARedundantSystemIsServedThroughTheSystem) {
  const std::string red = R"(redundant_master_system { name: "R" line_a: "A" master_a: 1 line_b: "B" master_b: 2 }
)";
  auto r = parse_scenario(kBase + red + R"(gateway { name: "g" line: "B" master: 2 modbus_tcp { } }
)", kFile);
  ASSERT_EQ(r.errors.size(), 1u);
  EXPECT_EQ(r.errors[0].line, 15);
  EXPECT_EQ(r.errors[0].column, 31);  // `master`
  EXPECT_EQ(r.errors[0].message,
            "dp_master 2 on line \"B\" is part of redundant_master_system \"R\": give "
            "redundant_master_system instead");
  r = parse_scenario(kBase + red + R"(gateway { name: "g" redundant_master_system: "R" modbus_tcp { }
  modbus { standby_units: true } }
)", kFile);
  ASSERT_TRUE(r.ok()) << r.errors[0].str();
  const GatewayPlan& g = r.plan->gateways[0];
  EXPECT_EQ(g.system, 0);
  EXPECT_EQ(g.dp_master, -1);
  EXPECT_TRUE(g.standby_units);
  EXPECT_EQ(g.served, "redundant_master_system \"R\"");
  EXPECT_TRUE(r.plan->dp_masters[0].gateway_outputs);
  EXPECT_TRUE(r.plan->dp_masters[1].gateway_outputs);
}

TEST(GatewayScenario, TheShippedExampleLoads) {
  const auto r = load_scenario_file(std::string(PBVBUS_SOURCE_DIR) + "/examples/gateway.textproto");
  ASSERT_TRUE(r.ok()) << r.errors[0].str();
  ASSERT_EQ(r.plan->gateways.size(), 1u);
  const GatewayPlan& g = r.plan->gateways[0];
  ASSERT_EQ(g.slaves.size(), 4u);
  const DpSlavePlan& s6 = r.plan->dp_slaves[static_cast<std::size_t>(g.slaves[3])];
  EXPECT_EQ(s6.address, 6);
  EXPECT_EQ(s6.model, "pbvbus GW16 gateway test station");
  EXPECT_EQ(s6.inputs, 32u);
  EXPECT_EQ(s6.outputs, 32u);
  EXPECT_EQ(s6.config.ident, 0x0A04);
  EXPECT_EQ(g.modbus_tcp->str(), "127.0.0.1:1502");
  EXPECT_EQ(g.modbus_rtu[0].link, "./ttyMB0");
  EXPECT_EQ(g.can->slcan_pty, "./ttyCAN0");
  EXPECT_EQ(g.can->slcan_tcp->str(), "127.0.0.1:20001");
  EXPECT_EQ(g.can->socketcand->str(), "127.0.0.1:29536");
}

}  // namespace
}  // namespace pbvbus::tools
