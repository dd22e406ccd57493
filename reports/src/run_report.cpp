// The run report in text and JSON (run_report.hpp).
#include "pbvbus/reports/run_report.hpp"

#include <algorithm>
#include <cstdio>
#include <ostream>

#include "pbvbus/reports/json_text.hpp"
#include "pbvbus/reports/quantum_report.hpp"
#include "pbvbus/reports/s7_report.hpp"

namespace pbvbus::tools {
namespace {

constexpr const char* kTypeNames[LineStats::kTypes] = {"SD1", "SD2", "SD3", "SD4", "SC"};

std::string fixed(double v, int decimals) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.*f", decimals, v);
  return buf;
}


}  // namespace

void write_text(const Report& r, std::ostream& os) {
  os << "scenario " << (r.name.empty() ? "(unnamed)" : r.name) << " (" << r.file << "), seed "
     << r.seed << "\n";
  os << "simulated " << bus::format_duration(r.duration) << " in " << fixed(r.wall_seconds, 3)
     << " s wall time";
  if (r.wall_seconds > 0)
    os << " (" << fixed(static_cast<double>(r.duration) / bus::kTicksPerSecond / r.wall_seconds, 1)
       << "x real time)";
  os << ", " << r.events << " events\n";
  for (const auto& s : r.serial) {
    const auto bit = bus::ticks_per_bit(s.baud);
    const auto& st = s.stats;
    os << "serial " << s.mode;
    if (s.address) os << " " << static_cast<int>(*s.address);
    os << " on line " << s.line << ": " << s.path;
    if (!s.link.empty()) os << " (" << s.link << ")";
    os << ", " << s.timing << " timing\n";
    os << "  from the program: " << st.bytes_in << " octets, " << st.frames_in << " telegrams ("
       << st.octets_sent << " octets) put on the line, " << st.garbage_bytes
       << " octets discarded (" << st.abandoned << " incomplete telegrams)";
    if (st.discarded) os << ", " << st.discarded << " telegrams lost unsent";
    os << "\n  dropped unsent: " << st.dropped_full << " (queue full), " << st.dropped_stale
       << " (too old), " << st.dropped_closed << " (program closed); program opens "
       << st.program_opens << ", closes " << st.program_closes << ", address changes "
       << st.address_changes;
    os << "\n  held " << st.held << " telegrams, total " << format_us(st.hold_total) << " us = "
       << st.hold_total / bit << " bit times, max " << format_us(st.hold_max) << " us = "
       << st.hold_max / bit << " bit times, at most " << st.queue_max << " waiting\n";
    os << "  to the program: " << st.frames_out << " frames (" << st.bytes_out << " octets), "
       << st.frames_dropped << " dropped (not read), " << st.frames_no_program
       << " while no program had it open\n";
    os << "  requests dropped by the line's receivers for too short an idle time (TSYN): "
       << s.receivers_tsyn_drops << "\n";
  }
  for (const auto& l : r.lines) {
    const auto bit = bus::ticks_per_bit(l.baud);
    os << "\nline " << l.name << " (" << bus::baud_name(l.baud) << "bit/s, TSL " << l.params.tsl
       << ", TTR " << l.params.ttr << " bit times)\n";
    if (!l.probe.empty()) os << "  traffic as seen at the probe next to " << l.probe << "\n";
    os << "  live list:";
    if (l.live.empty()) os << " (empty)";
    os << "\n";
    for (const auto& e : l.live)
      os << "    " << static_cast<int>(e.address) << "\t" << fdl::to_string(e.type) << "\n";
    for (const auto& m : l.masters) {
      os << "  master " << static_cast<int>(m.address);
      if (!m.state.empty()) os << " (" << m.state << ")";
      os << ": " << (m.in_ring ? "in the ring" : "not in the ring") << ", LAS {";
      for (std::size_t i = 0; i < m.las.size(); ++i) os << (i ? " " : "") << static_cast<int>(m.las[i]);
      os << "}\n    tokens received " << m.tokens_received << ", passed " << m.tokens_passed
         << " (" << m.token_pass_retries << " repeated), token losses/claims " << m.token_losses
         << ", stations dropped " << m.stations_dropped << ", admitted " << m.admissions
         << ", duplicate tokens " << m.duplicate_tokens << ", GAP polls " << m.gap_polls << "\n";
      if (m.rotation.count > 0) {
        os << "    token rotation (" << m.rotation.count << "): min " << format_us(m.rotation.min)
           << " / median " << format_us(m.rotation.median) << " / max " << format_us(m.rotation.max)
           << " us = " << m.rotation.min / bit << " / " << m.rotation.median / bit << " / "
           << m.rotation.max / bit << " bit times\n";
      }
      const auto& p = m.polls;
      os << "    polls: " << p.requests << " requests, " << p.ok << " ok, " << p.no_response
         << " no response, " << p.sent << " sent (SDN), " << p.retries << " retries\n";
    }
    for (const auto& s : l.stations) {
      os << "  station " << static_cast<int>(s.address) << ": " << s.requests << " requests, "
         << s.replies << " replies, " << s.fdl_status << " FDL status, " << s.cycles
         << " data cycles";
      if (s.tsyn_drops) os << ", " << s.tsyn_drops << " dropped (TSYN)";
      os << "\n";
    }
    const auto& t = l.traffic;
    os << "  frames: " << t.frames << " (" << t.octets << " octets):";
    for (std::size_t i = 0; i < LineStats::kTypes; ++i) os << " " << kTypeNames[i] << " " << t.by_type[i];
    if (t.garbage) os << " garbage " << t.garbage;
    os << "\n  requests:";
    bool any = false;
    for (std::size_t fn = 0; fn < t.requests_by_fn.size(); ++fn) {
      if (t.requests_by_fn[fn] == 0) continue;
      os << " " << fdl::to_string(static_cast<fdl::RequestFn>(fn)) << " " << t.requests_by_fn[fn];
      any = true;
    }
    if (!any) os << " none";
    os << "; responses " << t.responses << "\n";
    os << "  errors: " << t.error_frames() << " frames (collisions " << t.collisions
       << ", parity " << t.parity << ", bad FCS " << t.bad_fcs << ", malformed " << t.malformed
       << ", partial " << t.partial << ", babble " << t.babble << "); on the wire: no response "
       << t.no_response << ", retries " << t.repeats << ", requests after less than TSYN idle "
       << t.short_idle << "; dropped by the stations (TSYN) " << l.tsyn_drops << "\n";
    for (const auto& f : t.faults) os << "  fault at " << bus::format_duration(f.time) << ": " << f.text << "\n";
  }
  write_dp_text(r.dp_masters, os);
  write_dp_slaves_text(r.dp_slaves, os);
  write_redundancy_text(r.redundancy, os);
  write_h_text(r.h_systems, os);
  write_gateways_text(r.gateways, os);
  write_s7_text(r.s7, os);
  write_quantum_text(r.quantum, os);
  for (const auto& f : r.faults_not_reached) os << "not reached before the end: " << f << "\n";
}

