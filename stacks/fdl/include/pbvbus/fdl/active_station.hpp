#pragma once
// FDL active station: the token-passing MAC of IEC 61158-4-3 for masters (protocol-facts.md
// §C.2-§C.6, Appendix 2 item 2). A bus::Device that listens to the token ring, joins it, claims
// the token when it is lost, runs its user's message cycles within the token hold time, keeps
// its GAP and the live list, and passes the token on.
//
// States (§C.4): Offline, Listen_Token, Active_Idle, Claim_Token, Use_Token,
// Await_Data_Response, Check_Access_Time, Pass_Token, Check_Token_Pass, Await_Status_Response.
// Check_Access_Time is passed through within one event (the hold-time decision); Pass_Token is
// the state while a token to this station itself is on the wire.
//
// Timing (all from BusParams, in t_bit, converted exactly to ticks):
//  - The first frame after a received token, reply or acknowledgement starts TID1 after its end;
//    after an unacknowledged frame (SDN) TID2 after the end of our own frame. A repeat after a
//    missing reply, and whatever follows a GAP poll nobody answered, starts right when the slot
//    time expires (the line has then been idle for TSL > TSYN).
//  - Slot time: a reply (or the token receiver's first frame) must start within TSL after the
//    end of our frame. Since the line delivers whole frames at their end, the station asks the
//    port whether a frame is arriving when TSL expires (DevicePort::receiving(), carrier sense);
//    a frame already started then is awaited and judged when it ends. A frame starting exactly
//    at the expiry tick may or may not be seen (the same race exists on a real bus).
//  - TTO = 6·TSL + 2·n·TSL of bus silence, reloaded at the end of every frame heard or sent.
//  - On token receipt TRR = now − previous receipt (the real rotation time, also recorded as a
//    sample) and TTH = TTR − TRR. Hardware loads a down-counter and reads TRR = TTR − remaining,
//    which saturates at TTR; the samples keep the unsaturated value because that is what a
//    report wants, and TTH ≤ 0 either way.
//
// Decisions where the reference is uncertain (§C, Appendix 2):
//  - Token pass: 3 attempts in total (S2), then NS is removed from the LAS and the token goes
//    to the next station in the LAS; a lone master passes to itself (DC TS TS).
//  - GAP: the addresses after TS up to (excluding) NS in ascending order; past HSA the walk
//    continues at 0, so HSA itself IS polled (HSA = highest station address, inclusive).
//    Addresses above HSA and 127 are never polled. One address per token visit; when the walk
//    reaches NS (a complete scan), the next scan starts after G further token receipts.
//  - GAP polls run when hold time remains after the message cycles, or — if TTH was already
//    ≤ 0 at token arrival — after the one high-priority cycle, so that a loaded ring still
//    admits new masters. While a GAP poll is pending in a visit, message cycles other than the
//    first stop (TSL + 100) t_bit before the hold time ends, to leave room for it (S2), so
//    that GAP polls and low-priority traffic do not block each other.
//  - Listen_Token: the LAS is valid after two complete identical rotations, a rotation being
//    delimited by a token whose SA is not higher than the previous token's SA (ring order is
//    ascending). Until then FDL Status is answered "master not ready" (0x10), afterwards "ready
//    to enter the ring" (0x20) to any poller, which is then taken as the predecessor PS.
//  - Live LAS maintenance: a token DC b a seen on the bus means that no active station sits
//    between a and b (ring order), so those addresses leave the LAS; a token DC a a (claim or
//    lone master) leaves only a. A station that sees itself skipped is out of the ring and
//    answers the next FDL Status with 0x20 to be admitted again; so does a station in the ring
//    polled by a master of its LAS (the poll proves it is in that master's GAP).
//  - Token acceptance: from PS; from another SA only when the same SA passes it a second time.
//  - Duplicate token: a valid frame from another station while this one holds the token (not
//    the expected reply) means a second token: this station drops its token and goes to
//    Listen_Token. Merging two rings after a repaired cut resolves this way.
//  - Duplicate address: a second valid frame from someone else carrying our own SA makes the
//    station leave the ring (Listen_Token) and restart LAS discovery.
//  - Claim: DC TS TS, then after TID1 DC TS TS again; the second one is this station's token
//    receipt, and the GAP scan starts at TS+1.
//  - A reply that is corrupt (error flags, bad frame) counts as missing; the repeat starts TID1
//    after its end. A Check_Token_Pass frame that is corrupt is ignored unless TSL has expired.
//  - FCB per responder: first frame FCV=0/FCB=1; then FCV=1 with FCB toggled after each valid
//    reply; repeats keep the FCB. After max_retry repeats without a valid reply the responder is
//    non-operational: requests to it go without repeats and with a first frame again, until it
//    answers.
//  - A request that cannot be encoded (data too long, bad address or SAP, addressed to this
//    station) is not sent and confirmed NoResponse at once; so is a request whose reply was
//    pending when the station dropped its token (duplicate token): neither marks the responder
//    non-operational.
//  - Equidistance pause (InitiatorUser::pause_until, docs/dp-equidistance.md): at the start
//    of a visit with nothing to send, the station may keep the token until the user's next
//    cycle: FDL Status requests (SD1, DA = SA = TS) to itself, each followed by TSL (nobody
//    answers), while one fits; then silence until the cycle time. The pause is added to the
//    hold deadline.
//  - Requests addressed to this master are answered like a passive station would (FCB filter,
//    SAP mirroring, TSDR = min TSDR), with the FC's station type bits telling our MAC state.
//
// Passive (listen-only) mode, for a hot-standby master at the same address as an active one
// (docs/quantum-hsby-dp.md; Beckhoff FC310x "Redundancy Mode", ProSoft PTQ-PDPMV1 passive
// master): set_passive(true, now). The station then sends nothing at all (no token, no claim,
// no reply, no FDL Status answer) and runs no timer, but it keeps receiving: every valid frame
// goes to InitiatorUser::on_observed(); frames carrying its own SA are not taken for a
// duplicate address (they are the active master's, which the passive one shadows); tokens keep
// the LAS (Listen_Token discovery, then the live LAS rules); and it shadows the active master's
// FCB towards each responder (a request from our SA with FCV/FCB, then a valid reply or SC from
// that responder: the next FCB is the toggled one, exactly as the active master's own state).
// set_passive(false, now) leaves it like a station that just lost the token: Listen_Token with
// the LAS it tracked, and TTO counted from the end of the last frame heard (the station has been
// listening all along), so on a line silent for TTO it claims at once, otherwise when TTO
// expires (IEC 61158-4-3 claim after TTO; the FC310x's ClaimTokenTimeout (6 + 2·TS)·TSL). The
// first request to a responder then carries the shadowed FCB (FCV=1, toggled), or the first
// frame FCV=0/FCB=1 if no completed cycle was seen. Outside the token (Listen_Token,
// Active_Idle) the station keeps following the FCB of cycles run with its SA by someone else
// (the reply to a request seen while passive; a master at a duplicate address). If the old master is still sending, its
// frames with our SA are a duplicate address: the station stays in Listen_Token (never claims
// on a busy line) until the line falls silent — the misuse resolves without a collision.
//
// Steady state is allocation-free: the Request given to the user and the rotation sample
// buffer are members reused from visit to visit.

