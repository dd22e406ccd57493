#pragma once
// The key of a DP-V1 data record in the slave's tables, shared by the slave engine and the
// slave application.

#include <cstdint>

namespace pbvbus::dp {

/// The key of a DP-V1 data record (slot, index) in the slave's record tables.
constexpr std::uint16_t record_key(std::uint8_t slot, std::uint8_t index) {
  return static_cast<std::uint16_t>((slot << 8) | index);
}

}  // namespace pbvbus::dp
