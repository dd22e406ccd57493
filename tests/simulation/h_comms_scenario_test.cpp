// The h_system cp / connection entries and the scenario fault cp_failure (F4; docs/h-scenarios.md
// "CPs and connections"): planned, refused with FILE:LINE:COLUMN where the file is wrong, and
// run through the Simulation (HSystemNode -> HSystemModel -> HConnections), asserted from the
// report's connection rows.
//
// The run (pair defaults: startup 1 s, link-up 2 s, update 75 ms + 0.7 ms x 100 KB = 145 ms):
//   0 s       both CPUs on: CPU 0 master STARTUP, CPU 1 standby in STOP
//   1 s       CPU 0 RUN (Solo) and at the same instant CPU 1 LINK-UP: R8, no connection is
//             set up on either CPU until the update ends
//   3.145 s   Redundant (1 + 2 + 0.145): OS (fault-tolerant, active over rack 0 CP 0, rack 1
//             CP 0 a reserve), PG (standard, rack 0 CP 0) and S5 (standard, rack 0 CP 1, a
//             CP 443-5) established
//   5 s       rack 0 CP 0 fails: PG lost, OS continues over rack 1 CP 0
//   8 s       the CP replaced: OS regains rack 0 CP 0 as a reserve; the partner re-establishes PG
//   10 s      CPU 1 (standby) fails: OS's active path goes, it continues over rack 0 CP 0
//   12 s      CPU 1 back: LINK-UP 12 s .. 14 s, UPDATE .. 14.145 s: OS regains rack 1 CP 0
#include <gtest/gtest.h>

#include <string>
#include <utility>
#include <vector>

#include "scenario_run_support.hpp"
#include "pbvbus/scenario/scenario.hpp"
#include "pbvbus/simulation/simulation.hpp"

namespace pbvbus::tools {
namespace {

constexpr bus::Ticks kMs = bus::kTicksPerMs;
constexpr bus::Ticks kS = bus::kTicksPerSecond;
using K = PlanFault::Kind;

const std::string kText = R"(name: "f4"
duration: "20s"
h_system {
  name: "H-CPU"
  cpu { cpu0 { power_on: "0s" } cpu1 { power_on: "0s" } }
  cp { rack: 0 index: 0 }
  cp { rack: 1 index: 0 }
  cp { rack: 0 index: 1 kind: CP_443_5 }
  connection { name: "OS" kind: FAULT_TOLERANT cp: 0 }
  connection { name: "PG" rack: 0 cp: 0 }
  connection { name: "S5" rack: 0 cp: 1 }
}
fault { at: "5s" repair_at: "8s" cp_failure { rack: 0 cp: 0 } }
fault { at: "10s" repair_at: "12s" cpu_failure { rack: 1 } }
)";

std::vector<std::string> errors_of(const std::string& text) {
  return test::scenario_errors(text, "h.textproto");
}

TEST(HCommsScenario, CpsConnectionsAndTheFaultArePlanned) {
  const auto r = parse_scenario(kText, "h.textproto");
  ASSERT_TRUE(r.ok()) << r.errors[0].str();
  const HRuntimePlan& rt = *r.plan->h_systems.at(0).runtime;
  ASSERT_EQ(rt.cps.size(), 3u);
  EXPECT_EQ(rt.cps[2].rack, 0);
  EXPECT_EQ(rt.cps[2].index, 1);
  EXPECT_EQ(rt.cps[2].kind, devices::CpKind::Cp443_5);
  ASSERT_EQ(rt.connections.size(), 3u);
  EXPECT_EQ(rt.connections[0].name, "OS");
  EXPECT_EQ(rt.connections[0].kind, devices::ConnectionKind::FaultTolerant);
  EXPECT_EQ(rt.connections[1].kind, devices::ConnectionKind::Standard);
  EXPECT_EQ(rt.connections[2].cp, 1);
  const auto& f = r.plan->faults;
  ASSERT_EQ(f.size(), 2u);
  EXPECT_EQ(f[0].kind, K::CpFailure);
  EXPECT_EQ(f[0].at, 5 * kS);
  EXPECT_EQ(f[0].repair_at, 8 * kS);
  EXPECT_EQ(f[0].rack, 0);
  EXPECT_EQ(f[0].cp, 0);
  EXPECT_EQ(f[0].line, -1);
  EXPECT_EQ(f[0].description, "CP 0 in rack 0 fails (F4)");
  EXPECT_TRUE(is_h_fault(K::CpFailure));
}

// Columns by hand (1-based): line 3 `  cp { rack: 0 ` is 15 characters -> index at 16; line 4
// the cp entry at 3; line 5 `  connection { ` 15 + `name: "X" ` 10 + `kind: FAULT_TOLERANT ` 21
// = 46 -> cp at 47; line 6 the connection at 3; line 8 `fault { at: "1s" ` 17 -> kind at 18,
// `cp_failure { ` 13 + `rack: 1 ` 8 -> cp at 39.
TEST(HCommsScenario, RefusalsCarryTheirPositions) {
  const std::string text = R"(h_system { name: "H" cpu { }
  cp { rack: 0 index: 0 }
  cp { rack: 0 index: 0 }
  cp { index: 1 }
  connection { name: "X" kind: FAULT_TOLERANT cp: 0 }
  connection { name: "Y" cp: 0 }
}
fault { at: "1s" cp_failure { rack: 1 cp: 0 } }
fault { at: "1s" cp_failure { rack: 0 } }
)";
  EXPECT_EQ(errors_of(text),
            (std::vector<std::string>{
                "h.textproto:3:16: cp: rack 0 already has a CP 0",
                "h.textproto:4:3: cp needs a rack: rack: 0 or rack: 1",
                "h.textproto:5:47: connection \"X\": a fault-tolerant connection needs one or two "
                "CP 443-1 in each rack, the same number (found 1 and 0)",
                "h.textproto:6:3: connection \"Y\": a standard connection needs a rack",
                "h.textproto:8:39: cp_failure: rack 1 has no CP 0 (h_system cp entries)",
                "h.textproto:9:18: cp_failure needs a cp: the CP's index in the rack (an h_system "
                "cp entry)",
            }));
  // `h_system { name: "T" ` is 21 characters -> cp at 22.
  EXPECT_EQ(errors_of("h_system { name: \"T\" cp { rack: 0 } }\n"),
            (std::vector<std::string>{"h.textproto:1:22: h_system \"T\": cp and connection entries "
                                      "need a cpu part (the simulated pair)"}));
}

