// Text and JSON of the Quantum Hot Standby part of the run report (simulation/quantum_report.hpp
// has the schema).
#include "pbvbus/reports/quantum_report.hpp"

#include <cstdio>

#include "pbvbus/reports/json_text.hpp"

namespace pbvbus::tools {

namespace {

std::string qr_ms(bus::Ticks t) { return format_us(t / 1000) + " ms"; }

std::string qr_scans(double s) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.3f", s);
  return buf;
}

std::string qr_addr(int a) { return a == 0 ? std::string("-") : std::to_string(a); }

}  // namespace

void write_quantum_text(const std::vector<QuantumReport>& reports, std::ostream& os) {
  for (const QuantumReport& r : reports) {
    os << "\nQuantum Hot Standby " << r.name << " (" << r.cpu << (r.iec ? ", IEC" : ", 984")
       << "): scan " << qr_ms(r.scan_time) << (r.scan_time_estimated ? " (scan-time model)" : "")
       << ", transfer " << qr_ms(r.transfer_time) << "; fibre " << r.fibre << "; "
       << r.transfers_completed << " transfers, " << r.transfers_lost << " lost\n";
    os << "  per scan:";
    for (const auto& t : r.every_scan) os << " " << t.type << " " << t.first << "+" << t.count;
    if (r.additional_slices != 0) os << "; additional over " << r.additional_slices << " scans";
    if (r.non_transfer) os << "; non-transfer " << r.non_transfer->first << "+" << r.non_transfer->count;
    os << "; command register " << r.command_register << "\n";
    for (const QuantumRackReport& k : r.racks)
      os << "  rack " << k.rack << " (" << k.designation << "): " << k.state << ", key " << k.key
         << ", logic " << k.logic_checksum << ", " << k.scans << " scans as primary, DP module "
         << k.dp_head << "; LEDs ready " << k.ready << ", com act " << k.com_act << ", primary "
         << k.primary << ", com err " << k.com_err << ", standby " << k.standby << "\n";
    for (const QuantumSwitchoverReport& s : r.switchovers) {
      os << "  switchover at " << bus::format_duration(s.at) << ": rack " << s.from << " -> rack "
         << s.to << " (" << s.cause << "), takeover " << qr_ms(s.takeover) << " = "
         << qr_scans(s.takeover_scans) << " scans";
      for (const auto& m : s.modbus)
        os << "; Modbus port " << m.port << " " << qr_addr(m.before[0]) << "/" << qr_addr(m.before[1])
           << " -> " << qr_addr(m.after[0]) << "/" << qr_addr(m.after[1]);
      os << "\n";
    }
    for (const QuantumPortReport& p : r.modbus) {
      os << "  Modbus port " << p.port << " (" << p.wiring << ", address " << p.address
         << (p.swap ? ", swap" : ", no swap") << "): rack 0 at " << qr_addr(p.addresses[0])
         << ", rack 1 at " << qr_addr(p.addresses[1]) << "; " << p.requests << " requests, "
         << p.exceptions << " exceptions, " << p.no_reply << " unanswered";
      if (p.conflicts != 0) os << ", " << p.conflicts << " address conflicts";
      os << "\n";
      for (const auto& d : p.doors) os << "    " << d << "\n";
    }
    if (r.dp)
      os << "  DP master modules at " << r.dp->address << " on " << r.dp->line << ": "
         << r.dp->takeovers << " takeovers, " << r.dp->resumed << " slaves resumed, "
         << r.dp->restarted << " restarted\n";
    for (const auto& [t, text] : r.faults) os << "  fault at " << bus::format_duration(t) << ": " << text << "\n";
  }
}

