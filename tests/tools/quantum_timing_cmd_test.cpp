// `pbvbus timing` on quantum_hot_standby entries (docs/quantum-hsby.md "Scan time in `pbvbus
// timing`"): the Quantum Hot Standby manual's two scan-time examples (seed 003 pp. 33-35 and
// 49-50; seeds-digest.md §8, §10 item 7, §11 Q2) as examples/quantum-scan-984.textproto and
// examples/quantum-scan-iec.textproto, text and JSON, every figure worked out by hand here; the
// transfer area's lines; the seed's literal 0x/1x counts refused by the loader (why the examples
// hold the next multiples of 16).
//
// The model (quantum/scan_time.hpp): delta = sent every scan − the CPU type's baseline; bytes
// 0x/1x 3 bits, 3x 2 B, 4x 2 B + 2 bits, IEC-HSBY 3x 2 B (all of them), each type rounded to the
// nearest byte; transfer = bytes × rate µs per 1000 B; total = HSBY cost + standalone + transfer.
// One tick is 1/3636 µs: ns = ticks / 3636 × 1000 + (ticks mod 3636) × 1000 / 3636, rounded down.
//
// 984 (CPU 424 02, baseline 1536/512/1212/1872, HSBY 40 ms; transfer all; 36 ms logic; rate
// 1600 as the seed multiplies, the x13's), state RAM 3008 0x, 2512 1x, 2500 3x, 8000 4x:
//   deltas 1472, 2000, 1288, 6128   bytes 1472·3/8 = 552, 2000·3/8 = 750, 2576, 6128·18/8 = 13788
//   17666 B; × 1600 µs / 1000 B = 28 265.6 µs ≈ 28 ms; 40 + 36 + 28 = 104 ms
//   ticks 28 265 600 × 3636 / 1000 = 102 773 721 (.6 dropped) → 28 265 ns·1000 + 2181·1000/3636
//   = 28 265 599 ns; total 76 ms (276 336 000 ticks, exact) + that = 104 265 599 ns.
//   With the 424 02's own 2000: 17666 × 2000 = 35.332 ms ≈ 35 ms → 40 + 36 + 35 = 111 ms.
// The seed's literal 3000 0x / 2500 1x (deltas 1464/1988 → 549 + 746 → 17659 B) are tested on the
// model itself in tests/controllers/quantum/scan_time_test.cpp; the loader refuses them here.
//
// IEC (CPU 434 12, baseline 1536/512/512/1872, HSBY 40 ms; 25 ms logic; rate 1900), state RAM
// 208 0x, 304 1x, 150 3x, 400 4x, 14000 IEC-HSBY registers:
//   deltas −1328, −208, −362, −1472, 14000   bytes −498, −78, −724, −3312, +28000
//   23388 B; × 1900 µs / 1000 B = 44 437.2 µs ≈ 44 ms; 40 + 25 + 44 = 109 ms
//   ticks 44 437 200 × 3636 / 1000 = 161 573 659 (.2 dropped) → 44 437 000 + 727·1000/3636
//   = 44 437 199 ns; total 65 ms + that = 109 437 199 ns.
// (The seed's literal 200 0x / 300 1x give −501 − 80 → 23383 B, also 44 ms, 109 ms.)
#include <gtest/gtest.h>

#include <cstdio>
#include <fstream>
#include <sstream>
#include <string>

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

const std::string k984 = PBVBUS_SOURCE_DIR "/examples/quantum-scan-984.textproto";
const std::string kIec = PBVBUS_SOURCE_DIR "/examples/quantum-scan-iec.textproto";

