// The scenario's expansion racks (HSystem.expansion_rack, F8), HCpuPair.max_cycle_time and the
// faults expansion_rack_failure and cycle_overload (docs/h-scenarios.md): planned, refused with
// FILE:LINE:COLUMN where the file is wrong, and run through the Simulation (HSystemNode ->
// HSystemModel), asserted from the report.
//
// The run (pair defaults: startup 1 s, link-up 2 s, update 75 ms + 0.7 ms x 100 KB = 145 ms; no
// DP master system; OB 1 every 10 ms from 1000 ms; the one due at t3 = 3000 ms is dropped, OB 1
// again at t5 = 3145 ms):
//   0 s       both CPUs on: CPU 0 master, RUN (Solo) at 1 s; CPU 1 LINK-UP 1..3 s, UPDATE ->
//             Redundant at 3.145 s. Rack 3 (CPU 0) is read from 1 s, rack 9 (CPU 1) from 3.145 s.
//   3.203 s   rack 3 off: OB 86 W#16#39C1 on both; OB 85 W#16#39B1 at the OB 1 at 3.205 s
//   3.302 s   rack 3 back: OB 86 W#16#38C1 on both; OB 85 W#16#38B1 at 3.305 s
//   3.503 s   cycle_overload 95 ms: the OB 1 at 3.505 s lasts 105 ms > max_cycle_time 100 ms:
//             OB 80 W#16#3501 at 3.505 + 0.1 = 3.605 s on both; next OB 1 at 3.610 s
// The update's cycle (2.990 -> 3.145 s = 155 ms > 100 ms) gives no OB 80: no H parameters are
// configured, so the update's cycle is not monitored (docs/h-system.md).
#include <gtest/gtest.h>

#include <sstream>
#include <string>
#include <vector>

#include "scenario_run_support.hpp"
#include "pbvbus/simulation/h_report.hpp"
#include "pbvbus/scenario/scenario.hpp"
#include "pbvbus/simulation/simulation.hpp"
#include "pbvbus/reports/run_report.hpp"

