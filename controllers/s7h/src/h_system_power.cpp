// The H-system model's self-test and power faults (h_system.hpp; docs/h-changes.md): a checksum
// error of the cyclic self-test (001 Table 5-6) and the PS 407 10A R halves of F1 (000 L2517,
// 001 L8387-8390).
#include <string>
#include <utility>

#include "pbvbus/s7h/h_rack_power.hpp"
#include "pbvbus/s7h/h_system.hpp"

namespace pbvbus::devices {

bool HSystemModel::checksum_error(int rack) {
  if (!valid_rack(rack)) return false;
  const bool ok = m_pair.checksum_error(rack, HChecksumContext::Cyclic, m_sched.now());
  after_op();
  return ok;
}

void HSystemModel::log_entry(int rack, std::string text, std::uint16_t code) {
  if (!valid_rack(rack) || m_pair.state(rack) == CpuState::Off) return;
  m_pair.log_entry(rack, m_sched.now(), std::move(text), code);
  after_op();  // the deadlines log_entry ran may have changed a side
}

bool HSystemModel::ps_failure(int rack, int half) {
  if (!valid_rack(rack) || (half != 0 && half != 1)) return false;
  auto& h = m_ps_failed[static_cast<std::size_t>(rack)];
  if (h[static_cast<std::size_t>(half)]) return false;
  h[static_cast<std::size_t>(half)] = true;
  if (!(h[0] && h[1])) {
    const bus::Ticks now = m_sched.now();
    if (m_pair.state(rack) != CpuState::Off)
      m_pair.log_entry(rack, now,
                       "OB 81: power supply failure (PS 407 10A R half " + std::to_string(half) +
                           "), the other half supplies the rack",
                       kPsFailureIncoming);
    after_op();
    return false;
  }
  power_off(rack);  // F1: the CPU fails (as cpu_failure)
  return true;
}

bool HSystemModel::ps_repair(int rack, int half) {
  if (!valid_rack(rack) || (half != 0 && half != 1)) return false;
  auto& h = m_ps_failed[static_cast<std::size_t>(rack)];
  if (!h[static_cast<std::size_t>(half)]) return false;
  const bool both = h[0] && h[1];
  h[static_cast<std::size_t>(half)] = false;
  if (both) {
    power_on(rack);  // power returns (with set_rack_power: its RAM test rule)
    return true;
  }
  if (m_pair.state(rack) != CpuState::Off)
    m_pair.log_entry(rack, m_sched.now(),
                     "OB 81: power supply failure gone (PS 407 10A R half " +
                         std::to_string(half) + " replaced)",
                     kPsFailureOutgoing);
  after_op();
  return true;
}

}  // namespace pbvbus::devices
