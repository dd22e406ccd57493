// Slave redundancy in the Lua dissector (captures/lua/pbvbus.lua), checked with Debian's tshark
// against golden telegrams written by hand from protocol-facts.md §G.2/§G.3 (PI 2.212 as the AUMA
// manual lays it out) and §D.2/§D.4/§D.5, not produced by any pbvbus code: the dissector is an
// independent oracle for the redundancy codec.
//
// Every frame is SD2: 68 LE LE 68 | DA SA FC DSAP SSAP DU... | FCS 16, FCS = sum of DA..DU mod 256
// (§B.1). Master 1 (SA 0x81 with SAP extension), slave 10 (DA 0x8A), Set_Prm DSAP 61 (0x3D) from
// SSAP 62 (0x3E); Slave_Diag response DSAP 62 from SSAP 60 (0x3C), FC 0x08 (DL).

#include <gtest/gtest.h>

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "capture_fixture.hpp"
#include "tshark_helpers.hpp"

#include "pbvbus/captures/pcapng_writer.hpp"

namespace pbvbus::captures {
namespace {

using test::Bytes;
namespace ts = ::pbvbus::test;

// 1. Set_Prm with DPV1 status and two structured blocks, the second a PrmCmd Primary_Request.
//    8A 81 5D 3D 3E                    SRD_high FCB=0 FCV=1, DSAP 61, SSAP 62     sum 0x1E3
//    88 0A 0A 0B 0A 10 00              Lock_Req+WD_On, WD 10x10x10 ms, TSDR 11,
//                                      ident 0x0A10, group 0                      sum 0x0C1
//    80 20 88                          DPV1_Enable; Enable_Diagnostic_Alarm;
//                                      PrmCmd (0x80) | Prm_Structure (0x08)       sum 0x128
//    06 81 00 00 AA BB                 user prm block (type 0x81), 6 octets       sum 0x1EC
//    08 02 00 10 02 01 00 03           PrmCmd: length 8, type 2, slot 0, Seq_Nr 2
//                                      (0x10 >> 3), Function Primary_Request (0x02),
//                                      Properties bit 0, Output_Hold_Time 3 x 10 ms sum 0x020
//    LE = 5 + 7 + 3 + 6 + 8 = 29 = 0x1D; FCS = 0x5D8 mod 256 = 0xD8
const Bytes kSetPrmPrmCmd = {0x68, 0x1D, 0x1D, 0x68, 0x8A, 0x81, 0x5D, 0x3D, 0x3E, 0x88, 0x0A, 0x0A,
                             0x0B, 0x0A, 0x10, 0x00, 0x80, 0x20, 0x88, 0x06, 0x81, 0x00, 0x00, 0xAA,
                             0xBB, 0x08, 0x02, 0x00, 0x10, 0x02, 0x01, 0x00, 0x03, 0xD8, 0x16};

// 2. Pure PrmCmd: header, DPV1 status, one 8-octet block and nothing else (7 + 3 + 8 = 18 octets).
//    8A 81 7D 3D 3E                    SRD_high FCB=1 FCV=1                       sum 0x203
//    88 0A 0A 0B 0A 10 00                                                         sum 0x0C1
//    80 00 88                                                                     sum 0x108
//    08 02 00 18 42 00 00 0A           Seq_Nr 3, Primary_Request + Master_State_Clear
//                                      (0x42), Output_Hold_Time 10 x 10 ms = 100 ms sum 0x06E
//    LE = 23 = 0x17; FCS = 0x43A mod 256 = 0x3A
const Bytes kPurePrmCmd = {0x68, 0x17, 0x17, 0x68, 0x8A, 0x81, 0x7D, 0x3D, 0x3E, 0x88, 0x0A, 0x0A, 0x0B,
                           0x0A, 0x10, 0x00, 0x80, 0x00, 0x88, 0x08, 0x02, 0x00, 0x18, 0x42, 0x00, 0x00,
                           0x0A, 0x3A, 0x16};

// 3. Slave_Diag response with a Prm_Cmd_Ack and a Red_Status block (§G.3, 8 octets each).
//    81 8A 08 3E 3C                    DL, DSAP 62, SSAP 60                       sum 0x18D
//    08 0C 00 01 0A 10                 Ext_Diag; WD_On + always 1; master 1;
//                                      ident 0x0A10                               sum 0x02F
//    08 9E 00 10 02 0A 09 00           Prm_Cmd_Ack, slot 0, Seq_Nr 2, Function echo
//                                      Primary_Request, own Primary+Data_Exchange
//                                      (0x0A), partner Backup+Data_Exchange (0x09)  sum 0x0CB
//    08 9F 00 01 00 0A 09 00           Red_Status, "status appears", no function,
//                                      same states                                sum 0x0BB
//    LE = 5 + 6 + 8 + 8 = 27 = 0x1B; FCS = 0x342 mod 256 = 0x42
const Bytes kDiagRed = {0x68, 0x1B, 0x1B, 0x68, 0x81, 0x8A, 0x08, 0x3E, 0x3C, 0x08, 0x0C, 0x00,
                        0x01, 0x0A, 0x10, 0x08, 0x9E, 0x00, 0x10, 0x02, 0x0A, 0x09, 0x00, 0x08,
                        0x9F, 0x00, 0x01, 0x00, 0x0A, 0x09, 0x00, 0x42, 0x16};

// 4. Set_Prm whose PrmCmd block says 8 octets but the telegram ends after 5 (FDL intact).
//    8A 81 5D 3D 3E | 88 0A 0A 0B 0A 10 00 | 80 00 88 | 08 02 00 08 02
//    sums 0x1E3 + 0x0C1 + 0x108 + 0x014 = 0x3C0; LE = 20 = 0x14; FCS 0xC0
const Bytes kPrmCmdCut = {0x68, 0x14, 0x14, 0x68, 0x8A, 0x81, 0x5D, 0x3D, 0x3E, 0x88, 0x0A, 0x0A, 0x0B,
                          0x0A, 0x10, 0x00, 0x80, 0x00, 0x88, 0x08, 0x02, 0x00, 0x08, 0x02, 0xC0, 0x16};

// 5. Slave_Diag response whose Red_Status block (header 0x08) ends after Red_State_1.
//    81 8A 08 3E 3C | 08 0C 00 01 0A 10 | 08 9F 00 01 00 0A
//    sums 0x18D + 0x02F + 0x0B2 = 0x26E; LE = 17 = 0x11; FCS 0x6E
const Bytes kRedCut = {0x68, 0x11, 0x11, 0x68, 0x81, 0x8A, 0x08, 0x3E, 0x3C, 0x08, 0x0C,
                       0x00, 0x01, 0x0A, 0x10, 0x08, 0x9F, 0x00, 0x01, 0x00, 0x0A, 0x6E, 0x16};

// 6. DPV1_Status_3 = PrmCmd only (0x80, Prm_Structure missing), with a complete PrmCmd block.
//    8A 81 7D 3D 3E | 88 0A 0A 0B 0A 10 00 | 80 00 80 | 08 02 00 08 02 00 00 0A
//    sums 0x203 + 0x0C1 + 0x100 + 0x01E = 0x3E2; LE = 23 = 0x17; FCS 0xE2
const Bytes kPrmCmdNoStructure = {0x68, 0x17, 0x17, 0x68, 0x8A, 0x81, 0x7D, 0x3D, 0x3E, 0x88,
                                  0x0A, 0x0A, 0x0B, 0x0A, 0x10, 0x00, 0x80, 0x00, 0x80, 0x08,
                                  0x02, 0x00, 0x08, 0x02, 0x00, 0x00, 0x0A, 0xE2, 0x16};

// 7. A complete 6-octet block (header 0x06) of type Red_Status: too short for §G.3.
//    81 8A 08 3E 3C | 08 0C 00 01 0A 10 | 06 9F 00 01 00 0A
//    sums 0x18D + 0x02F + 0x0B0 = 0x26C; LE = 17 = 0x11; FCS 0x6C
const Bytes kRedShortHeader = {0x68, 0x11, 0x11, 0x68, 0x81, 0x8A, 0x08, 0x3E, 0x3C, 0x08, 0x0C,
                               0x00, 0x01, 0x0A, 0x10, 0x06, 0x9F, 0x00, 0x01, 0x00, 0x0A, 0x6C, 0x16};

// The goldens are well-formed SD2 frames: LE = LEr = octets DA..DU, FCS = their sum. This checks
// the hand arithmetic above, not the dissector.
TEST(TsharkRedundancyGoldens, FramesAreWellFormed) {
  for (const Bytes* f : {&kSetPrmPrmCmd, &kPurePrmCmd, &kDiagRed, &kPrmCmdCut, &kRedCut, &kPrmCmdNoStructure,
                         &kRedShortHeader}) {
    ASSERT_GE(f->size(), 6u);
    EXPECT_EQ((*f)[0], 0x68);
    EXPECT_EQ((*f)[3], 0x68);
    EXPECT_EQ((*f)[1], (*f)[2]);
    EXPECT_EQ(std::size_t{(*f)[1]} + 6, f->size());
    unsigned sum = 0;
    for (std::size_t i = 4; i + 2 < f->size(); ++i) sum += (*f)[i];
    EXPECT_EQ(sum & 0xFF, (*f)[f->size() - 2]);
    EXPECT_EQ(f->back(), 0x16);
  }
}

class TsharkRedundancy : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    s_path = test::temp_capture_path("pbvbus_tshark_redundancy");
    bus::Scheduler sched;
    bus::Line line(sched, "dpA", bus::Baud::k1_5M);
    auto w = PcapngWriter::open(s_path, {});
    ASSERT_TRUE(w);
    bus::Ticks t = 0;
    for (const Bytes* f : {&kSetPrmPrmCmd, &kPurePrmCmd, &kDiagRed, &kPrmCmdCut, &kRedCut, &kPrmCmdNoStructure,
                           &kRedShortHeader}) {
      t += 100 * bus::kTicksPerUs;
      w->on_frame(test::tap_frame(line, *f, t));
    }
  }
  static void TearDownTestSuite() { std::filesystem::remove(s_path); }
  void SetUp() override {
    if (!ts::tshark_available()) GTEST_SKIP() << ts::kNoTshark;
  }
  static std::vector<std::vector<std::string>> fields(const std::vector<std::string>& f) {
    return ts::tshark_fields(s_path, f);
  }
  static std::string s_path;
};
std::string TsharkRedundancy::s_path;

