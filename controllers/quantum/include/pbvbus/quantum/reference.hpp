#pragma once
// Quantum reference numbers as the manuals and configurators write them (seed 003 "State
// RAM"): a leading digit for the table (0 coils, 1 discrete inputs, 3 input registers, 4
// holding registers) followed by the 1-based number, in the 6-digit form "400001" (numbers up
// to 65535) or the 5-digit form "40001" (up to 9999). The 0-based index within the table is
// what state RAM and the Modbus PDU use (400001 = 4x index 0).

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>

#include "pbvbus/quantum/state_ram.hpp"

namespace pbvbus::quantum {

struct Reference {
  RefType type = RefType::Register4x;
  std::uint32_t index = 0;  ///< 0-based within the table
  bool operator==(const Reference&) const = default;
};

/// "400001" / "40001" → {4x, 0}; nullopt for anything else (wrong length, a table digit other
/// than 0/1/3/4, number 0, a 6-digit number above 65535, a sign or space).
std::optional<Reference> parse_reference(std::string_view text);

/// The 6-digit form: {4x, 0} → "400001".
std::string format_reference(const Reference& r);

/// The 6-digit form of a table index: (4x, 9007) → "409008".
inline std::string format_reference(RefType t, std::uint32_t index) {
  return format_reference(Reference{t, index});
}

}  // namespace pbvbus::quantum
