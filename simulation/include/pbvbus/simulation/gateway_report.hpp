#pragma once
// The gateways' part of the run report (docs/gateway-modbus.md): per gateway its doors (clients, requests,
// exceptions, CAN frames) and its cores' counters. Plain data, so the report does not depend on
// the gateway layer's types (gateway_node.cpp fills it).
//
// JSON (inside "pbvbus.run.report/1", after "h_systems_run"):
//   "gateways": [ {
//     "name": str, "served": str,               // e.g. "dp_master 1 on PROFIBUS_DP_1"
//     "modbus": { "requests","exceptions": int,  // answered by the core (all doors)
//                 "exceptions_by_code": { "<code>": int } } | null,   // e.g. "11": 3
//     "can": { "frames": int,                   // frames on the virtual CAN segment
//              "tpdo","heartbeat","bootup","emcy","sdo_sent": int,   // sent by the gateway
//              "rpdo","nmt","sdo_received","ignored","bad",          // received
//              "rpdo_refused","nmt_refused","sdo_aborts": int } | null,
//     "doors": [ { "kind": "modbus_tcp"|"modbus_rtu"|"slcan"|"socketcand"|
//                          "socketcan",
//                  "where": str,                // "127.0.0.1:1502", a pty path, an interface;
//                                               // slcan: "PTY HOST:PORT" (one door, both)
//                  "link": str,                 // the pty's symlink ("" none)
//                  "error": str,                // why the door did not open ("" = it did)
//                  "clients": int,              // connections now
//                  "clients_total": int,        // connections accepted in the run
//                  "clients_closed_bad": int,   // closed for a violation, flood or stall
//                  "clients_refused": int,      // TCP: closed at once, the door was full
//                                               // (CAN doors; Modbus only with max_clients 0)
//                  "clients_evicted": int,      // Modbus TCP: closed to make room (longest idle)
//                  "accept_pauses": int,        // TCP: accept() failed (out of descriptors)
//                  "requests","exceptions": int,   // Modbus: well-framed requests, exception answers
//                  "bad_frames": int,           // Modbus: bad MBAP header / bad CRC / overlong
//                  "frames_in","frames_out": int,  // CAN: onto the segment / to clients
//                  "errors","dropped": int } ]  // CAN: error answers, frames dropped (full queue)
//   } ]
#include <cstdint>
#include <iosfwd>
#include <map>
#include <optional>
#include <string>
#include <vector>

namespace pbvbus::tools {

struct GatewayDoorReport {
  std::string kind;
  std::string where;
  std::string link;
  std::string error;
  std::uint64_t clients = 0;
  std::uint64_t clients_total = 0;
  std::uint64_t clients_closed_bad = 0;
  std::uint64_t clients_refused = 0;
  std::uint64_t clients_evicted = 0;
  std::uint64_t accept_pauses = 0;
  std::uint64_t requests = 0;
  std::uint64_t exceptions = 0;
  std::uint64_t bad_frames = 0;
  std::uint64_t frames_in = 0;
  std::uint64_t frames_out = 0;
  std::uint64_t errors = 0;
  std::uint64_t dropped = 0;
};

struct GatewayModbusReport {
  std::uint64_t requests = 0;
  std::uint64_t exceptions = 0;
  std::map<int, std::uint64_t> exceptions_by_code;
};

struct GatewayCanReport {
  std::uint64_t frames = 0;
  std::uint64_t tpdo = 0, heartbeat = 0, bootup = 0, emcy = 0, sdo_sent = 0;
  std::uint64_t rpdo = 0, nmt = 0, sdo_received = 0, ignored = 0, bad = 0;
  std::uint64_t rpdo_refused = 0, nmt_refused = 0, sdo_aborts = 0;
};

struct GatewayReport {
  std::string name;
  std::string served;
  std::optional<GatewayModbusReport> modbus;
  std::optional<GatewayCanReport> can;
  std::vector<GatewayDoorReport> doors;
};

// Text and JSON forms: pbvbus/reports/gateway_report.hpp.

}  // namespace pbvbus::tools
