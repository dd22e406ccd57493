#pragma once
// Observers of a line (design.md "Taps"): captures, statistics and tests subscribe here; no
// device or stack ever knows that it is being observed.
//
// Two kinds of tap (bus::Line::add_tap):
//  - a whole-line tap sees every transmission once, from its sender's side of the cable
//    (statistics, tests of the line model); TapFrame::probe is -1;
//  - a probe tap sits at one cable position and sees what an analyzer clipped onto the cable
//    there would see (captures); TapFrame::probe is that position. See line.hpp for exactly
//    what reaches a probe.
// Line events (faults and repairs) reach every tap once, whatever its kind or number of probes.

#include <cstdint>
#include <span>
#include <string_view>

#include "pbvbus/bus/frame_memo.hpp"
#include "pbvbus/bus/time.hpp"

namespace pbvbus::bus {

class Line;

/// A transmission as it went over the line (whole-line tap) or as it reached a probe, delivered at
/// its end (or, cut short, at the moment it ended for that tap).
struct TapFrame {
  const Line* line = nullptr;
  std::span<const std::uint8_t> bytes;  ///< octets as they were on the wire (after corruption)
  Ticks start = 0;                      ///< start bit of the first character
  Ticks end = 0;                        ///< end of the last character actually sent
  std::uint16_t flags = 0;              ///< RxFlag bits (collision, noise, partial, babble)
  std::uint16_t sender = 0;             ///< attachment index of the transmitter
  /// Cable position (attachment index) of the probe that saw it; -1 for a whole-line tap.
  std::int16_t probe = -1;
  std::uint32_t sent_len = 0;           ///< octets the transmitter intended to send
  /// The transmission's decoded-view slot, shared with its receivers (frame_memo.hpp); nullptr
  /// for frames that come from no line. Valid only during the call.
  FrameMemo* memo = nullptr;
};

enum class LineEventKind : std::uint8_t {
  CableCut,
  CableRepaired,
  ShortCircuit,
  ShortRepaired,
  NoiseOn,
  NoiseOff,
  PowerOff,
  PowerOn,
  TransceiverFailed,
  TransceiverRepaired,
  BabbleOn,
  BabbleOff,
};
std::string_view to_string(LineEventKind k);

/// A fault injected or repaired. `a`/`b` are attachment indices where they apply.
struct LineEvent {
  const Line* line = nullptr;
  Ticks time = 0;
  LineEventKind kind{};
  int a = -1;
  int b = -1;
  std::uint64_t value = 0;  ///< noise: bit errors per 10^9 bits
};

class Tap {
 public:
  virtual void on_frame(const TapFrame& f) = 0;
  virtual void on_line_event(const LineEvent&) {}

 protected:
  ~Tap() = default;
};

}  // namespace pbvbus::bus
