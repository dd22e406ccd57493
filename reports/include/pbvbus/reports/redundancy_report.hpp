#pragma once
// The redundancy part of the run report in text and JSON (data: pbvbus/simulation/redundancy_system.hpp).

#include <ostream>
#include <vector>

#include "pbvbus/simulation/redundancy_system.hpp"

namespace pbvbus::tools {

/// `,"redundancy":[...]` (schema in simulation/report.hpp); nothing when there is no redundant
/// system.
void write_redundancy_text(const std::vector<RedundancyReport>& r, std::ostream& os);
void write_redundancy_json(const std::vector<RedundancyReport>& r, std::ostream& os);

}  // namespace pbvbus::tools
