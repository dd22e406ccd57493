// `pbvbus timing`: the reliability figures of an h_system (timing_reliability.hpp).
#include "timing_reliability.hpp"

#include <cmath>
#include <cstdio>
#include <cstdlib>

namespace pbvbus::tools {

const char* const kReliabilityUsage =
    "  --mtbf-years Y  MTBF of one channel (1oo1) in years for the h_system reliability\n"
    "                  figures (default 15: a CPU, S7-400H manual appendix A)\n"
    "  --dc F          diagnostic coverage 0..1 (default 0.95)\n"
    "  --mdt-hours H   mean down time in hours (default 4)\n";

bool parse_reliability_option(const std::vector<std::string>& args, std::size_t& k,
                              ReliabilityOptions& o, bool& matched, std::string& error) {
  const std::string& a = args[k];
  double* target = a == "--mtbf-years" ? &o.mtbf_years
                   : a == "--dc"       ? &o.dc
                   : a == "--mdt-hours" ? &o.mdt_hours
                                        : nullptr;
  matched = target != nullptr;
  if (!matched) return true;
  if (k + 1 >= args.size()) {
    error = a + " needs a value";
    return false;
  }
  const std::string& v = args[k + 1];
  char* end = nullptr;
  const double d = std::strtod(v.c_str(), &end);
  if (v.empty() || end != v.c_str() + v.size() || !std::isfinite(d)) {
    error = "bad value '" + v + "' for " + a;
    return false;
  }
  *target = d;
  ++k;
  return true;
}

namespace {

std::string rel_fixed(double v, int decimals) {
  char b[64];
  std::snprintf(b, sizeof b, "%.*f", decimals, v);
  return b;
}

}  // namespace

void print_reliability_text(const devices::ReliabilityResult& r, std::ostream& out) {
  const double y = devices::kHoursPerYear;
  out << "  reliability (1oo2, S7-400H manual appendix A): MTBF_1oo1 "
      << rel_fixed(r.in.mtbf_1oo1_h / y, 2) << " y (" << rel_fixed(r.in.mtbf_1oo1_h, 0) << " h), dc "
      << rel_fixed(r.in.dc, 3) << ", MDT " << rel_fixed(r.in.mdt_h, 2) << " h\n";
  out << "    MTBF_1oo2 = MTBF_1oo1^2 / (2 MDT + 2 (1 - dc) MTBF_1oo1) = "
      << rel_fixed(r.mtbf_1oo2_h / y, 2) << " y (" << rel_fixed(r.mtbf_1oo2_h, 0) << " h), "
      << rel_fixed(r.factor, 3) << " x MTBF_1oo1\n";
  out << "    availability V = MTBF / (MTBF + MDT): 1oo2 " << rel_fixed(100.0 * r.availability_1oo2, 6)
      << " % (" << rel_fixed(60.0 * r.downtime_1oo2_h_per_year, 2) << " min down a year), 1oo1 "
      << rel_fixed(100.0 * r.availability_1oo1, 6) << " % ("
      << rel_fixed(60.0 * r.downtime_1oo1_h_per_year, 2) << " min)\n";
}

void print_reliability_json(const devices::ReliabilityResult& r, std::ostream& out) {
  out << "\"reliability\": {\"mtbf_1oo1_h\": " << rel_fixed(r.in.mtbf_1oo1_h, 3)
      << ", \"dc\": " << rel_fixed(r.in.dc, 6) << ", \"mdt_h\": " << rel_fixed(r.in.mdt_h, 6)
      << ", \"mtbf_1oo2_h\": " << rel_fixed(r.mtbf_1oo2_h, 3) << ", \"factor\": "
      << rel_fixed(r.factor, 6) << ", \"availability_1oo1\": " << rel_fixed(r.availability_1oo1, 12)
      << ", \"availability_1oo2\": " << rel_fixed(r.availability_1oo2, 12) << "}";
}

}  // namespace pbvbus::tools
