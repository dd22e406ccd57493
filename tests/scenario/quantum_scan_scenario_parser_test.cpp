// The scan-time fields of a quantum_hot_standby entry (scenario/proto/scenario.proto message
// QuantumHotStandby: transfer_rate_us_per_kb, iec_hsby_registers; quantum_plan.cpp plan_scan):
// what the loader hands the scan-time model (quantum/scan_time.hpp), each refusal with its
// FILE:LINE:COLUMN, and timing-only files (no line) holding only quantum pairs.
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "pbvbus/scenario/scenario.hpp"

namespace pbvbus::tools {
namespace {

constexpr bus::Ticks kMs = bus::kTicksPerMs;
const std::string kFile = std::string(PBVBUS_SOURCE_DIR) + "/examples/q.textproto";

LoadResult load(const std::string& text) { return parse_scenario(text, kFile); }

std::vector<std::string> errors(const std::string& text) {
  std::vector<std::string> out;
  for (const auto& d : load(text).errors) {
    std::string s = d.str();
    if (s.rfind(kFile, 0) == 0) s = "q.textproto" + s.substr(kFile.size());
    out.push_back(s);
  }
  return out;
}

// Line 1 the name, line 2 `quantum_hot_standby {`, the entry's fields from line 3 on; a field
// written as `  field: ...` starts at column 3.
std::string pair(const std::string& fields) {
  return "name: \"q\"\nquantum_hot_standby {\n  name: \"P\"\n" + fields + "}\n";
}

// The rate replaces the CPU type's: a 424 02 (2000 µs per 1000 B by its own rate) at 1600.
// Baseline state RAM (the defaults) with the 12K transfer: every delta 0, bytes 0, so the
// estimate is HSBY 40 ms + logic 20 ms; with 16 more 4x (1888): 16 × 18 / 8 = 36 B,
// 36 × 1600 µs / 1000 = 57.6 µs.
TEST(QuantumScanScenario, TheRateReplacesTheCpuTypes) {
  const auto r = load(pair("  cpu: CPU_424_02\n"
                           "  state_ram { holding_registers: 1888 }\n"
                           "  transfer_rate_us_per_kb: 1600\n"));
  ASSERT_TRUE(r.ok()) << r.errors.at(0).str();
  const QuantumPlan& q = r.plan->quantum.at(0);
  EXPECT_EQ(q.estimate.deltas.holding, 16);
  EXPECT_EQ(q.estimate.bytes, 36);
  EXPECT_EQ(q.estimate.transfer, 36 * 1600 * bus::kTicksPerUs / 1000);
  EXPECT_EQ(q.scan_time, 40 * kMs + 20 * kMs + 36 * 1600 * bus::kTicksPerUs / 1000);
  EXPECT_TRUE(q.scan_time_estimated);
}

// The IEC-HSBY registers count 2 B each, all of them (the seed's IEC example, p. 50): 100 → 200 B
// on a 434 12 at 1900 µs per 1000 B = 380 µs. The estimate is kept when scan_time is configured.
TEST(QuantumScanScenario, IecHsbyRegistersCountTwoBytesEach) {
  const auto r = load(pair("  iec: true\n"
                           "  iec_hsby_registers: 100\n"
                           "  scan_time: \"80ms\"\n"));
  ASSERT_TRUE(r.ok()) << r.errors.at(0).str();
  const QuantumPlan& q = r.plan->quantum.at(0);
  EXPECT_EQ(q.estimate.deltas.iec_regs, 100);
  EXPECT_EQ(q.estimate.iec_bytes, 200);
  EXPECT_EQ(q.estimate.transfer, 380 * bus::kTicksPerUs);
  EXPECT_EQ(q.estimate.total, 40 * kMs + 20 * kMs + 380 * bus::kTicksPerUs);
  EXPECT_EQ(q.scan_time, 80 * kMs);
  EXPECT_FALSE(q.scan_time_estimated);
}

TEST(QuantumScanScenario, RateOutside1To100000IsRefused) {
  EXPECT_EQ(errors(pair("  transfer_rate_us_per_kb: 0\n")),
            std::vector<std::string>{
                "q.textproto:4:3: transfer_rate_us_per_kb 0 is outside 1..100000"});
  EXPECT_EQ(errors(pair("  cpu: CPU_X13\n  transfer_rate_us_per_kb: 100001\n")),
            std::vector<std::string>{
                "q.textproto:5:3: transfer_rate_us_per_kb 100001 is outside 1..100000"});
  EXPECT_TRUE(errors(pair("  transfer_rate_us_per_kb: 100000\n")).empty());
  EXPECT_TRUE(errors(pair("  transfer_rate_us_per_kb: 1\n")).empty());
}

TEST(QuantumScanScenario, IecHsbyRegistersNeedIec) {
  EXPECT_EQ(errors(pair("  logic_time: \"30ms\"\n  iec_hsby_registers: 14000\n")),
            std::vector<std::string>{
                "q.textproto:5:3: iec_hsby_registers needs iec: true (IEC-HSBY registers exist in "
                "IEC Hot Standby only)"});
}

// A file with no line is a timing-only file when its quantum pairs have neither remote I/O (dp)
// nor Modbus ports; one pair with a Modbus port makes it a runtime file that needs a line.
TEST(QuantumScanScenario, TimingOnlyFileNeedsNoLine) {
  EXPECT_TRUE(errors(pair("  logic_time: \"36ms\"\n")).empty());
  const std::string two = "name: \"q\"\n"
                          "quantum_hot_standby { name: \"A\" }\n"
                          "quantum_hot_standby { name: \"B\" modbus_port { port: 1 address: 1 "
                          "tcp { listen: \"127.0.0.1:0\" } } }\n";
  const auto e = errors(two);
  ASSERT_FALSE(e.empty());
  EXPECT_EQ(e.at(0), "q.textproto:1:1: the scenario has no line");
  EXPECT_EQ(errors("name: \"q\"\n"), std::vector<std::string>{"q.textproto:1:1: the scenario has no line"});
}

}  // namespace
}  // namespace pbvbus::tools
