// The scenario faults load_memory_error (F2) and sync_error (F18) (docs/h-scenarios.md "The H
// faults"): planned with their descriptions, refused with FILE:LINE:COLUMN where the file is
// wrong, and run through the Simulation (HSystemNode -> HSystemModel -> HCpuPair), asserted from
// the report's timeline rows, OB 72 rows and applied faults.
//
// The run (pair defaults: startup 1 s, link-up 2 s, update 75 ms + 0.7 ms x 100 KB = 145 ms):
//   0 s       both CPUs on together: CPU 0 master STOP -> STARTUP, CPU 1 standby in STOP
//   1 s       CPU 0 RUN (Solo), CPU 1 LINK-UP; 3 s UPDATE (1 + 2); 3.145 s Redundant
//   5 s       F2 on CPU 0 (master): CPU 0 RUN -> STOP with a reset request, CPU 1 master,
//             OB 72 (master CPU in STOP) on CPU 1, Solo
//   6 s / 7 s cpu_stop on CPU 0 and its repair: the STOP -> RUN at 7 s is refused (reset request)
//   10 s      memory_reset of CPU 0: the reset request is cleared, CPU 0 stays in STOP
//   11 s/12 s cpu_stop on CPU 0 and its repair: STOP -> RUN at 12 s: LINK-UP 12 s -> 14 s,
//             UPDATE -> 14.145 s Redundant (CPU 1 master)
//   20 s      F18: the standby (CPU 0) STOPs, OB 72 (standby CPU in STOP) on CPU 1, Solo
//   25 s      F18 again: Solo, nothing happens (the report's fault text says so)
#include <gtest/gtest.h>

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

const std::string kText = R"(name: "f2-f18"
duration: "30s"
h_system {
  name: "H-CPU"
  cpu { cpu0 { power_on: "0s" } cpu1 { power_on: "0s" } }
}
fault { at: "5s" load_memory_error { rack: 0 } }
fault { at: "6s" repair_at: "7s" cpu_stop { rack: 0 } }
fault { at: "10s" memory_reset { rack: 0 } }
fault { at: "11s" repair_at: "12s" cpu_stop { rack: 0 } }
fault { at: "20s" sync_error { } }
fault { at: "25s" sync_error { h_system: "H-CPU" } }
)";

std::vector<std::string> errors_of(const std::string& text) {
  return test::scenario_errors(text, "h.textproto");
}

bool has_row(const HCpuReport& c, bus::Ticks at, const std::string& change) {
  for (const auto& t : c.timeline)
    if (t.at == at && t.change == change) return true;
  return false;
}

std::vector<std::pair<bus::Ticks, devices::HReason>> ob72(const HCpuReport& c) {
  std::vector<std::pair<bus::Ticks, devices::HReason>> v;
  for (const auto& t : c.timeline)
    if (t.kind == devices::HEvent::Kind::Ob && t.ob == 72) v.emplace_back(t.at, t.reason);
  return v;
}

TEST(HF2F18Scenario, FaultsArePlannedWithTheirDescriptions) {
  const auto r = parse_scenario(kText, "h.textproto");
  ASSERT_TRUE(r.ok()) << r.errors[0].str();
  const auto& f = r.plan->faults;
  ASSERT_EQ(f.size(), 6u);
  EXPECT_EQ(f[0].kind, K::LoadMemoryError);
  EXPECT_EQ(f[0].at, 5 * kS);
  EXPECT_EQ(f[0].rack, 0);
  EXPECT_EQ(f[0].h_system, 0);
  EXPECT_EQ(f[0].line, -1);
  EXPECT_FALSE(f[0].repair_at.has_value());
  EXPECT_EQ(f[0].description, "CPU 0 (rack 0): load-memory access error");
  EXPECT_TRUE(is_h_fault(K::LoadMemoryError));
  EXPECT_EQ(f[4].kind, K::SyncError);
  EXPECT_EQ(f[4].at, 20 * kS);
  EXPECT_EQ(f[4].rack, -1);
  EXPECT_EQ(f[4].description, "sync error (diverging uninitialised data)");
  EXPECT_EQ(f[5].kind, K::SyncError);
  EXPECT_EQ(f[5].h_system, 0);
  EXPECT_TRUE(is_h_fault(K::SyncError));
}