namespace pbvbus::tools {
namespace {

constexpr bus::Ticks kMs = bus::kTicksPerMs;
using K = PlanFault::Kind;

const std::string kText = R"(name: "racks"
duration: "3995ms"
h_system {
  name: "H"
  cpu { cpu0 { power_on: "0s" } cpu1 { power_on: "0s" } max_cycle_time: "100ms" }
  program { copy { from_input: 0 to_output: 0 length: 2 } }
  expansion_rack {
    number: 3 side: 0
    module { name: "DI16" in_len: 2 counter { } }
    module { name: "DO16" out_len: 2 }
  }
  expansion_rack {
    number: 9 side: 1
    module { name: "DIO8" in_len: 1 out_len: 1 constant { value: 165 } }
  }
}
fault { at: "3203ms" repair_at: "3302ms" expansion_rack_failure { number: 3 } }
fault { at: "3503ms" cycle_overload { extra: "95ms" } }
)";

std::vector<std::string> errors_of(const std::string& text) {
  return test::scenario_errors(text, "h.textproto");
}

TEST(HRacksScenario, RacksAndFaultsArePlanned) {
  const auto r = parse_scenario(kText, "h.textproto");
  ASSERT_TRUE(r.ok()) << r.errors[0].str();
  const HRuntimePlan& rt = *r.plan->h_systems.at(0).runtime;
  EXPECT_EQ(rt.max_cycle_time, 100 * kMs);
  ASSERT_EQ(rt.racks.size(), 2u);
  EXPECT_EQ(rt.racks[0].number, 3);
  EXPECT_EQ(rt.racks[0].side, 0);
  ASSERT_EQ(rt.racks[0].modules.size(), 2u);
  EXPECT_EQ(rt.racks[0].modules[0].name, "DI16");
  EXPECT_EQ(rt.racks[0].modules[0].in_len, 2u);
  EXPECT_EQ(rt.racks[0].modules[0].inputs.kind, devices::IoBehaviour::Kind::Counter);
  EXPECT_EQ(rt.racks[0].modules[1].out_len, 2u);
  EXPECT_EQ(rt.racks[1].number, 9);
  EXPECT_EQ(rt.racks[1].side, 1);
  EXPECT_EQ(rt.racks[1].modules[0].inputs.constant, (std::vector<std::uint8_t>{0xA5}));
  const auto& f = r.plan->faults;
  ASSERT_EQ(f.size(), 2u);
  EXPECT_EQ(f[0].kind, K::ExpansionRackFailure);
  EXPECT_EQ(f[0].at, 3203 * kMs);
  EXPECT_EQ(f[0].repair_at, 3302 * kMs);
  EXPECT_EQ(f[0].rack_number, 3);
  EXPECT_EQ(f[0].rack, 0);
  EXPECT_EQ(f[0].description, "expansion rack 3 of CPU 0 off (IM 460/461)");
  EXPECT_EQ(f[1].kind, K::CycleOverload);
  EXPECT_EQ(f[1].extra, 95 * kMs);
  EXPECT_EQ(f[1].description, "OB 1 overload: the next OB 1 lasts 95 ms longer");
  EXPECT_TRUE(is_h_fault(K::ExpansionRackFailure));
  EXPECT_TRUE(is_h_fault(K::CycleOverload));
}

TEST(HRacksScenario, BadRacksAndFaultsAreRefusedWithTheirPlace) {
  const std::string text = R"(h_system { name: "H" cpu { max_cycle_time: "0s" }
  expansion_rack { number: 22 side: 0 module { in_len: 1 } }
  expansion_rack { side: 1 module { in_len: 1 } }
  expansion_rack { number: 4 side: 2 module { name: "X" } }
  expansion_rack { number: 5 side: 0 module { in_len: 1 echo { } } }
}
fault { at: "1s" expansion_rack_failure { number: 6 } }
fault { at: "1s" cycle_overload { } }
fault { at: "1s" cycle_overload { extra: "0s" } }
)";
  // Columns: line 2 "  expansion_rack { " is 19 wide -> number at 20; line 4 "number: 4 " 10
  // more -> side at 30, "side: 2 " 8 more -> module at 38; line 5 "module { in_len: 1 " 19 more
  // after 38 -> echo at 57; line 1 "h_system { name: \"H\" cpu { " 27 -> max_cycle_time at 28;
  // line 7 "fault { at: \"1s\" " 17 -> the kind at 18, "expansion_rack_failure { " 25 more ->
  // number at 43; line 9 "cycle_overload { " 17 more -> extra at 35.
  EXPECT_EQ(errors_of(text),
            (std::vector<std::string>{
                "h.textproto:2:20: expansion rack number 22 is not 1..21",
                "h.textproto:3:3: expansion rack needs a number: number: 1..21",
                "h.textproto:4:30: expansion rack 4: side 2 is not 0 or 1",
                "h.textproto:4:38: expansion rack 4 module \"X\": in_len and out_len are both 0",
                "h.textproto:5:57: expansion rack 5 module \"module 0\": echo source module 0 has no outputs",
                "h.textproto:1:28: max_cycle_time must be longer than 0",
                // No rack was planned (each had an error): rack 6 is unknown anyway.
                "h.textproto:7:43: expansion_rack_failure: h_system \"H\" has no expansion_rack 6",
                "h.textproto:8:18: cycle_overload needs extra: how much longer the next OB 1 lasts, e.g. \"200ms\"",
                "h.textproto:9:35: cycle_overload: extra must be longer than 0",
            }));
  // "h_system { name: \"T\" " is 21 wide -> expansion_rack at 22.
  EXPECT_EQ(errors_of("h_system { name: \"T\" expansion_rack { number: 1 side: 0 } }\n"),
            (std::vector<std::string>{
                "h.textproto:1:22: h_system \"T\": expansion racks need a cpu part (the simulated pair)"}));
}

