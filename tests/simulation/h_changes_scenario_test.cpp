// The scenario faults ps_failure (F1 with a PS 407 10A R pair) and checksum_error (001 Table
// 5-6) (docs/h-changes.md, docs/h-scenarios.md): planned with their descriptions, refused with
// FILE:LINE:COLUMN, and run through the Simulation (HSystemNode -> HSystemModel -> HCpuPair).
//
// The run (pair defaults: startup 1 s, link-up 2 s, update 145 ms):
//   0 s       both CPUs on: 1 s CPU 0 RUN (Solo), 3 s UPDATE, 3.145 s Redundant (CPU 0 master)
//   5 s       half 1 of rack 0's PS fails: W#16#3923 on CPU 0, nothing else
//   6 s       half 0 fails too: CPU 0 off (F1), CPU 1 master, OB 72 (master CPU lost)
//   8 s       half 0 replaced: power back, CPU 0 links up as standby: 8 + 2 = 10 s UPDATE,
//             10.145 s Redundant (CPU 1 master)
//   9 s       half 1 replaced: W#16#3823 on CPU 0
//   12 s      checksum error on CPU 0 (standby, Redundant): CPU 0 ERROR-SEARCH, OB 72
//             (checksum error) on CPU 1, Solo
#include <gtest/gtest.h>

#include <algorithm>
#include <string>
#include <vector>

#include "scenario_run_support.hpp"
#include "pbvbus/scenario/scenario.hpp"
#include "pbvbus/simulation/simulation.hpp"

namespace pbvbus::tools {
namespace {

constexpr bus::Ticks kMs = bus::kTicksPerMs;
constexpr bus::Ticks kS = bus::kTicksPerSecond;
using K = PlanFault::Kind;

const std::string kText = R"(name: "h-changes"
duration: "15s"
h_system {
  name: "H-CPU"
  cpu { cpu0 { power_on: "0s" } cpu1 { power_on: "0s" } }
}
fault { at: "5s" repair_at: "9s" ps_failure { rack: 0 half: 1 } }
fault { at: "6s" repair_at: "8s" ps_failure { rack: 0 half: 0 } }
fault { at: "12s" checksum_error { rack: 0 } }
)";

TEST(HChangesScenario, FaultsArePlannedWithTheirDescriptions) {
  const auto r = parse_scenario(kText, "h.textproto");
  ASSERT_TRUE(r.ok()) << r.errors[0].str();
  const auto& f = r.plan->faults;
  ASSERT_EQ(f.size(), 3u);
  EXPECT_EQ(f[0].kind, K::PsFailure);
  EXPECT_EQ(f[0].rack, 0);
  EXPECT_EQ(f[0].half, 1);
  EXPECT_EQ(f[0].line, -1);
  ASSERT_TRUE(f[0].repair_at.has_value());
  EXPECT_EQ(*f[0].repair_at, 9 * kS);
  EXPECT_EQ(f[0].description, "PS 407 10A R half 1 of rack 0 fails");
  EXPECT_EQ(f[2].kind, K::ChecksumError);
  EXPECT_EQ(f[2].rack, 0);
  EXPECT_EQ(f[2].description, "CPU 0 (rack 0): checksum error in the cyclic self-test");
  EXPECT_TRUE(is_h_fault(K::PsFailure));
  EXPECT_TRUE(is_h_fault(K::ChecksumError));
}

// Columns by hand: `fault { at: "1s" ` is 17 characters -> repair_at and the kind at 18;
// `ps_failure { ` is 13 more -> its first field at 31; `rack: 0 ` 8 more -> half at 39.
TEST(HChangesScenario, RefusalsCarryTheirPositions) {
  const std::string text = R"(h_system { name: "H" cpu { } }
fault { at: "1s" ps_failure { rack: 0 half: 2 } }
fault { at: "1s" ps_failure { rack: 0 } }
fault { at: "1s" ps_failure { half: 0 } }
fault { at: "1s" repair_at: "2s" checksum_error { rack: 0 } }
fault { at: "1s" checksum_error { } }
)";
  EXPECT_EQ(test::scenario_errors(text, "h.textproto"),
            (std::vector<std::string>{
                "h.textproto:2:39: ps_failure: half 2 is not 0 or 1",
                "h.textproto:3:18: ps_failure needs a half: half: 0 or half: 1 (the PS of the "
                "PS 407 10A R pair)",
                "h.textproto:4:18: ps_failure needs a rack: rack: 0 or rack: 1",
                "h.textproto:5:18: checksum_error has no repair: remove repair_at",
                "h.textproto:6:18: checksum_error needs a rack: rack: 0 or rack: 1",
            }));
}

std::vector<std::pair<bus::Ticks, devices::HReason>> ob72(const HCpuReport& c) {
  std::vector<std::pair<bus::Ticks, devices::HReason>> v;
  for (const auto& t : c.timeline)
    if (t.kind == devices::HEvent::Kind::Ob && t.ob == 72) v.emplace_back(t.at, t.reason);
  return v;
}

