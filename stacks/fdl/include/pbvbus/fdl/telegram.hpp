#pragma once
// FDL telegram codec (IEC 61158-4-3 / EN 50170 vol. 2; reference: protocol-facts.md §B).
//
// decode() accepts exactly one whole frame and checks everything a receiver checks: start and
// end delimiters, LE = LEr within 4..249, FCS, address extension chains, reserved function and
// status codes, broadcast only with SDN. It never throws; errors are values with a reason.
// encode() picks SD1/SD2/SD3 by the rules of §B.1 and never produces an invalid frame: whatever
// it accepts, decode() accepts and returns the same fields.
//
// Canonical form. Every frame decode() accepts is re-encoded to the identical bytes by
// reencode() (checked by the fuzz target tests/fuzz and tests/stacks/fdl/telegram_mutation_parser_test),
// with one deliberate exception: within one extension chain (DAE or SAE) the receiver accepts
// the region/segment octet before or after the SAP octet, because the parsing rule of §B.2 is
// order-free ("read octets while bit 7 is set; the SAP is the octet with bit 6 = 0"), while the
// encoder always writes the segment first. Both orders carry the same fields and the same FCS.
// A chain holds at most one SAP and one segment octet, and must hold a SAP (§B.2: a DAE/SAE
// names a SAP); anything else is BadExtension.
//
// Decisions where the spec is silent: a token (SD4) to DA 127 is BroadcastNotSdn (a token is not
// an SDN); a token with the extension bit in DA or SA is BadExtension; SA 127 is
// BadSourceAddress in every frame type. An SD2 frame whose DU is exactly 8 octets (the SD3 case)
// is accepted: §B.1 says a receiver must accept all three formats.

#include <array>
#include <cstdint>
#include <optional>
#include <span>
#include <string_view>

