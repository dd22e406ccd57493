// The simulated H-system in scenarios (docs/h-system.md; docs/h-scenarios.md): an h_system's `cpu` part
// and `program` planned into HSystemPlan::runtime, the H faults planned into PlanFault, and
// every refusal with its FILE:LINE:COLUMN (columns counted by hand in the comments). Also
// built into sanitize_tools (ASan+UBSan): bad input must never crash.
#include <gtest/gtest.h>

#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "pbvbus/tools/commands.hpp"
#include "pbvbus/scenario/scenario.hpp"

namespace pbvbus::tools {
namespace {

using bus::kTicksPerMs;
using bus::kTicksPerSecond;
using K = PlanFault::Kind;

std::vector<std::string> errors_of(const std::string& text) {
  std::vector<std::string> out;
  for (const auto& d : parse_scenario(text, "h.textproto").errors) out.push_back(d.str());
  return out;
}

const std::string kPair = R"(name: "h"
duration: "200s"
h_system {
  name: "H-CPU"
  work_memory_db_kb: 170
  cpu {
    profile: S7_1500RH
    cpu0 { power_on: "0s" }
    cpu1 { power_on: "2.5s" switch: STOP }
    fibres_connected_at_power_on: false
    startup_time: "1.5s" link_up_time: "3s" self_test_time: "60s"
    comparison_reaction: STOP
  }
  program {
    scan_time: "20ms"
    copy { from_input: 2 to_output: 4 length: 2 }
    counter { output: 0 width: 2 period: "500ms" step: 3 pulse_output: 6 pulse_bit: 7 pulse_high: "100ms" }
    monitor { input_a: 8 input_b: 9 mask: 15 to_output: 10 discrepancy_time: "2s" }
  }
}
)";

TEST(HScenarioParser, CpuPartAndProgramArePlanned) {
  const auto r = parse_scenario(kPair, "h.textproto");
  ASSERT_TRUE(r.ok()) << r.errors[0].str();
  ASSERT_EQ(r.plan->h_systems.size(), 1u);
  const HSystemPlan& h = r.plan->h_systems[0];
  ASSERT_TRUE(h.runtime.has_value());
  const HRuntimePlan& rt = *h.runtime;
  EXPECT_EQ(rt.pair.profile, devices::HProfile::S7_1500RH);
  EXPECT_EQ(rt.power_on[0], bus::Ticks{0});
  EXPECT_EQ(rt.power_on[1], 2500 * kTicksPerMs);  // 2.5 s = 9 090 000 000 ticks
  EXPECT_EQ(rt.power_on[1], bus::Ticks{9'090'000'000});
  EXPECT_TRUE(rt.pair.switch_run[0]);
  EXPECT_FALSE(rt.pair.switch_run[1]);
  EXPECT_FALSE(rt.fibres_connected_at_power_on);
  EXPECT_EQ(rt.pair.startup_time, 1500 * kTicksPerMs);
  EXPECT_EQ(rt.pair.link_up_time, 3 * kTicksPerSecond);
  EXPECT_EQ(rt.pair.self_test_time, 60 * kTicksPerSecond);
  // update_db_kb unset: the DBs in work memory (170 KB) -> UPDATE 75 + 0.7·170 = 194 ms.
  EXPECT_EQ(rt.pair.update_db_kb, 170u);
  EXPECT_EQ(devices::default_update_time(rt.pair.update_db_kb), 194 * kTicksPerMs);
  EXPECT_EQ(rt.pair.comparison_reaction, devices::ComparisonReaction::Stop);
  EXPECT_TRUE(rt.systems.empty());
  const devices::ProgramSpec& p = rt.program;
  EXPECT_EQ(p.scan_time, 20 * kTicksPerMs);
  ASSERT_EQ(p.copies.size(), 1u);
  EXPECT_EQ(p.copies[0].from_input, 2u);
  EXPECT_EQ(p.copies[0].to_output, 4u);
  EXPECT_EQ(p.copies[0].length, 2u);
  ASSERT_EQ(p.counters.size(), 1u);
  EXPECT_EQ(p.counters[0].output, 0u);
  EXPECT_EQ(p.counters[0].width, 2u);
  EXPECT_EQ(p.counters[0].period, 500 * kTicksPerMs);
  EXPECT_EQ(p.counters[0].step, 3u);
  EXPECT_EQ(p.counters[0].pulse_output, 6u);
  EXPECT_EQ(p.counters[0].pulse_bit, 7);
  EXPECT_EQ(p.counters[0].pulse_high, 100 * kTicksPerMs);
  ASSERT_EQ(p.monitors.size(), 1u);
  EXPECT_EQ(p.monitors[0].input_a, 8u);
  EXPECT_EQ(p.monitors[0].input_b, 9u);
  EXPECT_EQ(p.monitors[0].length, 1u);  // default
  EXPECT_EQ(p.monitors[0].mask, 0x0F);
  EXPECT_EQ(p.monitors[0].to_output, 10u);
  EXPECT_EQ(p.monitors[0].discrepancy_time, 2 * kTicksPerSecond);
}

TEST(HScenarioParser, Sfc90CallsArePlannedAndBadModesRefused) {
  // docs/h-sfc90.md: MODE 3 (disable update) at 0 s, MODE 4 (re-enable) at 3.15 s.
  const auto r = parse_scenario(R"(duration: "10s"
h_system {
  name: "H"
  cpu { }
  program {
    h_ctrl { at: "0s" mode: 3 }
    h_ctrl { at: "3.15s" mode: 4 submode: 0 }
    h_ctrl { at: "4s" mode: 12 submode: 255 }
  }
}
)", "h.textproto");
  ASSERT_TRUE(r.ok()) << r.errors[0].str();
  const auto& c = r.plan->h_systems[0].runtime->program.h_ctrl_calls;
  ASSERT_EQ(c.size(), 3u);
  EXPECT_EQ(c[0].at, bus::Ticks{0});
  EXPECT_EQ(c[0].mode, 3);
  EXPECT_EQ(c[1].at, 3150 * kTicksPerMs);
  EXPECT_EQ(c[1].mode, 4);
  EXPECT_EQ(c[2].submode, 255);
  EXPECT_EQ(errors_of(R"(duration: "10s"
h_system {
  name: "H"
  cpu { }
  program {
    h_ctrl { at: "soon" mode: 2 }
    h_ctrl { mode: 3 submode: 1 }
  }
}
)"),
            (std::vector<std::string>{
                "h.textproto:6:14: bad duration \"soon\" for at (e.g. \"3s\")",
                "h.textproto:6:25: SFC 90: MODE 2 is not 0, 1, 3, 4, 10, 11 or 12 (W#16#8090)",
                "h.textproto:7:22: SFC 90: SUBMODE 1 is not valid for MODE 3 (W#16#8091)",
            }));
}

TEST(HScenarioParser, AnEmptyCpuPartTakesThePairsDefaults) {
  const auto r = parse_scenario("h_system { name: \"H\" cpu { cpu1 { power_on: \"off\" } } }\n", "h.textproto");
  ASSERT_TRUE(r.ok()) << r.errors[0].str();
  const HRuntimePlan& rt = *r.plan->h_systems[0].runtime;
  const devices::HCpuPairParams d;
  EXPECT_EQ(rt.pair.profile, devices::HProfile::S7_400H);
  EXPECT_EQ(rt.power_on[0], bus::Ticks{0});
  EXPECT_FALSE(rt.power_on[1].has_value());  // "off"
  EXPECT_TRUE(rt.fibres_connected_at_power_on);
  EXPECT_EQ(rt.pair.startup_time, d.startup_time);
  EXPECT_EQ(rt.pair.link_up_time, d.link_up_time);
  EXPECT_EQ(rt.pair.update_db_kb, 100u);  // work_memory_db_kb 0 -> the pair's 100 KB
  EXPECT_EQ(rt.program.scan_time, 10 * kTicksPerMs);
  // A timing-only entry has no runtime.
  const auto t = parse_scenario("h_system { name: \"T\" }\n", "h.textproto");
  ASSERT_TRUE(t.ok());
  EXPECT_FALSE(t.plan->h_systems[0].runtime.has_value());
}

TEST(HScenarioParser, HFaultsArePlannedInTimeOrder) {
  // The 400H profile: HOLD and the operator swap exist there.
  std::string pair = kPair;
  pair.replace(pair.find("S7_1500RH"), 9, "S7_400H");
  const std::string text = pair + R"(
fault { at: "10s" repair_at: "12s" cpu_failure { rack: 0 } }
fault { at: "1s" repair_at: "2s" fibre_cut { h_system: "H-CPU" fibre: 1 } }
fault { at: "20s" update_load { kb: 500 } }
fault { at: "30s" program_change { kind: GLOBAL_DB } }
fault { at: "40s" repair_at: "41s" fibres_cut { } }
fault { at: "50s" repair_at: "51s" cpu_hold { rack: 1 } }
fault { at: "60s" one_sided_ob121 { rack: 1 } }
fault { at: "70s" memory_reset { rack: 1 } }
fault { at: "80s" master_swap { } }
fault { at: "90s" parameter_change { } }
fault { at: "95s" comparison_error { } }
fault { at: "96s" repair_at: "99s" hardware_fault { rack: 0 } }
fault { at: "97s" repair_at: "98s" cpu_stop { rack: 1 } }
)";
  const auto r = parse_scenario(text, "h.textproto");
  ASSERT_TRUE(r.ok()) << r.errors[0].str();
  const auto& f = r.plan->faults;
  ASSERT_EQ(f.size(), 13u);
  struct Want {
    K kind;
    bus::Ticks at;
    int rack, fibre;
    const char* text;
  };
  const Want want[] = {
      {K::FibreCut, 1 * kTicksPerSecond, -1, 1, "sync-link fibre 1 (lower) cut"},
      {K::CpuFailure, 10 * kTicksPerSecond, 0, -1, "CPU 0 (rack 0) fails"},
      {K::UpdateLoad, 20 * kTicksPerSecond, -1, -1, "DBs changed: the next update copies 500 KB"},
      {K::ProgramChange, 30 * kTicksPerSecond, -1, -1, "program change in RUN (structural change of a global DB)"},
      {K::FibresCut, 40 * kTicksPerSecond, -1, -1, "both sync-link fibres cut at once"},
      {K::CpuHold, 50 * kTicksPerSecond, 1, -1, "CPU 1 (rack 1) to HOLD"},
      {K::OneSidedOb121, 60 * kTicksPerSecond, 1, -1, "one-sided OB 121 on CPU 1 (rack 1)"},
      {K::MemoryReset, 70 * kTicksPerSecond, 1, -1, "memory reset of CPU 1 (rack 1) after its reset request"},
      {K::HMasterSwap, 80 * kTicksPerSecond, -1, -1,
       "operator master swap (switch to CPU with modified configuration)"},
      {K::ParameterChange, 90 * kTicksPerSecond, -1, -1,
       "a parameter that may not change is changed, then a master swap"},
      {K::ComparisonError, 95 * kTicksPerSecond, -1, -1, "comparison error between the CPUs"},
      {K::HardwareFault, 96 * kTicksPerSecond, 0, -1, "latent hardware fault in CPU 0 (rack 0)"},
      {K::CpuStop, 97 * kTicksPerSecond, 1, -1, "CPU 1 (rack 1): mode switch to STOP"},
  };
  for (std::size_t i = 0; i < 13; ++i) {
    SCOPED_TRACE(i);
    EXPECT_EQ(f[i].kind, want[i].kind);
    EXPECT_EQ(f[i].at, want[i].at);
    EXPECT_EQ(f[i].rack, want[i].rack);
    EXPECT_EQ(f[i].fibre, want[i].fibre);
    EXPECT_EQ(f[i].description, want[i].text);
    EXPECT_EQ(f[i].h_system, 0);
    EXPECT_EQ(f[i].line, -1);
    EXPECT_TRUE(is_h_fault(f[i].kind));
  }
  EXPECT_EQ(f[0].repair_at, 2 * kTicksPerSecond);
  EXPECT_EQ(f[2].kb, 500u);
  EXPECT_EQ(f[3].change, HProgramChangeKind::GlobalDb);
  EXPECT_FALSE(f[6].repair_at.has_value());
  EXPECT_FALSE(is_h_fault(K::CableCut));
}

// Columns by hand: `  cpu { cpu1 { power_on:` -> power_on at 16; `    copy { length` -> 12;
// `    counter { width` -> 15, then +9 "width: 3 " -> period at 24, +13 `period: "0s" ` ->
// pulse_high at 37; `    monitor { length` -> 15, +10 "length: 0 " -> discrepancy_time at 25;
// `fault { at: "1s" ` is 17 characters -> the kind at 18; `cpu_failure { ` +14 -> 32;
// `fibre_cut { ` +12 -> 30; `fibres_cut { ` +13 -> 31.
TEST(HScenarioParser, RefusalsCarryTheirPositions) {
  const std::string text = R"(duration: "100s"
h_system { name: "T" }
h_system {
  name: "H"
  cpu { cpu1 { power_on: "soon" } }
  program {
    copy { length: 0 }
    counter { width: 3 period: "0s" pulse_high: "1s" }
    monitor { length: 0 discrepancy_time: "0ms" }
  }
}
fault { at: "1s" cpu_failure { h_system: "X" rack: 0 } }
fault { at: "1s" cpu_failure { rack: 2 } }
fault { at: "1s" fibre_cut { fibre: 3 } }
fault { at: "1s" fibres_cut { h_system: "T" } }
fault { at: "1s" repair_at: "2s" comparison_error { } }
fault { at: "1s" cpu_stop { } }
fault { at: "1s" fibre_cut { } }
fault { at: "1s" update_load { } }
)";
  EXPECT_EQ(errors_of(text),
            (std::vector<std::string>{
                "h.textproto:5:16: bad duration \"soon\" for power_on (e.g. \"100ms\")",
                "h.textproto:7:12: copy network: length must be at least 1",
                "h.textproto:8:15: counter network: width 3 is not 1, 2 or 4 octets",
                "h.textproto:8:24: period must be longer than 0",
                "h.textproto:8:37: counter network: pulse_high 1s is not shorter than the period",
                "h.textproto:9:15: monitor network: length must be at least 1",
                "h.textproto:9:25: discrepancy_time must be longer than 0",
                "h.textproto:12:32: cpu_failure: no h_system \"X\"",
                "h.textproto:13:32: cpu_failure: rack 2 is not 0 or 1",
                "h.textproto:14:30: fibre_cut: fibre 3 is not 0 or 1",
                "h.textproto:15:31: fibres_cut: h_system \"T\" has no cpu part (it is timing input only)",
                "h.textproto:16:18: comparison_error has no repair: remove repair_at",
                "h.textproto:17:18: cpu_stop needs a rack: rack: 0 or rack: 1",
                "h.textproto:18:18: fibre_cut needs a fibre: fibre: 0 (upper) or fibre: 1 (lower)",
                "h.textproto:19:18: update_load needs kb > 0 (the KB of DBs the next update copies)",
            }));
}

TEST(HScenarioParser, FaultsNeedASimulatedPairAndANameWhenThereAreSeveral) {
  EXPECT_EQ(errors_of("h_system { name: \"T\" }\nfault { at: \"1s\" master_swap { } }\n"),
            (std::vector<std::string>{
                "h.textproto:2:18: master_swap: the scenario has no h_system with a cpu part"}));
  EXPECT_EQ(errors_of("h_system { name: \"A\" cpu { } }\nh_system { name: \"B\" cpu { } }\n"
                      "fault { at: \"1s\" master_swap { } }\n"),
            (std::vector<std::string>{"h.textproto:3:18: master_swap: several h_systems are simulated: "
                                      "name one (h_system: \"...\")"}));
  // Named: the description says which pair.
  const auto r = parse_scenario(
      "h_system { name: \"A\" cpu { } }\nh_system { name: \"B\" cpu { } }\n"
      "fault { at: \"1s\" cpu_failure { h_system: \"B\" rack: 1 } }\n",
      "h.textproto");
  ASSERT_TRUE(r.ok()) << r.errors[0].str();
  EXPECT_EQ(r.plan->faults[0].h_system, 1);
  EXPECT_EQ(r.plan->faults[0].description, "CPU 1 (rack 1) fails (h_system \"B\")");
  // The 1500 profile has neither HOLD nor the operator swap (docs/h-system.md rules 5, 13).
  EXPECT_EQ(errors_of("h_system { name: \"R\" cpu { profile: S7_1500RH } }\n"
                      "fault { at: \"1s\" repair_at: \"2s\" cpu_hold { rack: 0 } }\n"
                      "fault { at: \"1s\" master_swap { } }\n"),
            (std::vector<std::string>{"h.textproto:2:34: cpu_hold: the S7-1500R/H profile has no HOLD",
                                      "h.textproto:3:18: master_swap: the S7-1500R/H profile has no "
                                      "operator master swap"}));
  // Two simulated pairs of one name.
  EXPECT_EQ(errors_of("h_system { name: \"A\" cpu { } }\nh_system { name: \"A\" cpu { } }\n"),
            (std::vector<std::string>{
                "h.textproto:2:12: h_system \"A\" is defined twice (faults name it)"}));
  // A program without a pair.
  EXPECT_EQ(errors_of("h_system { name: \"T\"\n program { } }\n"),
            (std::vector<std::string>{
                "h.textproto:2:2: h_system \"T\": a program needs a cpu part (the simulated pair)"}));
}

// Central I/O only (no DP master system): T_PH = 30 ms, T_P15_AWP(0 KB) = 75 ms, T_P15_OD =
// 50 + 30 = 80 ms -> T_P15 = 80 ms. The set {1940, 776, 194, 150} breaks one rule:
// 50 ms + T_PH 150 = 200 ms > T_P15 194 ms. A simulated pair refuses it, a timing-only entry
// keeps it (pbvbus timing reports it).
TEST(HScenarioParser, ASimulatedPairRefusesBadHParameters) {
  const std::string params =
      " h_parameters { max_cycle_extension: \"1940ms\" max_communication_delay: \"776ms\""
      " max_blocking_time: \"194ms\" min_io_hold_time: \"150ms\" } }\n";
  EXPECT_TRUE(parse_scenario("h_system { name: \"T\"" + params, "h.textproto").ok());
  const auto r = parse_scenario("h_system { name: \"H\" cpu { }" + params, "h.textproto");
  ASSERT_EQ(r.errors.size(), 1u);
  EXPECT_EQ(r.errors[0].line, 1);
  EXPECT_EQ(r.errors[0].column, 30);  // `h_system { name: "H" cpu { }` is 28 characters, then a space
  EXPECT_NE(r.errors[0].message.find("h_system \"H\" (simulated): H parameters: "), std::string::npos)
      << r.errors[0].message;
  EXPECT_NE(r.errors[0].message.find("50 ms + T_PH = 200"), std::string::npos) << r.errors[0].message;
  // The good set passes: 50 + 90 = 140 <= 194.
  const std::string good =
      " h_parameters { max_cycle_extension: \"1940ms\" max_communication_delay: \"776ms\""
      " max_blocking_time: \"194ms\" min_io_hold_time: \"90ms\" } }\n";
  EXPECT_TRUE(parse_scenario("h_system { name: \"H\" cpu { }" + good, "h.textproto").ok());
}

// A redundant_master_system is driven by one pair only, and once.
TEST(HScenarioParser, ARedundantMasterSystemBelongsToOnePair) {
  std::ifstream in(PBVBUS_SOURCE_DIR "/examples/switched-io.textproto");
  std::stringstream ss;
  ss << in.rdbuf();
  const std::string file = PBVBUS_SOURCE_DIR "/examples/h_scenario_parser_test.textproto";
  const std::string h1 = "h_system { name: \"H1\" cpu { } dp_system { system: \"H-DP 1\" t_pto: \"2s\" } }\n";
  {
    const auto r = parse_scenario(ss.str() + h1, file);
    ASSERT_TRUE(r.ok()) << r.errors[0].str();
    const auto& rt = *r.plan->h_systems[0].runtime;
    ASSERT_EQ(rt.systems.size(), 1u);
    EXPECT_EQ(r.plan->redundant_systems[static_cast<std::size_t>(rt.systems[0])].name, "H-DP 1");
  }
  {
    const auto r = parse_scenario(
        ss.str() + h1 + "h_system { name: \"H2\" cpu { } dp_system { system: \"H-DP 1\" t_pto: \"2s\" } }\n", file);
    ASSERT_EQ(r.errors.size(), 1u);
    EXPECT_EQ(r.errors[0].message, "redundant_master_system \"H-DP 1\" is already driven by h_system \"H1\"");
  }
  {
    const auto r = parse_scenario(ss.str() +
                                      "h_system { name: \"H1\" cpu { } dp_system { system: \"H-DP 1\" t_pto: \"2s\" }"
                                      " dp_system { system: \"H-DP 1\" t_pto: \"3s\" } }\n",
                                  file);
    ASSERT_EQ(r.errors.size(), 1u);
    EXPECT_EQ(r.errors[0].message,
              "h_system \"H1\": redundant_master_system \"H-DP 1\" is named twice (a pair drives a system once)");
  }
  // Timing-only entries may share it (they only study it).
  const auto t = parse_scenario(ss.str() + "h_system { name: \"T1\" dp_system { system: \"H-DP 1\" t_pto: \"2s\" } }\n" +
                                    "h_system { name: \"T2\" dp_system { system: \"H-DP 1\" t_pto: \"2s\" } }\n",
                                file);
  EXPECT_TRUE(t.ok()) << t.errors[0].str();
}

TEST(HScenarioParser, TheExampleLoads) {
  const auto r = load_scenario_file(PBVBUS_SOURCE_DIR "/examples/h-system.textproto");
  ASSERT_TRUE(r.ok()) << r.errors[0].str();
  ASSERT_EQ(r.plan->h_systems.size(), 1u);
  const HSystemPlan& h = r.plan->h_systems[0];
  ASSERT_TRUE(h.runtime.has_value());
  EXPECT_EQ(h.runtime->systems.size(), 1u);
  EXPECT_EQ(h.runtime->power_on[0], bus::Ticks{0});
  EXPECT_EQ(h.runtime->power_on[1], bus::Ticks{0});
  EXPECT_EQ(h.runtime->program.counters.size(), 1u);
  EXPECT_EQ(h.runtime->program.copies.size(), 1u);
  int h_faults = 0;
  for (const auto& f : r.plan->faults) h_faults += is_h_fault(f.kind) ? 1 : 0;
  EXPECT_EQ(h_faults, 3);  // fibre_cut, cpu_stop, cpu_failure
}

// `pbvbus timing` still plans the example: the h_system is also timing input.
TEST(HScenarioParser, PbvbusTimingPlansTheExample) {
  std::ostringstream out, err;
  const int rc = cmd_timing({PBVBUS_SOURCE_DIR "/examples/h-system.textproto"}, out, err);
  ASSERT_EQ(rc, 0) << err.str();
  // T_P15_AWP(100 KB) = 75 + 0.7 x 100 = 145 ms > T_P15_OD = 50 + 30 = 80 ms -> T_P15 145 ms;
  // T_PH = MAX(30 ms, 3 x T_TR 2.38 ms) = 30 ms; the configured {1450, 580, 145, 30} passes.
  EXPECT_NE(out.str().find("T_P15_AWP = 75 ms + 0.7 ms x 100 KB = 145 ms"), std::string::npos) << out.str();
  EXPECT_NE(out.str().find("[3] T_P15 = MAX(T_P15_AWP, T_P15_OD) = 145 ms"), std::string::npos) << out.str();
  EXPECT_NE(out.str().find("configured H parameters: ok"), std::string::npos) << out.str();
  EXPECT_NE(out.str().find("H-DP 1"), std::string::npos) << out.str();
}

// Redundant I/O (docs/h-redundant-io.md "In a scenario"): bad redundant_io entries and the
// faults channel_stuck / red_depa are refused with a message and never crash (this file also
// runs under ASan+UBSan).
bool redio_has(const std::vector<std::string>& errs, const std::string& text) {
  for (const auto& e : errs)
    if (e.find(text) != std::string::npos) return true;
  return false;
}

TEST(HScenarioParser, RedundantIoRefusals) {
  const std::string no_cpu = R"(name: "h"
h_system { name: "T" redundant_io { kind: DI } }
)";
  EXPECT_TRUE(redio_has(errors_of(no_cpu), "redundant_io needs a cpu part"));
  auto pair = [](const std::string& body) {
    return R"(name: "h"
h_system { name: "H" cpu { } redundant_io { )" + body + R"( } }
)";
  };
  EXPECT_TRUE(redio_has(errors_of(pair("kind: AI")), "redundant_io needs two modules"));
  EXPECT_TRUE(redio_has(
      errors_of(pair(R"(module_a { system: "X" } module_b { system: "" address: 4000000000 })")),
      "\"X\" is not a redundant_master_system this h_system drives"));
  EXPECT_TRUE(redio_has(errors_of(pair(R"(kind: AI module_a { } module_b { } tolerance_permille: 4294967295 end_value: -2147483648 discrepancy_time: "-1ms")")),
                         "tolerance_permille 4294967295 is above 1000"));
  EXPECT_TRUE(redio_has(errors_of(pair(R"(kind: DI module_a { } module_b { } discrepancy_time: "soon")")),
                         "bad duration \"soon\" for discrepancy_time"));
  const std::string faults = R"(name: "h"
h_system { name: "H" cpu { } }
fault { at: "1s" channel_stuck { line: "nowhere" address: 255 module_index: 4294967295 stuck_value: 18446744073709551615 } }
fault { at: "1s" repair_at: "2s" red_depa { } }
)";
  const auto e = errors_of(faults);
  EXPECT_GE(e.size(), 2u);
  EXPECT_TRUE(redio_has(e, "red_depa")) << (e.empty() ? "" : e.back());
}

}  // namespace
}  // namespace pbvbus::tools
