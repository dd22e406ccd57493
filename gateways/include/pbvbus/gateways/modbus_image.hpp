#pragma once
// Conversions between a slave's DP telegram (octets) and its Modbus registers, following the
// layout in modbus_map.hpp: each module starts on a new register, first octet (after the word
// order) in the high byte, an odd module's last low byte is 0.

#include <cstdint>
#include <span>
#include <vector>

#include "pbvbus/gateways/modbus_map.hpp"

namespace pbvbus::gateways {

/// Reorders a module's octets in place (see WordOrder). Its own inverse.
void apply_word_order(std::span<std::uint8_t> octets, WordOrder order);

/// All data registers of a unit from its input telegram (`outputs` false: input_registers
/// values) or output telegram (`outputs` true: holding_registers values). The telegram must
/// have the unit's input_len/output_len octets (shorter: missing octets read 0).
std::vector<std::uint16_t> telegram_to_registers(const ModbusUnitMap& unit,
                                                 std::span<const std::uint8_t> telegram,
                                                 bool outputs);

/// Writes register `reg` (holding-register number in the data area) into `outputs` (the whole
/// output telegram) through its module's word order; the low byte of an odd module's last
/// register is dropped. Returns the module index, or -1 if `reg` is outside the data area.
int patch_output_register(const ModbusUnitMap& unit, std::uint16_t reg, std::uint16_t value,
                          std::span<std::uint8_t> outputs);

}  // namespace pbvbus::gateways
