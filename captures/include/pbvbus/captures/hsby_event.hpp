#pragma once
// The Quantum Hot Standby pair's events in a capture (EventCategory::Hsby; docs/quantum-hsby.md
// "Captures and timeline"). The captures layer sits below controllers/quantum, so the fields are
// plain numbers here; their meaning is that of quantum::PairEvent (quantum/hsby_pair.hpp), and
// simulation/src/quantum_node.cpp checks with static_asserts that the numbers below match the
// quantum enums. The Lua dissector names them (pbevent.hsby.*).
//
// Record (event_record.hpp layout):
//   category = 7 (Hsby)
//   code     = kind (quantum::PairEventKind): 0 power, 1 key, 2 state, 3 switchover, 4 transfer
//              lost, 5 logic mismatch, 6 duplicate designation, 7 fibre, 8 update, 9 override,
//              10 CPU, 11 ignored
//   line     = -1 (a rack is not on a line; its DP master module is, and shows on the lane)
//   a        = rack (0/1); -1 = the pair or the fibre
//   b        = that rack's state after the event (quantum::CpuState): 0 off, 1 offline,
//              2 primary, 3 standby; -1 = none (a = -1)
//   value    = switchover (code 3): the takeover time in ns, from the failure or request to the
//              new primary's first scan start (quantum::SwitchoverRecord::takeover_ticks); 0 for
//              every other kind, and for a switchover the pair filed no record for (two
//              primaries meeting again, both units primary after a silent transfer)
//   text     = "<pair>: rack 0: primary -> offline (key Off Line)"; "<pair>: <text>" for a = -1
#include <cstdint>
#include <optional>
#include <string>

#include "pbvbus/captures/event_record.hpp"

namespace pbvbus::captures {

enum class HsbyEventKind : std::uint16_t {
  Power = 0,
  Key = 1,
  State = 2,
  Switchover = 3,
  TransferLost = 4,
  LogicMismatch = 5,
  DuplicateDesignation = 6,
  Fibre = 7,
  Update = 8,
  Override = 9,
  Cpu = 10,
  Ignored = 11,
};
inline constexpr std::uint16_t kHsbyEventKinds = 12;

/// A rack's state (b): the numbers of quantum::CpuState.
enum class HsbyRackState : std::int32_t { None = -1, Off = 0, Offline = 1, Primary = 2, Standby = 3 };
inline constexpr int kHsbyRackStates = 4;

struct HsbyEventFields {
  HsbyEventKind kind = HsbyEventKind::State;
  int rack = -1;
  int state = -1;  ///< HsbyRackState as a number (kept as read: may be outside the enum)
  std::uint64_t takeover_ns = 0;
  std::string text;
};

/// "power", "key", "state", "switchover", "transfer lost", "logic mismatch", "duplicate
/// designation", "fibre", "update", "override", "cpu", "ignored" (quantum's to_string); "kind N"
/// outside.
std::string hsby_kind_name(int kind);
/// "off", "offline", "primary", "standby"; "none" for -1; "state N" otherwise.
std::string hsby_state_name(int state);

/// The record for `f` (category Hsby, line -1, value = takeover_ns).
EventRecord hsby_event_record(const HsbyEventFields& f);
/// The fields of an Hsby record; nullopt for another category or a kind above 11.
std::optional<HsbyEventFields> hsby_event_fields(const EventRecord& r);

/// The pair's name in a record's text: the part before ": rack <rack>: " (rack >= 0) or before
/// the first ": " (rack -1); "" when the text names no pair that way.
std::string hsby_pair_name(const std::string& text, int rack);

}  // namespace pbvbus::captures
