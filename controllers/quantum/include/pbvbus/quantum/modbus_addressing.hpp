#pragma once
// The Modbus and Modbus Plus address swap at switchover (seed 003 p. 93 "Swap Address at
// Switchover", "Modbus Plus Port Address Swapping at Switchover"; seeds-digest.md §8 "Address
// swap"; docs/quantum-hsby.md).
//
// Modbus (one ModbusPortAddressing per port, 1..3):
//   - each unit's port has a configured address (rotary switches / configuration; A and B
//     "should match" but may differ). With the swap in effect, the primary answers at its
//     configured address and the other unit (standby or offline) at its configured address
//     + 128, so the offset follows the primary role: A primary → A 1, B 129; after a switchover
//     B 1, A 129. Configured addresses must then be 1..119 (119 + 128 = 247, the highest Modbus
//     unit address).
//   - with the swap disabled for the port (command register bit "does not swap"), no offset at
//     all: both units answer at their configured address ("after switchover the two ports have
//     the same address"); configured addresses 1..247.
//   - a change of the swap setting (request_swap) is held pending and takes effect only at the
//     next switchover (on_switchover), "the port addresses are not affected until a switchover
//     occurs". The setting at construction is the startup value and is in effect at once.
//   - which unit is primary is the caller's (the pair's) knowledge: address() is asked with it.
// Modbus Plus: the standby is the primary's address + 32 within 1..64, wrapping (1 ↔ 33,
//   50 ↔ 18); always swapped, no option.

#include <cstdint>
#include <string>

namespace pbvbus::quantum {

inline constexpr int kRackA = 0;
inline constexpr int kRackB = 1;
/// The standby's Modbus offset and the highest primary address that leaves room for it.
inline constexpr int kModbusStandbyOffset = 128;
inline constexpr int kModbusMaxPrimaryAddress = 119;
inline constexpr int kModbusMaxAddress = 247;

/// "" when `address` can be configured on a Hot Standby port with the swap `swap_enabled`,
/// else the reason: with the swap 1..119 (so that +128 stays ≤ 247), without it 1..247.
std::string check_modbus_address(int address, bool swap_enabled);

class ModbusPortAddressing {
 public:
  /// Configured addresses of this port on unit A and unit B; the startup swap setting.
  ModbusPortAddressing(std::uint8_t address_a, std::uint8_t address_b, bool swap_enabled)
      : m_addr{address_a, address_b}, m_swap(swap_enabled), m_pending(swap_enabled) {}

  /// The Modbus unit address the port of `rack` (kRackA/kRackB) answers at while that unit is
  /// (primary == true) or is not the primary.
  std::uint8_t address(int rack, bool primary) const;

  /// The command register's swap setting for this port changed: effective at the next switchover.
  void request_swap(bool enabled) { m_pending = enabled; }
  /// A switchover happened: the pending setting takes effect (before address() is asked again).
  void on_switchover() { m_swap = m_pending; }

  bool swap_enabled() const { return m_swap; }
  bool swap_pending() const { return m_pending; }

 private:
  std::uint8_t m_addr[2];
  bool m_swap;
  bool m_pending;
};

/// The Modbus Plus address of the standby for a primary at `primary` (1..64): +32 wrapping
/// within 1..64. The same function gives the primary from the standby. 0 for an address outside
/// 1..64.
std::uint8_t mbplus_standby_address(std::uint8_t primary);

}  // namespace pbvbus::quantum
