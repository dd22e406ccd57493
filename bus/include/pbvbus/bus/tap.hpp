#pragma once
// Observers of a line (design.md "Taps"): captures, statistics and tests subscribe here; no
// device or stack ever knows that it is being observed.

#include <cstdint>
#include <span>
#include <string_view>

#include "pbvbus/bus/time.hpp"

namespace pbvbus::bus {

class Line;

/// A transmission as it went over the line, delivered at its end.
struct TapFrame {
  const Line* line = nullptr;
  std::span<const std::uint8_t> bytes;  ///< octets as they were on the wire (after corruption)
  Ticks start = 0;                      ///< start bit of the first character
  Ticks end = 0;                        ///< end of the last character actually sent
  std::uint16_t flags = 0;              ///< RxFlag bits (collision, noise, partial, babble)
  std::uint16_t sender = 0;             ///< attachment index of the transmitter
  std::uint32_t sent_len = 0;           ///< octets the transmitter intended to send
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
