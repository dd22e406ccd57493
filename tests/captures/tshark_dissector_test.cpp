// The capture as Debian's tshark sees it: plain tshark must open the file (USER 0), and the
// shipped Lua dissector (captures/lua/pbvbus.lua) must decode FDL, DP, DP-V1 and the event
// records. Frames are the goldens of protocol-facts.md Appendix 1 plus a few composed by hand
// from the tables of §D/§E (their FCS summed here, independently of the code under test).

#include <gtest/gtest.h>

#include <array>
#include <filesystem>

#include "capture_fixture.hpp"
#include "tshark_helpers.hpp"

#include "pbvbus/captures/pcapng_writer.hpp"

namespace pbvbus::captures {
namespace {

using test::Bytes;
namespace ts = ::pbvbus::test;

/// SD2 frame from its DA..DU octets (the B.1 layout), FCS summed by hand.
Bytes sd2(const Bytes& body) {
  Bytes f = {0x68, static_cast<std::uint8_t>(body.size()), static_cast<std::uint8_t>(body.size()),
             0x68};
  unsigned sum = 0;
  for (auto b : body) {
    f.push_back(b);
    sum += b;
  }
  f.push_back(static_cast<std::uint8_t>(sum & 0xFF));
  f.push_back(0x16);
  return f;
}

// Slave_Diag response 10 -> 1 with Ext_Diag: standard octets (Ext_Diag, WD_On + always-1,
// master 1, ident 0x1234), the §D.5 worked example (identifier block: module 8; channel block:
// module 8 channel 1 input bit short circuit; device block 3 octets), then a DP-V1
// Diagnostic_Alarm block for slot 2 with Seq_Nr 4, "error appears", 4 octets of user data.
const Bytes kDiagExt =
    sd2({0x81, 0x8A, 0x08, 0x3E, 0x3C, 0x08, 0x0C, 0x00, 0x01, 0x12, 0x34, 0x44, 0x00, 0x01, 0x00,
         0x88, 0x41, 0x21, 0x04, 0x10, 0x20, 0x30, 0x08, 0x01, 0x02, 0x21, 0xAA, 0xBB, 0xCC, 0xDD});
// Get_Cfg response 10 -> 1: 0x13 (4 B in), 0x31 (2 B in/out), 0xD7 (8 words in, consistent),
// special 0xC2: output length 0x81 (2 B consistent), input length 0x03 (4 B), 2 manufacturer
// octets AA BB; 0x00 empty slot.
const Bytes kGetCfgRes =
    sd2({0x81, 0x8A, 0x08, 0x3E, 0x3B, 0x13, 0x31, 0xD7, 0xC2, 0x81, 0x03, 0xAA, 0xBB, 0x00});
// Alarm_Ack 1 -> 10 to SAP 50 from SAP 51: slot 2, Diagnostic_Alarm, Seq_Nr 4 / error appears.
const Bytes kAlarmAck = sd2({0x8A, 0x81, 0x7D, 0x32, 0x33, 0x5C, 0x02, 0x01, 0x21});
// MSAC_C2 Abort from class-2 master 2 (SAP 50) to slave 10 connection SAP 48: subnet local,
// instance MSAC_C2, reason 3 (connection timeout).
const Bytes kC2Abort = sd2({0x8A, 0x82, 0x6D, 0x30, 0x32, 0x58, 0x01, 0x13, 0x00});

// Slave redundancy frames (§G.2/G.3), see SlaveRedundancyBlocks.
const Bytes kPrmCmd = sd2({0x8A, 0x81, 0x5D, 0x3D, 0x3E, 0x88, 0x0A, 0x0A, 0x0B, 0x12, 0x34, 0x00,
                           0x80, 0x00, 0x88, 0x08, 0x02, 0x00, 0x08, 0x02, 0x00, 0x00, 0x0A});
const Bytes kRedState = sd2({0x81, 0x8A, 0x08, 0x3E, 0x3C, 0x08, 0x0C, 0x00, 0x01, 0x12, 0x34, 0x08,
                             0x9F, 0x00, 0x08, 0x02, 0x0A, 0x01, 0x00});

class TsharkDissector : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    s_path = test::temp_capture_path("pbvbus_tshark_test");
    bus::Scheduler sched;
    bus::Line line(sched, "dp0", bus::Baud::k1_5M);
    test::IdleDevice m, s;
    line.attach(m, "master 3");
    line.attach(s, "slave 10");
    line.start();
    std::string why;
    auto w = PcapngWriter::open(s_path, {}, &why);
    ASSERT_TRUE(w) << why;
    line.add_tap(*w);
    const bus::Ticks us = bus::kTicksPerUs;
    bus::Ticks t = 0;
    auto put = [&](const Bytes& b, std::uint16_t flags = 0) {
      t += 100 * us;
      w->on_frame(test::tap_frame(line, b, t, flags));
    };
    put(test::kSlaveDiagReq);        // 1
    put(test::kSlaveDiagRes);        // 2
    put(test::kSetPrm);              // 3
    put(test::kSc);                  // 4
    put(test::kSetPrmDpv1);          // 5
    put(test::kChkCfg);              // 6
    put(test::kGlobalControlClear);  // 7
    put(test::kDataExchange);        // 8
    put(test::kDataExchangeRes);     // 9
    put(test::kDpv1Read);            // 10
    put(test::kDpv1ReadRes);         // 11
    put(test::kDpv1ReadNeg);         // 12
    put(test::kToken_2_to_5);        // 13
    Bytes hit = test::kDataExchange;
    hit[7] = 0xFF;                // AA -> FF: the FCS no longer matches
    put(hit, bus::kRxCollision);  // 14
    put(kDiagExt);                // 15
    put(kGetCfgRes);              // 16
    put(kAlarmAck);               // 17
    put(kC2Abort);                // 18
    put(test::kSetSlaveAdd);      // 19
    put(test::kFdlStatusReq);     // 20
    sched.schedule(t + 50 * us, [&] { line.set_cut_between(0, 1, true); });
    sched.run_until(t + 100 * us);  // 21: event
    line.remove_tap(*w);
  }
  static void TearDownTestSuite() { std::filesystem::remove(s_path); }
  void SetUp() override {
    if (!ts::tshark_available()) GTEST_SKIP() << ts::kNoTshark;
  }
  static std::string s_path;
};
std::string TsharkDissector::s_path;

