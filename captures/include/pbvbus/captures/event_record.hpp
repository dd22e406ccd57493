#pragma once
// Event records of a capture (design.md "Captures": events on their own interface).
//
// Faults injected, station failures, switchovers and similar happenings that the wire does not
// carry go into the capture as packets on an interface named "events" with link type USER1
// (148). Each packet is one record; the layout is pbvbus's own and versioned so that the Lua
// dissector (captures/lua/pbvbus.lua) and PcapngReader can decode old captures:
//
//   offset size  field
//   0      1     version (kEventRecordVersion = 1)
//   1      1     category (EventCategory)
//   2      2     code (meaning per category; for Line: bus::LineEventKind)
//   4      4     line     (i32, Line::index(); -1 = not tied to a line)
//   8      4     a        (i32, station / attachment index; -1 = none)
//   12     4     b        (i32, second station / attachment; -1 = none)
//   16     8     value    (u64, e.g. noise rate, S7 event id W#16#73A3)
//   24     n     text     (UTF-8, not terminated, the rest of the packet)
//
// All multi-octet fields are little-endian (like the pcapng sections pbvbus writes), whatever
// the byte order of the section that carries them. A reader must accept records longer than
// the header it knows when the version is the same (text), and reject a newer version.

#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <string_view>

namespace pbvbus::captures {

inline constexpr std::uint8_t kEventRecordVersion = 1;
inline constexpr std::size_t kEventHeaderSize = 24;
/// Longest text written; longer texts are cut (at a UTF-8 character boundary).
inline constexpr std::size_t kEventMaxText = 1024;

enum class EventCategory : std::uint8_t {
  Line = 1,        ///< fault injected or repaired on a line; code = bus::LineEventKind
  Station = 2,     ///< DP slave / station state (failure, return); a = station address
  Master = 3,      ///< DP master state (Stop/Clear/Operate, master failure)
  Redundancy = 4,  ///< switchover, redundancy loss/return; value = S7 event id if any
  /// H-system CPU pair events (cpu_event.hpp has the encoding): code = kind (0 state, 1 role,
  /// 2 system mode, 3 OB), line = -1, a = rack, b = role after the event (0 none, 1 master,
  /// 2 standby), value = S7 event id (bits 0..15, W#16#....) | OB << 16 | reason << 24 |
  /// to << 32 | from << 40; text "CPU 0: STOP -> STARTUP".
  Cpu = 5,
  Note = 6,        ///< free text from a scenario or tool
  /// Quantum Hot Standby pair events (docs/quantum-hsby.md "Captures"): code = event kind
  /// (quantum::PairEventKind: 0 power, 1 key, 2 state, 3 switchover, 4 transfer lost, 5 logic
  /// mismatch, 6 duplicate designation, 7 fibre, 8 update, 9 override, 10 CPU, 11 ignored),
  /// line = -1, a = rack (-1 = the pair or the fibre), b = that rack's state after the event (0
  /// off, 1 offline, 2 primary, 3 standby; -1 none), value = a switchover's takeover time in
  /// ns; text "Quantum: rack 0: primary -> offline (...)".
  Hsby = 7,
};
std::string_view to_string(EventCategory c);

struct EventRecord {
  EventCategory category = EventCategory::Note;
  std::uint16_t code = 0;
  std::int32_t line = -1;
  std::int32_t a = -1;
  std::int32_t b = -1;
  std::uint64_t value = 0;
  std::string text;
};

/// Writes the record into `out` (which must hold kEventHeaderSize + min(text, kEventMaxText)
/// octets); returns the number of octets written.
std::size_t encode_event(const EventRecord& e, std::span<std::uint8_t> out);
/// Size encode_event() needs for `e`.
std::size_t encoded_event_size(const EventRecord& e);
/// The same for a header plus a text given separately (no EventRecord needed).
std::size_t encode_event(const EventRecord& header, std::string_view text,
                         std::span<std::uint8_t> out);

/// Decodes a record; nullopt with a reason in `error` if it is too short or of another version.
/// Unknown categories are kept as their number (later minor additions stay readable).
std::optional<EventRecord> decode_event(std::span<const std::uint8_t> bytes,
                                        std::string* error = nullptr);

}  // namespace pbvbus::captures
