// The scenario's quantum_hot_standby entries (scenario/proto/scenario.proto message
// QuantumHotStandby; scenario/include/pbvbus/scenario/quantum_plan.hpp): what the loader plans
// from a valid entry, and the refusals with FILE:LINE:COLUMN and the seed's rule (seed 003
// pp. 86-95; seeds-digest.md §11 Q4).
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "pbvbus/scenario/scenario.hpp"

namespace pbvbus::tools {
namespace {

const std::string kFile = std::string(PBVBUS_SOURCE_DIR) + "/examples/q.textproto";

// Lines 1..5; a test appends its entry from line 6 on, one field per line, each indented by two
// spaces (so a field's name is at column 3 and a nested field's at column 5).
const std::string kBase = R"(name: "q"
duration: "1s"
line { name: "rio" baud: "1.5M" }
dp_master { address: 1 line: "rio" }
dp_slave { address: 3 line: "rio" gsd: "gsd/PBVB0A01.gsd" master: 1 }
)";

LoadResult qs_load(const std::string& more) { return parse_scenario(kBase + more, kFile); }

std::vector<std::string> qs_errors(const std::string& more) {
  std::vector<std::string> out;
  for (const auto& d : qs_load(more).errors) {
    std::string s = d.str();
    if (s.rfind(kFile, 0) == 0) s = "q.textproto" + s.substr(kFile.size());
    out.push_back(s);
  }
  return out;
}

TEST(QuantumScenario, PlansAPairWithItsDefaults) {
  const auto r = qs_load(R"(quantum_hot_standby {
  name: "Q"
  dp { line: "rio" address: 1 }
  modbus_port { port: 1 tcp { listen: "127.0.0.1:0" } }
}
)");
  ASSERT_TRUE(r.ok()) << r.errors[0].str();
  ASSERT_EQ(r.plan->quantum.size(), 1u);
  const QuantumPlan& q = r.plan->quantum[0];
  // The 434 12's baseline state RAM (seed 003 p. 49): 1536 0x, 512 1x, 512 3x, 1872 4x; all
  // of it fits the 12K default, so all is sent every scan in the order 0x, 1x, 3x, 4x.
  EXPECT_EQ(q.sizes, (quantum::StateRamSizes{1536, 512, 512, 1872}));
  ASSERT_EQ(q.plan.every_scan.size(), 4u);
  EXPECT_EQ(q.plan.every_scan[3], (quantum::TransferRange{quantum::RefType::Register4x, 0, 1872}));
  EXPECT_EQ(q.command_register, 0u);  // 400001
  // Scan time from the model: baseline transferred (no extra bytes), 40 ms HSBY cost + 20 ms
  // logic (the default logic_time).
  EXPECT_TRUE(q.scan_time_estimated);
  EXPECT_EQ(q.scan_time, 60 * bus::kTicksPerMs);
  // Racks: A at 0 s, B at 100 ms, both Run.
  EXPECT_FALSE(q.racks[0].designation_b);
  EXPECT_TRUE(q.racks[1].designation_b);
  EXPECT_EQ(q.racks[1].power_on_at, 100 * bus::kTicksPerMs);
  // The DP module is the dp_master; slave 3 (2 octets each way) gets 3x 300001 and the first
  // 4x after the command register: 400002.
  EXPECT_EQ(q.dp_address, 1);
  ASSERT_EQ(q.io.size(), 1u);
  EXPECT_EQ(q.io[0].address, 3);
  EXPECT_EQ(q.io[0].inputs, (quantum::Reference{quantum::RefType::Register3x, 0}));
  EXPECT_EQ(q.io[0].outputs, (quantum::Reference{quantum::RefType::Register4x, 1}));
  ASSERT_EQ(q.modbus.size(), 1u);
  EXPECT_EQ(q.modbus[0].address, 1);
  EXPECT_FALSE(q.modbus[0].no_swap);
}

// Q4: the command register must lie in the per-scan 4x area ...
TEST(QuantumScenario, CommandRegisterOutsideThePerScanAreaIsRefused) {
  EXPECT_EQ(qs_errors(R"(quantum_hot_standby {
  name: "Q"
  transfer { mode: USER_DEFINED coils: 16 holding_registers: 32 }
  command_register: "400040"
}
)"),
            std::vector<std::string>{"q.textproto:9:3: command register 400040 lies outside the 4x "
                                     "registers transferred every scan (400001..400032)"});
}