TEST_F(TsharkDissector, PlainTsharkOpensTheFile) {
  const auto r = ts::tshark(
      s_path,
      {"-T", "fields", "-e", "frame.number", "-e", "frame.interface_name", "-e", "frame.len"},
      /*with_dissector=*/false);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("1\tdp0\t11\n"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("21\tevents\t"), std::string::npos) << r.out;
  if (ts::find_program("capinfos")) {
    const auto c = ts::run_command("capinfos -t -E " + ts::shell_quote(s_path));
    EXPECT_NE(c.out.find("pcapng"), std::string::npos) << c.out;
    EXPECT_NE(c.out.find("Per packet"), std::string::npos) << c.out;  // USER 0 + USER 1
    EXPECT_NE(c.out.find("USER 0 (20)"), std::string::npos) << c.out;
    EXPECT_NE(c.out.find("USER 1 (1)"), std::string::npos) << c.out;
  }
  const auto enc = ts::run_command("tshark -n -r " + ts::shell_quote(s_path) +
                                   " -T fields -e frame.encap_type -c 1");
  EXPECT_EQ(enc.out, "45\n");  // WTAP_ENCAP_USER0
  const auto v = ts::tshark(s_path, {"-V", "-c", "1"}, /*with_dissector=*/false);
  EXPECT_NE(v.out.find("Encapsulation type: USER 0 (45)"), std::string::npos) << v.out;
  EXPECT_NE(v.out.find("Interface name: dp0"), std::string::npos) << v.out;
  // The first frame starts at 100 us of virtual time; if_tsresol 9 keeps the nanoseconds.
  EXPECT_NE(v.out.find("Epoch Time: 0.000100000 seconds"), std::string::npos) << v.out;
}

