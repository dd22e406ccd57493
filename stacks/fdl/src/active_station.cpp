#include "pbvbus/fdl/active_station.hpp"

#include <algorithm>

#include "pbvbus/fdl/decoded_frame.hpp"

namespace pbvbus::fdl {

std::string_view to_string(MacState s) {
  switch (s) {
    case MacState::Offline: return "Offline";
    case MacState::Listen_Token: return "Listen_Token";
    case MacState::Active_Idle: return "Active_Idle";
    case MacState::Claim_Token: return "Claim_Token";
    case MacState::Use_Token: return "Use_Token";
    case MacState::Await_Data_Response: return "Await_Data_Response";
    case MacState::Check_Access_Time: return "Check_Access_Time";
    case MacState::Pass_Token: return "Pass_Token";
    case MacState::Check_Token_Pass: return "Check_Token_Pass";
    case MacState::Await_Status_Response: return "Await_Status_Response";
  }
  return "?";
}

ActiveStation::ActiveStation(std::uint8_t address, const BusParams& params, InitiatorUser& user)
    : m_p(params), m_user(user), m_ts(static_cast<std::uint8_t>(address & 0x7F)) {
  m_tsyn = m_p.ticks(BusParams::kTsyn);
  m_tid1 = m_p.ticks(m_p.tid1());
  m_tid2 = m_p.ticks(m_p.tid2());
  m_tsl = m_p.ticks(m_p.tsl);
  m_tto = m_p.ticks(m_p.tto(m_ts));
  m_ttr = m_p.ticks(m_p.ttr);
  m_gap_reserve = m_p.ticks(static_cast<std::int64_t>(m_p.tsl) + 100);
  m_token_len = bus::chars_to_ticks(3, m_p.baud);
  m_live.fill(kNobody);
  m_rot_samples.assign(kRotationSamples, 0);
  m_responder.reset();
}

// --- accessors ----------------------------------------------------------------------------------

std::vector<std::uint8_t> ActiveStation::las() const {
  std::vector<std::uint8_t> out;
  for (std::size_t a = 0; a < 128; ++a)
    if (m_las.test(a)) out.push_back(static_cast<std::uint8_t>(a));
  return out;
}

std::optional<StationType> ActiveStation::live(std::uint8_t a) const {
  if (a >= 128) return std::nullopt;
  if (a == m_ts && m_state != MacState::Offline) return station_type();
  if (m_las.test(a)) return StationType::MasterInRing;
  if (m_live[a] == kNobody) return std::nullopt;
  return static_cast<StationType>(m_live[a]);
}

std::vector<std::pair<std::uint8_t, StationType>> ActiveStation::live_list() const {
  std::vector<std::pair<std::uint8_t, StationType>> out;
  for (std::uint8_t a = 0; a < 127; ++a)
    if (auto t = live(a)) out.emplace_back(a, *t);
  return out;
}

std::vector<bus::Ticks> ActiveStation::rotation_samples() const {
  std::vector<bus::Ticks> out;
  const std::size_t n = static_cast<std::size_t>(std::min<std::uint64_t>(m_rot_count, kRotationSamples));
  out.reserve(n);
  const std::size_t first = (m_rot_pos + kRotationSamples - n) % kRotationSamples;
  for (std::size_t i = 0; i < n; ++i) out.push_back(m_rot_samples[(first + i) % kRotationSamples]);
  return out;
}

void ActiveStation::record_rotation(bus::Ticks trr) {
  m_rot_samples[m_rot_pos] = trr;
  m_rot_pos = (m_rot_pos + 1) % kRotationSamples;
  if (m_rot_count == 0) {
    m_rot_min = m_rot_max = trr;
  } else {
    m_rot_min = std::min(m_rot_min, trr);
    m_rot_max = std::max(m_rot_max, trr);
  }
  m_rot_last = trr;
  ++m_rot_count;
}

// --- helpers ----------------------------------------------------------------------------------

void ActiveStation::arm(bus::Ticks at) {
  m_timer_at = at;
  port().set_timer(at);
}

void ActiveStation::arm_tto() { arm(m_last_activity + m_tto); }

bus::Ticks ActiveStation::send(bus::Ticks at, const Frame& f) {
  port().transmit(at, f.bytes());
  const bus::Ticks end = at + bus::chars_to_ticks(f.len, m_p.baud);
  m_last_activity = std::max(m_last_activity, end);
  return end;
}

std::uint8_t ActiveStation::next_addr(std::uint8_t a) const {
  const int b = a + 1;
  return static_cast<std::uint8_t>(b > m_p.hsa ? 0 : b);
}

std::uint8_t ActiveStation::compute_ns() const {
  // Called at every step: cache the walk for the current LAS (comparing 128 bits is cheap).
  if (m_ns_cache_valid && m_ns_cache_las == m_las) return m_ns_cache;
  std::uint8_t ns = m_ts;
  for (int i = 1; i < 128; ++i) {
    const auto a = static_cast<std::size_t>((m_ts + i) % 128);
    if (a != 127 && m_las.test(a)) {
      ns = static_cast<std::uint8_t>(a);
      break;
    }
  }
  m_ns_cache_las = m_las;
  m_ns_cache = ns;
  m_ns_cache_valid = true;
  return ns;
}

std::uint8_t ActiveStation::compute_ps() const {
  for (int i = 1; i < 128; ++i) {
    const auto a = static_cast<std::size_t>((m_ts + 128 - i) % 128);
    if (a != 127 && m_las.test(a)) return static_cast<std::uint8_t>(a);
  }
  return m_ts;
}

bool ActiveStation::in_gap(std::uint8_t a, std::uint8_t ns) const {
  if (a > m_p.hsa || a == m_ts || a >= 127) return false;
  if (ns == m_ts) return true;
  const int da = (a - m_ts + 128) % 128, dn = (ns - m_ts + 128) % 128;
  return da < dn;
}

StationType ActiveStation::station_type() const {
  switch (m_state) {
    case MacState::Offline:
    case MacState::Listen_Token:
      return m_las_valid ? StationType::MasterReady : StationType::MasterNotReady;
    case MacState::Active_Idle: return m_in_ring ? StationType::MasterInRing : StationType::MasterReady;
    default: return StationType::MasterInRing;
  }
}

void ActiveStation::set_live(std::uint8_t a, std::optional<StationType> t) {
  if (a >= 128) return;
  m_live[a] = t ? static_cast<std::uint8_t>(*t) : kNobody;
}

void ActiveStation::las_token_seen(std::uint8_t sa, std::uint8_t da) {
  // A token from sa to da: nobody active between them in ring order.
  if (sa == da) {
    // A claim or a lone master: its ring holds nobody else.
    m_las.reset();
    m_las.set(sa);
    m_in_ring = false;
    return;
  }
  for (int a = (sa + 1) % 128; a != da; a = (a + 1) % 128) {
    if (a == m_ts) m_in_ring = false;
    m_las.reset(static_cast<std::size_t>(a));
  }
  m_las.set(sa);
  m_las.set(da);
}

void ActiveStation::reset_discovery() {
  m_las_valid = false;
  m_prev_token_sa = -1;
  m_rot_started = false;
  m_rot_have_prev = false;
  m_rot_cur.reset();
  m_rot_prev.reset();
}

void ActiveStation::discovery_token(std::uint8_t sa) {
  if (m_prev_token_sa >= 0 && sa <= m_prev_token_sa) {
    // The ring wrapped: one rotation is complete.
    if (m_rot_started) {
      if (m_rot_have_prev && m_rot_cur == m_rot_prev && m_rot_cur.any()) {
        m_las = m_rot_cur;
        m_las_valid = true;
      } else {
        m_rot_prev = m_rot_cur;
        m_rot_have_prev = true;
      }
    }
    m_rot_started = true;
    m_rot_cur.reset();
  }
  if (m_rot_started) m_rot_cur.set(sa);
  m_prev_token_sa = sa;
}

void ActiveStation::leave_ring(bus::Ticks now) {
  if (m_state == MacState::Await_Data_Response) {
    finish_request(now, Confirmation::Result::NoResponse);
  } else if (m_sdn_pending) {
    finish_request(now, Confirmation::Result::Sent);
  }
  m_sdn_pending = false;
  m_state = MacState::Listen_Token;
  m_in_ring = false;
  m_las.reset();
  reset_discovery();
  m_token_at = bus::kNever;
  m_token_candidate = kNobody;
  m_pass_failures = 0;
  m_pass_next = false;
  m_last_activity = std::max(m_last_activity, now);
  arm_tto();
}

// --- Device -----------------------------------------------------------------------------------

void ActiveStation::on_power_on(bus::Ticks now) {
  m_powered = true;
  m_state = MacState::Listen_Token;
  m_las.reset();
  m_in_ring = false;
  reset_discovery();
  m_ns = m_ts;
  m_token_candidate = kNobody;
  m_pass_failures = 0;
  m_dup_seen = 0;
  m_live.fill(kNobody);
  m_gap_next = next_addr(m_ts);
  m_gap_wait = 0;
  m_token_at = bus::kNever;
  m_pass_next = false;
  m_sdn_pending = false;
  m_fcb_state.fill(0);
  m_nonop.reset();
  m_responder.reset();
  m_last_activity = now;
  m_shadow_da = kNobody;
  m_user.on_power_on(now);
  if (m_passive) {
    m_timer_at = bus::kNever;
    return;
  }
  arm_tto();
}

void ActiveStation::set_passive(bool on, bus::Ticks now) {
  if (on == m_passive) return;
  if (on) {
    // Give up whatever this station was doing on the line (a held token, an awaited reply).
    if (m_powered && m_state != MacState::Listen_Token && m_state != MacState::Active_Idle)
      leave_ring(now);
    m_passive = true;
    m_shadow_da = kNobody;
    if (m_powered) m_state = MacState::Listen_Token;
    m_in_ring = false;
    m_timer_at = bus::kNever;
    return;
  }
  m_passive = false;
  if (!m_powered) return;
  // Like a station that just lost the token: Listen_Token, TTO from the last frame heard.
  m_state = MacState::Listen_Token;
  m_in_ring = false;
  m_dup_seen = 0;
  m_token_at = bus::kNever;
  m_token_candidate = kNobody;
  m_pass_failures = 0;
  m_pass_next = false;
  m_sdn_pending = false;
  m_nonop.reset();
  arm(std::max(now, m_last_activity + m_tto));
}

void ActiveStation::shadow_fcb(const Telegram& t, bool valid) {
  // FCB shadow (§C.6): a completed cycle of the (other) master at our address toggles its FCB
  // towards that responder, exactly as it does in that master.
  if (!valid) {
    m_shadow_da = kNobody;
    return;
  }
  if (t.is_request() && t.sa == m_ts) {
    const RequestFn fn = fc_request_fn(t.fc);
    if (fn_uses_fcb(fn) && t.da < kBroadcast) {
      m_shadow_da = t.da;
      m_shadow_fcb = fc_fcb(t.fc);
    } else {
      m_shadow_da = kNobody;
    }
  } else if (m_shadow_da != kNobody &&
             (t.type == FrameType::SC ||
              (t.type != FrameType::SD4 && !t.is_request() && t.da == m_ts && t.sa == m_shadow_da))) {
    m_fcb_state[m_shadow_da] = m_shadow_fcb ? 1 : 2;
    m_shadow_da = kNobody;
  } else {
    m_shadow_da = kNobody;
  }
}

void ActiveStation::observe(const Telegram& t, bool valid, bus::Ticks now) {
  shadow_fcb(t, valid);
  if (!valid) return;
  // LAS: as in Listen_Token / Active_Idle.
  if (t.type == FrameType::SD4) {
    if (!m_las_valid) {
      discovery_token(t.sa);
    } else {
      las_token_seen(t.sa, t.da);
    }
    m_in_ring = false;
  }
  ++m_stats.frames_observed;
  m_user.on_observed(now, t);
}

void ActiveStation::on_power_off(bus::Ticks) {
  m_powered = false;
  m_state = MacState::Offline;
  m_in_ring = false;
  m_timer_at = bus::kNever;
}

void ActiveStation::on_frame(const bus::RxFrame& f) {
  if (!m_powered) return;
  const bus::Ticks now = f.end;
  m_last_activity = std::max(m_last_activity, f.end);
  DecodedFrame scratch;  // stays "not decoded" for a damaged frame
  const DecodedFrame& d = f.intact() ? decode_once(f, scratch) : scratch;
  const bool valid = d.ok();
  const Telegram& t = d.telegram;

  if (m_passive) {
    observe(t, valid, now);
    return;
  }
  // Not holding the token: keep following the FCB of a master sending with our address (the
  // reply to the last request seen while passive, or a duplicate address, see the header).
  if (m_state == MacState::Listen_Token || m_state == MacState::Active_Idle) shadow_fcb(t, valid);
  if (valid && t.type != FrameType::SC && t.sa == m_ts) {
    // Someone else sends with our address.
    if (++m_dup_seen >= 2) {
      m_dup_seen = 0;
      ++m_stats.duplicate_address;
      if (m_state == MacState::Listen_Token) {
        reset_discovery();
        arm_tto();
      } else {
        leave_ring(now);
      }
    } else if (m_state == MacState::Listen_Token || m_state == MacState::Active_Idle) {
      arm_tto();
    }
    return;
  }

  switch (m_state) {
    case MacState::Offline: return;
    case MacState::Listen_Token:
    case MacState::Active_Idle: handle_passive(f, t, valid); return;
    case MacState::Claim_Token:
    case MacState::Use_Token:
    case MacState::Check_Access_Time:
    case MacState::Pass_Token:
      if (valid) {
        foreign_while_holding(f, t);
      } else if (m_state == MacState::Use_Token) {
        // Noise: keep the required idle time after it before our next frame.
        arm(std::max(m_timer_at, now + m_tid1));
      }
      return;
    case MacState::Await_Data_Response: await_data_frame(f, t, valid); return;
    case MacState::Await_Status_Response: await_status_frame(f, t, valid); return;
    case MacState::Check_Token_Pass: check_pass_frame(f, t, valid); return;
  }
}

void ActiveStation::on_timer(bus::Ticks now) {
  if (!m_powered || m_passive) return;
  if (now < m_timer_at) {
    port().set_timer(m_timer_at);
    return;
  }
  switch (m_state) {
    case MacState::Offline: return;
    case MacState::Listen_Token:
    case MacState::Active_Idle:
      if (now < m_last_activity + m_tto) {
        arm_tto();
      } else if (!port().receiving()) {
        token_lost(now);
      }
      // else: a frame is arriving; its end reloads TTO.
      return;
    case MacState::Claim_Token:
      if (m_claim_step == 1) {
        m_claim_step = 2;
        ++m_stats.tokens_passed;
        arm(send(now, encode_token(m_ts, m_ts)));
      } else {
        token_received(now);
      }
      return;
    case MacState::Use_Token:
    case MacState::Check_Access_Time: step(now); return;
    case MacState::Pass_Token: token_received(now); return;
    case MacState::Await_Data_Response:
    case MacState::Await_Status_Response:
    case MacState::Check_Token_Pass: slot_expired(now); return;
  }
}

// --- not holding the token ------------------------------------------------------------------

void ActiveStation::handle_passive(const bus::RxFrame& f, const Telegram& t, bool valid) {
  if (valid) {
    if (t.type == FrameType::SD4) {
      if (t.da == m_ts && m_state == MacState::Active_Idle) {
        token_to_me(f, t);
        if (m_state != MacState::Active_Idle) return;
      } else if (!m_las_valid) {
        discovery_token(t.sa);
      } else if (t.da != m_ts) {
        las_token_seen(t.sa, t.da);
      }
    } else if (t.is_request() && t.da == m_ts) {
      answer_request(f, t);
    }
  }
  arm_tto();
}

void ActiveStation::answer_request(const bus::RxFrame& f, const Telegram& t) {
  if (f.idle_before < m_tsyn) return;
  const bus::Ticks start = f.end + m_p.ticks(m_p.min_tsdr);
  const RequestFn fn = fc_request_fn(t.fc);
  if (fn == RequestFn::FdlStatus) {
    StationType type = station_type();
    if (m_las_valid && (m_state == MacState::Listen_Token ||
                        (m_state == MacState::Active_Idle && m_las.test(t.sa)))) {
      // Ready to enter: the poller is about to make us its NS, so it is our PS.
      type = StationType::MasterReady;
      m_state = MacState::Active_Idle;
      m_in_ring = false;
      las_token_seen(t.sa, m_ts);
      m_token_candidate = kNobody;
    }
    send(start, Responder::fdl_status_reply(t, m_ts, type));
    ++m_stats.requests_answered;
    return;
  }
  const bool answer = fn_expects_reply(fn) && t.da != kBroadcast;
  if (answer && m_responder.check(t) == Responder::Check::Repeat) {
    const Frame& r = m_responder.stored_reply(t.sa);
    if (!r.empty()) send(start, r);
    return;
  }
  Responder::clear(m_reply);
  Indication ind;
  ind.now = f.end;
  ind.sa = t.sa;
  ind.da = t.da;
  ind.fn = fn;
  ind.dsap = t.dsap;
  ind.ssap = t.ssap;
  ind.data = t.data;
  m_user.on_request(ind, m_reply);
  if (!answer) return;
  const Frame& r = m_responder.finish(t, m_ts, station_type(), m_reply);
  if (!r.empty()) send(start, r);
  ++m_stats.requests_answered;
}

void ActiveStation::token_to_me(const bus::RxFrame& f, const Telegram& t) {
  if (f.idle_before < m_tsyn) return;
  const std::uint8_t from = t.sa;
  if (from != compute_ps() && from != m_token_candidate) {
    // Not from our predecessor: accept only when the same station passes it again.
    m_token_candidate = from;
    return;
  }
  m_token_candidate = kNobody;
  las_token_seen(from, m_ts);
  m_in_ring = true;
  token_received(f.end);
}

void ActiveStation::token_lost(bus::Ticks now) {
  // TTO expired on a silent bus: (re)initialise the ring with this station alone.
  ++m_stats.token_losses;
  m_state = MacState::Claim_Token;
  m_claim_step = 1;
  m_las.reset();
  m_las.set(m_ts);
  m_las_valid = true;
  m_in_ring = true;
  m_ns = m_ts;
  m_token_at = bus::kNever;
  m_token_candidate = kNobody;
  m_pass_failures = 0;
  m_gap_next = next_addr(m_ts);
  m_gap_wait = 0;
  ++m_stats.tokens_passed;
  arm(send(now, encode_token(m_ts, m_ts)) + m_tid1);
}

// --- holding the token ------------------------------------------------------------------------

void ActiveStation::token_received(bus::Ticks now) {
  ++m_stats.tokens_received;
  bus::Ticks trr = 0;
  if (m_token_at != bus::kNever) {
    trr = now - m_token_at;
    record_rotation(trr);
  }
  m_token_at = now;
  const bus::Ticks tth = m_ttr - trr;
  m_hold_deadline = now + tth;
  m_tth_expired = tth <= 0;
  m_cycles_visit = 0;
  m_gap_done_visit = false;
  m_pass_next = false;
  m_dup_seen = 0;
  if (m_gap_wait > 0) --m_gap_wait;
  m_state = MacState::Use_Token;
  m_user.on_token(now, trr);
  arm(now + m_tid1);
}

void ActiveStation::step(bus::Ticks now) {
  m_state = MacState::Check_Access_Time;
  if (m_sdn_pending) {
    m_sdn_pending = false;
    finish_request(now, Confirmation::Result::Sent);
  }
  if (m_pass_next) {
    pass_token(now);
    return;
  }
  const std::uint8_t ns = compute_ns();
  // GAP: find the address to poll this visit, or notice that the scan is complete.
  bool gap_due = false;
  if (!m_gap_done_visit && m_gap_wait == 0) {
    if (in_gap(m_gap_next, ns)) {
      gap_due = true;
    } else {
      m_gap_done_visit = true;
      m_gap_wait = m_p.gap_factor;
      m_gap_next = next_addr(m_ts);
    }
  }
  const bus::Ticks msg_deadline = m_hold_deadline - (gap_due ? m_gap_reserve : 0);
  for (;;) {
    Ask r = Ask::Nothing;
    if (m_cycles_visit == 0 || now < msg_deadline) r = ask(Priority::High, now);
    if (r == Ask::Nothing && now < msg_deadline) r = ask(Priority::Low, now);
    if (r == Ask::Sent) return;
    if (r == Ask::Nothing) break;
  }
  if (m_cycles_visit == 0) {
    const bus::Ticks until = m_user.pause_until(now);
    if (until > now) {
      equidistance_pause(now, until);
      return;
    }
  }
  if (gap_due && (now < m_hold_deadline || m_tth_expired)) {
    gap_poll(now, m_gap_next);
    return;
  }
  pass_token(now);
}

ActiveStation::Ask ActiveStation::ask(Priority prio, bus::Ticks now) {
  m_req.da = 0;
  m_req.fn = prio == Priority::High ? RequestFn::SrdHigh : RequestFn::SrdLow;
  m_req.dsap.reset();
  m_req.ssap.reset();
  m_req.data.clear();
  m_req.tag = 0;
  if (!m_user.next_request(prio, now, m_req)) return Ask::Nothing;
  ++m_cycles_visit;
  ++m_stats.requests;
  ++m_stats.requests_by_fn[static_cast<std::size_t>(m_req.fn) & 15];
  m_retry = 0;
  const std::uint8_t da = m_req.da;
  m_req_fcb = fn_uses_fcb(m_req.fn) && da < kBroadcast;
  std::uint8_t fc = make_request_fc(m_req.fn);
  if (m_req_fcb) {
    const std::uint8_t st = m_fcb_state[da];
    m_req_fcb_value = st != 1;  // first frame: FCB=1 (FCV=0); state 2: FCB=1; state 1: FCB=0
    fc = make_request_fc(m_req.fn, st != 0, m_req_fcb_value);
  }
  FrameSpec spec;
  spec.da = da;
  spec.sa = m_ts;
  spec.fc = fc;
  spec.dsap = m_req.dsap;
  spec.ssap = m_req.ssap;
  spec.data = m_req.data;
  if (da > kBroadcast || da == m_ts || encode(spec, m_tx) != EncodeError::None) {
    finish_request(now, Confirmation::Result::NoResponse);
    return Ask::Rejected;
  }
  transmit_request(now);
  return Ask::Sent;
}

void ActiveStation::transmit_request(bus::Ticks now) {
  const bus::Ticks end = send(now, m_tx);
  const bool reply_expected = fn_expects_reply(m_req.fn) && m_req.da != kBroadcast;
  if (reply_expected) {
    m_state = MacState::Await_Data_Response;
    m_slot_deadline = end + m_tsl;
    m_await_failed = false;
    arm(m_slot_deadline);
  } else {
    m_state = MacState::Use_Token;
    m_sdn_pending = true;
    arm(end + m_tid2);
  }
}

void ActiveStation::finish_request(bus::Ticks now, Confirmation::Result r) {
  Confirmation con;
  con.now = now;
  con.tag = m_req.tag;
  con.da = m_req.da;
  con.result = r;
  con.retries = m_retry;
  m_user.on_confirmation(con);
}

void ActiveStation::await_data_frame(const bus::RxFrame& f, const Telegram& t, bool valid) {
  const bus::Ticks now = f.end;
  if (!valid) {
    ++m_stats.invalid_replies;
    m_await_failed = true;
    arm(now + m_tid1);
    return;
  }
  const bool reply = t.type == FrameType::SC ||
                     (t.type != FrameType::SD4 && !t.is_request() && t.da == m_ts && t.sa == m_req.da);
  if (!reply) {
    foreign_while_holding(f, t);
    return;
  }
  const std::uint8_t da = m_req.da;
  if (m_req_fcb) m_fcb_state[da] = m_req_fcb_value ? 1 : 2;
  m_nonop.reset(da);
  Confirmation con;
  con.now = now;
  con.tag = m_req.tag;
  con.da = da;
  con.result = Confirmation::Result::Ok;
  con.retries = m_retry;
  if (t.type == FrameType::SC) {
    con.short_ack = true;
  } else {
    con.status = fc_status(t.fc);
    con.responder_type = fc_station_type(t.fc);
    con.dsap = t.dsap;
    con.ssap = t.ssap;
    con.data = t.data;
    if (!m_las.test(da)) set_live(da, con.responder_type);
  }
  m_state = MacState::Use_Token;
  arm(now + m_tid1);
  m_user.on_confirmation(con);
}

void ActiveStation::request_failed(bus::Ticks now) {
  const std::uint8_t da = m_req.da;
  const std::uint32_t limit = m_nonop.test(da) ? 0u : m_p.max_retry;
  if (m_retry < limit) {
    ++m_retry;
    ++m_stats.retries;
    transmit_request(now);
    return;
  }
  ++m_stats.no_response;
  m_nonop.set(da);
  m_fcb_state[da] = 0;
  if (!m_las.test(da)) set_live(da, std::nullopt);
  m_state = MacState::Use_Token;
  finish_request(now, Confirmation::Result::NoResponse);
  if (m_state == MacState::Use_Token) step(now);
}

void ActiveStation::gap_poll(bus::Ticks now, std::uint8_t addr) {
  m_gap_done_visit = true;
  m_gap_addr = addr;
  ++m_stats.gap_polls;
  FrameSpec spec;
  spec.da = addr;
  spec.sa = m_ts;
  spec.fc = make_request_fc(RequestFn::FdlStatus);
  encode_as(FrameType::SD1, spec, m_tx);
  m_state = MacState::Await_Status_Response;
  m_slot_deadline = send(now, m_tx) + m_tsl;
  m_await_failed = false;
  arm(m_slot_deadline);
}

void ActiveStation::await_status_frame(const bus::RxFrame& f, const Telegram& t, bool valid) {
  const bus::Ticks now = f.end;
  if (!valid) {
    ++m_stats.invalid_replies;
    m_await_failed = true;
    arm(now + m_tid1);
    return;
  }
  const bool reply = t.type != FrameType::SC && t.type != FrameType::SD4 && !t.is_request() &&
                     t.da == m_ts && t.sa == m_gap_addr;
  if (!reply) {
    foreign_while_holding(f, t);
    return;
  }
  const StationType type = fc_station_type(t.fc);
  set_live(m_gap_addr, type);
  m_gap_next = next_addr(m_gap_addr);
  if (type == StationType::MasterReady) {
    // Admission: the station becomes our NS and gets the token now.
    m_las.set(m_gap_addr);
    ++m_stats.admissions;
  }
  m_pass_next = true;
  m_state = MacState::Use_Token;
  arm(now + m_tid1);
}

void ActiveStation::gap_failed(bus::Ticks now) {
  if (!m_las.test(m_gap_addr)) set_live(m_gap_addr, std::nullopt);
  m_gap_next = next_addr(m_gap_addr);
  m_pass_next = true;
  m_state = MacState::Use_Token;
  step(now);
}

void ActiveStation::equidistance_pause(bus::Ticks now, bus::Ticks until) {
  // Active pause while an FDL Status request to ourselves (SD1, 6 octets) and its slot time
  // fit before `until`, then a passive pause (docs/dp-equidistance.md).
  bus::Ticks wake = until;
  if (until - now >= bus::chars_to_ticks(6, m_p.baud) + m_tsl) {
    FrameSpec spec;
    spec.da = m_ts;
    spec.sa = m_ts;
    spec.fc = make_request_fc(RequestFn::FdlStatus);
    encode_as(FrameType::SD1, spec, m_tx);
    ++m_stats.pause_frames;
    wake = send(now, m_tx) + m_tsl;
  }
  m_hold_deadline += wake - now;
  m_state = MacState::Use_Token;
  arm(wake);
}

void ActiveStation::pass_token(bus::Ticks now) {
  m_pass_next = false;
  const std::uint8_t ns = compute_ns();
  if (ns != m_ns) m_pass_failures = 0;
  m_ns = ns;
  ++m_stats.tokens_passed;
  const bus::Ticks end = send(now, encode_token(ns, m_ts));
  if (ns == m_ts) {
    m_state = MacState::Pass_Token;
    arm(end);
  } else {
    m_state = MacState::Check_Token_Pass;
    m_slot_deadline = end + m_tsl;
    m_await_failed = false;
    arm(m_slot_deadline);
  }
}

void ActiveStation::check_pass_frame(const bus::RxFrame& f, const Telegram& t, bool valid) {
  const bus::Ticks now = f.end;
  if (!valid) {
    if (f.start > m_slot_deadline || now >= m_slot_deadline) {
      m_await_failed = true;
      arm(now + m_tid1);
    }
    return;
  }
  // Activity: the pass worked (a frame from NS), or someone else is running the bus. Either way
  // the token is no longer ours; the frame is handled as in Active_Idle.
  m_pass_failures = 0;
  m_state = MacState::Active_Idle;
  handle_passive(f, t, valid);
}

void ActiveStation::pass_failed(bus::Ticks now) {
  if (++m_pass_failures < kTokenPassAttempts) {
    ++m_stats.token_pass_retries;
  } else {
    // NS is gone: drop it from the LAS and pass to the next one.
    ++m_stats.stations_dropped;
    m_las.reset(m_ns);
    set_live(m_ns, std::nullopt);
    m_pass_failures = 0;
  }
  pass_token(now);
}

void ActiveStation::slot_expired(bus::Ticks now) {
  if (!m_await_failed && port().receiving()) return;  // a frame is arriving: judge it at its end
  switch (m_state) {
    case MacState::Await_Data_Response: request_failed(now); return;
    case MacState::Await_Status_Response: gap_failed(now); return;
    case MacState::Check_Token_Pass: pass_failed(now); return;
    default: return;
  }
}

void ActiveStation::foreign_while_holding(const bus::RxFrame& f, const Telegram& t) {
  // Another station transmits while we hold the token: there are two tokens. Ours goes.
  ++m_stats.duplicate_token;
  leave_ring(f.end);
  handle_passive(f, t, true);
}

}  // namespace pbvbus::fdl
