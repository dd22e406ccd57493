// Reliability of a 1oo2 system (h_reliability.hpp; S7-400H manual appendix A, 000 L3955–L3991).
#include "pbvbus/s7h/h_reliability.hpp"

#include <cmath>

namespace pbvbus::devices {

double mtbf_1oo2(double mtbf_1oo1, double mdt, double dc) {
  return mtbf_1oo1 * mtbf_1oo1 / (2.0 * mdt + 2.0 * (1.0 - dc) * mtbf_1oo1);  // 000 L3979
}

double availability(double mtbf, double mdt) { return mtbf / (mtbf + mdt); }  // 000 L3991

double mdt_from_test_cycle(double test_cycle, double repair) { return test_cycle / 2.0 + repair; }

double mtbf_series(std::span<const double> mtbf) {
  double rate = 0;
  for (double m : mtbf) rate += 1.0 / m;
  return rate > 0 ? 1.0 / rate : 0.0;
}

std::string check_reliability_input(const ReliabilityInput& in) {
  if (!std::isfinite(in.mtbf_1oo1_h) || in.mtbf_1oo1_h <= 0) return "MTBF must be > 0";
  if (!std::isfinite(in.dc) || in.dc < 0 || in.dc > 1) return "dc must be within 0..1";
  if (!std::isfinite(in.mdt_h) || in.mdt_h < 0) return "MDT must be >= 0";
  if (in.dc == 1 && in.mdt_h == 0) return "dc 1 with MDT 0 gives an infinite MTBF";
  return "";
}

std::optional<ReliabilityResult> plan_reliability(const ReliabilityInput& in) {
  if (!check_reliability_input(in).empty()) return std::nullopt;
  ReliabilityResult r;
  r.in = in;
  r.mtbf_1oo2_h = mtbf_1oo2(in.mtbf_1oo1_h, in.mdt_h, in.dc);
  r.factor = r.mtbf_1oo2_h / in.mtbf_1oo1_h;
  r.availability_1oo1 = availability(in.mtbf_1oo1_h, in.mdt_h);
  r.availability_1oo2 = availability(r.mtbf_1oo2_h, in.mdt_h);
  r.downtime_1oo1_h_per_year = (1.0 - r.availability_1oo1) * kHoursPerYear;
  r.downtime_1oo2_h_per_year = (1.0 - r.availability_1oo2) * kHoursPerYear;
  return r;
}

}  // namespace pbvbus::devices
