#pragma once
// `pbvbus timing`: the reliability figures of an h_system (controllers/s7h h_reliability.hpp;
// S7-400H manual appendix A, 000 L3955–L3999; docs/h-timing.md "Reliability").
#include <ostream>
#include <string>
#include <string_view>
#include <vector>

#include "pbvbus/s7h/h_reliability.hpp"

namespace pbvbus::tools {

/// The options --mtbf-years, --dc, --mdt-hours (the manual's defaults: 15 y, 0.95, 4 h).
struct ReliabilityOptions {
  double mtbf_years = devices::kMtbfCpuYears;
  double dc = devices::kDiagnosticCoverage;
  double mdt_hours = devices::kMdtHours;
};

/// If args[k] is one of the options, reads its value (args[k + 1]) and advances k past it.
/// Returns false and sets `error` for a bad or missing value; `matched` tells whether args[k]
/// was one of them.
bool parse_reliability_option(const std::vector<std::string>& args, std::size_t& k,
                              ReliabilityOptions& o, bool& matched, std::string& error);

/// The usage lines of the options.
extern const char* const kReliabilityUsage;

void print_reliability_text(const devices::ReliabilityResult& r, std::ostream& out);
/// `"reliability": {...}` (without a leading comma).
void print_reliability_json(const devices::ReliabilityResult& r, std::ostream& out);

}  // namespace pbvbus::tools
