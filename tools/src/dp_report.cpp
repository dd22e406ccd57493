// The DP section of the `pbvbus run` report, text and JSON (schema in report.hpp).
#include <cstdio>
#include <ostream>

#include "pbvbus/tools/json_text.hpp"
#include "pbvbus/tools/dp_system.hpp"

namespace pbvbus::tools {

namespace {

std::string hex(const std::vector<std::uint8_t>& v) {
  std::string s;
  char buf[4];
  for (std::size_t i = 0; i < v.size(); ++i) {
    std::snprintf(buf, sizeof buf, "%02X", v[i]);
    if (i) s += ' ';
    s += buf;
  }
  return s;
}

}  // namespace

void write_dp_text(const std::vector<DpMasterReport>& r, std::ostream& os) {
  for (const auto& m : r) {
    const auto bit = bus::ticks_per_bit(m.baud);
    os << "\ndp master " << static_cast<int>(m.address) << " on line " << m.line << ": "
       << m.mode << ", Global_Control sent " << m.global_controls << ", Data_Control_Time "
       << m.data_control_time * 10 << " ms\n";
    for (const auto& s : m.slaves) {
      os << "  dp slave " << static_cast<int>(s.address) << " \"" << s.model << "\" [";
      for (std::size_t i = 0; i < s.modules.size(); ++i) os << (i ? ", " : "") << s.modules[i];
      os << "]: " << s.state << " (slave: " << s.slave_state << ")\n";
      os << "    diagnosis " << hex(s.diag);
      if (!s.diag_bits.empty()) {
        os << " (";
        for (std::size_t i = 0; i < s.diag_bits.size(); ++i) os << (i ? ", " : "") << s.diag_bits[i];
        os << ")";
      }
      os << "\n    inputs " << s.input_len << " octets: " << (s.inputs.empty() ? "-" : hex(s.inputs))
         << "\n    outputs " << s.output_len << " octets: " << (s.outputs.empty() ? "-" : hex(s.outputs))
         << "\n";
      const auto& st = s.stats;
      if (st.cycle_count > 0) {
        os << "    DP cycle (" << st.cycle_count << "): min " << format_us(st.cycle_min) << " / median "
           << format_us(s.cycle_median) << " / max " << format_us(st.cycle_max) << " us = " << st.cycle_min / bit
           << " / " << s.cycle_median / bit << " / " << st.cycle_max / bit << " bit times\n";
      }
      os << "    data exchanges " << st.data_exchanges << ", start-ups " << st.startups
         << ", diagnosis reads " << st.diag_reads << ", failures " << st.failures << ", returns "
         << st.returns << ", no response " << st.no_response << ", retries " << st.retries << "\n";
    }
  }
}

void write_dp_json(const std::vector<DpMasterReport>& r, std::ostream& os) {
  os << ",\n\"dp_masters\":[";
  for (std::size_t mi = 0; mi < r.size(); ++mi) {
    const auto& m = r[mi];
    const auto bit = bus::ticks_per_bit(m.baud);
    os << (mi ? ",\n" : "\n") << "{\"address\":" << static_cast<int>(m.address)
       << ",\"line\":" << json_quote(m.line) << ",\"mode\":" << json_quote(m.mode)
       << ",\"global_controls\":" << m.global_controls
       << ",\"data_control_time_ms\":" << m.data_control_time * 10 << ",\"slaves\":[";
    for (std::size_t i = 0; i < m.slaves.size(); ++i) {
      const auto& s = m.slaves[i];
      const auto& st = s.stats;
      os << (i ? ",\n  " : "\n  ") << "{\"address\":" << static_cast<int>(s.address)
         << ",\"model\":" << json_quote(s.model) << ",\"modules\":[";
      for (std::size_t k = 0; k < s.modules.size(); ++k) os << (k ? "," : "") << json_quote(s.modules[k]);
      os << "],\"state\":" << json_quote(s.state) << ",\"slave_state\":" << json_quote(s.slave_state)
         << ",\"diag\":" << json_quote(hex(s.diag)) << ",\"diag_bits\":[";
      for (std::size_t k = 0; k < s.diag_bits.size(); ++k) os << (k ? "," : "") << json_quote(s.diag_bits[k]);
      os << "],\"input_len\":" << s.input_len << ",\"output_len\":" << s.output_len
         << ",\"inputs\":" << json_quote(hex(s.inputs)) << ",\"outputs\":" << json_quote(hex(s.outputs))
         << ",\"cycle\":{\"count\":" << st.cycle_count << ",\"min_ns\":" << bus::ticks_to_ns(st.cycle_min)
         << ",\"median_ns\":" << bus::ticks_to_ns(s.cycle_median)
         << ",\"max_ns\":" << bus::ticks_to_ns(st.cycle_max) << ",\"min_bits\":" << st.cycle_min / bit
         << ",\"median_bits\":" << s.cycle_median / bit << ",\"max_bits\":" << st.cycle_max / bit
         << "},\"data_exchanges\":" << st.data_exchanges << ",\"startups\":" << st.startups
         << ",\"diag_reads\":" << st.diag_reads << ",\"failures\":" << st.failures
         << ",\"returns\":" << st.returns << ",\"no_response\":" << st.no_response
         << ",\"retries\":" << st.retries << "}";
    }
    os << "]}";
  }
  os << "]";
}

}  // namespace pbvbus::tools
