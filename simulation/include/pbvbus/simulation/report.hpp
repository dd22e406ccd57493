#pragma once
// The report at the end of `pbvbus run`: per line the live list, per master the token rotation
// times and ring counters, traffic by frame type and request function, errors and the faults
// applied. Written as text for people or as JSON for programs (--json).
//
// JSON schema "pbvbus.run.report/1" (stable: fields are only ever added; a change of meaning
// gets a new version). All times are integers: nanoseconds (`_ns`) of virtual time, or bit
// times (`_bits`) of the line's baud rate; wall-clock figures are the only floats.
//
//   { "schema": "pbvbus.run.report/1",
//     "scenario": { "name": str, "file": str, "seed": int },
//     "duration_ns": int,            // virtual time simulated
//     "wall_time_s": float, "speed": float,   // speed = virtual s / wall s
//     "events": int,                 // scheduler events run
//     "serial": [ { "line": str, "mode": "monitor"|"station", "path": str, "link": str,
//                   "address": int|null,              // the external station's (STATION)
//                   "timing": "interface"|"raw",
//                   "frames_in": int,                 // telegrams from the program put on the line
//                   "octets_in": int,                 // octets read from the program
//                   "octets_sent": int,               // octets of those telegrams
//                   "frames_out","octets_out": int,   // frames (octets) written to the program
//                   "frames_dropped": int,            // not written: the program did not read
//                   "garbage": int,                   // octets discarded (no start delimiter,
//                                                     // abandoned incomplete telegrams)
//                   "abandoned": int,                 // incomplete telegrams given up
//                   "held": int,                      // telegrams that went out later than
//                   "hold_total_ns","hold_max_ns": int,   // written, and by how much
//                   "hold_total_bits","hold_max_bits": int,
//                   "queue_max": int, "discarded": int,   // most waiting at once; lost unsent
//                   "dropped_full","dropped_stale","dropped_closed": int,  // dropped unsent:
//                                                     // queue full, too old, program closed
//                   "frames_no_program": int,         // for the program while none had it open
//                   "program_opens","program_closes": int, // the program's opens, last closes
//                   "address_changes": int,           // Set_Slave_Add the program acknowledged
//                   "receivers_tsyn_drops": int       // = the line's "tsyn_drops"
//                 } ],
//     "faults_not_reached": [ str ], // scheduled after the end of the run
//     "lines": [ {
//       "name": str,
//       "probe": str|null,   // "station 1": frames, errors and the wire's live list are what
//                            // an analyzer next to that station sees (the capture's default)
//       "baud": int,
//       "bus_params": { "tsl","min_tsdr","max_tsdr","tqui","tset","ttr","gap_factor","hsa",
//                       "max_retry": int },
//       "live_list": [ { "address": int, "type": "master_in_ring"|"master_ready"|
//                        "master_not_ready"|"slave" } ],          // ascending address
//       "frames": { "total","octets","SD1","SD2","SD3","SD4","SC","garbage","responses": int },
//       "requests": { "<function>": int },   // intact requests, e.g. "SRD_low", "FDL_Status"
//       "errors": { "error_frames","collisions","parity","bad_fcs","malformed","partial",
//                   "babble": int,
//                   "no_response": int,  // requests (not FDL Status) without a reply on the wire
//                   "retries": int,      // requests repeated on the wire (same octets again)
//                   "short_idle": int,   // requests/tokens after less than TSYN idle
//                   "tsyn_drops": int }, // requests the stations dropped for too short an idle
//                                        // time (sum of "stations" and "dp_slaves" below)
//       "faults": [ { "time_ns": int, "text": str } ],   // faults and repairs as applied
//       "masters": [ { "address": int, "state": str, "in_ring": bool, "las": [int],
//                      "tokens_received","tokens_passed","token_pass_retries",
//                      "stations_dropped","token_losses","admissions","duplicate_tokens",
//                      "gap_polls": int,
//                      "rotation": { "count": int, "min_ns","median_ns","max_ns": int,
//                                    "min_bits","median_bits","max_bits": int },
//                      "polls": { "requests","ok","no_response","sent","retries",
//                                 "data_octets": int } } ],
//       "stations": [ { "address": int, "requests","replies","fdl_status","cycles",
//                       "tsyn_drops": int } ]
//     } ],
//     "dp_masters": [ { "address": int, "line": str, "mode": "Operate"|"Clear"|"Stop"|"Offline",
//       "global_controls": int, "data_control_time_ms": int,
//       "equidistance": { "t_dp_ns","t_dp_bits","cycles","overruns","missed","max_lateness_ns",
//                         "max_lateness_bits","jitter_bits","on_time_intervals": int },
//                                    // only with equidistant_cycle (docs/dp-equidistance.md)
//       "slaves": [ { "address": int, "model": str, "modules": [str],
//                     "state": str,          // the master's view, e.g. "DataExchange"
//                     "slave_state": str,    // the slave's own, e.g. "Data_Exch"
//                     "diag": "hex octets", "diag_bits": [str],   // e.g. "Always_1"
//                     "input_len","output_len": int, "inputs","outputs": "hex octets",
//                     "cycle": { "count","min_ns","median_ns","max_ns","min_bits",
//                                "median_bits","max_bits": int },  // DP cycle time
//                     "data_exchanges","startups","diag_reads","failures","returns",
//                     "no_response","retries": int } ] } ],
//     "dp_slaves": [ {              // every DP slave, in line and cable order: its own view
//       "line": str, "address": int, "model": str, "gsd": str (resolved path), "modules": [str],
//       "master": int|null,         // its dp_master in the scenario; null: none in pbvbus
//       "state": "Power_On"|"Wait_Prm"|"Wait_Cfg"|"Data_Exch",
//       "owner": int|null,          // the master that parameterised (locked) it
//       "watchdog_ns": int|null,    // response monitoring set by the owner; null = off
//       "diag": "hex octets", "diag_bits": [str],   // the diagnosis it would send now
//       "input_len","output_len": int,
//       "inputs": "hex octets",     // sent in its last Data_Exchange reply
//       "outputs": "hex octets",    // received in its last accepted Data_Exchange
//       "requests": { "set_prm","chk_cfg","slave_diag","data_exchange","global_control",
//                     "get_cfg","rd_inp","rd_outp","set_slave_add","dpv1","other": int },
//       "refused": int,             // of those, answered RS
//       "prm_faults","cfg_faults","data_exch_entries","watchdog_expiries": int,
//       "fdl": { "requests","replies","repeats","fdl_status","dropped_errors",
//                "dropped_tsyn": int } } ],
//     "redundancy": [ {             // every redundant_master_system (docs/redundancy.md)
//       "name": str, "lines": [str, str], "masters": [int, int],
//       "t_tr_ns": [int, int], "recognition_ns": [int, int],   // the planner's (line A, B)
//       "system_bound_ns": [int, int],                        // a whole line lost (short)
//       "stations": [ { "address": int, "model": str, "modules": [str],
//                       "active": str|null,                   // the active channel's line
//                       "roles": [str, str],                  // interface A, B: "PRIMARY" ...
//                       "redundancy_lost","failed","outputs_held": bool,
//                       "outputs": "hex octets",              // the backplane
//                       "t_slave_um_ns": int|null, "bound_ns": [int, int] } ],
//       "events": [ { "time_ns": int, "ob": int, "code": "W#16#73A3"|null, "kind": str,
//                     "line": str, "station": int|null, "cause": str, "from": str|null } ],
//       "switchovers": [ { "station": int, "from": str|null, "to": str, "cause": str,
//                          "system_level": bool, "fault": str, "fault_ns": int,
//                          "commanded_ns": int, "fresh_ns": int|null,
//                          "measured_ns": int|null, "im_ns": int|null,  // the IM's drawn time (S5)
//                          "bound_ns": int, "exceeded": bool } ],
//       "exceeded": int } ],
//     "h_systems_run": [ {          // every simulated h_system (docs/h-scenarios.md, h_report.hpp)
//       "name","profile","system_mode": str,
//       "cpus": [ { "rack": int, "state","role","system_mode": str,
//                   "leds": { "mstr","rack0","rack1": bool, "redf": str, "ifm1f","ifm2f": bool,
//                             "busf": [str] },               // per driven DP master system
//                   "diag": [ { "time_ns","time_ms", "role": str, "code": int, "text": str } ],
//                   "timeline": [ { "time_ns","time_ms", "kind","change","state","role",
//                                   "system_mode","redf": str, "mstr": bool, "ob","code": int,
//                                   "reason": str } ] } ],
//       "faults": [ { "time_ns","time_ms", "text": str } ],
//       "io_map": [ { "station","module","in_addr","in_len","out_addr","out_len": int } ],
//       "io_events": [ { "time_ns","time_ms", "racks": [int], "ob","code": int, "text": str } ],
//       "updates": [ { "rack": int, "t1_*","t3_*","t4_*","t5_*", "completed": bool,
//                      "t_p15_window_*","planned_t_p15_*", "t_p15_verdict": str,
//                      "t_ph_window_*","planned_t_ph_*", "t_ph_verdict": str,
//                      "last_io_before_*","first_io_after_*" } ] } ],   // *_ns, *_ms; null
//     "gateways": [ ... ] }        // every gateway (docs/gateway-modbus.md): its doors' clients, requests,
//                                  // exceptions and CAN frames; fields in gateway_report.hpp
//
// A DP slave's "requests" count each request that reached its DP layer once, from any master
// (FCB repeats are answered by its FDL layer and counted under "fdl"."repeats"), so they match
// what a master counts as answered. The line's "live_list", "frames", "requests" and "errors"
// come from what was on the wire, whoever sent it (line_stats.hpp), merged with the live lists
// of the pbvbus masters.
//
// The DP cycle time of a slave is the time between the starts of two consecutive
// Data_Exchange requests to it (dp::MasterSlaveStats); its median is over the last 1024
// cycles, min and max over the whole run.
//
// Token rotation times are the real rotation times (TRR) the master measured at each token
// receipt over the whole run, so the maximum includes rotations disturbed by faults (a ring
// re-forming after a cut); the median is the figure for the undisturbed ring. A token loss is
// a TTO expiry, after which the master claims the token: "token_losses" counts both.

