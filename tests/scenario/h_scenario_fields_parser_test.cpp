// The loader's refusals of the fields of docs/h-scenario-changes.md (battery/RAM, T8, watchdog
// OBs, OB 72's SFC 27, partitions, the fault switch_to_cpu), each with its FILE:LINE:COLUMN; also
// under ASan+UBSan. The runs are in tests/simulation/h_scenario_fields_test.cpp.
#include <gtest/gtest.h>

#include <algorithm>
#include <string>
#include <vector>

#include "pbvbus/scenario/scenario.hpp"

namespace pbvbus::tools {
namespace {

// ---- refusals with FILE:LINE:COLUMN (columns counted by hand in the comments) ----
TEST(HScenarioFieldsParser, RefusalsCarryTheirPositions) {
  const std::string text = R"(h_system { name: "H"
cpu { load_memory_mb: 2 link_up_time: "3s"
cpu0 { ram_mb: 1 }
cpu1 { ram_mb: 2 }
s7_memory { db { number: 1 size: 4 } } }
expansion_rack { number: 3 side: 0 module { name: "DO" out_len: 1 partition: 16 } }
program {
watchdog_ob { ob: 29 cycle: "100ms" }
watchdog_ob { ob: 35 }
watchdog_ob { ob: 36 cycle: "100ms" phase: "100ms" }
watchdog_ob { ob: 37 cycle: "10ms" db: 2 }
ob72_updat_po: 16
}
}
fault { at: "1s" switch_to_cpu { added_module { system: "X" address: 3 } changed_db: 9 } }
)";
  // line 2 `cpu { ` 6 -> col 7; line 4 `cpu1 { ` 7 -> col 8; line 6: 17 + 10 + 8 + 9 + 11 + 11
  // = 66 -> col 67; line 8 `watchdog_ob { ` 14 -> col 15; line 9 the entry (col 1); line 10
  // 14 + 7 + 15 = 36 -> col 37; line 11 14 + 7 + 14 = 35 -> col 36; line 12 col 1; line 15
  // `fault { at: "1s" ` 17 + `switch_to_cpu { ` 16 + `added_module { ` 15 = 48 -> col 49, and
  // + `system: "X" ` 12 + `address: 3 ` 11 + `} ` 2 = 73 -> col 74.
  std::vector<std::string> got;
  for (const auto& d : parse_scenario(text, "h.textproto").errors) got.push_back(d.str());
  std::sort(got.begin(), got.end());
  std::vector<std::string> want = {
      "h.textproto:2:7: load_memory_mb derives the link-up time (T8): remove link_up_time or load_memory_mb",
      "h.textproto:4:8: ram_mb 2 differs from cpu0's 1 (both CPUs of a pair have the same RAM)",
      "h.textproto:6:67: partition 16 is not 1..15 (0: the OB 1 image)",
      "h.textproto:8:15: watchdog_ob: OB 29 is not a watchdog OB 30..38",
      "h.textproto:9:1: watchdog_ob needs a cycle, e.g. cycle: \"100ms\"",
      "h.textproto:10:37: watchdog_ob: phase 100ms is not below the cycle 100ms",
      "h.textproto:11:36: watchdog_ob: DB 2 is not in cpu.s7_memory",
      "h.textproto:12:1: ob72_updat_po: partition 16 is not 1..15 (SFC 27 refuses it with W#16#8090)",
      "h.textproto:15:49: switch_to_cpu: \"X\" is not a redundant_master_system this h_system drives",
      "h.textproto:15:74: switch_to_cpu: DB 9 is not in the h_system's cpu.s7_memory",
  };
  std::sort(want.begin(), want.end());
  EXPECT_EQ(got, want);
}

// A bad duration and fields without what they need.
TEST(HScenarioFieldsParser, BadValuesAreRefused) {
  const std::string text = R"(h_system { name: "H"
cpu { work_memory_mb: 1
cpu0 { ram_mb: 70000 } }
program {
watchdog_ob { ob: 35 cycle: "fast" }
watchdog_ob { ob: 35 cycle: "100ms" width: 3 }
}
}
fault { at: "1s" repair_at: "2s" switch_to_cpu { } }
)";
  // line 2 `cpu { ` -> col 7; line 3 `cpu0 { ` -> col 8; line 5 14 + 7 = 21 -> col 22; line 6
  // 14 + 7 + 15 = 36 -> col 37; line 9 `fault { at: "1s" ` -> repair_at at col 18.
  std::vector<std::string> got;
  for (const auto& d : parse_scenario(text, "h.textproto").errors) got.push_back(d.str());
  std::sort(got.begin(), got.end());
  std::vector<std::string> want = {
      "h.textproto:2:7: work_memory_mb and link_up_base_time need load_memory_mb (T8: the link-up from the memory size)",
      "h.textproto:3:8: ram_mb 70000 is above 65536",
      "h.textproto:5:22: bad duration \"fast\" for cycle (e.g. \"100ms\")",
      "h.textproto:6:37: watchdog_ob: width 3 is not 1, 2 or 4",
      "h.textproto:9:18: switch_to_cpu has no repair: remove repair_at",
  };
  std::sort(want.begin(), want.end());
  EXPECT_EQ(got, want);
}

// The S7-1500R/H profile has no operator master swap (docs/h-system.md rule 13): refused at the
// fault's kind, `fault { at: "1s" ` 17 characters -> col 18.
TEST(HScenarioFieldsParser, SwitchToCpuIsRefusedInThe1500Profile) {
  const auto r = parse_scenario(R"(h_system { name: "H" cpu { profile: S7_1500RH } }
fault { at: "1s" switch_to_cpu { } }
)",
                                "h.textproto");
  ASSERT_EQ(r.errors.size(), 1u);
  EXPECT_EQ(r.errors[0].str(), "h.textproto:2:18: switch_to_cpu: the S7-1500R/H profile has no operator master swap");
}

}  // namespace
}  // namespace pbvbus::tools
