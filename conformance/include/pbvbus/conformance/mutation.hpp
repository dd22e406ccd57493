#pragma once
// Mutation score of the battery (docs/conformance.md): run it against every mutant slave
// (devices/slave_mutant.hpp) of a DUT spec and count which broken rules it catches
// (conformance/src/mutation.cpp).
//
// For one DUT spec (a slave model; a pty DUT has no mutants):
// - the unbroken model runs the whole battery once (it must pass);
// - each mutant runs only the tests aimed at it (TestCase::targets):
//     killed          one of them failed;
//     survived        all of them passed, or no test is aimed at it (a gap in the battery);
//     not applicable  every one of them was n/a (the GSD lacks the feature, e.g. no Freeze);
//     error           the mutant DUT could not be built.
// score = killed / (killed + survived) (1 when both are 0).

#include <optional>
#include <string>
#include <vector>

#include "pbvbus/conformance/battery.hpp"

namespace pbvbus::conformance {

enum class MutantStatus : std::uint8_t { Killed, Survived, NotApplicable, Error };
const char* mutant_status_name(MutantStatus s);  ///< "killed", "survived", "n/a", "error"

struct MutantOutcome {
  devices::SlaveMutant mutant{};
  MutantStatus status = MutantStatus::Survived;
  std::vector<std::string> targeted;  ///< ids of the tests aimed at it
  std::vector<std::string> failing;   ///< ids of those that failed
  std::string note;                   ///< why (n/a reasons, "no test aimed at it", DUT error)
};

struct MutationReport {
  DutSpec spec;                      ///< without mutant
  bool unbroken_passed = false;      ///< the unbroken model passed the whole battery
  std::vector<std::string> unbroken_failures;  ///< ids (or "DUT: error") when it did not
  std::vector<MutantOutcome> mutants;          ///< in slave_mutants() order
  std::size_t count(MutantStatus s) const;
  /// killed / (killed + survived); 1.0 when there is nothing to count.
  double score() const;
};

/// Runs the unbroken model and every mutant of `spec` (spec.mutant and spec.pty_path ignored).
MutationReport mutation_score(const DutSpec& spec);

/// The table mutant × DUT: per mutant its status and failing test ids for each report, and the
/// score per report. Markdown (for docs) and aligned text (for the terminal).
std::string mutation_table_markdown(const std::vector<MutationReport>& reports);
std::string mutation_table_text(const std::vector<MutationReport>& reports);

}  // namespace pbvbus::conformance
