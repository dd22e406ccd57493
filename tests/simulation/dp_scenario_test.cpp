// dp_master / dp_slave in scenario files: planning from the GSDs, derived bus parameters, and
// errors located at FILE:LINE:COLUMN (scenario/include/pbvbus/scenario/dp_plan.hpp).
#include <gtest/gtest.h>

#include <sstream>
#include <string>

#include "pbvbus/scenario/scenario.hpp"
#include "pbvbus/simulation/simulation.hpp"
#include "pbvbus/reports/run_report.hpp"

namespace pbvbus::tools {
namespace {

// The file name decides where relative GSD paths are looked up: examples/.
const std::string kFile = PBVBUS_SOURCE_DIR "/examples/test.textproto";

std::string head() {
  return "name: \"t\"\nduration: \"100ms\"\nline { name: \"A\" baud: \"1.5M\" }\n"
         "dp_master { address: 1 line: \"A\" }\n";
}

std::vector<std::string> errors_of(const std::string& text) {
  const auto r = parse_scenario(text, kFile);
  std::vector<std::string> out;
  for (const auto& e : r.errors) out.push_back(e.str());
  return out;
}

TEST(DpScenario, PlansSlavesFromTheGsd) {
  const auto r = parse_scenario(
      head() + "dp_slave { address: 4 line: \"A\" gsd: \"gsd/PBVB0A02.gsd\" master: 1\n"
               "  modules: [\"16DI DC24V\", \"2AO U/I 16 bit\"] }\n",
      kFile);
  ASSERT_TRUE(r.ok()) << r.errors.front().str();
  ASSERT_EQ(r.plan->dp_slaves.size(), 1u);
  const DpSlavePlan& s = r.plan->dp_slaves[0];
  EXPECT_EQ(s.inputs, 2u);
  EXPECT_EQ(s.outputs, 4u);
  EXPECT_EQ(s.params.ident, 0x0A02);
  EXPECT_EQ(s.params.chk_cfg_du(), (std::vector<std::uint8_t>{0x11, 0x61}));
  // Global 01, 16DI ref 10 = 1 → 01, 2AO ref 30 = 2 twice.
  EXPECT_EQ(s.params.user_prm, (std::vector<std::uint8_t>{0x01, 0x01, 0x02, 0x02}));
  // Watchdog default 1 s = 100 × 10 ms = 10 × 10.
  EXPECT_EQ(s.params.wd_fact_1, 10);
  EXPECT_EQ(s.params.wd_fact_2, 10);
  // Derived line parameters: max TSDR 150 (GSD MaxTsdr_1.5M), TSL 300, and TTR =
  // 2 × pass + TSL + 100 with pass = (11·(9+4) + 150 + 11·(9+2) + 37) + (33 + 37) + (143 + 150)
  // + (66 + 300 + 37) = 451 + 70 + 293 + 403 = 1217.
  const auto& p = r.plan->lines[0].params;
  EXPECT_EQ(p.max_tsdr, 150u);
  EXPECT_EQ(p.tsl, 300u);
  EXPECT_EQ(p.ttr, 2 * 1217u + 300 + 100);
}

TEST(DpScenario, GivenBusParametersWin) {
  const auto r = parse_scenario(
      "line { name: \"A\" baud: \"1.5M\" bus_params { ttr: 10000 } }\n"
      "dp_master { address: 1 line: \"A\" }\n"
      "dp_slave { address: 3 line: \"A\" gsd: \"gsd/PBVB0A01.gsd\" master: 1 }\n",
      kFile);
  ASSERT_TRUE(r.ok()) << r.errors.front().str();
  EXPECT_EQ(r.plan->lines[0].params.ttr, 10000u);
}

TEST(DpScenario, ErrorsNameFileLineAndColumn) {
  // Columns: `dp_slave { address: 3 line: "A" gsd: ...` has `gsd` at column 33, `master` at
  // 57 and `tsdr_bits` at 67 when written as below.
  const auto unknown_gsd = errors_of(head() + "dp_slave { address: 3 line: \"A\" gsd: \"gsd/NOPE.gsd\" master: 1 }\n");
  ASSERT_EQ(unknown_gsd.size(), 1u);
  EXPECT_EQ(unknown_gsd[0].rfind(kFile + ":5:33: GSD file \"gsd/NOPE.gsd\"", 0), 0u) << unknown_gsd[0];

  const auto unknown_module = errors_of(
      head() + "dp_slave { address: 4 line: \"A\" gsd: \"gsd/PBVB0A02.gsd\" master: 1\n"
               "  modules: [\"8DI DC24V\", \"99DI\"] }\n");
  ASSERT_EQ(unknown_module.size(), 1u);
  EXPECT_EQ(unknown_module[0].rfind(kFile + ":6:3: unknown module \"99DI\" in gsd/PBVB0A02.gsd", 0), 0u)
      << unknown_module[0];

  const auto tsdr = errors_of(head() + "dp_slave { address: 3 line: \"A\" gsd: \"gsd/PBVB0A01.gsd\" master: 1 tsdr_bits: 151 }\n");
  ASSERT_EQ(tsdr.size(), 1u);
  EXPECT_EQ(tsdr[0], kFile + ":5:67: tsdr_bits 151 is outside [min TSDR 11, MaxTsdr 150 of gsd/PBVB0A01.gsd]");

  const auto clash = errors_of(head() + "dp_slave { address: 1 line: \"A\" gsd: \"gsd/PBVB0A01.gsd\" master: 1 }\n");
  ASSERT_EQ(clash.size(), 1u);
  EXPECT_EQ(clash[0], kFile + ":5:12: address 1 is already used on line \"A\" (at 4:13)");

  const auto no_master = errors_of(head() + "dp_slave { address: 3 line: \"A\" gsd: \"gsd/PBVB0A01.gsd\" master: 2 }\n");
  ASSERT_EQ(no_master.size(), 1u);
  EXPECT_EQ(no_master[0], kFile + ":5:57: no dp_master 2 on line \"A\"");

  const auto modular = errors_of(head() + "dp_slave { address: 3 line: \"A\" gsd: \"gsd/PBVB0A02.gsd\" master: 1 }\n");
  ASSERT_EQ(modular.size(), 1u);
  EXPECT_EQ(modular[0], kFile + ":5:1: dp_slave with the modular GSD \"gsd/PBVB0A02.gsd\" needs a module "
                                "list (modules: [\"...\"], at most Max_Module = 8)");

  const auto wd = errors_of("line { name: \"A\" }\ndp_master { address: 1 line: \"A\" watchdog: \"15ms\" }\n");
  ASSERT_EQ(wd.size(), 1u);
  EXPECT_EQ(wd[0], kFile + ":2:34: watchdog \"15ms\" is not a positive multiple of 10 ms");
}

TEST(DpScenario, ReportShowsEverySlave) {
  const auto r = parse_scenario(
      head() + "dp_slave { address: 3 line: \"A\" gsd: \"gsd/PBVB0A01.gsd\" master: 1 inputs: ECHO }\n",
      kFile);
  ASSERT_TRUE(r.ok()) << r.errors.front().str();
  Simulation sim(*r.plan);
  sim.run_until(*sim.duration());
  const Report rep = sim.report(0.0);
  ASSERT_EQ(rep.dp_masters.size(), 1u);
  const DpSlaveReport& s = rep.dp_masters[0].slaves.at(0);
  EXPECT_EQ(s.state, "data exchange");
  EXPECT_EQ(s.input_len, 2u);
  EXPECT_EQ(s.output_len, 2u);
  // Echo: the inputs are the outputs of the previous cycle, which the master-side program set
  // to its token count; both octets carry the same value.
  EXPECT_EQ(s.inputs[0], s.inputs[1]);
  EXPECT_NE(s.outputs[0], 0);
  std::ostringstream json;
  write_json(rep, json);
  EXPECT_NE(json.str().find("\"dp_masters\":[\n{\"address\":1,\"line\":\"A\",\"mode\":"), std::string::npos)
      << json.str();
  EXPECT_NE(json.str().find("\"diag\":\"00 0C 00 01 0A 01\",\"diag_bits\":[\"always_1\",\"WD_On\"]"),
            std::string::npos);
  std::ostringstream text;
  write_text(rep, text);
  EXPECT_NE(text.str().find("dp slave 3 \"pbvbus CS16 16DI/16DO\""), std::string::npos) << text.str();
}

// ---- equidistance (docs/dp-equidistance.md) ----
// One PBVB0A01 slave (2 octets in, 2 out) at 1.5 Mbit/s: max TSDR 150 (GSD), TSL 300,
// TID1 = max(33 + 4, 11) = 37, TID2 = max(37, 150) = 150. Planned DP cycle: Data_Exchange
// 11·11 + 150 + 11·11 + 37 = 429, Global_Control 11·13 + 150 = 293, GAP poll 66 + 300 + 37 =
// 403, token 33 + 37 = 70: 1195 bit times; margin one repeat 11·11 + 300 = 421: 1616 bit
// times = 1077.333 µs.
std::string equidistant(const std::string& t_dp) {
  return "name: \"t\"\nduration: \"100ms\"\nline { name: \"A\" baud: \"1.5M\" }\n"
         "dp_master { address: 1 line: \"A\" equidistant_cycle: \"" + t_dp + "\" }\n"
         "dp_slave { address: 3 line: \"A\" gsd: \"gsd/PBVB0A01.gsd\" master: 1 }\n";
}

TEST(DpScenario, AnEquidistantCycleShorterThanThePlannedCycleIsRefused) {
  // `dp_master { address: 1 line: "A" ` is 33 columns: the field at column 34 of line 4.
  EXPECT_EQ(errors_of(equidistant("1ms")),
            (std::vector<std::string>{
                kFile + ":4:34: dp_master 1: equidistant_cycle \"1ms\" (1500 bit times at line \"A\") is "
                        "shorter than the planned DP cycle of 1195 bit times (1 slave, Global_Control, GAP poll, "
                        "token) + a margin of 421 (one repeat) = 1616 bit times (1077.333 us)"}));
  EXPECT_EQ(errors_of(equidistant("0ms")),
            (std::vector<std::string>{kFile + ":4:34: dp_master 1: equidistant_cycle \"0ms\" is not a positive "
                                              "duration (e.g. \"2ms\")"}));
  // 1616 bit times load: 1616 / 1.5 µs is not a whole µs, 1078 µs = 1617 bit times is the first.
  EXPECT_TRUE(errors_of(equidistant("1078us")).empty());
  EXPECT_FALSE(errors_of(equidistant("1077us")).empty());
}

TEST(DpScenario, AnEquidistantMasterRunsOnItsGrid) {
  const auto r = parse_scenario(equidistant("2ms"), kFile);
  ASSERT_TRUE(r.ok()) << r.errors.front().str();
  EXPECT_EQ(r.plan->dp_masters[0].params.equidistant_cycle, 2 * bus::kTicksPerMs);
  // TTR = 2 × 1195 + 300 + 100 = 2790 (DpScenario.PlansSlavesFromTheGsd), raised by T_DP =
  // 3000 bit times.
  EXPECT_EQ(r.plan->lines[0].params.ttr, 2790u + 3000u);
  Simulation sim(*r.plan);
  sim.run_until(*sim.duration());
  const Report rep = sim.report(0.0);
  ASSERT_EQ(rep.dp_masters.size(), 1u);
  const auto& e = rep.dp_masters[0].equidistance;
  EXPECT_EQ(e.period, 2 * bus::kTicksPerMs);
  EXPECT_EQ(e.overruns, 0u);
  EXPECT_EQ(e.jitter, 0);
  // 100 ms / 2 ms: the grid starts at the first pass, a few hundred µs after power-on.
  EXPECT_GE(e.cycles, 49u);
  EXPECT_LE(e.cycles, 50u);
  EXPECT_EQ(e.intervals, e.cycles - 1);
  EXPECT_EQ(e.interval_min, 2 * bus::kTicksPerMs);
  EXPECT_EQ(e.interval_max, 2 * bus::kTicksPerMs);
  EXPECT_EQ(rep.dp_masters[0].slaves.at(0).state, "data exchange");
  std::ostringstream text;
  write_text(rep, text);
  EXPECT_NE(text.str().find("  equidistance: T_DP 2000.000 us = 3000 bit times, cycles "), std::string::npos)
      << text.str();
  EXPECT_NE(text.str().find(", overruns 0 (due times passed over 0), max lateness 0.000 us = 0 bit times, "
                            "cycle start jitter 0 bit times over "),
            std::string::npos)
      << text.str();
  std::ostringstream json;
  write_json(rep, json);
  EXPECT_NE(json.str().find(",\"equidistance\":{\"t_dp_ns\":2000000,\"t_dp_bits\":3000,\"cycles\":"),
            std::string::npos)
      << json.str();
}

TEST(DpScenario, WithoutEquidistanceTheReportHasNoEquidistance) {
  const auto r = parse_scenario(
      head() + "dp_slave { address: 3 line: \"A\" gsd: \"gsd/PBVB0A01.gsd\" master: 1 }\n", kFile);
  ASSERT_TRUE(r.ok()) << r.errors.front().str();
  EXPECT_EQ(r.plan->dp_masters[0].params.equidistant_cycle, 0);
  Simulation sim(*r.plan);
  sim.run_until(10 * bus::kTicksPerMs);
  const Report rep = sim.report(0.0);
  std::ostringstream text, json;
  write_text(rep, text);
  write_json(rep, json);
  EXPECT_EQ(text.str().find("equidistance"), std::string::npos);
  EXPECT_EQ(json.str().find("equidistance"), std::string::npos);
}

TEST(DpScenario, TheEquidistanceExampleHoldsItsGrid) {
  const LoadResult r = load_scenario_file(PBVBUS_SOURCE_DIR "/examples/dp-equidistance.textproto");
  ASSERT_TRUE(r.ok()) << r.errors.front().str();
  Simulation sim(*r.plan);
  sim.run_until(*sim.duration());
  const Report rep = sim.report(0.0);
  ASSERT_EQ(rep.dp_masters.size(), 1u);
  const auto& e = rep.dp_masters[0].equidistance;
  EXPECT_EQ(e.period, 2 * bus::kTicksPerMs);
  EXPECT_EQ(e.overruns, 0u);
  EXPECT_EQ(e.jitter, 0);
  EXPECT_GE(e.cycles, 99u);  // 200 ms / 2 ms
  for (const auto& s : rep.dp_masters[0].slaves) EXPECT_EQ(s.state, "data exchange") << int{s.address};
  // The pause frames (FDL Status to itself) are neither repeats nor unanswered requests.
  std::ostringstream all;
  write_text(rep, all);
  EXPECT_NE(all.str().find("on the wire: no response 0, retries 0,"), std::string::npos) << all.str();
  if (::testing::Test::HasFailure()) {
    std::ostringstream text;
    write_text(rep, text);
    ADD_FAILURE() << text.str();
  }
}

}  // namespace
}  // namespace pbvbus::tools