#include <array>
#include <bitset>
#include <cstdint>
#include <optional>
#include <string_view>
#include <utility>
#include <vector>

#include "pbvbus/bus/device.hpp"
#include "pbvbus/fdl/bus_params.hpp"
#include "pbvbus/fdl/responder.hpp"
#include "pbvbus/fdl/station.hpp"
#include "pbvbus/fdl/telegram.hpp"

namespace pbvbus::fdl {

enum class MacState : std::uint8_t {
  Offline,
  Listen_Token,
  Active_Idle,
  Claim_Token,
  Use_Token,
  Await_Data_Response,
  Check_Access_Time,
  Pass_Token,
  Check_Token_Pass,
  Await_Status_Response,
};
std::string_view to_string(MacState s);

struct ActiveStats {
  std::uint64_t tokens_received = 0;     ///< token receipts (incl. passes to itself)
  std::uint64_t tokens_passed = 0;       ///< token frames sent (incl. repeats and claims)
  std::uint64_t token_pass_retries = 0;  ///< repeated token passes after no activity
  std::uint64_t stations_dropped = 0;    ///< NS removed from the LAS after 3 failed passes
  std::uint64_t token_losses = 0;        ///< TTO expiries: token lost, token claimed
  std::uint64_t admissions = 0;          ///< masters admitted to the ring after a GAP poll
  std::uint64_t gap_polls = 0;
  std::uint64_t requests = 0;            ///< message cycles started (without repeats)
  std::uint64_t retries = 0;             ///< repeats of requests
  std::uint64_t no_response = 0;         ///< requests given up (responder non-operational)
  std::uint64_t invalid_replies = 0;     ///< corrupt frames where a reply was awaited
  std::uint64_t duplicate_token = 0;     ///< foreign frames heard while holding the token
  std::uint64_t duplicate_address = 0;   ///< own address detected in use by another station
  std::uint64_t requests_answered = 0;   ///< requests from other masters answered
  std::uint64_t frames_observed = 0;     ///< valid frames reported while passive
  std::uint64_t pause_frames = 0;        ///< equidistance: FDL Status requests to itself
  std::array<std::uint64_t, 16> requests_by_fn{};  ///< message cycles by request function
};

class ActiveStation final : public bus::Device {
 public:
  static constexpr int kTokenPassAttempts = 3;
  static constexpr std::size_t kRotationSamples = 4096;

