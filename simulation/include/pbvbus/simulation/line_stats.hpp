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
//
// What the wire shows, whoever sent it (stations inside pbvbus or a program behind a pty), the
// way a bus analyser works it out (frames in the order they end):
//  - Live list (`heard`): a station that sends a token or a request is an active station
//    holding the token (master in the ring); a response frame gives its sender's station type
//    from its FC (protocol-facts.md §B.3); an SC answers the request just before it, so its DA
//    is live (as a slave unless known otherwise). A request or token that gets no reply, i.e.
//    the next frame on the line is not a response from its DA (an SC for a request, any frame
//    from the token's receiver), takes its DA off the list; a damaged next frame decides
//    nothing.
//  - `no_response`: requests expecting a reply (SDA, SRD, ... to one station) that got none,
//    each transmission counted, repeats included. Request FDL Status is left out: it is how
//    masters look for stations (GAP polls), and unanswered ones are normal.
//  - `repeats`: a request expecting a reply whose octets equal the previous such request of
//    the same sender (a retry: same FCB, protocol-facts.md §C.6).
//  - `short_idle`: intact requests and tokens that started less than TSYN (33 bit times) after
//    the end of the previous frame; receivers drop them (the stations count what they drop).

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "pbvbus/bus/tap.hpp"
#include "pbvbus/fdl/decoded_frame.hpp"
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
  // From the wire (see the header comment).
  std::uint64_t no_response = 0;
  std::uint64_t repeats = 0;
  std::uint64_t short_idle = 0;
  /// Live list by address: -1 not live, else the fdl::StationType value last shown.
  std::array<std::int8_t, 128> heard = make_unheard();
  std::vector<FaultRecord> faults;

  std::uint64_t error_frames() const { return m_error_frames; }

  void on_frame(const bus::TapFrame& f) override;
  void on_line_event(const bus::LineEvent& e) override;

 private:
  static std::array<std::int8_t, 128> make_unheard() {
    std::array<std::int8_t, 128> a{};
    a.fill(-1);
    return a;
  }
  void mark(std::uint8_t addr, fdl::StationType t, bool upgrade_only);
  /// The intact frame after a request or token (m_awaiting set): did its DA answer? (A
  /// damaged one decides nothing: on_frame() only clears m_awaiting.)
  void settle(const fdl::Telegram& frame);
  /// TSYN (33 bit times) of `line`, kept for the last line asked.
  bus::Ticks tsyn_of(const bus::Line& line);

  std::uint64_t m_error_frames = 0;
  // The request or token waiting for its reply.
  bool m_awaiting = false;
  bool m_await_token = false;
  bool m_await_counts = false;  ///< counts in no_response when unanswered
  std::uint8_t m_await_da = 0;
  // The last request expecting a reply, by sender: a hash of its octets (0 = none).
  std::array<std::uint64_t, 128> m_last_request{};
  const bus::Line* m_tsyn_line = nullptr;
  bus::Baud m_tsyn_baud{};
  bus::Ticks m_tsyn = 0;
  fdl::DecodedFrame m_scratch;  ///< decode_once()'s scratch (a frame without a memo)
  bus::Ticks m_last_end = -1;  ///< end of the previous frame (-1 = none yet)
};

}  // namespace pbvbus::tools
