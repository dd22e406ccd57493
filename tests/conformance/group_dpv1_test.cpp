// Group "DP-V1" (V1-nn) on the shipped slave models and on the mutant aimed at it.
#include <gtest/gtest.h>

#include "group_test_support.hpp"

namespace pbvbus::conformance::testing {
namespace {

using devices::SlaveMutant;

TEST(GroupDpv1, PassesOnTheDpv1ModelAndIsNotApplicableElsewhere) {
  for (Shipped s : kAllShipped) {
    SCOPED_TRACE(shipped_name(s));
    const auto r = run_only(shipped(s), "DP-V1");
    ASSERT_EQ(r.results.size(), 6u) << describe(r);
    // Only PBVB0A03 says DPV1_Slave = 1 (with C1_Read_Write_supp and Process_Alarm_supp).
    const Verdict want = s == Shipped::A03 ? Verdict::Pass : Verdict::NotApplicable;
    for (const char* id : {"V1-01", "V1-02", "V1-03", "V1-04", "V1-05", "V1-06"})
      EXPECT_EQ(verdict_of(r, id), want) << id << describe(r);
  }
}

TEST(GroupDpv1, UnknownIndexTelegrams) {
  const auto r = run_only(shipped(Shipped::A03), "V1-03");
  const TestResult* t = find_result(r, "V1-03");
  ASSERT_NE(t, nullptr);
  ASSERT_EQ(t->verdict, Verdict::Pass) << t->message;
  // MSAC_C1 Read slot 0 index 254 (FE) length 16 (10): DA 83, SA 81, FC 4D, DSAP 33, SSAP 33,
  // 5E 00 FE 10; LE = 5 + 4 = 9; FCS = 83+81+4D+33+33+5E+00+FE+10 = 0x323 -> 23.
  const Exchange* e = find_exchange(*t, "index 254");
  ASSERT_NE(e, nullptr);
  EXPECT_EQ(e->request, (std::vector<std::uint8_t>{0x68, 0x09, 0x09, 0x68, 0x83, 0x81, 0x4D, 0x33,
                                                   0x33, 0x5E, 0x00, 0xFE, 0x10, 0x23, 0x16}));
  // Negative response DE 80 B0 00 (protocol-facts.md Appendix 1 has it from slave 10):
  // FCS = 81+83+08+33+33+DE+80+B0+00 = 0x380 -> 80.
  EXPECT_EQ(e->response, (std::vector<std::uint8_t>{0x68, 0x09, 0x09, 0x68, 0x81, 0x83, 0x08, 0x33,
                                                    0x33, 0xDE, 0x80, 0xB0, 0x00, 0x80, 0x16}));
}

TEST(GroupDpv1, AlarmAckTelegrams) {
  const auto r = run_only(shipped(Shipped::A03), "V1-06");
  const TestResult* t = find_result(r, "V1-06");
  ASSERT_NE(t, nullptr);
  ASSERT_EQ(t->verdict, Verdict::Pass) << t->message;
  // The model raises the process alarm of module 0 for slot 1, specifier 00 (Seq_Nr 0, no
  // Add_Ack, AlarmSpec None). Alarm_Ack to SAP 50 (32) from SSAP 51 (33): 5C 01 02 00;
  // FCS = 83+81+4D+32+33+5C+01+02+00 = 0x215 -> 15.
  const Exchange* ack = find_exchange(*t, "Alarm_Ack");
  ASSERT_NE(ack, nullptr);
  EXPECT_EQ(ack->request, (std::vector<std::uint8_t>{0x68, 0x09, 0x09, 0x68, 0x83, 0x81, 0x4D, 0x32,
                                                     0x33, 0x5C, 0x01, 0x02, 0x00, 0x15, 0x16}));
  // The echo: FCS = 81+83+08+33+32+5C+01+02+00 = 0x1D0 -> D0.
  EXPECT_EQ(ack->response,
            (std::vector<std::uint8_t>{0x68, 0x09, 0x09, 0x68, 0x81, 0x83, 0x08, 0x33, 0x32, 0x5C,
                                       0x01, 0x02, 0x00, 0xD0, 0x16}));
  // The second, unmatched Alarm_Ack: DC 80 B5 00; FCS = 81+83+08+33+32+DC+80+B5+00 = 0x382 -> 82.
  const Exchange* again = find_exchange(*t, "Alarm_Ack again");
  ASSERT_NE(again, nullptr);
  EXPECT_EQ(again->response,
            (std::vector<std::uint8_t>{0x68, 0x09, 0x09, 0x68, 0x81, 0x83, 0x08, 0x33, 0x32, 0xDC,
                                       0x80, 0xB5, 0x00, 0x82, 0x16}));
}

TEST(GroupDpv1, BadIndexAcceptedFails) {
  const auto r = run_only(shipped(Shipped::A03, SlaveMutant::Dpv1BadIndexAccepted), "DP-V1");
  EXPECT_EQ(verdict_of(r, "V1-03"), Verdict::Fail) << describe(r);
  EXPECT_EQ(verdict_of(r, "V1-01"), Verdict::Pass) << describe(r);  // not its rule
}

}  // namespace
}  // namespace pbvbus::conformance::testing
