// Group "Set_Slave_Add" (ADD-nn) on the shipped slave models.
#include <gtest/gtest.h>

#include "group_test_support.hpp"

namespace pbvbus::conformance::testing {
namespace {

TEST(GroupSetSlaveAdd, PassesWhereSupportedAndIsNotApplicableElsewhere) {
  for (Shipped s : kAllShipped) {
    SCOPED_TRACE(shipped_name(s));
    const auto r = run_only(shipped(s), "Set_Slave_Add");
    ASSERT_TRUE(r.dut_error.empty()) << r.dut_error;
    ASSERT_EQ(r.results.size(), 4u) << describe(r);
    // Set_Slave_Add_supp: PBVB0A01 1, PBVB0A02 0, PBVB0A03 1, PBVB0A04 0.
    const bool supp = s == Shipped::A01 || s == Shipped::A03;
    for (const char* id : {"ADD-01", "ADD-02", "ADD-03", "ADD-04"})
      EXPECT_EQ(verdict_of(r, id), supp ? Verdict::Pass : Verdict::NotApplicable)
          << id << describe(r);
  }
}

TEST(GroupSetSlaveAdd, NewAddressTelegrams) {
  const auto r = run_only(shipped(Shipped::A01), "ADD-01");
  const TestResult* t = find_result(r, "ADD-01");
  ASSERT_NE(t, nullptr) << describe(r);
  ASSERT_EQ(t->verdict, Verdict::Pass) << t->message;
  // Set_Slave_Add 3 -> 100 (0x64), ident 0x0A01, No_Add_Chg 0, from the tester (1):
  //   DA 3|EXT = 83, SA 1|EXT = 81, FC SRD high FCV = 0: 4D, DSAP 37 (55), SSAP 3E (62),
  //   DU 64 0A 01 00; LE = 5 + 4 = 9; FCS = 83+81+4D+37+3E+64+0A+01+00 = 0x235 -> 35.
  const Exchange* e = find_exchange(*t, "Set_Slave_Add (3 -> 100)");
  ASSERT_NE(e, nullptr);
  EXPECT_EQ(e->request, (std::vector<std::uint8_t>{0x68, 0x09, 0x09, 0x68, 0x83, 0x81, 0x4D, 0x37,
                                                   0x3E, 0x64, 0x0A, 0x01, 0x00, 0x35, 0x16}));
  EXPECT_EQ(e->response, (std::vector<std::uint8_t>{0xE5}));  // SC
  // Slave_Diag at the old address 3 is not answered: 68 05 05 68 83 81 4D 3C 3E FCS 16 with
  // FCS = 83+81+4D+3C+3E = 0x1CB -> CB.
  const Exchange* old_diag = find_exchange(*t, "Slave_Diag at the old address");
  ASSERT_NE(old_diag, nullptr);
  EXPECT_EQ(old_diag->request, (std::vector<std::uint8_t>{0x68, 0x05, 0x05, 0x68, 0x83, 0x81, 0x4D,
                                                          0x3C, 0x3E, 0xCB, 0x16}));
  EXPECT_FALSE(old_diag->answered);
  // Slave_Diag at 100 is answered from SA 100|EXT = E4: the 6-octet diagnosis + DSAP/SSAP is an
  // 8-octet DU -> SD3: A2 81 E4 08 3E 3C 02 05 00 FF 0A 01 FCS 16,
  // FCS = 81+E4+08+3E+3C+02+05+00+FF+0A+01 = 0x2F8 -> F8.
  const Exchange* new_diag = find_exchange(*t, "Slave_Diag at the new address");
  ASSERT_NE(new_diag, nullptr);
  EXPECT_EQ(new_diag->response,
            (std::vector<std::uint8_t>{0xA2, 0x81, 0xE4, 0x08, 0x3E, 0x3C, 0x02, 0x05, 0x00, 0xFF,
                                       0x0A, 0x01, 0xF8, 0x16}));
}

}  // namespace
}  // namespace pbvbus::conformance::testing