  ActiveStation(std::uint8_t address, const BusParams& params, InitiatorUser& user);

  void on_power_on(bus::Ticks now) override;
  void on_power_off(bus::Ticks now) override;
  void on_frame(const bus::RxFrame& frame) override;
  void on_timer(bus::Ticks now) override;
  const char* kind() const override { return "active station"; }

  /// Passive (listen-only) mode, see the header comment. May be called before power-on.
  void set_passive(bool on, bus::Ticks now);
  bool passive() const { return m_passive; }
  /// Next FCB state towards `a` (0 = first frame FCV=0/FCB=1 next, 1 = FCB 0 next, 2 = FCB 1
  /// next), as used or, while passive, as shadowed from the active master.
  std::uint8_t fcb_state(std::uint8_t a) const { return a < 128 ? m_fcb_state[a] : 0; }

  MacState state() const { return m_state; }
  std::uint8_t address() const { return m_ts; }
  const BusParams& params() const { return m_p; }
  /// Whether this station currently considers itself a member of the token ring.
  bool in_ring() const { return m_in_ring; }
  /// List of active stations in ring order (ascending, the ring wraps to the first).
  std::vector<std::uint8_t> las() const;
  bool las_contains(std::uint8_t a) const { return a < 128 && m_las.test(a); }
  bool las_valid() const { return m_las_valid; }
  /// Next station (token receiver) and previous station as currently known.
  std::uint8_t next_station() const { return compute_ns(); }
  std::uint8_t previous_station() const { return compute_ps(); }
  /// Station type at `a` as known from GAP polls, replies and the LAS; nullopt = nobody.
  std::optional<StationType> live(std::uint8_t a) const;
  std::vector<std::pair<std::uint8_t, StationType>> live_list() const;
  /// The transceiver's read-back reports a bus fault (bus::DevicePort::medium_fault(): a
  /// short circuit); false while not attached.
  bool medium_fault() const { return bound() && port().medium_fault(); }
  /// Whether requests to `a` currently go without repeats (it did not answer).
  bool non_operational(std::uint8_t a) const { return a < 128 && m_nonop.test(a); }

  /// Real rotation times (TRR) at the last token receipts, oldest first, in ticks.
  std::vector<bus::Ticks> rotation_samples() const;
  std::uint64_t rotation_count() const { return m_rot_count; }
  bus::Ticks rotation_min() const { return m_rot_min; }
  bus::Ticks rotation_max() const { return m_rot_max; }
  bus::Ticks rotation_last() const { return m_rot_last; }

  const ActiveStats& stats() const { return m_stats; }

 private:
  enum class Ask : std::uint8_t { Sent, Nothing, Rejected };
  static constexpr std::uint8_t kNobody = 0xFF;

