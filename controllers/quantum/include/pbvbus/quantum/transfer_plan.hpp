#pragma once
// What the primary sends to the standby (seed 003 "State RAM transfer", seeds-digest.md §8):
// the ranges of state RAM carried on every scan, the "additional" ranges spread over several
// scans, and the non-transfer area inside the per-scan 4x range. transfer_area.hpp computes a
// plan from the configuration (12K default, user defined, additional, transfer all, IEC); the
// pair (hsby_pair.hpp) carries it out scan by scan.

#include <cstdint>
#include <vector>

#include "pbvbus/quantum/state_ram.hpp"

namespace pbvbus::quantum {

/// `count` references of one table from 0-based index `first` (reference 400001 = 4x index 0).
struct TransferRange {
  RefType type = RefType::Coil0x;
  std::uint32_t first = 0;
  std::uint32_t count = 0;
  bool operator==(const TransferRange&) const = default;
};

/// The 4x registers the transfer skips (seed 003 "Nontransfer area"): `count` ≥ 4 contiguous
/// registers from 0-based 4x index `first`, inside the per-scan 4x range. Registers first and
/// first+1 are the reverse transfer (standby → primary), first+2 is the status register.
struct NonTransferArea {
  std::uint32_t first = 0;
  std::uint32_t count = 0;  ///< 0 = no non-transfer area configured
  bool operator==(const NonTransferArea&) const = default;
};

struct TransferPlan {
  /// Sent on every scan, in the seed's order 0x, 1x, 3x, 4x (at most one range per table).
  std::vector<TransferRange> every_scan;
  /// The "additional" data: slice k (0-based) is sent with scan number n when n % slices.size()
  /// == k, in addition to every_scan; empty when no additional transfer is configured.
  std::vector<std::vector<TransferRange>> additional_slices;
  NonTransferArea non_transfer;
  bool operator==(const TransferPlan&) const = default;
};

}  // namespace pbvbus::quantum
