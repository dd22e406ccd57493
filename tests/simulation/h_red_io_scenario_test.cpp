// The scenario's redundant I/O (HSystem.redundant_io, faults channel_stuck and red_depa;
// docs/h-redundant-io.md "In a scenario"): planned, refused where the file is wrong, and run
// through the Simulation (HSystemNode -> HSystemModel -> RedundantIo), asserted from the
// report's events.
//
// The run (pair as in h_f3_f15_scenario_test.cpp: Redundant from 3.145 s). I/O map: station 3
// IB 0..1, station 20 (line A, one-sided) IB 2, station 22 (line B, one-sided) IB 3: the pair is
// module_L = station 20's 8DI (IB 2), module_H = station 22's 8DI (IB 3), discrepancy time
// 100 ms. Both follow the same table: 0, I x.0 = 1 from 4 s, 0 from 5 s.
//   3.5 s   channel_stuck: station 22's inputs stick at 0
//   4 s     station 20 goes 1: 7960 100 ms after the first OB 1 that sees it (4.1 .. 4.13 s),
//           nobody passivated (001 L5949-5954)
//   5 s     station 20 goes back to 0: the change is in module_L, so module_H (station 22) is
//           passivated: 7961 (001 L5957-5959)
//   6 s     channel_stuck repaired (station 22 follows its table again: 0)
//   7 s     red_depa (FC 451): module_H depassivated at the next OB 1: 7963
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "scenario_run_support.hpp"
#include "pbvbus/reports/run_report.hpp"
#include "pbvbus/scenario/scenario.hpp"
#include "pbvbus/simulation/h_report.hpp"
#include "pbvbus/simulation/simulation.hpp"

namespace pbvbus::tools {
namespace {

constexpr bus::Ticks kMs = bus::kTicksPerMs;
constexpr bus::Ticks kS = bus::kTicksPerSecond;
using K = PlanFault::Kind;
const std::string kFile = PBVBUS_SOURCE_DIR "/examples/test.textproto";

const std::string kTable =
    R"(io { module_index: 0 table { row { at: "0s" value: 0 } row { at: "4s" value: 1 } row { at: "5s" value: 0 } } })";

std::string head(const std::string& pair) {
  return R"(name: "red-io"
duration: "7500ms"
line { name: "DP_A" baud: "1.5M" }
line { name: "DP_B" baud: "1.5M" }
dp_master { address: 1 line: "DP_A" watchdog: "100ms" }
dp_master { address: 1 line: "DP_B" watchdog: "100ms" }
redundant_master_system { name: "S" line_a: "DP_A" master_a: 1 line_b: "DP_B" master_b: 1 }
switched_station { system: "S" address: 3 gsd: "gsd/PBVB0A10.gsd" modules: ["16DI DC24V", "16DO DC24V/0.5A"] }
dp_slave { address: 20 line: "DP_A" gsd: "gsd/PBVB0A02.gsd" master: 1 modules: ["8DI DC24V", "8DO DC24V/0.5A"] )" +
         kTable + R"( }
dp_slave { address: 22 line: "DP_B" gsd: "gsd/PBVB0A02.gsd" master: 1 modules: ["8DI DC24V", "8DO DC24V/0.5A"] )" +
         kTable + R"( }
h_system {
  name: "H"
  dp_system { system: "S" t_pto: "1250ms" }
  cpu { cpu0 { power_on: "0s" } cpu1 { power_on: "0s" } startup_time: "1s" link_up_time: "2s" }
  program { scan_time: "10ms" copy { from_input: 2 to_output: 2 } }
  )" + pair + R"(
}
)";
}

const std::string kPair =
    R"(redundant_io { kind: DI module_a { system: "S" address: 20 module: "8DI DC24V" } module_b { system: "S" address: 22 module_index: 0 } discrepancy_time: "100ms" })";
const std::string kFaults = R"(fault { at: "3500ms" repair_at: "6s" channel_stuck { line: "DP_B" address: 22 module_index: 0 stuck_value: 0 } }
fault { at: "7s" red_depa { } }
)";

std::vector<std::string> errors_of(const std::string& text) {
  return test::scenario_errors(text, kFile);
}

