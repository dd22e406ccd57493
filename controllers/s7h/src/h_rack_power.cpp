// The racks' power: PS 407 10A R halves, battery, RAM test (h_rack_power.hpp; docs/h-changes.md).
#include "pbvbus/s7h/h_rack_power.hpp"

#include <algorithm>
#include <stdexcept>
#include <string>

namespace pbvbus::devices {

HRackPower::HRackPower(HCpuPair& pair, HRackPowerParams p) : m_pair(pair), m_p(p) {}

std::size_t HRackPower::idx(int r) {
  if (r != 0 && r != 1) throw std::out_of_range("HRackPower: rack/half must be 0 or 1");
  return static_cast<std::size_t>(r);
}

bool HRackPower::supplied(int r) const {
  const auto& h = m_half[idx(r)];
  return m_on[idx(r)] && (m_p.redundant_ps ? (h[0] || h[1]) : h[0]);
}

void HRackPower::switch_on(int r, bus::Ticks now) {
  const std::size_t i = idx(r);
  m_pair.on_time(now);
  if (m_on[i]) return;
  m_on[i] = true;
  if (!supplied(r)) return;
  const bool buffered = m_ever_on[i] && m_p.battery[i];
  m_ever_on[i] = true;
  if (buffered || m_p.ram_kb == 0) {
    m_pair.power_on(r, now);
    return;
  }
  m_test_end[i] = now + ram_test_time(m_p.ram_kb);
}

void HRackPower::switch_off(int r, bus::Ticks now) {
  const std::size_t i = idx(r);
  m_pair.on_time(now);
  const bool was = supplied(r);
  m_on[i] = false;
  m_test_end[i] = bus::kNever;
  m_checksum[i] = false;
  if (was) m_pair.power_off(r, now);
}

bool HRackPower::fail_half(int r, int half, bus::Ticks now) {
  const std::size_t i = idx(r), h = idx(half);
  m_pair.on_time(now);
  if (!m_half[i][h]) return false;
  const bool was = supplied(r);
  m_half[i][h] = false;
  if (!was) return false;
  if (supplied(r)) {
    if (m_pair.state(r) != CpuState::Off)
      m_pair.log_entry(r, now,
                       "OB 81: power supply failure (PS 407 10A R half " + std::to_string(half) +
                           "), the other half supplies the rack",
                       kPsFailureIncoming);
    return false;
  }
  m_test_end[i] = bus::kNever;
  m_checksum[i] = false;
  if (m_pair.state(r) != CpuState::Off) m_pair.power_off(r, now);
  return true;
}

void HRackPower::repair_half(int r, int half, bus::Ticks now) {
  const std::size_t i = idx(r), h = idx(half);
  m_pair.on_time(now);
  if (m_half[i][h]) return;
  const bool was = supplied(r);
  m_half[i][h] = true;
  if (was) {
    if (m_pair.state(r) != CpuState::Off)
      m_pair.log_entry(r, now,
                       "OB 81: power supply failure gone (PS 407 10A R half " +
                           std::to_string(half) + " replaced)",
                       kPsFailureOutgoing);
    return;
  }
  if (!supplied(r)) return;
  m_on[i] = false;  // power returns as at switch_on (buffered or the RAM test)
  switch_on(r, now);
}

bool HRackPower::checksum_in_power_on_test(int r, bus::Ticks now) {
  m_pair.on_time(now);
  on_time(now);
  if (!self_testing(r)) return false;
  m_checksum[idx(r)] = true;
  return true;
}

bus::Ticks HRackPower::next_deadline() const { return std::min(m_test_end[0], m_test_end[1]); }

void HRackPower::on_time(bus::Ticks now) {
  for (;;) {
    const int r = m_test_end[0] <= m_test_end[1] ? 0 : 1;
    const bus::Ticks t = m_test_end[idx(r)];
    if (t == bus::kNever || t > now) return;
    m_test_end[idx(r)] = bus::kNever;
    m_pair.power_on(r, t);
    if (m_checksum[idx(r)]) {
      m_checksum[idx(r)] = false;
      m_pair.checksum_error(r, HChecksumContext::PowerOnTest, t);
    }
  }
}

}  // namespace pbvbus::devices
