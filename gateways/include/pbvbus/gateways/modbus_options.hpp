#pragma once
// The Modbus gateway's options (docs/gateway-modbus.md): plain structs the scenario loader fills. The register
// layout (modbus_map.hpp) and the gateway (modbus_gateway.hpp) both read them.

#include <cstddef>
#include <cstdint>
#include <map>
#include <vector>

namespace pbvbus::gateways {

/// Byte/word order of a module's octets in its registers. Applied within the module, from its
/// first octet, in groups of 4 octets ("ABCD" = the module's octets in telegram order); a
/// trailing group shorter than 4 octets gets only the byte part (pairs swapped, a last odd
/// octet stays). Each order is its own inverse, so writes use the same transform.
enum class WordOrder : std::uint8_t {
  HighByteFirst,  ///< AB CD (default: first octet in the high byte, as real gateways do)
  ByteSwap,       ///< BA DC
  WordSwap,       ///< CD AB: the two 16-bit words of each 4-octet group swapped
  ByteWordSwap,   ///< DC BA
};

/// What a read of process data answers while the slave is not in data exchange.
enum class StaleReaction : std::uint8_t {
  Exception,  ///< 0x0B gateway target failed (reads and writes of process data; the default)
  KeepLast,   ///< the last image the master received
  Zero,       ///< zeros
  Value,      ///< `stale_value` in every register (bits: its low bit)
};

struct ModbusSlaveOptions {
  WordOrder word_order = WordOrder::HighByteFirst;
  /// Per module (index in slot order, 0-based): wins over `word_order`.
  std::map<std::size_t, WordOrder> module_word_order;
  StaleReaction stale = StaleReaction::Exception;
  std::uint16_t stale_value = 0;
};

/// Highest slave address with a standby unit (address + 128 = 247, the highest individual
/// Modbus address; 248..255 are reserved, Modbus over Serial Line V1.02 §2.2).
inline constexpr std::uint8_t kMaxStandbyAddress = 119;

struct ModbusGatewayOptions {
  /// Per PROFIBUS address; slaves not listed get the defaults.
  std::map<std::uint8_t, ModbusSlaveOptions> slaves;
  /// Units 0 and 255 answer as the gateway itself (live list, counters, master mode).
  bool gateway_units = true;
  /// Quantum-style standby addressing (seeds-digest Q3): unit = address + 128 shows the
  /// Standby side of a redundant source, read-only. Ignored for a plain master system. Only
  /// for addresses 1..kMaxStandbyAddress (seed 003: primary 1..119, standby <= 247): a slave
  /// above 119 is reachable only at its primary unit (the map carries a warning).
  bool standby_units = false;

  const ModbusSlaveOptions& slave(std::uint8_t address) const {
    static const ModbusSlaveOptions kDefault{};
    auto it = slaves.find(address);
    return it == slaves.end() ? kDefault : it->second;
  }
};

}  // namespace pbvbus::gateways
