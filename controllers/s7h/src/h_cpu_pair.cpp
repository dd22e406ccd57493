#include "pbvbus/s7h/h_cpu_pair.hpp"

#include <algorithm>
#include <stdexcept>
#include <utility>

namespace pbvbus::devices {

std::string_view to_string(CpuState s) {
  switch (s) {
    case CpuState::Off:
      return "OFF";
    case CpuState::Stop:
      return "STOP";
    case CpuState::Startup:
      return "STARTUP";
    case CpuState::Run:
      return "RUN";
    case CpuState::LinkUp:
      return "LINK-UP";
    case CpuState::Update:
      return "UPDATE";
    case CpuState::Hold:
      return "HOLD";
    case CpuState::ErrorSearch:
      return "ERROR-SEARCH";
    case CpuState::Defective:
      return "DEFECTIVE";
    case CpuState::SyncUp:
      return "SYNCUP";
  }
  return "?";
}

std::string_view to_string(CpuRole r, HProfile p) {
  const bool r1500 = p == HProfile::S7_1500RH;
  switch (r) {
    case CpuRole::None:
      return "none";
    case CpuRole::Master:
      return r1500 ? "primary" : "master";
    case CpuRole::Standby:
      return r1500 ? "backup" : "standby";
  }
  return "?";
}

std::string_view to_string(SystemMode m, HProfile p) {
  const bool r1500 = p == HProfile::S7_1500RH;
  switch (m) {
    case SystemMode::Stop:
      return "Stop";
    case SystemMode::Startup:
      return "Startup";
    case SystemMode::Solo:
      return r1500 ? "RUN-Solo" : "Solo";
    case SystemMode::LinkUp:
      return "Link-up";
    case SystemMode::Update:
      return "Update";
    case SystemMode::Redundant:
      return r1500 ? "RUN-Redundant" : "Redundant";
    case SystemMode::Hold:
      return "Hold";
    case SystemMode::SyncUp:
      return "SYNCUP";
  }
  return "?";
}

std::string_view to_string(Redf r) {
  switch (r) {
    case Redf::Off:
      return "off";
    case Redf::Flash0_5Hz:
      return "0.5 Hz";
    case Redf::Flash2Hz:
      return "2 Hz";
    case Redf::On:
      return "on";
  }
  return "?";
}

std::string_view to_string(HReason r) {
  switch (r) {
    case HReason::None:
      return "none";
    case HReason::MasterLost:
      return "master CPU lost";
    case HReason::MasterStop:
      return "master CPU in STOP";
    case HReason::StandbyLost:
      return "standby CPU lost";
    case HReason::StandbyStop:
      return "standby CPU in STOP";
    case HReason::LinkLost:
      return "redundant link lost";
    case HReason::ComparisonError:
      return "comparison error";
    case HReason::OneSidedOb121:
      return "one-sided OB 121";
    case HReason::MasterSwap:
      return "master/standby swap";
    case HReason::UpdateTimeout:
      return "update timeout";
    case HReason::ChecksumError:
      return "checksum error";
  }
  return "?";
}

std::string_view to_string(HChange c) {
  switch (c) {
    case HChange::Allowed:
      return "allowed change";
    case HChange::StructuralFbInterface:
      return "structural FB-interface change";
    case HChange::GlobalDb:
      return "global-DB change";
  }
  return "?";
}

std::string_view to_string(HChangeResult r) {
  switch (r) {
    case HChangeResult::Loaded:
      return "loaded";
    case HChangeResult::BothStopped:
      return "both CPUs STOP";
    case HChangeResult::Refused:
      return "refused";
  }
  return "?";
}

namespace {
bool syncing(CpuState s) {
  return s == CpuState::LinkUp || s == CpuState::Update || s == CpuState::SyncUp;
}
bool running(CpuState s) {
  return s == CpuState::Startup || s == CpuState::Run || s == CpuState::Hold || syncing(s);
}
void check_rack(int r) {
  if (r != 0 && r != 1) throw std::out_of_range("HCpuPair: rack must be 0 or 1");
}
}  // namespace

HCpuPair::HCpuPair(HCpuPairParams p) : m_p(std::move(p)) {
  if (m_p.startup_time < 0 || m_p.link_up_time < 0 || (m_p.update_time && *m_p.update_time < 0) ||
      m_p.role_window <= 0 || m_p.self_test_time < 0)
    throw std::invalid_argument("HCpuPair: negative duration");
  if (m_p.load_memory_copy_time &&
      (*m_p.load_memory_copy_time < 0 || *m_p.load_memory_copy_time > m_p.link_up_time))
    throw std::invalid_argument("HCpuPair: load_memory_copy_time must lie in 0..link_up_time");
  // The model must not run on a set the checker rejects (the scenario loader checks first).
  for (const HViolation& v : check_h_parameters(m_p.h_parameters).violations)
    if (v.severity == Severity::Error) throw std::invalid_argument(v.message);
  for (int r = 0; r < 2; ++r) m_cpu[r].switch_run = m_p.switch_run[r];
}

// ---------------------------------------------------------------- update model

namespace {
/// A configured H parameter that is monitored (set and not 0), in ticks.
std::optional<bus::Ticks> monitored(const std::optional<Us>& v) {
  if (!v || *v <= 0) return std::nullopt;
  return to_ticks(*v);
}
}  // namespace

bus::Ticks HCpuPair::update_time() const {
  const bus::Ticks copy =
      m_p.update_time ? *m_p.update_time : to_ticks(t_p15_awp(m_p.update_db_kb));
  const std::optional<bus::Ticks> tph = monitored(m_p.h_parameters.t_ph);
  // Without T_PH the output copy lies inside the copy time (T_P15_OD = 50 ms < the 75 ms base
  // of T_P15_AWP), so an explicit update_time stays exact.
  return tph ? std::max(copy, to_ticks(kOutputCopyTime) + *tph) : copy;
}

bool HCpuPair::io_frozen() const {
  return m_update_running && m_window && m_window->t3 <= m_now && m_now < m_window->t5;
}

bool HCpuPair::outputs_held_by_both() const {
  return m_update_running && m_window && m_window->t4 <= m_now && m_now < m_window->t5;
}

bool HCpuPair::interrupts_held() const {
  return m_update_running && m_window && m_window->t1 <= m_now && m_now < m_window->t5;
}

std::uint16_t HCpuPair::record_job_result(int sfc, bus::Ticks now) {
  run_due(now);
  if (!interrupts_held()) return 0;  // [t1, t5): the update restrictions
  if (sfc == 51) return 0x8085;
  if (sfc == 13 || (sfc >= 55 && sfc <= 59)) return 0x80C3;
  return 0;
}

void HCpuPair::begin_update(int s, bus::Ticks now) {
  const int m = partner(s);
  set_state(s, CpuState::Update, now, "link-up done");
  const bus::Ticks w = update_time();
  const bus::Ticks tph = monitored(m_p.h_parameters.t_ph).value_or(0);
  // t1 = t3: the delay stages (data records, messages, classes <= 15) take no time here.
  UpdateWindow win;
  win.t1 = now;
  win.t3 = now;
  win.t5 = now + w;
  win.t4 = win.t5 - tph;
  m_window = win;
  m_update_running = true;
  m_phase_at = tph > 0 ? win.t4 : bus::kNever;
  // F19: the first monitoring limit shorter than the part of the update it covers (each
  // covers W from t1 = t2 = t3 here). With a valid set T_P15 < comm delay < cycle extension,
  // so T_P15 is reached first; the others matter only when T_P15 is 0 (not monitored).
  m_update_abort_at = bus::kNever;
  m_update_limit.clear();
  const std::pair<const std::optional<Us>*, const char*> limits[] = {
      {&m_p.h_parameters.t_p15, "T_P15"},
      {&m_p.h_parameters.max_comm_delay, "max communication delay"},
      {&m_p.h_parameters.max_cycle_extension, "max scan-cycle extension"}};
  for (const auto& [v, name] : limits) {
    const std::optional<bus::Ticks> l = monitored(*v);
    if (l && *l < w && now + *l < m_update_abort_at) {
      m_update_abort_at = now + *l;
      m_update_limit = name;
    }
  }
  m_cpu[s].deadline = std::min(win.t5, m_update_abort_at);
  const std::string text =
      "UPDATE: data-record jobs refused, OB 1 and classes <= 15 delayed; "
      "no OB and no I/O update until Redundant mode (" +
      format_ms(ticks_to_us_ceil(w)) + ")";
  diag(s, now, text);
  diag(m, now, text);
}

void HCpuPair::output_hold_begins(bus::Ticks now) {
  for (int r = 0; r < 2; ++r)
    if (powered(r))
      diag(r, now, "UPDATE: outputs copied to the standby; both CPUs drive the outputs (T_PH)");
}

void HCpuPair::close_window(bus::Ticks now, bool aborted, bool timed_out) {
  if (!m_update_running) return;
  m_update_running = false;
  m_phase_at = bus::kNever;
  m_update_abort_at = bus::kNever;
  m_window->t5 = now;
  m_window->t4 = std::min(m_window->t4, now);
  m_window->aborted = aborted;
  m_window->timed_out = timed_out;
}

void HCpuPair::update_timeout(int s, bus::Ticks now) {
  const int m = partner(s);
  Cpu& c = m_cpu[s];
  const std::string why = "update timeout: " + m_update_limit + " exceeded";
  close_window(now, true, true);
  stop_cpu(s, now, why);
  diag(s, now, "SDBs re-read after the update timeout");
  diag(m, now, "update aborted (" + why + "): Solo mode with the same master");
  ob(m, 72, HReason::UpdateTimeout, now);
  if (m_tries < kUpdateMaxTries) {
    c.retry_at = now + kUpdateRetryDelayTicks;
    diag(s, now, "link-up retry in 60 s (try " + std::to_string(m_tries + 1) + ")");
  } else {
    const std::string t =
        "update failed " + std::to_string(m_tries) + " times: link-up must be restarted manually";
    diag(s, now, t);
    diag(m, now, t);
  }
}

void HCpuPair::retry_due(int r, bus::Ticks now) {
  Cpu& c = m_cpu[r];
  c.retry_at = bus::kNever;
  if (powered(r) && c.state == CpuState::Stop && c.role == CpuRole::Standby && c.switch_run &&
      !c.reset_request) {
    c.retrying = true;
    c.want_run = true;
    diag(r, now, "link-up retry after the update timeout");
  } else {
    diag(r, now, "link-up retry dropped: the standby is not ready");
  }
}

void HCpuPair::set_reset_request(int r, bus::Ticks now) {
  Cpu& c = m_cpu[r];
  c.reset_request = true;
  const bool copying =
      c.link_up_start != bus::kNever && now - c.link_up_start < load_memory_copy_time();
  if (copying)
    diag(r, now, "reset request: link-up interrupted during the load-memory copy", 0x6523);
  else
    diag(r, now, "reset request: link-up interrupted");
}

// ---------------------------------------------------------------- queries

int HCpuPair::master() const {
  if (m_cpu[0].role == CpuRole::Master) return 0;
  if (m_cpu[1].role == CpuRole::Master) return 1;
  return -1;
}

int HCpuPair::master_count() const {
  return (m_cpu[0].role == CpuRole::Master ? 1 : 0) + (m_cpu[1].role == CpuRole::Master ? 1 : 0);
}

SystemMode HCpuPair::mode_of_master(int m) const {
  switch (m_cpu[m].state) {
    case CpuState::Startup:
      return SystemMode::Startup;
    case CpuState::Hold:
      return SystemMode::Hold;
    case CpuState::SyncUp:
      return SystemMode::SyncUp;
    case CpuState::Run:
      break;
    default:
      return SystemMode::Stop;
  }
  const int s = partner(m);
  if (!linked(m) || m_cpu[s].role != CpuRole::Standby) return SystemMode::Solo;
  switch (m_cpu[s].state) {
    case CpuState::Startup:
    case CpuState::LinkUp:
      return SystemMode::LinkUp;
    case CpuState::Update:
      return SystemMode::Update;
    case CpuState::Run:
      return SystemMode::Redundant;
    case CpuState::SyncUp:
      return SystemMode::SyncUp;
    default:
      return SystemMode::Solo;
  }
}

SystemMode HCpuPair::system_mode() const {
  const int m = master();
  return m < 0 ? SystemMode::Stop : mode_of_master(m);
}

SystemMode HCpuPair::system_mode(int r) const {
  check_rack(r);
  if (!powered(r)) return SystemMode::Stop;
  if (m_cpu[r].role == CpuRole::Master) return mode_of_master(r);
  const int p = partner(r);
  if (m_cpu[r].role == CpuRole::Standby && linked(r) && m_cpu[p].role == CpuRole::Master)
    return mode_of_master(p);
  return SystemMode::Stop;
}

bool HCpuPair::accesses_switched_io(int r) const {
  const Cpu& c = m_cpu[r];
  return powered(r) && c.role == CpuRole::Master && c.state != CpuState::Defective &&
         c.state != CpuState::ErrorSearch;
}

bool HCpuPair::dp_master_running(int r) const {
  const Cpu& c = m_cpu[r];
  if (!powered(r) || c.state == CpuState::Defective || c.state == CpuState::ErrorSearch)
    return false;
  if (c.role == CpuRole::Master) return true;
  if (c.role == CpuRole::Standby)
    return c.state == CpuState::Update || c.state == CpuState::Run || c.state == CpuState::SyncUp;
  return false;
}

bool HCpuPair::dp_master_operate(int r) const {
  const CpuState s = m_cpu[r].state;
  return s == CpuState::Run || s == CpuState::SyncUp;
}

CpuLeds HCpuPair::leds(int r) const {
  check_rack(r);
  CpuLeds l;
  if (!powered(r)) return l;
  l.mstr = m_cpu[r].role == CpuRole::Master;
  l.rack0 = r == 0;
  l.rack1 = r == 1;
  switch (system_mode(r)) {
    case SystemMode::LinkUp:
    case SystemMode::SyncUp:
      l.redf = Redf::Flash0_5Hz;
      break;
    case SystemMode::Update:
      l.redf = Redf::Flash2Hz;
      break;
    case SystemMode::Redundant:
      l.redf = Redf::Off;
      break;
    default:
      l.redf = Redf::On;
      break;
  }
  const bool partner_off = !powered(partner(r));
  l.ifm1f = !m_fibre_ok[0] || partner_off;
  l.ifm2f = !m_fibre_ok[1] || partner_off;
  return l;
}

bus::Ticks HCpuPair::next_deadline() const {
  bus::Ticks t = m_phase_at;
  for (const Cpu& c : m_cpu) t = std::min({t, c.deadline, c.pending_master, c.retry_at});
  return t;
}

// ---------------------------------------------------------------- records

void HCpuPair::emit(HEvent e) {
  m_events.push_back(e);
  if (m_cb) m_cb(m_events.back());
}

void HCpuPair::diag(int r, bus::Ticks now, std::string text, std::uint16_t code) {
  Cpu& c = m_cpu[r];
  c.diag.push_back(DiagEntry{now, c.role, code, std::move(text)});
  while (c.diag.size() > m_p.diag_capacity) c.diag.pop_front();
}

void HCpuPair::set_state(int r, CpuState s, bus::Ticks now, std::string_view why) {
  Cpu& c = m_cpu[r];
  if (c.state == s) return;
  // The standby leaves UPDATE: the update window ends (Redundant/swap, or aborted).
  if (c.state == CpuState::Update) close_window(now, s != CpuState::Run, false);
  if (c.state == CpuState::LinkUp) c.update_waiting = false;  // SFC 90 wait ends with LINK-UP
  HEvent e;
  e.kind = HEvent::Kind::State;
  e.at = now;
  e.rack = r;
  e.from_state = c.state;
  e.to_state = s;
  c.state = s;
  if (s == CpuState::Off || s == CpuState::ErrorSearch || s == CpuState::Defective) {
    // A CPU that carries no connections breaks every one it had (h_connections.hpp).
    c.connections = 0;
    ++c.connection_epoch;
  }
  e.role = c.role;
  emit(e);
  std::string t = std::string(to_string(e.from_state)) + " -> " + std::string(to_string(s));
  if (!why.empty()) t += " (" + std::string(why) + ")";
  if (s != CpuState::Off) diag(r, now, std::move(t));
}

void HCpuPair::set_role(int r, CpuRole role, bus::Ticks now, std::string_view why) {
  Cpu& c = m_cpu[r];
  if (c.role == role) return;
  HEvent e;
  e.kind = HEvent::Kind::Role;
  e.at = now;
  e.rack = r;
  e.from_role = c.role;
  e.role = role;
  c.role = role;
  if (role != CpuRole::None) c.remembered = role;
  emit(e);
  if (role != CpuRole::None) {
    std::string t = "role: " + std::string(to_string(role, m_p.profile));
    if (!why.empty()) t += " (" + std::string(why) + ")";
    diag(r, now, std::move(t));
  }
}

void HCpuPair::ob(int r, int ob_nr, HReason why, bus::Ticks now, std::uint16_t code) {
  HEvent e;
  e.kind = HEvent::Kind::Ob;
  e.at = now;
  e.rack = r;
  e.role = m_cpu[r].role;
  e.ob = ob_nr;
  e.code = code;
  e.reason = why;
  emit(e);
  diag(r, now, "OB " + std::to_string(ob_nr) + ": " + std::string(to_string(why)), code);
}

// ---------------------------------------------------------------- time

void HCpuPair::on_time(bus::Ticks now) {
  run_due(now);
}

void HCpuPair::run_due(bus::Ticks now) {
  for (;;) {
    int r = -1;
    bus::Ticks t = bus::kNever;
    for (int i = 0; i < 2; ++i) {
      const Cpu& c = m_cpu[i];
      const bus::Ticks d = std::min({c.deadline, c.pending_master, c.retry_at});
      if (d < t) {
        t = d;
        r = i;
      }
    }
    // t4 (output hold) only when no CPU deadline comes first or at the same time: an abort
    // at t4 wins, the outputs were not copied.
    if (m_phase_at < t && m_phase_at <= now) {
      m_now = std::max(m_now, m_phase_at);
      const bus::Ticks at = m_phase_at;
      m_phase_at = bus::kNever;
      output_hold_begins(at);
      continue;
    }
    if (r < 0 || t > now) break;
    m_now = std::max(m_now, t);
    expire(r, t);
    after_step(t);
  }
  m_now = std::max(m_now, now);
}

void HCpuPair::expire(int r, bus::Ticks now) {
  Cpu& c = m_cpu[r];
  if (c.pending_master <= now && c.pending_master <= c.deadline) {
    c.pending_master = bus::kNever;
    set_role(r, CpuRole::Master, now, "partner not started within the role window");
    return;
  }
  if (c.retry_at <= now && c.retry_at <= c.deadline) {
    retry_due(r, now);
    return;
  }
  c.deadline = bus::kNever;
  const int p = partner(r);
  switch (c.state) {
    case CpuState::Startup:
      set_state(r, CpuState::Run, now, "startup done");
      break;
    case CpuState::LinkUp:
      if (m_update_disabled) {  // SFC 90 MODE 3: wait in LINK-UP until MODE 4
        c.update_waiting = true;
        diag(r, now, "link-up done: update disabled (SFC 90), waiting");
        diag(p, now, "link-up done: update disabled (SFC 90), waiting");
      } else {
        begin_update(r, now);
      }
      break;
    case CpuState::Update:
      if (m_update_abort_at <= now)
        update_timeout(r, now);
      else
        finish_update(r, now);
      break;
    case CpuState::SyncUp:
      finish_update(r, now);
      break;
    case CpuState::ErrorSearch:
      if (c.hw_fault) {
        make_defective(r, now, "self-test: fault found");
      } else {
        diag(r, now, "self-test: no fault found");
        if (c.switch_run && c.role == CpuRole::Standby && linked(r) &&
            m_cpu[p].role == CpuRole::Master && m_cpu[p].state == CpuState::Run &&
            mode_of_master(p) == SystemMode::Solo && !m_link_up_disabled)
          begin_link_up(r, now, Pending::Relink);
        else if (c.switch_run && c.role == CpuRole::Standby && m_link_up_disabled) {
          // SFC 90 MODE 0: STOP with the start request kept; MODE 1 links up (no swap then).
          stop_cpu(r, now, "self-test done, link-up disabled (SFC 90)");
          c.want_run = true;
        } else
          stop_cpu(r, now, "self-test done, no link-up possible");
      }
      break;
    default:
      break;
  }
}

void HCpuPair::evaluate(bus::Ticks now) {
  for (int r = 0; r < 2; ++r) {
    Cpu& c = m_cpu[r];
    // A standby that sees over a whole link that its partner is off is the only CPU: master.
    if (c.role == CpuRole::Standby && c.state != CpuState::Defective && link_whole() &&
        !powered(partner(r)))
      set_role(r, CpuRole::Master, now, "only CPU");
    if (c.state != CpuState::Stop || !c.want_run) continue;
    if (c.reset_request) {  // F20: no start until MRES
      c.want_run = false;
      continue;
    }
    if (c.role == CpuRole::Master) {
      c.want_run = false;
      set_state(r, CpuState::Startup, now, "start request");
      c.deadline = now + m_p.startup_time;
    } else if (c.role == CpuRole::Standby && linked(r)) {
      const int p = partner(r);
      const Cpu& q = m_cpu[p];
      if (q.role != CpuRole::Master) continue;
      if (q.state == CpuState::Hold) {
        c.want_run = false;
        diag(r, now, "link-up not possible: master CPU in HOLD");
        diag(p, now, "link-up request of the standby CPU refused: HOLD");
      } else if (q.state == CpuState::Run && mode_of_master(p) == SystemMode::Solo) {
        if (m_link_up_disabled) {  // SFC 90 MODE 0: the request waits for MODE 1
          if (!c.link_up_waits) diag(r, now, "link-up request waits: link-up disabled (SFC 90)");
          c.link_up_waits = true;
          continue;
        }
        begin_link_up(r, now, Pending::None);
      }
    }
  }
}

void HCpuPair::after_step(bus::Ticks now) {
  evaluate(now);
  const SystemMode m = system_mode();
  if (m != m_mode) {
    HEvent e;
    e.kind = HEvent::Kind::SystemMode;
    e.at = now;
    const int r = master();
    e.rack = r < 0 ? 0 : r;
    e.role = r < 0 ? CpuRole::None : CpuRole::Master;
    e.from_mode = m_mode;
    e.to_mode = m;
    m_mode = m;
    emit(e);
  }
}

// ---------------------------------------------------------------- transitions

void HCpuPair::stop_cpu(int r, bus::Ticks now, std::string_view why) {
  Cpu& c = m_cpu[r];
  c.deadline = bus::kNever;
  c.after_update = Pending::None;
  c.hold_remaining = -1;
  c.want_run = false;
  set_state(r, CpuState::Stop, now, why);
}

void HCpuPair::make_defective(int r, bus::Ticks now, std::string_view why) {
  Cpu& c = m_cpu[r];
  c.defective = true;
  c.deadline = bus::kNever;
  c.after_update = Pending::None;
  c.want_run = false;
  set_state(r, CpuState::Defective, now, why);
  if (c.role == CpuRole::Master) {
    // A DEFECTIVE CPU is never master: a linked standby partner takes the role (in its state).
    set_role(r, CpuRole::Standby, now, "defective");
    const int p = partner(r);
    if (linked(r) && m_cpu[p].role == CpuRole::Standby && m_cpu[p].state != CpuState::Defective)
      set_role(p, CpuRole::Master, now, "partner CPU defective");
  }
}

void HCpuPair::begin_link_up(int s, bus::Ticks now, Pending after) {
  Cpu& c = m_cpu[s];
  const int m = partner(s);
  c.want_run = false;
  c.link_up_waits = false;
  c.after_update = after;
  // F19: an automatic retry continues the series, any other start begins a new one.
  if (!c.retrying) m_tries = 0;
  c.retrying = false;
  ++m_tries;
  c.retry_at = bus::kNever;
  if (is_1500()) {
    set_state(s, CpuState::SyncUp, now, "backup to RUN");
    set_state(m, CpuState::SyncUp, now, "backup to RUN");
    c.deadline = now + m_p.link_up_time + update_time();
  } else {
    c.link_up_start = now;
    // R8: the standby's connections are all broken at link-up; the master keeps its own.
    if (c.connections > 0)
      diag(s, now,
           "link-up: " + std::to_string(c.connections) + " connection(s) of this CPU broken");
    c.connections = 0;
    ++c.connection_epoch;
    set_state(s, CpuState::LinkUp, now,
              after == Pending::Relink ? "re-link after error search"
              : after == Pending::Swap ? "master swap requested"
                                       : "link-up request");
    diag(m, now, "link-up with the standby CPU (rack " + std::to_string(s) + ")");
    diag(s, now,
         "LINK-UP: copying the load memory (" +
             format_ms(ticks_to_us_ceil(load_memory_copy_time())) + ")");
    c.deadline = now + m_p.link_up_time;
  }
}

void HCpuPair::finish_update(int s, bus::Ticks now) {
  Cpu& c = m_cpu[s];
  const int m = partner(s);
  const Pending after = c.after_update;
  c.after_update = Pending::None;
  set_state(s, CpuState::Run, now, is_1500() ? "syncup done" : "update done");
  if (is_1500()) set_state(m, CpuState::Run, now, "syncup done");
  switch (after) {
    case Pending::None:
      break;
    case Pending::Relink:
      set_role(m, CpuRole::Standby, now, "automatic swap after error search");
      set_role(s, CpuRole::Master, now, "automatic swap after error search");
      ob(s, 72, HReason::MasterSwap, now);
      ob(m, 72, HReason::MasterSwap, now);
      m_search_redundant_at = now;
      break;
    case Pending::Swap:
      set_role(m, CpuRole::Standby, now, "operator master swap");
      set_role(s, CpuRole::Master, now, "operator master swap");
      stop_cpu(m, now, "operator master swap");
      ob(s, 72, HReason::MasterSwap, now);
      break;
  }
}

void HCpuPair::abort_link_up(int s, bus::Ticks now, std::string_view why) {
  const int m = partner(s);
  stop_cpu(s, now, why);
  if (is_1500() && powered(m) && m_cpu[m].state == CpuState::SyncUp)
    set_state(m, CpuState::Run, now, why);
}

void HCpuPair::partner_lost(int r, bool master_was, CpuState was, bool power, bus::Ticks now) {
  const int p = partner(r);
  Cpu& q = m_cpu[p];
  const std::string rack = "rack " + std::to_string(r);
  if (power) diag(p, now, "partner CPU (" + rack + ") lost");
  if (master_was) {
    if (q.role != CpuRole::Standby) return;
    if (q.state == CpuState::Run && was == CpuState::Run) {
      set_role(p, CpuRole::Master, now, power ? "master CPU lost" : "master CPU in STOP");
      ob(p, 72, power ? HReason::MasterLost : HReason::MasterStop, now);
    } else if (syncing(q.state)) {
      abort_link_up(
          p, now,
          power ? "link-up aborted: master CPU lost" : "link-up aborted: master CPU in STOP");
      if (power) set_role(p, CpuRole::Master, now, "only CPU");
    } else if (power && (q.state == CpuState::Stop || q.state == CpuState::ErrorSearch)) {
      set_role(p, CpuRole::Master, now, "only CPU");
    }
  } else if (q.role == CpuRole::Master) {
    if (was == CpuState::Run && q.state == CpuState::Run) {
      ob(p, 72, power ? HReason::StandbyLost : HReason::StandbyStop, now);
    } else if (syncing(was)) {
      diag(p, now, power ? "link-up aborted: standby CPU lost" : "link-up aborted: standby STOP");
      if (is_1500() && q.state == CpuState::SyncUp)
        set_state(p, CpuState::Run, now, "syncup aborted");
    }
  }
}

// ---------------------------------------------------------------- operations

void HCpuPair::power_on(int r, bus::Ticks now) {
  check_rack(r);
  run_due(now);
  if (powered(r)) return;
  Cpu& c = m_cpu[r];
  const int p = partner(r);
  Cpu& q = m_cpu[p];
  c.deadline = bus::kNever;
  c.pending_master = bus::kNever;
  c.after_update = Pending::None;
  c.hold_remaining = -1;
  c.want_run = c.switch_run && c.restart_on_power && !c.reset_request;
  c.retry_at = bus::kNever;
  c.retrying = false;
  if (c.defective) {
    set_state(r, CpuState::Defective, now, "power on");
    set_role(r, CpuRole::Standby, now, "defective");
    after_step(now);
    return;
  }
  set_state(r, CpuState::Stop, now, "power on");
  if (c.reset_request) diag(r, now, "reset request pending: no start before a memory reset");
  const bool lk = powered(p) && link_whole();
  if (lk && q.role == CpuRole::Master) {
    set_role(r, CpuRole::Standby, now, "partner is master");
  } else if (lk && q.pending_master != bus::kNever) {
    if (c.remembered != CpuRole::Standby) {
      q.pending_master = bus::kNever;
      set_role(r, CpuRole::Master, now, "partner started less than 3 s earlier");
      set_role(p, CpuRole::Standby, now, "master started within 3 s");
    } else {
      set_role(r, CpuRole::Standby, now, "partner will be master");
    }
  } else if (lk && q.role == CpuRole::Standby) {
    set_role(r, CpuRole::Master, now, "partner is standby");
  } else if (c.remembered == CpuRole::Standby) {
    c.pending_master = now + m_p.role_window;
    diag(r, now, "waiting for the master CPU");
  } else {
    set_role(r, CpuRole::Master, now, lk ? "first to start" : "no partner on the sync link");
  }
  after_step(now);
}

void HCpuPair::power_on_both(bus::Ticks now) {
  power_on(0, now);
  power_on(1, now);
}

void HCpuPair::power_off(int r, bus::Ticks now) {
  check_rack(r);
  run_due(now);
  if (!powered(r)) return;
  Cpu& c = m_cpu[r];
  const CpuState was = c.state;
  const bool was_master = c.role == CpuRole::Master;
  const bool lk = linked(r);
  c.restart_on_power = was != CpuState::Stop;
  c.deadline = bus::kNever;
  c.pending_master = bus::kNever;
  c.after_update = Pending::None;
  c.hold_remaining = -1;
  c.want_run = false;
  c.retry_at = bus::kNever;
  c.retrying = false;
  c.connections = 0;
  diag(r, now, "power off");
  if (!is_1500() && was == CpuState::LinkUp && c.role == CpuRole::Standby)
    set_reset_request(r, now);  // F20/R9
  set_state(r, CpuState::Off, now);
  set_role(r, CpuRole::None, now);
  if (lk) partner_lost(r, was_master, was, true, now);
  after_step(now);
}

void HCpuPair::switch_to_run(int r, bus::Ticks now) {
  check_rack(r);
  run_due(now);
  Cpu& c = m_cpu[r];
  c.switch_run = true;
  c.retry_at = bus::kNever;  // a manual start begins a new series of tries (F19)
  c.retrying = false;
  if (c.state == CpuState::Stop) {
    if (c.reset_request)
      diag(r, now, "STOP -> RUN refused: reset request (memory reset needed)");
    else
      c.want_run = true;
  }
  after_step(now);
}

void HCpuPair::switch_to_stop(int r, bus::Ticks now) {
  check_rack(r);
  run_due(now);
  Cpu& c = m_cpu[r];
  c.switch_run = false;
  c.want_run = false;
  c.retry_at = bus::kNever;
  c.retrying = false;
  if (running(c.state)) {
    const CpuState was = c.state;
    const bool was_master = c.role == CpuRole::Master;
    const bool lk = linked(r);
    stop_cpu(r, now, "mode switch STOP");
    if (!is_1500() && was == CpuState::LinkUp && c.role == CpuRole::Standby)
      set_reset_request(r, now);  // F20/R9
    if (lk) partner_lost(r, was_master, was, false, now);
    if (lk && was_master && m_cpu[partner(r)].role == CpuRole::Master)
      set_role(r, CpuRole::Standby, now, "partner is master");
  }
  after_step(now);
}

void HCpuPair::cut_fibre(int f, bus::Ticks now) {
  if (f != 0 && f != 1) throw std::out_of_range("HCpuPair: fibre must be 0 or 1");
  run_due(now);
  if (!m_fibre_ok[f]) return;
  const bool was = link_whole() && powered(0) && powered(1);
  const bool second = !link_whole() && powered(0) && powered(1);
  m_fibre_ok[f] = false;
  for (int r = 0; r < 2; ++r)
    if (powered(r))
      diag(r, now,
           std::string("sync link fault: ") +
               (f == 0 ? "upper fibre (IFM1F)" : "lower fibre (IFM2F)"));
  if (was) {
    const int m = master();
    const int s = m < 0 ? -1 : partner(m);
    if (m >= 0 && master_count() == 1 && m_cpu[s].role == CpuRole::Standby) {
      const CpuState st = m_cpu[s].state;
      if (st == CpuState::Run) {
        stop_cpu(s, now, "redundant link lost");
        if (m_cpu[m].state == CpuState::Run) ob(m, 72, HReason::LinkLost, now);
      } else if (syncing(st)) {
        abort_link_up(s, now, "link-up aborted: redundant link lost");
      }
    }
  } else if (second) {
    second_link_lost(now);  // F5, second part: h_cpu_pair_sfc90.cpp
  }
  after_step(now);
}

void HCpuPair::cut_both_fibres(bus::Ticks now) {
  run_due(now);
  if (!link_whole()) {
    // Not "at once": the link was already down; the rest is a second fibre later.
    for (int f = 0; f < 2; ++f) cut_fibre(f, now);
    return;
  }
  const bool was = powered(0) && powered(1);
  m_fibre_ok = {false, false};
  for (int r = 0; r < 2; ++r)
    if (powered(r)) diag(r, now, "sync link fault: both fibres (IFM1F, IFM2F)");
  if (was) {
    const int m = master();
    const int s = m < 0 ? -1 : partner(m);
    if (m >= 0 && master_count() == 1 && m_cpu[s].role == CpuRole::Standby) {
      const CpuState st = m_cpu[s].state;
      if (st == CpuState::Run) {
        set_role(s, CpuRole::Master, now, "redundant link lost at once on both fibres");
        if (m_cpu[m].state == CpuState::Run) ob(m, 72, HReason::LinkLost, now);
        ob(s, 72, HReason::LinkLost, now);
      } else if (syncing(st)) {
        abort_link_up(s, now, "link-up aborted: redundant link lost");
      }
    }
  }
  after_step(now);
}

void HCpuPair::repair_fibre(int f, bus::Ticks now) {
  if (f != 0 && f != 1) throw std::out_of_range("HCpuPair: fibre must be 0 or 1");
  run_due(now);
  if (m_fibre_ok[f]) return;
  m_fibre_ok[f] = true;
  for (int r = 0; r < 2; ++r)
    if (powered(r))
      diag(r, now, std::string("sync link: ") + (f == 0 ? "upper" : "lower") + " fibre back");
  after_step(now);
}

bool HCpuPair::hold(int r, bus::Ticks now) {
  check_rack(r);
  run_due(now);
  Cpu& c = m_cpu[r];
  if (is_1500() || c.role != CpuRole::Master) return false;
  if (c.state == CpuState::Startup) {
    c.hold_remaining = c.deadline - now;
    c.deadline = bus::kNever;
  } else if (c.state == CpuState::Run && mode_of_master(r) == SystemMode::Solo) {
    c.hold_remaining = -1;
  } else {
    return false;
  }
  set_state(r, CpuState::Hold, now, "HOLD requested");
  after_step(now);
  return true;
}

bool HCpuPair::release_hold(int r, bus::Ticks now) {
  check_rack(r);
  run_due(now);
  Cpu& c = m_cpu[r];
  if (c.state != CpuState::Hold) return false;
  if (c.hold_remaining >= 0) {
    set_state(r, CpuState::Startup, now, "HOLD released");
    c.deadline = now + c.hold_remaining;
  } else {
    set_state(r, CpuState::Run, now, "HOLD released");
  }
  c.hold_remaining = -1;
  after_step(now);
  return true;
}

bool HCpuPair::inject_comparison_error(bus::Ticks now) {
  run_due(now);
  if (system_mode() != SystemMode::Redundant) return false;
  const int m = master();
  const int s = partner(m);
  const bool repeated = m_search_redundant_at != bus::kNever &&
                        now - m_search_redundant_at < m_p.cyclic_self_test_period;
  m_search_redundant_at = bus::kNever;
  if (is_1500() || repeated || m_p.comparison_reaction == ComparisonReaction::Stop) {
    stop_cpu(s, now,
             repeated ? "comparison error again in the first self-test cycle" : "comparison error");
  } else {
    set_state(s, CpuState::ErrorSearch, now, "comparison error");
    m_cpu[s].deadline = now + m_p.self_test_time;
  }
  ob(m, 72, HReason::ComparisonError, now);
  after_step(now);
  return true;
}

bool HCpuPair::one_sided_ob121(int r, bus::Ticks now) {
  check_rack(r);
  run_due(now);
  if (system_mode() != SystemMode::Redundant) return false;
  Cpu& c = m_cpu[r];
  const int p = partner(r);
  ob(r, 121, HReason::OneSidedOb121, now);
  const bool repeated = c.last_ob121 && now - *c.last_ob121 <= m_p.defective_window;
  c.last_ob121 = now;
  if (c.role == CpuRole::Master) {
    set_role(r, CpuRole::Standby, now, "one-sided OB 121");
    set_role(p, CpuRole::Master, now, "partner: one-sided OB 121");
  }
  if (is_1500()) {
    stop_cpu(r, now, "one-sided OB 121");
  } else if (repeated) {
    make_defective(r, now, "one-sided OB 121 repeated within 7 days");
  } else {
    set_state(r, CpuState::ErrorSearch, now, "one-sided OB 121");
    c.deadline = now + m_p.self_test_time;
  }
  ob(p, 72, HReason::OneSidedOb121, now);
  after_step(now);
  return true;
}

bool HCpuPair::load_memory_error(int r, bus::Ticks now) {
  check_rack(r);
  run_due(now);
  Cpu& c = m_cpu[r];
  if (!powered(r) || c.state == CpuState::Defective) return false;
  // The reset request first: nothing may restart the CPU (switch_to_run, power-on, the F19
  // retry all check it) until a memory reset.
  c.reset_request = true;
  c.retry_at = bus::kNever;
  c.retrying = false;
  diag(r, now, "load-memory access error: STOP, reset request (memory reset needed)");
  if (c.state != CpuState::Stop) {
    // As a STOP of r (switch_to_stop), but the mode switch stays at its position.
    const CpuState was = c.state;
    const bool was_master = c.role == CpuRole::Master;
    const bool lk = linked(r);
    stop_cpu(r, now, "load-memory access error");
    if (lk) partner_lost(r, was_master, was, false, now);
    if (lk && was_master && m_cpu[partner(r)].role == CpuRole::Master)
      set_role(r, CpuRole::Standby, now, "partner is master");
  }
  after_step(now);
  return true;
}

void HCpuPair::inject_hardware_fault(int r, bus::Ticks now) {
  check_rack(r);
  run_due(now);
  m_cpu[r].hw_fault = true;
}

void HCpuPair::repair_cpu(int r, bus::Ticks now) {
  check_rack(r);
  run_due(now);
  Cpu& c = m_cpu[r];
  c.hw_fault = false;
  c.defective = false;
  c.last_ob121.reset();
  c.last_checksum.reset();
  if (c.state == CpuState::Defective) stop_cpu(r, now, "CPU repaired");
  after_step(now);
}

bool HCpuPair::request_master_swap(bus::Ticks now) {
  run_due(now);
  const int m = master();
  if (is_1500() || m < 0 || master_count() != 1 || m_cpu[m].state != CpuState::Run ||
      mode_of_master(m) != SystemMode::Solo)
    return false;
  const int s = partner(m);
  if (!linked(m) || m_cpu[s].role != CpuRole::Standby || m_cpu[s].state != CpuState::Stop)
    return false;
  diag(m, now, "PG/ES: switch to CPU with modified configuration");
  if (m_link_up_disabled) {  // SFC 90 MODE 0: the swap is a link-up
    diag(m, now, "master swap refused: link-up disabled (SFC 90)");
    after_step(now);
    return false;
  }
  if (m_param_change) {  // F23: no swap, the standby stays in STOP
    const std::string t = "master swap refused: a parameter that may not change was changed";
    diag(m, now, t, 0x5966);
    diag(s, now, t, 0x5966);
    after_step(now);
    return false;
  }
  begin_link_up(s, now, Pending::Swap);
  after_step(now);
  return true;
}

void HCpuPair::set_changed_db_kb(std::uint32_t kb, bus::Ticks now) {
  run_due(now);
  m_p.update_db_kb = kb;
  m_p.update_time.reset();
}

bool HCpuPair::memory_reset(int r, bus::Ticks now) {
  check_rack(r);
  run_due(now);
  Cpu& c = m_cpu[r];
  if (c.state != CpuState::Stop) return false;
  c.reset_request = false;
  diag(r, now, "memory reset (MRES)");
  after_step(now);
  return true;
}

bool HCpuPair::connect(int r, bus::Ticks now) {
  check_rack(r);
  run_due(now);
  if (!accepts_connections(r)) return false;
  if (m_p.max_connections > 0 && m_cpu[r].connections >= m_p.max_connections) return false;
  ++m_cpu[r].connections;
  return true;
}

void HCpuPair::disconnect(int r) {
  if ((r == 0 || r == 1) && m_cpu[r].connections > 0) --m_cpu[r].connections;
}

bool HCpuPair::accepts_connections(int r) const {
  if (r != 0 && r != 1) return false;
  const Cpu& c = m_cpu[r];
  if (!powered(r) || c.state == CpuState::ErrorSearch || c.state == CpuState::Defective)
    return false;
  // R8: no new connections on either CPU from the start of link-up to the end of the update.
  for (const Cpu& x : m_cpu)
    if (x.state == CpuState::LinkUp || x.state == CpuState::Update) return false;
  return true;
}

HChangeResult HCpuPair::load_change(HChange kind, bus::Ticks now) {
  run_due(now);
  const SystemMode mode = system_mode();
  const int m = master();
  if (m < 0 || (mode != SystemMode::Solo && mode != SystemMode::Redundant)) {
    if (m >= 0)
      diag(m, now,
           "load refused: " + std::string(to_string(kind)) + " (" +
               std::string(to_string(mode, m_p.profile)) + ")");
    return HChangeResult::Refused;
  }
  const int s = partner(m);
  const bool redundant = mode == SystemMode::Redundant;
  if (kind == HChange::Allowed || !redundant) {
    const std::string t = "program change loaded: " + std::string(to_string(kind));
    diag(m, now, t);
    if (redundant) diag(s, now, t);
    return HChangeResult::Loaded;
  }
  // F22: the change may not be made in Redundant mode: both CPUs STOP (no OB 72: nobody runs).
  const std::string why = std::string(to_string(kind)) + " loaded in Redundant mode";
  stop_cpu(s, now, why);
  stop_cpu(m, now, why);
  after_step(now);
  return HChangeResult::BothStopped;
}

}  // namespace pbvbus::devices
