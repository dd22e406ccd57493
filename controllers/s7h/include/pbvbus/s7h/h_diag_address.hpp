#pragma once
// D1: the DP diagnostic addresses as STEP 7 assigns them (001 §4.9.1 L2621-2630, Table 4-8
// L3053-3120; docs/h-diag-address.md).
//
// "DP diagnostic addresses occupy at least one byte of the address area for the DP master and
// for each DP slave ... If they are not assigned, STEP 7 assigns addresses starting from the
// highest byte address downwards" (001 L2621-2628). The manual's example: the master's
// diagnostic address 1023, the slave's in the master system 1022 (001 L3103-3106); OB 86 on a
// station failure carries "the DP slave's diagnostic address assigned to the DP master" (001
// L3064-3068).
// Decisions (a PG's defaults, as an S7 engineer finds them after configuring without typing any):
// - The highest byte address = the CPU's I/O address area per direction minus 1 (001 Table 4-5
//   L2601-2618: 8192 octets on a 414-4H -> 8191, 16384 on a 417-4H -> 16383).
// - Master systems in their order (the model's systems); each takes the next address down for
//   its DP master (the H-system's redundant DP master system has ONE diagnostic address, the
//   pair of interfaces being one master system), then one per DP slave in PROFIBUS address
//   order (a switched station once, like its I/O addresses), each the next one down. The
//   engineer configures the slaves in address order; STEP 7 counts in configuration order.
// - One address per slave (S7-compatible mode; the manual's "usually two in DPV1 mode", L2629,
//   is the second, slot-0 address, which no event of the model names).

#include <cstddef>
#include <cstdint>
#include <optional>
#include <vector>

namespace pbvbus::devices {

/// The highest byte address of a 417-4H's I/O address area (001 Table 4-5: 16384 octets).
inline constexpr std::uint16_t kDiagTop417 = 16383;
/// ... of a 414-4H (8192 octets).
inline constexpr std::uint16_t kDiagTop414 = 8191;

class HDiagAddresses {
 public:
  HDiagAddresses() = default;
  /// `stations[s]` = the PROFIBUS addresses of master system s's slaves (any order, repeats
  /// ignored). Assigned from `top` downwards as described above.
  HDiagAddresses(std::uint16_t top, const std::vector<std::vector<std::uint8_t>>& stations);
  /// Master system s's own diagnostic address (nullopt: no such system).
  std::optional<std::uint16_t> master(std::size_t system) const;
  /// The slave's diagnostic address in its master system (nullopt: not configured).
  std::optional<std::uint16_t> slave(std::size_t system, std::uint8_t station) const;

 private:
  struct System {
    std::uint16_t master = 0;
    std::vector<std::pair<std::uint8_t, std::uint16_t>> slaves;  ///< by PROFIBUS address
  };
  std::vector<System> m_systems;
};

}  // namespace pbvbus::devices
