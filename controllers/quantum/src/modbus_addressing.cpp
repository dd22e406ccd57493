#include "pbvbus/quantum/modbus_addressing.hpp"

namespace pbvbus::quantum {

std::string check_modbus_address(int address, bool swap_enabled) {
  if (swap_enabled && (address < 1 || address > kModbusMaxPrimaryAddress))
    return "Modbus address " + std::to_string(address) +
           " is outside 1..119, which a Hot Standby port with the address swap needs (the "
           "standby answers at +128, at most 247)";
  if (!swap_enabled && (address < 1 || address > kModbusMaxAddress))
    return "Modbus address " + std::to_string(address) + " is outside 1..247";
  return {};
}

std::uint8_t ModbusPortAddressing::address(int rack, bool primary) const {
  const std::uint8_t own = m_addr[rack == kRackB ? 1 : 0];
  if (!m_swap || primary) return own;
  // An address check_modbus_address refuses (> 119) gets no offset rather than a wrapped one.
  if (own + kModbusStandbyOffset > kModbusMaxAddress) return own;
  return static_cast<std::uint8_t>(own + kModbusStandbyOffset);
}

std::uint8_t mbplus_standby_address(std::uint8_t primary) {
  if (primary < 1 || primary > 64) return 0;
  return static_cast<std::uint8_t>((primary - 1 + 32) % 64 + 1);
}

}  // namespace pbvbus::quantum