TEST_F(TsharkDissector, InfoColumn) {
  const auto info = ts::tshark_info(s_path);
  ASSERT_EQ(info.size(), 21u);
  EXPECT_EQ(info[0], "SRD_high 1→10 Slave_Diag.req FCB=1 FCV=0");
  EXPECT_EQ(info[1],
            "10→1 DL Slave_Diag.res ident 0x1234 master none [Station_Not_Ready, Prm_Req]");
  EXPECT_EQ(info[2], "SRD_high 1→10 Set_Prm.req ident 0x1234 WD 1000 ms FCB=0 FCV=1");
  EXPECT_EQ(info[3], "SC");
  EXPECT_EQ(info[5], "SRD_high 1→10 Chk_Cfg.req 2 identifiers FCB=1 FCV=1");
  EXPECT_EQ(info[6], "SDN_high 1→127 Global_Control.req Clear group 0x00");
  EXPECT_EQ(info[7], "SRD_high 1→10 Data_Exchange.req 2 B FCB=0 FCV=1");
  EXPECT_EQ(info[8], "10→1 DL Data_Exchange.res 1 B");
  EXPECT_EQ(info[9], "SRD_high 1→10 MSAC_C1 Read.req slot 0 index 0 len 64 FCB=1 FCV=1");
  EXPECT_EQ(info[10], "10→1 DL MSAC_C1 Read.res slot 0 index 0 len 2");
  EXPECT_EQ(info[11], "10→1 DL MSAC_C1 Read.res- access: invalid index");
  EXPECT_EQ(info[12], "Token 2→5");
  EXPECT_EQ(info[13], "SRD_high 1→10 Data_Exchange.req 2 B FCB=0 FCV=1 [FCS mismatch]");
  EXPECT_EQ(info[16],
            "SRD_high 1→10 MSAC_C1 alarm Alarm_Ack.req slot 2 Diagnostic_Alarm seq 4 FCB=1 FCV=1");
  EXPECT_EQ(info[17], "SRD_high 2→10 MSAC_C2 Abort.req connection timeout FCB=1 FCV=0");
  EXPECT_EQ(info[18], "SRD_high 1→126 Set_Slave_Add.req new address 5 ident 0x1234 FCB=1 FCV=0");
  EXPECT_EQ(info[19], "FDL_Status 1→3");
  EXPECT_EQ(info[20], "[line] dp0: cable cut between 'master 3' and 'slave 10'");
}

TEST_F(TsharkDissector, FdlFields) {
  const auto rows =
      ts::tshark_fields(s_path,
                        {"frame.number", "_ws.col.Protocol", "pbfdl.type", "pbfdl.da", "pbfdl.sa",
                         "pbfdl.dsap", "pbfdl.ssap", "pbfdl.fc", "pbfdl.fc.name", "pbfdl.fc.fcb",
                         "pbfdl.fc.fcv", "pbfdl.data", "pbfdl.fcs_ok"},
                        "pbfdl");
  ASSERT_EQ(rows.size(), 20u);
  using R = std::vector<std::string>;
  EXPECT_EQ(rows[0],
            (R{"1", "DP", "SD2", "10", "1", "60", "62", "0x6d", "SRD_high", "1", "0", "", "1"}));
  EXPECT_EQ(rows[1], (R{"2", "DP", "SD3", "1", "10", "62", "60", "0x08", "DL", "", "",
                        "020500ff1234", "1"}));
  EXPECT_EQ(rows[3], (R{"4", "FDL", "SC", "", "", "", "", "", "", "", "", "", ""}));
  EXPECT_EQ(rows[7],
            (R{"8", "DP", "SD2", "10", "1", "", "", "0x5d", "SRD_high", "0", "1", "aa55", "1"}));
  EXPECT_EQ(rows[12], (R{"13", "FDL", "SD4", "5", "2", "", "", "", "", "", "", "", ""}));
  EXPECT_EQ(rows[13][12], "0");  // the collided frame: FCS wrong
  EXPECT_EQ(rows[19],
            (R{"20", "FDL", "SD1", "3", "1", "", "", "0x49", "FDL_Status", "0", "0", "", "1"}));
}

