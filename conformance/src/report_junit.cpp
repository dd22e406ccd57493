// JUnit XML report of a conformance run (report.hpp; schema tests/data/junit/junit.xsd).
//
// Decisions: one <testsuite> per group in report order, classname = the group, name = "ID NAME";
// n/a is <skipped> (CI servers show it as skipped, not failed); times are 0 (the battery runs in
// virtual time; wall time would say nothing about the DUT). A DUT that could not be built is one
// testsuite "DUT" with an <error>, so a CI job shows it instead of an empty, green report.

#include <sstream>

#include "pbvbus/conformance/report.hpp"
#include "report_util.hpp"

namespace pbvbus::conformance {

using detail::xml_escape;

std::string to_junit(const BatteryReport& report) {
  std::ostringstream o;
  o << "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n";
  if (!report.dut_error.empty()) {
    o << "<testsuites name=\"pbvbus conformance\" tests=\"1\" failures=\"0\" errors=\"1\" skipped=\"0\" time=\"0\">\n"
      << "  <testsuite name=\"DUT\" tests=\"1\" failures=\"0\" errors=\"1\" skipped=\"0\" time=\"0\">\n"
      << "    <testcase classname=\"DUT\" name=\"build the device under test\" time=\"0\">\n"
      << "      <error message=\"" << xml_escape(report.dut_error) << "\" type=\"dut\">"
      << xml_escape(describe_dut(report.spec)) << "</error>\n"
      << "    </testcase>\n  </testsuite>\n</testsuites>\n";
    return o.str();
  }
  o << "<testsuites name=\"pbvbus conformance\" tests=\"" << report.results.size() << "\" failures=\""
    << report.count(Verdict::Fail) << "\" errors=\"" << report.count(Verdict::Error) << "\" skipped=\"" << report.count(Verdict::NotApplicable)
    << "\" time=\"0\">\n";
  std::size_t i = 0;
  while (i < report.results.size()) {
    const std::string& group = report.results[i].group;
    std::size_t j = i;
    std::size_t fails = 0, skips = 0, errors = 0;
    while (j < report.results.size() && report.results[j].group == group) {
      fails += report.results[j].verdict == Verdict::Fail;
      skips += report.results[j].verdict == Verdict::NotApplicable;
      errors += report.results[j].verdict == Verdict::Error;
      ++j;
    }
    o << "  <testsuite name=\"" << xml_escape(group) << "\" tests=\"" << (j - i) << "\" failures=\"" << fails
      << "\" errors=\"" << errors << "\" skipped=\"" << skips << "\" time=\"0\">\n";
    for (std::size_t k = i; k < j; ++k) {
      const TestResult& r = report.results[k];
      o << "    <testcase classname=\"" << xml_escape(group) << "\" name=\"" << xml_escape(r.id + " " + r.name)
        << "\" time=\"0\">\n";
      if (r.verdict == Verdict::Fail) {
        o << "      <failure message=\"" << xml_escape(r.message) << "\" type=\"conformance\">"
          << xml_escape(r.message + "\nrequirement: " + r.requirement + "\nDUT: " + describe_dut(report.spec) +
                        "\nevidence (> tester to DUT, < DUT to tester, times in bit times):\n" +
                        evidence_text(r.evidence, "  "))
          << "</failure>\n";
      } else if (r.verdict == Verdict::Error) {
        o << "      <error message=\"" << xml_escape(r.message) << "\" type=\"precondition\">"
          << xml_escape(r.message + "\nrequirement (not tested): " + r.requirement +
                        "\nDUT: " + describe_dut(report.spec) +
                        "\nevidence (> tester to DUT, < DUT to tester, times in bit times):\n" +
                        evidence_text(r.evidence, "  "))
          << "</error>\n";
      } else if (r.verdict == Verdict::NotApplicable) {
        o << "      <skipped message=\"" << xml_escape(r.message) << "\"/>\n";
      }
      std::string out = r.requirement;
      if (r.timing_not_meaningful) out += std::string("\ntiming not meaningful: ") + kPtyTimingNote;
      o << "      <system-out>" << xml_escape(out) << "</system-out>\n";
      o << "    </testcase>\n";
    }
    o << "  </testsuite>\n";
    i = j;
  }
  o << "</testsuites>\n";
  return o.str();
}

}  // namespace pbvbus::conformance