TEST(HChangesScenario, RunShowsPsHalvesAndChecksumError) {
  const test::ScenarioRun run = test::run_scenario(kText, "h.textproto");
  ASSERT_TRUE(run.report) << run.error;
  const HSystemReport& h = run.report->h_systems.at(0);
  const HCpuReport& c0 = h.cpus[0];
  const HCpuReport& c1 = h.cpus[1];
  using R = devices::HReason;
  EXPECT_EQ(ob72(c1), (std::vector<std::pair<bus::Ticks, R>>{{6 * kS, R::MasterLost},
                                                              {12 * kS, R::ChecksumError}}));
  EXPECT_TRUE(ob72(c0).empty());
  std::vector<std::pair<bus::Ticks, std::uint16_t>> ps;
  for (const auto& d : c0.diag)
    if (d.code == 0x3923 || d.code == 0x3823) ps.emplace_back(d.at, d.code);
  EXPECT_EQ(ps, (std::vector<std::pair<bus::Ticks, std::uint16_t>>{{5 * kS, 0x3923},
                                                                    {9 * kS, 0x3823}}));
  EXPECT_EQ(c0.state, devices::CpuState::ErrorSearch);
  EXPECT_EQ(c1.role, devices::CpuRole::Master);
  EXPECT_EQ(h.mode, devices::SystemMode::Solo);
  const std::vector<std::pair<bus::Ticks, std::string>> want = {
      {5 * kS, "PS 407 10A R half 1 of rack 0 fails: the other half supplies the rack"},
      {6 * kS, "PS 407 10A R half 0 of rack 0 fails: no half left, the CPU fails"},
      {8 * kS, "repair of PS 407 10A R half 0 of rack 0 fails"},
      {9 * kS, "repair of PS 407 10A R half 1 of rack 0 fails"},
      {12 * kS, "CPU 0 (rack 0): checksum error in the cyclic self-test"},
  };
  EXPECT_EQ(h.faults, want);
}

// The scenario's master_swap goes through HConfigChange (docs/h-changes.md "In the H-system
// model"): CPU 1's switch at STOP; CPU 0 RUN at 1 s (STARTUP 1 s); the swap at 2 s: LINK-UP
// 2 -> 4 s, UPDATE 4 -> 4.145 s, CPU 1 master (OB 72 master swap), CPU 0 STOP; the cpu_stop's
// repair at 6 s restarts CPU 0: LINK-UP 6 -> 8 s, UPDATE 8 -> 8.145 s, Redundant, no swap back.
TEST(HChangesScenario, MasterSwapIsTheSwitchToCpuWithModifiedConfiguration) {
  const std::string text = R"(name: "h-swap"
duration: "9s"
h_system {
  name: "H-CPU"
  cpu { cpu0 { power_on: "0s" } cpu1 { power_on: "0s" switch: STOP } }
}
fault { at: "2s" master_swap { } }
fault { at: "5s" repair_at: "6s" cpu_stop { rack: 0 } }
)";
  const test::ScenarioRun run = test::run_scenario(text, "h.textproto");
  ASSERT_TRUE(run.report) << run.error;
  const HSystemReport& h = run.report->h_systems.at(0);
  const HCpuReport& c0 = h.cpus[0];
  const HCpuReport& c1 = h.cpus[1];
  const auto o = ob72(c1);
  ASSERT_FALSE(o.empty());
  EXPECT_EQ(o.front(), (std::pair<bus::Ticks, devices::HReason>{4145 * kMs,
                                                                devices::HReason::MasterSwap}));
  const std::string note =
      "PG/ES: switch to CPU with modified configuration: no blocks copied; data blocks as 5.2.3";
  const auto is_note = [&](const devices::DiagEntry& d) { return d.at == 2 * kS && d.text == note; };
  EXPECT_EQ(std::count_if(c0.diag.begin(), c0.diag.end(), is_note), 1);
  EXPECT_EQ(h.mode, devices::SystemMode::Redundant);
  EXPECT_EQ(c1.role, devices::CpuRole::Master);
}


// HCpuPair.param_transfer_time_100ms (001 L8094-8114; docs/h-changes.md) reaches the runtime
// plan as given; unset = 0 = off.
TEST(HChangesScenario, ParamTransferTimeIsPlanned) {
  const auto r = parse_scenario(R"(h_system { name: "H" cpu { param_transfer_time_100ms: 600 } })",
                                "h.textproto");
  ASSERT_TRUE(r.ok()) << r.errors[0].str();
  ASSERT_TRUE(r.plan->h_systems.at(0).runtime.has_value());
  EXPECT_EQ(r.plan->h_systems.at(0).runtime->param_transfer_time_100ms, 600u);
  const auto d = parse_scenario(R"(h_system { name: "H" cpu { } })", "h.textproto");
  ASSERT_TRUE(d.ok()) << d.errors[0].str();
  EXPECT_EQ(d.plan->h_systems.at(0).runtime->param_transfer_time_100ms, 0u);
}

}  // namespace
}  // namespace pbvbus::tools
