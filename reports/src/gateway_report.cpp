// Text and JSON of the gateways' report (gateway_report.hpp has the schema).
#include "pbvbus/reports/gateway_report.hpp"

#include <cstdio>
#include <ostream>

#include "pbvbus/reports/json_text.hpp"

namespace pbvbus::tools {

void write_gateways_text(const std::vector<GatewayReport>& r, std::ostream& os) {
  for (const GatewayReport& g : r) {
    os << "\ngateway " << g.name << " (" << g.served << ")\n";
    if (g.modbus) {
      os << "  modbus: " << g.modbus->requests << " requests, " << g.modbus->exceptions
         << " exceptions";
      for (const auto& [code, n] : g.modbus->exceptions_by_code) {
        char buf[8];
        std::snprintf(buf, sizeof buf, "0x%02X", code);
        os << ", " << buf << ": " << n;
      }
      os << "\n";
    }
    if (g.can) {
      const GatewayCanReport& c = *g.can;
      os << "  can: " << c.frames << " frames on the segment; sent " << c.tpdo << " TPDO, "
         << c.heartbeat << " heartbeat, " << c.bootup << " boot-up, " << c.emcy << " EMCY, "
         << c.sdo_sent << " SDO; received " << c.rpdo << " RPDO (" << c.rpdo_refused
         << " refused), " << c.nmt << " NMT (" << c.nmt_refused << " refused), " << c.sdo_received
         << " SDO (" << c.sdo_aborts << " aborts), " << c.ignored << " ignored, " << c.bad
         << " bad\n";
    }
    for (const GatewayDoorReport& d : g.doors) {
      // The link names the pty, the first part of `where` ("PTY HOST:PORT" for slcan).
      const auto sp = d.where.find(' ');
      os << "  " << d.kind << " " << d.where.substr(0, sp);
      if (!d.link.empty()) os << " (" << d.link << ")";
      if (sp != std::string::npos) os << d.where.substr(sp);
      if (!d.error.empty()) {
        os << ": not open: " << d.error << "\n";
        continue;
      }
      os << ": " << d.clients_total << " clients (" << d.clients << " now, "
         << d.clients_closed_bad << " closed bad";
      // Only when they happened: a door under pressure says so, a quiet one stays short.
      if (d.clients_refused != 0) os << ", " << d.clients_refused << " refused";
      if (d.clients_evicted != 0) os << ", " << d.clients_evicted << " evicted";
      if (d.accept_pauses != 0) os << ", " << d.accept_pauses << " accept pauses";
      os << ")";
      if (d.kind.rfind("modbus", 0) == 0)
        os << ", " << d.requests << " requests, " << d.exceptions << " exceptions, "
           << d.bad_frames << " bad frames";
      else
        os << ", frames " << d.frames_in << " in / " << d.frames_out << " out, " << d.errors
           << " errors, " << d.dropped << " dropped";
      os << "\n";
    }
  }
}

void write_gateways_json(const std::vector<GatewayReport>& r, std::ostream& os) {
  os << ",\"gateways\":[";
  for (std::size_t i = 0; i < r.size(); ++i) {
    const GatewayReport& g = r[i];
    if (i != 0) os << ",";
    os << "{\"name\":" << json_quote(g.name) << ",\"served\":" << json_quote(g.served)
       << ",\"modbus\":";
    if (g.modbus) {
      os << "{\"requests\":" << g.modbus->requests << ",\"exceptions\":" << g.modbus->exceptions
         << ",\"exceptions_by_code\":{";
      bool first = true;
      for (const auto& [code, n] : g.modbus->exceptions_by_code) {
        os << (first ? "" : ",") << "\"" << code << "\":" << n;
        first = false;
      }
      os << "}}";
    } else {
      os << "null";
    }
    os << ",\"can\":";
    if (g.can) {
      const GatewayCanReport& c = *g.can;
      os << "{\"frames\":" << c.frames << ",\"tpdo\":" << c.tpdo << ",\"heartbeat\":" << c.heartbeat
         << ",\"bootup\":" << c.bootup << ",\"emcy\":" << c.emcy << ",\"sdo_sent\":" << c.sdo_sent
         << ",\"rpdo\":" << c.rpdo << ",\"nmt\":" << c.nmt << ",\"sdo_received\":" << c.sdo_received
         << ",\"ignored\":" << c.ignored << ",\"bad\":" << c.bad
         << ",\"rpdo_refused\":" << c.rpdo_refused << ",\"nmt_refused\":" << c.nmt_refused
         << ",\"sdo_aborts\":" << c.sdo_aborts << "}";
    } else {
      os << "null";
    }
    os << ",\"doors\":[";
    for (std::size_t k = 0; k < g.doors.size(); ++k) {
      const GatewayDoorReport& d = g.doors[k];
      os << (k ? "," : "") << "{\"kind\":" << json_quote(d.kind) << ",\"where\":" << json_quote(d.where)
         << ",\"link\":" << json_quote(d.link) << ",\"error\":" << json_quote(d.error)
         << ",\"clients\":" << d.clients << ",\"clients_total\":" << d.clients_total
         << ",\"clients_closed_bad\":" << d.clients_closed_bad
         << ",\"clients_refused\":" << d.clients_refused
         << ",\"clients_evicted\":" << d.clients_evicted
         << ",\"accept_pauses\":" << d.accept_pauses << ",\"requests\":" << d.requests
         << ",\"exceptions\":" << d.exceptions << ",\"bad_frames\":" << d.bad_frames
         << ",\"frames_in\":" << d.frames_in << ",\"frames_out\":" << d.frames_out
         << ",\"errors\":" << d.errors << ",\"dropped\":" << d.dropped << "}";
    }
    os << "]}";
  }
  os << "]";
}

}  // namespace pbvbus::tools
