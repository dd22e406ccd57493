// Capture probes from the scenario (`capture { line: "A" at: 14 }`) and the command line
// (`pbvbus run --capture FILE --probe first|last|ADDR`): where each line is captured, the
// interface names, and the errors with FILE:LINE:COLUMN.
#include <gtest/gtest.h>

#include <fstream>
#include <unistd.h>
#include <sstream>
#include <string>
#include <vector>

#include "pbvbus/captures/pcapng_reader.hpp"
#include "pbvbus/simulation/capture_probes.hpp"
#include "pbvbus/tools/commands.hpp"
#include "pbvbus/scenario/scenario.hpp"

namespace pbvbus::tools {
namespace {

using Errs = std::vector<std::string>;

const std::string kStations = R"(duration: "20ms"
line { name: "A" }
line { name: "B" }
master { address: 1 line: "A" poll { address: [14] } }
passive_station { address: 14 line: "A" }
master { address: 3 line: "A" }
master { address: 2 line: "B" }
passive_station { address: 20 line: "B" }
)";  // 8 lines

std::vector<std::string> errors_of(const std::string& text) {
  std::vector<std::string> out;
  for (const auto& d : parse_scenario(text, "s.textproto").errors) out.push_back(d.str());
  return out;
}

/// "name=position:where" per probe.
std::vector<std::string> probes_of(const std::string& text, ProbeDefault def = {}) {
  const auto r = parse_scenario(text, "s.textproto");
  EXPECT_TRUE(r.ok()) << (r.errors.empty() ? "" : r.errors[0].str());
  if (!r.ok()) return {};
  std::string why;
  const auto probes = plan_capture_probes(*r.plan, def, &why);
  EXPECT_TRUE(probes.has_value()) << why;
  std::vector<std::string> out;
  if (probes)
    for (const auto& p : *probes)
      out.push_back(std::to_string(p.line) + ":" + p.name + "=" + std::to_string(p.position) +
                    ":" + p.where);
  return out;
}

TEST(CaptureProbes, EveryLineGetsTheDefaultProbeUnlessTheScenarioPlacesIt) {
  EXPECT_EQ(probes_of(kStations), (Errs{"0:A=0:station 1", "1:B=0:station 2"}));
  EXPECT_EQ(probes_of(kStations, {ProbeDefault::Kind::Last, 0}),
            (Errs{"0:A=2:station 3", "1:B=1:station 20"}));
  EXPECT_EQ(probes_of(kStations + "capture { line: \"A\" at: 14 }\n"),
            (Errs{"0:A=1:station 14", "1:B=0:station 2"}));
  // Several probes on a line: one interface each, named LINE@ADDR, in file order; an entry
  // without `at` is the default position, which is not doubled.
  EXPECT_EQ(probes_of(kStations + "capture { line: \"A\" at: 3 }\ncapture { line: \"A\" }\n"
                                  "capture { line: \"A\" at: 1 }\n"),
            (Errs{"0:A@3=2:station 3", "0:A@1=0:station 1", "1:B=0:station 2"}));
  EXPECT_EQ(probes_of(kStations + "capture { line: \"B\" }\n", {ProbeDefault::Kind::Last, 0}),
            (Errs{"0:A=2:station 3", "1:B=1:station 20"}));
}

TEST(CaptureProbes, ADefaultAddressMustBeOnEveryLineThatTakesTheDefault) {
  const auto r = parse_scenario(kStations, "s.textproto");
  ASSERT_TRUE(r.ok());
  std::string why;
  EXPECT_FALSE(plan_capture_probes(*r.plan, {ProbeDefault::Kind::Address, 14}, &why));
  EXPECT_EQ(why,
            "--probe 14: no station 14 on line \"B\" (a scenario entry capture { line: \"B\" at: "
            "N } places that line's probe)");
  EXPECT_EQ(probes_of(kStations + "capture { line: \"B\" at: 20 }\n",
                      {ProbeDefault::Kind::Address, 14}),
            (Errs{"0:A=1:station 14", "1:B=1:station 20"}));
}

TEST(CaptureProbes, ProbeDefaultParses) {
  EXPECT_EQ(parse_probe_default("first")->kind, ProbeDefault::Kind::First);
  EXPECT_EQ(parse_probe_default("last")->kind, ProbeDefault::Kind::Last);
  EXPECT_EQ(parse_probe_default("14")->kind, ProbeDefault::Kind::Address);
  EXPECT_EQ(parse_probe_default("14")->address, 14);
  EXPECT_EQ(parse_probe_default("0")->address, 0);
  for (const char* bad : {"", "127", "-1", "1x", "middle", " 3"})
    EXPECT_FALSE(parse_probe_default(bad).has_value()) << bad;
}

TEST(CaptureProbes, ScenarioErrorsCarryFileLineAndColumn) {
  EXPECT_EQ(errors_of(kStations + R"(capture { line: "C" at: 1 }
capture { line: "A" at: 2 }
capture { line: "A" at: 99 }
capture { line: "A" at: 14 }
capture { line: "A" at: 14 }
capture { at: 1 }
capture { line: "B" }
capture { line: "B" }
)"),
            (Errs{"s.textproto:9:11: unknown line \"C\"",
                  "s.textproto:10:21: capture on line \"A\": station 2 is on line \"B\"",
                  "s.textproto:11:21: capture: no station 99 on line \"A\"",
                  "s.textproto:13:21: capture: a probe at station 14 on line \"A\" is already "
                  "given (at 12:21)",
                  "s.textproto:14:1: capture needs a line",
                  "s.textproto:16:1: capture: line \"B\" already has a probe at the default "
                  "position (at 15:1)"}));
}

struct Result {
  int rc;
  std::string out;
  std::string err;
};

Result run(const Args& args) {
  std::ostringstream out, err;
  const int rc = cmd_run(args, out, err);
  return {rc, out.str(), err.str()};
}

std::string temp_path(const std::string& name) {
  return std::string(PBVBUS_BINARY_DIR) + "/capture_probes_test_" + std::to_string(::getpid()) +
         "_" + name;
}

TEST(CaptureProbes, CommandLineProbeOption) {
  const std::string scenario = temp_path("s.textproto");
  std::ofstream(scenario) << kStations;
  const std::string pcap = temp_path("last.pcapng");

  auto r = run({scenario, "--probe", "last"});
  EXPECT_EQ(r.rc, 2);
  EXPECT_EQ(r.err, "pbvbus run: --probe places the capture's probe; it needs --capture\n"
                   "Try 'pbvbus run --help'.\n");
  r = run({scenario, "--capture", pcap, "--probe", "nowhere"});
  EXPECT_EQ(r.rc, 2);
  EXPECT_EQ(r.err, "pbvbus run: bad probe 'nowhere' (expected first, last or an address "
                   "0..126)\nTry 'pbvbus run --help'.\n");
  r = run({scenario, "--capture", pcap, "--probe"});
  EXPECT_EQ(r.rc, 2);
  r = run({scenario, "--capture", pcap, "--probe", "14", "--quiet"});
  EXPECT_EQ(r.rc, 2);
  EXPECT_EQ(r.err, "pbvbus run: --probe 14: no station 14 on line \"B\" (a scenario entry "
                   "capture { line: \"B\" at: N } places that line's probe)\n");

  r = run({scenario, "--capture", pcap, "--probe", "last", "--quiet"});
  ASSERT_EQ(r.rc, 0) << r.err;
  captures::PcapngError e;
  auto reader = captures::PcapngReader::open(pcap, e);
  ASSERT_TRUE(reader) << e.to_string();
  captures::PcapngRecord rec;
  std::size_t n = 0;
  while (reader->next(rec)) ++n;
  ASSERT_FALSE(reader->error());
  EXPECT_GT(n, 10u);
  const auto& ifs = reader->interfaces();
  ASSERT_EQ(ifs.size(), 3u);
  EXPECT_EQ(ifs[0].name, "A");
  EXPECT_EQ(ifs[0].description, "PROFIBUS-DP 1.5 Mbit/s, probe at station 3");
  EXPECT_EQ(ifs[1].name, "B");
  EXPECT_EQ(ifs[1].description, "PROFIBUS-DP 1.5 Mbit/s, probe at station 20");
  EXPECT_EQ(ifs[2].name, "events");
  std::remove(pcap.c_str());
  std::remove(scenario.c_str());
}

}  // namespace
}  // namespace pbvbus::tools
