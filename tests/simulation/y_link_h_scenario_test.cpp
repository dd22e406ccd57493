// A Y-link under an H-system (docs/dp-link.md "Lower station failure"): the lower stations are
// modules of a switched station for the H CPUs. Lower station 3 (the link's module 0, IB 0..1:
// the I/O map has only the link, 2 x 2 octets, from address 0) loses power at 2 s and returns
// at 3 s: the link shows its module missing (Module_Status 11B) and the H model runs OB 83
// W#16#3961 (module removed) with MDL_ADDR 0, then W#16#3861 (inserted); nothing for module 1
// (station 4) and no OB 86 for the link.
#include <gtest/gtest.h>

#include <string>

#include "scenario_run_support.hpp"
#include "pbvbus/simulation/h_report.hpp"

namespace pbvbus::tools {
namespace {

constexpr bus::Ticks kMs = bus::kTicksPerMs;
constexpr bus::Ticks kS = bus::kTicksPerSecond;
const std::string kFile = PBVBUS_SOURCE_DIR "/examples/test.textproto";

const std::string kText = R"(name: "y-link-h"
duration: "3.5s"
line { name: "DP_A" baud: "1.5M" }
line { name: "DP_B" baud: "1.5M" }
line { name: "Y" baud: "1.5M" }
dp_master { address: 1 line: "DP_A" watchdog: "100ms" }
dp_master { address: 1 line: "DP_B" watchdog: "100ms" }
redundant_master_system { name: "S" line_a: "DP_A" master_a: 1 line_b: "DP_B" master_b: 1 }
y_link { system: "S" address: 6 lower_line: "Y" }
dp_slave { address: 3 line: "Y" gsd: "gsd/PBVB0A01.gsd" }
dp_slave { address: 4 line: "Y" gsd: "gsd/PBVB0A01.gsd" }
h_system {
  name: "H"
  dp_system { system: "S" t_pto: "1250ms" }
  cpu { cpu0 { power_on: "0s" } cpu1 { power_on: "0s" } startup_time: "1s" link_up_time: "2s" }
  program { scan_time: "10ms" counter { output: 0 width: 2 period: "100ms" step: 1 } }
}
fault { at: "2s" repair_at: "3s" power_loss { line: "Y" address: 3 } }
)";

TEST(YLinkHScenario, LowerStationFailureIsOb83OfTheLinksModule) {
  const test::ScenarioRun done = test::run_scenario(kText, kFile);
  ASSERT_TRUE(done.report) << done.error;
  ASSERT_EQ(done.report->h_systems.size(), 1u);
  const auto& io = done.report->h_systems[0].io_events;
  int removed = 0, inserted = 0;
  for (const auto& e : io) {
    EXPECT_NE(e.ob, 86) << e.text;
    if (e.ob != 83) continue;
    EXPECT_NE(e.text.find("station 6, module 0"), std::string::npos) << e.text;
    EXPECT_EQ(e.mdl_addr, std::optional<std::uint16_t>(0));
    if (e.code == 0x3961) {
      ++removed;
      // The lower master misses station 3 at its next poll (one lower cycle, ~1 ms), the link's
      // diagnosis changes, the upper master reads it after the link's DH answer: < 20 ms.
      EXPECT_GT(e.at, 2 * kS);
      EXPECT_LT(e.at, 2 * kS + 20 * kMs);
    }
    if (e.code == 0x3861) {
      ++inserted;
      EXPECT_GT(e.at, 3 * kS);  // the lower station's start-up again, then the diagnosis
      EXPECT_LT(e.at, 3 * kS + 50 * kMs);
    }
  }
  EXPECT_EQ(removed, 1);
  EXPECT_EQ(inserted, 1);
}

}  // namespace
}  // namespace pbvbus::tools
