#include "pbvbus/gateways/modbus_image.hpp"

#include <utility>

namespace pbvbus::gateways {

void apply_word_order(std::span<std::uint8_t> v, WordOrder order) {
  const bool words = order == WordOrder::WordSwap || order == WordOrder::ByteWordSwap;
  const bool bytes = order == WordOrder::ByteSwap || order == WordOrder::ByteWordSwap;
  const std::size_t n = v.size();
  const std::size_t full = n / 4 * 4;
  for (std::size_t i = 0; i < full; i += 4) {
    if (words) {
      std::swap(v[i], v[i + 2]);
      std::swap(v[i + 1], v[i + 3]);
    }
    if (bytes) {
      std::swap(v[i], v[i + 1]);
      std::swap(v[i + 2], v[i + 3]);
    }
  }
  // A trailing group shorter than 4 octets gets only the byte part.
  if (bytes)
    for (std::size_t i = full; i + 1 < n; i += 2) std::swap(v[i], v[i + 1]);
}

std::vector<std::uint16_t> telegram_to_registers(const ModbusUnitMap& unit,
                                                 std::span<const std::uint8_t> telegram,
                                                 bool outputs) {
  std::vector<std::uint16_t> regs(outputs ? unit.holding_registers : unit.input_registers, 0);
  std::vector<std::uint8_t> view;
  for (const ModbusModuleMap& m : unit.modules) {
    const std::size_t off = outputs ? m.out_offset : m.in_offset;
    const std::size_t len = outputs ? m.out_len : m.in_len;
    const std::size_t first = outputs ? m.holding_register : m.input_register;
    view.assign(len, 0);
    for (std::size_t i = 0; i < len && off + i < telegram.size(); ++i) view[i] = telegram[off + i];
    apply_word_order(view, m.order);
    for (std::size_t i = 0; i < len; ++i) {
      auto& r = regs[first + i / 2];
      r = static_cast<std::uint16_t>(r | (i % 2 == 0 ? view[i] << 8 : view[i]));
    }
  }
  return regs;
}

int patch_output_register(const ModbusUnitMap& unit, std::uint16_t reg, std::uint16_t value,
                          std::span<std::uint8_t> outputs) {
  if (reg >= unit.holding_register_module.size()) return -1;
  const std::size_t mi = unit.holding_register_module[reg];
  const ModbusModuleMap& m = unit.modules[mi];
  if (m.out_offset + m.out_len > outputs.size()) return -1;
  auto octets = outputs.subspan(m.out_offset, m.out_len);
  std::vector<std::uint8_t> view(octets.begin(), octets.end());
  apply_word_order(view, m.order);
  const std::size_t k = 2u * (reg - m.holding_register);
  view[k] = static_cast<std::uint8_t>(value >> 8);
  if (k + 1 < view.size()) view[k + 1] = static_cast<std::uint8_t>(value & 0xFF);
  apply_word_order(view, m.order);
  std::copy(view.begin(), view.end(), octets.begin());
  return static_cast<int>(mi);
}

}  // namespace pbvbus::gateways
