#pragma once
// The per-scan state RAM transfer allocator (seed 003 pp. 36-41 "The State RAM Transfer and
// Scan Time", "Default Transfer Area", "Customizing Options"; pp. 94-100 "Transfer All State
// RAM", "Defining the Transfer Area of State RAM", "Transferring Additional State RAM Data";
// p. 44 and p. 48 (IEC heap); seeds-digest.md §8 "Transfer area (984)"; docs/quantum-hsby.md).
//
// Default "12K" area (pp. 38-39, 76, 98): the first 8192 0x, the first 8192 1x and a quota of
// 10 000 registers, 1000 for 3x and 9000 for 4x, computed by allocate_12k_registers:
//   - 3x + 4x ≤ 10 000: all registers of both types;
//   - otherwise 3x = min(3x, 1000 + max(0, 9000 − 4x)) (4x's unused quota moves to 3x), and
//     4x = min(4x, 10 000 − that 3x) (3x's unused quota moves to 4x);
//   - then 4x is rounded UP to the next multiple of 16 unless all 4x are included (capped at
//     the configured 4x count, i.e. rounding that would pass the end includes them all). 3x is
//     never rounded (the seed's example 2 transfers 3000 3x).
//   (3200, 9600) → (1000, 9008); (3200, 7000) → (3000, 7000); (700, 9600) → (700, 9312).

#include <cstdint>
#include <optional>
#include <string>
#include <utility>

#include "pbvbus/quantum/state_ram.hpp"
#include "pbvbus/quantum/transfer_plan.hpp"

namespace pbvbus::quantum {

struct TransferConfig {
  enum class Mode : std::uint8_t { Default12K, UserDefined, TransferAll };
  Mode mode = Mode::Default12K;
  /// "User defined": references of each type sent every scan (0 or multiples of 16, 4x ≥ 16).
  std::uint32_t coils = 0, inputs = 0, input_regs = 0, holding = 0;
  /// "Transfer Additional State RAM" (user defined only): references after the per-scan ones,
  /// sent in slices over `scans` scans (1..255), counts 0 or multiples of 16, at least one ≥ 16.
  struct Additional {
    bool enabled = false;
    std::uint32_t coils = 0, inputs = 0, input_regs = 0, holding = 0;
    int scans = 1;
  } additional;
  NonTransferArea non_transfer;        ///< 0-based 4x index, count (0 = none)
  std::uint32_t command_register = 0;  ///< 0-based 4x index: 400001 -> 0
  bool iec = false;                    ///< IEC Hot Standby: everything is transferred
  std::uint32_t iec_heap_bytes = 0;    ///< IEC heap (program data + DFB instance data)
};

/// The 12K option's register split: (3x, 4x) transferred every scan for the configured
/// counts (rule in the file comment).
std::pair<std::uint32_t, std::uint32_t> allocate_12k_registers(std::uint32_t regs3x,
                                                               std::uint32_t regs4x);

struct TransferPlanResult {
  std::optional<TransferPlan> plan;
  std::string error;  ///< one sentence when refused, else empty
};

/// The plan for a configuration against the configured state RAM, or the reason it is refused
/// (the first rule broken, in the order: mode rules, IEC limit, non-transfer area, command
/// register).
TransferPlanResult plan_transfer(const TransferConfig& cfg, const StateRamSizes& sizes);

/// References of `type` sent every scan by `plan` (all per-scan ranges start at index 0).
std::uint32_t per_scan_count(const TransferPlan& plan, RefType type);

/// The 0x/1x limit of the 12K option and the register quota (p. 38).
inline constexpr std::uint32_t kTwelveKBits = 8192;
inline constexpr std::uint32_t kTwelveKRegisters = 10000;
inline constexpr std::uint32_t kTwelveK3x = 1000;
inline constexpr std::uint32_t kTwelveK4x = 9000;
/// State RAM plus IEC heap of an IEC Hot Standby system (p. 44, p. 48): 128 KB.
inline constexpr std::uint32_t kIecTransferLimitBytes = 128U * 1024U;

/// Bytes of state RAM counted against the IEC limit: registers 2 B each, 0x and 1x packed 16
/// to a word (p. 44 counts state RAM in words: "10K Words (20 KByte)").
std::uint32_t state_ram_bytes(const StateRamSizes& sizes);

}  // namespace pbvbus::quantum
