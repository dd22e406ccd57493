// Switched station, slave side (protocol-facts.md §G); decisions in redundant_slave.hpp.
#include "pbvbus/redundancy/redundant_slave.hpp"

#include <algorithm>
#include <stdexcept>

#include "pbvbus/dp/sap.hpp"

namespace pbvbus::redundancy {

std::string_view to_string(Role r) {
  switch (r) {
    case Role::SWaiting: return "S_WAITING";
    case Role::SPrimary: return "S_PRIMARY";
    case Role::Primary: return "PRIMARY";
    case Role::Backup: return "BACKUP";
    case Role::BpSwitchover: return "BP_SWITCHOVER";
    case Role::Failed: return "FAILED";
    case Role::Off: return "OFF";
  }
  return "?";
}

bus::Ticks draw_im_time(std::uint64_t seed, std::uint64_t n, bus::Ticks bound) {
  if (bound <= 0) return 0;
  // splitmix64 of (seed, n): portable, unlike the std distributions.
  std::uint64_t z = seed + (n + 1) * 0x9E3779B97F4A7C15ull;
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
  z ^= z >> 31;
  const bus::Ticks lo = bound / 2;
  const auto span = static_cast<std::uint64_t>(bound - lo) + 1;
  return lo + static_cast<bus::Ticks>(z % span);
}

std::string_view to_string(RedundancyMode m) {
  return m == RedundancyMode::Flying ? "flying" : "system";
}

/// One interface as seen by its FDL station: the engine, silenced when failed, with the
/// redundancy bookkeeping around each request.
class RedundantSlave::Port final : public fdl::ResponderUser {
 public:
  Port(RedundantSlave& rs, int i) : m_rs(rs), m_i(i) {}
  void on_power_on(bus::Ticks now) override {
    m_rs.m_if[m_i].engine->on_power_on(now);
    if (!m_rs.m_powered) m_rs.power_on(now);
  }
  void on_request(const fdl::Indication& ind, fdl::Reply& reply) override {
    m_rs.on_time(ind.now);
    if (!m_rs.m_powered || !m_rs.alive(m_i)) {  // a dead station or a failed interface
      reply.none();
      return;
    }
    auto& e = *m_rs.m_if[m_i].engine;
    const auto dx = e.stats().data_exchange;
    const auto rs = e.stats().refused;
    m_rs.before_request(m_i, ind.now);
    e.on_request(ind, reply);
    m_rs.after_request(m_i, ind.now, dx, rs);
  }
  bus::Ticks next_deadline() const override { return m_rs.next_deadline(); }
  void on_time(bus::Ticks now) override { m_rs.on_time(now); }