// Columns by hand: `fault { at: "1s" ` is 17 characters -> repair_at and the kind at 18;
// `load_memory_error { ` is 20 more -> rack at 38.
TEST(HF2F18Scenario, RefusalsCarryTheirPositions) {
  const std::string text = R"(h_system { name: "H" cpu { } }
fault { at: "1s" load_memory_error { rack: 2 } }
fault { at: "1s" repair_at: "2s" load_memory_error { rack: 0 } }
fault { at: "1s" repair_at: "2s" sync_error { } }
fault { at: "1s" load_memory_error { } }
fault { at: "1s" sync_error { h_system: "X" } }
)";
  EXPECT_EQ(errors_of(text),
            (std::vector<std::string>{
                "h.textproto:2:38: load_memory_error: rack 2 is not 0 or 1",
                "h.textproto:3:18: load_memory_error has no repair: remove repair_at (the repair "
                "is a memory_reset fault, then a cpu_stop repair)",
                "h.textproto:4:18: sync_error has no repair: remove repair_at",
                "h.textproto:5:18: load_memory_error needs a rack: rack: 0 or rack: 1",
                // `sync_error { ` is 13 after column 18 -> h_system at 31.
                "h.textproto:6:31: sync_error: no h_system \"X\"",
            }));
  // No simulated pair at all.
  EXPECT_EQ(errors_of("h_system { name: \"T\" }\nfault { at: \"1s\" sync_error { } }\n"),
            (std::vector<std::string>{
                "h.textproto:2:18: sync_error: the scenario has no h_system with a cpu part"}));
}

TEST(HF2F18Scenario, RunShowsStopResetRequestAndSyncError) {
  const test::ScenarioRun run = test::run_scenario(kText, "h.textproto");
  ASSERT_TRUE(run.report) << run.error;
  const Report& r = *run.report;
  ASSERT_EQ(r.h_systems.size(), 1u);
  const HSystemReport& h = r.h_systems[0];
  const HCpuReport& c0 = h.cpus[0];
  const HCpuReport& c1 = h.cpus[1];
  // Up to Redundant: 1 s RUN, 1 + 2 = 3 s UPDATE, 3 + 0.145 = 3.145 s RUN.
  EXPECT_TRUE(has_row(c0, 1000 * kMs, "CPU 0: STARTUP -> RUN"));
  EXPECT_TRUE(has_row(c1, 3145 * kMs, "CPU 1: UPDATE -> RUN"));
  // F2 at 5 s.
  EXPECT_TRUE(has_row(c0, 5 * kS, "CPU 0: RUN -> STOP"));
  EXPECT_TRUE(has_row(c1, 5 * kS, "CPU 1: role standby -> master"));
  EXPECT_TRUE(has_row(c1, 5 * kS, "CPU 1: OB 72 (master CPU in STOP)"));
  // The STOP -> RUN at 7 s is refused: no state row for CPU 0 between 5 s and 12 s.
  for (const auto& t : c0.timeline) {
    if (t.kind == devices::HEvent::Kind::State) {
      EXPECT_FALSE(t.at > 5 * kS && t.at < 12 * kS) << t.change;
    }
  }
  // After the memory reset (10 s), the STOP -> RUN at 12 s: 12 + 2 = 14 s, + 0.145 = 14.145 s.
  EXPECT_TRUE(has_row(c0, 12 * kS, "CPU 0: STOP -> LINK-UP"));
  EXPECT_TRUE(has_row(c0, 14 * kS, "CPU 0: LINK-UP -> UPDATE"));
  EXPECT_TRUE(has_row(c0, 14145 * kMs, "CPU 0: UPDATE -> RUN"));
  // F18 at 20 s: the standby (CPU 0) STOPs.
  EXPECT_TRUE(has_row(c0, 20 * kS, "CPU 0: RUN -> STOP"));
  EXPECT_TRUE(has_row(c1, 20 * kS, "CPU 1: OB 72 (standby CPU in STOP)"));
  using R = devices::HReason;
  EXPECT_EQ(ob72(c1), (std::vector<std::pair<bus::Ticks, R>>{{5 * kS, R::MasterStop},
                                                              {20 * kS, R::StandbyStop}}));
  EXPECT_TRUE(ob72(c0).empty());
  EXPECT_EQ(h.mode, devices::SystemMode::Solo);
  EXPECT_EQ(c1.role, devices::CpuRole::Master);
  EXPECT_EQ(c0.state, devices::CpuState::Stop);
  bool sync_entry = false;
  for (const auto& d : c0.diag)
    sync_entry = sync_entry ||
                 (d.at == 20 * kS &&
                  d.text == "sync error (F18): diverging uninitialised data; standby rack 0 to STOP");
  EXPECT_TRUE(sync_entry);
  // The faults as applied, with what the pair answered.
  const std::vector<std::pair<bus::Ticks, std::string>> want = {
      {5 * kS, "CPU 0 (rack 0): load-memory access error"},
      {6 * kS, "CPU 0 (rack 0): mode switch to STOP"},
      {7 * kS, "repair of CPU 0 (rack 0): mode switch to STOP"},
      {10 * kS, "memory reset of CPU 0 (rack 0) after its reset request"},
      {11 * kS, "CPU 0 (rack 0): mode switch to STOP"},
      {12 * kS, "repair of CPU 0 (rack 0): mode switch to STOP"},
      {20 * kS, "sync error (diverging uninitialised data)"},
      {25 * kS, "sync error (diverging uninitialised data): not in Redundant mode, nothing happens"},
  };
  EXPECT_EQ(h.faults, want);
}

}  // namespace
}  // namespace pbvbus::tools
