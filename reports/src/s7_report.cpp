// Text and JSON of the S7 part of the run report (simulation/s7_report.hpp has the schema).
#include "pbvbus/reports/s7_report.hpp"

#include <ostream>

#include "pbvbus/reports/json_text.hpp"

namespace pbvbus::tools {

namespace {
std::string s7_ms(bus::Ticks t) { return format_us(t / 1000) + " ms"; }
}  // namespace

void write_s7_text(const S7Report& r, std::ostream& os) {
  for (const S7CpuReport& c : r.cpus) {
    os << "\nS7 CPU " << c.name;
    if (c.mpi_address) os << " (MPI " << static_cast<int>(*c.mpi_address) << ")";
    os << ": " << c.accepted << " MPI connections accepted, " << c.refused << " refused, " << c.open
       << " open; " << c.pdus_received << " S7 PDUs in, " << c.pdus_sent << " out; "
       << c.dp_exchanges << " DP image exchanges";
    if (c.unmapped_bytes != 0) os << ", " << c.unmapped_bytes << " slave I/O bytes outside I/Q";
    os << "\n";
  }
  for (const MpiStationReport& s : r.stations) {
    os << "\n" << (s.op ? "OP " : "PG ") << static_cast<int>(s.address) << " on " << s.line << ": "
       << s.connects << " connects, " << s.breaks << " broken, " << s.refused << " refused";
    for (const auto& [why, n] : s.broken) os << ", " << why << " " << n;
    os << "\n";
    for (const S7ReadReport& rd : s.reads) {
      os << "  read " << rd.item << " from CPU " << static_cast<int>(rd.cpu) << ": " << rd.requests
         << " requests, " << rd.ok << " ok, " << rd.errors << " errors";
      if (rd.errors != 0) os << " (last code " << hex_octets(std::span(&rd.last_code, 1)) << ")";
      if (rd.ok != 0)
        os << "; last value " << hex_octets(rd.last_value) << ", latency last " << s7_ms(rd.last_latency)
           << ", max " << s7_ms(rd.max_latency);
      os << "\n";
    }
  }
  for (const S7DoorReport& d : r.doors) {
    os << "\nS7 door " << d.name << " " << d.listen;
    if (d.port == 0) {
      os << ": not open (the run was not paced)\n";
      continue;
    }
    os << " (port " << d.port << "): " << d.clients << " clients, " << d.connects << " connects ("
       << d.connects_refused << " refused), " << d.jobs << " jobs, " << d.answers << " answers, "
       << d.routes_closed << " routes closed";
    if (d.closed_garbage + d.closed_stalled + d.closed_idle + d.closed_queue_full != 0)
      os << "; closed: " << d.closed_garbage << " garbage, " << d.closed_stalled << " stalled, "
         << d.closed_idle << " idle, " << d.closed_queue_full << " queue full";
    os << "\n";
  }
}

void write_s7_json(const S7Report& r, std::ostream& os) {
  if (r.empty()) return;
  os << ",\n\"s7\":{\"cpus\":[";
  for (std::size_t i = 0; i < r.cpus.size(); ++i) {
    const S7CpuReport& c = r.cpus[i];
    os << (i ? "," : "") << "{\"name\":" << json_quote(c.name) << ",\"mpi_address\":";
    if (c.mpi_address) os << static_cast<int>(*c.mpi_address);
    else os << "null";
    os << ",\"connections_accepted\":" << c.accepted << ",\"connections_refused\":" << c.refused
       << ",\"connections_open\":" << c.open << ",\"pdus_received\":" << c.pdus_received
       << ",\"pdus_sent\":" << c.pdus_sent << ",\"dp_exchanges\":" << c.dp_exchanges
       << ",\"unmapped_bytes\":" << c.unmapped_bytes << "}";
  }
  os << "],\"stations\":[";
  for (std::size_t i = 0; i < r.stations.size(); ++i) {
    const MpiStationReport& s = r.stations[i];
    os << (i ? "," : "") << "{\"role\":\"" << (s.op ? "OP" : "PG") << "\",\"line\":"
       << json_quote(s.line) << ",\"address\":" << static_cast<int>(s.address)
       << ",\"connects\":" << s.connects << ",\"breaks\":" << s.breaks
       << ",\"refused\":" << s.refused << ",\"broken\":{";
    bool first = true;
    for (const auto& [why, n] : s.broken) {
      os << (first ? "" : ",") << json_quote(why) << ":" << n;
      first = false;
    }
    os << "},\"reads\":[";
    for (std::size_t k = 0; k < s.reads.size(); ++k) {
      const S7ReadReport& rd = s.reads[k];
      os << (k ? "," : "") << "{\"cpu\":" << static_cast<int>(rd.cpu) << ",\"item\":"
         << json_quote(rd.item) << ",\"requests\":" << rd.requests << ",\"ok\":" << rd.ok
         << ",\"errors\":" << rd.errors << ",\"last_code\":" << static_cast<int>(rd.last_code)
         << ",\"last_value\":" << json_quote(hex_octets(rd.last_value))
         << ",\"last_latency_ns\":" << bus::ticks_to_ns(rd.last_latency)
         << ",\"max_latency_ns\":" << bus::ticks_to_ns(rd.max_latency) << "}";
    }
    os << "]}";
  }
  os << "],\"doors\":[";
  for (std::size_t i = 0; i < r.doors.size(); ++i) {
    const S7DoorReport& d = r.doors[i];
    os << (i ? "," : "") << "{\"name\":" << json_quote(d.name) << ",\"listen\":" << json_quote(d.listen)
       << ",\"port\":" << d.port << ",\"clients\":" << d.clients << ",\"connects\":" << d.connects
       << ",\"connects_refused\":" << d.connects_refused << ",\"routes_closed\":" << d.routes_closed
       << ",\"jobs\":" << d.jobs << ",\"answers\":" << d.answers
       << ",\"closed_garbage\":" << d.closed_garbage << ",\"closed_stalled\":" << d.closed_stalled
       << ",\"closed_idle\":" << d.closed_idle << ",\"closed_queue_full\":" << d.closed_queue_full
       << "}";
  }
  os << "]}";
}

}  // namespace pbvbus::tools
