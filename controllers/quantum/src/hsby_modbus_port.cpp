// One Modbus port of the Hot Standby pair (hsby_modbus_port.hpp).
#include "pbvbus/quantum/hsby_modbus_port.hpp"

#include "pbvbus/quantum/command_register.hpp"

namespace pbvbus::quantum {

HsbyModbusPort::HsbyModbusPort(const HsbyPair& pair, int port, std::uint8_t address_rack0,
                               std::uint8_t address_rack1, bool swap)
    : m_pair(pair), m_port(port), m_addr(address_rack0, address_rack1, swap),
      m_seen(pair.switchovers().size()) {}

void HsbyModbusPort::sync() {
  const auto& sw = m_pair.switchovers();
  while (m_seen < sw.size()) {
    // The setting in the command register takes effect at the switchover (seed p. 93: "the
    // port addresses are not affected until a switchover occurs").
    const int p = sw[m_seen].new_rack;
    if (p >= 0 && m_port >= 1 && m_port <= 3) {
      const std::uint16_t w = m_pair.ram(p).holding(m_pair.params().command_register);
      m_addr.request_swap(!decode_command(w).swap_disabled[static_cast<std::size_t>(m_port - 1)]);
    }
    m_addr.on_switchover();
    ++m_seen;
  }
}

bool HsbyModbusPort::answers(int r) const {
  return m_pair.powered(r) && m_pair.cpu_running(r) && m_pair.state(r) != CpuState::Off;
}

std::uint8_t HsbyModbusPort::address(int r) {
  sync();
  if (!answers(r)) return 0;
  return m_addr.address(r, m_pair.state(r) == CpuState::Primary);
}

int HsbyModbusPort::rack_for(std::uint8_t unit) {
  if (unit == 0) return -1;
  const bool a0 = address(0) == unit;
  const bool a1 = address(1) == unit;
  if (a0 && a1) {
    ++m_conflicts;
    const int p = m_pair.primary();
    return p >= 0 ? p : 0;
  }
  return a0 ? 0 : a1 ? 1 : -1;
}

int HsbyModbusPort::rack_only(int r, std::uint8_t unit) {
  return unit != 0 && address(r) == unit ? r : -1;
}

}  // namespace pbvbus::quantum
