// The H-system model: the CPU pair driving the redundant DP master systems (h_system.hpp has
// the decisions, docs/h-system.md the reasons).
#include "pbvbus/s7h/h_system.hpp"

#include <algorithm>
#include <cstdio>

namespace pbvbus::devices {

namespace {

constexpr std::uint64_t kTagScan = 1;  // deadline tags are (generation << 1), scans odd

std::string hex4(std::uint16_t c) {
  char buf[16];
  std::snprintf(buf, sizeof buf, "W#16#%04X", static_cast<unsigned>(c));
  return buf;
}

bool running(HSystemModel::SideMode m) {
  return m == HSystemModel::SideMode::Clear || m == HSystemModel::SideMode::Operate;
}

}  // namespace

std::string_view to_string(BusLed l) {
  switch (l) {
    case BusLed::Off: return "off";
    case BusLed::On: return "on";
    case BusLed::Flashing: return "flashing";
  }
  return "?";
}

HSystemModel::HSystemModel(bus::Scheduler& sched, HCpuPairParams params,
                           std::vector<RedundantMasterSystemModel*> systems)
    : m_sched(sched), m_pair(std::move(params)) {
  for (auto* s : systems)
    if (s != nullptr) m_systems.push_back(s);
  m_side.resize(m_systems.size());
  m_map = HIoMap(m_systems);
  set_diag_address_top(kDiagTop417);
  m_pii.assign(m_map.pii_size(), 0);
  m_piq.assign(m_map.piq_size(), 0);
  m_pair.on_event([this](const HEvent& e) { on_pair_event(e); });
  for (std::size_t s = 0; s < m_systems.size(); ++s) {
    m_systems[s]->system().on_event(
        [this, s](const redundancy::SystemEvent& e) { on_io_event(s, e); });
    m_systems[s]->system().on_alarm(
        [this, s](const redundancy::SystemAlarm& a) { on_alarm(s, a); });
    m_systems[s]->system().on_diagnosis(
        [this, s](const redundancy::SystemDiagnosis& d) { on_diagnosis(s, d); });
  }
  reconcile();
  arm_deadline();
}

// ---- operations --------------------------------------------------------------------------

void HSystemModel::after_op() {
  reconcile();
  arm_deadline();
}

void HSystemModel::power_on(int r) {
  if (!valid_rack(r)) return;
  if (m_rp) m_rp->switch_on(r, m_sched.now());  // the RAM test first if unbuffered
  else m_pair.power_on(r, m_sched.now());
  rack_power_arm();
  after_op();
}
void HSystemModel::power_on_both() {
  if (m_rp) {  // as HCpuPair::power_on_both: rack 0, then rack 1
    m_rp->switch_on(0, m_sched.now());
    m_rp->switch_on(1, m_sched.now());
  } else {
    m_pair.power_on_both(m_sched.now());
  }
  rack_power_arm();
  after_op();
}
void HSystemModel::power_off(int r) {
  if (!valid_rack(r)) return;
  if (m_rp) m_rp->switch_off(r, m_sched.now());  // also ends a RAM test
  else m_pair.power_off(r, m_sched.now());
  after_op();
}
void HSystemModel::switch_to_run(int r) {
  if (!valid_rack(r)) return;
  m_pair.switch_to_run(r, m_sched.now());
  after_op();
}
void HSystemModel::switch_to_stop(int r) {
  if (!valid_rack(r)) return;
  m_pair.switch_to_stop(r, m_sched.now());
  after_op();
}
void HSystemModel::cut_fibre(int i) {
  if (i != 0 && i != 1) return;
  m_pair.cut_fibre(i, m_sched.now());
  after_op();
}
void HSystemModel::cut_both_fibres() {
  m_pair.cut_both_fibres(m_sched.now());
  after_op();
}
void HSystemModel::repair_fibre(int i) {
  if (i != 0 && i != 1) return;
  m_pair.repair_fibre(i, m_sched.now());
  after_op();
}
bool HSystemModel::hold(int r) {
  if (!valid_rack(r)) return false;
  const bool ok = m_pair.hold(r, m_sched.now());
  after_op();
  return ok;
}
bool HSystemModel::release_hold(int r) {
  if (!valid_rack(r)) return false;
  const bool ok = m_pair.release_hold(r, m_sched.now());
  after_op();
  return ok;
}
bool HSystemModel::inject_comparison_error() {
  const bool ok = m_pair.inject_comparison_error(m_sched.now());
  after_op();
  return ok;
}
bool HSystemModel::one_sided_ob121(int r) {
  if (!valid_rack(r)) return false;
  const bool ok = m_pair.one_sided_ob121(r, m_sched.now());
  after_op();
  return ok;
}
void HSystemModel::inject_hardware_fault(int r) {
  if (!valid_rack(r)) return;
  m_pair.inject_hardware_fault(r, m_sched.now());
  after_op();
}
void HSystemModel::repair_cpu(int r) {
  if (!valid_rack(r)) return;
  m_pair.repair_cpu(r, m_sched.now());
  after_op();
}
bool HSystemModel::request_master_swap() {
  // The operator's swap is the "switch to CPU with modified configuration" with nothing changed
  // (000 L1120): HConfigChange (h_system_config_change.cpp).
  return switch_to_cpu(HSwitchVariant::ModifiedConfiguration, {}, {});
}

// ---- reconciliation ----------------------------------------------------------------------

HSystemModel::SideMode HSystemModel::target(int r) const {
  if (m_pair.state(r) == CpuState::Off) return SideMode::Unpowered;
  if (!m_pair.dp_master_running(r)) return SideMode::Stop;
  // The standby in UPDATE: Clear until t4 (its outputs are not driven yet; every station is
  // active on the master's line), Operate from t4 (the output copy: both drive during T_PH).
  if (m_pair.state(r) == CpuState::Update && !m_pair.outputs_held_by_both()) return SideMode::Clear;
  // One program: the master CPU's. With two masters (F6/F7) each CPU runs its own.
  const int m = m_pair.master_count() >= 2 ? r : m_pair.master();
  return m >= 0 && m_pair.dp_master_operate(m) ? SideMode::Operate : SideMode::Clear;
}

bool HSystemModel::program_runs() const {
  for (int r = 0; r < 2; ++r)
    if (m_pair.is_master(r) && m_pair.dp_master_operate(r)) return true;
  return false;
}

void HSystemModel::reconcile() {
  for (int r = 0; r < 2; ++r) {
    const SideMode to = target(r);
    for (std::size_t s = 0; s < m_systems.size(); ++s) apply(s, r, to);
  }
  cc_observe();  // the swap, the return to Redundant (h_system_config_change.cpp)
  track_update(m_sched.now());
  deliver_held(m_sched.now());
  sfc90_reconcile(m_sched.now());  // watchdog OBs and S7 jobs held by the update
  if (has_program() && !m_scan_armed && program_runs() && !m_pair.io_frozen())
    arm_scan(m_sched.now());
  comms_update(m_sched.now());  // F4 connections, SSL: h_system_comms.cpp
}

void HSystemModel::apply(std::size_t s, int r, SideMode to) {
  Side& sd = m_side[s][static_cast<std::size_t>(r)];
  if (sd.known && sd.mode == to) return;
  const bool was_running = sd.known && running(sd.mode);
  sd.known = true;
  sd.mode = to;
  RedundantMasterSystemModel& m = *m_systems[s];
  redundancy::MasterSystem& ms = m.system();
  const bus::Ticks now = m_sched.now();
  switch (to) {
    case SideMode::Unpowered:
      // The system first (every station of the line to the other one at once), then the master.
      if (!sd.ran) ms.mark_line_idle(r);
      else if (was_running) ms.line_lost(r, redundancy::LineLoss::CpuFailure, now);
      m.master(r).set_mode(dp::MasterMode::Stop);
      m.set_cpu_power(r, false);
      break;
    case SideMode::Stop:
      if (!sd.ran) ms.mark_line_idle(r);
      else if (was_running) ms.line_lost(r, redundancy::LineLoss::MasterStop, now);
      m.master(r).set_mode(dp::MasterMode::Stop);
      m.set_cpu_power(r, true);
      break;
    case SideMode::Clear:
    case SideMode::Operate: {
      m.set_cpu_power(r, true);
      if (!sd.ran) {
        ms.start_line(r, now);  // silent: the I/O was never redundant over this line
        sd.ran = true;
      } else if (!was_running) {
        // Back from the CPU's own loss only (a short circuit or a failed module is not ours).
        const auto loss = ms.line_loss(r);
        if (loss && (*loss == redundancy::LineLoss::MasterStop ||
                     *loss == redundancy::LineLoss::CpuFailure))
          ms.line_back(r, now);
      }
      m.master(r).set_mode(to == SideMode::Clear ? dp::MasterMode::Clear
                                                 : dp::MasterMode::Operate);
      break;
    }
  }
}

HSystemModel::SideMode HSystemModel::side_mode(std::size_t s, int r) const {
  if (s >= m_side.size() || !valid_rack(r)) return SideMode::Unpowered;
  return m_side[s][static_cast<std::size_t>(r)].mode;
}

// ---- scheduling --------------------------------------------------------------------------

void HSystemModel::arm_deadline() {
  const bus::Ticks t = m_pair.next_deadline();
  if (t == m_armed_at) return;
  m_armed_at = t;
  ++m_gen;
  if (t == bus::kNever) return;  // the old event, if any, is stale now
  m_sched.schedule(t, *this, m_gen << 1);
}

void HSystemModel::arm_scan(bus::Ticks at) {
  m_scan_armed = true;
  m_sched.schedule(at, *this, kTagScan);
}

void HSystemModel::set_program(Program hook, bus::Ticks scan_time) {
  m_program = std::move(hook);
  m_exec.reset();  // one program: the hook (or none) replaces a spec
  m_s7_spec.reset();
  m_s7_layout = layout(m_s7_cfg, 0);  // M and the DBs in the model's own storage again
  m_scan_time = scan_time > 0 ? scan_time : bus::kTicksPerMs;
  if (has_program() && !m_scan_armed && program_runs()) arm_scan(m_sched.now());
}

void HSystemModel::on_event(bus::Ticks now, std::uint64_t tag) {
  if (tag == kTagScan) {
    m_scan_armed = true;  // this event is the armed scan: a reconcile below must not arm another
    // A pair deadline at the same instant comes first (as in the pair: deadlines before
    // operations), so a scan at t3 sees the freeze and a scan at t5 sees it lifted.
    if (m_pair.next_deadline() <= now) {
      m_armed_at = bus::kNever;
      ++m_gen;  // the scheduled deadline event is stale now
      m_pair.on_time(now);
      reconcile();
      arm_deadline();
    }
    // Not running, or inside the update's no-I/O window [t3, t5): no OB 1 and no I/O update
    // at all; reconcile() starts the next scan at once when it runs again / at t5 or the abort
    // (a late OB 1 starts at once and the cycle continues from there).
    if (!has_program() || !program_runs() || m_pair.io_frozen()) {
      m_scan_armed = false;
      return;
    }
    scan(now);
    m_sched.schedule(end_cycle(now), *this, kTagScan);  // OB 80 monitoring, cycle_overload
    return;
  }
  if ((tag >> 1) != m_gen) return;  // stale deadline
  m_armed_at = bus::kNever;
  m_pair.on_time(now);
  reconcile();
  arm_deadline();
}

void HSystemModel::scan(bus::Ticks now) {
  if (m_gate && !m_gate(now)) return;
  if (!m_measures.empty() && m_measures.back().done &&
      m_measures.back().first_scan_after == bus::kNever)
    m_measures.back().first_scan_after = now;
  m_last_scan = now;
  cc_ob1(now);  // OB1_SCAN_1 (h_system_config_change.cpp)
  m_in_scan = true;  // SFC 90 from OB 1: its effect on the pair after this OB 1
  run_program_h_ctrl(now);
  struct ScanEnd {
    HSystemModel* m;
    ~ScanEnd() { m->after_scan_h_ctrl(); }
  } scan_end{this};
  check_process_image(now);
  read_racks(now);  // F8: the expansion racks' OB 85 and inputs (h_system_racks.cpp)
  if (m_exec) {
    scan_execution(now);
    if (m_split_outputs)  // two masters: each side's racks take their own CPU's PIQ
      write_racks(m_exec->image(0).piq(), m_exec->image(1).piq());
    else
      write_racks();
    return;
  }
  ++m_scans;
  m_map.read_inputs(m_systems, m_pii);
  red_io_in(now);
  m_program(m_pii, m_piq, now);
  m_map.write_outputs(m_systems, red_io_out(m_piq));
  write_racks();
}

// ---- events, diagnostics, LEDs -----------------------------------------------------------

namespace {
void insert_sorted(std::vector<HSystemEvent>& v, HSystemEvent e) {
  auto it = std::upper_bound(v.begin(), v.end(), e.time,
                             [](bus::Ticks t, const HSystemEvent& x) { return t < x.time; });
  v.insert(it, std::move(e));
}
}  // namespace

void HSystemModel::add_event(HSystemEvent e) {
  if (m_handler) m_handler(e);
  if (!m_red_io) return insert_sorted(m_events, std::move(e));
  const HSystemEvent copy = e;
  insert_sorted(m_events, std::move(e));
  red_io_on_event(copy);  // OB 82/85 of a paired module: RED_DIAG (h_system_redundant_io.cpp)
}

void HSystemModel::on_pair_event(const HEvent& e) {
  if (m_pair_handler) m_pair_handler(e);
  if (m_red_io) red_io_on_pair_event(e);  // OB 100 / OB 72 Redundant: depassivation
  ptt_on_pair_event(e);  // W#16#6547 monitoring (h_system_dp_startup.cpp)
  if (e.kind != HEvent::Kind::Ob) return;
  HSystemEvent h;
  h.time = e.at;
  h.rack = e.rack;
  h.role = e.role;
  h.ob = e.ob;
  h.code = e.code;
  h.text = "OB " + std::to_string(e.ob) + " " + std::string(to_string(e.reason));
  if (e.ob == 72 && e.reason == HReason::ComparisonError && !m_ob72_note.empty())
    h.text += ", " + m_ob72_note;
  h.source = HSystemEvent::Source::Cpu;
  h.original_time = h.time;
  add_event(std::move(h));
}

// Every powered CPU logs an I/O event with its role (F3 "both CPUs log"), the newest
// diag_capacity entries.
void HSystemModel::log_on_powered(bus::Ticks now, std::uint16_t code, const std::string& text) {
  const auto cap = m_pair.params().diag_capacity;
  for (int r = 0; r < 2; ++r) {
    if (m_pair.state(r) == CpuState::Off) continue;
    auto& d = m_io_diag[static_cast<std::size_t>(r)];
    d.push_back({now, m_pair.role(r), code, text});
    if (cap > 0 && d.size() > cap) d.erase(d.begin());
  }
}

void HSystemModel::on_io_event(std::size_t s, const redundancy::SystemEvent& e) {
  if (!e.s7()) return;
  std::string text = "OB " + std::to_string(e.ob()) + " " + hex4(e.code()) + " " +
                     std::string(to_string(e.kind)) + ", DP master system " +
                     std::to_string(s + 1) + ", line " + (e.line == 1 ? "B" : "A");
  if (e.station != 0xFF) text += ", station " + std::to_string(e.station);
  // Every powered CPU logs it; the OB runs on the CPUs that run a program.
  log_on_powered(e.time, e.code(), text);
  const bool run0 = m_pair.dp_master_operate(0), run1 = m_pair.dp_master_operate(1);
  if (!run0 && !run1) return;  // no program runs: no OB, only the buffer entries
  HSystemEvent h;
  h.time = e.time;
  h.rack = run0 && run1 ? -1 : (run0 ? 0 : 1);
  h.role = h.rack < 0 ? CpuRole::Master : m_pair.role(h.rack);
  h.ob = e.ob();
  h.code = e.code();
  h.text = std::move(text);
  h.source = HSystemEvent::Source::Io;
  h.system = static_cast<int>(s);
  h.line = e.line;
  h.station = e.station;
  h.original_time = h.time;
  // D1 (001 Table 4-8 L3064-3068): the slave's diagnostic address as the master sees it; an
  // event of the whole master system: its master's.
  const auto diag = e.station == 0xFF ? m_diag.master(s) : m_diag.slave(s, e.station);
  if (diag) h.mdl_addr = *diag;
  add_event(std::move(h));
}

void HSystemModel::set_diag_address_top(std::uint16_t top) {
  std::vector<std::vector<std::uint8_t>> st;
  for (RedundantMasterSystemModel* m : m_systems) {
    st.emplace_back();
    if (m == nullptr) continue;
    for (std::uint8_t a : m->system().addresses()) st.back().push_back(a);
  }
  m_diag = HDiagAddresses(top, st);
}

std::vector<DiagEntry> HSystemModel::diag_buffer(int r) const {
  std::vector<DiagEntry> out;
  if (!valid_rack(r)) return out;
  const auto& cpu = m_pair.diag_buffer(r);
  const auto& io = m_io_diag[static_cast<std::size_t>(r)];
  out.reserve(cpu.size() + io.size());
  // Merge by time; at equal times the CPU's entries first.
  std::size_t i = 0, j = 0;
  while (i < cpu.size() || j < io.size()) {
    if (j >= io.size() || (i < cpu.size() && cpu[i].at <= io[j].at)) out.push_back(cpu[i++]);
    else out.push_back(io[j++]);
  }
  const auto cap = m_pair.params().diag_capacity;
  if (cap > 0 && out.size() > cap)
    out.erase(out.begin(), out.begin() + static_cast<std::ptrdiff_t>(out.size() - cap));
  return out;
}

HSystemLeds HSystemModel::leds(int r) const {
  HSystemLeds l;
  if (!valid_rack(r)) return l;
  l.cpu = m_pair.leds(r);
  l.busf.assign(m_systems.size(), BusLed::Off);
  if (m_pair.state(r) == CpuState::Off) return l;  // dark
  for (std::size_t s = 0; s < m_systems.size(); ++s) {
    const redundancy::MasterSystem& ms = m_systems[s]->system();
    const auto loss = ms.line_loss(r);
    if (loss && (*loss == redundancy::LineLoss::ShortCircuit ||
                 *loss == redundancy::LineLoss::MasterFailure)) {
      l.busf[s] = BusLed::On;
      continue;
    }
    if (loss || ms.line_idle(r) || !running(m_side[s][static_cast<std::size_t>(r)].mode)) continue;
    const dp::Master& master = ms.master(r);
    for (std::uint8_t a : ms.addresses()) {
      if (!master.has_slave(a)) continue;
      const bool bad = ms.station_failed(a) ||
                       (ms.is_switched(a) && ms.redundancy_lost(a) && !ms.channel_up(a, r));
      if (bad) {
        l.busf[s] = BusLed::Flashing;
        break;
      }
    }
  }
  return l;
}

}  // namespace pbvbus::devices
