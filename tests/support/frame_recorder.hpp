#pragma once
// A Tap that keeps copies of everything it sees (design.md "Taps"), for tests that assert the
// bytes on the wire and their timing in bit times.

#include <cstdint>
#include <string>
#include <vector>

#include "pbvbus/bus/tap.hpp"
#include "pbvbus/bus/time.hpp"

namespace pbvbus::test {

class FrameRecorder final : public bus::Tap {
 public:
  /// A TapFrame with its bytes copied (the span in TapFrame dies after on_frame()).
  struct Frame {
    const bus::Line* line = nullptr;
    std::vector<std::uint8_t> bytes;
    bus::Ticks start = 0;
    bus::Ticks end = 0;
    std::uint16_t flags = 0;
    std::uint16_t sender = 0;
    std::uint32_t sent_len = 0;
    bool intact() const { return flags == 0; }
  };

  void on_frame(const bus::TapFrame& f) override;
  void on_line_event(const bus::LineEvent& e) override;

  const std::vector<Frame>& frames() const { return m_frames; }
  std::size_t size() const { return m_frames.size(); }
  const Frame& frame(std::size_t i) const { return m_frames.at(i); }
  const std::vector<bus::LineEvent>& events() const { return m_events; }

  /// Bytes of frame i as "68 05 05 68 ..." (uppercase).
  std::string hex(std::size_t i) const;
  /// All frames' hex, one per element: handy for EXPECT_THAT(..., ElementsAre(...)).
  std::vector<std::string> hex_all() const;
  /// Idle bit times between the end of frame i-1 and the start of frame i, at the baud of frame
  /// i's line (frames on different lines are not comparable: throws std::logic_error). For i = 0
  /// it is the idle time since tick 0. Rounded down, like a UART counting whole idle bits.
  std::int64_t gap_bits(std::size_t i) const;
  /// Start and end of frame i in bit times of its line since tick 0.
  std::int64_t start_bits(std::size_t i) const;
  std::int64_t end_bits(std::size_t i) const;

  void clear() {
    m_frames.clear();
    m_events.clear();
  }

 private:
  std::vector<Frame> m_frames;
  std::vector<bus::LineEvent> m_events;
};

}  // namespace pbvbus::test
