// Group "Global_Control" (GC-nn) on the shipped slave models and on the mutants aimed at it.
#include <gtest/gtest.h>

#include "group_test_support.hpp"

namespace pbvbus::conformance::testing {
namespace {

using devices::SlaveMutant;

TEST(GroupGlobalControl, PassesOnEveryShippedModel) {
  for (Shipped s : kAllShipped) {
    SCOPED_TRACE(shipped_name(s));
    const auto r = run_only(shipped(s), "Global_Control");
    ASSERT_TRUE(r.dut_error.empty()) << r.dut_error;
    ASSERT_EQ(r.results.size(), 6u) << describe(r);
    EXPECT_EQ(r.count(Verdict::Fail), 0u) << describe(r);
    // Every shipped GSD has outputs, Sync_Mode_supp = Freeze_Mode_supp = 1.
    for (const char* id : {"GC-01", "GC-02", "GC-03", "GC-04", "GC-05"})
      EXPECT_EQ(verdict_of(r, id), Verdict::Pass) << id << describe(r);
    EXPECT_EQ(verdict_of(r, "GC-06"), Verdict::NotApplicable) << describe(r);
  }
}

TEST(GroupGlobalControl, ClearDataTelegramsOnTheWire) {
  const auto r = run_only(shipped(Shipped::A01), "GC-01");
  const TestResult* t = find_result(r, "GC-01");
  ASSERT_NE(t, nullptr) << describe(r);
  ASSERT_EQ(t->verdict, Verdict::Pass) << t->message;
  // Global_Control Clear_Data, broadcast SDN from the tester (1) to 127:
  //   SD2 LE LEr SD2 | DA = 127|EXT = FF | SA = 1|EXT = 81 | FC = SDN high 46 (FCV = FCB = 0,
  //   §B.4) | DSAP 3A (58) | SSAP 3E (62) | 02 00 | FCS | ED
  //   LE = DA SA FC DSAP SSAP + 2 = 7; FCS = FF+81+46+3A+3E+02+00 = 0x240 -> 40
  //   (protocol-facts.md Appendix 1 has the same frame).
  const Exchange* gc = find_exchange(*t, "Clear_Data (02 00)");
  ASSERT_NE(gc, nullptr);
  EXPECT_EQ(gc->request, (std::vector<std::uint8_t>{0x68, 0x07, 0x07, 0x68, 0xFF, 0x81, 0x46, 0x3A,
                                                    0x3E, 0x02, 0x00, 0x40, 0x16}));
  EXPECT_FALSE(gc->expects_reply);
  EXPECT_FALSE(gc->answered);
  // Data_Exchange with outputs A5 A5 to slave 3, SRD high with FCV = 0 (4D), default SAP:
  //   LE = DA SA FC + 2 = 5; FCS = 03+01+4D+A5+A5 = 0x19B -> 9B.
  const Exchange* dx = find_exchange(*t, "outputs A5");
  ASSERT_NE(dx, nullptr);
  EXPECT_EQ(dx->request, (std::vector<std::uint8_t>{0x68, 0x05, 0x05, 0x68, 0x03, 0x01, 0x4D, 0xA5,
                                                    0xA5, 0x9B, 0x16}));
  // Reply: DL (08) from 3 to 1 with the 2 input octets: 68 05 05 68 01 03 08 i0 i1 FCS 16.
  ASSERT_EQ(dx->response.size(), 11u);
  EXPECT_EQ(std::vector<std::uint8_t>(dx->response.begin(), dx->response.begin() + 7),
            (std::vector<std::uint8_t>{0x68, 0x05, 0x05, 0x68, 0x01, 0x03, 0x08}));
}

TEST(GroupGlobalControl, EachMutantFailsTheTestAimedAtIt) {
  const struct {
    SlaveMutant m;
    const char* id;
  } cases[] = {{SlaveMutant::IgnoreClearData, "GC-01"},
               {SlaveMutant::IgnoreSync, "GC-02"},
               {SlaveMutant::IgnoreFreeze, "GC-03"}};
  for (const auto& c : cases) {
    SCOPED_TRACE(c.id);
    for (Shipped s : {Shipped::A01, Shipped::A03}) {
      const auto r = run_only(shipped(s, c.m), c.id);
      EXPECT_EQ(verdict_of(r, c.id), Verdict::Fail) << shipped_name(s) << describe(r);
    }
  }
}

TEST(GroupGlobalControl, UnsupportedSyncGivesNotSupported) {
  // PBVB0A01 with Sync_Mode_supp = 0: GC-02 is n/a, GC-06 checks the refusal.
  auto gsd = shipped_gsd_with("PBVB0A01.gsd", "Sync_Mode_supp          = 1",
                              "Sync_Mode_supp          = 0");
  ASSERT_NE(gsd, nullptr);
  const auto r = run_only(shipped(Shipped::A01, std::nullopt, gsd), "Global_Control");
  EXPECT_EQ(verdict_of(r, "GC-02"), Verdict::NotApplicable) << describe(r);
  EXPECT_EQ(verdict_of(r, "GC-06"), Verdict::Pass) << describe(r);
  const TestResult* t = find_result(r, "GC-06");
  ASSERT_NE(t, nullptr);
  // Slave_Diag after the refused Set_Prm: Not_Supported (10) | Station_Not_Ready (02) = 12,
  // Prm_Req | always-1 = 05, 00, no master FF, ident 0A 01.
  EXPECT_NE(t->message.find("12 05 00 FF 0A 01"), std::string::npos) << t->message;
}

}  // namespace
}  // namespace pbvbus::conformance::testing
