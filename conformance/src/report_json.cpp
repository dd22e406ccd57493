// JSON report of a conformance run, schema "pbvbus.conformance/1" (every field documented in
// report.hpp).

#include <sstream>

#include "pbvbus/conformance/report.hpp"
#include "report_util.hpp"

namespace pbvbus::conformance {

namespace {

using detail::json_str;

std::string ident_hex(std::uint16_t id) {
  char buf[8];
  std::snprintf(buf, sizeof buf, "0x%04X", id);
  return buf;
}

void evidence_json(std::ostringstream& o, const Exchange& e) {
  const bus::Ticks tb = bus::ticks_per_bit(e.baud);
  o << "{\"note\":" << json_str(e.note) << ",\"baud\":" << static_cast<std::uint32_t>(e.baud)
    << ",\"request\":" << json_str(detail::hex_octets(e.request))
    << ",\"request_start_bits\":" << e.request_start / tb << ",\"request_end_bits\":" << e.request_end / tb
    << ",\"expects_reply\":" << (e.expects_reply ? "true" : "false")
    << ",\"answered\":" << (e.answered ? "true" : "false")
    << ",\"response\":" << json_str(detail::hex_octets(e.response))
    << ",\"response_flags\":" << e.response_flags << ",\"response_start_bits\":";
  if (e.answered) o << e.response_start / tb;
  else o << "null";
  o << ",\"tsdr_bits\":";
  if (e.answered) o << e.tsdr_bits;
  else o << "null";
  o << ",\"sender\":" << int(e.sender) << "}";
}

}  // namespace

std::string to_json(const BatteryReport& report) {
  std::ostringstream o;
  const DutSpec& s = report.spec;
  o << "{\"schema\":\"pbvbus.conformance/1\",\"dut\":{";
  o << "\"kind\":" << json_str(s.pty_path ? "pty" : "model");
  o << ",\"gsd\":" << json_str(s.gsd_path);
  o << ",\"model_name\":" << json_str(s.gsd ? s.gsd->info().model_name : "");
  o << ",\"ident\":" << json_str(s.gsd ? ident_hex(s.gsd->ident_number()) : "");
  o << ",\"modules\":[";
  for (std::size_t i = 0; i < s.modules.size(); ++i)
    o << (i ? "," : "")
      << json_str(s.modules[i].index ? "#" + std::to_string(*s.modules[i].index) : s.modules[i].name);
  o << "],\"address\":" << int(s.address);
  o << ",\"baud\":" << json_str(bus::baud_name(dut_main_baud(s)));
  o << ",\"mutant\":";
  if (s.mutant) o << json_str(devices::slave_mutant_name(*s.mutant));
  else o << "null";
  o << ",\"pty\":";
  if (s.pty_path) o << json_str(*s.pty_path);
  else o << "null";
  o << ",\"speed\":";
  if (s.pty_path) o << json_str(std::to_string(s.speed.num) + "/" + std::to_string(s.speed.den));
  else o << "null";
  o << "},\"dut_error\":" << json_str(report.dut_error);
  o << ",\"passed\":" << (report.passed() ? "true" : "false");
  o << ",\"totals\":{\"tests\":" << report.results.size() << ",\"pass\":" << report.count(Verdict::Pass)
    << ",\"fail\":" << report.count(Verdict::Fail) << ",\"error\":" << report.count(Verdict::Error) << ",\"na\":" << report.count(Verdict::NotApplicable) << "}";
  o << ",\"timing_not_meaningful\":[";
  bool first = true;
  for (const auto& r : report.results)
    if (r.timing_not_meaningful) {
      o << (first ? "" : ",") << json_str(r.id);
      first = false;
    }
  o << "],\"timing_note\":" << json_str(s.pty_path ? kPtyTimingNote : "");
  {
    const TimingPlan& t = report.timing;
    const auto us = [](bus::Ticks x) { return std::to_string(bus::ticks_to_us(x)); };
    o << ",\"timing\":{\"tsl_bits\":" << t.tsl_bits << ",\"reply_wall_ms\":" << t.reply_wall.count()
      << ",\"exchange_span_us\":" << us(t.exchange_span) << ",\"twd_us\":" << us(t.twd)
      << ",\"wd_margin_us\":" << us(t.wd_margin) << "}";
  }
  o << ",\"tests\":[";
  for (std::size_t i = 0; i < report.results.size(); ++i) {
    const TestResult& r = report.results[i];
    o << (i ? "," : "") << "{\"id\":" << json_str(r.id) << ",\"group\":" << json_str(r.group)
      << ",\"name\":" << json_str(r.name) << ",\"requirement\":" << json_str(r.requirement)
      << ",\"verdict\":" << json_str(verdict_name(r.verdict)) << ",\"message\":" << json_str(r.message)
      << ",\"timing_not_meaningful\":" << (r.timing_not_meaningful ? "true" : "false") << ",\"evidence\":[";
    for (std::size_t k = 0; k < r.evidence.size(); ++k) {
      if (k) o << ",";
      evidence_json(o, r.evidence[k]);
    }
    o << "]}";
  }
  o << "]}\n";
  return o.str();
}

}  // namespace pbvbus::conformance
