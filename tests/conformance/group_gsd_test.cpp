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
    ASSERT_EQ(r.results.size(), 8u) << describe(r);
    for (const char* id :
         {"GSD-01", "GSD-02", "GSD-03", "GSD-04", "GSD-05", "GSD-06", "GSD-07", "GSD-08"})
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

TEST(GroupGsd, MinSlaveIntervallStated) {
  // PBVB0A01 writes Min_Slave_Intervall = 1: 100 us.
  const auto r = run_only(shipped(Shipped::A01), "GSD-08");
  const TestResult* t = find_result(r, "GSD-08");
  ASSERT_NE(t, nullptr);
  EXPECT_EQ(t->verdict, Verdict::Pass);
  EXPECT_EQ(t->message, "Min_Slave_Intervall = 1 (100 us)");
  EXPECT_TRUE(t->evidence.empty());  // judged on the file, no telegram
}

TEST(GroupGsd, MissingMinSlaveIntervallIsAGsdFaultNotATimingFault) {
  // The keyword removed: GSD-08 fails with the reason, TIM-02 runs with the smallest legal value
  // (1 = 100 us) and passes on the model, since the slave answers every poll.
  auto gsd = shipped_gsd_with("PBVB0A01.gsd", "Min_Slave_Intervall     = 1", "");
  ASSERT_NE(gsd, nullptr);
  ASSERT_EQ(gsd->slave_features().min_slave_intervall, 0);
  const auto r = run_only(shipped(Shipped::A01, std::nullopt, gsd), "GSD-08");
  const TestResult* g = find_result(r, "GSD-08");
  ASSERT_NE(g, nullptr);
  EXPECT_EQ(g->verdict, Verdict::Fail);
  EXPECT_EQ(g->group, "GSD");
  EXPECT_EQ(g->message, "the GSD lacks the mandatory Min_Slave_Intervall");

  const auto tr = run_only(shipped(Shipped::A01, std::nullopt, gsd), "TIM-02");
  const TestResult* t = find_result(tr, "TIM-02");
  ASSERT_NE(t, nullptr);
  ASSERT_EQ(t->verdict, Verdict::Pass) << t->message;
  // 100 us = 150 bit times at 1.5 Mbit/s is shorter than one message cycle (286 bit times, see
  // group_timing_test.cpp), so the polls come one message cycle apart: 286 bits = 190.67 us.
  EXPECT_EQ(t->message,
            "20 Data_Exchanges answered, request starts 190..190 us apart (Min_Slave_Intervall 100 us); "
            "one message cycle is longer than Min_Slave_Intervall at this baud; the GSD states no "
            "Min_Slave_Intervall (GSD-08), so the smallest legal value 1 (100 us) was used");
  // The slow-interval mutant still fails TIM-02 at that spacing (it needs 10 x 100 us).
  const auto m = run_only(shipped(Shipped::A01, SlaveMutant::SlowSlaveInterval, gsd), "TIM-02");
  EXPECT_EQ(verdict_of(m, "TIM-02"), Verdict::Fail) << describe(m);

  // Written as 0: outside the standard's range 1..65535, same verdict, its own reason.
  auto zero = shipped_gsd_with("PBVB0A01.gsd", "Min_Slave_Intervall     = 1", "Min_Slave_Intervall     = 0");
  ASSERT_NE(zero, nullptr);
  const auto z = run_only(shipped(Shipped::A01, std::nullopt, zero), "GSD-08");
  ASSERT_NE(find_result(z, "GSD-08"), nullptr);
  EXPECT_EQ(find_result(z, "GSD-08")->verdict, Verdict::Fail);
  EXPECT_EQ(find_result(z, "GSD-08")->message, "the GSD gives Min_Slave_Intervall = 0, outside 1..65535 (x 100 us)");
}

}  // namespace
}  // namespace pbvbus::conformance::testing