TEST_F(TsharkDissector, BadFrameHasExpertInfoAndPcapngFlags) {
  const auto rows = ts::tshark_fields(
      s_path,
      {"frame.number", "_ws.expert.message", "frame.comment", "frame.packet_flags_symbol_error",
       "frame.packet_flags_crc_error", "pbfdl.fcs_calc"},
      "pbfdl.fcs_bad");
  ASSERT_EQ(rows.size(), 1u);
  EXPECT_EQ(rows[0][0], "14");
  EXPECT_NE(rows[0][1].find("FCS mismatch: 0x67 in the frame, 0xBC computed"), std::string::npos)
      << rows[0][1];
  EXPECT_EQ(rows[0][2], "collision, FCS mismatch");
  EXPECT_EQ(rows[0][3], "1");
  EXPECT_EQ(rows[0][4], "1");
  EXPECT_EQ(rows[0][5], "0xbc");  // 0A+01+5D+FF+55 = 0x1BC
}

TEST_F(TsharkDissector, DpDecodes) {
  using R = std::vector<std::string>;
  auto prm =
      ts::tshark_fields(s_path,
                        {"pbdp.prm.lock_req", "pbdp.prm.wd_on", "pbdp.prm.wd_fact_1",
                         "pbdp.prm.wd_fact_2", "pbdp.prm.min_tsdr", "pbdp.ident",
                         "pbdp.prm.group_ident", "pbdp.prm.dpv1_enable", "pbdp.prm.watchdog_ms"},
                        "pbdp.service == \"Set_Prm.req\"");
  ASSERT_EQ(prm.size(), 2u);
  EXPECT_EQ(prm[0], (R{"1", "1", "10", "10", "11", "0x1234", "0x00", "", "1000"}));
  EXPECT_EQ(prm[1], (R{"1", "1", "10", "10", "11", "0x1234", "0x00", "1", "1000"}));

  auto cfg = ts::tshark_fields(s_path, {"pbdp.cfg.id", "pbdp.cfg.text"}, "frame.number == 6");
  ASSERT_EQ(cfg.size(), 1u);
  EXPECT_EQ(cfg[0], (R{"0x10,0x20", "1 byte in,1 byte out"}));
  auto get =
      ts::tshark_fields(s_path, {"pbdp.service", "pbdp.cfg.id", "pbdp.cfg.format", "pbdp.cfg.text"},
                        "frame.number == 16");
  ASSERT_EQ(get.size(), 1u);
  EXPECT_EQ(get[0][0], "Get_Cfg.res");
  EXPECT_EQ(get[0][1], "0x13,0x31,0xd7,0xc2,0x00");
  EXPECT_EQ(get[0][2], "general,general,general,special,special");
  EXPECT_EQ(get[0][3],
            "4 bytes in,2 bytes in/out,8 words in consistent,"
            "2 bytes out consistent, 4 bytes in, 2 manufacturer octets,empty slot");

  auto diag = ts::tshark_fields(s_path,
                                {"pbdp.diag.station_not_ready", "pbdp.diag.prm_req",
                                 "pbdp.diag.master_add", "pbdp.ident", "pbdp.diag.status"},
                                "frame.number == 2");
  EXPECT_EQ(diag[0], (R{"1", "1", "255", "0x1234", "Station_Not_Ready, Prm_Req"}));
  auto ext = ts::tshark_fields(
      s_path,
      {"pbdp.diag.status", "pbdp.diag.block_type", "pbdp.diag.faulty_modules",
       "pbdp.diag.channel.module", "pbdp.diag.channel.number", "pbdp.diag.channel.error",
       "pbdpv1.alarm_type", "pbdpv1.slot", "pbdpv1.seq_nr", "pbdpv1.specifier"},
      "frame.number == 15");
  EXPECT_EQ(ext[0], (R{"Ext_Diag, WD_On",
                       "identifier-related,channel-related,device-related,device-related", "8", "8",
                       "1", "1", "1", "2", "4", "1"}));

  auto gc =
      ts::tshark_fields(s_path, {"pbdp.gc.clear_data", "pbdp.gc.sync", "pbdp.gc.group_select"},
                        "pbdp.service == \"Global_Control.req\"");
  EXPECT_EQ(gc[0], (R{"1", "0", "0x00"}));
  auto dx = ts::tshark_fields(s_path, {"pbdp.outputs", "pbdp.inputs"},
                              "pbdp.service contains \"Data_Exchange\"");
  ASSERT_EQ(dx.size(), 3u);
  EXPECT_EQ(dx[0], (R{"aa55", ""}));
  EXPECT_EQ(dx[1], (R{"", "3c"}));
  auto ssa = ts::tshark_fields(
      s_path, {"pbdp.ssa.new_address", "pbdp.ident", "pbdp.ssa.no_add_chg"}, "frame.number == 19");
  EXPECT_EQ(ssa[0], (R{"5", "0x1234", "0x00"}));
}

