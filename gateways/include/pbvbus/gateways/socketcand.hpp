#pragma once
// socketcand's ASCII protocol (linux-can/socketcand doc/protocol.md; tools-and-formats.md §2.3):
// the element splitter and command parser, the encoders, and one client's state machine
// (SocketcandSession). Pure: no I/O, no clock — the door (socketcand_door.hpp) feeds bytes in
// and writes what comes out; the fuzz target feeds anything.
//
// Decisions (also in docs/gateway-can-doors.md):
//  - An element is `< ... >`. Whitespace between elements is ignored; any other byte outside an
//    element starts a garbage run (up to the next '<'), answered at once with one
//    `< error ... >`; an element longer than kMaxElement (256) characters without its '>' is
//    answered the same way and discarded up to its '>'. Every further kMaxElement bytes of the
//    same garbage run or overlong element count as one more error, so an endless stream of
//    garbage is closed too: after kMaxConsecutiveErrors errors in a row with no valid command
//    between them, wants_close() turns true and the door closes the connection. An element
//    that parses but is not a valid command is an error too (counted in the same row). The rule
//    holds at every error, whatever the read boundaries: once wants_close() is true, feed()
//    reads nothing more, so the client gets exactly kMaxConsecutiveErrors error answers.
//  - States: greeted (after `< hi >`) → `< open CHANNEL >` → BCM mode → `< rawmode >` → raw
//    mode. `open` with another channel name than the door's is an error. Frames from the bus go
//    to the client only in raw mode.
//  - `< send ID DLC b0 .. >` is accepted after `open` (in BCM mode it is socketcand's
//    "send a single frame"; in raw mode a frame). ID: 1..8 hex digits, either case; it is
//    extended if it has 8 digits OR its value is > 0x7FF (python-can 4.1 sends `{:X}`, unpadded,
//    so extended 0x80 arrives as `< send 80 0  >`; §2.3). DLC: one digit 0..8, then exactly DLC
//    bytes of 1..2 hex digits each.
//  - `< echo >` → `< echo >` in every state. `< bcmmode >` in raw mode goes back to BCM mode
//    (`< ok >`). `< controlmode >`, `< statistics .. >`, `< isotpmode >` and the BCM commands
//    (add update delete filter subscribe unsubscribe) → `< error ... not supported >`.
//  - Pushed frames: `< frame ID SECS.USECS DATA >`, ID %03X / %08X, DATA upper-case hex without
//    spaces, time = the frame's virtual time. Each is PRECEDED by ONE SPACE: python-can 4.1
//    drops the character after the last complete element in its receive buffer (`[n + 1:]`), so
//    without a separator a frame split over two recv() calls loses its '<' and is discarded by
//    the client; a space after the frame instead would be left over as "Bad data" (a warning
//    on the client's stderr at every receive). Whitespace between elements is legal.
//  - `< hi >` and every `< ok >` are sent exactly, alone (python-can compares one recv(256)
//    with them); the door takes care not to coalesce frames with the rawmode `< ok >`.

#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "pbvbus/bus/time.hpp"
#include "pbvbus/gateways/can_frame.hpp"

namespace pbvbus::gateways::socketcand {

inline constexpr std::uint16_t kDefaultPort = 29536;
/// Longest element content kept; longer ones are discarded and answered with an error.
inline constexpr std::size_t kMaxElement = 256;
/// Errors in a row after which the connection is closed.
inline constexpr int kMaxConsecutiveErrors = 8;

inline constexpr std::string_view kHi = "< hi >";
inline constexpr std::string_view kOk = "< ok >";
inline constexpr std::string_view kEcho = "< echo >";

enum class Op : std::uint8_t {
  Open,         ///< `open NAME`, channel
  RawMode,      ///< `rawmode`
  BcmMode,      ///< `bcmmode`
  Send,         ///< `send ID DLC data..`, frame
  Echo,         ///< `echo`
  Unsupported,  ///< controlmode, statistics, isotpmode, BCM commands: word
};

struct Command {
  Op op = Op::Echo;
  std::string word;  ///< the command word (for Unsupported) or the channel name (for Open)
  CanFrame frame{};
};

struct Parsed {
  std::optional<Command> command;
  std::string error;
};

/// Parses an element's content, the text between '<' and '>'. Never throws.
Parsed parse_element(std::string_view content);

/// `< frame ID SECS.USECS DATA >` (without the leading space the session adds).
std::string encode_frame(const CanFrame& f, bus::Ticks t);
/// `< error TEXT >`.
std::string encode_error(std::string_view text);

/// One client of the socketcand door.
class SocketcandSession {
 public:
  enum class Mode : std::uint8_t { Greeted, Bcm, Raw };
  struct Stats {
    std::uint64_t elements = 0;   ///< complete elements handled
    std::uint64_t errors = 0;     ///< `< error >` answers (garbage runs and overlong included)
    std::uint64_t garbage = 0;    ///< of those, garbage runs and overlong elements
    std::uint64_t frames_in = 0;  ///< frames accepted from the client
  };

  explicit SocketcandSession(std::string channel = "can0") : m_channel(std::move(channel)) {}

  /// What the door sends on connect.
  static std::string greeting() { return std::string(kHi); }
  /// Feeds bytes from the client. Each reply element is appended to `replies` as its own
  /// string (the door may need to send `< ok >` alone); frames to send to `to_bus`. Stops at
  /// the error that makes wants_close() true; ignores everything once it is.
  void feed(std::string_view bytes, std::vector<std::string>& replies,
            std::vector<CanFrame>& to_bus);
  Mode mode() const { return m_mode; }
  /// The text for a frame from the bus (with its leading space), or nullopt unless raw mode.
  std::optional<std::string> frame_to_client(const CanFrame& f, bus::Ticks now) const;
  bool wants_close() const { return m_consecutive_errors >= kMaxConsecutiveErrors; }
  const Stats& stats() const { return m_stats; }

 private:
  void handle(std::string_view content, std::vector<std::string>& replies,
              std::vector<CanFrame>& to_bus);
  void error(std::string text, std::vector<std::string>& replies, bool garbage);

  std::string m_channel;
  Mode m_mode = Mode::Greeted;
  enum class Lex : std::uint8_t { Between, InElement, Garbage, Discarding } m_lex = Lex::Between;
  std::string m_element;
  std::size_t m_run = 0;  // bytes of the current garbage run / discarded element
  int m_consecutive_errors = 0;
  Stats m_stats;
};

}  // namespace pbvbus::gateways::socketcand
