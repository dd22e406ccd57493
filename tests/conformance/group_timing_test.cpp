// Group "Timing" (TIM-nn) on the shipped slave models and on the mutants aimed at it.
#include <gtest/gtest.h>

#include "group_test_support.hpp"

namespace pbvbus::conformance::testing {
namespace {

using devices::SlaveMutant;

TEST(GroupTiming, PassesOnEveryShippedModel) {
  for (Shipped s : kAllShipped) {
    SCOPED_TRACE(shipped_name(s));
    const auto r = run_only(shipped(s), "Timing");
    ASSERT_EQ(r.results.size(), 3u) << describe(r);
    for (const char* id : {"TIM-01", "TIM-02", "TIM-03"})
      EXPECT_EQ(verdict_of(r, id), Verdict::Pass) << id << describe(r);
  }
}

TEST(GroupTiming, TsdrIsTheModelsOwnDelayAtEveryBaud) {
  // The shipped GSDs support all ten DP rates from 9.6k to 12M. The model's station delay is
  // unset, so it answers after the line's min TSDR = 11 bit times (slave_model.hpp). Per baud the
  // test sends Slave_Diag, Set_Prm, Chk_Cfg, Slave_Diag and one Data_Exchange: 10 x 5 = 50
  // exchanges, every one answered after exactly 11 idle bit times.
  const auto r = run_only(shipped(Shipped::A01), "TIM-01");
  const TestResult* t = find_result(r, "TIM-01");
  ASSERT_NE(t, nullptr);
  ASSERT_EQ(t->verdict, Verdict::Pass) << t->message;
  ASSERT_EQ(t->evidence.size(), 50u);
  for (const auto& e : t->evidence) {
    EXPECT_TRUE(e.answered) << e.note;
    EXPECT_EQ(e.tsdr_bits, 11) << e.note;
  }
  EXPECT_FALSE(t->timing_not_meaningful);
}

TEST(GroupTiming, TsdrTooLateFailsAtTheFirstBaud) {
  // tsdr_too_late answers 20 bit times after the GSD's MaxTsdr: at 9.6k MaxTsdr_9.6 = 60, so 80.
  const auto r = run_only(shipped(Shipped::A01, SlaveMutant::TsdrTooLate), "TIM-01");
  const TestResult* t = find_result(r, "TIM-01");
  ASSERT_NE(t, nullptr);
  EXPECT_EQ(t->verdict, Verdict::Fail);
  EXPECT_NE(t->message.find("at 9.6k"), std::string::npos) << t->message;
  EXPECT_NE(t->message.find("TSDR = 80 bit times, outside [11, 60]"), std::string::npos)
      << t->message;
}

TEST(GroupTiming, PollsAtMinSlaveIntervalSpacing) {
  // PBVB0A01 with Min_Slave_Intervall = 20 (2 ms): at 1.5 Mbit/s that is 3000 bit times, longer
  // than one message cycle (Data_Exchange SD2 11 octets = 121 bits, TSDR 11, reply 11 octets =
  // 121 bits, TSYN 33: 286 bits), so the polls start exactly 3000 bit times apart.
  auto gsd = shipped_gsd_with("PBVB0A01.gsd", "Min_Slave_Intervall     = 1",
                              "Min_Slave_Intervall     = 20");
  ASSERT_NE(gsd, nullptr);
  const auto r = run_only(shipped(Shipped::A01, std::nullopt, gsd), "TIM-02");
  const TestResult* t = find_result(r, "TIM-02");
  ASSERT_NE(t, nullptr);
  ASSERT_EQ(t->verdict, Verdict::Pass) << t->message;
  std::vector<const Exchange*> polls;
  for (const auto& e : t->evidence)
    if (e.note.rfind("Data_Exchange ", 0) == 0) polls.push_back(&e);
  ASSERT_EQ(polls.size(), 20u);
  const bus::Ticks bit = bus::ticks_per_bit(bus::Baud::k1_5M);
  for (std::size_t i = 1; i < polls.size(); ++i)
    EXPECT_EQ(polls[i]->request_start - polls[i - 1]->request_start, 3000 * bit) << i;
  // The same spacing starves slow_slave_interval (it needs 10 x 2 ms between polls).
  const auto m = run_only(shipped(Shipped::A01, SlaveMutant::SlowSlaveInterval, gsd), "TIM-02");
  EXPECT_EQ(verdict_of(m, "TIM-02"), Verdict::Fail) << describe(m);
  // And the shipped spacing (one message cycle, 286 bit times > 100 us = 150 bits) too.
  const auto m2 = run_only(shipped(Shipped::A01, SlaveMutant::SlowSlaveInterval), "TIM-02");
  EXPECT_EQ(verdict_of(m2, "TIM-02"), Verdict::Fail) << describe(m2);
}

TEST(GroupTiming, RequestsFollowRepliesAfterExactlyTsyn) {
  const auto r = run_only(shipped(Shipped::A02), "TIM-03");
  const TestResult* t = find_result(r, "TIM-03");
  ASSERT_NE(t, nullptr);
  ASSERT_EQ(t->verdict, Verdict::Pass) << t->message;
  const bus::Ticks bit = bus::ticks_per_bit(bus::Baud::k1_5M);
  int checked = 0;
  for (std::size_t i = 1; i < t->evidence.size(); ++i) {
    if (t->evidence[i].note.find("after 33 bit times of idle") == std::string::npos) continue;
    EXPECT_EQ(t->evidence[i].request_start - t->evidence[i - 1].response_end, 33 * bit) << i;
    EXPECT_TRUE(t->evidence[i].answered);
    ++checked;
  }
  EXPECT_EQ(checked, 6);
}

}  // namespace
}  // namespace pbvbus::conformance::testing
