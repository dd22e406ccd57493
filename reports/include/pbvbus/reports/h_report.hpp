#pragma once
// The H-system part of the run report in text and JSON (data: pbvbus/simulation/h_report.hpp).

#include <ostream>
#include <string>
#include <string_view>
#include <vector>

#include "pbvbus/bus/time.hpp"
#include "pbvbus/simulation/h_report.hpp"

namespace pbvbus::tools {

/// "within" / "EXCEEDED" for a measured window against its planned bound.
std::string_view window_verdict(bus::Ticks measured, bus::Ticks planned);

/// The text part: per pair the CPUs, a timeline table per CPU, the I/O events, the updates.
void write_h_text(const std::vector<HSystemReport>& systems, std::ostream& os);
/// `,"h_systems_run":[...]` (nothing when `systems` is empty), to append inside a JSON object.
void write_h_json(const std::vector<HSystemReport>& systems, std::ostream& os);

/// "12.345" (s with ms, rounded down).
std::string format_s_ms(bus::Ticks t);

}  // namespace pbvbus::tools
