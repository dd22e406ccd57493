// `pbvbus run SCENARIO --dp2 ...`: a class-2 master joins a running FDL scenario at the lowest
// free address, sends its requests at their virtual times and reports the results; the request
// telegrams in the capture are the bytes the standard prescribes (written here by hand).
#include <gtest/gtest.h>

#include <algorithm>
#include <fstream>
#include <iostream>
#include <sstream>
#include <string>
#include <vector>

#include "pbvbus/captures/pcapng_reader.hpp"
#include "pbvbus/gsd/gsd.hpp"
#include "pbvbus/slaves/slave_model.hpp"
#include "pbvbus/dp/master.hpp"
#include "pbvbus/fdl/active_station.hpp"
#include "pbvbus/tools/class2_cli.hpp"
#include "pbvbus/scenario/scenario.hpp"
#include "pbvbus/simulation/simulation.hpp"
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
  EXPECT_NE(r.out.find("class-2 master 0 on A:\n"), std::string::npos) << r.out;
  // Station 20 does not exist: no reply after the retries.
  EXPECT_NE(r.out.find("  1.000 s slave_diag 20: no response at 1.0"), std::string::npos) << r.out;
  // A plain FDL station acknowledges the SRD with SC: no configuration came back.
  EXPECT_NE(r.out.find("  1.000 s get_cfg 10: no data (SC) at 1.0"), std::string::npos) << r.out;

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
  EXPECT_NE(r.out.find("\"service\":\"slave_diag\",\"station\":20,\"master\":0,\"status\":\"no response\","
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

// DP systems are not in scenarios yet: the test attaches a class-1 dp::Master (address 1) with
// the PBVB0A01 compact slave at 5 (module "16DI/16DO DC24V" = 0x11 0x21: 2 input and 2 output
// octets), and a second PBVB0A01 at 126 that nobody parameterises, to the scenario's line.
TEST(Class2Cli, AgainstDpSlaves) {
  const auto loaded = parse_scenario(R"(
name: "class2-dp"
seed: 1
duration: "3s"
line { name: "dp" baud: "1.5M" }
passive_station { address: 50 line: "dp" response_length: 0 }
)",
                                     "<test>");
  ASSERT_TRUE(loaded.ok());
  Simulation sim(*loaded.plan);
  const fdl::BusParams bp = loaded.plan->lines[0].params;
  auto gsd = devices::load_gsd(std::string(PBVBUS_SOURCE_DIR) + "/examples/gsd/PBVB0A01.gsd");
  ASSERT_TRUE(gsd.ok());
  const std::vector<devices::ModuleChoice> mods = {devices::ModuleChoice::named("16DI/16DO DC24V")};
  auto sp = devices::master_slave_params(*gsd.file, mods, 5);
  ASSERT_TRUE(sp.ok());
  dp::Master master(dp::MasterParams{}, std::vector<dp::SlaveParams>{*sp.value});
  fdl::ActiveStation master_station(1, bp, master);
  sim.line(0).attach(master_station, "master 1");
  devices::SlaveModelOptions o;
  o.bus_params = bp;
  o.address = 5;
  auto s5 = devices::SlaveModel::build(*gsd.file, mods, o);
  ASSERT_TRUE(s5.ok());
  ASSERT_EQ(s5.model->set_behaviour(0, devices::IoBehaviour::constant_value({0xA5, 0x3C})), "");
  sim.line(0).attach(*s5.model, "slave 5");
  o.address = 126;
  auto s126 = devices::SlaveModel::build(*gsd.file, mods, o);
  ASSERT_TRUE(s126.ok());
  sim.line(0).attach(*s126.model, "slave 126");

  Class2Options c2;
  for (const char* spec : {"1s:get_cfg:5", "1s:rd_inp:5", "1s:rd_outp:5", "1s:slave_diag:5",
                           "2s:set_slave_add:126:new=7,ident=0x0A01", "2500ms:get_cfg:7",
                           "2500ms:get_cfg:126"}) {
    std::string err;
    auto r = parse_class2_spec(spec, err);
    ASSERT_TRUE(r) << err;
    c2.requests.push_back(*r);
  }
  std::string err;
  auto cli = Class2Cli::attach(sim, c2, err);
  ASSERT_TRUE(cli) << err;
  EXPECT_EQ(cli->address(), 0);
  sim.start();
  sim.run_until(3 * bus::kTicksPerSecond);
  std::ostringstream text;
  cli->write_text(text);
  EXPECT_EQ(text.str().rfind("class-2 master 0 on dp:\n  1.000 s get_cfg 5: OK 11 21 (2 B in, 2 B out) at 1.0", 0), 0u) << text.str();
  const auto& out = cli->outcomes();
  ASSERT_EQ(out.size(), 7u);
  for (const auto& oc : out) EXPECT_GT(oc.done, oc.at) << format_class2_line(oc);
  using B = std::vector<std::uint8_t>;
  EXPECT_EQ(out[0].status, "OK");
  EXPECT_EQ(out[0].bytes, (B{0x11, 0x21}));
  EXPECT_EQ(out[0].text, "2 B in, 2 B out");
  EXPECT_EQ(out[1].status, "OK");
  EXPECT_EQ(out[1].bytes, (B{0xA5, 0x3C}));
  EXPECT_EQ(out[2].status, "OK");
  EXPECT_EQ(out[2].bytes, (B{0x00, 0x00}));
  EXPECT_EQ(out[3].status, "OK");
  // In data exchange with master 1: Station_Status_1 0, Station_Status_2 0x0C (bit 2 always 1,
  // WD_On from master 1's Set_Prm), Station_Status_3 0, Diag.Master_Add 1, ident 0x0A01.
  EXPECT_EQ(out[3].bytes, (B{0x00, 0x0C, 0x00, 0x01, 0x0A, 0x01}));
  EXPECT_EQ(format_class2_line(out[3]).rfind("1.000 s slave_diag 5: OK 00 0C 00 01 0A 01 (WD_On | Master_Add 1 | Ident 0x0A01) at 1.0", 0), 0u);
  EXPECT_EQ(out[4].status, "OK");
  EXPECT_EQ(out[5].status, "OK");
  EXPECT_EQ(out[5].bytes, (B{0x11, 0x21}));
  EXPECT_EQ(out[6].status, "no response");  // it is at 7 now
}

// examples/dp-basic.textproto (DP master system from the scenario): Get_Cfg of the compact
// PBVB0A01 at 3 gives its module's identifiers; two MSAC_C2 requests to one slave at the same
// time run one after the other (one connection per slave), neither is rejected.
TEST(Class2Cli, DpBasicScenario) {
  const Result r = run({PBVBUS_SOURCE_DIR "/examples/dp-basic.textproto", "--json", "--dp2", "1s:get_cfg:3",
                        "--dp2", "1500ms:read:5:slot=1,index=2,len=8", "--dp2",
                        "1500ms:write:5:slot=1,index=2,data=0102"});
  ASSERT_EQ(r.rc, 0) << r.err;
  const std::size_t c2 = r.out.find(",\"class2\":[");
  ASSERT_NE(c2, std::string::npos) << r.out;
  const std::string j = r.out.substr(c2);
  EXPECT_NE(j.find("\"service\":\"get_cfg\",\"station\":3,\"master\":0,\"status\":\"OK\",\"bytes\":\"1121\","
                   "\"text\":\"2 B in, 2 B out\"}"),
            std::string::npos)
      << j;
  EXPECT_EQ(j.find("pending"), std::string::npos) << j;
  EXPECT_EQ(j.find("rejected"), std::string::npos) << j;
  EXPECT_EQ(j.find("\"done_ns\":null"), std::string::npos) << j;
}

}  // namespace
}  // namespace pbvbus::tools
