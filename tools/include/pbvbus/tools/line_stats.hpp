#pragma once
// Traffic statistics of one line, collected by a bus::Tap (design.md "Taps"): frames by
// telegram type (protocol-facts.md §B.1) and by request function (§B.3), tokens passed per
// master, error frames by cause, and the faults applied. Nothing here allocates per frame.
//
// Classification of a frame as the tap sees it:
//  - error flags from the line (collision, parity/framing, partial, babble) are counted by
//    cause; a frame may count under several causes;
//  - an unflagged frame that fdl::decode() rejects counts as "bad FCS" if that is the reason
//    and as "malformed" otherwise (never produced by our stations: a sign of an external
//    station through a pty, or of a bug);
//  - every frame whose first octet is a start delimiter counts under its type, even if damaged,
//    since that is what a bus analyser shows; frames that start with anything else count as
//    "garbage".

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "pbvbus/bus/tap.hpp"
#include "pbvbus/fdl/telegram.hpp"

namespace pbvbus::tools {

struct FaultRecord {
  bus::Ticks time = 0;
  std::string text;  ///< e.g. "cable cut between 'master 3' and 'slave 14'"
};

class LineStats final : public bus::Tap {
 public:
  static constexpr std::size_t kTypes = 5;  ///< SD1, SD2, SD3, SD4, SC (fdl::FrameType order)

  std::uint64_t frames = 0;
  std::uint64_t octets = 0;
  std::array<std::uint64_t, kTypes> by_type{};
  std::uint64_t garbage = 0;  ///< no start delimiter
  /// Intact requests by function code (index = fdl::RequestFn value, 0..15).
  std::array<std::uint64_t, 16> requests_by_fn{};
  std::uint64_t responses = 0;  ///< intact SD1/SD2/SD3 responses (not SC)
  // Errors by cause.
  std::uint64_t collisions = 0;
  std::uint64_t parity = 0;  ///< parity or framing error (noise)
  std::uint64_t bad_fcs = 0;
  std::uint64_t malformed = 0;
  std::uint64_t partial = 0;
  std::uint64_t babble = 0;
  /// Token frames sent, by source address (index 0..127).
  std::array<std::uint64_t, 128> tokens_by_sa{};
  std::vector<FaultRecord> faults;

  std::uint64_t error_frames() const { return m_error_frames; }

  void on_frame(const bus::TapFrame& f) override;
  void on_line_event(const bus::LineEvent& e) override;

 private:
  std::uint64_t m_error_frames = 0;
};

}  // namespace pbvbus::tools
