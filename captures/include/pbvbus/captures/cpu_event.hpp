#pragma once
// The H-system CPU pair's events in a capture (EventCategory::Cpu; docs/h-system.md;
// docs/h-scenarios.md). The captures layer does not depend on devices/, so the fields are
// plain numbers here; their meaning is that of devices::HEvent (devices/h_cpu_pair.hpp), and
// tools/h_report.cpp (h_event_record) checks with static_asserts that the numbers below match
// the devices enums. The Lua dissector names them (pbevent.cpu.*).
//
// Record (event_record.hpp layout):
//   category = 5 (Cpu)
//   code     = kind: 0 state change, 1 role change, 2 system-mode change, 3 OB
//   line     = -1 (a CPU is not on a line)
//   a        = rack (0/1) of the CPU (system mode: the master's rack, 0 without one)
//   b        = the CPU's role after the event: 0 none, 1 master (primary), 2 standby (backup)
//   value    = bits  0..15 S7 event ID (W#16#....; 0 = none given)
//              bits 16..23 OB number (kind 3: 72, 121, ...)
//              bits 24..31 reason (kind 3: devices::HReason: 0 none, 1 master lost, 2 master
//                          STOP, 3 standby lost, 4 standby STOP, 5 link lost, 6 comparison
//                          error, 7 one-sided OB 121, 8 master/standby swap)
//              bits 32..39 "to": state (kind 0: devices::CpuState 0 OFF, 1 STOP, 2 STARTUP,
//                          3 RUN, 4 LINK-UP, 5 UPDATE, 6 HOLD, 7 ERROR-SEARCH, 8 DEFECTIVE,
//                          9 SYNCUP), role (kind 1) or system mode (kind 2:
//                          devices::SystemMode 0 Stop, 1 Startup, 2 Solo, 3 Link-up, 4 Update,
//                          5 Redundant, 6 Hold, 7 SYNCUP)
//              bits 40..47 "from": the same for the value before the event
//              bits 48..63 0
//   text     = the event in words, e.g. "CPU 0: STOP -> STARTUP", "CPU 1: OB 72 (master CPU lost)"
// Keeping the event ID in the low 16 bits keeps the existing rule "Cpu records carry the S7
// event id in the value" (the dissector's pbevent.s7 shows value & 0xFFFF for this category).
#include <cstdint>
#include <optional>
#include <string>

#include "pbvbus/captures/event_record.hpp"

namespace pbvbus::captures {

enum class CpuEventKind : std::uint16_t { State = 0, Role = 1, SystemMode = 2, Ob = 3 };

struct CpuEventFields {
  CpuEventKind kind = CpuEventKind::State;
  int rack = 0;
  int role = 0;
  std::uint16_t event_id = 0;
  std::uint8_t ob = 0;
  std::uint8_t reason = 0;
  std::uint8_t to = 0;
  std::uint8_t from = 0;
  std::string text;
};

/// Names of the numbers in the records (devices' to_string, S7-400H profile: the S7-1500R/H's
/// primary/backup are the same numbers as master/standby): "OFF", "STOP", ..., "LINK-UP",
/// "SYNCUP"; "none", "master", "standby"; "Stop", ..., "Redundant", "SYNCUP". A number outside
/// the enum gives "state N" / "role N" / "mode N".
std::string cpu_state_name(int state);
std::string cpu_role_name(int role);
std::string cpu_system_mode_name(int mode);

/// The record for `f` (category Cpu, line -1).
EventRecord cpu_event_record(const CpuEventFields& f);
/// The fields of a Cpu record; nullopt for another category or an unknown kind.
std::optional<CpuEventFields> cpu_event_fields(const EventRecord& r);

}  // namespace pbvbus::captures
