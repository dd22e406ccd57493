// Group "GSD" (GSD-nn) on the shipped slave models and on the mutants aimed at it.
#include <gtest/gtest.h>

#include "group_test_support.hpp"

namespace pbvbus::conformance::testing {
namespace {

using devices::SlaveMutant;

TEST(GroupGsd, PassesOnEveryShippedModel) {
  for (Shipped s : kAllShipped) {
    SCOPED_TRACE(shipped_name(s));
    const auto r = run_only(shipped(s), "GSD");
    ASSERT_EQ(r.results.size(), 7u) << describe(r);
    for (const char* id : {"GSD-01", "GSD-02", "GSD-03", "GSD-04", "GSD-05", "GSD-06", "GSD-07"})
      EXPECT_EQ(verdict_of(r, id), Verdict::Pass) << id << describe(r);
  }
}

TEST(GroupGsd, GetCfgTelegrams) {
  const auto r = run_only(shipped(Shipped::A04), "GSD-02");
  const TestResult* t = find_result(r, "GSD-02");
  ASSERT_NE(t, nullptr);
  ASSERT_EQ(t->verdict, Verdict::Pass) << t->message;
  // Get_Cfg: DSAP 3B (59), SSAP 3E; FCS = 83+81+4D+3B+3E = 0x1CA -> CA.
  const Exchange* e = find_exchange(*t, "Get_Cfg");
  ASSERT_NE(e, nullptr);
  EXPECT_EQ(e->request, (std::vector<std::uint8_t>{0x68, 0x05, 0x05, 0x68, 0x83, 0x81, 0x4D, 0x3B,
                                                   0x3E, 0xCA, 0x16}));
  // PBVB0A04's one module is FF (16 words in/out, consistent): DL, DSAP 3E, SSAP 3B, FF;
  // LE = 6; FCS = 81+83+08+3E+3B+FF = 0x284 -> 84.
  EXPECT_EQ(e->response, (std::vector<std::uint8_t>{0x68, 0x06, 0x06, 0x68, 0x81, 0x83, 0x08, 0x3E,
                                                    0x3B, 0xFF, 0x84, 0x16}));
}

TEST(GroupGsd, MaxDiagDataLenCountsTheCfgFaultBlock) {
  // PBVB0A01: Max_Diag_Data_Len = 8; after a Chk_Cfg with one module too many the diagnosis is
  // the 6 standard octets plus an identifier-related block of 2 (header 42, one bitmap octet):
  // exactly 8.
  const auto r = run_only(shipped(Shipped::A01), "GSD-05");
  const TestResult* t = find_result(r, "GSD-05");
  ASSERT_NE(t, nullptr);
  ASSERT_EQ(t->verdict, Verdict::Pass) << t->message;
  EXPECT_NE(t->message.find("(longest 8)"), std::string::npos) << t->message;
}

TEST(GroupGsd, MutantsFail) {
  for (Shipped s : kAllShipped) {
    SCOPED_TRACE(shipped_name(s));
    const auto a = run_only(shipped(s, SlaveMutant::WrongDiagIdent), "GSD-01");
    EXPECT_EQ(verdict_of(a, "GSD-01"), Verdict::Fail) << describe(a);
    const auto b = run_only(shipped(s, SlaveMutant::WrongGetCfg), "GSD-02");
    EXPECT_EQ(verdict_of(b, "GSD-02"), Verdict::Fail) << describe(b);
  }
}

TEST(GroupGsd, UnsupportedFreezeMustGiveNotSupported) {
  auto gsd = shipped_gsd_with("PBVB0A02.gsd", "Freeze_Mode_supp        = 1",
                              "Freeze_Mode_supp        = 0");
  ASSERT_NE(gsd, nullptr);
  const auto r = run_only(shipped(Shipped::A02, std::nullopt, gsd), "GSD-07");
  const TestResult* t = find_result(r, "GSD-07");
  ASSERT_NE(t, nullptr);
  EXPECT_EQ(t->verdict, Verdict::Pass) << t->message;
  EXPECT_NE(t->message.find("Freeze_Req Not_Supported"), std::string::npos) << t->message;
}

}  // namespace
}  // namespace pbvbus::conformance::testing