// ... and outside the non-transfer area ...
TEST(QuantumScenario, CommandRegisterInsideTheNonTransferAreaIsRefused) {
  const auto e = qs_errors(R"(quantum_hot_standby {
  name: "Q"
  command_register: "400011"
  non_transfer { start: "400010" length: 4 }
}
)");
  ASSERT_EQ(e.size(), 1u);
  EXPECT_EQ(e[0].rfind("q.textproto:8:3: command register 400011 lies inside the non-transfer area (400010..400013)", 0), 0u)
      << e[0];
}

// ... and the non-transfer area needs at least 4 registers.
TEST(QuantumScenario, NonTransferAreaShorterThanFourIsRefused) {
  EXPECT_EQ(qs_errors(R"(quantum_hot_standby {
  name: "Q"
  non_transfer { start: "400010" length: 3 }
}
)"),
            std::vector<std::string>{"q.textproto:8:3: the non-transfer area 400010 has 3 registers, it "
                                     "must have at least 4 (2 reverse transfer, the status register, "
                                     "one more)"});
}

TEST(QuantumScenario, ModbusAddressAbove119WithTheSwapIsRefused) {
  EXPECT_EQ(qs_errors(R"(quantum_hot_standby {
  name: "Q"
  modbus_port { port: 1 address: 120 tcp { listen: "127.0.0.1:0" } }
}
)"),
            std::vector<std::string>{"q.textproto:8:25: Modbus address 120 is out of range 1..119 (the "
                                     "standby answers at the address + 128, at most 247; seed 003 p. 93)"});
  // Without the swap both units keep the address: up to 247.
  EXPECT_TRUE(qs_errors(R"(quantum_hot_standby {
  name: "Q"
  modbus_port { port: 1 address: 247 no_swap: true tcp { listen: "127.0.0.1:0" } }
}
)").empty());
}

TEST(QuantumScenario, LocalIoInAHotStandbyRackIsRefused) {
  const auto e = qs_errors(R"(quantum_hot_standby {
  name: "Q"
  rack { local_io: "140 DDI 353 00" }
}
)");
  ASSERT_EQ(e.size(), 1u);
  EXPECT_EQ(e[0].rfind("q.textproto:8:10: local I/O \"140 DDI 353 00\" in a Hot Standby rack: only remote I/O is supported", 0), 0u)
      << e[0];
}

TEST(QuantumScenario, TheDpModuleMustBeADpMaster) {
  EXPECT_EQ(qs_errors(R"(quantum_hot_standby {
  name: "Q"
  dp { line: "rio" address: 2 }
}
)"),
            std::vector<std::string>{"q.textproto:8:20: no dp_master with address 2 on line \"rio\""});
}

TEST(QuantumScenario, SlaveOutputsMustBeTransferredEveryScan) {
  // User defined: 16 4x every scan; slave 3's output word at 400100 would reach the standby
  // never, so a takeover would drive it from a stale value.
  const auto e = qs_errors(R"(quantum_hot_standby {
  name: "Q"
  transfer { mode: USER_DEFINED holding_registers: 16 }
  dp { line: "rio" address: 1 map { slave: 3 outputs: "400100" } }
}
)");
  ASSERT_EQ(e.size(), 1u);
  EXPECT_NE(e[0].find("slave 3's outputs from 400100 are not transferred every scan"), std::string::npos) << e[0];
}

TEST(QuantumScenario, FaultsNameTheirPairAndRack) {
  const std::string pair = R"(quantum_hot_standby { name: "Q" }
)";
  EXPECT_EQ(qs_errors(pair + R"(fault { at: "0.5s" quantum_power_loss { } }
)"),
            std::vector<std::string>{"q.textproto:7:20: quantum_power_loss needs a rack: 0 or 1"});
  EXPECT_EQ(qs_errors(pair + R"(fault { at: "0.5s" repair_at: "0.6s" quantum_update { rack: 1 } }
)"),
            std::vector<std::string>{"q.textproto:7:20: quantum_update has no repair"});
  const auto r = qs_load(pair + R"(fault { at: "0.5s" quantum_command { keyswitch_override: true } }
)");
  ASSERT_TRUE(r.ok()) << r.errors[0].str();
  ASSERT_EQ(r.plan->faults.size(), 1u);
  EXPECT_EQ(r.plan->faults[0].kind, PlanFault::Kind::QuantumCommand);
  EXPECT_TRUE(r.plan->faults[0].keyswitch_override);
  EXPECT_EQ(r.plan->faults[0].description,
            "command register written: keyswitch override on, run A 0, run B 0");
}

}  // namespace
}  // namespace pbvbus::tools
