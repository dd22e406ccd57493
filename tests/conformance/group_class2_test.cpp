// Group "Class 2" (C2-nn) on the shipped slave models and on the mutants aimed at it.
#include <gtest/gtest.h>

#include "group_test_support.hpp"

namespace pbvbus::conformance::testing {
namespace {

using devices::SlaveMutant;

TEST(GroupClass2, PassesOnEveryShippedModel) {
  for (Shipped s : kAllShipped) {
    SCOPED_TRACE(shipped_name(s));
    const auto r = run_only(shipped(s), "Class 2");
    ASSERT_EQ(r.results.size(), 4u) << describe(r);
    for (const char* id : {"C2-01", "C2-02", "C2-03", "C2-04"})
      EXPECT_EQ(verdict_of(r, id), Verdict::Pass) << id << describe(r);
  }
}

TEST(GroupClass2, Class2DiagShowsTheOwner) {
  const auto r = run_only(shipped(Shipped::A01), "C2-01");
  const TestResult* t = find_result(r, "C2-01");
  ASSERT_NE(t, nullptr);
  ASSERT_EQ(t->verdict, Verdict::Pass) << t->message;
  // Slave_Diag from the class-2 master: DA 3|EXT 83, SA 2|EXT 82, SRD high FCV = 0 4D, DSAP 3C,
  // SSAP 3E; FCS = 83+82+4D+3C+3E = 0x1CC -> CC.
  const Exchange* e = find_exchange(*t, "class 2: Slave_Diag");
  ASSERT_NE(e, nullptr);
  EXPECT_EQ(e->request, (std::vector<std::uint8_t>{0x68, 0x05, 0x05, 0x68, 0x83, 0x82, 0x4D, 0x3C,
                                                   0x3E, 0xCC, 0x16}));
  // Answer (SD3): in Data_Exch with the tester: 00, WD_On|always-1 0C, 00, Master_Add 01, 0A 01;
  // FCS = 82+83+08+3E+3C+00+0C+00+01+0A+01 = 0x19F -> 9F.
  EXPECT_EQ(e->response, (std::vector<std::uint8_t>{0xA2, 0x82, 0x83, 0x08, 0x3E, 0x3C, 0x00, 0x0C,
                                                    0x00, 0x01, 0x0A, 0x01, 0x9F, 0x16}));
}

TEST(GroupClass2, IgnoreLockFails) {
  for (Shipped s : kAllShipped) {
    const auto r = run_only(shipped(s, SlaveMutant::IgnoreLock), "C2-02");
    EXPECT_EQ(verdict_of(r, "C2-02"), Verdict::Fail) << shipped_name(s) << describe(r);
  }
}

}  // namespace
}  // namespace pbvbus::conformance::testing