void write_json(const Report& r, std::ostream& os) {
  os << "{\"schema\":\"pbvbus.run.report/1\",\n";
  os << "\"scenario\":{\"name\":" << json_quote(r.name) << ",\"file\":" << json_quote(r.file)
     << ",\"seed\":" << r.seed << "},\n";
  os << "\"duration_ns\":" << bus::ticks_to_ns(r.duration) << ",\"wall_time_s\":"
     << fixed(r.wall_seconds, 6) << ",\"speed\":"
     << fixed(r.wall_seconds > 0 ? static_cast<double>(r.duration) / bus::kTicksPerSecond / r.wall_seconds : 0.0, 3)
     << ",\"events\":" << r.events << ",\n";
  os << "\"serial\":[";
  for (std::size_t i = 0; i < r.serial.size(); ++i) {
    const auto& s = r.serial[i];
    const auto bit = bus::ticks_per_bit(s.baud);
    const auto& st = s.stats;
    os << (i ? ",\n " : "") << "{\"line\":" << json_quote(s.line) << ",\"mode\":" << json_quote(s.mode)
       << ",\"path\":" << json_quote(s.path) << ",\"link\":" << json_quote(s.link)
       << ",\"address\":" << (s.address ? std::to_string(*s.address) : std::string("null"))
       << ",\"timing\":" << json_quote(s.timing) << ",\"frames_in\":" << st.frames_in
       << ",\"octets_in\":" << st.bytes_in << ",\"octets_sent\":" << st.octets_sent
       << ",\"frames_out\":" << st.frames_out << ",\"octets_out\":" << st.bytes_out
       << ",\"frames_dropped\":" << st.frames_dropped << ",\"garbage\":" << st.garbage_bytes
       << ",\"abandoned\":" << st.abandoned << ",\"held\":" << st.held
       << ",\"hold_total_ns\":" << bus::ticks_to_ns(st.hold_total)
       << ",\"hold_max_ns\":" << bus::ticks_to_ns(st.hold_max)
       << ",\"hold_total_bits\":" << st.hold_total / bit << ",\"hold_max_bits\":" << st.hold_max / bit
       << ",\"queue_max\":" << st.queue_max << ",\"discarded\":" << st.discarded
       << ",\"dropped_full\":" << st.dropped_full << ",\"dropped_stale\":" << st.dropped_stale
       << ",\"dropped_closed\":" << st.dropped_closed
       << ",\"frames_no_program\":" << st.frames_no_program
       << ",\"program_opens\":" << st.program_opens << ",\"program_closes\":" << st.program_closes
       << ",\"address_changes\":" << st.address_changes
       << ",\"receivers_tsyn_drops\":" << s.receivers_tsyn_drops << "}";
  }
  os << "],\n\"faults_not_reached\":[";
  for (std::size_t i = 0; i < r.faults_not_reached.size(); ++i)
    os << (i ? "," : "") << json_quote(r.faults_not_reached[i]);
  os << "],\n\"lines\":[";
  for (std::size_t li = 0; li < r.lines.size(); ++li) {
    const auto& l = r.lines[li];
    const auto bit = bus::ticks_per_bit(l.baud);
    const auto& p = l.params;
    os << (li ? ",\n" : "\n") << "{\"name\":" << json_quote(l.name)
       << ",\"probe\":" << (l.probe.empty() ? std::string("null") : json_quote(l.probe))
       << ",\"baud\":" << static_cast<std::uint32_t>(l.baud) << ",\n \"bus_params\":{\"tsl\":"
       << p.tsl << ",\"min_tsdr\":" << p.min_tsdr << ",\"max_tsdr\":" << p.max_tsdr
       << ",\"tqui\":" << p.tqui << ",\"tset\":" << p.tset << ",\"ttr\":" << p.ttr
       << ",\"gap_factor\":" << p.gap_factor << ",\"hsa\":" << static_cast<int>(p.hsa)
       << ",\"max_retry\":" << static_cast<int>(p.max_retry) << "},\n \"live_list\":[";
    for (std::size_t i = 0; i < l.live.size(); ++i)
      os << (i ? "," : "") << "{\"address\":" << static_cast<int>(l.live[i].address)
         << ",\"type\":\"" << live_type_key(l.live[i].type) << "\"}";
    const auto& t = l.traffic;
    os << "],\n \"frames\":{\"total\":" << t.frames << ",\"octets\":" << t.octets;
    for (std::size_t i = 0; i < LineStats::kTypes; ++i) os << ",\"" << kTypeNames[i] << "\":" << t.by_type[i];
    os << ",\"garbage\":" << t.garbage << ",\"responses\":" << t.responses << "},\n \"requests\":{";
    bool first = true;
    for (std::size_t fn = 0; fn < t.requests_by_fn.size(); ++fn) {
      if (t.requests_by_fn[fn] == 0) continue;
      os << (first ? "" : ",") << json_quote(fdl::to_string(static_cast<fdl::RequestFn>(fn)))
         << ":" << t.requests_by_fn[fn];
      first = false;
    }
    os << "},\n \"errors\":{\"error_frames\":" << t.error_frames() << ",\"collisions\":" << t.collisions
       << ",\"parity\":" << t.parity << ",\"bad_fcs\":" << t.bad_fcs << ",\"malformed\":"
       << t.malformed << ",\"partial\":" << t.partial << ",\"babble\":" << t.babble
       << ",\"no_response\":" << t.no_response << ",\"retries\":" << t.repeats
       << ",\"short_idle\":" << t.short_idle << ",\"tsyn_drops\":" << l.tsyn_drops
       << "},\n \"faults\":[";
    for (std::size_t i = 0; i < t.faults.size(); ++i)
      os << (i ? "," : "") << "{\"time_ns\":" << bus::ticks_to_ns(t.faults[i].time)
         << ",\"text\":" << json_quote(t.faults[i].text) << "}";
    os << "],\n \"masters\":[";
    for (std::size_t i = 0; i < l.masters.size(); ++i) {
      const auto& m = l.masters[i];
      const auto& ro = m.rotation;
      os << (i ? ",\n  " : "\n  ") << "{\"address\":" << static_cast<int>(m.address)
         << ",\"state\":" << json_quote(m.state) << ",\"in_ring\":" << (m.in_ring ? "true" : "false")
         << ",\"las\":[";
      for (std::size_t k = 0; k < m.las.size(); ++k) os << (k ? "," : "") << static_cast<int>(m.las[k]);
      os << "],\"tokens_received\":" << m.tokens_received << ",\"tokens_passed\":" << m.tokens_passed
         << ",\"token_pass_retries\":" << m.token_pass_retries << ",\"stations_dropped\":"
         << m.stations_dropped << ",\"token_losses\":" << m.token_losses << ",\"admissions\":"
         << m.admissions << ",\"duplicate_tokens\":" << m.duplicate_tokens << ",\"gap_polls\":"
         << m.gap_polls << ",\"rotation\":{\"count\":" << ro.count
         << ",\"min_ns\":" << bus::ticks_to_ns(ro.min) << ",\"median_ns\":" << bus::ticks_to_ns(ro.median)
         << ",\"max_ns\":" << bus::ticks_to_ns(ro.max) << ",\"min_bits\":" << ro.min / bit
         << ",\"median_bits\":" << ro.median / bit << ",\"max_bits\":" << ro.max / bit
         << "},\"polls\":{\"requests\":" << m.polls.requests << ",\"ok\":" << m.polls.ok
         << ",\"no_response\":" << m.polls.no_response << ",\"sent\":" << m.polls.sent
         << ",\"retries\":" << m.polls.retries << ",\"data_octets\":" << m.polls.data_octets << "}}";
    }
    os << "],\n \"stations\":[";
    for (std::size_t i = 0; i < l.stations.size(); ++i) {
      const auto& s = l.stations[i];
      os << (i ? "," : "") << "{\"address\":" << static_cast<int>(s.address)
         << ",\"requests\":" << s.requests << ",\"replies\":" << s.replies
         << ",\"fdl_status\":" << s.fdl_status << ",\"cycles\":" << s.cycles
         << ",\"tsyn_drops\":" << s.tsyn_drops << "}";
    }
    os << "]}";
  }
  os << "]";
  write_dp_json(r.dp_masters, os);
  write_dp_slaves_json(r.dp_slaves, os);
  write_redundancy_json(r.redundancy, os);
  write_h_json(r.h_systems, os);
  write_gateways_json(r.gateways, os);
  write_s7_json(r.s7, os);
  write_quantum_json(r.quantum, os);
  os << "}\n";
}

}  // namespace pbvbus::tools
