#pragma once
// `pbvbus replay` (docs/replay.md): the capture's initiator frames are sent
// again to a target — the slaves of a scenario whose masters are left out, one station of it,
// or an outside slave behind a pty — and every reply is compared octet by octet with the
// recorded one. Sans-I/O: the Replayer is a bus::Device; the caller builds the line and runs the
// scheduler (fast) or the PacedRunner (a pty). Reading the capture: replay_input.hpp. Playing a
// capture raw into a serial port for an analyzer: replay_serial.hpp.
//
// Decisions:
//  - Targets. All stations (`station` empty): every token and request of the line is sent, so
//    the slaves see the traffic of the recorded masters. One station: only requests whose DA is
//    it, and broadcasts (Global_Control, ...); tokens and other traffic are skipped.
//  - Frames are sent verbatim (same octets: FCB/FCV toggle as recorded; a slave started from
//    power-on sees the same FCB history as in the recording).
//  - Pacing. AsRecorded: frame k goes out at power-on + TSYN + (its recorded start − the first
//    sent frame's recorded start). If then the line is busy (a frame on it, or less than TSYN
//    idle since the last one ended: a late or long reply) it waits for TSYN of idle line and
//    counts a pacing slip. Fast: the next frame goes out TSYN after the end of the previous
//    exchange: the reply's end, or (no reply) the request's end + TSL; TSYN after a frame that
//    expects no reply. In both, a request never starts while a frame is on the line.
//  - What is a reply: every frame heard between the end of a sent frame and the start of the
//    next sent frame (or the end of the run) belongs to the sent frame. The first is its reply,
//    any further one an "extra reply". Frames heard after a frame that expects no reply
//    (token, SDN) are extra replies too.
//  - Comparison, per sent request that expects a reply and whose recorded reply is usable
//    ("compared"): missing reply (recorded one, replayed none), extra reply (replayed one where
//    none was recorded, or a second frame), other FC (frame type or FC octet differs: SC vs a
//    data reply, DL vs RS, DL vs DH), other data (any other octet differs after masking: the
//    differing octet offsets are listed, frame offsets and DU offsets), timing (replayed reply
//    start − request end, in whole bit times, outside [min TSDR, max TSDR]). A reply can have
//    two differences (other data and timing); "matches" counts compared requests with none.
//  - Masks (ReplayMask) make octets of the DU compare as equal, by rule:
//      inputs       the DU of Data_Exchange replies and of Rd_Inp replies
//      diag-ext     Slave_Diag reply octets 7.. (DU offsets 6..; the extended diagnosis)
//      counter:A:O[-E]   Data_Exchange reply of station A, DU octets O..E (a life counter)
//      A:SAP:O[-E]  replies of station A to requests with DSAP SAP (`dx` = Data_Exchange, no
//                   SAP), DU octets O..E (0-based, inclusive; E defaults to O)
//    The FCS is not compared where a masked octet differs (it follows the DU). The report says
//    which masks were active and how many octets they hid.
//  - Report (ReplayReport): totals, the first `max_diffs` differences as aligned hex — recorded
//    above replayed, a marker line (^^) under differing octets and the field names (SD LE LEr
//    SD DA SA FC DSAP SSAP DU.. FCS ED) — with time, station and service. JSON schema
//    "pbvbus.replay/1":
//      { "schema": "pbvbus.replay/1", "line": str, "baud": int bit/s, "target": "all" | int,
//        "pacing": "as-recorded" | "fast",
//        "totals": { "recorded_frames": n, "requests_replayed": n (requests sent),
//                    "tokens_replayed": n, "compared": n, "matches": n, "differences": n,
//                    "by_kind": { "missing_reply": n, "extra_reply": n, "other_fc": n,
//                                 "other_data": n, "timing": n },
//                    "not_compared_reply_unusable": n, "unusable": n, "pacing_slips": n },
//        "tsdr_window": [min, max] (bit times),
//        "masks": [ { "rule": str, "octets_masked": n } ],
//        "unusable": [ { "record": n, "offset": n, "time_ns": n, "reason": str } ],
//        "read_error": str (only when reading stopped early),
//        "differences": [ { "kind": str, "time_ns": n (recorded start of the request,
//                           relative to the line's first frame), "station": n,
//                           "service": str, "request": hex, "recorded": hex|null,
//                           "replayed": hex|null, "frame_offsets": [n], "du_offsets": [n],
//                           "tsdr_bits": n|null } ]  (the first max_diffs only)
//      }
//  - Exit status (replay_exit_status): 0 no differences, 1 differences, 2 bad input (the CLI
//    returns 2 itself before any replay).

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "pbvbus/bus/device.hpp"
#include "pbvbus/bus/time.hpp"
#include "pbvbus/conformance/replay_input.hpp"

namespace pbvbus::conformance {

enum class ReplayPacing : std::uint8_t { AsRecorded, Fast };
const char* replay_pacing_name(ReplayPacing p);

struct ReplayerOptions {
  ReplayPacing pacing = ReplayPacing::Fast;
  std::optional<std::uint8_t> station;  ///< one station as target; nullopt = all stations
};

/// The frames of `in` a target gets (indices into in.frames), in order.
std::vector<std::size_t> replay_plan(const ReplayInput& in, std::optional<std::uint8_t> station);

class Replayer final : public bus::Device {
 public:
  struct Sent {
    std::size_t frame = 0;  ///< index into ReplayInput::frames
    bus::Ticks start = 0;
    bus::Ticks end = 0;
    bus::Ticks desired = 0;  ///< when pacing wanted it out
  };
  struct Heard {
    std::vector<std::uint8_t> bytes;
    bus::Ticks start = 0;
    bus::Ticks end = 0;
    std::uint16_t flags = 0;  ///< bus::RxFlag bits
  };

