// HCpuPair: the SFC 90 H_CTRL blocks of link-up and update (h_sfc90.hpp decodes the SFC) and
// F5's second part (a second sync link failing later). docs/h-sfc90.md has the rules.
#include "pbvbus/s7h/h_cpu_pair.hpp"

namespace pbvbus::devices {

bool HCpuPair::set_link_up_enabled(bool on, bus::Ticks now) {
  run_due(now);
  if (m_link_up_disabled == !on) return false;
  m_link_up_disabled = !on;
  for (int r = 0; r < 2; ++r)
    if (powered(r)) diag(r, now, on ? "SFC 90: link-up re-enabled" : "SFC 90: link-up disabled");
  after_step(now);  // a waiting start request links up now (evaluate)
  return true;
}

bool HCpuPair::set_update_enabled(bool on, bus::Ticks now) {
  run_due(now);
  if (m_update_disabled == !on) return false;
  m_update_disabled = !on;
  for (int r = 0; r < 2; ++r)
    if (powered(r)) diag(r, now, on ? "SFC 90: update re-enabled" : "SFC 90: update disabled");
  if (on) {
    for (int s = 0; s < 2; ++s) {
      if (!m_cpu[s].update_waiting) continue;
      m_cpu[s].update_waiting = false;
      // Only a standby still in LINK-UP over a whole link with its master in RUN waits here
      // (any loss aborted the link-up and ended the wait, set_state).
      begin_update(s, now);
    }
  }
  after_step(now);
  return true;
}

// 000 L2594-2597 (replacing the sync modules or fibres one after the other): "If both
// fiber-optic cables or synchronization submodules are successively damaged ... the system
// reactions are the same as described above. The only exception is that the standby CPU does
// not go to STOP mode but instead requests a reset." The first failure already stopped the
// standby (F5); the second gives it the reset request (STOP until MRES, rule 20).
void HCpuPair::second_link_lost(bus::Ticks now) {
  const int m = master();
  if (m < 0 || master_count() != 1) return;
  const int s = partner(m);
  Cpu& c = m_cpu[s];
  if (c.role != CpuRole::Standby || c.state != CpuState::Stop || c.reset_request) return;
  c.reset_request = true;
  c.want_run = false;
  diag(s, now, "reset request: second sync link failed (memory reset needed)");
  diag(m, now, "second sync link failed: the standby CPU requests a reset");
}

}  // namespace pbvbus::devices