using R = std::vector<std::string>;

TEST_F(TsharkRedundancy, InfoColumn) {
  const auto info = ts::tshark_info(s_path);
  ASSERT_EQ(info.size(), 7u);
  EXPECT_EQ(info[0], "SRD_high 1→10 Set_Prm.req ident 0x0A10 WD 1000 ms PrmCmd Primary_Request FCB=0 FCV=1");
  EXPECT_EQ(info[1],
            "SRD_high 1→10 Set_Prm.req ident 0x0A10 WD 1000 ms pure PrmCmd Primary_Request+Master_State_Clear "
            "FCB=1 FCV=1");
  EXPECT_EQ(info[2],
            "10→1 DL Slave_Diag.res ident 0x0A10 master 1 [Ext_Diag, WD_On] ext: Prm_Cmd_Ack Primary_Request "
            "own Primary+DX, partner Backup+DX, Red_Status own Primary+DX, partner Backup+DX");
  EXPECT_EQ(info[3], "SRD_high 1→10 Set_Prm.req ident 0x0A10 WD 1000 ms PrmCmd Primary_Request FCB=0 FCV=1");
  EXPECT_EQ(info[4], "10→1 DL Slave_Diag.res ident 0x0A10 master 1 [Ext_Diag, WD_On] ext: Red_Status own Primary+DX");
  // Not structured, but still header + status + one PrmCmd block and nothing else.
  EXPECT_EQ(info[5], "SRD_high 1→10 Set_Prm.req ident 0x0A10 WD 1000 ms pure PrmCmd Primary_Request FCB=1 FCV=1");
  EXPECT_EQ(info[6], "10→1 DL Slave_Diag.res ident 0x0A10 master 1 [Ext_Diag, WD_On] ext: Red_Status own Primary+DX");
}

