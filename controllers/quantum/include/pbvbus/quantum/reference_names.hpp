#pragma once
// How the seed writes a state RAM reference (seed 003 "State RAM"): the table digit followed by
// the 1-based number in five digits, e.g. 4x index 0 = "400001", 0x index 95 = "000096". Used
// in the refusal messages of the transfer plan and the register checks.

#include <cstdint>
#include <string>

#include "pbvbus/quantum/state_ram.hpp"

namespace pbvbus::quantum {

/// "400001" for (Register4x, 0); numbers above 99999 keep all their digits ("465536").
std::string reference_name(RefType type, std::uint32_t index);

}  // namespace pbvbus::quantum