TEST_F(TsharkDissector, Dpv1Decodes) {
  using R = std::vector<std::string>;
  auto rows =
      ts::tshark_fields(s_path,
                        {"frame.number", "_ws.col.Protocol", "pbdpv1.service", "pbdpv1.slot",
                         "pbdpv1.index", "pbdpv1.length", "pbdpv1.data", "pbdpv1.error_decode",
                         "pbdpv1.error_class", "pbdpv1.error_code", "pbdpv1.error_text"},
                        "pbdpv1.function_num");
  ASSERT_EQ(rows.size(), 5u);
  EXPECT_EQ(rows[0], (R{"10", "DP-V1", "Read.req", "0", "0", "64", "", "", "", "", ""}));
  EXPECT_EQ(rows[1], (R{"11", "DP-V1", "Read.res", "0", "0", "2", "abcd", "", "", "", ""}));
  EXPECT_EQ(rows[2], (R{"12", "DP-V1", "Read.res-", "", "", "", "", "0x80", "0x0b", "0x00",
                        "access: invalid index"}));
  EXPECT_EQ(rows[3][2], "Alarm_Ack.req");
  EXPECT_EQ(rows[4][2], "Abort.req");
  auto ab = ts::tshark_fields(
      s_path, {"pbdpv1.abort.subnet", "pbdpv1.abort.instance", "pbdpv1.abort.reason"},
      "frame.number == 18");
  EXPECT_EQ(ab[0], (R{"1", "1", "3"}));
}

TEST_F(TsharkDissector, EventRecords) {
  using R = std::vector<std::string>;
  auto rows =
      ts::tshark_fields(s_path,
                        {"frame.number", "_ws.col.Protocol", "pbevent.category", "pbevent.code",
                         "pbevent.code_name", "pbevent.a", "pbevent.b", "pbevent.text"},
                        "pbevent");
  ASSERT_EQ(rows.size(), 1u);
  EXPECT_EQ(rows[0], (R{"21", "Event", "1", "0", "cable cut", "0", "1",
                        "dp0: cable cut between 'master 3' and 'slave 10'"}));
}