TEST(HCommsScenario, RunShowsF4StandardLostFaultTolerantSwitchedAndBack) {
  const test::ScenarioRun run = test::run_scenario(kText, "h.textproto");
  ASSERT_TRUE(run.report) << run.error;
  const Report& r = *run.report;
  ASSERT_EQ(r.h_systems.size(), 1u);
  const HSystemReport& h = r.h_systems[0];
  ASSERT_EQ(h.connections.size(), 3u);
  using Ev = std::vector<std::pair<bus::Ticks, std::string>>;
  const HConnectionRow& os = h.connections[0];
  EXPECT_EQ(os.name, "OS");
  EXPECT_EQ(os.kind, "fault-tolerant");
  EXPECT_EQ(os.state, "established");
  EXPECT_EQ(os.active, "CP 443-1 rack 0 CP 0");
  const bus::Ticks redundant1 = 1 * kS + 2 * kS + 145 * kMs;   // 3.145 s
  const bus::Ticks redundant2 = 12 * kS + 2 * kS + 145 * kMs;  // 14.145 s
  EXPECT_EQ(os.events,
            (Ev{{redundant1, "connection OS established over CP 443-1 rack 0 CP 0"},
                {5 * kS, "connection OS: active path CP 443-1 rack 0 CP 0 down (CP failed), continues "
                         "over CP 443-1 rack 1 CP 0"},
                {8 * kS, "connection OS: path CP 443-1 rack 0 CP 0 back as a reserve"},
                {10 * kS, "connection OS: active path CP 443-1 rack 1 CP 0 down (CPU off), continues "
                          "over CP 443-1 rack 0 CP 0"},
                {redundant2, "connection OS: path CP 443-1 rack 1 CP 0 back as a reserve"}}));
  const HConnectionRow& pg = h.connections[1];
  EXPECT_EQ(pg.kind, "standard");
  EXPECT_EQ(pg.state, "established");
  EXPECT_EQ(pg.events,
            (Ev{{redundant1, "connection PG established over CP 443-1 rack 0 CP 0"},
                {5 * kS, "connection PG lost: CP 443-1 rack 0 CP 0 down (CP failed)"},
                {8 * kS, "connection PG re-established over CP 443-1 rack 0 CP 0"}}));
  const HConnectionRow& s5 = h.connections[2];
  EXPECT_EQ(s5.active, "CP 443-5 rack 0 CP 1");
  EXPECT_EQ(s5.events, (Ev{{redundant1, "connection S5 established over CP 443-5 rack 0 CP 1"}}));
  // Both CPUs log the CP failure (000 §9.1.4).
  for (int rack = 0; rack < 2; ++rack) {
    bool logged = false;
    for (const auto& d : h.cpus[static_cast<std::size_t>(rack)].diag)
      logged = logged || (d.at == 5 * kS && d.text == "CP 443-1 rack 0 CP 0 failed (F4)");
    EXPECT_TRUE(logged) << rack;
  }
  const Ev want_faults{{5 * kS, "CP 0 in rack 0 fails (F4)"},
                       {8 * kS, "repair of CP 0 in rack 0 fails (F4)"},
                       {10 * kS, "CPU 1 (rack 1) fails"},
                       {12 * kS, "repair of CPU 1 (rack 1) fails"}};
  EXPECT_EQ(h.faults, want_faults);
}

}  // namespace
}  // namespace pbvbus::tools