 private:
  RedundantSlave& m_rs;
  int m_i;
};

RedundantSlave::RedundantSlave(dp::SlaveConfig cfg, RedundantSlaveParams p)
    : m_p(p), m_hold_time(p.output_hold) {
  // A live partner answers a switchover request after 2 × link_delay; a shorter timeout would
  // make the requester PRIMARY while the partner still is: two primaries.
  if (m_p.switch_timeout <= 2 * m_p.link_delay)
    throw std::invalid_argument("switch_timeout must exceed 2 x link_delay");
  cfg.features.dpv1 = true;
  cfg.features.prm_cmd = cfg.features.prm_structure = true;
  for (int i = 0; i < 2; ++i) {
    dp::SlaveConfig c = cfg;
    c.on_prm_cmd = [this, i](const dp::PrmCmdView& v) { return handle_prm_cmd(i, v); };
    m_if[i].engine = std::make_unique<dp::SlaveEngine>(std::move(c));
    m_if[i].port = std::make_unique<Port>(*this, i);
    m_if[i].engine->application().on_alarm_ack(
        [this, i](std::uint8_t type, std::uint8_t slot, std::uint8_t seq) {
          alarm_acked(i, type, slot, seq);
        });
  }
  m_out.assign(m_if[0].engine->layout().outputs, 0);
  m_scratch.assign(m_out.size(), 0);
}

RedundantSlave::~RedundantSlave() = default;

fdl::ResponderUser& RedundantSlave::interface(int i) { return *m_if[i].port; }

int RedundantSlave::primary() const {
  for (int i = 0; i < 2; ++i)
    if (m_if[i].role == Role::Primary) return i;
  return -1;
}

RedState RedundantSlave::red_state(int i) const {
  const Iface& f = m_if[i];
  RedState s;
  if (f.role == Role::Off) return s;  // no power: nothing to report (nobody reads it either)
  if (f.role == Role::Failed) {  // a failed interface is known only as defective
    s.hardware_defective = true;
    return s;
  }
  s.primary = f.role == Role::Primary || f.role == Role::SPrimary;
  s.backup = f.role == Role::Backup || f.role == Role::BpSwitchover;
  s.hardware_defective = f.role == Role::Failed;
  s.data_exchange = f.role != Role::Failed && f.engine->state() == dp::SlaveState::DataExch;
  s.master_state_clear = f.master_state_clear;
  s.baudrate_found = f.baudrate_found;
  s.output_hold_started = s.primary && outputs_held();
  return s;
}

bool RedundantSlave::write_inputs(std::size_t module, std::span<const std::uint8_t> data) {
  bool ok = true;
  for (auto& f : m_if) ok = f.engine->application().write_inputs(module, data) && ok;
  return ok;
}

void RedundantSlave::emit(RedEvent::Kind k, bus::Ticks at, int iface, Role from, Role to) {
  if (m_cb) m_cb(RedEvent{k, at, iface, from, to});
}

// --- time -------------------------------------------------------------------------------------

void RedundantSlave::power_on(bus::Ticks now) {
  m_powered = true;
  m_link.clear();
  m_hold_deadline = bus::kNever;
  m_fresh_pending = true;  // the first outputs of the first PRIMARY end the start-up
  for (int i = 0; i < 2; ++i) {
    Iface& f = m_if[i];
    // A cold start: the engine restarts (Wait_Prm) and forgets the last PrmCmd; the
    // Prm_Cmd_Ack of a previous life must not show in the new diagnosis.
    f.engine->on_power_on(now);
    f.engine->application().clear_status(kStatusPrmCmdAck, 0);
    f.baudrate_found = f.master_state_clear = f.was_data_exch = f.ack_pending = false;
    f.cmd_spec = f.cmd_function = 0;
    f.switch_deadline = bus::kNever;
    f.im_ready_at = bus::kNever;
    f.im_wait = false;
    f.im_index = -1;
    f.last_heard = now;
    f.next_heartbeat = now;
    f.partner_lost = false;
    if (f.role == Role::Failed) continue;  // a defective interface stays defective
    const Role from = f.role;
    f.role = i == 0 ? Role::SPrimary : Role::SWaiting;
    // The first power-on is the start state, not a change; a return from power_off() is.
    if (from == Role::Off) emit(RedEvent::Kind::RoleChanged, now, i, from, f.role);
  }
  m_decided = false;
  m_swapped = false;
  m_tsprimary = m_p.tsprimary_start;
  m_alternate_at = now + m_tsprimary;
  refresh_status();
}

void RedundantSlave::power_off(bus::Ticks now) {
  if (!m_powered) return;
  on_time(now);
  // A dead station drives nothing: outputs 0 at once. That is not a hold expiring (no event)
  // and not a pulse: no module is powered to show one.
  std::fill(m_out.begin(), m_out.end(), 0);
  m_hold_deadline = bus::kNever;
  m_alternate_at = bus::kNever;
  m_fresh_pending = false;
  m_link.clear();    // messages on the internal link die with it
  m_alarms.clear();  // volatile: a restarted station has no alarms to repeat
  for (int i = 0; i < 2; ++i) {
    Iface& f = m_if[i];
    f.switch_deadline = bus::kNever;
    if (f.role == Role::Failed) continue;
    const Role from = f.role;
    f.role = Role::Off;
    emit(RedEvent::Kind::RoleChanged, now, i, from, Role::Off);
  }
  m_powered = false;
}

bus::Ticks RedundantSlave::next_deadline() const {
  if (!m_powered) return bus::kNever;
  bus::Ticks t = std::min(m_alternate_at, m_hold_deadline);
  if (!m_link.empty()) t = std::min(t, m_link.front().at);
  for (const auto& f : m_if) {
    t = std::min(t, f.engine->next_deadline());
    if (f.role == Role::Failed) continue;
    if (f.role == Role::BpSwitchover) t = std::min(t, f.switch_deadline);
    if (f.role == Role::BpSwitchover && f.im_wait) t = std::min(t, f.im_ready_at);
    t = std::min(t, f.next_heartbeat);
    if (!f.partner_lost) t = std::min(t, f.last_heard + m_p.supervision);
  }
  return t;
}

void RedundantSlave::on_time(bus::Ticks now) {
  if (!m_powered) return;
  for (;;) {
    const bus::Ticks t = next_deadline();
    if (t > now) break;
    // Engines (watchdogs) first, then the link, heartbeats, supervision, alternation, hold.
    for (auto& f : m_if)
      if (f.engine->next_deadline() <= t) f.engine->on_time(t);
    check_primary_lost_master(t);
    while (!m_link.empty() && m_link.front().at <= t) {
      const LinkMsg m = m_link.front();
      m_link.erase(m_link.begin());
      deliver(m, t);
    }
    for (int i = 0; i < 2; ++i) {
      Iface& f = m_if[i];
      if (f.role == Role::Failed) continue;
      if (f.next_heartbeat <= t) {
        send(i, Msg::Heartbeat, f.next_heartbeat);
        f.next_heartbeat += m_p.heartbeat_period;
      }
      if (!f.partner_lost && f.last_heard + m_p.supervision <= t) {
        f.partner_lost = true;
        emit(RedEvent::Kind::PartnerLost, f.last_heard + m_p.supervision, i);
        if (f.role == Role::Backup || f.role == Role::BpSwitchover) {
          if (f.role == Role::BpSwitchover) f.ack_pending = true;
          start_im(i, f.last_heard + m_p.supervision);
          become_primary(i, t);
        }
      }
      if (f.role == Role::BpSwitchover && f.switch_deadline <= t) {
        // No take-over within switch_timeout: the partner has failed without the supervision
        // noticing yet. Count it lost and take over, as a real IM does (command carried out:
        // Prm_Cmd_Ack as at a take-over).
        if (!f.partner_lost) {
          f.partner_lost = true;
          emit(RedEvent::Kind::PartnerLost, t, i);
        }
        f.ack_pending = true;
        become_primary(i, t);
      }
      if (f.role == Role::BpSwitchover && f.im_wait && f.im_ready_at <= t) become_primary(i, t);
    }
    if (m_alternate_at <= t) {
      for (int i = 0; i < 2; ++i) {
        if (m_if[i].role == Role::SPrimary) set_role(i, Role::SWaiting, t);
        else if (m_if[i].role == Role::SWaiting) set_role(i, Role::SPrimary, t);
      }
      m_tsprimary = std::min(2 * m_tsprimary, m_p.tsprimary_max);
      m_alternate_at = t + m_tsprimary;
    }
    if (m_hold_deadline <= t) {
      m_hold_deadline = bus::kNever;
      std::fill(m_out.begin(), m_out.end(), 0);
      emit(RedEvent::Kind::OutputHoldExpired, t, std::max(primary(), 0));
    }
    refresh_status();
    sync_alarms(t);
  }
}

// --- link ---------------------------------------------------------------------------------------

void RedundantSlave::send(int from, Msg m, bus::Ticks now) {
  if (!alive(from)) return;
  const LinkMsg lm{now + m_p.link_delay, 1 - from, m, m_if[from].role};
  const auto it = std::upper_bound(m_link.begin(), m_link.end(), lm,
                                   [](const LinkMsg& a, const LinkMsg& b) { return a.at < b.at; });
  m_link.insert(it, lm);
}

void RedundantSlave::deliver(const LinkMsg& m, bus::Ticks now) {
  const int i = m.to;
  Iface& f = m_if[i];
  if (!alive(i)) return;  // lost
  f.last_heard = now;
  if (f.partner_lost) {
    f.partner_lost = false;
    emit(RedEvent::Kind::PartnerBack, now, i);
  }
  switch (m.msg) {
    case Msg::Heartbeat:
      // A (re)started partner while this one is primary: no switch back, it becomes backup.
      if (f.role == Role::Primary &&
          (m.sender_role == Role::SWaiting || m.sender_role == Role::SPrimary))
        send(i, Msg::BecomeBackup, now);
      break;
    case Msg::SwitchReq:
      if (f.role == Role::Primary) {
        set_role(i, Role::Backup, now);
        send(i, Msg::TakeOver, now);
      }
      break;
    case Msg::TakeOver:
      if (f.role == Role::Backup || f.role == Role::BpSwitchover) {
        start_im(i, now);  // an autonomous hand-over starts here; a commanded one has started
        become_primary(i, now);
      }
      break;
    case Msg::BecomeBackup:
      if (f.role != Role::Primary) set_role(i, Role::Backup, now);
      break;
  }
}

// --- roles ----------------------------------------------------------------------------------------

void RedundantSlave::set_role(int i, Role r, bus::Ticks now) {
  Iface& f = m_if[i];
  const Role from = f.role;
  if (from == r) return;
  f.role = r;
  f.switch_deadline = r == Role::BpSwitchover ? now + m_p.switch_timeout : bus::kNever;
  if (r != Role::BpSwitchover) {  // the switchover is over (PRIMARY) or abandoned
    if (r == Role::Primary && f.im_index >= 0)
      m_im[static_cast<std::size_t>(f.im_index)].primary_at = now;
    f.im_ready_at = bus::kNever;
    f.im_wait = false;
    f.im_index = -1;
  }
  bool swapped = false;
  if (from == Role::Primary) lose_primary(now);
  if (r == Role::Primary) {
    m_decided = true;
    if (address_offset(i) != 0) {
      // Flying Redundancy: the primary address follows the PRIMARY role, at this instant.
      m_swapped = !m_swapped;
      swapped = true;
    }
    m_alternate_at = bus::kNever;
    if (m_if[1 - i].role == Role::SPrimary || m_if[1 - i].role == Role::SWaiting)
      send(i, Msg::BecomeBackup, now);
    if (f.ack_pending) set_ack(i);
    // Outputs come from this interface's next accepted Data_Exchange.
  }
  if (r == Role::Backup && f.ack_pending) set_ack(i);
  emit(RedEvent::Kind::RoleChanged, now, i, from, r);
  if (swapped) emit(RedEvent::Kind::AddressSwap, now, i);
  refresh_status();
}

void RedundantSlave::start_im(int i, bus::Ticks now) {
  Iface& f = m_if[i];
  if (f.im_ready_at != bus::kNever) return;  // this switchover has its time already
  if (!m_decided || m_p.im_switchover_bound <= 0) {
    // Start-up (the first Primary_Request is not a switchover), or no IM time: nothing drawn.
    f.im_ready_at = now;
    return;
  }
  const bus::Ticks d = draw_im_time(m_p.im_seed, m_im.size(), m_p.im_switchover_bound);
  f.im_ready_at = now + d;
  f.im_index = static_cast<int>(m_im.size());
  m_im.push_back({i, now, d, bus::kNever});
}

void RedundantSlave::become_primary(int i, bus::Ticks now) {
  Iface& f = m_if[i];
  if (f.im_ready_at != bus::kNever && now < f.im_ready_at) {
    // The link steps are done; the IM needs the rest of its time: BP_SWITCHOVER (Red_State
    // Backup), outputs held, no Prm_Cmd_Ack yet.
    set_role(i, Role::BpSwitchover, now);
    f.switch_deadline = bus::kNever;
    f.im_wait = true;
    return;
  }
  set_role(i, Role::Primary, now);
}

void RedundantSlave::lose_primary(bus::Ticks now) {
  if (m_hold_deadline == bus::kNever) m_hold_deadline = now + m_hold_time;
  m_fresh_pending = true;
}

void RedundantSlave::take_outputs(int i, bus::Ticks now) {
  auto& app = m_if[i].engine->application();
  for (std::size_t m = 0; m < app.modules(); ++m) {
    const auto& ml = app.module(m);
    if (ml.out_len == 0) continue;
    app.read_outputs(m, std::span(m_scratch).subspan(ml.out_offset, ml.out_len));
  }
  std::copy(m_scratch.begin(), m_scratch.end(), m_out.begin());
  m_hold_deadline = bus::kNever;
  if (m_fresh_pending) {
    m_fresh_pending = false;
    emit(RedEvent::Kind::FreshOutputs, now, i);
  }
}

bool RedundantSlave::partner_in_dx(int i) const {
  const int p = 1 - i;
  return alive(p) && !m_if[i].partner_lost &&
         m_if[p].engine->state() == dp::SlaveState::DataExch;
}

void RedundantSlave::check_primary_lost_master(bus::Ticks now) {
  for (int i = 0; i < 2; ++i) {
    Iface& f = m_if[i];
    const bool dx = f.engine->state() == dp::SlaveState::DataExch;
    if (f.role == Role::Primary && f.was_data_exch && !dx) {
      lose_primary(now);  // the primary's engine has set its own image safe; hold the backplane
      if (m_p.autonomous_switchover && partner_in_dx(i) && m_if[1 - i].role == Role::Backup) {
        set_role(i, Role::Backup, now);
        send(i, Msg::TakeOver, now);
      }
    }
    f.was_data_exch = dx;
  }
}

// --- requests ---------------------------------------------------------------------------------------

void RedundantSlave::before_request(int i, bus::Ticks /*now*/) { m_if[i].baudrate_found = true; }

void RedundantSlave::after_request(int i, bus::Ticks now, std::uint64_t dx_before,
                                   std::uint64_t rs_before) {
  Iface& f = m_if[i];
  const auto& st = f.engine->stats();
  const bool dx_ok = st.data_exchange != dx_before && st.refused == rs_before &&
                     f.engine->state() == dp::SlaveState::DataExch;
  if (dx_ok && f.role == Role::Primary) take_outputs(i, now);
  check_primary_lost_master(now);
  refresh_status();
  sync_alarms(now);
}

dp::PrmCmdResult RedundantSlave::handle_prm_cmd(int i, const dp::PrmCmdView& v) {
  PrmCmd c;
  if (decode_prm_cmd(v.block, c) != PrmCmdError::None) return dp::PrmCmdResult::Reject;
  Iface& f = m_if[i];
  f.cmd_spec = c.specifier_octet();
  f.cmd_function = c.function();
  f.master_state_clear = c.master_state_clear;
  m_hold_time = c.output_hold_ticks();
  f.ack_pending = true;
  if (c.primary_request) {
    switch (f.role) {
      case Role::Primary: set_ack(i); break;
      case Role::Backup:
      case Role::SWaiting:
      case Role::SPrimary: {
        // With a PRIMARY partner (e.g. this interface was just repaired and restarts in
        // S_WAITING while the other carries the process), Primary_Request is a commanded
        // switchover through the partner, never a second primary. A partner that has failed
        // without being counted lost yet is, for this interface, still what it was: it asks,
        // gets no answer and takes over after switch_timeout.
        const Iface& partner = m_if[1 - i];
        const Role believed = partner.role == Role::Failed ? partner.failed_from : partner.role;
        start_im(i, v.now);
        if (!f.partner_lost && believed == Role::Primary) {
          set_role(i, Role::BpSwitchover, v.now);
          send(i, Msg::SwitchReq, v.now);
        } else {
          become_primary(i, v.now);
        }
        break;
      }
      case Role::BpSwitchover:
      case Role::Failed:
      case Role::Off: break;
    }
  } else {
    set_ack(i);
  }
  refresh_status();
  return dp::PrmCmdResult::Accept;
}

void RedundantSlave::set_ack(int i) {
  Iface& f = m_if[i];
  f.ack_pending = false;
  const std::array<std::uint8_t, 4> d{f.cmd_function, red_state(i).octet(),
                                      red_state(1 - i).octet(), 0};
  f.engine->application().set_status(kStatusPrmCmdAck, 0, f.cmd_spec, d);
}

void RedundantSlave::refresh_status() {
  // Runs after every request: each Red_State once (bench/switched_io_bench.cpp profile).
  const std::uint8_t state[2] = {red_state(0).octet(), red_state(1).octet()};
  for (int i = 0; i < 2; ++i) {
    Iface& f = m_if[i];
    const std::uint8_t own = state[i];
    const std::uint8_t partner = state[1 - i];
    const std::int32_t key = (f.cmd_spec << 16) | (own << 8) | partner;
    if (key == f.status_cache) continue;
    f.status_cache = key;
    const std::array<std::uint8_t, 4> d{0, own, partner, 0};
    f.engine->application().set_status(kStatusRedStatus, 0,
                                       static_cast<std::uint8_t>(f.cmd_spec & 0xF8), d);
  }
}

// --- faults ------------------------------------------------------------------------------------------

void RedundantSlave::fail_interface(int i, bus::Ticks now) {
  on_time(now);
  if (m_if[i].role != Role::Failed) m_if[i].failed_from = m_if[i].role;
  set_role(i, Role::Failed, now);
  m_if[i].was_data_exch = false;
  sync_alarms(now);
}

void RedundantSlave::repair_interface(int i, bus::Ticks now) {
  on_time(now);
  Iface& f = m_if[i];
  if (f.role != Role::Failed) return;
  if (!m_powered) {  // repaired while the station has no power: it starts with the station
    f.role = Role::Off;
    emit(RedEvent::Kind::RoleChanged, now, i, Role::Failed, Role::Off);
    return;
  }
  f.engine->on_power_on(now);  // the interface restarts: Wait_Prm
  f.baudrate_found = f.master_state_clear = f.ack_pending = false;
  f.last_heard = now;
  f.partner_lost = false;
  f.next_heartbeat = now;
  set_role(i, Role::SWaiting, now);
  sync_alarms(now);
}

// --- DP-V1 alarms over the active channel -----------------------------------------------------------

dp::AlarmResult RedundantSlave::raise_alarm(std::uint8_t type, std::uint8_t slot,
                                            dp::AlarmSpec spec, bool add_ack,
                                            std::span<const std::uint8_t> data, bus::Ticks now,
                                            std::uint8_t* seq_nr) {
  if (dp::alarm_enable_bit(type) == 0 || data.size() > 59) return dp::AlarmResult::BadArgument;
  if (!m_powered) return dp::AlarmResult::Closed;  // a dead station raises nothing
  if (m_alarms.size() >= kMaxStationAlarms) return dp::AlarmResult::LimitExpired;
  on_time(now);
  StationAlarm a;
  a.type = type;
  a.slot = slot;
  a.spec = spec;
  a.add_ack = add_ack;
  a.data.assign(data.begin(), data.end());
  m_alarms.push_back(std::move(a));
  sync_alarms(now);
  if (seq_nr && m_alarms.back().iface >= 0) *seq_nr = m_alarms.back().seq;
  return dp::AlarmResult::Ok;
}

void RedundantSlave::sync_alarms(bus::Ticks now) {
  if (!m_powered || m_alarms.empty()) return;
  const int p = primary();
  for (auto& a : m_alarms) {
    if (a.iface < 0) continue;
    dp::SlaveEngine& e = *m_if[a.iface].engine;
    // The engine drops its alarms whenever it leaves (or re-enters) Data_Exch.
    const bool there =
        e.state() == dp::SlaveState::DataExch && e.stats().data_exch_entries == a.dx_entry;
    if (a.iface != p && there) {
      // No longer the PRIMARY: take it out of that diagnosis (the only way the dp layer offers
      // is an Alarm_Ack from the engine's owner, played internally; see the header).
      const std::array<std::uint8_t, 4> pdu{dp::kFnAlarmAck, a.slot, a.type,
                                            dp::alarm_specifier(a.seq, a.add_ack, a.spec)};
      fdl::Indication ind;
      ind.now = now;
      ind.sa = e.master_address();
      ind.da = 0;  // any unicast address: the engine does not check its own
      ind.fn = fdl::RequestFn::SrdHigh;
      ind.dsap = dp::kSapC1Alarm;
      ind.ssap = dp::kSapMs1;
      ind.data = pdu;
      fdl::Reply ignored;
      m_withdrawing = true;
      e.on_request(ind, ignored);
      m_withdrawing = false;
    }
    if (a.iface != p || !there) a.iface = -1;
  }
  if (p < 0) return;
  dp::SlaveEngine& e = *m_if[p].engine;
  for (auto& a : m_alarms) {
    if (a.iface >= 0) continue;
    std::uint8_t seq = 0;
    const dp::AlarmResult r =
        e.application().raise_alarm(a.type, a.slot, a.spec, a.add_ack, a.data, &seq);
    if (r == dp::AlarmResult::Ok) {
      a.iface = p;
      a.seq = seq;
      a.dx_entry = e.stats().data_exch_entries;
    } else if (r == dp::AlarmResult::Closed) {
      break;  // not in Data_Exch with DP-V1: none fits; a type or limit refusal may let others
    }
  }
}

void RedundantSlave::alarm_acked(int i, std::uint8_t type, std::uint8_t slot, std::uint8_t seq) {
  if (m_withdrawing) return;  // our own withdrawal, not the master's acknowledgement
  const auto it = std::find_if(m_alarms.begin(), m_alarms.end(), [&](const StationAlarm& a) {
    return a.iface == i && a.type == type && a.slot == slot && a.seq == seq;
  });
  if (it == m_alarms.end()) return;  // not one of the station's (raised on the engine directly)
  m_alarms.erase(it);
  ++m_alarms_acked;
}

}  // namespace pbvbus::redundancy
