#pragma once
// The Hot Standby command register, the status register and the non-transfer area (seed 003
// pp. 75-95: "CHS Instruction Block", "Command Register", "Elements of the Nontransfer Area",
// "The Hot Standby Status Register", "Bits in the Hot Standby Command Register", "Hot Standby
// Status Register for Configuration Extension"; seeds-digest.md §8; docs/quantum-hsby.md).
//
// Bits are numbered the Modicon way: bit 1 is the most significant bit of the 16-bit word,
// bit 16 the least significant (the public IEC 840 USE 106 page: "Bit 16 in Modicon convention
// is bit 0 in IEC convention. Setting bit 16 means writing a 0x0001 into the command register").
//
// Command register (a 4x register, default 400001):
//   bit 16  keyswitch override: 1 = enabled (the command register, not the CHS keys, decides
//           Offline/Run). Public IEC page above (bit 16 = 0x0001) and the public ProSoft
//           description of the same word ("this bit takes effect only if bit 16 is set").
//   bit 15  controller A: 1 = Run, 0 = Offline   } seed p. 90-91: "bits 14 and 15", "the
//   bit 14  controller B: 1 = Run, 0 = Offline   } operating mode of controller B is determined
//                                                   by the state of bit 14".
//   bit 13  logic mismatch: 0 = force the standby offline, 1 = it stays standby.
//   bit 12  executive upgrade: 0 = only after the application stops, 1 = while running.
//           Bits 13 and 12: not fixed by the seed's text (its figure lost the positions); they
//           are the next two in the seed's field order, and the Unity-era successor of this
//           word (%SW60, IEC numbering) keeps override/A/B/mismatch/upgrade at IEC bits 0..4 =
//           Modicon bits 16..12.
//   bit 8   Modbus port 1: 0 = swap the address at switchover, 1 = do not swap.
//   bit 7   Modbus port 2, same meaning.
//   bit 6   Modbus port 3, same meaning.
//           Ports: no source fixes them. Decision: the successor word has "swap Modbus port 1"
//           at IEC bit 8 (= Modicon bit 8); ports 2 and 3 continue upwards in IEC numbering
//           (IEC 9, 10 = Modicon 7, 6). Polarity follows the seed (1 = does NOT swap), not the
//           successor (which inverted it).
//   Other bits: unused; decode ignores them, encode writes 0.
//
// Status register (third register of the non-transfer area; written by each unit for itself):
//   bits 15-16  this unit:  01 offline, 10 primary, 11 standby (bit 15 is the code's first
//               digit). Seed p. 83-84: the reverse-transfer example enables STAT "if this PLC is
//               the Standby" from status bits 15 and 16.
//   bits 13-14  the other unit, same codes; 00 = not known / not reachable (the seed lists only
//               01/10/11; 00 is what a unit writes when it hears nothing from the other).
//   bit 12      logic: 0 = the PLCs have matching logic, 1 = they do not.
//   bit 11      this unit's designation switch: 0 = A, 1 = B.
//   bit 2       CHS interface: 0 = healthy, 1 = an interface error has been detected.
//   bit 1       hot standby: 1 = active, 0 = not activated.
//               Bits 1-2 only with a configuration extension (seed p. 95 note). Which of the
//               two is bit 1: the seed's figure lists the fields from bit 16 leftwards and
//               names the interface error before "hot standby active", so the error is bit 2.

#include <array>
#include <cstdint>
#include <string>

#include "pbvbus/quantum/transfer_plan.hpp"

namespace pbvbus::quantum {

/// Mask of Modicon bit n (1 = MSB .. 16 = LSB).
constexpr std::uint16_t modicon_bit(int n) {
  return static_cast<std::uint16_t>(1U << (16 - n));
}

struct CommandRegister {
  bool keyswitch_override = false;               ///< bit 16
  bool run_a = false;                            ///< bit 15
  bool run_b = false;                            ///< bit 14
  bool standby_stays_on_logic_mismatch = false;  ///< bit 13
  bool exec_upgrade_while_running = false;       ///< bit 12
  std::array<bool, 3> swap_disabled{};           ///< ports 1..3: bits 8, 7, 6 (1 = no swap)
  bool operator==(const CommandRegister&) const = default;
};

inline constexpr int kCmdOverrideBit = 16;
inline constexpr int kCmdRunABit = 15;
inline constexpr int kCmdRunBBit = 14;
inline constexpr int kCmdLogicMismatchBit = 13;
inline constexpr int kCmdExecUpgradeBit = 12;
inline constexpr std::array<int, 3> kCmdSwapDisabledBits = {8, 7, 6};
/// Every bit the command register defines.
inline constexpr std::uint16_t kCommandMask = modicon_bit(16) | modicon_bit(15) | modicon_bit(14) |
                                              modicon_bit(13) | modicon_bit(12) | modicon_bit(8) |
                                              modicon_bit(7) | modicon_bit(6);

CommandRegister decode_command(std::uint16_t word);
std::uint16_t encode_command(const CommandRegister& c);

enum class UnitCode : std::uint8_t { None = 0, Offline = 0b01, Primary = 0b10, Standby = 0b11 };

struct StatusRegister {
  UnitCode this_unit = UnitCode::None;   ///< bits 15-16
  UnitCode other_unit = UnitCode::None;  ///< bits 13-14
  bool logic_mismatch = false;           ///< bit 12
  bool designation_b = false;            ///< bit 11
  bool hsby_active = false;              ///< bit 1
  bool chs_interface_error = false;      ///< bit 2
  bool operator==(const StatusRegister&) const = default;
};

/// Every bit the status register defines.
inline constexpr std::uint16_t kStatusMask = modicon_bit(16) | modicon_bit(15) | modicon_bit(14) |
                                             modicon_bit(13) | modicon_bit(12) | modicon_bit(11) |
                                             modicon_bit(2) | modicon_bit(1);

std::uint16_t encode_status(const StatusRegister& s);
StatusRegister decode_status(std::uint16_t word);

/// 0-based 4x index of reverse transfer register k (k = 0, 1): the area's first two registers,
/// copied standby → primary (seed p. 82 "registers 4x and 4x + 1 in the nontransfer block").
constexpr std::uint32_t reverse_transfer_index(const NonTransferArea& area, int k) {
  return area.first + static_cast<std::uint32_t>(k);
}
/// 0-based 4x index of the status register: the area's third register (seed p. 81: an area
/// from 40010 puts the status register at 40012).
constexpr std::uint32_t status_register_index(const NonTransferArea& area) {
  return area.first + 2;
}

/// The smallest non-transfer area (seed p. 76-78 "four or more 4x registers").
inline constexpr std::uint32_t kMinNonTransferRegisters = 4;
/// With the 12K option the command register must be one of the first 9000 4x (seed p. 89).
inline constexpr std::uint32_t kTwelveKCommandLimit = 9000;

/// Placement of the non-transfer area: none (count 0) is accepted; otherwise ≥ 4 contiguous
/// registers entirely inside the 4x registers sent every scan (indexes 0..per_scan_4x-1).
/// Returns "" when accepted, else the reason (one sentence).
std::string check_non_transfer_area(const NonTransferArea& area, std::uint32_t per_scan_4x);

/// Placement of the command register (0-based 4x index): inside the 4x registers sent every
/// scan, with the 12K option also among the first 9000 4x, and outside the non-transfer area.
/// Returns "" when accepted, else the reason (one sentence).
std::string check_command_register(std::uint32_t command_index, std::uint32_t per_scan_4x,
                                   bool twelve_k, const NonTransferArea& area);

}  // namespace pbvbus::quantum
