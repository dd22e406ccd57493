// Group "Fail-safe" (FS-nn) on the shipped slave models and on the mutant aimed at it.
#include <gtest/gtest.h>

#include "group_test_support.hpp"

namespace pbvbus::conformance::testing {
namespace {

using devices::SlaveMutant;

TEST(GroupFailSafe, PassesWhereFailSafeAndIsNotApplicableElsewhere) {
  for (Shipped s : kAllShipped) {
    SCOPED_TRACE(shipped_name(s));
    const auto r = run_only(shipped(s), "Fail-safe");
    ASSERT_EQ(r.results.size(), 2u) << describe(r);
    // Fail_Safe: PBVB0A01..03 = 1, PBVB0A04 = 0.
    EXPECT_EQ(verdict_of(r, "FS-01"), s == Shipped::A04 ? Verdict::NotApplicable : Verdict::Pass)
        << describe(r);
    EXPECT_EQ(verdict_of(r, "FS-02"), Verdict::Pass) << describe(r);
  }
}

TEST(GroupFailSafe, ZeroLengthDataExchangeOnTheWire) {
  const auto r = run_only(shipped(Shipped::A01), "FS-01");
  const TestResult* t = find_result(r, "FS-01");
  ASSERT_NE(t, nullptr);
  ASSERT_EQ(t->verdict, Verdict::Pass) << t->message;
  // No DU at all -> SD1: 10 DA SA FC FCS 16 = 10 03 01 4D, FCS = 03+01+4D = 51.
  const Exchange* e = find_exchange(*t, "without output data");
  ASSERT_NE(e, nullptr);
  EXPECT_EQ(e->request, (std::vector<std::uint8_t>{0x10, 0x03, 0x01, 0x4D, 0x51, 0x16}));
  // Answered DL with the 2 input octets: 68 05 05 68 01 03 08 i0 i1 FCS 16.
  ASSERT_EQ(e->response.size(), 11u);
  EXPECT_EQ(std::vector<std::uint8_t>(e->response.begin(), e->response.begin() + 7),
            (std::vector<std::uint8_t>{0x68, 0x05, 0x05, 0x68, 0x01, 0x03, 0x08}));
}

TEST(GroupFailSafe, RejectFailSafeFails) {
  for (Shipped s : {Shipped::A01, Shipped::A02, Shipped::A03}) {
    const auto r = run_only(shipped(s, SlaveMutant::RejectFailSafe), "FS-01");
    EXPECT_EQ(verdict_of(r, "FS-01"), Verdict::Fail) << shipped_name(s) << describe(r);
  }
}

}  // namespace
}  // namespace pbvbus::conformance::testing