#include <cstdint>
#include <iosfwd>
#include <optional>
#include <string>
#include <vector>

#include "pbvbus/bus/pty_station.hpp"
#include "pbvbus/bus/time.hpp"
#include "pbvbus/fdl_traffic/fdl_poller.hpp"
#include "pbvbus/fdl/bus_params.hpp"
#include "pbvbus/simulation/dp_system.hpp"
#include "pbvbus/simulation/gateway_report.hpp"
#include "pbvbus/simulation/quantum_report.hpp"
#include "pbvbus/simulation/s7_report.hpp"
#include "pbvbus/simulation/line_stats.hpp"
#include "pbvbus/simulation/h_report.hpp"
#include "pbvbus/simulation/redundancy_system.hpp"

namespace pbvbus::tools {

struct RotationStats {
  std::uint64_t count = 0;
  bus::Ticks min = 0;
  bus::Ticks median = 0;
  bus::Ticks max = 0;
};
/// min/median/max of `samples` (the median of an even count is the lower middle value).
RotationStats rotation_stats(std::vector<bus::Ticks> samples);

struct MasterReport {
  std::uint8_t address = 0;
  std::string state;  ///< MAC state at the end, e.g. "Active_Idle"
  bool in_ring = false;
  std::vector<std::uint8_t> las;  ///< its list of active stations at the end
  std::uint64_t tokens_received = 0;
  std::uint64_t tokens_passed = 0;       ///< token frames sent, incl. repeats and claims
  std::uint64_t token_pass_retries = 0;  ///< token passes repeated (no activity from NS)
  std::uint64_t stations_dropped = 0;    ///< NS removed from the LAS after failed passes
  std::uint64_t token_losses = 0;        ///< token lost (TTO expired) and claimed
  std::uint64_t admissions = 0;          ///< masters admitted to the ring by this one
  std::uint64_t duplicate_tokens = 0;    ///< token dropped on hearing a second token holder
  std::uint64_t gap_polls = 0;
  RotationStats rotation;
  devices::PollStats polls;
};

struct StationReport {
  std::uint8_t address = 0;
  std::uint64_t requests = 0;
  std::uint64_t replies = 0;
  std::uint64_t fdl_status = 0;
  std::uint64_t cycles = 0;  ///< SRD answered with fresh data
  std::uint64_t tsyn_drops = 0;  ///< requests dropped after less than TSYN idle
};

struct LiveEntry {
  std::uint8_t address = 0;
  fdl::StationType type = fdl::StationType::Slave;
};

struct LineReport {
  std::string name;
  bus::Baud baud = bus::Baud::k1_5M;
  fdl::BusParams params;
  std::vector<LiveEntry> live;
  /// Where the statistics tap listens: "station 1" (a probe next to it, the same default as
  /// the capture), or "" for the whole line. Frame counts, errors, the wire's live list and
  /// its no-response/retry/short-idle counts are what reaches that point.
  std::string probe;
  LineStats traffic;  ///< a copy of the line's statistics tap
  std::uint64_t tsyn_drops = 0;  ///< requests the line's passive stations dropped (TSYN)
  std::vector<MasterReport> masters;
  std::vector<StationReport> stations;
};

struct SerialReport {
  std::string line;
  std::string mode;  ///< "monitor" or "station"
  std::string path;  ///< the pty, e.g. /dev/pts/7
  std::string link;  ///< the symlink to it, or ""
  std::optional<std::uint8_t> address;  ///< STATION: the external station's address
  std::string timing = "interface";     ///< "interface" or "raw"
  bus::Baud baud = bus::Baud::k1_5M;    ///< the line's, for bit times
  bus::PtyStation::Stats stats;         ///< as of the report
  std::uint64_t receivers_tsyn_drops = 0;  ///< the line's LineReport::tsyn_drops
};

struct Report {
  std::string name;
  std::string file;
  std::uint64_t seed = 0;
  bus::Ticks duration = 0;
  double wall_seconds = 0;
  std::uint64_t events = 0;
  std::vector<SerialReport> serial;
  std::vector<std::string> faults_not_reached;
  std::vector<LineReport> lines;
  std::vector<DpMasterReport> dp_masters;
  std::vector<DpSlaveView> dp_slaves;
  std::vector<RedundancyReport> redundancy;  ///< redundant master systems (docs/redundancy.md)
  std::vector<HSystemReport> h_systems;      ///< simulated H-system CPU pairs (docs/h-system.md)
  std::vector<GatewayReport> gateways;       ///< gateways (docs/gateway-modbus.md; gateway_report.hpp)
  S7Report s7;                               ///< S7 CPUs, PGs/OPs, S7 doors (s7_report.hpp)
  std::vector<QuantumReport> quantum;        ///< Quantum Hot Standby pairs (quantum_report.hpp)
};

/// "master_in_ring", "master_ready", "master_not_ready", "slave".
std::string_view live_type_key(fdl::StationType t);

// Text and JSON forms: pbvbus/reports/run_report.hpp.

}  // namespace pbvbus::tools
