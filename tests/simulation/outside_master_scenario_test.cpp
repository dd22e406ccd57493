// Scenarios for a DP master outside pbvbus: dp_slave without `master`, serial `timing`, and the
// report's slave view and wire statistics when the master is a program behind a pty.
#include <fcntl.h>
#include <gtest/gtest.h>
#include <poll.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <thread>

#include "pbvbus/dp/sap.hpp"
#include "pbvbus/fdl/telegram.hpp"
#include "pbvbus/scenario/scenario.hpp"
#include "pbvbus/simulation/simulation.hpp"
#include "pbvbus/reports/run_report.hpp"

namespace pbvbus::tools {
namespace {

const std::string kFile = PBVBUS_SOURCE_DIR "/examples/test.textproto";  // GSD paths: examples/

std::string outside(const std::string& serial_extra = "") {
  return "name: \"outside\"\nduration: \"1s\"\n"
         "line { name: \"DP\" baud: \"45.45k\" }\n"
         "serial { line: \"DP\" mode: STATION address: 2 " + serial_extra + "}\n"
         "dp_slave { address: 3 line: \"DP\" gsd: \"gsd/PBVB0A01.gsd\" }\n"
         "dp_slave { address: 4 line: \"DP\" gsd: \"gsd/PBVB0A02.gsd\"\n"
         "  modules: [\"8DI DC24V\", \"8DO DC24V/0.5A\", \"2AO U/I 16 bit\"] }\n";
}

TEST(OutsideMasterScenario, SlavesWithoutAMasterAndNoDpMasterAtAll) {
  const auto r = parse_scenario(outside(), kFile);
  ASSERT_TRUE(r.ok()) << r.errors.front().str();
  EXPECT_TRUE(r.plan->dp_masters.empty());
  ASSERT_EQ(r.plan->dp_slaves.size(), 2u);
  for (const auto& s : r.plan->dp_slaves) {
    EXPECT_EQ(s.master, dp::kNoMaster);
    // What a configuration tool would give the outside master: Set_Prm with the default
    // watchdog (1 s) and the GSD's User_Prm_Data, Chk_Cfg with the modules' identifiers.
    EXPECT_EQ(s.params.wd_fact_1, 10);
    EXPECT_EQ(s.params.wd_fact_2, 10);
  }
  EXPECT_EQ(r.plan->dp_slaves[0].params.chk_cfg_du(), (std::vector<std::uint8_t>{0x11, 0x21}));
  EXPECT_EQ(r.plan->dp_slaves[1].params.chk_cfg_du(), (std::vector<std::uint8_t>{0x10, 0x20, 0x61}));
  // The line's bus parameters are still derived for the slaves: max TSDR and TSL from the
  // 45.45k defaults (400, 640; above the GSDs' MaxTsdr_45.45 of 250), TTR from their frame
  // lengths (outputs, inputs) = (2, 2) and (5, 1).
  const auto& p = r.plan->lines[0].params;
  EXPECT_EQ(p.max_tsdr, 400u);
  EXPECT_EQ(p.tsl, 640u);
  EXPECT_EQ(p.ttr, dp_ttr(p, {{2, 2}, {5, 1}}));
  EXPECT_NE(p.ttr, fdl::BusParams::defaults(bus::Baud::k45_45).ttr);
}

TEST(OutsideMasterScenario, AMasterNamedMustStillExist) {
  const auto r = parse_scenario(
      "line { name: \"DP\" }\n"
      "dp_slave { address: 3 line: \"DP\" gsd: \"gsd/PBVB0A01.gsd\" master: 1 }\n",
      kFile);
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.errors[0].str(), kFile + ":2:58: no dp_master 1 on line \"DP\"");
}

TEST(OutsideMasterScenario, SerialTimingIsInterfaceUnlessRawIsAsked) {
  const auto d = parse_scenario(outside(), kFile);
  ASSERT_TRUE(d.ok());
  EXPECT_EQ(d.plan->proto.serial(0).timing(), scenario::Serial::INTERFACE);
  const auto raw = parse_scenario(outside("timing: RAW "), kFile);
  ASSERT_TRUE(raw.ok());
  EXPECT_EQ(raw.plan->proto.serial(0).timing(), scenario::Serial::RAW);
  const auto bad = parse_scenario(outside("timing: FAST "), kFile);
  ASSERT_FALSE(bad.ok());
  EXPECT_NE(bad.errors[0].str().find(":4:"), std::string::npos) << bad.errors[0].str();
  EXPECT_NE(bad.errors[0].str().find("FAST"), std::string::npos) << bad.errors[0].str();

  Simulation a(*d.plan), b(*raw.plan);
  EXPECT_EQ(a.report(0).serial.at(0).timing, "interface");
  EXPECT_EQ(b.report(0).serial.at(0).timing, "raw");
  EXPECT_EQ(a.report(0).serial.at(0).address, std::optional<std::uint8_t>(2));
}

std::string hex(const std::vector<std::uint8_t>& b) {
  std::string s;
  char buf[4];
  for (std::uint8_t x : b) {
    std::snprintf(buf, sizeof buf, "%02X", x);
    s += buf;
  }
  return s;
}

// examples/outside-master.textproto loads, and the --slave arguments its comment gives for the
// test master are what the plan says a configuration tool would put into a master.
TEST(OutsideMasterScenario, ExampleLoadsAndItsCommentIsRight) {
  const std::string file = PBVBUS_SOURCE_DIR "/examples/outside-master.textproto";
  const auto r = load_scenario_file(file);
  ASSERT_TRUE(r.ok()) << r.errors.front().str();
  EXPECT_TRUE(r.plan->dp_masters.empty());
  ASSERT_EQ(r.plan->dp_slaves.size(), 2u);
  EXPECT_EQ(r.plan->proto.serial(0).timing(), scenario::Serial::INTERFACE);
  EXPECT_EQ(r.plan->proto.serial(0).link(), "/tmp/pbvbus-dp");
  std::ifstream in(file);
  const std::string text{std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
  for (const auto& sp : r.plan->dp_slaves) {
    char ident[8];
    std::snprintf(ident, sizeof ident, "0x%04X", sp.params.ident);
    const std::string arg = "--slave " + std::to_string(sp.address) + ":" + ident + ":" +
                            hex(sp.params.user_prm) + ":" + hex(sp.params.chk_cfg_du()) + ":" +
                            std::to_string(sp.inputs) + ":" + std::to_string(sp.outputs);
    EXPECT_NE(text.find(arg), std::string::npos) << arg;
    EXPECT_EQ(sp.master, dp::kNoMaster);
  }
}

// --- a scripted program behind the pty --------------------------------------------------------

std::vector<std::uint8_t> frame(std::uint8_t da, std::uint8_t fc, std::optional<std::uint8_t> dsap,
                                const std::vector<std::uint8_t>& data) {
  fdl::FrameSpec s;
  s.da = da;
  s.sa = 2;
  s.fc = fc;
  s.dsap = dsap;
  if (dsap) s.ssap = dp::kSapMs0;
  s.data = data;
  fdl::Frame f;
  EXPECT_EQ(fdl::encode(s, f), fdl::EncodeError::None);
  return {f.bytes().begin(), f.bytes().end()};
}

std::vector<std::uint8_t> read_all(int fd) {
  std::vector<std::uint8_t> out;
  std::uint8_t buf[4096];
  for (;;) {
    const ssize_t n = ::read(fd, buf, sizeof buf);
    if (n <= 0) break;
    out.insert(out.end(), buf, buf + n);
  }
  return out;
}

// A program writes a whole start-up and two Data_Exchanges for slave 3 in one go, as a master
// that does not wait would. The INTERFACE attachment paces them (reply or slot time, TSYN);
// the report then shows the slave's own view and the wire's live list, although no pbvbus
// master exists.
TEST(OutsideMasterScenario, ReportShowsTheSlavesOwnViewAndTheWire) {
  const auto r = parse_scenario(outside(), kFile);
  ASSERT_TRUE(r.ok()) << r.errors.front().str();
  const dp::SlaveParams& sp = r.plan->dp_slaves[0].params;
  Simulation sim(*r.plan);
  const int fd = ::open(sim.serial_ports()[0].path.c_str(), O_RDWR | O_NOCTTY | O_NONBLOCK);
  ASSERT_GE(fd, 0);
  sim.run_until(bus::kTicksPerMs);  // powered: the attachment listens from now on
  using fdl::RequestFn;
  const auto fc = [](bool fcv, bool fcb) { return fdl::make_request_fc(RequestFn::SrdHigh, fcv, fcb); };
  std::vector<std::uint8_t> all;
  for (const auto& f : {frame(3, fc(false, true), dp::kSapSlaveDiag, {}),
                        frame(3, fc(true, false), dp::kSapSetPrm, sp.set_prm_du()),
                        frame(3, fc(true, true), dp::kSapChkCfg, sp.chk_cfg_du()),
                        frame(3, fc(true, false), dp::kSapSlaveDiag, {}),
                        frame(3, fc(true, true), std::nullopt, {0xA5, 0x01}),
                        frame(3, fc(true, false), std::nullopt, {0xA5, 0x02}),
                        frame(9, fc(false, true), dp::kSapSlaveDiag, {}),  // nobody at 9
                        frame(3, fc(true, true), dp::kSapSlaveDiag, {})})
    all.insert(all.end(), f.begin(), f.end());
  ASSERT_EQ(::write(fd, all.data(), all.size()), static_cast<ssize_t>(all.size()));
  std::this_thread::sleep_for(std::chrono::milliseconds(20));
  sim.poll_serial();
  sim.run_until(500 * bus::kTicksPerMs);
  std::this_thread::sleep_for(std::chrono::milliseconds(20));
  const auto replies = read_all(fd);
  ::close(fd);
  EXPECT_FALSE(replies.empty());

  const Report rep = sim.report(0.0);
  ASSERT_EQ(rep.dp_slaves.size(), 2u);
  const DpSlaveView& v = rep.dp_slaves[0];
  EXPECT_EQ(v.address, 3);
  EXPECT_EQ(v.line, "DP");
  EXPECT_EQ(v.master, std::nullopt);
  EXPECT_EQ(v.state, "Data_Exch");
  EXPECT_EQ(v.owner, std::optional<std::uint8_t>(2));
  EXPECT_EQ(v.watchdog, std::optional<bus::Ticks>(bus::kTicksPerSecond));
  EXPECT_EQ(v.stats.set_prm, 1u);
  EXPECT_EQ(v.stats.chk_cfg, 1u);
  EXPECT_EQ(v.stats.slave_diag, 3u);
  EXPECT_EQ(v.stats.data_exchange, 2u);
  EXPECT_EQ(v.stats.refused, 0u);
  EXPECT_EQ(v.outputs, (std::vector<std::uint8_t>{0xA5, 0x02}));
  // The default COUNTER behaviour: a big-endian count of the DP cycles before this one.
  EXPECT_EQ(v.inputs, (std::vector<std::uint8_t>{0x00, 0x01}));
  EXPECT_EQ(v.fdl.dropped_tsyn, 0u);
  EXPECT_EQ(rep.dp_slaves[1].state, "Wait_Prm");
  EXPECT_EQ(rep.dp_slaves[1].owner, std::nullopt);
  EXPECT_TRUE(rep.dp_masters.empty());

  // The wire: the program's station is a master, 3 a slave; 9 never answered.
  ASSERT_EQ(rep.lines.size(), 1u);
  const LineReport& l = rep.lines[0];
  std::map<int, fdl::StationType> live;
  for (const auto& e : l.live) live[e.address] = e.type;
  EXPECT_EQ(live, (std::map<int, fdl::StationType>{{2, fdl::StationType::MasterInRing},
                                                   {3, fdl::StationType::Slave}}));
  EXPECT_EQ(l.traffic.no_response, 1u);
  EXPECT_EQ(l.traffic.repeats, 0u);
  EXPECT_EQ(l.traffic.short_idle, 0u);
  EXPECT_EQ(l.tsyn_drops, 0u);

  // The attachment held the telegrams it could not send yet.
  ASSERT_EQ(rep.serial.size(), 1u);
  const auto& st = rep.serial[0].stats;
  EXPECT_EQ(st.frames_in, 8u);
  EXPECT_EQ(st.held, 7u);
  EXPECT_EQ(st.queue_max, 8u);
  // The longest wait: behind the unanswered request to 9, a slot time (640 bit times) after it.
  EXPECT_GE(st.hold_max, 640 * bus::ticks_per_bit(bus::Baud::k45_45));
  EXPECT_EQ(st.frames_out, 7u);  // the seven replies of slave 3
  EXPECT_EQ(rep.serial[0].receivers_tsyn_drops, 0u);

  std::ostringstream json;
  write_json(rep, json);
  const std::string j = json.str();
  EXPECT_NE(j.find("\"dp_slaves\":[\n{\"line\":\"DP\",\"address\":3,"), std::string::npos) << j;
  EXPECT_NE(j.find("\"master\":null,\"state\":\"Data_Exch\",\"owner\":2,\"watchdog_ns\":1000000000,"),
            std::string::npos)
      << j;
  EXPECT_NE(j.find("\"inputs\":\"00 01\",\"outputs\":\"A5 02\""), std::string::npos) << j;
  EXPECT_NE(j.find("\"requests\":{\"set_prm\":1,\"chk_cfg\":1,\"slave_diag\":3,\"data_exchange\":2,"),
            std::string::npos)
      << j;
  EXPECT_NE(j.find("\"timing\":\"interface\",\"frames_in\":8,"), std::string::npos) << j;
  EXPECT_NE(j.find("\"no_response\":1,\"retries\":0,\"short_idle\":0,\"tsyn_drops\":0}"),
            std::string::npos)
      << j;
  std::ostringstream text;
  write_text(rep, text);
  EXPECT_NE(text.str().find("its own view: Data_Exch, owner 2 (no pbvbus master)"), std::string::npos)
      << text.str();
}

}  // namespace
}  // namespace pbvbus::tools
