// The racks' power supply of the H-system model (h_system.hpp block "the racks' power supply,
// RAM test"; docs/h-changes.md "In the H-system model"): HRackPower (h_rack_power.hpp) between
// the model's power operations and the pair, so that an unbuffered POWER ON runs the RAM test
// (000 L640, L786; 001 L1149-1153: about 8 s per MB) before the CPU starts.
#include <memory>

#include "pbvbus/s7h/h_system.hpp"

namespace pbvbus::devices {

void HSystemModel::set_rack_power(HRackPowerParams p) {
  m_rp = std::make_unique<HRackPower>(m_pair, p);
  m_rp_armed = bus::kNever;
}

void HSystemModel::rack_power_arm() {
  if (!m_rp) return;
  const bus::Ticks t = m_rp->next_deadline();
  if (t == bus::kNever || t == m_rp_armed) return;
  m_rp_armed = t;
  // A test ended early (power off) leaves a stale event: on_time() then finds nothing due.
  m_sched.schedule(t, [this] {
    m_rp_armed = bus::kNever;
    if (!m_rp) return;
    m_rp->on_time(m_sched.now());  // the pair's power_on at the test's end
    rack_power_arm();
    after_op();
  });
}

}  // namespace pbvbus::devices
