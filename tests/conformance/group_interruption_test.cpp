// Group "Interruption" (INT-nn) on the shipped slave models and on the mutants aimed at it.
#include <gtest/gtest.h>

#include "group_test_support.hpp"

namespace pbvbus::conformance::testing {
namespace {

using devices::SlaveMutant;

TEST(GroupInterruption, PassesOnEveryShippedModel) {
  for (Shipped s : kAllShipped) {
    SCOPED_TRACE(shipped_name(s));
    const auto r = run_only(shipped(s), "Interruption");
    ASSERT_EQ(r.results.size(), 4u) << describe(r);
    for (const char* id : {"INT-01", "INT-02", "INT-03", "INT-04"})
      EXPECT_EQ(verdict_of(r, id), Verdict::Pass) << id << describe(r);
  }
}

TEST(GroupInterruption, PowerCycleTelegrams) {
  const auto r = run_only(shipped(Shipped::A01), "INT-03");
  const TestResult* t = find_result(r, "INT-03");
  ASSERT_NE(t, nullptr);
  ASSERT_EQ(t->verdict, Verdict::Pass) << t->message;
  // Set_Prm with the 100 ms watchdog: Station_Status Lock_Req|WD_On 88, WD_Fact_1 0A, WD_Fact_2
  // 01 (10 x 1 x 10 ms), min TSDR 0B, ident 0A 01, group 00, User_Prm_Data = the GSD defaults:
  // Bit(1) = 1 -> 02, BitArea(4-5) = 1 -> 10, Bit(0) = 0: 12. DU 8 octets, LE = 5 + 8 = 0D;
  // FCS = 83+81+4D+3D+3E+88+0A+01+0B+0A+01+00+12 = 0x287 -> 87.
  const Exchange* prm = find_exchange(*t, "start-up: Set_Prm");
  ASSERT_NE(prm, nullptr);
  EXPECT_EQ(prm->request,
            (std::vector<std::uint8_t>{0x68, 0x0D, 0x0D, 0x68, 0x83, 0x81, 0x4D, 0x3D, 0x3E, 0x88,
                                       0x0A, 0x01, 0x0B, 0x0A, 0x01, 0x00, 0x12, 0x87, 0x16}));
  // After power off/on: SD3 A2 DA=1|EXT 81, SA=3|EXT 83, FC DL 08, DSAP 3E, SSAP 3C,
  // 02 05 00 FF 0A 01; FCS = 81+83+08+3E+3C+02+05+00+FF+0A+01 = 0x297 -> 97.
  const Exchange* d = find_exchange(*t, "Slave_Diag after power off/on");
  ASSERT_NE(d, nullptr);
  EXPECT_EQ(d->response, (std::vector<std::uint8_t>{0xA2, 0x81, 0x83, 0x08, 0x3E, 0x3C, 0x02, 0x05,
                                                    0x00, 0xFF, 0x0A, 0x01, 0x97, 0x16}));
  // Data_Exchange in Wait_Prm: RS = SD1 10 01 03 03 FCS 16, FCS = 01+03+03 = 07.
  const Exchange* dx = find_exchange(*t, "Data_Exchange after power off/on");
  ASSERT_NE(dx, nullptr);
  EXPECT_EQ(dx->response, (std::vector<std::uint8_t>{0x10, 0x01, 0x03, 0x03, 0x07, 0x16}));
}

TEST(GroupInterruption, MutantsFail) {
  for (Shipped s : {Shipped::A01, Shipped::A04}) {
    SCOPED_TRACE(shipped_name(s));
    const auto k = run_only(shipped(s, SlaveMutant::KeepStateOnPowerCycle), "INT-03");
    EXPECT_EQ(verdict_of(k, "INT-03"), Verdict::Fail) << describe(k);
    const auto w = run_only(shipped(s, SlaveMutant::IgnoreWatchdog), "Interruption");
    EXPECT_EQ(verdict_of(w, "INT-01"), Verdict::Fail) << describe(w);
    EXPECT_EQ(verdict_of(w, "INT-04"), Verdict::Fail) << describe(w);
    EXPECT_EQ(verdict_of(w, "INT-02"), Verdict::Pass) << describe(w);  // not its rule
  }
}

}  // namespace
}  // namespace pbvbus::conformance::testing