TEST_F(TsharkRedundancy, PrmCmdFields) {
  const auto rows = fields({"pbdp.prm.prmcmd", "pbdp.prm.prm_structure", "pbdp.prmcmd.structure_length",
                            "pbdp.prmcmd.structure_type", "pbdp.prmcmd.slot", "pbdp.prmcmd.seq_nr",
                            "pbdp.prmcmd.function", "pbdp.prmcmd.primary_request", "pbdp.prmcmd.master_state_clear",
                            "pbdp.prmcmd.functions", "pbdp.prmcmd.properties",
                            "pbdp.prmcmd.properties.primary_req_ms0_ms1_used", "pbdp.prmcmd.output_hold_time",
                            "pbdp.prmcmd.output_hold_time_ms", "pbdp.prmcmd.pure", "pbdp.prm.block_type"});
  ASSERT_EQ(rows.size(), 7u);
  // Two blocks: the user prm block shows as an ordinary structured block, the PrmCmd in its own
  // subtree.
  EXPECT_EQ(rows[0], (R{"1", "1", "8", "0x02", "0", "2", "0x02", "1", "0", "Primary_Request", "0x01", "1", "3",
                        "30", "", "0x81"}));
  EXPECT_EQ(rows[1], (R{"1", "1", "8", "0x02", "0", "3", "0x42", "1", "1", "Primary_Request+Master_State_Clear",
                        "0x00", "0", "10", "100", "1", ""}));
  // Cut short after the Function octet: what is there is decoded.
  EXPECT_EQ(rows[3], (R{"1", "1", "8", "0x02", "0", "1", "0x02", "1", "0", "Primary_Request", "", "", "", "", "",
                        ""}));
  EXPECT_EQ(rows[5], (R{"1", "0", "8", "0x02", "0", "1", "0x02", "1", "0", "Primary_Request", "0x00", "0", "10",
                        "100", "1", ""}));
}