  /// `in` must outlive the Replayer.
  Replayer(const ReplayInput& in, ReplayerOptions opts);

  const std::vector<std::size_t>& plan() const { return m_plan; }
  const std::vector<Sent>& sent() const { return m_sent; }
  const std::vector<Heard>& heard() const { return m_heard; }
  std::uint64_t pacing_slips() const { return m_slips; }
  /// Every frame sent and the last one's reply window (TSL + a longest frame) over.
  bool finished() const { return m_finished; }
  const ReplayerOptions& options() const { return m_opts; }

  void on_power_on(bus::Ticks now) override;
  void on_power_off(bus::Ticks now) override;
  void on_frame(const bus::RxFrame& frame) override;
  void on_timer(bus::Ticks now) override;
  const char* kind() const override { return "replayer"; }

 private:
  bus::Ticks bits(std::int64_t n) const { return bus::bits_to_ticks(n, m_in.baud); }
  bus::Ticks desired_time() const;
  void schedule_next(bus::Ticks now);

  const ReplayInput& m_in;
  ReplayerOptions m_opts;
  std::vector<std::size_t> m_plan;
  std::vector<Sent> m_sent;
  std::vector<Heard> m_heard;
  std::size_t m_next = 0;
  bool m_powered = false;
  bool m_awaiting = false;      ///< Fast: waiting for the reply to the last sent request
  bool m_finishing = false;     ///< last frame sent, waiting for its reply window
  bool m_finished = false;
  bus::Ticks m_t0 = 0;
  bus::Ticks m_deadline = 0;    ///< end of the reply window (m_awaiting, m_finishing)
  bus::Ticks m_fast_ready = 0;  ///< Fast: earliest start of the next frame
  bus::Ticks m_last_end = 0;    ///< end of the last frame on the line (own or heard)
  std::uint64_t m_slips = 0;
};

// --- Masks -------------------------------------------------------------------------------------
struct ReplayMask {
  enum class Kind : std::uint8_t { Inputs, DiagExt, Octets };
  Kind kind = Kind::Octets;
  std::uint8_t station = 0;          ///< Octets
  std::optional<std::uint8_t> sap;   ///< Octets: request DSAP; nullopt = Data_Exchange
  std::size_t first = 0, last = 0;   ///< Octets: DU offsets, inclusive
  std::string text;                  ///< the rule as written
};
/// Parses "inputs", "diag-ext", "counter:ADDR:OFFSET[-END]", "ADDR:SAP:OFFSET[-END]" (SAP a
/// number or "dx"). nullopt and `error` on a bad rule.
std::optional<ReplayMask> parse_replay_mask(const std::string& rule, std::string& error);

// --- Comparison --------------------------------------------------------------------------------
enum class DiffKind : std::uint8_t { MissingReply, ExtraReply, OtherFc, OtherData, Timing };
const char* diff_kind_name(DiffKind k);  ///< "missing reply", "extra reply", ...
const char* diff_kind_key(DiffKind k);   ///< "missing_reply", "extra_reply", ... (JSON)

struct ReplayDiff {
  DiffKind kind = DiffKind::OtherData;
  std::size_t frame = 0;            ///< the request (index into ReplayInput::frames)
  bus::Ticks time = 0;              ///< its recorded start, relative to the line's first frame
  std::uint8_t station = 0;         ///< the request's DA
  std::string service;
  std::vector<std::uint8_t> request;
  std::optional<std::vector<std::uint8_t>> recorded, replayed;
  std::vector<std::size_t> frame_offsets;  ///< OtherFc/OtherData: differing octets of the frame
  std::vector<std::size_t> du_offsets;     ///< OtherData: of those, the DU offsets
  std::optional<std::int64_t> tsdr_bits;   ///< the replayed reply's TSDR
};

struct ReplayCompareOptions {
  std::uint32_t min_tsdr = 11;
  std::uint32_t max_tsdr = 0;  ///< 0 = the DP profile's for the baud
  std::vector<ReplayMask> masks;
};

struct ReplayResult {
  std::string line;
  bus::Baud baud = bus::Baud::k1_5M;
  std::optional<std::uint8_t> station;
  ReplayPacing pacing = ReplayPacing::Fast;
  std::uint32_t min_tsdr = 0, max_tsdr = 0;
  std::size_t recorded_frames = 0;
  std::size_t requests_replayed = 0;
  std::size_t tokens_replayed = 0;
  std::size_t compared = 0;
  std::size_t matches = 0;
  std::size_t not_compared_unusable = 0;  ///< recorded reply damaged
  std::size_t by_kind[5] = {};
  std::uint64_t pacing_slips = 0;
  std::vector<std::pair<std::string, std::size_t>> masks;  ///< rule, octets it hid
  std::vector<const ReplayFrame*> unusable;                ///< into the ReplayInput
  std::string read_error;
  std::vector<ReplayDiff> diffs;  ///< every difference, in order

  std::size_t differences() const { return diffs.size(); }
};

/// Compares what the Replayer sent and heard with the recording.
ReplayResult compare_replay(const ReplayInput& in, const Replayer& r, const ReplayCompareOptions& o);

// --- Report ------------------------------------------------------------------------------------
/// The frame's field names, one per octet: SD LE LEr SD DA SA FC DSAP SSAP DU.. FCS ED.
std::vector<std::string> frame_field_names(const std::vector<std::uint8_t>& bytes);
std::string replay_text(const ReplayResult& r, std::size_t max_diffs = 10);
std::string replay_json(const ReplayResult& r, std::size_t max_diffs = 10);
/// 0 no differences, 1 differences.
int replay_exit_status(const ReplayResult& r);

}  // namespace pbvbus::conformance
