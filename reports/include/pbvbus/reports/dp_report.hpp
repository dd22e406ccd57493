#pragma once
// The DP part of the run report in text and JSON (data: pbvbus/simulation/dp_system.hpp).

#include <ostream>
#include <vector>

#include "pbvbus/simulation/dp_system.hpp"

namespace pbvbus::tools {

/// The DP part of the text report.
void write_dp_text(const std::vector<DpMasterReport>& r, std::ostream& os);
/// The DP part of the JSON report: `,"dp_masters":[...]` (schema in simulation/report.hpp).
void write_dp_json(const std::vector<DpMasterReport>& r, std::ostream& os);
/// The slaves' own views, text and JSON (`,"dp_slaves":[...]`).
void write_dp_slaves_text(const std::vector<DpSlaveView>& r, std::ostream& os);
void write_dp_slaves_json(const std::vector<DpSlaveView>& r, std::ostream& os);

}  // namespace pbvbus::tools
