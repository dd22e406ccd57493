#pragma once
// What the scenario tests of tools/ share: the parser's messages for a text, and a whole run of
// a valid scenario to its duration with its report (as `pbvbus run` makes it, speed 1.0).
#include <optional>
#include <string>
#include <vector>

#include "pbvbus/simulation/report.hpp"
#include "pbvbus/scenario/scenario.hpp"
#include "pbvbus/simulation/simulation.hpp"

namespace pbvbus::tools::test {

/// Every message of parse_scenario(text, file) as "FILE:LINE:COLUMN: text".
inline std::vector<std::string> scenario_errors(const std::string& text,
                                                const std::string& file = "h.textproto") {
  std::vector<std::string> out;
  for (const auto& d : parse_scenario(text, file).errors) out.push_back(d.str());
  return out;
}

struct ScenarioRun {
  std::string error;            ///< the parser's first message when the text is not valid
  std::optional<Report> report;
};

/// Parses `text`, runs it from start to its duration and reports.
inline ScenarioRun run_scenario(const std::string& text, const std::string& file = "h.textproto") {
  ScenarioRun out;
  const auto loaded = parse_scenario(text, file);
  if (!loaded.ok()) {
    out.error = loaded.errors.empty() ? "not valid" : loaded.errors[0].str();
    return out;
  }
  Simulation sim(*loaded.plan);
  sim.start();
  sim.run_until(*sim.duration());
  out.report = sim.report(1.0);
  return out;
}

}  // namespace pbvbus::tools::test