void write_quantum_json(const std::vector<QuantumReport>& reports, std::ostream& os) {
  if (reports.empty()) return;
  os << ",\n\"quantum\":[";
  for (std::size_t i = 0; i < reports.size(); ++i) {
    const QuantumReport& r = reports[i];
    os << (i ? ",\n" : "") << "{\"name\":" << json_quote(r.name) << ",\"cpu\":" << json_quote(r.cpu)
       << ",\"iec\":" << (r.iec ? "true" : "false") << ",\"scan_time_ns\":" << bus::ticks_to_ns(r.scan_time)
       << ",\"scan_time_estimated\":" << (r.scan_time_estimated ? "true" : "false")
       << ",\"transfer_time_ns\":" << bus::ticks_to_ns(r.transfer_time) << ",\"transfer\":{\"every_scan\":[";
    for (std::size_t k = 0; k < r.every_scan.size(); ++k)
      os << (k ? "," : "") << "{\"type\":" << json_quote(r.every_scan[k].type) << ",\"first\":"
         << json_quote(r.every_scan[k].first) << ",\"count\":" << r.every_scan[k].count << "}";
    os << "],\"additional_slices\":" << r.additional_slices << ",\"non_transfer\":";
    if (r.non_transfer)
      os << "{\"first\":" << json_quote(r.non_transfer->first) << ",\"count\":" << r.non_transfer->count << "}";
    else
      os << "null";
    os << ",\"command_register\":" << json_quote(r.command_register) << "},\"racks\":[";
    for (std::size_t k = 0; k < 2; ++k) {
      const QuantumRackReport& c = r.racks[k];
      os << (k ? "," : "") << "{\"rack\":" << c.rack << ",\"designation\":" << json_quote(c.designation)
         << ",\"state\":" << json_quote(c.state) << ",\"key\":" << json_quote(c.key)
         << ",\"logic_checksum\":" << c.logic_checksum << ",\"scans\":" << c.scans << ",\"leds\":{\"ready\":"
         << json_quote(c.ready) << ",\"com_act\":" << json_quote(c.com_act) << ",\"primary\":"
         << json_quote(c.primary) << ",\"com_err\":" << json_quote(c.com_err) << ",\"standby\":"
         << json_quote(c.standby) << "},\"dp_head\":" << json_quote(c.dp_head) << "}";
    }
    os << "],\"fibre\":" << json_quote(r.fibre) << ",\"transfers_completed\":" << r.transfers_completed
       << ",\"transfers_lost\":" << r.transfers_lost << ",\"switchovers\":[";
    for (std::size_t k = 0; k < r.switchovers.size(); ++k) {
      const QuantumSwitchoverReport& s = r.switchovers[k];
      os << (k ? "," : "") << "{\"at_ns\":" << bus::ticks_to_ns(s.at) << ",\"cause_ns\":"
         << bus::ticks_to_ns(s.cause_at) << ",\"cause\":" << json_quote(s.cause) << ",\"from\":" << s.from
         << ",\"to\":" << s.to << ",\"takeover_ns\":" << bus::ticks_to_ns(s.takeover)
         << ",\"takeover_scans\":" << qr_scans(s.takeover_scans) << ",\"modbus\":[";
      for (std::size_t m = 0; m < s.modbus.size(); ++m)
        os << (m ? "," : "") << "{\"port\":" << s.modbus[m].port << ",\"before\":[" << s.modbus[m].before[0]
           << "," << s.modbus[m].before[1] << "],\"after\":[" << s.modbus[m].after[0] << ","
           << s.modbus[m].after[1] << "]}";
      os << "]}";
    }
    os << "],\"modbus\":[";
    for (std::size_t k = 0; k < r.modbus.size(); ++k) {
      const QuantumPortReport& p = r.modbus[k];
      os << (k ? "," : "") << "{\"port\":" << p.port << ",\"address\":" << p.address << ",\"swap\":"
         << (p.swap ? "true" : "false") << ",\"wiring\":" << json_quote(p.wiring) << ",\"addresses\":["
         << p.addresses[0] << "," << p.addresses[1] << "],\"doors\":[";
      for (std::size_t d = 0; d < p.doors.size(); ++d) os << (d ? "," : "") << json_quote(p.doors[d]);
      os << "],\"requests\":" << p.requests << ",\"exceptions\":" << p.exceptions << ",\"no_reply\":"
         << p.no_reply << ",\"conflicts\":" << p.conflicts << "}";
    }
    os << "],\"dp\":";
    if (r.dp)
      os << "{\"line\":" << json_quote(r.dp->line) << ",\"address\":" << r.dp->address << ",\"takeovers\":"
         << r.dp->takeovers << ",\"resumed\":" << r.dp->resumed << ",\"restarted\":" << r.dp->restarted << "}";
    else
      os << "null";
    os << ",\"events\":[";
    for (std::size_t k = 0; k < r.events.size(); ++k)
      os << (k ? "," : "") << "{\"at_ns\":" << bus::ticks_to_ns(r.events[k].at) << ",\"rack\":" << r.events[k].rack
         << ",\"kind\":" << json_quote(r.events[k].kind) << ",\"text\":" << json_quote(r.events[k].text) << "}";
    os << "],\"faults\":[";
    for (std::size_t k = 0; k < r.faults.size(); ++k)
      os << (k ? "," : "") << "{\"at_ns\":" << bus::ticks_to_ns(r.faults[k].first) << ",\"text\":"
         << json_quote(r.faults[k].second) << "}";
    os << "]}";
  }
  os << "]";
}

}  // namespace pbvbus::tools
