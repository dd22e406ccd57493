// The seed's scan-time model (scan_time.hpp; seed 003 pp. 33-35, 49-50; seeds-digest.md §8,
// §10 item 7, §11 Q2). Expected numbers worked out here by hand from the seed's tables:
//
// 984 example, CPU 424 02 (baseline 1536/512/1212/1872), 36 ms standalone, transferring
// 3000 0x, 2500 1x, 2500 3x, 8000 4x:
//   deltas 3000−1536 = 1464, 2500−512 = 1988, 2500−1212 = 1288, 8000−1872 = 6128
//   bytes  1464×3/8 = 549, 1988×3/8 = 745.5 → 746, 1288×2 = 2576, 6128×2 + 6128×2/8 = 13788
//   sum 17659 B; × 1.6 ms per 1000 B (the seed uses the x13 rate) = 28.25 ms ≈ 28 ms
//   total 40 (HSBY, 424 02) + 36 + 28 = 104 ms.
// IEC example, CPU 434 12 (baseline 1536/512/512/1872), 25 ms, transferring 200 0x, 300 1x,
// 150 3x, 400 4x and 14000 IEC-HSBY 3x:
//   deltas −1336, −212, −362, −1472; bytes −501, −79.5 → −80, −724, −3312, +28000
//   sum 23383 B; × 1.9 = 44.43 ms ≈ 44 ms; total 40 + 25 + 44 = 109 ms.
#include "pbvbus/quantum/scan_time.hpp"

#include <gtest/gtest.h>

namespace pbvbus::quantum {
namespace {

constexpr bus::Ticks kMs = bus::kTicksPerMs;

ScanInputs example_984() {
  ScanInputs in;
  in.transferred = {3000, 2500, 2500, 8000, 0};
  in.standalone = 36 * kMs;
  return in;
}

TEST(ScanTime, Seed984Example104ms) {
  ScanInputs in = example_984();
  in.rate_override = rate_us_per_1000_bytes(CpuType::X13);  // as the seed's example does
  const ScanEstimate e = estimate_scan(CpuType::Cpu42402, in);
  EXPECT_EQ(e.deltas.coils, 1464);
  EXPECT_EQ(e.deltas.inputs, 1988);
  EXPECT_EQ(e.deltas.input_regs, 1288);
  EXPECT_EQ(e.deltas.holding, 6128);
  EXPECT_EQ(e.coil_bytes, 549);
  EXPECT_EQ(e.input_bytes, 746);
  EXPECT_EQ(e.input_reg_bytes, 2576);
  EXPECT_EQ(e.holding_bytes, 13788);
  EXPECT_EQ(e.bytes, 17659);
  EXPECT_EQ(e.transfer_ms, 28);
  EXPECT_EQ(e.hsby, 40 * kMs);
  EXPECT_EQ(e.total_ms, 104);
  // Exact: 17659 B × 1.6 µs = 28 254.4 µs = 102 732 998.4 ticks (3636 per µs), truncated.
  EXPECT_EQ(e.transfer, 102'732'998);
  EXPECT_EQ(e.total, 76 * kMs + 102'732'998);
}

TEST(ScanTime, Seed984ExampleWithThe42402sOwnRate) {
  // 17659 B × 2.0 ms per 1000 B = 35.3 ms ≈ 35 → 40 + 36 + 35 = 111 ms.
  const ScanEstimate e = estimate_scan(CpuType::Cpu42402, example_984());
  EXPECT_EQ(e.transfer_ms, 35);
  EXPECT_EQ(e.total_ms, 111);
}

TEST(ScanTime, SeedIecExample109ms) {
  ScanInputs in;
  in.transferred = {200, 300, 150, 400, 14000};
  in.standalone = 25 * kMs;
  const ScanEstimate e = estimate_scan(CpuType::Cpu43412, in);
  EXPECT_EQ(e.deltas.coils, -1336);
  EXPECT_EQ(e.deltas.inputs, -212);
  EXPECT_EQ(e.deltas.input_regs, -362);
  EXPECT_EQ(e.deltas.holding, -1472);
  EXPECT_EQ(e.coil_bytes, -501);
  EXPECT_EQ(e.input_bytes, -80);
  EXPECT_EQ(e.input_reg_bytes, -724);
  EXPECT_EQ(e.holding_bytes, -3312);
  EXPECT_EQ(e.iec_bytes, 28000);
  EXPECT_EQ(e.bytes, 23383);
  EXPECT_EQ(e.transfer_ms, 44);
  EXPECT_EQ(e.total_ms, 109);
}

TEST(ScanTime, TablesOfTheSeed) {
  EXPECT_EQ(baseline(CpuType::X13).input_regs, 3000);
  EXPECT_EQ(baseline(CpuType::Cpu42402).input_regs, 1212);
  EXPECT_EQ(baseline(CpuType::Cpu43412).input_regs, 512);
  EXPECT_EQ(baseline(CpuType::Cpu43412).iec_regs, 700);
  EXPECT_EQ(hsby_cost(CpuType::X13), 25 * kMs);
  EXPECT_EQ(hsby_cost(CpuType::Cpu43412), 40 * kMs);
  EXPECT_EQ(rate_us_per_1000_bytes(CpuType::X13), 1600);
  EXPECT_EQ(rate_us_per_1000_bytes(CpuType::Cpu42402), 2000);
  EXPECT_EQ(rate_us_per_1000_bytes(CpuType::Cpu43412), 1900);
}

TEST(ScanTime, BaselineCostsOnlyTheHsbyTime) {
  ScanInputs in;
  in.transferred = baseline(CpuType::X13);
  in.standalone = 10 * kMs;
  const ScanEstimate e = estimate_scan(CpuType::X13, in);
  EXPECT_EQ(e.bytes, 0);
  EXPECT_EQ(e.total, 35 * kMs);
  EXPECT_EQ(e.total_ms, 35);
}

TEST(ScanTime, HsbyPartNeverBelowZero) {
  // Nothing transferred on an x13: 1536×3/8 = 576, 512×3/8 = 192, 3000×2 = 6000,
  // 1872×2.25 = 4212 → −10980 B × 1.6 = −17.6 ms; 25 − 17.6 > 0 so no clamp here ...
  ScanInputs in;
  in.standalone = 10 * kMs;
  ScanEstimate e = estimate_scan(CpuType::X13, in);
  EXPECT_EQ(e.bytes, -10980);
  EXPECT_EQ(e.transfer_ms, -18);
  EXPECT_EQ(e.total_ms, 10 + 25 - 18);
  // ... but with a rate of 3 ms per 1000 B, 25 − 32.9 < 0: the HSBY part counts 0.
  in.rate_override = 3000;
  e = estimate_scan(CpuType::X13, in);
  EXPECT_EQ(e.total, 10 * kMs);
  EXPECT_EQ(e.total_ms, 10);
}

TEST(SimulatedScan, TransferAddsTimeOnlyWhenLongerThanTheLogic) {
  const bus::Ticks copy = 3 * kMs;
  EXPECT_EQ(simulated_scan_time(36 * kMs, copy, 14 * kMs), 39 * kMs);  // long logic
  EXPECT_EQ(simulated_scan_time(5 * kMs, copy, 14 * kMs), 17 * kMs);   // short logic
}

TEST(SimulatedScan, FibreAtTenMegabit) {
  // 1250 B × 8 = 10 000 bits at 10 Mbit/s = 1 ms.
  EXPECT_EQ(fibre_transfer_time(1250), kMs);
  EXPECT_EQ(fibre_transfer_time(0), 0);
}

}  // namespace
}  // namespace pbvbus::quantum
