// Semantic errors of a dp_slave's module list and User_Prm_Data come out as FILE:LINE:COLUMN,
// never as an abort inside protobuf (issue: a repeated field located without an index made
// ParseInfoTree::GetLocation abort with "Index must be in range", exit 134). Also built into
// the ASan+UBSan suite.
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "pbvbus/scenario/scenario.hpp"

namespace pbvbus::tools {
namespace {

// Relative GSD paths are looked up next to the scenario file: examples/gsd.
const std::string kFile = PBVBUS_SOURCE_DIR "/examples/refused.textproto";

std::vector<std::string> errors_of(const std::string& text) {
  std::vector<std::string> out;
  for (const auto& d : parse_scenario(text, kFile).errors) out.push_back(d.str());
  return out;
}

const std::string kHead =
    "line { name: \"A\" baud: \"1.5M\" }\n"           // line 1
    "dp_master { address: 1 line: \"A\" }\n";         // line 2

TEST(ScenarioRefusedModules, MoreModulesThanMaxModule) {
  // PBVB0A02 is modular with Max_Module = 8; nine modules are one too many. The error points at
  // the module list (its first element: line 4, column 12).
  std::string text = kHead + "dp_slave { address: 4 line: \"A\" gsd: \"gsd/PBVB0A02.gsd\" master: 1\n"
                             "  modules: [\"8DI DC24V\", \"8DI DC24V\", \"8DI DC24V\", \"8DI DC24V\",\n"
                             "            \"8DI DC24V\", \"8DI DC24V\", \"8DI DC24V\", \"8DI DC24V\",\n"
                             "            \"8DI DC24V\"] }\n";
  const auto errs = errors_of(text);
  ASSERT_EQ(errs.size(), 1u);
  EXPECT_EQ(errs[0], kFile + ":4:3: module list refused by gsd/PBVB0A02.gsd: 9 modules selected, "
                             "Max_Module = 8");
}

TEST(ScenarioRefusedModules, CompactStationGivenSeveralModules) {
  // PBVB0A01 is a compact station (Modular_Station = 0) with one module.
  const auto errs = errors_of(kHead +
                              "dp_slave { address: 3 line: \"A\" gsd: \"gsd/PBVB0A01.gsd\" master: 1\n"
                              "  modules: [\"16DI/16DO DC24V\", \"16DI/16DO DC24V\"] }\n");
  ASSERT_EQ(errs.size(), 1u);
  EXPECT_NE(errs[0].find(kFile + ":4:3: module list refused by gsd/PBVB0A01.gsd: a compact station "
                                 "(Modular_Station = 0) takes exactly one module"),
            std::string::npos)
      << errs[0];
  EXPECT_EQ(errs[0].find("modular GSD"), std::string::npos) << errs[0];
}

TEST(ScenarioRefusedModules, ModularStationWithoutModules) {
  const auto errs = errors_of(kHead +
                              "dp_slave { address: 4 line: \"A\" gsd: \"gsd/PBVB0A02.gsd\" master: 1 }\n");
  ASSERT_EQ(errs.size(), 1u);
  EXPECT_EQ(errs[0], kFile + ":3:1: dp_slave with the modular GSD \"gsd/PBVB0A02.gsd\" needs a "
                             "module list (modules: [\"...\"], at most Max_Module = 8)");
}

TEST(ScenarioRefusedModules, UnknownModuleIsLocatedAtItsElement) {
  const auto errs = errors_of(kHead +
                              "dp_slave { address: 4 line: \"A\" gsd: \"gsd/PBVB0A02.gsd\" master: 1\n"
                              "  modules: [\"8DI DC24V\", \"no such\"] }\n");
  ASSERT_EQ(errs.size(), 1u);
  EXPECT_EQ(errs[0].rfind(kFile + ":4:", 0), 0u) << errs[0];
  EXPECT_NE(errs[0].find("unknown module \"no such\""), std::string::npos) << errs[0];
}

TEST(ScenarioRefusedModules, IoAndFaultModuleReferencesOutOfRange) {
  // module_index beyond the list, in an io entry and in a fault: errors, not aborts.
  const auto errs = errors_of(
      kHead +
      "dp_slave { address: 4 line: \"A\" gsd: \"gsd/PBVB0A02.gsd\" master: 1\n"
      "  modules: [\"8DI DC24V\"] io { module_index: 5 constant { value: 1 } } }\n"
      "fault { at: \"1ms\" channel_diag { line: \"A\" address: 4 module_index: 7 channel: 0 "
      "error_type: 1 } }\n");
  ASSERT_EQ(errs.size(), 2u);
  for (const auto& e : errs) EXPECT_EQ(e.rfind(kFile + ":", 0), 0u) << e;
}

}  // namespace
}  // namespace pbvbus::tools
