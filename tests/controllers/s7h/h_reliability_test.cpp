// The reliability calculator (h_reliability.hpp) against the S7-400H manual's appendix A
// (000 L3955–L3999, 001 L13190–L13273): MTBF_1oo2 = MTBF_1oo1² / (2·MDT + 2·(1 − dc)·MTBF_1oo1),
// V = MTBF / (MTBF + MDT). The manual gives the formulas and the inputs (CPU 15 years, I/O module
// 50 years, dc ≈ 95 %, MDT 4 h; test cycle 90 min, repair 4 h) but no worked figures: every
// expected value below is worked out by hand from those inputs (a year = 8 760 h).
#include <gtest/gtest.h>

#include <array>

#include "pbvbus/s7h/h_reliability.hpp"

namespace pbvbus::devices {
namespace {

TEST(HReliability, CpuPairWithTheManualsDefaults) {
  // MTBF_1oo1 = 15 y = 15 · 8 760 = 131 400 h. Denominator 2·4 + 2·0.05·131 400 = 8 + 13 140
  // = 13 148 h. MTBF_1oo2 = 131 400² / 13 148 = 17 265 960 000 / 13 148: 13 148 · 1 313 200
  // = 17 265 953 600, remainder 6 400 → 1 313 200.487 h = 149.909 y, 9.994 × the single CPU.
  const auto r = plan_reliability({});
  ASSERT_TRUE(r.has_value());
  EXPECT_DOUBLE_EQ(r->in.mtbf_1oo1_h, 131400.0);
  EXPECT_NEAR(r->mtbf_1oo2_h, 1313200.487, 0.001);
  EXPECT_NEAR(r->mtbf_1oo2_h / kHoursPerYear, 149.909, 0.001);
  EXPECT_NEAR(r->factor, 9.994, 0.001);
  // V_1oo2 = 1 − 4 / 1 313 204.487 = 1 − 3.046e-6 (99.99970 %): 0.02668 h = 1.6 min a year.
  EXPECT_NEAR(1.0 - r->availability_1oo2, 3.046e-6, 0.001e-6);
  EXPECT_NEAR(r->downtime_1oo2_h_per_year, 0.02668, 0.00001);
  // The single CPU: V = 131 400 / 131 404 = 1 − 3.044e-5: 0.2667 h a year.
  EXPECT_NEAR(1.0 - r->availability_1oo1, 3.044e-5, 0.001e-5);
  EXPECT_NEAR(r->downtime_1oo1_h_per_year, 0.2667, 0.0001);
}

TEST(HReliability, IoModuleAndTheLimitsOfTheFormula) {
  // I/O module 50 y = 438 000 h: 438 000² / (8 + 0.1 · 438 000 = 43 808) = 191 844 000 000 /
  // 43 808: 43 808 · 4 379 200 = 191 843 993 600, remainder 6 400 → 4 379 200.146 h.
  EXPECT_NEAR(mtbf_1oo2(kMtbfIoModuleYears * kHoursPerYear, kMdtHours, kDiagnosticCoverage),
              4379200.146, 0.001);
  // dc = 1 (every fault found): only a second fault within the MDT stops the pair:
  // 131 400² / 8 = 2 158 245 000 h.
  EXPECT_DOUBLE_EQ(mtbf_1oo2(131400, 4, 1.0), 2158245000.0);
  // dc = 0: 131 400² / (8 + 262 800) = 65 698.0 h, about half the single channel (two
  // channels, either undetected fault counts).
  EXPECT_NEAR(mtbf_1oo2(131400, 4, 0.0), 65698.0, 0.001);
}

TEST(HReliability, MdtFromTheTestCycleAndSeriesChannels) {
  // MDT = 90 min / 2 + 4 h = 4.75 h (000 L3981–L3983); with it the CPU pair:
  // 17 265 960 000 / (9.5 + 13 140 = 13 149.5) = 1 313 050.686 h.
  const double mdt = mdt_from_test_cycle(kTestCycleHours, kRepairHours);
  EXPECT_DOUBLE_EQ(mdt, 4.75);
  EXPECT_NEAR(mtbf_1oo2(131400, mdt, 0.95), 1313050.686, 0.001);
  // A channel of a CPU (131 400 h) and an I/O module (438 000 h) in series:
  // 1 / (1/131 400 + 1/438 000) = 57 553 200 000 / 569 400 = 101 076.923 h.
  const std::array<double, 2> ch{131400, 438000};
  EXPECT_NEAR(mtbf_series(ch), 101076.923, 0.001);
  EXPECT_EQ(mtbf_series({}), 0.0);
}

TEST(HReliability, RefusesUnusableInput) {
  EXPECT_EQ(check_reliability_input({}), "");
  EXPECT_NE(check_reliability_input({0, 0.95, 4}), "");
  EXPECT_NE(check_reliability_input({131400, 1.5, 4}), "");
  EXPECT_NE(check_reliability_input({131400, -0.1, 4}), "");
  EXPECT_NE(check_reliability_input({131400, 0.95, -1}), "");
  EXPECT_NE(check_reliability_input({131400, 1.0, 0}), "");
  EXPECT_FALSE(plan_reliability({131400, 0.95, -1}).has_value());
}

}  // namespace
}  // namespace pbvbus::devices
