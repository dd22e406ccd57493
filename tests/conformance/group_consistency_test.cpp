// Group "Consistency" (CON-nn) on the shipped slave models and on the mutant aimed at it.
#include <gtest/gtest.h>

#include "group_test_support.hpp"

namespace pbvbus::conformance::testing {
namespace {

using devices::SlaveMutant;

TEST(GroupConsistency, PassesWhereAConsistentModuleIsConfigured) {
  for (Shipped s : kAllShipped) {
    SCOPED_TRACE(shipped_name(s));
    const auto r = run_only(shipped(s), "Consistency");
    ASSERT_EQ(r.results.size(), 1u) << describe(r);
    // Consistent modules: PBVB0A03 "2AI U/I consistent" (D1: 2 words in), PBVB0A04 FF (16 words
    // in and out). PBVB0A01 (11 21) and the PBVB0A02 selection (10 20 61) have none.
    const bool has = s == Shipped::A03 || s == Shipped::A04;
    EXPECT_EQ(verdict_of(r, "CON-01"), has ? Verdict::Pass : Verdict::NotApplicable) << describe(r);
  }
}

TEST(GroupConsistency, WordsOfTheModuleAreEqualInEveryReply) {
  const auto r = run_only(shipped(Shipped::A03), "CON-01");
  const TestResult* t = find_result(r, "CON-01");
  ASSERT_NE(t, nullptr);
  ASSERT_EQ(t->verdict, Verdict::Pass) << t->message;
  // Inputs of PBVB0A03's selection: 8DI (1 octet), then D1 at offsets 1..4; the reply is
  // 68 08 08 68 01 03 08 | in0 w0h w0l w1h w1l | FCS 16. Both words of the module carry the
  // same DP-cycle counter.
  int seen = 0;
  for (const auto& e : t->evidence) {
    if (e.note.rfind("Data_Exchange ", 0) != 0) continue;
    ASSERT_EQ(e.response.size(), 14u) << e.note;
    EXPECT_EQ(e.response[8], e.response[10]) << e.note;
    EXPECT_EQ(e.response[9], e.response[11]) << e.note;
    ++seen;
  }
  EXPECT_EQ(seen, 60);  // the 200 polls' evidence is cut to the first 24 and last 40 exchanges
}

TEST(GroupConsistency, TearConsistentFails) {
  for (Shipped s : {Shipped::A03, Shipped::A04}) {
    const auto r = run_only(shipped(s, SlaveMutant::TearConsistent), "CON-01");
    EXPECT_EQ(verdict_of(r, "CON-01"), Verdict::Fail) << shipped_name(s) << describe(r);
  }
}

}  // namespace
}  // namespace pbvbus::conformance::testing
