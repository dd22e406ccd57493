#pragma once
// The Quantum Hot Standby part of the run report in text and JSON (data and schema:
// pbvbus/simulation/quantum_report.hpp).
#include <ostream>
#include <vector>

#include "pbvbus/simulation/quantum_report.hpp"

namespace pbvbus::tools {

void write_quantum_text(const std::vector<QuantumReport>& r, std::ostream& os);
/// `,"quantum":[...]` (nothing without a quantum_hot_standby).
void write_quantum_json(const std::vector<QuantumReport>& r, std::ostream& os);

}  // namespace pbvbus::tools
