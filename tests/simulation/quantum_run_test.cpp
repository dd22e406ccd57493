// The Quantum Hot Standby pair in a running scenario (simulation/quantum_node.hpp):
// examples/quantum-hsby.textproto run in virtual time, its switchovers, the seed's reactions
// (seed 003; seeds-digest.md §11 Q3, Q5-Q7), the DP slaves kept in data exchange across every
// takeover, the Modbus addresses before and after, and a pair whose racks share a designation
// (Q6).
#include <gtest/gtest.h>

#include <fstream>
#include <sstream>
#include <string>

#include "pbvbus/scenario/scenario.hpp"
#include "pbvbus/simulation/simulation.hpp"

namespace pbvbus::tools {
namespace {

const std::string kExample = std::string(PBVBUS_SOURCE_DIR) + "/examples/quantum-hsby.textproto";
constexpr bus::Ticks kMs = bus::kTicksPerMs;

std::string qr_read(const std::string& path) {
  std::ifstream in(path);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

bool qr_has_event(const quantum::HsbyPair& pair, quantum::PairEventKind k, int rack) {
  for (const auto& e : pair.events())
    if (e.kind == k && e.rack == rack) return true;
  return false;
}

TEST(QuantumRun, TheExamplesSwitchoversAndReactions) {
  auto r = load_scenario_file(kExample);
  ASSERT_TRUE(r.ok()) << r.errors[0].str();
  // Without the Modbus doors (they need a paced run): the same pair, only fast.
  r.plan->quantum[0].modbus[0].tcp.reset();
  r.plan->quantum[0].modbus[0].rtu.reset();
  Simulation sim(*r.plan);
  sim.start();
  sim.run_until(*sim.duration());
  const quantum::HsbyPair& pair = sim.quantum(0).pair();
  const QuantumReport rep = sim.quantum(0).report();
  const bus::Ticks scan = rep.scan_time;
  EXPECT_EQ(scan, 60 * kMs);  // 40 ms HSBY cost + 20 ms logic (seed's model, no extra bytes)

  // Three switchovers: the primary's power (2 s), its key to Off Line (5 s), the command
  // register's run bits both 0 (9 s). Each within one scan of its cause (Q7, Q5).
  const auto& sw = pair.switchovers();
  ASSERT_EQ(sw.size(), 3u);
  EXPECT_EQ(sw[0].cause, quantum::SwitchoverCause::PrimaryPowerOff);
  EXPECT_EQ(sw[0].old_rack, 0);
  EXPECT_EQ(sw[1].cause, quantum::SwitchoverCause::KeyOffLine);
  EXPECT_EQ(sw[1].old_rack, 1);
  EXPECT_EQ(sw[2].cause, quantum::SwitchoverCause::CommandRegister);
  EXPECT_EQ(sw[2].old_rack, 0);
  for (const auto& s : sw) EXPECT_LE(s.takeover_ticks, scan);
  // Q5: override with both run bits 0 — the old primary went offline ...
  bool offline_after_override = false;
  for (const auto& e : pair.events())
    if (e.rack == 0 && e.kind == quantum::PairEventKind::State && e.state == quantum::CpuState::Offline &&
        e.time >= 9000 * kMs && e.time < 10000 * kMs)
      offline_after_override = true;
  EXPECT_TRUE(offline_after_override);
  // ... the logic mismatch at 13 s took the standby offline, the update at 14 s brought it back.
  EXPECT_TRUE(qr_has_event(pair, quantum::PairEventKind::LogicMismatch, 0));
  EXPECT_TRUE(qr_has_event(pair, quantum::PairEventKind::Update, 0));
  // Q7: the primary's key to Xfer (20 s) changed nothing: no fourth switchover; the fibre cut
  // (17 s) took the standby offline and it came back after the repair.
  EXPECT_TRUE(qr_has_event(pair, quantum::PairEventKind::Ignored, 1));
  EXPECT_EQ(pair.primary(), 1);
  EXPECT_EQ(pair.standby(), 0);
  EXPECT_EQ(pair.logic_checksum(0), 1u);  // the update copied the primary's program

  // Q3 on the switchovers: 1/129 follow the primary (rack 0's address "-" while unpowered).
  ASSERT_EQ(rep.switchovers.size(), 3u);
  ASSERT_EQ(rep.switchovers[0].modbus.size(), 1u);
  EXPECT_EQ(rep.switchovers[0].modbus[0].before, (std::array<int, 2>{1, 129}));
  EXPECT_EQ(rep.switchovers[0].modbus[0].after, (std::array<int, 2>{0, 1}));
  EXPECT_EQ(rep.switchovers[1].modbus[0].before, (std::array<int, 2>{129, 1}));
  EXPECT_EQ(rep.switchovers[1].modbus[0].after, (std::array<int, 2>{1, 129}));

  // The DP modules: three takeovers, each slave resumed (no restart); the slaves never left
  // data exchange (no watchdog expiry at 300 ms).
  ASSERT_TRUE(rep.dp.has_value());
  EXPECT_EQ(rep.dp->takeovers, 3u);
  EXPECT_EQ(rep.dp->resumed, 9u);
  EXPECT_EQ(rep.dp->restarted, 0u);
  const Report full = sim.report(0.0);
  ASSERT_EQ(full.dp_slaves.size(), 3u);
  for (const auto& s : full.dp_slaves) {
    EXPECT_EQ(s.stats.watchdog_expiries, 0u) << static_cast<int>(s.address);
    EXPECT_EQ(s.stats.data_exch_entries, 1u) << static_cast<int>(s.address);
  }
}

TEST(QuantumRun, SameDesignationOnBothRacksKeepsTheSecondOffline) {
  std::string text = qr_read(kExample);
  // Q6: both slide switches at A.
  const std::string b = "rack { designation: B power_on_at: \"100ms\" }";
  const auto at = text.find(b);
  ASSERT_NE(at, std::string::npos);
  text.replace(at, b.size(), "rack { designation: A power_on_at: \"100ms\" }");
  // Only the start: no faults.
  text = text.substr(0, text.find("fault {"));
  auto r = parse_scenario(text, kExample);
  ASSERT_TRUE(r.ok()) << r.errors[0].str();
  r.plan->quantum[0].modbus.clear();
  r.plan->duration = 1000 * kMs;
  Simulation sim(*r.plan);
  sim.start();
  sim.run_until(*sim.duration());
  const quantum::HsbyPair& pair = sim.quantum(0).pair();
  EXPECT_EQ(pair.state(0), quantum::CpuState::Primary);
  EXPECT_EQ(pair.state(1), quantum::CpuState::Offline);
  EXPECT_EQ(pair.leds(1).com_act, quantum::Led::Blinking);
  EXPECT_TRUE(qr_has_event(pair, quantum::PairEventKind::DuplicateDesignation, 1));
}

}  // namespace
}  // namespace pbvbus::tools