namespace pbvbus::fdl {

inline constexpr std::uint8_t kSD1 = 0x10;  ///< no data
inline constexpr std::uint8_t kSD2 = 0x68;  ///< variable data length
inline constexpr std::uint8_t kSD3 = 0xA2;  ///< 8 data octets
inline constexpr std::uint8_t kSD4 = 0xDC;  ///< token
inline constexpr std::uint8_t kSC = 0xE5;   ///< short acknowledgement
inline constexpr std::uint8_t kED = 0x16;   ///< end delimiter
inline constexpr std::uint8_t kBroadcast = 127;
inline constexpr std::uint8_t kExt = 0x80;          ///< address/extension octet: another octet follows
inline constexpr std::uint8_t kExtSegment = 0x40;   ///< extension octet is a segment, not a SAP
inline constexpr std::size_t kMaxLe = 249;
inline constexpr std::size_t kMinLe = 4;
inline constexpr std::size_t kMaxDu = kMaxLe - 3;   ///< DU incl. extension octets
inline constexpr std::size_t kMaxFrame = kMaxLe + 6;

enum class FrameType : std::uint8_t { SD1, SD2, SD3, SD4, SC };
std::string_view to_string(FrameType t);

// --- Function code octet (§B.3) ---------------------------------------------------------------
enum class RequestFn : std::uint8_t {
  TimeEvent = 0x0,  ///< with bit 7 set: Clock Value (FC 0xC0)
  SdaLow = 0x3,
  SdnLow = 0x4,
  SdaHigh = 0x5,
  SdnHigh = 0x6,
  Msrd = 0x7,
  FdlStatus = 0x9,
  SrdLow = 0xC,
  SrdHigh = 0xD,
  Ident = 0xE,
  LsapStatus = 0xF,
};
enum class ResponseStatus : std::uint8_t {
  OK = 0x0,   ///< positive acknowledgement
  UE = 0x1,   ///< user error
  RR = 0x2,   ///< no resources
  RS = 0x3,   ///< SAP not activated
  DL = 0x8,   ///< response data low
  NR = 0x9,   ///< no response data
  DH = 0xA,   ///< response data high (DP: diagnosis pending)
  RDL = 0xC,  ///< data not received, response data low
  RDH = 0xD,  ///< data not received, response data high
};
enum class StationType : std::uint8_t {
  Slave = 0,
  MasterNotReady = 1,
  MasterReady = 2,  ///< ready to enter the logical token ring
  MasterInRing = 3,
};
inline constexpr std::uint8_t kFcRequest = 0x40;
inline constexpr std::uint8_t kFcFcb = 0x20;
inline constexpr std::uint8_t kFcFcv = 0x10;
inline constexpr std::uint8_t kFcClockValue = 0xC0;

constexpr bool fc_is_request(std::uint8_t fc) { return (fc & kFcRequest) != 0; }
constexpr RequestFn fc_request_fn(std::uint8_t fc) { return static_cast<RequestFn>(fc & 0x0F); }
constexpr ResponseStatus fc_status(std::uint8_t fc) { return static_cast<ResponseStatus>(fc & 0x0F); }
constexpr StationType fc_station_type(std::uint8_t fc) { return static_cast<StationType>((fc >> 4) & 3); }
constexpr bool fc_fcb(std::uint8_t fc) { return (fc & kFcFcb) != 0; }
constexpr bool fc_fcv(std::uint8_t fc) { return (fc & kFcFcv) != 0; }
constexpr std::uint8_t make_request_fc(RequestFn fn, bool fcv = false, bool fcb = false) {
  return static_cast<std::uint8_t>(kFcRequest | (fcb ? kFcFcb : 0) | (fcv ? kFcFcv : 0) |
                                   static_cast<std::uint8_t>(fn));
}
constexpr std::uint8_t make_response_fc(StationType st, ResponseStatus s) {
  return static_cast<std::uint8_t>((static_cast<std::uint8_t>(st) << 4) | static_cast<std::uint8_t>(s));
}
/// Whether a request function expects an acknowledgement or response (SDA, SRD, MSRD, status...).
constexpr bool fn_expects_reply(RequestFn fn) {
  return fn != RequestFn::SdnLow && fn != RequestFn::SdnHigh && fn != RequestFn::TimeEvent;
}
constexpr bool fn_is_high_priority(RequestFn fn) {
  return fn == RequestFn::SdaHigh || fn == RequestFn::SdnHigh || fn == RequestFn::SrdHigh;
}
/// Valid request function (not one of the reserved codes 1, 2, 8, A, B).
bool request_fn_valid(std::uint8_t fn);
/// Valid response status (OK, UE, RR, RS, DL, NR, DH, RDL, RDH).
bool response_status_valid(std::uint8_t status);
std::string_view to_string(RequestFn f);
std::string_view to_string(ResponseStatus s);
std::string_view to_string(StationType s);

// --- Decoded telegram -------------------------------------------------------------------------
/// A decoded telegram. `data` points into the buffer given to decode().
struct Telegram {
  FrameType type = FrameType::SC;
  std::uint8_t da = 0;  ///< destination address 0..127 (extension bit removed)
  std::uint8_t sa = 0;  ///< source address 0..126 (extension bit removed)
  std::uint8_t fc = 0;  ///< function code octet (0 for SD4 and SC)
  std::optional<std::uint8_t> dsap;        ///< destination SAP from the DAE chain
  std::optional<std::uint8_t> ssap;        ///< source SAP from the SAE chain
  std::optional<std::uint8_t> da_segment;  ///< region/segment octet in the DAE chain
  std::optional<std::uint8_t> sa_segment;  ///< region/segment octet in the SAE chain
  std::span<const std::uint8_t> data;      ///< DU after the extension octets

