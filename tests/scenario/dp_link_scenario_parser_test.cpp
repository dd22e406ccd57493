// y_link / dp_pa_link entries (scenario/dp_link_plan.hpp, docs/dp-link.md): planned as one
// switched station of their redundant_master_system whose modules are the lower dp_slaves, and
// the refusals (D5; 001 L8128) as FILE:LINE:COLUMN errors at the field concerned. A
// *_parser_test: the sanitizer builds run it too.
#include <gtest/gtest.h>

#include <string>

#include "pbvbus/scenario/scenario.hpp"

namespace pbvbus::tools {
namespace {

const std::string kGsdDp = PBVBUS_SOURCE_DIR "/examples/gsd/PBVB0A01.gsd";
const std::string kGsdPa = PBVBUS_SOURCE_DIR "/examples/gsd/PBVB0A5A.gsd";

/// Upper lines at `upper`, a lower line "L" at `lower`, `n` lower stations from 3 on, `link`
/// = the entry's text (line 13 of the text).
std::string text(const std::string& upper, const std::string& lower, int n, bool pa,
                 const std::string& link) {
  std::string t = "name: \"t\"\n"                                              // 1
                  "line { name: \"A\" baud: \"" + upper + "\" }\n"             // 2
                  "line { name: \"B\" baud: \"" + upper + "\" }\n"             // 3
                  "line { name: \"L\" baud: \"" + lower + "\" }\n"             // 4
                  "dp_master { address: 1 line: \"A\" }\n"                     // 5
                  "dp_master { address: 1 line: \"B\" }\n"                     // 6
                  "redundant_master_system {\n"                                // 7
                  "  name: \"S\"\n"                                            // 8
                  "  line_a: \"A\" master_a: 1\n"                              // 9
                  "  line_b: \"B\" master_b: 1\n"                              // 10
                  "}\n"                                                        // 11
                  "\n"                                                         // 12
                  + link + "\n";                                               // 13
  for (int k = 0; k < n; ++k)
    t += "dp_slave { address: " + std::to_string(3 + k) + " line: \"L\" gsd: \"" +
         (pa ? kGsdPa + "\" modules: [\"AI short\", \"AO short\"]" : kGsdDp + "\"") + " }\n";
  return t;
}

std::string errors(const LoadResult& r) {
  std::string s;
  for (const auto& d : r.errors) s += d.str() + "\n";
  return s;
}

TEST(DpLinkPlan, AYLinkIsASwitchedStationOfTheLowerStations) {
  const auto r = parse_scenario(
      text("1.5M", "1.5M", 3, false, "y_link { system: \"S\" address: 6 lower_line: \"L\" }"),
      "t.textproto");
  ASSERT_TRUE(r.ok()) << errors(r);
  const ScenarioPlan& p = *r.plan;
  ASSERT_EQ(p.dp_links.size(), 1u);
  const DpLinkPlan& l = p.dp_links[0];
  EXPECT_EQ(l.kind, devices::DpLinkKind::YLink);
  EXPECT_EQ(l.address, 6);
  EXPECT_EQ(l.master, 1);  // default
  EXPECT_EQ(l.switchover, 100 * bus::kTicksPerMs);
  ASSERT_EQ(l.lower.size(), 3u);
  ASSERT_EQ(p.switched.size(), 1u);
  EXPECT_EQ(p.switched[0].link, 0);
  EXPECT_EQ(p.switched[0].t_slave_um, 100 * bus::kTicksPerMs);
  // Both upper masters hold the link: ident 0x0A57, Chk_Cfg = the three stations' 11 21.
  const DpSlavePlan& a = p.dp_slaves.at(static_cast<std::size_t>(p.switched[0].slave[0]));
  EXPECT_EQ(a.params.ident, 0x0A57);
  EXPECT_EQ(a.params.chk_cfg_du(),
            (std::vector<std::uint8_t>{0x11, 0x21, 0x11, 0x21, 0x11, 0x21}));
  EXPECT_EQ(a.params.prm_cmd.size(), 8u);
  EXPECT_EQ(a.inputs, 6u);
  EXPECT_EQ(a.outputs, 6u);
  EXPECT_EQ(p.redundant_systems[0].switched, (std::vector<int>{0}));
  EXPECT_EQ(link_of_lower_line(p, 2), 0);
}

TEST(DpLinkPlan, UpperLinesAbove1_5MbitAreRefused) {
  // D5, 001 L8128: with a DP/PA link or Y-link the redundant system runs at 1.5 MBd at most.
  const auto r = parse_scenario(
      text("12M", "1.5M", 2, false, "y_link { system: \"S\" address: 6 lower_line: \"L\" }"),
      "t.textproto");
  ASSERT_FALSE(r.ok());
  const std::string e = errors(r);
  EXPECT_NE(e.find("t.textproto:13:10: redundant_master_system \"S\" with a Y-link runs at 1.5 "
                   "Mbit/s at most (001 L8128)"),
            std::string::npos)
      << e;
}

TEST(DpLinkPlan, LowerBaudRatesAreRefused) {
  auto r = parse_scenario(
      text("1.5M", "12M", 2, false, "y_link { system: \"S\" address: 6 lower_line: \"L\" }"),
      "t.textproto");
  ASSERT_FALSE(r.ok());
  EXPECT_NE(errors(r).find("t.textproto:13:33: a Y-link's lower DP line runs at 187.5 kbit/s to "
                           "1.5 Mbit/s"),
            std::string::npos)
      << errors(r);
  r = parse_scenario(
      text("1.5M", "45.45k", 2, true, "dp_pa_link { system: \"S\" address: 6 lower_line: \"L\" }"),
      "t.textproto");
  ASSERT_FALSE(r.ok());
  EXPECT_NE(errors(r).find("t.textproto:13:37: a DP/PA link's lower line (PROFIBUS PA, MBP) runs "
                           "at 31.25 kbit/s only"),
            std::string::npos)
      << errors(r);
}

TEST(DpLinkPlan, PaSegmentsTakeThirtyDevicesTenInEx) {
  // D5: PA <= 30 nodes, <= 10 nodes / 100 mA in an Ex area.
  const std::string pa = "dp_pa_link { system: \"S\" address: 6 lower_line: \"L\"";
  auto r = parse_scenario(text("1.5M", "31.25k", 2, true, pa + " }"), "t.textproto");
  EXPECT_TRUE(r.ok()) << errors(r);
  if (r.ok()) {
    EXPECT_EQ(r.plan->dp_links.at(0).kind, devices::DpLinkKind::DpPaLink);
  }
  r = parse_scenario(text("1.5M", "31.25k", 11, true, pa + " ex: true }"), "t.textproto");
  ASSERT_FALSE(r.ok());
  EXPECT_NE(errors(r).find("t.textproto:13:53: 11 PA devices on \"L\": a PA segment takes at "
                           "most 10 in an Ex area (100 mA) (D5)"),
            std::string::npos)
      << errors(r);
  r = parse_scenario(text("1.5M", "31.25k", 10, true, pa + " ex: true }"), "t.textproto");
  EXPECT_TRUE(r.ok()) << errors(r);
}

TEST(DpLinkPlan, LowerStationsHaveNoMasterOfTheirOwn) {
  auto r = parse_scenario(
      text("1.5M", "1.5M", 2, false, "y_link { system: \"S\" address: 6 lower_line: \"L\" master: 3 }"),
      "t.textproto");
  ASSERT_FALSE(r.ok());
  EXPECT_NE(errors(r).find("t.textproto:13:49: the coupler's master address 3 is dp_slave 3's "
                           "on \"L\""),
            std::string::npos)
      << errors(r);
  r = parse_scenario(
      text("1.5M", "1.5M", 1, false, "y_link { system: \"S\" address: 6 lower_line: \"A\" }"),
      "t.textproto");
  ASSERT_FALSE(r.ok());
  EXPECT_NE(errors(r).find("lower_line \"A\" is a line of redundant_master_system \"S\""),
            std::string::npos)
      << errors(r);
}

}  // namespace
}  // namespace pbvbus::tools
