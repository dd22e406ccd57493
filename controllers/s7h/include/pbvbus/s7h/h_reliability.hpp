#pragma once
// Reliability and availability of a 1-out-of-2 (redundant) system, as the S7-400H manual's
// appendix A "Characteristics of Redundant Programmable Controllers" gives them (000 L3955–L3991;
// 001 L13190–L13258, the same formulas and figures). docs/h-timing.md "Reliability" has the
// worked example. A pure library: no I/O, no clock.
//
//   MTBF_1oo2 = MTBF_1oo1² / (2·MDT + 2·(1 − dc)·MTBF_1oo1)            (000 L3979)
//   V         = MTBF / (MTBF + MDT) · 100 %                             (000 L3991, for 1oo2;
//               the same expression for the single channel, for comparison)
//   MDT       = error-detection time + repair time; the error-detection time is half the test
//               cycle time (default 90 min), the repair time normally 4 h (000 L3981–L3983)
//   the single channel (1oo1) of several components in series: 1/MTBF = Σ 1/MTBF_i (the usual
//               sum of failure rates; the manual says only "by calculating the failure rates of
//               the components used", 000 L3962)
//
// The manual's figures (the calculator's defaults): MTBF of a CPU 15 years, of an I/O module 50
// years (000 L3970–L3971), dc ≈ 95 % (000 L3975), MDT 4 hours (the comparison's framework,
// 000 L3999). Years are 8 760 hours (365 days; decision: the manual does not say).
//
// Units: hours, as double (the formula is a quotient; nothing here needs tick exactness).

#include <optional>
#include <span>
#include <string>

namespace pbvbus::devices {

inline constexpr double kHoursPerYear = 8760.0;

/// The manual's defaults (000 L3970–L3999).
inline constexpr double kMtbfCpuYears = 15.0;
inline constexpr double kMtbfIoModuleYears = 50.0;
inline constexpr double kDiagnosticCoverage = 0.95;
inline constexpr double kMdtHours = 4.0;
inline constexpr double kTestCycleHours = 1.5;  ///< 90 min (000 L3983)
inline constexpr double kRepairHours = 4.0;     ///< "normally four hours" (000 L3983)

/// MTBF of a 1oo2 system from its channel's MTBF_1oo1, MDT (same unit) and dc (0..1).
double mtbf_1oo2(double mtbf_1oo1, double mdt, double dc);
/// Availability MTBF / (MTBF + MDT) as a fraction (× 100 for %).
double availability(double mtbf, double mdt);
/// MDT = half the test cycle time + the repair time (000 L3981–L3983).
double mdt_from_test_cycle(double test_cycle, double repair);
/// One channel of components in series: 1 / Σ (1 / MTBF_i). 0 for an empty list.
double mtbf_series(std::span<const double> mtbf);

struct ReliabilityInput {
  double mtbf_1oo1_h = kMtbfCpuYears * kHoursPerYear;  ///< one channel (hours)
  double dc = kDiagnosticCoverage;
  double mdt_h = kMdtHours;
};

struct ReliabilityResult {
  ReliabilityInput in;
  double mtbf_1oo2_h = 0;
  double factor = 0;            ///< MTBF_1oo2 / MTBF_1oo1
  double availability_1oo1 = 0;  ///< fraction
  double availability_1oo2 = 0;  ///< fraction
  /// Expected down time per year (hours): (1 − V) · 8 760.
  double downtime_1oo1_h_per_year = 0;
  double downtime_1oo2_h_per_year = 0;
};

/// "" if the input is usable, else why not (MTBF > 0, 0 <= dc <= 1, MDT >= 0, all finite).
std::string check_reliability_input(const ReliabilityInput& in);
/// The figures; nullopt when check_reliability_input() refuses the input.
std::optional<ReliabilityResult> plan_reliability(const ReliabilityInput& in);

}  // namespace pbvbus::devices
