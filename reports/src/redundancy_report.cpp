// The redundancy part of the run report (redundancy_system.hpp; schema in report.hpp).
#include "pbvbus/reports/redundancy_report.hpp"

#include <cstdio>
#include <ostream>

#include "pbvbus/reports/json_text.hpp"

namespace pbvbus::tools {

namespace {

std::string code_text(std::uint16_t code) {
  char b[16];
  std::snprintf(b, sizeof b, "W#16#%04X", code);
  return b;
}

std::string ms(bus::Ticks t) { return format_us(t) + " us"; }

std::string json_or_null(const std::string& s) { return s.empty() ? "null" : json_quote(s); }

}  // namespace

void write_redundancy_text(const std::vector<RedundancyReport>& reports, std::ostream& os) {
  for (const auto& r : reports) {
    os << "redundant DP master system \"" << r.name << "\": line " << r.line[0] << " (master "
       << int(r.master[0]) << ") and line " << r.line[1] << " (master " << int(r.master[1])
       << ")\n";
    os << "  planned: T_TR " << ms(r.t_tr[0]) << " / " << ms(r.t_tr[1]) << ", error recognition "
       << ms(r.recognition[0]) << " / " << ms(r.recognition[1]) << ", whole-line switchover bound "
       << ms(r.system_bound[0]) << " / " << ms(r.system_bound[1]) << "\n";
    for (const auto& s : r.stations) {
      os << "  switched station " << int(s.address) << " " << s.model << ": active "
         << (s.active.empty() ? "none" : "line " + s.active) << " (interfaces " << s.roles[0]
         << " / " << s.roles[1] << ")" << (s.redundancy_lost ? ", redundancy lost" : "")
         << (s.failed ? ", FAILED" : "") << ", outputs " << (s.outputs.empty() ? "-" : hex_octets(s.outputs))
         << (s.outputs_held ? " (held)" : "");
      if (s.t_slave_um) os << ", T_SLAVE_UM " << ms(*s.t_slave_um);
      os << ", bound " << ms(s.bound[0]) << " / " << ms(s.bound[1]) << "\n";
    }
    for (const auto& e : r.events) {
      os << "  " << bus::format_duration(e.time) << ": ";
      if (e.ob != 0) os << "OB " << e.ob << " " << code_text(e.code) << " ";
      os << e.kind;
      if (e.station >= 0) os << ", station " << e.station;
      os << ", line " << e.line;
      if (e.ob == 0 && !e.from.empty()) os << " (from line " << e.from << ")";
      os << " [" << e.cause << "]\n";
    }
    for (const auto& w : r.switchovers) {
      os << "  switchover of station " << int(w.station) << " to line " << w.to
         << (w.system_level ? " (system-level)" : "") << ": ";
      if (w.measured) {
        os << "measured " << ms(*w.measured) << " (fault at " << bus::format_duration(w.fault_at)
           << ", fresh outputs at " << bus::format_duration(*w.fresh) << ")";
        if (w.im_time) os << ", IM " << ms(*w.im_time);
        os << ", bound " << ms(w.bound) << (w.exceeded ? "  ** EXCEEDS THE BOUND **" : "");
      } else {
        os << "no fresh outputs on the new channel (station lost), bound " << ms(w.bound);
      }
      if (!w.fault.empty()) os << "; fault: " << w.fault;
      os << "\n";
    }
    if (r.exceeded != 0) os << "  " << r.exceeded << " switchover(s) exceeded the planned bound\n";
  }
}

void write_redundancy_json(const std::vector<RedundancyReport>& reports, std::ostream& os) {
  if (reports.empty()) return;
  os << ",\n\"redundancy\":[";
  bool first = true;
  for (const auto& r : reports) {
    os << (first ? "" : ",") << "\n{\"name\":" << json_quote(r.name) << ",\"lines\":["
       << json_quote(r.line[0]) << "," << json_quote(r.line[1]) << "],\"masters\":["
       << int(r.master[0]) << "," << int(r.master[1]) << "],\"t_tr_ns\":["
       << bus::ticks_to_ns(r.t_tr[0]) << "," << bus::ticks_to_ns(r.t_tr[1])
       << "],\"recognition_ns\":[" << bus::ticks_to_ns(r.recognition[0]) << ","
       << bus::ticks_to_ns(r.recognition[1]) << "],\"system_bound_ns\":["
       << bus::ticks_to_ns(r.system_bound[0]) << "," << bus::ticks_to_ns(r.system_bound[1])
       << "],\n\"stations\":[";
    first = false;
    bool f2 = true;
    for (const auto& s : r.stations) {
      os << (f2 ? "" : ",") << "\n{\"address\":" << int(s.address) << ",\"model\":"
         << json_quote(s.model) << ",\"modules\":[";
      for (std::size_t i = 0; i < s.modules.size(); ++i) os << (i ? "," : "") << json_quote(s.modules[i]);
      os << "],\"active\":" << json_or_null(s.active) << ",\"roles\":[" << json_quote(s.roles[0])
         << "," << json_quote(s.roles[1]) << "],\"redundancy_lost\":"
         << (s.redundancy_lost ? "true" : "false") << ",\"failed\":" << (s.failed ? "true" : "false")
         << ",\"outputs_held\":" << (s.outputs_held ? "true" : "false") << ",\"outputs\":"
         << json_quote(hex_octets(s.outputs)) << ",\"t_slave_um_ns\":";
      if (s.t_slave_um) os << bus::ticks_to_ns(*s.t_slave_um);
      else os << "null";
      os << ",\"bound_ns\":[" << bus::ticks_to_ns(s.bound[0]) << "," << bus::ticks_to_ns(s.bound[1])
         << "]}";
      f2 = false;
    }
    os << "],\n\"events\":[";
    f2 = true;
    for (const auto& e : r.events) {
      os << (f2 ? "" : ",") << "\n{\"time_ns\":" << bus::ticks_to_ns(e.time) << ",\"ob\":" << e.ob
         << ",\"code\":" << (e.ob != 0 ? json_quote(code_text(e.code)) : "null") << ",\"kind\":"
         << json_quote(e.kind) << ",\"line\":" << json_quote(e.line) << ",\"station\":";
      if (e.station >= 0) os << e.station;
      else os << "null";
      os << ",\"cause\":" << json_quote(e.cause) << ",\"from\":" << json_or_null(e.from) << "}";
      f2 = false;
    }
    os << "],\n\"switchovers\":[";
    f2 = true;
    for (const auto& w : r.switchovers) {
      os << (f2 ? "" : ",") << "\n{\"station\":" << int(w.station) << ",\"from\":"
         << json_or_null(w.from) << ",\"to\":" << json_quote(w.to) << ",\"cause\":"
         << json_quote(w.cause) << ",\"system_level\":" << (w.system_level ? "true" : "false")
         << ",\"fault\":" << json_quote(w.fault) << ",\"fault_ns\":" << bus::ticks_to_ns(w.fault_at)
         << ",\"commanded_ns\":" << bus::ticks_to_ns(w.commanded) << ",\"fresh_ns\":";
      if (w.fresh) os << bus::ticks_to_ns(*w.fresh);
      else os << "null";
      os << ",\"measured_ns\":";
      if (w.measured) os << bus::ticks_to_ns(*w.measured);
      else os << "null";
      os << ",\"im_ns\":";
      if (w.im_time) os << bus::ticks_to_ns(*w.im_time);
      else os << "null";
      os << ",\"bound_ns\":" << bus::ticks_to_ns(w.bound) << ",\"exceeded\":"
         << (w.exceeded ? "true" : "false") << "}";
      f2 = false;
    }
    os << "],\"exceeded\":" << r.exceeded << "}";
  }
  os << "]";
}

}  // namespace pbvbus::tools
