#include <algorithm>

#include "pbvbus/conformance/battery.hpp"

namespace pbvbus::conformance {

const char* verdict_name(Verdict v) {
  switch (v) {
    case Verdict::Pass: return "pass";
    case Verdict::Fail: return "fail";
    case Verdict::NotApplicable: return "n/a";
    case Verdict::Error: return "error";
  }
  return "?";
}

std::size_t BatteryReport::count(Verdict v) const {
  return static_cast<std::size_t>(
      std::count_if(results.begin(), results.end(), [v](const TestResult& r) { return r.verdict == v; }));
}

}  // namespace pbvbus::conformance
