#include "pbvbus/quantum/command_register.hpp"

#include "pbvbus/quantum/reference.hpp"

namespace pbvbus::quantum {
namespace {

bool bit(std::uint16_t w, int n) {
  return (w & modicon_bit(n)) != 0;
}
void put(std::uint16_t& w, int n, bool v) {
  if (v) w = static_cast<std::uint16_t>(w | modicon_bit(n));
}
/// A two-bit code whose first digit is Modicon bit `hi` and second bit `hi + 1`.
UnitCode code_at(std::uint16_t w, int hi) {
  return static_cast<UnitCode>((bit(w, hi) ? 2 : 0) | (bit(w, hi + 1) ? 1 : 0));
}
void put_code(std::uint16_t& w, int hi, UnitCode c) {
  const auto v = static_cast<unsigned>(c);
  put(w, hi, (v & 2U) != 0);
  put(w, hi + 1, (v & 1U) != 0);
}
std::string ref4x(std::uint32_t i) {
  return format_reference(RefType::Register4x, i);
}

}  // namespace

CommandRegister decode_command(std::uint16_t w) {
  CommandRegister c;
  c.keyswitch_override = bit(w, kCmdOverrideBit);
  c.run_a = bit(w, kCmdRunABit);
  c.run_b = bit(w, kCmdRunBBit);
  c.standby_stays_on_logic_mismatch = bit(w, kCmdLogicMismatchBit);
  c.exec_upgrade_while_running = bit(w, kCmdExecUpgradeBit);
  for (std::size_t p = 0; p < 3; ++p) c.swap_disabled[p] = bit(w, kCmdSwapDisabledBits[p]);
  return c;
}

std::uint16_t encode_command(const CommandRegister& c) {
  std::uint16_t w = 0;
  put(w, kCmdOverrideBit, c.keyswitch_override);
  put(w, kCmdRunABit, c.run_a);
  put(w, kCmdRunBBit, c.run_b);
  put(w, kCmdLogicMismatchBit, c.standby_stays_on_logic_mismatch);
  put(w, kCmdExecUpgradeBit, c.exec_upgrade_while_running);
  for (std::size_t p = 0; p < 3; ++p) put(w, kCmdSwapDisabledBits[p], c.swap_disabled[p]);
  return w;
}

std::uint16_t encode_status(const StatusRegister& s) {
  std::uint16_t w = 0;
  put_code(w, 15, s.this_unit);
  put_code(w, 13, s.other_unit);
  put(w, 12, s.logic_mismatch);
  put(w, 11, s.designation_b);
  put(w, 2, s.chs_interface_error);
  put(w, 1, s.hsby_active);
  return w;
}

StatusRegister decode_status(std::uint16_t w) {
  StatusRegister s;
  s.this_unit = code_at(w, 15);
  s.other_unit = code_at(w, 13);
  s.logic_mismatch = bit(w, 12);
  s.designation_b = bit(w, 11);
  s.chs_interface_error = bit(w, 2);
  s.hsby_active = bit(w, 1);
  return s;
}

std::string check_non_transfer_area(const NonTransferArea& area, std::uint32_t per_scan_4x) {
  if (area.count == 0) return {};
  if (area.count < kMinNonTransferRegisters)
    return "the non-transfer area " + ref4x(area.first) + " has " + std::to_string(area.count) +
           " registers, it must have at least 4 (2 reverse transfer, the status register, one "
           "more)";
  const std::uint64_t end = std::uint64_t{area.first} + area.count;  // one past the last
  if (end > per_scan_4x) {
    const std::string last = ref4x(static_cast<std::uint32_t>(end - 1));
    if (per_scan_4x == 0)
      return "the non-transfer area " + ref4x(area.first) + ".." + last +
             " must lie inside the 4x registers transferred every scan, and none are";
    return "the non-transfer area " + ref4x(area.first) + ".." + last +
           " does not lie entirely inside the 4x registers transferred every scan (" + ref4x(0) +
           ".." + ref4x(per_scan_4x - 1) + ")";
  }
  return {};
}

std::string check_command_register(std::uint32_t cmd, std::uint32_t per_scan_4x, bool twelve_k,
                                   const NonTransferArea& area) {
  if (cmd >= per_scan_4x) {
    if (per_scan_4x == 0)
      return "command register " + ref4x(cmd) +
             " must lie in the 4x registers transferred every scan, and none are";
    return "command register " + ref4x(cmd) +
           " lies outside the 4x registers transferred every scan (" + ref4x(0) + ".." +
           ref4x(per_scan_4x - 1) + ")";
  }
  if (twelve_k && cmd >= kTwelveKCommandLimit)
    return "command register " + ref4x(cmd) +
           " is not one of the first 9000 4x registers (400001..409000), which the 12K option "
           "requires";
  if (area.count != 0 && cmd >= area.first && cmd - area.first < area.count)
    return "command register " + ref4x(cmd) + " lies inside the non-transfer area (" +
           ref4x(area.first) + ".." + ref4x(area.first + area.count - 1) +
           "); it must be outside it";
  return {};
}

}  // namespace pbvbus::quantum