  // Timers and transmission.
  void arm(bus::Ticks at);
  void arm_tto();
  bus::Ticks send(bus::Ticks at, const Frame& f);  // returns the frame's end
  // Ring bookkeeping.
  std::uint8_t compute_ns() const;
  std::uint8_t compute_ps() const;
  std::uint8_t next_addr(std::uint8_t a) const;
  bool in_gap(std::uint8_t a, std::uint8_t ns) const;
  void las_token_seen(std::uint8_t sa, std::uint8_t da);
  void discovery_token(std::uint8_t sa);
  void reset_discovery();
  void leave_ring(bus::Ticks now);
  StationType station_type() const;
  void set_live(std::uint8_t a, std::optional<StationType> t);
  // Frame handling per state.
  void handle_passive(const bus::RxFrame& f, const Telegram& t, bool valid);
  void observe(const Telegram& t, bool valid, bus::Ticks now);
  void shadow_fcb(const Telegram& t, bool valid);
  void answer_request(const bus::RxFrame& f, const Telegram& t);
  void token_to_me(const bus::RxFrame& f, const Telegram& t);
  void await_data_frame(const bus::RxFrame& f, const Telegram& t, bool valid);
  void await_status_frame(const bus::RxFrame& f, const Telegram& t, bool valid);
  void check_pass_frame(const bus::RxFrame& f, const Telegram& t, bool valid);
  void foreign_while_holding(const bus::RxFrame& f, const Telegram& t);
  // Token holding.
  void token_lost(bus::Ticks now);
  void token_received(bus::Ticks now);
  void step(bus::Ticks now);
  Ask ask(Priority prio, bus::Ticks now);
  void transmit_request(bus::Ticks now);
  void request_failed(bus::Ticks now);
  void finish_request(bus::Ticks now, Confirmation::Result r);
  void gap_poll(bus::Ticks now, std::uint8_t addr);
  void gap_failed(bus::Ticks now);
  void pass_token(bus::Ticks now);
  void equidistance_pause(bus::Ticks now, bus::Ticks until);
  void pass_failed(bus::Ticks now);
  void slot_expired(bus::Ticks now);
  void record_rotation(bus::Ticks trr);

  BusParams m_p;
  InitiatorUser& m_user;
  std::uint8_t m_ts;
  MacState m_state = MacState::Offline;
  bool m_powered = false;
  bool m_passive = false;
  // Passive FCB shadow: the responder of the last request from our SA with an FCB, and that FCB.
  std::uint8_t m_shadow_da = kNobody;
  bool m_shadow_fcb = false;

  // Durations in ticks.
  bus::Ticks m_tsyn, m_tid1, m_tid2, m_tsl, m_tto, m_ttr, m_gap_reserve, m_token_len;

  bus::Ticks m_timer_at = bus::kNever;
  bus::Ticks m_last_activity = 0;  // end of the last frame heard or sent (TTO reference)

  // LAS and ring.
  std::bitset<128> m_las;
  bool m_las_valid = false;
  bool m_in_ring = false;
  std::uint8_t m_ns = 0;
  mutable std::bitset<128> m_ns_cache_las;
  mutable std::uint8_t m_ns_cache = 0;
  mutable bool m_ns_cache_valid = false;
  std::uint8_t m_token_candidate = kNobody;
  int m_pass_failures = 0;
  // Listen_Token discovery: two complete identical rotations.
  int m_prev_token_sa = -1;
  bool m_rot_started = false;
  bool m_rot_have_prev = false;
  std::bitset<128> m_rot_cur, m_rot_prev;
  int m_dup_seen = 0;

  // Live list: station type per address, or kNobody.
  std::array<std::uint8_t, 128> m_live{};

  // GAP.
  std::uint8_t m_gap_next = 0;
  std::uint32_t m_gap_wait = 0;
  bool m_gap_done_visit = false;
  std::uint8_t m_gap_addr = 0;

  // Token hold.
  bus::Ticks m_token_at = bus::kNever;
  bus::Ticks m_hold_deadline = 0;
  bool m_tth_expired = false;
  std::uint32_t m_cycles_visit = 0;
  bool m_pass_next = false;
  int m_claim_step = 0;

  // Current message cycle.
  Request m_req;
  Frame m_tx;
  bool m_req_fcb = false;      // the request carries an FCB
  bool m_req_fcb_value = false;
  std::uint32_t m_retry = 0;
  bus::Ticks m_slot_deadline = 0;
  bool m_await_failed = false;
  bool m_sdn_pending = false;

  // Per responder: 0 = next is a first frame, 1 = next FCB 0, 2 = next FCB 1.
  std::array<std::uint8_t, 128> m_fcb_state{};
  std::bitset<128> m_nonop;

  Responder m_responder;
  Reply m_reply;

  std::vector<bus::Ticks> m_rot_samples;
  std::size_t m_rot_pos = 0;
  std::uint64_t m_rot_count = 0;
  bus::Ticks m_rot_min = 0, m_rot_max = 0, m_rot_last = 0;

  ActiveStats m_stats;
};

}  // namespace pbvbus::fdl
