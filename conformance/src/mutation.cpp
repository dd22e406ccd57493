// Mutation score of the battery (mutation.hpp).

#include "pbvbus/conformance/mutation.hpp"

#include <algorithm>
#include <cstdio>
#include <sstream>

namespace pbvbus::conformance {

const char* mutant_status_name(MutantStatus s) {
  switch (s) {
    case MutantStatus::Killed: return "killed";
    case MutantStatus::Survived: return "survived";
    case MutantStatus::NotApplicable: return "n/a";
    case MutantStatus::Error: return "error";
  }
  return "?";
}

std::size_t MutationReport::count(MutantStatus s) const {
  return static_cast<std::size_t>(
      std::count_if(mutants.begin(), mutants.end(), [s](const MutantOutcome& m) { return m.status == s; }));
}

double MutationReport::score() const {
  const std::size_t k = count(MutantStatus::Killed), s = count(MutantStatus::Survived);
  return k + s == 0 ? 1.0 : static_cast<double>(k) / static_cast<double>(k + s);
}

MutationReport mutation_score(const DutSpec& in) {
  MutationReport rep;
  rep.spec = in;
  rep.spec.mutant.reset();
  rep.spec.pty_path.reset();

  const BatteryReport base = run_battery(rep.spec);
  if (!base.dut_error.empty()) rep.unbroken_failures.push_back("DUT: " + base.dut_error);
  for (const auto& r : base.results)
    if (r.verdict == Verdict::Fail || r.verdict == Verdict::Error)
      rep.unbroken_failures.push_back(r.id + (r.verdict == Verdict::Error ? " (error)" : ""));
  rep.unbroken_passed = base.passed();

  for (const auto& info : devices::slave_mutants()) {
    MutantOutcome m;
    m.mutant = info.mutant;
    for (const auto& t : all_tests())
      if (std::find(t.targets.begin(), t.targets.end(), info.mutant) != t.targets.end()) m.targeted.push_back(t.id);
    if (m.targeted.empty()) {
      m.status = MutantStatus::Survived;
      m.note = "no test is aimed at it";
      rep.mutants.push_back(std::move(m));
      continue;
    }
    DutSpec s = rep.spec;
    s.mutant = info.mutant;
    BatteryOptions o;
    o.only = m.targeted;
    const BatteryReport r = run_battery(s, o);
    if (!r.dut_error.empty()) {
      m.status = MutantStatus::Error;
      m.note = r.dut_error;
      rep.mutants.push_back(std::move(m));
      continue;
    }
    std::size_t na = 0;
    for (const auto& t : r.results) {
      if (t.verdict == Verdict::Fail) m.failing.push_back(t.id);
      if (t.verdict == Verdict::NotApplicable) {
        ++na;
        if (m.note.empty()) m.note = t.id + ": " + t.message;
      }
    }
    if (!m.failing.empty()) {
      m.status = MutantStatus::Killed;
      m.note.clear();
    } else if (na == r.results.size()) {
      m.status = MutantStatus::NotApplicable;
    } else {
      // An error (the test could not establish its precondition) did not test the rule: the
      // mutant is not killed by it.
      m.status = MutantStatus::Survived;
      m.note = "every test aimed at it passed (or could not run: error)";
    }
    rep.mutants.push_back(std::move(m));
  }
  return rep;
}

namespace {

std::string cell(const MutantOutcome& m) {
  std::string o = mutant_status_name(m.status);
  if (!m.failing.empty()) {
    o += ":";
    for (const auto& id : m.failing) o += " " + id;
  } else if (m.status != MutantStatus::Killed && !m.note.empty()) {
    o += " (" + m.note + ")";
  }
  return o;
}

std::string dut_name(const MutationReport& r) {
  std::string p = r.spec.gsd_path;
  const auto slash = p.find_last_of('/');
  return slash == std::string::npos ? p : p.substr(slash + 1);
}

std::string score_text(const MutationReport& r) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.0f %% (%zu/%zu)", 100.0 * r.score(), r.count(MutantStatus::Killed),
                r.count(MutantStatus::Killed) + r.count(MutantStatus::Survived));
  return buf;
}

}  // namespace

std::string mutation_table_markdown(const std::vector<MutationReport>& reports) {
  std::ostringstream o;
  o << "| mutant |";
  for (const auto& r : reports) o << " " << dut_name(r) << " |";
  o << "\n|---|";
  for (std::size_t i = 0; i < reports.size(); ++i) o << "---|";
  o << "\n";
  for (std::size_t k = 0; k < devices::slave_mutants().size(); ++k) {
    o << "| `" << devices::slave_mutants()[k].name << "` |";
    for (const auto& r : reports) o << " " << (k < r.mutants.size() ? cell(r.mutants[k]) : "") << " |";
    o << "\n";
  }
  o << "| unbroken model |";
  for (const auto& r : reports) o << " " << (r.unbroken_passed ? "passes" : "FAILS") << " |";
  o << "\n| **score** |";
  for (const auto& r : reports) o << " **" << score_text(r) << "** |";
  o << "\n";
  return o.str();
}

std::string mutation_table_text(const std::vector<MutationReport>& reports) {
  std::ostringstream o;
  for (const auto& r : reports) {
    o << dut_name(r) << " (" << r.spec.gsd_path << "): score " << score_text(r) << ", unbroken model "
      << (r.unbroken_passed ? "passes" : "FAILS");
    if (!r.unbroken_failures.empty()) {
      o << " (";
      for (std::size_t i = 0; i < r.unbroken_failures.size(); ++i) o << (i ? " " : "") << r.unbroken_failures[i];
      o << ")";
    }
    o << "\n";
    for (const auto& m : r.mutants) {
      char name[32];
      std::snprintf(name, sizeof name, "  %-26s ", std::string(devices::slave_mutant_name(m.mutant)).c_str());
      o << name << cell(m) << "\n";
    }
  }
  return o.str();
}

}  // namespace pbvbus::conformance
