#pragma once
// The S7 part of the run report in text and JSON (data and schema: pbvbus/simulation/s7_report.hpp).

#include <ostream>

#include "pbvbus/simulation/s7_report.hpp"

namespace pbvbus::tools {

void write_s7_text(const S7Report& r, std::ostream& os);
/// `,"s7":{...}` (nothing when the scenario has no S7 entries).
void write_s7_json(const S7Report& r, std::ostream& os);

}  // namespace pbvbus::tools