TEST_F(TsharkRedundancy, RedStatusFields) {
  const auto rows =
      fields({"pbdp.red.status_type", "pbdp.red.slot", "pbdp.red.seq_nr", "pbdp.red.specifier_bits",
              "pbdp.red.function", "pbdp.red.function.primary_request", "pbdp.red.state_1",
              "pbdp.red.state_1.primary", "pbdp.red.state_1.data_exchange", "pbdp.red.state_1.backup",
              "pbdp.red.state_2", "pbdp.red.state_2.backup", "pbdp.red.state_2.primary", "pbdp.red.state_3",
              "pbdp.red.own", "pbdp.red.partner", "pbdp.red.state"});
  ASSERT_EQ(rows.size(), 7u);
  EXPECT_EQ(rows[2], (R{"0x9e,0x9f", "0,0", "2,0", "0,1", "0x02,0x00", "1,0", "0x0a,0x0a", "1,1", "1,1", "0,0",
                        "0x09,0x09", "1,1", "0,0", "0x00,0x00", "Primary, Data_Exchange,Primary, Data_Exchange",
                        "Backup, Data_Exchange,Backup, Data_Exchange",
                        "own Primary, Data_Exchange; partner Backup, Data_Exchange,own Primary, Data_Exchange; "
                        "partner Backup, Data_Exchange"}));
  // Cut after Red_State_1: no partner, no Red_State_3.
  EXPECT_EQ(rows[4], (R{"0x9f", "0", "0", "1", "0x00", "0", "0x0a", "1", "1", "0", "", "", "", "",
                        "Primary, Data_Exchange", "", "own Primary, Data_Exchange"}));
  EXPECT_EQ(rows[6][0], "0x9f");
  EXPECT_EQ(rows[6][6], "0x0a");
  // Set_Prm frames carry no status block.
  EXPECT_EQ(rows[0][0], "");
}

// The good frames decode without any expert item; each broken one names what is wrong.
TEST_F(TsharkRedundancy, ExpertInfoOnlyOnBrokenFrames) {
  const auto rows = fields({"frame.number", "_ws.expert.message", "_ws.malformed"});
  ASSERT_EQ(rows.size(), 7u);
  for (int good : {0, 1, 2}) {
    EXPECT_EQ(rows[good][1], "") << "frame " << good + 1;
    EXPECT_EQ(rows[good][2], "") << "frame " << good + 1;
  }
  EXPECT_EQ(rows[3][1], "PrmCmd block cut short: 5 of 8 octets");
  EXPECT_EQ(rows[4][1], "diagnosis block cut short,Red_Status block cut short: 6 of 8 octets");
  EXPECT_EQ(rows[5][1], "DPV1_Status_3 has PrmCmd but not Prm_Structure; blocks decoded anyway");
  EXPECT_EQ(rows[6][1], "Red_Status block of 6 octets, expected 8");
  // Blocks cut short or of the wrong length are malformed; the contradicting status bits are a
  // protocol warning only.
  EXPECT_EQ(rows[3][2], "_ws.malformed");
  EXPECT_EQ(rows[4][2], "_ws.malformed,_ws.malformed");
  EXPECT_EQ(rows[5][2], "");
  EXPECT_EQ(rows[6][2], "_ws.malformed");
  for (const auto& r : rows) EXPECT_EQ(r[1].find("Lua"), std::string::npos) << "frame " << r[0] << ": " << r[1];
}

