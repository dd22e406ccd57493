// The pair's link-up/update operations through the H-system model (h_system.hpp): each at
// scheduler.now(), then the reconciliation like every other operation.
#include "pbvbus/s7h/h_system.hpp"

namespace pbvbus::devices {

void HSystemModel::set_changed_db_kb(std::uint32_t kb) {
  m_pair.set_changed_db_kb(kb, m_sched.now());
  after_op();
}

HChangeResult HSystemModel::load_change(HChange kind) {
  const HChangeResult r = m_pair.load_change(kind, m_sched.now());
  after_op();
  return r;
}

void HSystemModel::set_standby_parameter_change(bool may_not_change) {
  m_pair.set_standby_parameter_change(may_not_change);
}

bool HSystemModel::memory_reset(int rack) {
  if (rack != 0 && rack != 1) return false;
  const bool ok = m_pair.memory_reset(rack, m_sched.now());
  after_op();
  return ok;
}

bool HSystemModel::load_memory_error(int rack) {
  if (!valid_rack(rack)) return false;
  const bool ok = m_pair.load_memory_error(rack, m_sched.now());
  after_op();
  return ok;
}

bool HSystemModel::inject_sync_error() {
  // The reaction of scan_execution's F18 (h_system_program.cpp), for a sync error injected by a
  // scenario ("diverging uninitialised data", digest §7 F18, §5): the same entries, then the
  // standby's switch_to_stop. Only a Redundant pair has two CPUs in step that can diverge.
  const bus::Ticks now = m_sched.now();
  m_pair.on_time(now);  // deadlines due now first, as every pair operation does
  if (m_pair.system_mode() != SystemMode::Redundant) {
    after_op();  // the deadlines just run may have changed a side
    return false;
  }
  sync_error_reaction(1 - m_pair.master(), now, "diverging uninitialised data");
  after_op();
  return true;
}

void HSystemModel::sync_error_reaction(int standby, bus::Ticks now, std::string_view cause) {
  // The pair has no sync-error operation: the standby's switch_to_stop gives exactly F18's
  // reaction (standby STOP, Solo, OB 72 StandbyStop on the master); like every fault STOP it
  // needs a STOP -> RUN to restart. Both CPUs log it.
  log_on_powered(now, 0,
                 "sync error (F18): " + std::string(cause) + "; standby rack " +
                     std::to_string(standby) + " to STOP");
  m_pair.switch_to_stop(standby, now);
}

}  // namespace pbvbus::devices