  bool is_request() const { return type != FrameType::SC && type != FrameType::SD4 && fc_is_request(fc); }
};

enum class DecodeError : std::uint8_t {
  None = 0,
  Empty,
  UnknownDelimiter,    ///< first octet is not SD1/SD2/SD3/SD4/SC
  Truncated,           ///< fewer octets than the frame type requires
  TrailingOctets,      ///< more octets than the frame holds
  LengthMismatch,      ///< SD2: LE != LEr
  LengthOutOfRange,    ///< SD2: LE outside 4..249
  BadSecondDelimiter,  ///< SD2: fourth octet not 0x68
  BadFcs,
  BadEndDelimiter,
  BadSourceAddress,    ///< SA = 127
  BadExtension,        ///< extension chain runs past the data, has no SAP or two SAPs
  ReservedFunction,    ///< request with a reserved function code or a bad bit 7
  ReservedStatus,      ///< response with a reserved status or bit 7 set
  BroadcastNotSdn,     ///< DA 127 with a function other than SDN / time event
};
std::string_view to_string(DecodeError e);

/// Decodes exactly one frame from `bytes`.
DecodeError decode(std::span<const std::uint8_t> bytes, Telegram& out);

/// Length of the frame that starts at bytes[0], judged from its header: 0 if more octets are
/// needed to tell, -1 if bytes[0] is no start delimiter or the SD2 header is inconsistent.
/// Used to split a raw byte stream (a serial port) into frames.
int frame_length(std::span<const std::uint8_t> bytes);

/// Sum of the octets mod 256 (the FDL frame check sequence).
std::uint8_t fcs(std::span<const std::uint8_t> bytes);

// --- Encoding ---------------------------------------------------------------------------------
/// A frame on the wire; fixed storage, no allocation.
struct Frame {
  std::array<std::uint8_t, kMaxFrame> buf{};
  std::uint16_t len = 0;
  std::span<const std::uint8_t> bytes() const { return {buf.data(), len}; }
  bool empty() const { return len == 0; }
};

/// What to put in a frame with an FC octet. SAPs, if present, go out as one DAE and one SAE
/// octet each (DP practice); a segment octet may precede each.
struct FrameSpec {
  std::uint8_t da = 0;
  std::uint8_t sa = 0;
  std::uint8_t fc = 0;
  std::optional<std::uint8_t> dsap;
  std::optional<std::uint8_t> ssap;
  std::optional<std::uint8_t> da_segment;
  std::optional<std::uint8_t> sa_segment;
  std::span<const std::uint8_t> data;
};

enum class EncodeError : std::uint8_t {
  None = 0,
  DataTooLong,     ///< more octets after FC than the frame type holds (SD2: DU > 246)
  BadAddress,      ///< DA > 127, SA > 126, or DA 127 with a function other than SDN / time event
  BadSap,          ///< SAP or segment > 63, or a segment without its SAP
  BadFunction,     ///< reserved request function, reserved response status, or a bad bit 7
  DataTooShort,    ///< fewer octets after FC than the frame type needs (SD3: 8, SD2: 1)
  WrongFrameType,  ///< encode_as() with SD4 or SC (use encode_token() / encode_sc())
};
std::string_view to_string(EncodeError e);

/// Encodes with the shortest legal frame type: SD1 if there is nothing after FC, SD3 if exactly
/// 8 octets follow FC (extensions + data), SD2 otherwise.
EncodeError encode(const FrameSpec& spec, Frame& out);
/// Encodes with a given type (SD1, SD2 or SD3); fails if the content does not fit that type.
EncodeError encode_as(FrameType type, const FrameSpec& spec, Frame& out);
/// A token frame. da and sa are masked to 7 bits; the caller keeps them below 127.
Frame encode_token(std::uint8_t da, std::uint8_t sa);
Frame encode_sc();

/// The FrameSpec that carries a decoded telegram's fields (its `data` points where t.data does).
FrameSpec to_spec(const Telegram& t);
/// Encodes a decoded telegram again in its own frame type, SD4 and SC included. For every frame
/// decode() accepts this gives the same bytes, except for the chain-order case described at the
/// top of this header.
EncodeError reencode(const Telegram& t, Frame& out);

}  // namespace pbvbus::fdl