// The full decode (-V) of every frame: no Lua error anywhere.
TEST_F(TsharkRedundancy, NoLuaErrors) {
  const auto r = ts::tshark(s_path, {"-V"});
  EXPECT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(r.out.find("Lua Error"), std::string::npos) << r.out;
  EXPECT_EQ(r.err.find("Lua"), std::string::npos) << r.err;
  // The subtrees as a reader sees them.
  EXPECT_NE(r.out.find("PrmCmd block: Primary_Request, Output_Hold_Time 30 ms"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("Red_State_1 (this interface): 0x0a (Primary+DX)"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("Red_State_2 (partner): 0x09 (Backup+DX)"), std::string::npos) << r.out;
}

}  // namespace
}  // namespace pbvbus::captures

namespace pbvbus::captures {
namespace {

// The redundancy goldens cut, bit-flipped and extended at random (FDL header kept plausible so
// the DP decoders see odd block lengths): tshark must never report a Lua error.
TEST(TsharkRedundancyRobustness, MutatedRedundancyFramesDecodeWithoutLuaErrors) {
  if (!ts::tshark_available()) GTEST_SKIP() << ts::kNoTshark;
  const auto path = test::temp_capture_path("pbvbus_tshark_red_garbage");
  const std::vector<const Bytes*> goldens = {&kSetPrmPrmCmd, &kPurePrmCmd, &kDiagRed, &kPrmCmdCut,
                                             &kRedCut, &kPrmCmdNoStructure, &kRedShortHeader};
  std::uint64_t rng = 0xA5A5'0212'0000'0001ULL;
  auto next = [&] {
    rng ^= rng << 13;
    rng ^= rng >> 7;
    rng ^= rng << 17;
    return rng;
  };
  {
    bus::Scheduler sched;
    bus::Line line(sched, "dpA", bus::Baud::k12M);
    auto w = PcapngWriter::open(path, {});
    ASSERT_TRUE(w);
    for (int i = 0; i < 400; ++i) {
      Bytes b = *goldens[next() % goldens.size()];
      // Mutate only the DU (after DSAP/SSAP, before FCS), where the blocks are.
      const std::size_t du = 9, end = b.size() - 2;
      switch (next() % 3) {
        case 0:
          b.erase(b.begin() + static_cast<std::ptrdiff_t>(du + next() % (end - du)), b.begin() + static_cast<std::ptrdiff_t>(end));
          break;
        case 1:
          for (int k = 0; k < 3; ++k) b[du + next() % (end - du)] = static_cast<std::uint8_t>(next());
          break;
        default:
          b.insert(b.begin() + static_cast<std::ptrdiff_t>(end), static_cast<std::uint8_t>(next()));
          break;
      }
      // Keep LE and the FCS right so every frame reaches the DP decoders.
      b[1] = b[2] = static_cast<std::uint8_t>(b.size() - 6);
      unsigned sum = 0;
      for (std::size_t k = 4; k + 2 < b.size(); ++k) sum += b[k];
      b[b.size() - 2] = static_cast<std::uint8_t>(sum);
      w->on_frame(test::tap_frame(line, b, (i + 1) * 1000));
    }
  }
  const auto r = ts::tshark(path, {"-V"});
  std::filesystem::remove(path);
  EXPECT_EQ(r.exit_code, 0) << r.err;
  const auto at = r.out.find("Lua Error");
  EXPECT_EQ(at, std::string::npos) << r.out.substr(at > 1500 ? at - 1500 : 0, 2000);
  EXPECT_EQ(r.err.find("Lua"), std::string::npos) << r.err;
}

}  // namespace
}  // namespace pbvbus::captures
