// `pbvbus timing` on h_system entries (docs/h-system.md): the S7-400H manual's worked
// example (examples/h-update-example.textproto) reproduced exactly, text and JSON, with every
// figure worked out by hand here from seeds-digest.md §3.1; the configured H parameters checked;
// an h_system that takes its DP master system from a redundant_master_system; loader errors.
#include <gtest/gtest.h>

#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "pbvbus/tools/commands.hpp"

namespace pbvbus::tools {
namespace {

struct Result {
  int rc = -1;
  std::string out, err;
};

Result timing(const Args& args) {
  std::ostringstream out, err;
  Result r;
  r.rc = cmd_timing(args, out, err);
  r.out = out.str();
  r.err = err.str();
  return r;
}

const std::string kExample = PBVBUS_SOURCE_DIR "/examples/h-update-example.textproto";

/// Into the build tree (never the sources); relative GSD paths made absolute.
std::string write_scenario(const std::string& name, std::string text) {
  const std::string gsd = "gsd: \"gsd/";
  const std::string abs = "gsd: \"" PBVBUS_SOURCE_DIR "/examples/gsd/";
  for (auto at = text.find(gsd); at != std::string::npos; at = text.find(gsd, at + abs.size()))
    text.replace(at, gsd.size(), abs);
  const std::string path = std::string(PBVBUS_BINARY_DIR) + "/" + name;
  std::ofstream(path) << text;
  return path;
}

bool has(const std::string& hay, const std::string& needle) {
  return hay.find(needle) != std::string::npos;
}

// [1] system 1: 1250 − (2·25 + 300 + 50 + 100 + 30) = 1250 − 530 = 720 ms
//     system 2: 1200 − (2·30 + 300 + 50 + 80 + 50) = 1200 − 540 = 660 ms → T_P15_HW = 660 ms
// T_PH = MAX(30, 3·T_TRmax = 3·30) = 90 ms; T_P15_OD = 50 + 90 = 140 ms
// T_P15_AWP = 75 + 0.7·170 = 75 + 119 = 194 ms; [3] T_P15 = MAX(194, 140) = 194 ms
// recommended: 4·194 = 776 ms, 10·194 = 1940 ms
TEST(HTimingCmd, ReproducesTheManualsWorkedExample) {
  const Result r = timing({kExample});
  ASSERT_EQ(r.rc, 0) << r.err;
  for (const char* line :
       {"= 530 ms) = 720 ms", "= 540 ms) = 660 ms", "T_P15_HW = 660 ms (system 2)",
        "T_PH = MAX(30 ms, 3 x T_TRmax 30 ms) = 90 ms", "T_P15_OD = 50 ms + T_PH = 140 ms",
        "T_P15_AWP = 75 ms + 0.7 ms x 170 KB = 194 ms", "[3] T_P15 = MAX(T_P15_AWP, T_P15_OD) = 194 ms",
        "max communication delay 4 x T_P15 = 776 ms", "max cycle extension 10 x T_P15 = 1940 ms",
        "configured H parameters: ok"})
    EXPECT_TRUE(has(r.out, line)) << line << "\n" << r.out;

  const Result j = timing({kExample, "--json"});
  ASSERT_EQ(j.rc, 0) << j.err;
  for (const char* field :
       {"\"subtracted_us\": 530000, \"t_p15_us\": 720000", "\"subtracted_us\": 540000, \"t_p15_us\": 660000",
        "\"t_p15_hw_us\": 660000", "\"t_ph_us\": 90000", "\"t_p15_od_us\": 140000",
        "\"t_p15_awp_us\": 194000", "\"t_p15_us\": 194000", "\"recommended_comm_delay_us\": 776000",
        "\"recommended_cycle_extension_us\": 1940000", "\"checks_ok\": true", "\"abort\": \"none\""})
    EXPECT_TRUE(has(j.out, field)) << field << "\n" << j.out;
}

// A configured T_P15 of 150 ms is below the planned 194 ms (the update would not fit), and
// 50 ms + T_PH (90) = 140 ≤ 150 still holds: exactly the one check fails.
TEST(HTimingCmd, ChecksTheConfiguredHParametersAgainstThePlan) {
  std::ifstream in(kExample);
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const auto at = text.find("max_blocking_time: \"194ms\"");
  ASSERT_NE(at, std::string::npos);
  text.replace(at, std::string("max_blocking_time: \"194ms\"").size(), "max_blocking_time: \"150ms\"");
  const std::string path = write_scenario("h_timing_cmd_test_150.textproto", text);
  const Result r = timing({path});
  std::remove(path.c_str());
  ASSERT_EQ(r.rc, 0) << r.err;
  EXPECT_TRUE(has(r.out, "configured H parameters: NOT OK")) << r.out;
  EXPECT_TRUE(has(r.out, "error: ")) << r.out;
  EXPECT_TRUE(has(r.out, "194")) << r.out;
}

// Figures from a redundant_master_system: examples/switched-io.textproto's system. Its planner
// (tests/simulation/switched_io_scenario_test.cpp) gives T_TR = 4996 bits at 1.5 Mbit/s =
// 3330.666 µs, rounded up to 3331 µs; the slowest T_SLAVE_UM is 820 ms (PBVB0A11).
TEST(HTimingCmd, TakesTheDpFiguresFromARedundantSystem) {
  std::ifstream in(PBVBUS_SOURCE_DIR "/examples/switched-io.textproto");
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  text += "h_system { name: \"H\" dp_system { system: \"H-DP 1\" t_pto: \"2s\" } t_wa: \"100ms\" "
          "t_prog: \"10ms\" work_memory_db_kb: 100 }\n";
  const std::string path = write_scenario("h_timing_cmd_test_sys.textproto", text);
  const Result j = timing({path, "--json"});
  std::remove(path.c_str());
  ASSERT_EQ(j.rc, 0) << j.err;
  EXPECT_TRUE(has(j.out, "{\"name\": \"H-DP 1\", \"t_tr_us\": 3331,")) << j.out;
  EXPECT_TRUE(has(j.out, "\"t_slave_um_us\": 820000")) << j.out;
  // T_PH = MAX(30 ms, 3·3331 µs = 9993 µs) = 30 ms; T_P15_AWP = 75 + 70 = 145 ms.
  EXPECT_TRUE(has(j.out, "\"t_ph_us\": 30000")) << j.out;
  EXPECT_TRUE(has(j.out, "\"t_p15_awp_us\": 145000")) << j.out;
}

TEST(HTimingCmd, BrokenEntriesAreLoaderErrorsWithPositions) {
  const std::string path = write_scenario(
      "h_timing_cmd_test_bad.textproto",
      "name: \"bad\"\n"
      "h_system {\n"
      "  dp_system { name: \"x\" t_tr: \"25ms\" }\n"
      "  dp_system { system: \"nope\" t_pto: \"1s\" }\n"
      "  t_wa: \"three\"\n"
      "}\n");
  const Result r = timing({path});
  std::remove(path.c_str());
  EXPECT_EQ(r.rc, 2);
  EXPECT_TRUE(has(r.err, "h_timing_cmd_test_bad.textproto:3:")) << r.err;
  EXPECT_TRUE(has(r.err, "needs t_tr, t_dp_um and t_slave_um")) << r.err;
  EXPECT_TRUE(has(r.err, "needs t_pto")) << r.err;
  EXPECT_TRUE(has(r.err, "no redundant_master_system \"nope\"")) << r.err;
  EXPECT_TRUE(has(r.err, "h_timing_cmd_test_bad.textproto:5:")) << r.err;
  EXPECT_TRUE(has(r.err, "bad duration \"three\"")) << r.err;
}

// Reliability (docs/h-timing.md "Reliability"; 000 L3979, L3991): the manual's defaults CPU
// MTBF 15 y = 131 400 h, dc 0.95, MDT 4 h → 131 400² / (8 + 13 140) = 1 313 200.487 h = 149.91 y,
// 9.994 × 1oo1; V_1oo2 = 1 − 4 / 1 313 204.487 = 99.999695 %, (1 − V)·8 760 h = 1.60 min a year;
// V_1oo1 = 131 400 / 131 404 = 99.996956 %, 16.00 min.
TEST(HTimingCmd, ReliabilityWithTheManualsDefaults) {
  const Result r = timing({kExample});
  ASSERT_EQ(r.rc, 0) << r.err;
  for (const char* line :
       {"MTBF_1oo1 15.00 y (131400 h), dc 0.950, MDT 4.00 h", "= 149.91 y (1313200 h), 9.994 x",
        "1oo2 99.999695 % (1.60 min down a year), 1oo1 99.996956 % (16.00 min)"})
    EXPECT_TRUE(has(r.out, line)) << line << "\n" << r.out;
  const Result j = timing({kExample, "--json"});
  ASSERT_EQ(j.rc, 0) << j.err;
  EXPECT_TRUE(has(j.out, "\"mtbf_1oo2_h\": 1313200.487")) << j.out;
}

// --mtbf-years 50 (an I/O module) --dc 1 --mdt-hours 4.75: 438 000² / 9.5 =
// 20 194 105 263.158 h = 2 305 263.16 y; --dc 0.9 --mtbf-years 15: 131 400² / (8 + 26 280) =
// 656 800.061 h = 74.98 y.
TEST(HTimingCmd, ReliabilityOptionsAndBadValues) {
  Result r = timing({kExample, "--mtbf-years", "50", "--dc", "1", "--mdt-hours", "4.75"});
  ASSERT_EQ(r.rc, 0) << r.err;
  EXPECT_TRUE(has(r.out, "= 2305263.16 y (20194105263 h)")) << r.out;
  r = timing({kExample, "--dc", "0.9"});
  ASSERT_EQ(r.rc, 0) << r.err;
  EXPECT_TRUE(has(r.out, "= 74.98 y (656800 h)")) << r.out;
  EXPECT_EQ(timing({kExample, "--dc", "1.5"}).rc, 2);
  EXPECT_EQ(timing({kExample, "--dc"}).rc, 2);
  EXPECT_EQ(timing({kExample, "--mtbf-years", "x"}).rc, 2);
  EXPECT_EQ(timing({kExample, "--mdt-hours", "-1"}).rc, 2);
}

}  // namespace
}  // namespace pbvbus::tools
