// The pair's link-up/update operations through the H-system model (h_system.hpp): each at
// scheduler.now(), then the reconciliation like every other operation.
#include "pbvbus/devices/h_system.hpp"

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

}  // namespace pbvbus::devices