// Segment octets in the extension chain, a partial frame, SRD low, an FDL status reply from a
// master and a DP-V1 poll with no data (E.4).
TEST(TsharkDissectorMore, SegmentsPartialFramesAndPolls) {
  if (!ts::tshark_available()) GTEST_SKIP() << ts::kNoTshark;
  const auto path = test::temp_capture_path("pbvbus_tshark_more");
  {
    bus::Scheduler sched;
    bus::Line line(sched, "dp1", bus::Baud::k187_5);
    auto w = PcapngWriter::open(path, {});
    ASSERT_TRUE(w);
    // Slave_Diag request as SRD low with a destination segment octet (0xC5: EXT | segment | 5)
    // before DSAP 60.
    w->on_frame(test::tap_frame(line, sd2({0x8A, 0x81, 0x4C, 0xC5, 0x3C, 0x3E}), 1000));
    // Set_Prm cut after 7 of 18 octets.
    const Bytes part(test::kSetPrm.begin(), test::kSetPrm.begin() + 7);
    w->on_frame(test::tap_frame(line, part, 2000, bus::kRxPartial, 18));
    // FDL Status reply from master 5 in the ring (Appendix 1).
    w->on_frame(test::tap_frame(line, Bytes{0x10, 0x01, 0x05, 0x30, 0x36, 0x16}, 3000));
    // DP-V1 poll: SRD to SAP 51 without data, and the slave's empty DL answer.
    w->on_frame(test::tap_frame(line, sd2({0x8A, 0xB3, 0x5D, 0x33, 0x33}), 4000));
    w->on_frame(test::tap_frame(line, sd2({0xB3, 0x8A, 0x08, 0x33, 0x33}), 5000));
  }
  using R = std::vector<std::string>;
  const auto rows =
      ts::tshark_fields(path, {"_ws.col.Info", "pbfdl.da_segment", "pbfdl.dsap", "pbfdl.ssap",
                               "pbfdl.fc.station_type", "_ws.expert.message"});
  std::filesystem::remove(path);
  ASSERT_EQ(rows.size(), 5u);
  EXPECT_EQ(rows[0], (R{"SRD_low 1→10 Slave_Diag.req FCB=0 FCV=0", "5", "60", "62", "", ""}));
  // The DSAP octet was never sent: no DP service, and no complaint about the extension chain.
  EXPECT_EQ(rows[1][0], "SRD_high 1→10 FCB=0 FCV=1 [truncated]");
  // Wireshark shows the pcapng comment as an expert item too, then the dissector's own.
  EXPECT_EQ(rows[1][5], "partial: 7 of 18 octets,7 of 18 octets");
  EXPECT_EQ(rows[2], (R{"5→1 OK (master in the ring)", "", "", "", "3", ""}));
  EXPECT_EQ(rows[3][0], "SRD_high 51→10 MSAC_C1 poll FCB=0 FCV=1");
  EXPECT_EQ(rows[4][0], "10→51 DL MSAC_C1 not ready");
}

// Slave redundancy (protocol-facts.md §G.2/G.3): a Set_Prm with DPV1_Status_3 = PrmCmd |
// Prm_Structure and an 8-octet PrmCmd block (Seq_Nr 1, Primary_Request, Output_Hold_Time 10 x
// 10 ms), and a diagnosis with a Red_Status status block (own: Primary + Data_Exchange; partner:
// Backup).
TEST(TsharkDissectorMore, SlaveRedundancyBlocks) {
  if (!ts::tshark_available()) GTEST_SKIP() << ts::kNoTshark;
  const auto path = test::temp_capture_path("pbvbus_tshark_red");
  {
    bus::Scheduler sched;
    bus::Line line(sched, "dpA", bus::Baud::k1_5M);
    auto w = PcapngWriter::open(path, {});
    ASSERT_TRUE(w);
    w->on_frame(test::tap_frame(line, kPrmCmd, 1000));
    w->on_frame(test::tap_frame(line, kRedState, 2000));
  }
  using R = std::vector<std::string>;
  const auto rows = ts::tshark_fields(
      path, {"_ws.col.Info", "pbdp.prm.prmcmd", "pbdp.prmcmd.structure_type", "pbdp.prmcmd.seq_nr",
             "pbdp.prmcmd.primary_request", "pbdp.prmcmd.output_hold_time", "pbdp.red.seq_nr",
             "pbdp.red.state_1", "pbdp.red.state_2", "pbdp.red.state"});
  std::filesystem::remove(path);
  ASSERT_EQ(rows.size(), 2u);
  // More cases in tshark_redundancy_test.cpp.
  EXPECT_EQ(rows[0], (R{"SRD_high 1→10 Set_Prm.req ident 0x1234 WD 1000 ms pure PrmCmd Primary_Request FCB=0 FCV=1",
                        "1", "0x02", "1", "1", "10", "", "", "", ""}));
  EXPECT_EQ(rows[1], (R{"10→1 DL Slave_Diag.res ident 0x1234 master 1 [Ext_Diag, WD_On] ext: Red_Status "
                        "own Primary+DX, partner Backup",
                        "", "", "", "", "", "1", "0x0a", "0x01", "own Primary, Data_Exchange; partner Backup"}));
}

