#pragma once
// The Quantum Hot Standby part of the run report (docs/quantum-hsby.md "Run report").
// JSON (inside pbvbus.run.report/1, added fields):
//
//   "quantum": [ {
//     "name": str, "cpu": str, "iec": bool,
//     "scan_time_ns": int, "scan_time_estimated": bool, "transfer_time_ns": int,
//     "transfer": { "every_scan": [ { "type": "0x"|"1x"|"3x"|"4x", "first": str, "count": int } ],
//                   "additional_slices": int,
//                   "non_transfer": { "first": str, "count": int } | null,
//                   "command_register": str },
//     "racks": [ { "rack": int, "designation": "A"|"B", "state": "off"|"offline"|"primary"|"standby",
//                  "key": "Off Line"|"Xfer"|"Run", "logic_checksum": int, "scans": int,
//                  "leds": { "ready","com_act","primary","com_err","standby": "off"|"on"|"blinking" },
//                  "dp_head": "off"|"passive"|"active"|"none" } ],     // 2 entries; none: no `dp`
//     "fibre": "ok"|"cut"|"Tx/Rx not crossed",
//     "transfers_completed","transfers_lost": int,
//     "switchovers": [ { "at_ns": int, "cause_ns": int, "cause": str, "from": int, "to": int,
//                        "takeover_ns": int, "takeover_scans": number,
//                        "modbus": [ { "port": int, "before": [int,int], "after": [int,int] } ] } ],
//     "modbus": [ { "port": int, "address": int, "swap": bool, "wiring": "shared"|"rack 0"|"rack 1",
//                   "addresses": [int, int],         // rack 0, rack 1 now (0: answers nothing)
//                   "doors": [str],                  // "modbus_tcp on 127.0.0.1:1502", "modbus_rtu on /dev/pts/4"
//                   "requests","exceptions","no_reply","conflicts": int } ],
//     "dp": { "line": str, "address": int, "takeovers": int, "resumed": int, "restarted": int } | null,
//     "events": [ { "at_ns": int, "rack": int, "kind": str, "text": str } ],
//     "faults": [ { "at_ns": int, "text": str } ] } ]
#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "pbvbus/bus/time.hpp"

namespace pbvbus::tools {

struct QuantumRackReport {
  int rack = 0;
  std::string designation, state, key;
  std::uint32_t logic_checksum = 0;
  std::uint64_t scans = 0;
  std::string ready, com_act, primary, com_err, standby;  ///< LEDs
  std::string dp_head;
};

struct QuantumModbusSwap {
  int port = 1;
  std::array<int, 2> before{}, after{};
};

struct QuantumSwitchoverReport {
  bus::Ticks at = 0, cause_at = 0;
  std::string cause;
  int from = -1, to = -1;
  bus::Ticks takeover = 0;
  double takeover_scans = 0;
  std::vector<QuantumModbusSwap> modbus;
};

struct QuantumTransferRange {
  std::string type, first;
  std::uint32_t count = 0;
};

struct QuantumPortReport {
  int port = 1;
  int address = 1;
  bool swap = true;
  std::string wiring;
  std::array<int, 2> addresses{};
  std::vector<std::string> doors;
  std::uint64_t requests = 0, exceptions = 0, no_reply = 0, conflicts = 0;
};

struct QuantumDpReport {
  std::string line;
  int address = 0;
  std::uint64_t takeovers = 0, resumed = 0, restarted = 0;
};

struct QuantumEventReport {
  bus::Ticks at = 0;
  int rack = -1;
  std::string kind, text;
};

struct QuantumReport {
  std::string name, cpu;
  bool iec = false;
  bus::Ticks scan_time = 0, transfer_time = 0;
  bool scan_time_estimated = false;
  std::vector<QuantumTransferRange> every_scan;
  std::size_t additional_slices = 0;
  std::optional<QuantumTransferRange> non_transfer;
  std::string command_register;
  std::array<QuantumRackReport, 2> racks;
  std::string fibre;
  std::uint64_t transfers_completed = 0, transfers_lost = 0;
  std::vector<QuantumSwitchoverReport> switchovers;
  std::vector<QuantumPortReport> modbus;
  std::optional<QuantumDpReport> dp;
  std::vector<QuantumEventReport> events;
  std::vector<std::pair<bus::Ticks, std::string>> faults;
};

}  // namespace pbvbus::tools
