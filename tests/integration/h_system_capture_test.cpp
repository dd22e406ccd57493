// The capture of the built-in default scenario (examples/h-system.textproto, docs/h-system.md
// deliverable 5: "... and in the capture's event interface"), read by Debian's tshark with the
// pbvbus Lua dissector: the CPU pair's state changes and OB 72s as Cpu records with their
// fields, the H faults as Note records before their reactions, the OB 85s of the program as Cpu
// records of kind OB, and the DP master system failure of the lost side as a redundancy record.
// Times are the scenario's (see tests/simulation/h_system_run_test.cpp for their derivation).
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <fstream>
#include <string>
#include <vector>
#include <unistd.h>

#include "../captures/tshark_helpers.hpp"
#include "pbvbus/captures/pcapng_writer.hpp"
#include "pbvbus/scenario/scenario.hpp"
#include "pbvbus/simulation/simulation.hpp"

namespace pbvbus::tools {
namespace {

namespace ts = pbvbus::test;

std::string g_written;  // the capture this process wrote, removed at the end if all passed

// The capture stays for a look only when a test failed (ctest leaves one per process).
class RemoveCapture : public ::testing::Environment {
 public:
  void TearDown() override {
    if (!g_written.empty() && ::testing::UnitTest::GetInstance()->Passed())
      std::remove(g_written.c_str());
  }
};
[[maybe_unused]] ::testing::Environment* const g_remove =
    ::testing::AddGlobalTestEnvironment(new RemoveCapture);

const std::string& capture_file() {
  static const std::string path = [] {
    // One file per process: ctest runs each test in its own process, in parallel.
    const std::string p = std::string(PBVBUS_BINARY_DIR) + "/h_system_default." +
                          std::to_string(::getpid()) + ".pcapng";
    std::ofstream f(p, std::ios::binary);
    g_written = p;
    const auto loaded = parse_scenario(default_scenario_text(), "<default>");
    EXPECT_TRUE(loaded.ok());
    if (!loaded.ok()) return p;
    captures::PcapngWriter w([&f](std::span<const std::uint8_t> b) {
      f.write(reinterpret_cast<const char*>(b.data()), static_cast<std::streamsize>(b.size()));
      return static_cast<bool>(f);
    });
    SimulationOptions o;
    o.capture = &w;
    Simulation sim(*loaded.plan, o);
    sim.start();
    sim.run_until(*sim.duration());
    w.flush();
    return p;
  }();
  return path;
}

using Rows = std::vector<std::vector<std::string>>;

bool has(const Rows& rows, const std::vector<std::string>& want) {
  return std::find(rows.begin(), rows.end(), want) != rows.end();
}

TEST(HSystemCapture, CpuRecordsNamedByTheDissector) {
  if (!ts::tshark_available()) GTEST_SKIP() << ts::kNoTshark;
  const Rows rows = ts::tshark_fields(
      capture_file(),
      {"frame.time_relative", "pbevent.cpu.kind", "pbevent.cpu.rack", "pbevent.cpu.ob_name", "pbevent.text"},
      "pbevent.category == 5");
  ASSERT_FALSE(rows.empty());
  for (const auto& r : rows) ASSERT_EQ(r.size(), 5u);
  auto find = [&](const std::string& text) {
    for (const auto& r : rows)
      if (r[4] == text) return r;
    return std::vector<std::string>{};
  };
  // F5 at 5 s: OB 72 on the master, CPU 1 to STOP.
  const auto ob72 = find("H-CPU: CPU 0: OB 72 (redundant link lost)");
  ASSERT_FALSE(ob72.empty());
  EXPECT_EQ(ob72[0], "5.000000000");
  EXPECT_EQ(ob72[2], "0");
  EXPECT_EQ(ob72[3], "OB 72");
  EXPECT_EQ(find("H-CPU: CPU 1: RUN -> STOP").at(0), "5.000000000");
  // F1 at 12 s: CPU 1 takes over.
  EXPECT_EQ(find("H-CPU: CPU 1: OB 72 (master CPU lost)").at(0), "12.000000000");
  EXPECT_EQ(find("H-CPU: CPU 1: role standby -> master").at(0), "12.000000000");
  // The returning CPU 0's update ends at 16.145 s.
  EXPECT_EQ(find("H-CPU: CPU 0: UPDATE -> RUN").at(0), "16.145000000");
  // OB 85 for the one-sided slave of the lost side at the first OB 1 that misses it.
  const auto ob85 = find("H-CPU: CPU 0: process-image transfer error incoming: DP master system \"H-DP 1\", station 11");
  ASSERT_FALSE(ob85.empty());
  EXPECT_EQ(ob85[0], "5.005000000");
  EXPECT_EQ(ob85[3], "OB 85");
}

TEST(HSystemCapture, FaultNoteComesBeforeItsReactions) {
  if (!ts::tshark_available()) GTEST_SKIP() << ts::kNoTshark;
  const Rows rows = ts::tshark_fields(capture_file(), {"frame.time_relative", "pbevent.text"},
                                      "pbevent && frame.time_relative >= 12 && frame.time_relative < 12.001");
  ASSERT_GE(rows.size(), 3u);
  EXPECT_EQ(rows[0], (std::vector<std::string>{"12.000000000", "H-CPU: CPU 0 (rack 0) fails"}));
  EXPECT_TRUE(has(rows, {"12.000000000",
                         "OB 86 W#16#39C3 master system failure: DP master system \"H-DP 1\", line DP_A"}))
      << rows.size();
}

}  // namespace
}  // namespace pbvbus::tools