TEST(HRedIoScenario, PairAndFaultsArePlanned) {
  const auto r = parse_scenario(head(kPair) + kFaults, kFile);
  ASSERT_TRUE(r.ok()) << r.errors[0].str();
  const HRuntimePlan& rt = *r.plan->h_systems.at(0).runtime;
  ASSERT_EQ(rt.redundant_io.size(), 1u);
  const HRedIoPlan& p = rt.redundant_io[0];
  EXPECT_EQ(p.spec.kind, devices::RedIoKind::DI);
  EXPECT_EQ(p.spec.discrepancy_time, 100 * kMs);
  EXPECT_EQ(p.system[0], 0);
  EXPECT_EQ(p.station[0], 20);
  EXPECT_EQ(p.module[0], 0u);
  EXPECT_EQ(p.station[1], 22);
  const auto& f = r.plan->faults;
  ASSERT_EQ(f.size(), 2u);
  EXPECT_EQ(f[0].kind, K::ChannelStuck);
  EXPECT_EQ(f[0].slave, 22);
  EXPECT_EQ(f[0].module, 0u);
  EXPECT_EQ(f[0].repair_at, 6 * kS);
  EXPECT_EQ(f[0].description, "inputs of module 0 (8DI DC24V) of DP slave 22 on line DP_B stuck at 0");
  EXPECT_FALSE(is_h_fault(K::ChannelStuck));
  EXPECT_EQ(f[1].kind, K::RedDepa);
  EXPECT_TRUE(is_h_fault(K::RedDepa));
  EXPECT_EQ(f[1].description, "FC 451 RED_DEPA (depassivation of the redundant I/O)");
}

bool has_error(const std::vector<std::string>& errs, const std::string& text) {
  for (const auto& e : errs)
    if (e.find(text) != std::string::npos) return true;
  return false;
}

TEST(HRedIoScenario, BadPairsAreRefused) {
  auto e = errors_of(head(R"(redundant_io { module_a { system: "T" address: 20 module_index: 0 } module_b { system: "S" address: 22 module_index: 0 } discrepancy_time: "1s" })"));
  EXPECT_TRUE(has_error(e, "redundant_io: \"T\" is not a redundant_master_system this h_system drives"))
      << (e.empty() ? "" : e[0]);
  e = errors_of(head(R"(redundant_io { module_a { system: "S" address: 21 module_index: 0 } module_b { system: "S" address: 22 module_index: 0 } discrepancy_time: "1s" })"));
  EXPECT_TRUE(has_error(e, "redundant_master_system \"S\" has no station 21")) << (e.empty() ? "" : e[0]);
  e = errors_of(head(R"(redundant_io { module_a { system: "S" address: 20 module_index: 2 } module_b { system: "S" address: 22 module_index: 0 } discrepancy_time: "1s" })"));
  EXPECT_TRUE(has_error(e, "module_index 2 is not below the 2 modules of station 20")) << (e.empty() ? "" : e[0]);
  e = errors_of(head(R"(redundant_io { module_a { system: "S" address: 20 module_index: 0 } module_b { system: "S" address: 22 module_index: 0 } })"));
  EXPECT_TRUE(has_error(e, "an input pair needs a discrepancy_time")) << (e.empty() ? "" : e[0]);
  e = errors_of(head(R"(redundant_io { module_a { system: "S" address: 20 module_index: 0 } module_b { system: "S" address: 20 module_index: 0 } discrepancy_time: "1s" })"));
  EXPECT_TRUE(has_error(e, "module_a and module_b are the same module")) << (e.empty() ? "" : e[0]);
}

TEST(HRedIoScenario, RunShows7960ThenPassivationAndFc451) {
  const test::ScenarioRun done = test::run_scenario(head(kPair) + kFaults, kFile);
  ASSERT_TRUE(done.report) << done.error;
  const Report& rep = *done.report;
  ASSERT_EQ(rep.h_systems.size(), 1u);
  const auto& io = rep.h_systems[0].io_events;
  auto find = [&](std::uint16_t code) -> const HIoEvent* {
    for (const auto& e : io)
      if (e.code == code) return &e;
    return nullptr;
  };
  const std::vector<int> both{0, 1};
  const HIoEvent* disc = find(0x7960);
  ASSERT_NE(disc, nullptr);
  // The change reaches the PII within a DP cycle and one 10 ms scan; 7960 100 ms after that.
  EXPECT_GE(disc->at, 4100 * kMs);
  EXPECT_LE(disc->at, 4130 * kMs);
  EXPECT_EQ(disc->racks, both);
  const HIoEvent* pass = find(0x7961);
  ASSERT_NE(pass, nullptr);
  EXPECT_GT(pass->at, 5000 * kMs);
  EXPECT_LE(pass->at, 5030 * kMs);
  EXPECT_NE(pass->text.find("module_H (IB 3) passivated"), std::string::npos) << pass->text;
  const HIoEvent* depa = find(0x7963);
  ASSERT_NE(depa, nullptr);
  EXPECT_GE(depa->at, 7000 * kMs);
  EXPECT_LE(depa->at, 7010 * kMs);
  // Every other redundant-I/O entry is absent: no second 7960, no OB-driven passivation.
  int n = 0;
  for (const auto& e : io) n += (e.code & 0xFFF0) == 0x7960 ? 1 : 0;
  EXPECT_EQ(n, 3);
}

}  // namespace
}  // namespace pbvbus::tools
