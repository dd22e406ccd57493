// Scenario loader: syntax and semantic errors with FILE:LINE:COLUMN, and the plan it builds.
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "pbvbus/scenario/scenario.hpp"

namespace pbvbus::tools {
namespace {

std::vector<std::string> errors_of(const std::string& text) {
  std::vector<std::string> out;
  for (const auto& d : parse_scenario(text, "s.textproto").errors) out.push_back(d.str());
  return out;
}

using Errs = std::vector<std::string>;

// A minimal valid scenario that the error tests extend.
const std::string kLine = "line { name: \"A\" baud: \"1.5M\" }\n";

TEST(ScenarioParser, ValidScenarioPlansStationsInOrderOfAppearance) {
  const auto r = parse_scenario(R"(name: "t"
seed: 7
duration: "5s"
line { name: "A" baud: "1.5M" }
line { name: "B" bit_rate: 187500 bus_params { ttr: 50000 } }
passive_station { address: 10 line: "A" response_length: 4 }
master { address: 3 line: "A" poll { address: [10, 11] length: 2 } }
passive_station { address: 11 line: "A" }
master { address: 1 line: "B" }
serial { line: "A" mode: MONITOR }
fault { at: "2s" repair_at: "3s" cable_cut { line: "A" between_a: 11 between_b: 3 } }
fault { at: "1s" short_circuit { line: "B" } }
)",
                                "s.textproto");
  ASSERT_TRUE(r.ok()) << (r.errors.empty() ? "" : r.errors[0].str());
  const ScenarioPlan& p = *r.plan;
  EXPECT_EQ(p.name, "t");
  EXPECT_EQ(p.seed, 7u);
  EXPECT_EQ(p.duration, 5 * bus::kTicksPerSecond);
  ASSERT_EQ(p.lines.size(), 2u);
  EXPECT_EQ(p.lines[0].baud, bus::Baud::k1_5M);
  EXPECT_EQ(p.lines[0].params.tsl, 300u);  // §C.1 default at 1.5M
  EXPECT_EQ(p.lines[1].baud, bus::Baud::k187_5);
  EXPECT_EQ(p.lines[1].params.ttr, 50000u);
  EXPECT_EQ(p.lines[1].params.tsl, 100u);
  // Line A in cable order: passive 10, master 3, passive 11, the monitor.
  const auto& st = p.lines[0].stations;
  ASSERT_EQ(st.size(), 4u);
  EXPECT_EQ(st[0].kind, StationKind::Passive);
  EXPECT_EQ(st[0].address, 10);
  EXPECT_EQ(st[1].kind, StationKind::Master);
  EXPECT_EQ(st[1].address, 3);
  EXPECT_EQ(st[2].address, 11);
  EXPECT_EQ(st[2].source, 1);
  EXPECT_EQ(st[3].kind, StationKind::SerialMonitor);
  EXPECT_FALSE(st[3].address.has_value());
  ASSERT_EQ(p.lines[1].stations.size(), 1u);
  // Faults sorted by time; the cut sits between cable positions 1 (master 3) and 2 (station 11).
  ASSERT_EQ(p.faults.size(), 2u);
  EXPECT_EQ(p.faults[0].kind, PlanFault::Kind::ShortCircuit);
  EXPECT_EQ(p.faults[0].at, bus::kTicksPerSecond);
  EXPECT_EQ(p.faults[1].kind, PlanFault::Kind::CableCut);
  EXPECT_EQ(p.faults[1].a, 1);
  EXPECT_EQ(p.faults[1].b, 2);
  EXPECT_EQ(p.faults[1].repair_at, 3 * bus::kTicksPerSecond);
  EXPECT_EQ(p.faults[1].description, "cable cut on line A between 11 and 3");
}

// The protobuf tokenizer reports some errors at the token after the offending one (the ':'
// after an unknown field name, the '}' after an unknown enum value): that is its position.
TEST(ScenarioParser, SyntaxErrorsCarryLineAndColumn) {
  EXPECT_EQ(errors_of(kLine + "master { adress: 1 }\n"),
            Errs{"s.textproto:2:16: Message type \"pbvbus.scenario.Master\" has no field named "
                 "\"adress\"."});
  EXPECT_EQ(errors_of("line { name: \"A\"\n"),
            Errs{"s.textproto:2:1: Expected identifier, got: "});
  EXPECT_EQ(errors_of(kLine + "master { address: -1 }\n"),
            Errs{"s.textproto:2:19: Expected integer, got: -"});
  EXPECT_EQ(errors_of(kLine + "serial { line: \"A\" mode: LISTEN }\n"),
            Errs{"s.textproto:2:33: Unknown enumeration value of \"LISTEN\" for field \"mode\"."});
}

TEST(ScenarioParser, UnknownLine) {
  EXPECT_EQ(errors_of(kLine + "master { address: 1 line: \"B\" }\n"),
            Errs{"s.textproto:2:21: unknown line \"B\""});
  EXPECT_EQ(errors_of(kLine + "passive_station { address: 1 }\n"),
            Errs{"s.textproto:2:1: passive_station needs a line"});
}

TEST(ScenarioParser, AddressesMustBeUniqueAndInRange) {
  EXPECT_EQ(errors_of(kLine +
                      "passive_station { address: 10 line: \"A\" }\n"
                      "master { line: \"A\"\n"
                      "         address: 10 }\n"),
            Errs{"s.textproto:4:10: address 10 is already used on line \"A\" (at 2:19)"});
  EXPECT_EQ(errors_of(kLine + "passive_station { address: 127 line: \"A\" }\n"),
            Errs{"s.textproto:2:19: address 127 is out of range 0..126"});
  EXPECT_EQ(errors_of(kLine + "master { line: \"A\" }\n"),
            Errs{"s.textproto:2:1: master needs an address"});
  // The same address on two lines is fine.
  EXPECT_TRUE(errors_of(kLine + "line { name: \"B\" }\n"
                                "passive_station { address: 10 line: \"A\" }\n"
                                "passive_station { address: 10 line: \"B\" }\n")
                  .empty());
}

TEST(ScenarioParser, MastersMustBeBelowHsa) {
  EXPECT_EQ(errors_of("line { name: \"A\" bus_params { hsa: 30 } }\n"
                      "master { address: 30 line: \"A\" }\n"),
            Errs{"s.textproto:2:10: master address 30 is not below HSA 30 of line \"A\""});
  EXPECT_EQ(errors_of(kLine + "master { address: 126 line: \"A\" }\n"),
            Errs{"s.textproto:2:10: master address 126 is not below HSA 126 of line \"A\""});
}

TEST(ScenarioParser, BadDurations) {
  EXPECT_EQ(errors_of(kLine + "duration: \"5 parsecs\"\n"),
            Errs{"s.textproto:2:1: bad duration \"5 parsecs\" (expected a number and a unit: ns, "
                 "us, ms, s, min, h, e.g. \"250ms\")"});
  EXPECT_EQ(errors_of(kLine + "duration: \"5\"\n"),
            Errs{"s.textproto:2:1: bad duration \"5\" (expected a number and a unit: ns, us, ms, "
                 "s, min, h, e.g. \"250ms\")"});
  EXPECT_EQ(errors_of(kLine + "duration: \"0s\"\n"),
            Errs{"s.textproto:2:1: duration must be longer than 0"});
  EXPECT_EQ(errors_of(kLine + "fault {\n  at: \"soon\" short_circuit { line: \"A\" } }\n"),
            Errs{"s.textproto:3:3: bad duration \"soon\" (expected a number and a unit: ns, us, "
                 "ms, s, min, h, e.g. \"250ms\")"});
}

TEST(ScenarioParser, BaudMustBeAProfibusRate) {
  EXPECT_EQ(errors_of("line { name: \"A\" baud: \"1.4M\" }\n"),
            Errs{"s.textproto:1:18: \"1.4M\" is not a PROFIBUS baud rate (9.6k, 19.2k, 31.25k, "
                 "45.45k, 93.75k, 187.5k, 500k, 1.5M, 3M, 6M, 12M)"});
  EXPECT_EQ(errors_of("line { name: \"A\" bit_rate: 115200 }\n"),
            Errs{"s.textproto:1:18: 115200 bit/s is not a PROFIBUS baud rate (9.6k, 19.2k, "
                 "31.25k, 45.45k, 93.75k, 187.5k, 500k, 1.5M, 3M, 6M, 12M)"});
  EXPECT_TRUE(errors_of("line { name: \"A\" baud: \"12M\" }\n").empty());
  EXPECT_TRUE(errors_of("line { name: \"A\" baud: \"1500000\" }\n").empty());
}

TEST(ScenarioParser, BusParameterViolations) {
  // max TSDR + 15 <= TSL (protocol-facts.md §C.1).
  EXPECT_EQ(errors_of("line { name: \"A\"\n  bus_params { tsl: 100 } }\n"),
            Errs{"s.textproto:2:3: bus parameters of line \"A\": TSL 100 must be at least max "
                 "TSDR + 15 = 165"});
  // A master's overrides are checked on top of its line's parameters.
  EXPECT_EQ(errors_of(kLine + "master { address: 1 line: \"A\" bus_params { ttr: 100 } }\n"),
            Errs{"s.textproto:2:31: bus parameters of master 1: TTR 100 must be at least 256"});
  EXPECT_EQ(errors_of("line { name: \"A\" bus_params { hsa: 127 } }\n"),
            Errs{"s.textproto:1:31: hsa 127 is out of range 1..126"});
  EXPECT_EQ(errors_of("line { name: \"A\" bus_params { max_retry: 16 } }\n"),
            Errs{"s.textproto:1:31: max_retry 16 is out of range 0..15"});
  EXPECT_EQ(errors_of(kLine + "line { name: \"A\" }\n"),
            Errs{"s.textproto:2:8: line \"A\" is defined twice"});
}

TEST(ScenarioParser, FaultTimes) {
  EXPECT_EQ(errors_of(kLine + "duration: \"5s\"\nfault { at: \"6s\" short_circuit { line: \"A\" } }\n"),
            Errs{"s.textproto:3:9: fault at 6s is after the end of the run (5s)"});
  EXPECT_EQ(errors_of(kLine + "duration: \"5s\"\n"
                              "fault { at: \"2s\" repair_at: \"2s\" short_circuit { line: \"A\" } }\n"),
            Errs{"s.textproto:3:18: repair_at 2s is not after the fault (at 2s)"});
  EXPECT_EQ(errors_of(kLine + "duration: \"5s\"\n"
                              "fault { at: \"2s\" repair_at: \"1h\" short_circuit { line: \"A\" } }\n"),
            Errs{"s.textproto:3:18: repair_at 1h is after the end of the run (5s)"});
  EXPECT_EQ(errors_of(kLine + "fault { at: \"2s\" }\n"),
            Errs{"s.textproto:2:1: fault needs a kind: cable_cut, short_circuit, noise, "
                 "power_loss, transceiver_failure or babble"});
  EXPECT_EQ(errors_of(kLine + "fault { short_circuit { line: \"A\" } }\n"),
            Errs{"s.textproto:2:1: fault needs a time: at: \"2s\""});
}

TEST(ScenarioParser, CableCutStationsMustBeOnTheLine) {
  const std::string two_lines = kLine +
                                "line { name: \"B\" }\n"
                                "master { address: 1 line: \"A\" }\n"
                                "passive_station { address: 20 line: \"B\" }\n";
  EXPECT_EQ(errors_of(two_lines +
                      "fault { at: \"1s\" cable_cut { line: \"A\" between_a: 1 between_b: 20 } }\n"),
            Errs{"s.textproto:5:53: cable_cut on line \"A\": station 20 is on line \"B\""});
  EXPECT_EQ(errors_of(two_lines +
                      "fault { at: \"1s\" cable_cut { line: \"A\" between_a: 1 between_b: 99 } }\n"),
            Errs{"s.textproto:5:53: cable_cut: no station 99 on line \"A\""});
  EXPECT_EQ(errors_of(two_lines + "fault { at: \"1s\" cable_cut { line: \"A\" between_a: 1 } }\n"),
            Errs{"s.textproto:5:18: cable_cut needs two stations: between_a and between_b"});
  EXPECT_EQ(errors_of(two_lines + "fault { at: \"1s\" cable_cut { line: \"C\" } }\n"),
            Errs{"s.textproto:5:30: unknown line \"C\""});
  EXPECT_EQ(errors_of(two_lines + "fault { at: \"1s\" power_loss { line: \"B\" address: 1 } }\n"),
            Errs{"s.textproto:5:41: power_loss on line \"B\": station 1 is on line \"A\""});
}

TEST(ScenarioParser, StationDetails) {
  EXPECT_EQ(errors_of(kLine + "passive_station { address: 10 line: \"A\" response_delay: 200 }\n"),
            Errs{"s.textproto:2:41: response_delay 200 bit times is outside [min TSDR, max TSDR] "
                 "= [11, 150] of line \"A\""});
  EXPECT_EQ(errors_of(kLine + "passive_station { address: 10 line: \"A\" response_length: 247 }\n"),
            Errs{"s.textproto:2:41: response_length 247 is over the maximum of 246 octets"});
  EXPECT_EQ(errors_of(kLine + "master { address: 1 line: \"A\" poll { address: [2, 1] } }\n"),
            Errs{"s.textproto:2:38: master 1 cannot poll itself"});
  EXPECT_EQ(errors_of(kLine + "master { address: 1 line: \"A\" poll { length: 3 } }\n"),
            Errs{"s.textproto:2:31: poll needs at least one address"});
  EXPECT_EQ(errors_of(kLine + "serial { line: \"A\" mode: MONITOR address: 3 }\n"),
            Errs{"s.textproto:2:34: a serial MONITOR has no address (only a STATION has one)"});
  EXPECT_EQ(errors_of(kLine + "serial { line: \"A\" mode: STATION }\n"),
            Errs{"s.textproto:2:1: a serial STATION needs the address of the external station"});
}

TEST(ScenarioParser, CollectsEveryError) {
  const auto errs = errors_of(kLine +
                              "master { address: 200 line: \"A\" }\n"
                              "passive_station { address: 5 line: \"X\" }\n");
  EXPECT_EQ(errs, (Errs{"s.textproto:2:10: address 200 is out of range 0..126",
                        "s.textproto:3:30: unknown line \"X\""}));
}

TEST(ScenarioParser, AnEmptyScenarioIsLocatedAtTheStartOfTheFile) {
  EXPECT_EQ(errors_of("name: \"x\"\n"), Errs{"s.textproto:1:1: the scenario has no line"});
  EXPECT_EQ(errors_of(""), Errs{"s.textproto:1:1: the scenario has no line"});
}

TEST(ScenarioParser, MissingFileIsAnError) {
  const auto r = load_scenario_file("/nonexistent/x.textproto");
  ASSERT_EQ(r.errors.size(), 1u);
  EXPECT_EQ(r.errors[0].str(),
            "/nonexistent/x.textproto: cannot read the file: No such file or directory");
}

TEST(ScenarioParser, BuiltInDefaultAndExamplesAreValid) {
  const auto d = parse_scenario(default_scenario_text(), "<default>");
  EXPECT_TRUE(d.ok()) << (d.errors.empty() ? "" : d.errors[0].str());
  const auto m = load_scenario_file(PBVBUS_SOURCE_DIR "/examples/multimaster.textproto");
  EXPECT_TRUE(m.ok()) << (m.errors.empty() ? "" : m.errors[0].str());
}

}  // namespace
}  // namespace pbvbus::tools
