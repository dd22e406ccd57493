#pragma once
// Quantum state RAM (seed 003 "State RAM", seeds-digest.md §8): the four reference tables of a
// 984/IEC controller — 0x coils (discrete outputs), 1x discrete inputs, 3x input registers,
// 4x holding registers. References are 1-based as the manuals write them (000001, 100001,
// 300001, 400001); `index` below is the 0-based offset within a table (reference 400001 is
// index 0 of the 4x table), which is also the Modbus PDU address (FC01/05/15 coils = 0x,
// FC02 = 1x, FC04 = 3x, FC03/06/16/23 = 4x).
//
// Sizes are configured per table (a real CPU configures them in its configurator: 0x and 1x
// in multiples of 16, up to the CPU's state RAM). Storage is one octet per bit and one word
// per register: simple to copy in transfer order, and the transfer's byte cost is computed by
// the scan-time model from the counts, not from this layout.

#include <cstddef>
#include <cstdint>
#include <vector>

namespace pbvbus::quantum {

enum class RefType : std::uint8_t { Coil0x = 0, Input1x = 1, Register3x = 3, Register4x = 4 };

struct StateRamSizes {
  std::uint32_t coils = 1536;      ///< 0x
  std::uint32_t inputs = 512;      ///< 1x
  std::uint32_t input_regs = 512;  ///< 3x
  std::uint32_t holding = 1872;    ///< 4x
  bool operator==(const StateRamSizes&) const = default;
};

class StateRam {
 public:
  StateRam() : StateRam(StateRamSizes{}) {}
  explicit StateRam(const StateRamSizes& s)
      : m_sizes(s), m_coils(s.coils, 0), m_inputs(s.inputs, 0), m_input_regs(s.input_regs, 0),
        m_holding(s.holding, 0) {}

  const StateRamSizes& sizes() const { return m_sizes; }

  /// Number of references of one table.
  std::uint32_t count(RefType t) const {
    switch (t) {
      case RefType::Coil0x: return m_sizes.coils;
      case RefType::Input1x: return m_sizes.inputs;
      case RefType::Register3x: return m_sizes.input_regs;
      case RefType::Register4x: return m_sizes.holding;
    }
    return 0;
  }

  // Bits: 0 or 1. Out-of-range indexes are the caller's error (checked by the Modbus handler
  // against count() before any access); at() throws std::out_of_range.
  bool coil(std::uint32_t i) const { return m_coils.at(i) != 0; }
  void set_coil(std::uint32_t i, bool v) { m_coils.at(i) = v ? 1 : 0; }
  bool input(std::uint32_t i) const { return m_inputs.at(i) != 0; }
  void set_input(std::uint32_t i, bool v) { m_inputs.at(i) = v ? 1 : 0; }
  std::uint16_t input_reg(std::uint32_t i) const { return m_input_regs.at(i); }
  void set_input_reg(std::uint32_t i, std::uint16_t v) { m_input_regs.at(i) = v; }
  std::uint16_t holding(std::uint32_t i) const { return m_holding.at(i); }
  void set_holding(std::uint32_t i, std::uint16_t v) { m_holding.at(i) = v; }

  // Whole tables, for the transfer (copied range by range in the order 0x, 1x, 3x, 4x).
  std::vector<std::uint8_t>& coils() { return m_coils; }
  std::vector<std::uint8_t>& inputs() { return m_inputs; }
  std::vector<std::uint16_t>& input_regs() { return m_input_regs; }
  std::vector<std::uint16_t>& holdings() { return m_holding; }
  const std::vector<std::uint8_t>& coils() const { return m_coils; }
  const std::vector<std::uint8_t>& inputs() const { return m_inputs; }
  const std::vector<std::uint16_t>& input_regs() const { return m_input_regs; }
  const std::vector<std::uint16_t>& holdings() const { return m_holding; }

 private:
  StateRamSizes m_sizes;
  std::vector<std::uint8_t> m_coils;
  std::vector<std::uint8_t> m_inputs;
  std::vector<std::uint16_t> m_input_regs;
  std::vector<std::uint16_t> m_holding;
};

}  // namespace pbvbus::quantum
