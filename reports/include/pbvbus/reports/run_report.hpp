#pragma once
// The run report (pbvbus/simulation/report.hpp) in text and JSON: what `pbvbus run` prints. Includes the per-kind parts.

#include <ostream>
#include <vector>

#include "pbvbus/reports/dp_report.hpp"
#include "pbvbus/reports/gateway_report.hpp"
#include "pbvbus/reports/h_report.hpp"
#include "pbvbus/reports/redundancy_report.hpp"
#include "pbvbus/simulation/report.hpp"

namespace pbvbus::tools {

void write_text(const Report& r, std::ostream& os);
void write_json(const Report& r, std::ostream& os);

}  // namespace pbvbus::tools
