// `dp_slave { mutant: "..." }` (test-only mutant slaves, devices/slave_mutant.hpp): the loader
// parses the name into DpSlavePlan::mutant, an unknown name is an error at FILE:LINE:COLUMN that
// lists the valid names, and the slave model built from the plan carries the mutant.
#include <gtest/gtest.h>

#include <string>

#include "pbvbus/slaves/slave_mutant.hpp"
#include "pbvbus/simulation/dp_system.hpp"
#include "pbvbus/scenario/scenario.hpp"

namespace pbvbus::tools {
namespace {

// The file name decides where relative GSD paths are looked up: examples/.
const std::string kFile = PBVBUS_SOURCE_DIR "/examples/test.textproto";

std::string head() {
  return "name: \"t\"\nduration: \"100ms\"\nline { name: \"A\" baud: \"1.5M\" }\n"
         "dp_master { address: 1 line: \"A\" }\n";
}

TEST(DpMutantScenario, MutantIsParsedAndBuilt) {
  const auto r = parse_scenario(
      head() +
          "dp_slave { address: 3 line: \"A\" gsd: \"gsd/PBVB0A01.gsd\" master: 1 mutant: \"ignore_fcb\" }\n"
          "dp_slave { address: 4 line: \"A\" gsd: \"gsd/PBVB0A01.gsd\" master: 1 }\n",
      kFile);
  ASSERT_TRUE(r.ok()) << r.errors.front().str();
  ASSERT_EQ(r.plan->dp_slaves.size(), 2u);
  EXPECT_EQ(r.plan->dp_slaves[0].mutant, devices::SlaveMutant::IgnoreFcb);
  EXPECT_EQ(r.plan->dp_slaves[1].mutant, std::nullopt);
  // The model built from the plan is the mutant: its station executes FCB repeats.
  DpSlaveNode node(r.plan->dp_slaves[0], r.plan->lines[0].params);
  EXPECT_EQ(node.model().mutant(), devices::SlaveMutant::IgnoreFcb);
  EXPECT_TRUE(node.model().station().mutation().ignore_fcb);
  DpSlaveNode plain(r.plan->dp_slaves[1], r.plan->lines[0].params);
  EXPECT_EQ(plain.model().mutant(), std::nullopt);
  EXPECT_FALSE(plain.model().station().mutation().any());
}

TEST(DpMutantScenario, TsdrTooLateBypassesTheMaxTsdrBound) {
  const auto r = parse_scenario(
      head() +
          "dp_slave { address: 3 line: \"A\" gsd: \"gsd/PBVB0A01.gsd\" master: 1 mutant: \"tsdr_too_late\" }\n",
      kFile);
  ASSERT_TRUE(r.ok()) << r.errors.front().str();
  DpSlaveNode node(r.plan->dp_slaves[0], r.plan->lines[0].params);
  // PBVB0A01: MaxTsdr_1.5M = 150, so the mutant answers after 150 + 20 = 170 t_bit.
  EXPECT_EQ(node.model().tsdr(), 170u);
  EXPECT_EQ(node.model().station().response_delay(), 170u);
}

TEST(DpMutantScenario, UnknownMutantIsAnErrorAtItsField) {
  // `dp_slave { address: 3 line: "A" gsd: "gsd/PBVB0A01.gsd" master: 1 mutant: ...`: `mutant`
  // starts at column 67 (`master` at 57 + "master: 1 " = 10).
  const auto r = parse_scenario(
      head() + "dp_slave { address: 3 line: \"A\" gsd: \"gsd/PBVB0A01.gsd\" master: 1 mutant: \"nope\" }\n",
      kFile);
  ASSERT_EQ(r.errors.size(), 1u);
  std::string known;
  for (const auto& i : devices::slave_mutants()) known += (known.empty() ? "" : ", ") + std::string(i.name);
  EXPECT_EQ(r.errors[0].str(), kFile + ":5:67: unknown mutant \"nope\" (known: " + known + ")");
  // The list starts with the first names of the catalogue, spelled as in scenarios.
  EXPECT_EQ(known.rfind("tsdr_too_late, ignore_min_tsdr, ignore_fcb, no_prm_req_bit", 0), 0u);
}

}  // namespace
}  // namespace pbvbus::tools