TEST(HRacksScenario, RunReportsRacksOb86Ob85AndOb80) {
  const test::ScenarioRun run = test::run_scenario(kText, "h.textproto");
  ASSERT_TRUE(run.report) << run.error;
  const Report& r = *run.report;
  ASSERT_EQ(r.h_systems.size(), 1u);
  const HSystemReport& h = r.h_systems[0];

  // The map: rack 3's DI16 at IB 0..1, its DO16 at QB 0..1; rack 9's DIO8 at IB 2 / QB 2.
  ASSERT_EQ(h.io_map.size(), 3u);
  EXPECT_EQ(h.io_map[0].rack, 3);
  EXPECT_EQ(h.io_map[0].in_addr, 0u);
  EXPECT_EQ(h.io_map[1].out_addr, 0u);
  EXPECT_EQ(h.io_map[2].rack, 9);
  EXPECT_EQ(h.io_map[2].in_addr, 2u);
  EXPECT_EQ(h.io_map[2].out_addr, 2u);

  struct Row {
    bus::Ticks at;
    int ob;
    std::uint16_t code;
  };
  std::vector<Row> got;
  for (const auto& e : h.io_events) {
    EXPECT_EQ(e.racks, (std::vector<int>{0, 1})) << e.text;  // Redundant: on both
    got.push_back({e.at, e.ob, e.code});
  }
  const std::vector<Row> want{{3203 * kMs, 86, 0x39C1}, {3205 * kMs, 85, 0x39B1},
                              {3302 * kMs, 86, 0x38C1}, {3305 * kMs, 85, 0x38B1},
                              {3605 * kMs, 80, 0x3501}};
  ASSERT_EQ(got.size(), want.size());
  for (std::size_t k = 0; k < want.size(); ++k) {
    EXPECT_EQ(got[k].at, want[k].at) << k;
    EXPECT_EQ(got[k].ob, want[k].ob) << k;
    EXPECT_EQ(got[k].code, want[k].code) << k;
  }
  EXPECT_EQ(h.ob80, 1u);

  // Rack 3's reads: 1000..2990 (200), 3145..3195 (6), 3305..3505 (21), 3610..3990 (39) = 266;
  // the last read shows 265 = 0x0109, which the copy network puts into DO16.
  ASSERT_EQ(h.racks.size(), 2u);
  EXPECT_EQ(h.racks[0].number, 3);
  EXPECT_TRUE(h.racks[0].on);
  EXPECT_TRUE(h.racks[0].reachable);
  EXPECT_FALSE(h.racks[0].ob85);
  ASSERT_EQ(h.racks[0].modules.size(), 2u);
  EXPECT_EQ(h.racks[0].modules[1].outputs, (std::vector<std::uint8_t>{0x01, 0x09}));
  EXPECT_EQ(h.racks[1].number, 9);
  EXPECT_EQ(h.racks[1].side, 1);
  EXPECT_TRUE(h.racks[1].reachable);

  // Both CPUs' buffers log the rack failure.
  for (int c = 0; c < 2; ++c) {
    bool found = false;
    for (const auto& d : h.cpus[static_cast<std::size_t>(c)].diag)
      found |= d.at == 3203 * kMs && d.code == 0x39C1;
    EXPECT_TRUE(found) << c;
  }
  std::ostringstream text;
  write_h_text(r.h_systems, text);
  EXPECT_NE(text.str().find("    rack 3 on CPU 0: on, reachable; DO16 outputs 01 09\n"), std::string::npos)
      << text.str();
  EXPECT_NE(text.str().find("    expansion rack 9 module 0: IB 2..2 QB 2..2\n"), std::string::npos);
  std::ostringstream json;
  write_h_json(r.h_systems, json);
  EXPECT_NE(json.str().find(
                "\"ob80\":1,\"expansion_racks\":[{\"number\":3,\"side\":0,\"on\":true,\"reachable\":"
                "true,\"ob85\":false,\"modules\":[{\"name\":\"DI16\",\"outputs\":[]},{\"name\":"
                "\"DO16\",\"outputs\":[1,9]}]}"),
            std::string::npos)
      << json.str();
}

}  // namespace
}  // namespace pbvbus::tools
