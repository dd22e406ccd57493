#pragma once
// The S7 part of the run report (docs/mpi.md, docs/iso-on-tcp.md): CPUs, PGs/OPs and S7 doors.
// JSON (inside pbvbus.run.report/1, added fields):
//
//   "s7": {
//     "cpus": [ { "name": str, "mpi_address": int|null,   // X1 on MPI
//                 "connections_accepted","connections_refused","connections_open": int,
//                 "pdus_received","pdus_sent": int,       // S7 PDUs over MPI
//                 "dp_exchanges": int,                     // process-image exchanges with its DP masters
//                 "unmapped_bytes": int } ],               // slave I/O that did not fit I/Q
//     "stations": [ { "role": "PG"|"OP", "line": str, "address": int,
//                     "connects","breaks","refused": int,  // connect requests, broken or
//                                                           // closed connections, refusals
//                     "broken": { reason: int },            // broken or closed connections by
//                                                           // reason (mpi_station), those seen
//                     "reads": [ { "cpu": int, "item": str, "requests","ok","errors": int,
//                                  "last_code": int,            // return code of the last error
//                                  "last_value": str,           // hex, the last good answer
//                                  "last_latency_ns","max_latency_ns": int } ] } ],
//     "doors": [ { "name": str, "listen": str, "port": int,   // 0: not open (fast run)
//                  "clients","connects","connects_refused","routes_closed","jobs","answers",
//                  "closed_garbage","closed_stalled","closed_idle","closed_queue_full": int } ]
//   }
#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "pbvbus/bus/time.hpp"

namespace pbvbus::tools {

struct S7CpuReport {
  std::string name;
  std::optional<std::uint8_t> mpi_address;
  std::uint64_t accepted = 0, refused = 0, open = 0, pdus_received = 0, pdus_sent = 0;
  std::uint64_t dp_exchanges = 0;
  std::uint32_t unmapped_bytes = 0;
};

struct S7ReadReport {
  std::uint8_t cpu = 0;
  std::string item;
  std::uint64_t requests = 0, ok = 0, errors = 0;
  std::uint8_t last_code = 0;
  std::vector<std::uint8_t> last_value;
  bus::Ticks last_latency = 0, max_latency = 0;
};

struct MpiStationReport {
  bool op = false;
  std::string line;
  std::uint8_t address = 0;
  std::uint64_t connects = 0, breaks = 0, refused = 0;
  std::map<std::string, std::uint64_t> broken;
  std::vector<S7ReadReport> reads;
};

struct S7DoorReport {
  std::string name, listen;
  std::uint16_t port = 0;
  std::uint64_t clients = 0, connects = 0, connects_refused = 0, routes_closed = 0, jobs = 0,
                answers = 0, closed_garbage = 0, closed_stalled = 0, closed_idle = 0,
                closed_queue_full = 0;
};

struct S7Report {
  std::vector<S7CpuReport> cpus;
  std::vector<MpiStationReport> stations;
  std::vector<S7DoorReport> doors;
  bool empty() const { return cpus.empty() && stations.empty() && doors.empty(); }
};

}  // namespace pbvbus::tools
