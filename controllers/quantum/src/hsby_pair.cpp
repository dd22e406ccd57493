// The Quantum Hot Standby pair (hsby_pair.hpp has the rules, docs/quantum-hsby-pair.md the
// reasons): construction, the operations on the racks' controls, the reconciliation that runs
// after each of them and at every scan start, the LEDs and the status register.
#include "pbvbus/quantum/hsby_pair.hpp"

#include "pbvbus/quantum/command_register.hpp"

#include <stdexcept>
#include <string>

namespace pbvbus::quantum {

namespace {

std::string hsby_rack_name(int r) {
  return "rack " + std::to_string(r);
}

}  // namespace

HsbyPair::HsbyPair(bus::Scheduler& sched, HsbyPairParams params, std::array<IoHead*, 2> heads)
    : m_sched(sched), m_p(std::move(params)) {
  if (m_p.scan_time <= 0) throw std::invalid_argument("hot standby: scan time must be > 0");
  if (m_p.command_register >= m_p.sizes.holding)
    throw std::invalid_argument("hot standby: command register 4x index " +
                                std::to_string(m_p.command_register) + " outside the " +
                                std::to_string(m_p.sizes.holding) + " configured 4x registers");
  m_transfer_time = m_p.transfer_time > 0 ? m_p.transfer_time : m_p.scan_time / 4;
  if (m_transfer_time > m_p.scan_time)
    throw std::invalid_argument("hot standby: transfer time longer than the scan time");
  m_update_time = m_p.update_time > 0 ? m_p.update_time : bus::kTicksPerSecond;
  if (m_p.line_check_delay < 0 || 2 * m_p.line_check_delay > m_p.scan_time)
    throw std::invalid_argument("hot standby: line check delay outside [0, scan time / 2]");
  for (int r = 0; r < 2; ++r) {
    Rack& k = rk(r);
    const RackParams& rp = m_p.racks[static_cast<std::size_t>(r)];
    k.key = rp.key;
    k.slide = rp.designation;
    k.designation = rp.designation;
    k.checksum = rp.logic_checksum;
    k.firmware = rp.firmware;
    k.ram = StateRam(m_p.sizes);
    k.head = heads[static_cast<std::size_t>(r)];
  }
  update_heads();
}

// ---- program -----------------------------------------------------------------------------

void HsbyPair::set_logic(UserLogic logic) {
  rk(0).logic = logic;
  rk(1).logic = std::move(logic);
}

void HsbyPair::set_logic(int r, UserLogic logic) {
  if (valid(r)) rk(r).logic = std::move(logic);
}

void HsbyPair::load_program(int r, std::uint32_t checksum, UserLogic logic) {
  if (!valid(r)) return;
  rk(r).checksum = checksum;
  rk(r).logic = std::move(logic);
  log(r, PairEventKind::LogicMismatch,
      logic_match() ? "program loaded: logic matches the other unit"
                    : "program loaded: logic mismatch with the other unit");
  reconcile();
}

std::string HsbyPair::upgrade_executive(int r, std::uint32_t version) {
  if (!valid(r)) return "no such rack";
  Rack& k = rk(r);
  const int p = primary();
  const StateRam& cmd_ram = p >= 0 ? rk(p).ram : k.ram;
  const bool while_running = decode_command(cmd_ram.holding(m_p.command_register)).exec_upgrade_while_running;
  std::string why;
  if (!k.powered)
    why = "the rack has no power";
  else if (k.state == CpuState::Primary)
    why = "the unit is primary: hand control over first";
  else if (!while_running && p >= 0)
    why = "the command register allows an exec upgrade only after the application stops, and rack " +
          std::to_string(p) + " runs it";
  if (!why.empty()) {
    log(r, PairEventKind::Ignored, "executive upgrade to " + std::to_string(version) + " refused: " + why);
    return why;
  }
  log(r, PairEventKind::Cpu, "executive upgraded from " + std::to_string(k.firmware) + " to " + std::to_string(version));
  k.firmware = version;
  if (k.state == CpuState::Standby) set_state(r, CpuState::Offline, "executive upgrade");
  reconcile();
  join_on_own_event(r);
  return "";
}

// ---- operations ----------------------------------------------------------------------------

void HsbyPair::power_on(int r) {
  if (!valid(r) || rk(r).powered) return;
  Rack& k = rk(r);
  k.powered = true;
  k.cpu_run = true;
  k.designation = k.slide;  // the slide switch is read at power-on
  k.duplicate = false;
  k.blocker.clear();
  k.state = CpuState::Offline;
  log(r, PairEventKind::Power,
      "power on (designation " + std::string(to_string(k.designation)) + ", key " +
          std::string(to_string(k.key)) + ")");
  join_on_own_event(r);
  reconcile();
}

void HsbyPair::power_off(int r) {
  if (!valid(r) || !rk(r).powered) return;
  log(r, PairEventKind::Power, "power off");
  if (rk(r).state == CpuState::Primary) primary_gone(r, SwitchoverCause::PrimaryPowerOff);
  abort_update(r, "power off");
  set_state(r, CpuState::Off, "power off");
  Rack& k = rk(r);
  k.powered = false;
  k.duplicate = false;
  k.blocker.clear();
  reconcile();
}

void HsbyPair::stop_cpu(int r) {
  if (!valid(r) || !rk(r).powered || !rk(r).cpu_run) return;
  log(r, PairEventKind::Cpu, "CPU stopped");
  if (rk(r).state == CpuState::Primary) primary_gone(r, SwitchoverCause::PrimaryCpuStop);
  abort_update(r, "CPU stopped");
  rk(r).cpu_run = false;
  set_state(r, CpuState::Offline, "CPU stopped");
  reconcile();
}

void HsbyPair::start_cpu(int r) {
  if (!valid(r) || !rk(r).powered || rk(r).cpu_run) return;
  rk(r).cpu_run = true;
  log(r, PairEventKind::Cpu, "CPU runs again");
  join_on_own_event(r);
  reconcile();
}

void HsbyPair::set_key(int r, KeySwitch key) {
  if (!valid(r)) return;
  Rack& k = rk(r);
  const KeySwitch was = k.key;
  if (was == key) return;
  k.key = key;
  log(r, PairEventKind::Key,
      "key " + std::string(to_string(was)) + " -> " + std::string(to_string(key)));
  if (!k.powered) return;
  if (m_p.keyswitch_override) {
    log(r, PairEventKind::Ignored, "keyswitch override enabled: the key is ignored");
    return;
  }
  const int o = 1 - r;
  if (k.state == CpuState::Primary && key == KeySwitch::Xfer) {
    log(r, PairEventKind::Ignored, "primary key to Xfer: ignored");  // seed p. 22, Q7
    return;
  }
  // The program update sequence (seed pp. 21-22).
  if (key == KeySwitch::Xfer && k.update_button && k.update == UpdatePhase::None &&
      k.state != CpuState::Primary) {
    if (rk(o).state == CpuState::Primary && m_fibre == FibreState::Ok && k.cpu_run) {
      k.update = UpdatePhase::Armed;
      ++k.update_gen;
      if (k.state == CpuState::Standby) set_state(r, CpuState::Offline, "program update");
      log(r, PairEventKind::Update, "program update armed (update button held, key to Xfer)");
    } else {
      log(r, PairEventKind::Ignored, "program update impossible: no primary reachable");
    }
  } else if (k.update == UpdatePhase::Armed && key != KeySwitch::Xfer) {
    k.update = UpdatePhase::Requested;
    log(r, PairEventKind::Update,
        "program update requested, the unit goes to " + std::string(to_string(key)) +
            " afterwards");
  }
  if (key == KeySwitch::Run && k.update == UpdatePhase::None) join_on_own_event(r);
  reconcile();
}

void HsbyPair::press_update(int r) {
  if (!valid(r) || rk(r).update_button) return;
  Rack& k = rk(r);
  k.update_button = true;
  log(r, PairEventKind::Update, "update button pressed");
  if (!k.powered) return;
  if (m_p.keyswitch_override) {
    log(r, PairEventKind::Ignored, "keyswitch override enabled: no program update at the module");
    return;
  }
  if (k.key == KeySwitch::Xfer && k.update == UpdatePhase::None && k.state != CpuState::Primary &&
      rk(1 - r).state == CpuState::Primary && m_fibre == FibreState::Ok && k.cpu_run) {
    // Key already at Xfer: the same as turning it there with the button held.
    k.update = UpdatePhase::Armed;
    ++k.update_gen;
    if (k.state == CpuState::Standby) set_state(r, CpuState::Offline, "program update");
    log(r, PairEventKind::Update, "program update armed (key at Xfer, update button pressed)");
    reconcile();
  }
}

void HsbyPair::release_update(int r) {
  if (!valid(r) || !rk(r).update_button) return;
  Rack& k = rk(r);
  k.update_button = false;
  log(r, PairEventKind::Update, "update button released");
  if (k.update == UpdatePhase::Requested) {
    k.update = UpdatePhase::Running;
    ++k.update_gen;
    log(r, PairEventKind::Update, "program update running");
    arm_update(r);
  } else if (k.update == UpdatePhase::Armed) {
    abort_update(r, "update button released with the key at Xfer");
  }
  reconcile();
}

void HsbyPair::set_designation(int r, Designation d) {
  if (!valid(r) || rk(r).slide == d) return;
  rk(r).slide = d;
  log(r, PairEventKind::Key,
      "designation slide switch to " + std::string(to_string(d)) + " (read at the next power-on)");
}

void HsbyPair::set_fibre(FibreState f) {
  if (f == m_fibre) return;
  log(-1, PairEventKind::Fibre,
      "fibre " + std::string(to_string(m_fibre)) + " -> " + std::string(to_string(f)));
  m_fibre = f;
  if (f != FibreState::Ok) {
    m_link_fault_time = m_sched.now();
    lose_in_flight("fibre " + std::string(to_string(f)));
  }
  reconcile();
}

void HsbyPair::set_keyswitch_override(bool on) {
  if (m_p.keyswitch_override == on) return;
  m_p.keyswitch_override = on;
  log(-1, PairEventKind::Override,
      on ? "keyswitch override enabled: the run bits decide (read at once)"
         : "keyswitch override disabled: the keyswitches decide");
  reconcile();  // reads bits 14/15 at once (seed p. 90)
}

void HsbyPair::set_standby_stays_on_logic_mismatch(bool on) {
  if (m_p.standby_stays_on_logic_mismatch == on) return;
  m_p.standby_stays_on_logic_mismatch = on;
  log(-1, PairEventKind::LogicMismatch,
      on ? "option: the standby stays online on a logic mismatch"
         : "option: the standby goes offline on a logic mismatch");
  reconcile();
}

// ---- the rules -----------------------------------------------------------------------------

void HsbyPair::log(int rack, PairEventKind kind, std::string text) {
  log_as(rack, kind, std::move(text), valid(rack) ? rk(rack).state : CpuState::Off);
}

void HsbyPair::log_as(int rack, PairEventKind kind, std::string text, CpuState after) {
  m_events.push_back(PairEvent{m_sched.now(), rack, kind, std::move(text), after});
  if (m_on_event) m_on_event(m_events.back());
}

void HsbyPair::set_state(int r, CpuState s, std::string_view why) {
  Rack& k = rk(r);
  if (k.state == s) return;
  log_as(r, PairEventKind::State,
         std::string(to_string(k.state)) + " -> " + std::string(to_string(s)) + " (" +
             std::string(why) + ")",
         s);
  if (m_flight.active && (r == m_flight.from || r == m_flight.to))
    lose_in_flight(hsby_rack_name(r) + " " + std::string(to_string(s)));
  if (s == CpuState::Standby) m_alone_logged = false;
  if (s == CpuState::Standby && k.state != CpuState::Standby) k.updated = false;
  if (s == CpuState::Primary) {
    k.primary_since = m_sched.now();
    k.scans_as_primary = 0;
  }
  k.state = s;
  if (s != CpuState::Primary) ++k.scan_gen;
  if (s == CpuState::Standby) arm_watch(r);
}

bool HsbyPair::run_bit(int r) const {
  // The primary reads the command register in its own state RAM; with no primary (start-up)
  // a unit reads its own (battery-backed) copy.
  const int p = primary();
  const StateRam& src = p >= 0 ? rk(p).ram : rk(r).ram;
  // Run modes: bit 15 for the unit designated A, bit 14 for B (seed p. 90; command_register.hpp).
  const CommandRegister c = decode_command(src.holding(m_p.command_register));
  return rk(r).designation == Designation::A ? c.run_a : c.run_b;
}

bool HsbyPair::wants_run(int r) const {
  return m_p.keyswitch_override ? run_bit(r) : rk(r).key == KeySwitch::Run;
}

bool HsbyPair::wants_offline(int r) const {
  return m_p.keyswitch_override ? !run_bit(r) : rk(r).key == KeySwitch::OffLine;
}

std::string HsbyPair::join_blocker(int r) const {
  const Rack& k = rk(r);
  const Rack& o = rk(1 - r);
  if (m_fibre == FibreState::TxRxNotCrossed) return "fibre Tx/Rx not crossed: no communication";
  if (m_fibre == FibreState::Cut) return "fibre cut: no communication";
  if (k.duplicate || k.designation == o.designation)
    return "same designation " + std::string(to_string(k.designation)) + " as the primary";
  if (k.checksum != o.checksum && !m_p.standby_stays_on_logic_mismatch)
    return "logic mismatch with the primary";
  // Seed p. 96: by default "the Standby controller would not go online while having a newer
  // or older firmware version than the one on the Primary controller".
  if (k.firmware != o.firmware && !m_p.allow_different_firmware)
    return "executive " + std::to_string(k.firmware) + " differs from the primary's " + std::to_string(o.firmware);
  return "";
}

void HsbyPair::join_on_own_event(int r) {
  Rack& k = rk(r);
  if (!k.powered || !k.cpu_run || k.state != CpuState::Offline || k.update != UpdatePhase::None)
    return;
  const CpuState other = rk(1 - r).state;
  if (other == CpuState::Primary) return;  // Standby or not: reconcile() decides
  // A standby whose primary just failed takes over at its watchdog; until then nobody else
  // becomes primary.
  if (other == CpuState::Standby) return;
  if (wants_run(r)) become_primary(r, m_sched.now(), nullptr);
}

void HsbyPair::lose_in_flight(std::string_view why) {
  if (!m_flight.active) return;
  m_flight.active = false;
  ++m_transfers_lost;
  log(-1, PairEventKind::TransferLost,
      "transfer of the scan started at " + std::to_string(m_flight.scan_start) + " ticks lost (" +
          std::string(why) + ")");
}

void HsbyPair::primary_gone(int r, SwitchoverCause cause) {
  m_failure = PendingFailure{true, r, m_sched.now(), cause};
  m_handover.active = false;
  ++rk(r).scan_gen;
}

void HsbyPair::abort_update(int r, std::string_view why) {
  Rack& k = rk(r);
  if (k.update == UpdatePhase::None) return;
  k.update = UpdatePhase::None;
  ++k.update_gen;
  log(r, PairEventKind::Update, "program update aborted (" + std::string(why) + ")");
}

void HsbyPair::reconcile() {
  for (int r = 0; r < 2; ++r) {
    Rack& k = rk(r);
    if (k.update == UpdatePhase::None) continue;
    if (!k.powered || !k.cpu_run)
      abort_update(r, "unit down");
    else if (rk(1 - r).state != CpuState::Primary)
      abort_update(r, "no primary");
    else if (m_fibre != FibreState::Ok)
      abort_update(r, "no CHS communication");
    else if (m_p.keyswitch_override)
      abort_update(r, "keyswitch override");
  }
  // Two primaries (a standby took over while the fibre and its line were both silent) hear
  // each other again over the fibre: the later one gives control back and goes offline.
  if (rk(0).state == CpuState::Primary && rk(1).state == CpuState::Primary &&
      m_fibre == FibreState::Ok) {
    const int later = rk(1).primary_since >= rk(0).primary_since ? 1 : 0;
    log(later, PairEventKind::Switchover,
        "two primaries meet again over the fibre: the later one goes offline");
    set_state(later, CpuState::Offline, "second primary");
  }
  // The primary asked to go offline: the handover at its next scan boundary, if a standby
  // is there to take control; alone it keeps control. Before the standby's own rules (the
  // override's both-bits-0 case) and again after a unit joined.
  auto request_handover = [this] {
    const int p = primary();
    if (p < 0 || !wants_offline(p)) {
      m_handover.active = false;
      return;
    }
    if (rk(1 - p).state == CpuState::Standby) {
      if (!m_handover.active)
        m_handover = PendingHandover{true, m_sched.now(),
                                     m_p.keyswitch_override ? SwitchoverCause::CommandRegister
                                                            : SwitchoverCause::KeyOffLine};
    } else if (!m_alone_logged) {
      m_alone_logged = true;
      log(p, PairEventKind::Ignored,
          "asked to go offline but no standby can take control: the primary keeps control");
    }
  };
  request_handover();
  // A standby that must leave: its key at Off Line / its run bit 0, or a logic mismatch.
  for (int r = 0; r < 2; ++r) {
    if (rk(r).state != CpuState::Standby) continue;
    // Override, the primary's run bit 0 too: the switchover comes first and the standby, about
    // to be primary, stays (seed p. 90: both bits 0 -> switchover, the new primary continues).
    const bool taking_over = m_p.keyswitch_override && m_handover.active;
    if (wants_offline(r) && !taking_over) {
      set_state(r, CpuState::Offline, m_p.keyswitch_override ? "run bit 0" : "key Off Line");
    } else if (rk(r).checksum != rk(1 - r).checksum && !m_p.standby_stays_on_logic_mismatch) {
      log(r, PairEventKind::LogicMismatch, "logic mismatch: the standby goes offline");
      set_state(r, CpuState::Offline, "logic mismatch");
    }
  }
  // An offline unit that wants to run beside a primary joins as standby when it may.
  for (int r = 0; r < 2; ++r) {
    Rack& k = rk(r);
    if (!k.powered || !k.cpu_run || k.state != CpuState::Offline || k.update != UpdatePhase::None ||
        rk(1 - r).state != CpuState::Primary || !wants_run(r))
      continue;
    const std::string b = join_blocker(r);
    if (b.empty()) {
      k.blocker.clear();
      if (k.checksum != rk(1 - r).checksum)
        log(r, PairEventKind::LogicMismatch,
            "logic mismatch allowed by the option: the unit stays online as standby");
      set_state(r, CpuState::Standby, "joins the primary");
      continue;
    }
    if (b == k.blocker) continue;
    k.blocker = b;
    if (b.rfind("same designation", 0) == 0) {
      k.duplicate = true;  // Q6: a startup error until the next power-on (Com Act blinking)
      log(r, PairEventKind::DuplicateDesignation, "stays offline: " + b);
    } else if (b.rfind("logic", 0) == 0) {
      log(r, PairEventKind::LogicMismatch, "stays offline: " + b);
    } else {
      log(r, PairEventKind::Fibre, "stays offline: " + b);
    }
  }
  request_handover();
  update_heads();
  for (int r = 0; r < 2; ++r) write_status(r);
}

void HsbyPair::update_heads() {
  // Two passes: a head leaves Active before the other one enters it.
  for (int pass = 0; pass < 2; ++pass) {
    for (int r = 0; r < 2; ++r) {
      Rack& k = rk(r);
      const HeadRole want = !k.powered                     ? HeadRole::Off
                            : k.state == CpuState::Primary ? HeadRole::Active
                                                           : HeadRole::Passive;
      if ((want == HeadRole::Active) != (pass == 1)) continue;
      if (k.head_told && k.head_role == want) continue;
      k.head_told = true;
      k.head_role = want;
      if (k.head != nullptr) k.head->set_role(m_sched.now(), want);
    }
  }
}

void HsbyPair::write_status(int r) {
  const NonTransferArea& nt = m_p.plan.non_transfer;
  if (!rk(r).powered || nt.count < 3 || nt.first + 2 >= m_p.sizes.holding) return;
  rk(r).ram.set_holding(nt.first + 2, status_word(r));
}

std::uint16_t HsbyPair::status_word(int r) const {
  // The seed's status register (command_register.hpp): this unit and the other (01/10/11; 00
  // when this unit cannot hear it), logic mismatch, designation, hot standby active. The CHS
  // interface error bit stays 0: the CPU-CHS interface is not modelled.
  if (!valid(r)) return 0;
  const Rack& k = rk(r);
  const Rack& o = rk(1 - r);
  const bool hears_other = o.powered && m_fibre == FibreState::Ok;
  auto code = [](CpuState s) {
    switch (s) {
      case CpuState::Offline: return UnitCode::Offline;
      case CpuState::Primary: return UnitCode::Primary;
      case CpuState::Standby: return UnitCode::Standby;
      case CpuState::Off: break;
    }
    return UnitCode::None;
  };
  StatusRegister st;
  st.this_unit = code(k.state);
  st.other_unit = hears_other ? code(o.state) : UnitCode::None;
  st.logic_mismatch = hears_other && k.checksum != o.checksum;
  st.designation_b = k.designation == Designation::B;
  st.hsby_active = true;
  return encode_status(st);
}

// ---- observers -----------------------------------------------------------------------------

CpuState HsbyPair::state(int r) const {
  return valid(r) ? rk(r).state : CpuState::Off;
}

int HsbyPair::primary() const {
  for (int r = 0; r < 2; ++r)
    if (rk(r).state == CpuState::Primary) return r;
  return -1;
}

int HsbyPair::standby() const {
  for (int r = 0; r < 2; ++r)
    if (rk(r).state == CpuState::Standby) return r;
  return -1;
}

bool HsbyPair::powered(int r) const {
  return valid(r) && rk(r).powered;
}
bool HsbyPair::cpu_running(int r) const {
  return valid(r) && rk(r).powered && rk(r).cpu_run;
}
KeySwitch HsbyPair::key(int r) const {
  return valid(r) ? rk(r).key : KeySwitch::Run;
}
Designation HsbyPair::designation(int r) const {
  return valid(r) ? rk(r).designation : Designation::A;
}
std::uint32_t HsbyPair::firmware(int r) const { return valid(r) ? rk(r).firmware : 0; }

std::uint32_t HsbyPair::logic_checksum(int r) const {
  return valid(r) ? rk(r).checksum : 0;
}
bool HsbyPair::logic_match() const {
  return rk(0).checksum == rk(1).checksum;
}
UpdatePhase HsbyPair::update_phase(int r) const {
  return valid(r) ? rk(r).update : UpdatePhase::None;
}
HeadRole HsbyPair::head_role(int r) const {
  return valid(r) ? rk(r).head_role : HeadRole::Off;
}
StateRam& HsbyPair::ram(int r) {
  return rk(r == 1 ? 1 : 0).ram;
}
const StateRam& HsbyPair::ram(int r) const {
  return rk(r == 1 ? 1 : 0).ram;
}
std::uint64_t HsbyPair::scans(int r) const {
  return valid(r) ? rk(r).scans : 0;
}

ChsLeds HsbyPair::leds(int r) const {
  ChsLeds l;
  if (!valid(r) || !rk(r).powered) return l;
  const Rack& k = rk(r);
  const Rack& o = rk(1 - r);
  l.ready = Led::On;
  l.primary = k.state == CpuState::Primary ? Led::On : Led::Off;
  l.standby = (k.update == UpdatePhase::Requested || k.update == UpdatePhase::Running)
                  ? Led::Blinking
              : k.state == CpuState::Standby ? Led::On
                                             : Led::Off;
  if (k.duplicate) {
    l.com_act = Led::Blinking;  // Q6: startup error
  } else {
    const bool talking = o.powered && m_fibre == FibreState::Ok && k.cpu_run && o.cpu_run &&
                         !o.duplicate && k.update == UpdatePhase::None;
    l.com_act = talking ? Led::On : Led::Off;  // off from the key to Xfer of an update (p. 21)
  }
  l.com_err = (o.powered && m_fibre != FibreState::Ok) ? Led::On : Led::Off;
  return l;
}

}  // namespace pbvbus::quantum