std::string read(const std::string& path) {
  std::ifstream in(path);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

/// Into the build tree (never the sources).
std::string write_scenario(const std::string& name, const std::string& text) {
  const std::string path = std::string(PBVBUS_BINARY_DIR) + "/" + name;
  std::ofstream(path) << text;
  return path;
}

std::string replaced(std::string text, const std::string& from, const std::string& to) {
  const auto at = text.find(from);
  EXPECT_NE(at, std::string::npos) << from;
  if (at != std::string::npos) text.replace(at, from.size(), to);
  return text;
}

bool has(const std::string& hay, const std::string& needle) {
  return hay.find(needle) != std::string::npos;
}

/// The text with every run of spaces made one (the table's padding left out).
std::string squeezed(const std::string& text) {
  std::string s;
  for (char c : text)
    if (c != ' ' || s.empty() || s.back() != ' ') s += c;
  return s;
}

TEST(QuantumTimingCmd, Seed984Example104ms) {
  const Result r = timing({k984});
  ASSERT_EQ(r.rc, 0) << r.err;
  for (const char* line :
       {"Quantum Hot Standby \"984 example\": scan time",
        "CPU 424 02, 984 Hot Standby; logic (standalone scan) 36.000 ms", "transfer area: transfer all",
        "every scan: 0x 3008, 1x 2512, 3x 2500, 4x 8000", "additional: none",
        "non-transfer area: none", "command register: 400001",
        "rate 1600 us per 1000 B (transfer_rate_us_per_kb; the CPU's is 2000;",
        "transfer 17666 B x 1600 us / 1000 B = 28.265 ms ~ 28 ms",
        "HSBY cost 40.000 ms, standalone 36.000 ms", "total 40 + 36 + 28 = 104 ms (exact 104.265 ms)",
        "scan time 104.265 ms (estimated: the model's total)",
        "adds scan time only when the logic is shorter than the transfer"})
    EXPECT_TRUE(has(r.out, line)) << line << "\n" << r.out;
  // The table's rows: type, every scan, baseline, delta, bytes.
  for (const char* row : {"\n 0x 3008 1536 1472 552\n", "\n 1x 2512 512 2000 750\n",
                          "\n 3x 2500 1212 1288 2576\n", "\n 4x 8000 1872 6128 13788\n",
                          "\n total 17666 B\n"})
    EXPECT_TRUE(has(squeezed(r.out), row)) << row << "\n" << r.out;

  const Result j = timing({k984, "--json"});
  ASSERT_EQ(j.rc, 0) << j.err;
  for (const char* field :
       {"\"name\": \"984 example\", \"cpu\": \"424 02\", \"iec\": false, \"logic_time_ns\": 36000000",
        "\"mode\": \"transfer_all\", \"every_scan\": {\"coils\": 3008, \"inputs\": 2512, "
        "\"input_registers\": 2500, \"holding_registers\": 8000}",
        "\"additional\": [], \"non_transfer\": null, \"command_register\": \"400001\"",
        "\"baseline\": {\"coils\": 1536, \"inputs\": 512, \"input_registers\": 1212, "
        "\"holding_registers\": 1872}",
        "\"deltas\": {\"coils\": 1472, \"inputs\": 2000, \"input_registers\": 1288, "
        "\"holding_registers\": 6128}",
        "\"bytes\": {\"coils\": 552, \"inputs\": 750, \"input_registers\": 2576, "
        "\"holding_registers\": 13788}",
        "\"total_bytes\": 17666, \"rate_us_per_kb\": 1600, \"rate_source\": \"scenario\", "
        "\"transfer_ns\": 28265599, \"transfer_ms\": 28",
        "\"hsby_ns\": 40000000, \"standalone_ns\": 36000000, \"total_ns\": 104265599, "
        "\"total_ms\": 104}",
        "\"scan_time_ns\": 104265599, \"scan_time_source\": \"estimated\""})
    EXPECT_TRUE(has(j.out, field)) << field << "\n" << j.out;
}

// The 424 02's own rate (2.0): 35 ms instead of 28, 111 ms (seeds-digest.md §10 item 7).
TEST(QuantumTimingCmd, The42402sOwnRateGives111ms) {
  const std::string path = write_scenario(
      "quantum_timing_cmd_test_2000.textproto",
      replaced(read(k984), "  transfer_rate_us_per_kb: 1600\n", ""));
  const Result r = timing({path});
  const Result j = timing({path, "--json"});
  std::remove(path.c_str());
  ASSERT_EQ(r.rc, 0) << r.err;
  EXPECT_TRUE(has(r.out, "rate 2000 us per 1000 B (the CPU's;")) << r.out;
  EXPECT_TRUE(has(r.out, "total 40 + 36 + 35 = 111 ms")) << r.out;
  EXPECT_TRUE(has(j.out, "\"rate_us_per_kb\": 2000, \"rate_source\": \"cpu\"")) << j.out;
}

TEST(QuantumTimingCmd, SeedIecExample109ms) {
  const Result r = timing({kIec});
  ASSERT_EQ(r.rc, 0) << r.err;
  for (const char* line :
       {"CPU 434 12, IEC Hot Standby; logic (standalone scan) 25.000 ms",
        "transfer area: IEC: all state RAM", "every scan: 0x 208, 1x 304, 3x 150, 4x 400",
        "rate 1900 us per 1000 B (the CPU's;", "transfer 23388 B x 1900 us / 1000 B = 44.437 ms ~ 44 ms",
        "total 40 + 25 + 44 = 109 ms (exact 109.437 ms)", "scan time 109.437 ms (estimated"})
    EXPECT_TRUE(has(r.out, line)) << line << "\n" << r.out;
  for (const char* row : {"\n 0x 208 1536 -1328 -498\n", "\n 1x 304 512 -208 -78\n",
                          "\n 3x 150 512 -362 -724\n", "\n 4x 400 1872 -1472 -3312\n",
                          "\n IEC-HSBY 3x 14000 - 14000 28000\n", "\n total 23388 B\n"})
    EXPECT_TRUE(has(squeezed(r.out), row)) << row << "\n" << r.out;

  const Result j = timing({kIec, "--json"});
  ASSERT_EQ(j.rc, 0) << j.err;
  for (const char* field :
       {"\"cpu\": \"434 12\", \"iec\": true", "\"mode\": \"iec\"",
        "\"deltas\": {\"coils\": -1328, \"inputs\": -208, \"input_registers\": -362, "
        "\"holding_registers\": -1472, \"iec_hsby_registers\": 14000}",
        "\"bytes\": {\"coils\": -498, \"inputs\": -78, \"input_registers\": -724, "
        "\"holding_registers\": -3312, \"iec_hsby_registers\": 28000}",
        "\"total_bytes\": 23388, \"rate_us_per_kb\": 1900, \"rate_source\": \"cpu\", "
        "\"transfer_ns\": 44437199, \"transfer_ms\": 44",
        "\"total_ns\": 109437199, \"total_ms\": 109}"})
    EXPECT_TRUE(has(j.out, field)) << field << "\n" << j.out;
}

// The seed's literal 3000 0x and 2500 1x: the loader takes 0x and 1x in multiples of 16 only,
// which is why the example holds 3008 and 2512 (its comment).
TEST(QuantumTimingCmd, TheSeedsLiteralCountsAreNotMultiplesOf16) {
  const std::string text = replaced(read(k984), "coils: 3008 inputs: 2512", "coils: 3000 inputs: 2500");
  const std::string path = write_scenario("quantum_timing_cmd_test_3000.textproto", text);
  const Result r = timing({path});
  std::remove(path.c_str());
  EXPECT_EQ(r.rc, 2);
  EXPECT_TRUE(has(r.err, "coils 3000 is not a multiple of 16")) << r.err;
  EXPECT_TRUE(has(r.err, "inputs 2500 is not a multiple of 16")) << r.err;
}

// The transfer area's lines with the seed's "additional" example (p. 39): 2048 coils every scan
// and 1024 more over 2 scans: 002049..002560, then 002561..003072; a non-transfer area of 4
// registers from 400010 (400010..400013); the command register at 400005. Configured scan time.
TEST(QuantumTimingCmd, TransferAreaAndConfiguredScanTime) {
  const std::string path = write_scenario("quantum_timing_cmd_test_area.textproto", R"(name: "area"
quantum_hot_standby {
  name: "P"
  cpu: CPU_X13
  state_ram { coils: 3072 }
  transfer { mode: USER_DEFINED coils: 2048 holding_registers: 1872
             additional { coils: 1024 scans: 2 } }
  command_register: "400005"
  non_transfer { start: "400010" length: 4 }
  scan_time: "90ms"
}
)");
  const Result r = timing({path});
  const Result j = timing({path, "--json"});
  std::remove(path.c_str());
  ASSERT_EQ(r.rc, 0) << r.err;
  for (const char* line :
       {"transfer area: user defined", "every scan: 0x 2048, 1x 0, 3x 0, 4x 1872",
        "additional: 2 slices, one a scan", "slice 0: 002049..002560", "slice 1: 002561..003072",
        "non-transfer area: 400010..400013 (4 registers)", "command register: 400005",
        "scan time 90.000 ms (configured)"})
    EXPECT_TRUE(has(r.out, line)) << line << "\n" << r.out;
  ASSERT_EQ(j.rc, 0) << j.err;
  for (const char* field :
       {"\"mode\": \"user_defined\"",
        "\"additional\": [[{\"first\": \"002049\", \"count\": 512}], [{\"first\": \"002561\", "
        "\"count\": 512}]], \"non_transfer\": {\"first\": \"400010\", \"count\": 4}, "
        "\"command_register\": \"400005\"",
        "\"scan_time_ns\": 90000000, \"scan_time_source\": \"configured\""})
    EXPECT_TRUE(has(j.out, field)) << field << "\n" << j.out;
}

// A timing-only file with quantum pairs only (no line): planned, nothing else printed.
TEST(QuantumTimingCmd, TimingOnlyFileWithoutLine) {
  const Result r = timing({kIec});
  ASSERT_EQ(r.rc, 0) << r.err;
  EXPECT_FALSE(has(r.out, "nothing to plan")) << r.out;
  EXPECT_FALSE(has(r.out, "DP master")) << r.out;
  const Result j = timing({k984, "--json"});
  EXPECT_TRUE(has(j.out, "\"redundant_systems\": [],")) << j.out;
  EXPECT_TRUE(has(j.out, "\"dp_masters\": []")) << j.out;
  EXPECT_TRUE(has(j.out, "\"h_systems\": []")) << j.out;
}

}  // namespace
}  // namespace pbvbus::tools
