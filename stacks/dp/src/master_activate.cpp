// Deactivating and activating a configured slave at run time (master.hpp set_slave_active;
// S7 SFC 12 D_ACT_DP, docs/s7cpu.md "DP system functions").
#include "pbvbus/dp/master.hpp"

namespace pbvbus::dp {

bool Master::set_slave_active(std::uint8_t address, bool active) {
  if (!has_slave(address)) return false;
  Slave& s = slave(address);
  if (s.p.active == active) return true;
  s.p.active = active;
  // As reset_slaves() does for one slave: the start-up begins afresh.
  fail_jobs(s, m_now);
  s.in_dx = false;
  s.image->set_valid(false);
  s.last_dx = bus::kNever;
  s.last_main = bus::kNever;
  s.last_retry = bus::kNever;
  s.diag_after_dh = false;
  s.alarms_seen.clear();
  s.probe = false;
  s.failed = false;  // a deactivated slave is not a failed one: no StationReturn later
  if (!active) {
    s.state = SlaveStatusState::Inactive;
    const StandardDiag d{0, kDiagDeactivated, 0, kNoMaster, s.p.ident};
    const auto b = d.encode();
    s.diag.assign(b.begin(), b.end());
  } else {
    const bool running = m_mode == MasterMode::Clear || m_mode == MasterMode::Operate;
    s.state = running ? SlaveStatusState::Diag : SlaveStatusState::Inactive;
  }
  return true;
}

}  // namespace pbvbus::dp