// MSAC_C2 (protocol-facts.md §E.6): Initiate.req to the resource manager (SAP 49) from the
// class-2 master's SAP 50, the RM answer naming server SAP 48 and Send_Timeout 100, the
// Initiate.res from SAP 48, a Data_Transport and an Idle on the connection.
TEST(TsharkDissectorMore, Msac2Connection) {
  if (!ts::tshark_available()) GTEST_SKIP() << ts::kNoTshark;
  const auto path = test::temp_capture_path("pbvbus_tshark_c2");
  {
    bus::Scheduler sched;
    bus::Line line(sched, "dp0", bus::Baud::k1_5M);
    auto w = PcapngWriter::open(path, {});
    ASSERT_TRUE(w);
    // 57 | 3 reserved | Send_Timeout 0x0064 | features 01 00 | profile features 00 00 |
    // profile ident 0x0000 | S_Type 00 S_Len 02 D_Type 00 D_Len 02 | Addr_Data 4 octets
    w->on_frame(test::tap_frame(
        line, sd2({0x8A, 0x82, 0x6D, 0x31, 0x32, 0x57, 0x00, 0x00, 0x00, 0x00, 0x64, 0x01, 0x00,
                   0x00, 0x00, 0x00, 0x00, 0x00, 0x02, 0x00, 0x02, 0x00, 0x01, 0x00, 0x02}),
        1000));
    w->on_frame(
        test::tap_frame(line, sd2({0x82, 0x8A, 0x08, 0x32, 0x31, 0x56, 0x30, 0x00, 0x64}), 2000));
    // Initiate.res: 57 | Max_Len_Data_Unit 0xF0 | 01 00 00 00 | 0000 | 00 02 00 02 | 4 octets
    w->on_frame(
        test::tap_frame(line, sd2({0x82, 0x8A, 0x08, 0x32, 0x30, 0x57, 0xF0, 0x01, 0x00, 0x00, 0x00,
                                   0x00, 0x00, 0x00, 0x02, 0x00, 0x02, 0x00, 0x01, 0x00, 0x02}),
                        3000));
    w->on_frame(test::tap_frame(
        line, sd2({0x8A, 0x82, 0x7D, 0x30, 0x32, 0x51, 0x01, 0x02, 0x03, 0xAA, 0xBB, 0xCC}), 4000));
    w->on_frame(test::tap_frame(line, sd2({0x8A, 0x82, 0x5D, 0x30, 0x32, 0x48, 0x00}), 5000));
  }
  using R = std::vector<std::string>;
  const auto rows = ts::tshark_fields(
      path, {"_ws.col.Info", "pbdpv1.service", "pbdpv1.send_timeout", "pbdpv1.server_sap",
             "pbdpv1.max_len_data_unit", "pbdpv1.s_len", "pbdpv1.addr_data", "pbdpv1.data"});
  std::filesystem::remove(path);
  ASSERT_EQ(rows.size(), 5u);
  EXPECT_EQ(rows[0], (R{"SRD_high 2→10 MSAC_C2 Initiate.req FCB=1 FCV=0", "Initiate.req", "100", "",
                        "", "2", "00010002", ""}));
  EXPECT_EQ(rows[1],
            (R{"10→2 DL MSAC_C2 RM.res server SAP 48", "RM.res", "100", "48", "", "", "", ""}));
  EXPECT_EQ(rows[2], (R{"10→2 DL MSAC_C2 Initiate.res", "Initiate.res", "", "", "240", "2",
                        "00010002", ""}));
  EXPECT_EQ(rows[3], (R{"SRD_high 2→10 MSAC_C2 Data_Transport.req slot 1 index 2 len 3 FCB=1 FCV=1",
                        "Data_Transport.req", "", "", "", "", "", "aabbcc"}));
  EXPECT_EQ(rows[4][0], "SRD_high 2→10 MSAC_C2 Idle.req FCB=0 FCV=1");
}

