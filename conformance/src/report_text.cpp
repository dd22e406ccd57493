// The readable report of a conformance run (report.hpp: format in the header comment).

#include <cstdio>
#include <sstream>

#include "pbvbus/conformance/report.hpp"
#include "report_util.hpp"

namespace pbvbus::conformance {

const char* const kPtyTimingNote =
    "the DUT is a program behind a pty: its reply time is wall time scaled by --speed, and the "
    "pty adds the operating system's scheduling delay, so timing checks (TSDR, min TSDR, "
    "watchdog time, Min_Slave_Interval) say nothing about the device's own timing";

namespace {

std::string modules_text(const DutSpec& s) {
  if (s.modules.empty()) return "(the compact station's module)";
  std::string o;
  for (const auto& m : s.modules) {
    if (!o.empty()) o += ", ";
    o += m.index ? "#" + std::to_string(*m.index) : "\"" + m.name + "\"";
  }
  return o;
}

char hex_digit(unsigned v) { return "0123456789ABCDEF"[v & 0xF]; }

std::string ident_text(std::uint16_t id) {
  std::string o = "0x";
  for (int sh = 12; sh >= 0; sh -= 4) o += hex_digit(static_cast<unsigned>(id >> sh));
  return o;
}

}  // namespace

std::string describe_dut(const DutSpec& spec) {
  std::string o = spec.gsd_path.empty() ? std::string("(GSD)") : spec.gsd_path;
  if (spec.gsd) o += " (" + spec.gsd->info().model_name + ", ident " + ident_text(spec.gsd->ident_number()) + ")";
  o += " at address " + std::to_string(spec.address) + ", " + std::string(bus::baud_name(dut_main_baud(spec)));
  if (spec.pty_path)
    o += ", outside slave on pty " + *spec.pty_path + " at speed " + std::to_string(spec.speed.num) + "/" +
         std::to_string(spec.speed.den);
  else
    o += ", slave model";
  if (spec.mutant) o += ", mutant " + std::string(devices::slave_mutant_name(*spec.mutant));
  return o;
}

std::string evidence_text(const std::vector<Exchange>& evidence, const std::string& indent) {
  std::ostringstream o;
  for (const Exchange& e : evidence) {
    const bus::Ticks tb = bus::ticks_per_bit(e.baud);
    o << indent << "> " << e.request_start / tb << " bt  " << detail::hex_octets(e.request);
    if (!e.note.empty()) o << "  (" << e.note << ", SA " << int(e.sender) << ")";
    o << "\n";
    if (!e.expects_reply) continue;
    if (!e.answered) {
      o << indent << "< no reply within TSL\n";
      continue;
    }
    o << indent << "< " << e.response_start / tb << " bt  " << detail::hex_octets(e.response) << "  (TSDR "
      << e.tsdr_bits << " bit times";
    if (e.response_flags != 0) o << ", receive errors " << e.response_flags;
    o << ")\n";
  }
  return o.str();
}

std::string to_text(const BatteryReport& report) {
  std::ostringstream o;
  const DutSpec& s = report.spec;
  o << "pbvbus conformance\n";
  o << "  DUT:      " << describe_dut(s) << "\n";
  o << "  GSD:      " << (s.gsd_path.empty() ? "-" : s.gsd_path);
  if (s.gsd) o << "  Model_Name \"" << s.gsd->info().model_name << "\", Ident_Number " << ident_text(s.gsd->ident_number());
  o << "\n";
  o << "  modules:  " << modules_text(s) << "\n";
  o << "  address:  " << int(s.address) << "\n";
  o << "  baud:     " << bus::baud_name(dut_main_baud(s)) << "\n";
  if (report.timing.twd > 0) o << "  timing:   " << report.timing.summary() << "\n";
  if (s.mutant) o << "  mutant:   " << devices::slave_mutant_name(*s.mutant) << "\n";
  if (s.pty_path) {
    o << "  pty:      " << *s.pty_path << ", speed " << s.speed.num << "/" << s.speed.den << "\n";
    std::string ids;
    for (const auto& r : report.results)
      if (r.timing_not_meaningful) ids += (ids.empty() ? "" : ", ") + r.id;
    o << "  timing not meaningful: " << (ids.empty() ? "(none run)" : ids) << "\n    (" << kPtyTimingNote << ")\n";
  }
  if (!report.dut_error.empty()) {
    o << "\nDUT ERROR: " << report.dut_error << "\nno tests run\n";
    return o.str();
  }
  std::string group;
  for (const TestResult& r : report.results) {
    if (r.group != group) {
      group = r.group;
      o << "\n" << group << "\n";
    }
    char line[32];
    std::snprintf(line, sizeof line, "  %-8s %-5s ", r.id.c_str(), verdict_name(r.verdict));
    o << line << r.name << (r.timing_not_meaningful ? "  [timing not meaningful]" : "") << "\n";
    if (r.verdict == Verdict::Fail) {
      o << "      " << r.message << "\n";
      o << "      requirement: " << r.requirement << "\n";
      o << evidence_text(r.evidence, "      ");
    } else if (r.verdict == Verdict::NotApplicable) {
      o << "      n/a: " << r.message << "\n";
    } else if (r.verdict == Verdict::Error) {
      o << "      error (not tested): " << r.message << "\n";
      o << evidence_text(r.evidence, "      ");
    }
  }
  o << "\n" << report.results.size() << " tests: " << report.count(Verdict::Pass) << " passed, "
    << report.count(Verdict::Fail) << " failed, " << report.count(Verdict::Error) << " errors, "
    << report.count(Verdict::NotApplicable) << " n/a\n";
  o << (report.passed() ? "PASSED\n" : "FAILED\n");
  return o.str();
}

}  // namespace pbvbus::conformance
