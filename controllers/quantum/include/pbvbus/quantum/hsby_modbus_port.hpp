#pragma once
// One Modbus port (1..3) of the Hot Standby pair as a polling host sees it (seed 003 p. 93;
// docs/quantum-hsby-modbus.md "The port and its network"): both racks' port p on one network,
// each answering at the address modbus_addressing.hpp gives it for its role. The owner asks
// rack_for(unit) for every request; the port follows the pair's switchovers lazily (each new
// switchover record: the swap setting the command register held at that moment takes effect,
// then the roles swap the addresses).
//
// Decisions:
//  - An unpowered rack, or one whose CPU is stopped, answers nothing.
//  - Two racks at one address (swap disabled, both configured alike) on a shared network would
//    collide on the wire; the port answers from the primary (or, without one, rack 0) and
//    counts the conflict. A user who disables the swap wires one point-to-point door per rack
//    (rack_only()).
//  - The command register's port bit is read from the primary's state RAM (with no primary,
//    from the new primary's at the switchover).

#include <cstdint>
#include <optional>

#include "pbvbus/quantum/hsby_pair.hpp"
#include "pbvbus/quantum/modbus_addressing.hpp"

namespace pbvbus::quantum {

class HsbyModbusPort {
 public:
  /// `address_a`/`address_b`: the port's configured address on rack 0 and rack 1. `swap`: the
  /// startup setting (command register "swap address at switchover" for this port).
  HsbyModbusPort(const HsbyPair& pair, int port, std::uint8_t address_rack0,
                 std::uint8_t address_rack1, bool swap);

  int port() const { return m_port; }
  /// The rack answering `unit` on the shared network now, or -1 (nobody: no reply / 0x0B).
  int rack_for(std::uint8_t unit);
  /// The address rack `r`'s port answers at now (0: it answers nothing).
  std::uint8_t address(int r);
  /// Point to point: only rack `r` is wired; the rack answering `unit`, or -1.
  int rack_only(int r, std::uint8_t unit);

  std::uint64_t conflicts() const { return m_conflicts; }
  bool swap_enabled() { sync(); return m_addr.swap_enabled(); }
  /// Brings the addressing up to the pair's switchovers (rack_for/address call it).
  void sync();

 private:
  bool answers(int r) const;
  const HsbyPair& m_pair;
  int m_port;
  ModbusPortAddressing m_addr;
  std::size_t m_seen = 0;  ///< switchover records applied
  std::uint64_t m_conflicts = 0;
};

}  // namespace pbvbus::quantum