// Mutated and random frames must never make the dissector raise a Lua error.
TEST(TsharkDissectorRobustness, GarbageFramesDecodeWithoutLuaErrors) {
  if (!ts::tshark_available()) GTEST_SKIP() << ts::kNoTshark;
  const auto path = test::temp_capture_path("pbvbus_tshark_garbage");
  const std::vector<const Bytes*> goldens = {&test::kSlaveDiagReq,
                                             &test::kSlaveDiagRes,
                                             &test::kSetPrmDpv1,
                                             &test::kChkCfg,
                                             &test::kGlobalControlClear,
                                             &test::kDpv1Read,
                                             &test::kDpv1ReadNeg,
                                             &test::kSetSlaveAdd,
                                             &kDiagExt,
                                             &kGetCfgRes,
                                             &kAlarmAck,
                                             &kC2Abort,
                                             &test::kToken_2_to_5,
                                             &kPrmCmd,
                                             &kRedState};
  std::uint64_t rng = 0x9E3779B97F4A7C15ULL;
  auto next = [&] {
    rng ^= rng << 13;
    rng ^= rng >> 7;
    rng ^= rng << 17;
    return rng;
  };
  int frames = 0;
  {
    bus::Scheduler sched;
    bus::Line line(sched, "dp0", bus::Baud::k12M);
    auto w = PcapngWriter::open(path, {});
    ASSERT_TRUE(w);
    for (int i = 0; i < 600; ++i) {
      Bytes b = *goldens[next() % goldens.size()];
      switch (next() % 4) {
        case 0:
          b.resize(next() % (b.size() + 1));
          break;  // cut anywhere
        case 1:
          b[next() % b.size()] = static_cast<std::uint8_t>(next());
          break;
        case 2:
          for (auto& o : b) o = static_cast<std::uint8_t>(next());  // noise
          b[0] = std::array<std::uint8_t, 5>{0x10, 0x68, 0xA2, 0xDC, 0xE5}[next() % 5];
          break;
        default:
          b.push_back(static_cast<std::uint8_t>(next()));
          break;
      }
      // Keep SD2 headers plausible often enough to reach the DP decoders with odd lengths.
      if (b.size() > 4 && b[0] == 0x68 && next() % 2 == 0) {
        b[1] = b[2] = static_cast<std::uint8_t>(b.size() - 6);
        b[3] = 0x68;
      }
      w->on_frame(test::tap_frame(line, b, (i + 1) * 1000));
      ++frames;
    }
    EventRecord short_event;
    w->write_event(0, short_event);
  }
  const auto r = ts::tshark(path, {"-V"});
  std::filesystem::remove(path);
  EXPECT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(r.out.find("Lua Error"), std::string::npos)
      << r.out.substr(r.out.find("Lua Error") > 400 ? r.out.find("Lua Error") - 400 : 0, 1200);
  EXPECT_EQ(r.err.find("Lua"), std::string::npos) << r.err;
  EXPECT_EQ(frames, 600);
}

}  // namespace
}  // namespace pbvbus::captures
