// `pbvbus run SCENARIO --dp2 ...`: a class-2 master joins a running FDL scenario at the lowest
// free address, sends its requests at their virtual times and reports the results; the request
// telegrams in the capture are the bytes the standard prescribes (written here by hand).
#include <gtest/gtest.h>

#include <algorithm>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "pbvbus/captures/pcapng_reader.hpp"
#include "pbvbus/tools/commands.hpp"

namespace pbvbus::tools {
namespace {

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

std::string write_temp(const std::string& name, const std::string& text) {
  const std::string path = std::string(PBVBUS_BINARY_DIR) + "/" + name;
  std::ofstream(path) << text;
  return path;
}

// Master 1 polls plain FDL passive station 10; addresses 0 and 2.. are free, so the class-2
// master takes 0.
const char* kScenario = R"(
name: "class2-fdl"
seed: 7
duration: "1500ms"
line { name: "A" baud: "1.5M" }
master { address: 1 line: "A" poll { address: [10] length: 2 } }
passive_station { address: 10 line: "A" response_length: 0 }
)";

TEST(Class2Cli, AgainstPlainFdlStations) {
  const std::string scen = write_temp("class2_fdl.textproto", kScenario);
  const std::string cap = std::string(PBVBUS_BINARY_DIR) + "/class2_fdl.pcapng";
  const Result r = run({scen, "--capture", cap, "--dp2", "1s:get_cfg:10", "--dp2", "1s:slave_diag:20"});
  ASSERT_EQ(r.rc, 0) << r.err;
  std::cout << r.out;
  EXPECT_NE(r.out.find("class-2 master 0 on A:\n"), std::string::npos) << r.out;
  // Station 20 does not exist: no reply after the retries.
  EXPECT_NE(r.out.find("  1.000 s slave_diag 20: NoResponse at "), std::string::npos) << r.out;

  // Get_Cfg.req from 0 to 10: SD2, DA 0x8A, SA 0x80, FC 0x6D (SRD high, first FCB), DSAP 59
  // (0x3B), SSAP 62 (0x3E); FCS = 8A+80+6D+3B+3E = 0x1F0 -> F0.
  const std::vector<std::uint8_t> get_cfg = {0x68, 0x05, 0x05, 0x68, 0x8A, 0x80, 0x6D, 0x3B, 0x3E, 0xF0, 0x16};
  captures::PcapngError err;
  auto c = captures::read_pcapng_file(cap, err);
  ASSERT_TRUE(c) << err.to_string();
  const auto it = std::find_if(c->records.begin(), c->records.end(),
                               [&](const captures::PcapngRecord& rec) { return rec.bytes == get_cfg; });
  ASSERT_NE(it, c->records.end());
  EXPECT_GE(it->ts_ns, 1'000'000'000);
  EXPECT_LT(it->ts_ns, 1'100'000'000);
}

TEST(Class2Cli, JsonAndErrors) {
  const std::string scen = write_temp("class2_fdl2.textproto", kScenario);
  Result r = run({scen, "--json", "--dp2", "1s:slave_diag:20"});
  ASSERT_EQ(r.rc, 0) << r.err;
  EXPECT_NE(r.out.find(",\"class2\":[{\"time_ns\":1000000000,\"done_ns\":"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("\"service\":\"slave_diag\",\"station\":20,\"master\":0,\"status\":\"NoResponse\","
                       "\"bytes\":\"\",\"text\":\"\"}]}"),
            std::string::npos)
      << r.out;

  r = run({scen, "--dp2", "1s:get_cfg:500"});
  EXPECT_EQ(r.rc, 2);
  EXPECT_EQ(r.err,
            "pbvbus run: --dp2 '1s:get_cfg:500': bad station '500' (expected an address 0..126)\n"
            "Try 'pbvbus run --help'.\n");
  r = run({scen, "--dp2", "1s:get_cfg:10", "--dp2-address", "10"});
  EXPECT_EQ(r.rc, 2);
  EXPECT_EQ(r.err, "pbvbus run: --dp2-address 10 is in use on line 'A'\n");
  r = run({scen, "--dp2", "1s:get_cfg:10", "--dp2-line", "B"});
  EXPECT_EQ(r.rc, 2);
  EXPECT_EQ(r.err, "pbvbus run: --dp2-line: no line named 'B' in the scenario\n");
  r = run({"--help"});
  EXPECT_NE(r.out.find("  --dp2 SPEC "), std::string::npos);
}

}  // namespace
}  // namespace pbvbus::tools
