#pragma once
// The gateways part of the run report in text and JSON (data: pbvbus/simulation/gateway_report.hpp).

#include <ostream>
#include <vector>

#include "pbvbus/simulation/gateway_report.hpp"

namespace pbvbus::tools {

void write_gateways_text(const std::vector<GatewayReport>& r, std::ostream& os);
/// `,"gateways":[...]` (schema in simulation/gateway_report.hpp).
void write_gateways_json(const std::vector<GatewayReport>& r, std::ostream& os);

}  // namespace pbvbus::tools
