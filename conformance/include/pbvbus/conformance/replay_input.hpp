#pragma once
// Replay input (docs/replay.md): one line of a pcapng capture read as the frames a replayer
// sends and the replies it compares with. Sans-I/O: bytes in, a ReplayInput out; never throws,
// never crashes on a broken file (tests/conformance/replay_parser_test.cpp, fuzz_pcapng).
//
// Decisions:
//  - A line is one USER0 (147) or PROFIBUS_DL (257) interface, chosen by name (`line`), default
//    the first one. Its baud is if_speed, which must be a PROFIBUS rate (else bad input: the
//    replay could not keep bit times). Event records (USER1) and other interfaces are ignored
//    (counted in `ignored_records`).
//  - Timestamps are frame STARTS (pcapng_writer.hpp and design.md "Captures": the start bit of
//    the first character), in ns. They are converted to ticks relative to the line's first
//    frame, rounded to the nearest whole bit time: the writer rounded the tick time down to
//    whole ns, which loses up to 3 ticks, and a bit time is at least 83 ns (12 Mbit/s), so the
//    nearest bit time is the recorded one whenever frames start on bit times (every pbvbus
//    capture; a hardware capture gets bit-time resolution, which is what replay compares in).
//    A frame's end is its start + 11 bit times per captured octet.
//  - A record is "unusable" (kept, with its reason, counted, never sent and never compared
//    with) when: its epb_flags have a link-layer error bit (kFlagErrorMask; reason = the
//    record's comment, else the bits), it was cut short (orig_len > captured length), the FDL
//    decoder rejects it (bad FCS, truncated, ...), or its timestamp is before the previous
//    frame's or more than kMaxSpanNs after the first frame.
//  - A reader error (a truncated last block, a wrong length) after some records does not throw
//    the records away: they are used and `read_error` says where reading stopped. A file that is
//    not pcapng, has no such line, or whose line has no usable frame is bad input
//    (build_replay_input returns nullopt with the reason).
//  - Roles: SD4 = token; SD1/SD2/SD3 with the FC request bit = request; SC and SD1/SD2/SD3
//    response FCs = response. A request expects a reply when its function does (SDA, SRD, FDL
//    Status, ...) and DA is not 127.
//  - Pairing: a response belongs to the frame just before it when that is a request expecting
//    a reply, not yet answered, the response starts within TSL bit times of the request's end,
//    and its SA/DA are the request's DA/SA (an SC carries none: it answers the last request).
//    An unusable record in that place (starting within TSL) is the request's reply, damaged:
//    that request is sent but not compared (`reply_unusable`).

#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "pbvbus/bus/time.hpp"

namespace pbvbus::conformance {

enum class ReplayRole : std::uint8_t { Token, Request, Response, Unusable };
const char* replay_role_name(ReplayRole r);

/// One record of the chosen line.
struct ReplayFrame {
  std::size_t record = 0;       ///< index of the record in the file (all interfaces counted)
  std::uint64_t offset = 0;     ///< file offset of its block
  std::int64_t ts_ns = 0;       ///< timestamp as recorded (frame start)
  bus::Ticks start = 0;         ///< start relative to the line's first frame
  bus::Ticks end = 0;           ///< start + 11 bit times per captured octet
  std::vector<std::uint8_t> bytes;
  ReplayRole role = ReplayRole::Unusable;
  std::string unusable_reason;  ///< set for Unusable
  // Decoded fields (usable frames only).
  std::uint8_t type = 0;        ///< first octet (SD1/SD2/SD3/SD4/SC)
  std::uint8_t da = 0, sa = 0, fc = 0;
  std::optional<std::uint8_t> dsap, ssap;
  std::size_t du_offset = 0;    ///< index of the DU's first octet in `bytes`
  std::size_t du_len = 0;
  bool expects_reply = false;   ///< a request whose function and DA call for a reply
  int reply = -1;               ///< requests: index (in ReplayInput::frames) of the reply
  int request = -1;             ///< responses and unusable replies: index of their request
  bool reply_unusable = false;  ///< requests: the recorded reply is damaged
};

struct ReplayInputOptions {
  std::string line;                    ///< interface name; "" = the first USER0/257 one
  std::optional<std::uint32_t> tsl;    ///< slot time in bit times; default: DP profile's
};

struct ReplayInput {
  std::string line;
  std::uint32_t interface = 0;
  bus::Baud baud = bus::Baud::k1_5M;
  std::uint32_t tsl = 0;               ///< the slot time used for pairing
  std::vector<ReplayFrame> frames;     ///< every record of the line, in file order
  std::size_t ignored_records = 0;     ///< records of other interfaces (events, other lines)
  std::string read_error;              ///< "" or where reading stopped ("offset N: ...")
  std::vector<std::string> lines;      ///< names of every USER0/257 interface

  std::size_t count(ReplayRole r) const;
  /// Requests that expect a reply and whose recorded reply is not damaged.
  std::size_t comparable_requests() const;
};

/// 2^50 ns ≈ 13 days: later timestamps are unusable (keeps tick arithmetic far from overflow).
inline constexpr std::int64_t kMaxSpanNs = std::int64_t{1} << 50;

/// Reads `data` (a whole pcapng file) as replay input. nullopt and `error` on bad input.
std::optional<ReplayInput> build_replay_input(std::span<const std::uint8_t> data,
                                              const ReplayInputOptions& opts, std::string& error);

/// DP service of a request, from its DSAP and frame: "Data_Exchange", "Set_Prm", "Chk_Cfg",
/// "Slave_Diag", "Global_Control", "Get_Cfg", "Rd_Inp", "Rd_Outp", "Set_Slave_Add",
/// "MSAC_C1", "Alarm_Ack", "MSAC_C2_Initiate", "MSAC_C2", "FDL_Status", "Token", "SDN", ...
std::string replay_service_name(const ReplayFrame& request);

}  // namespace pbvbus::conformance
