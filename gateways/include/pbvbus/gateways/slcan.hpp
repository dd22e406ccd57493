#pragma once
// SLCAN (Lawicel ASCII, CANUSB / CAN232 manuals; tools-and-formats.md §2.2): the command parser,
// the encoders, and one channel's state machine (SlcanSession). Pure: no I/O, no clock — the
// door (slcan_door.hpp) feeds bytes in and writes what comes out; the fuzz target feeds anything.
//
// Decisions (also in docs/gateway-can-doors.md):
//  - Lines end at '\r'. '\n' is ignored everywhere, so a terminal or `printf '...\r\n'` works.
//  - A line longer than kMaxLine (32; the longest valid command, an extended frame with 8 data
//    bytes, is 26) is discarded up to the next '\r' and answered with one '\a'; it is counted.
//  - An empty line (a bare '\r', which hosts send to flush the adapter) is answered '\r'.
//  - `O` / `L` while open are not errors (python-can 4.1 sends `O` twice): they switch the mode
//    and answer '\r'. `Sn` / `sxxyy` while open are errors ('\a'), as on the CANUSB.
//  - Frame sends (`t T r R`) while closed or listen-only are refused with '\a'; accepted ones are
//    answered `z\r` (standard) / `Z\r` (extended), as the CANUSB does.
//  - Hex digits are accepted in either case; frames are written in upper case.
//  - Bit rates: S0..S8 (Lawicel's table). python-can's non-standard S9 (83.3k) is refused with
//    '\a', which python-can ignores. The bit rate has no effect on the virtual segment.
//  - `V` → `V1013\r`, `v` → `v1013\r`, `N` → `N` + 4 characters of the door's serial number.
//  - `F` → `Fxx\r` with the door's current status flags (bit 3 "data overrun" once frames were
//    dropped for this client; reading clears it, as on the CANUSB).
//  - `Zn` (n 0/1), `Mxxxxxxxx`, `mxxxxxxxx`, `Xn`, `Qn`, `Un`, `P`, `A` are accepted and
//    answered '\r' (acceptance filters are not applied: the virtual segment is small).
//  - With `Z1`, each frame sent to the host ends with 4 hex digits: the frame's virtual time in
//    ms modulo 60000 (0000..EA5F).

#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "pbvbus/bus/time.hpp"
#include "pbvbus/gateways/can_frame.hpp"

namespace pbvbus::gateways::slcan {

/// Longest line kept (without '\r'); longer lines are discarded and answered '\a'.
inline constexpr std::size_t kMaxLine = 32;

inline constexpr std::string_view kOk = "\r";
inline constexpr std::string_view kError = "\a";
inline constexpr std::string_view kSentStandard = "z\r";
inline constexpr std::string_view kSentExtended = "Z\r";
inline constexpr std::string_view kVersion = "V1013\r";
inline constexpr std::string_view kSoftwareVersion = "v1013\r";

enum class Op : std::uint8_t {
  Empty,            ///< a bare '\r'
  SetBitrate,       ///< Sn, value = n (0..8)
  SetBtr,           ///< sxxyy, value = 0xXXYY
  Open,             ///< O
  ListenOnly,       ///< L
  Close,            ///< C
  Send,             ///< t / T / r / R, frame
  ReadFlags,        ///< F
  Version,          ///< V
  SoftwareVersion,  ///< v
  SerialNumber,     ///< N
  Timestamps,       ///< Zn, value = n (0/1)
  AcceptanceCode,   ///< Mxxxxxxxx, value
  AcceptanceMask,   ///< mxxxxxxxx, value
  AutoPoll,         ///< Xn (0/1)
  AutoStart,        ///< Qn (0..2)
  UartRate,         ///< Un (0..6)
  PollOne,          ///< P
  PollAll,          ///< A
};

struct Command {
  Op op = Op::Empty;
  std::uint32_t value = 0;
  CanFrame frame{};
};

/// The result of parsing one line: a command, or an error message (never both).
struct Parsed {
  std::optional<Command> command;
  std::string error;
};

/// Parses one line without its '\r' (and without '\n'). Never throws.
Parsed parse_line(std::string_view line);

/// A frame as the host receives it: `tIIILDD..`, `TIIIIIIIILDD..`, `rIIIL`, `RIIIIIIIIL`, plus
/// `%04X` of `timestamp_ms` when given, and '\r'.
std::string encode_frame(const CanFrame& f, std::optional<std::uint16_t> timestamp_ms = {});
/// The Z1 timestamp of a frame at virtual time `t`: ms modulo 60000.
std::uint16_t timestamp_ms(bus::Ticks t);
/// `Nxxxx\r`: the first 4 characters of `serial`, padded with '0'.
std::string serial_reply(std::string_view serial);
/// `Fxx\r`.
std::string flags_reply(std::uint8_t flags);

/// Status flag bits of `F` (Lawicel).
inline constexpr std::uint8_t kFlagDataOverrun = 0x08;

/// One SLCAN channel: a client connection's line buffer and CAN channel state.
class SlcanSession {
 public:
  struct Stats {
    std::uint64_t lines = 0;     ///< complete lines handled (overlong ones included)
    std::uint64_t errors = 0;    ///< lines answered '\a'
    std::uint64_t overlong = 0;  ///< of those, lines longer than kMaxLine
    std::uint64_t frames_in = 0; ///< frames accepted from the host
  };

  explicit SlcanSession(std::string serial = "PBV1") : m_serial(std::move(serial)) {}

  /// Feeds bytes from the host. Replies are appended to `reply`, frames to send on the bus to
  /// `to_bus`, in order.
  void feed(std::string_view bytes, std::string& reply, std::vector<CanFrame>& to_bus);

  bool is_open() const { return m_open; }
  bool listen_only() const { return m_listen_only; }
  bool timestamps() const { return m_timestamps; }
  /// The line for a frame from the bus, or nullopt while the channel is closed.
  std::optional<std::string> frame_to_host(const CanFrame& f, bus::Ticks now) const;
  /// Remembers that a frame for this host was dropped (shown by `F`).
  void note_overrun() { m_flags |= kFlagDataOverrun; }
  const Stats& stats() const { return m_stats; }

 private:
  void handle_line(std::string_view line, std::string& reply, std::vector<CanFrame>& to_bus);

  std::string m_serial;
  std::string m_line;
  bool m_discarding = false;  // inside an overlong line, until the next '\r'
  bool m_open = false;
  bool m_listen_only = false;
  bool m_timestamps = false;
  std::uint8_t m_flags = 0;
  Stats m_stats;
};

}  // namespace pbvbus::gateways::slcan
