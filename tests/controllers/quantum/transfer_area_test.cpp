// The per-scan transfer allocator (transfer_area.hpp) against the seed's numbers (seed 003
// pp. 36-41, 76, 94-100; seeds-digest.md §11 Q1): the 12K register split of the seed's three
// examples, the user defined and additional rules, transfer all, IEC and the refusals.
#include "pbvbus/quantum/transfer_area.hpp"

#include <gtest/gtest.h>

namespace pbvbus::quantum {
namespace {

using Mode = TransferConfig::Mode;

StateRamSizes sizes(std::uint32_t c, std::uint32_t i, std::uint32_t r3, std::uint32_t r4) {
  StateRamSizes s;
  s.coils = c;
  s.inputs = i;
  s.input_regs = r3;
  s.holding = r4;
  return s;
}

TEST(TwelveK, SeedExample1_3200_9600) {
  // 1000 3x (the full allotment); 9000 4x + 8 to the next multiple of 16 (9008 = 563 × 16).
  EXPECT_EQ(allocate_12k_registers(3200, 9600),
            (std::pair<std::uint32_t, std::uint32_t>{1000, 9008}));
}
TEST(TwelveK, SeedExample2_3200_7000) {
  // All 7000 4x; 3x gets 1000 + the 2000 4x do not use = 3000 (not rounded).
  EXPECT_EQ(allocate_12k_registers(3200, 7000),
            (std::pair<std::uint32_t, std::uint32_t>{3000, 7000}));
}
TEST(TwelveK, SeedExample3_700_9600) {
  // All 700 3x; 9000 + 300 unused 3x = 9300, + 12 to 9312 = 582 × 16.
  EXPECT_EQ(allocate_12k_registers(700, 9600),
            (std::pair<std::uint32_t, std::uint32_t>{700, 9312}));
}
TEST(TwelveK, AtMostTenThousandAllTransferred) {
  EXPECT_EQ(allocate_12k_registers(3000, 7000),
            (std::pair<std::uint32_t, std::uint32_t>{3000, 7000}));
  EXPECT_EQ(allocate_12k_registers(512, 1872),
            (std::pair<std::uint32_t, std::uint32_t>{512, 1872}));
}
TEST(TwelveK, RoundingStopsAtTheConfigured4x) {
  // 1000 3x, 9005 4x: quota 9000 → rounded 9008 > 9005 → all 9005 (all included, no rounding).
  EXPECT_EQ(allocate_12k_registers(1000, 9005),
            (std::pair<std::uint32_t, std::uint32_t>{1000, 9005}));
}

TEST(PlanTransfer, Default12KOrderAndLimits) {
  TransferConfig c;  // 12K, command register 400001, no non-transfer area
  const auto r = plan_transfer(c, sizes(10000, 100, 3200, 9600));
  ASSERT_TRUE(r.plan) << r.error;
  const std::vector<TransferRange> want = {{RefType::Coil0x, 0, 8192},
                                           {RefType::Input1x, 0, 100},
                                           {RefType::Register3x, 0, 1000},
                                           {RefType::Register4x, 0, 9008}};
  EXPECT_EQ(r.plan->every_scan, want);
  EXPECT_TRUE(r.plan->additional_slices.empty());
}

TEST(PlanTransfer, NoZeroCountRanges) {
  TransferConfig c;
  const auto r = plan_transfer(c, sizes(0, 0, 0, 64));
  ASSERT_TRUE(r.plan) << r.error;
  ASSERT_EQ(r.plan->every_scan.size(), 1U);
  EXPECT_EQ(r.plan->every_scan[0], (TransferRange{RefType::Register4x, 0, 64}));
}

TEST(PlanTransfer, TwelveKIgnoresUserAndAdditionalEntries) {
  TransferConfig c;
  c.coils = 17;  // would be refused in user defined mode
  c.additional.enabled = true;
  const auto r = plan_transfer(c, sizes(32, 32, 32, 32));
  ASSERT_TRUE(r.plan) << r.error;
  EXPECT_TRUE(r.plan->additional_slices.empty());
}

TEST(PlanTransfer, UserDefinedCounts) {
  TransferConfig c;
  c.mode = Mode::UserDefined;
  c.coils = 96;  // the seed's example: coils 000001..000096
  c.holding = 16;
  const auto r = plan_transfer(c, sizes(1536, 512, 512, 1872));
  ASSERT_TRUE(r.plan) << r.error;
  const std::vector<TransferRange> want = {{RefType::Coil0x, 0, 96}, {RefType::Register4x, 0, 16}};
  EXPECT_EQ(r.plan->every_scan, want);
}

TEST(PlanTransfer, UserDefinedRefusals) {
  TransferConfig c;
  c.mode = Mode::UserDefined;
  c.coils = 100;
  c.holding = 16;
  auto r = plan_transfer(c, sizes(1536, 512, 512, 1872));
  EXPECT_FALSE(r.plan);
  EXPECT_EQ(r.error, "a user defined transfer of 100 coils (0x) is not 0 or a multiple of 16");

  c.coils = 0;
  c.holding = 0;
  r = plan_transfer(c, sizes(1536, 512, 512, 1872));
  EXPECT_EQ(r.error, "a user defined transfer needs at least 16 holding registers (4x), 0 given");

  c.holding = 2048;
  r = plan_transfer(c, sizes(1536, 512, 512, 1872));
  EXPECT_EQ(r.error,
            "a user defined transfer of 2048 holding registers (4x) exceeds the 1872 configured "
            "in state RAM");
}

TEST(PlanTransfer, AdditionalSeedExample2048Plus1024OverTwoScans) {
  // Seed p. 40: 2048 coils every scan (000001..002048), 1024 additional over 2 scans:
  // 002049..002560 with one scan, 002561..003072 with the next.
  TransferConfig c;
  c.mode = Mode::UserDefined;
  c.coils = 2048;
  c.holding = 16;
  c.additional.enabled = true;
  c.additional.coils = 1024;
  c.additional.scans = 2;
  const auto r = plan_transfer(c, sizes(4096, 0, 0, 1872));
  ASSERT_TRUE(r.plan) << r.error;
  ASSERT_EQ(r.plan->additional_slices.size(), 2U);
  EXPECT_EQ(r.plan->additional_slices[0],
            (std::vector<TransferRange>{{RefType::Coil0x, 2048, 512}}));
  EXPECT_EQ(r.plan->additional_slices[1],
            (std::vector<TransferRange>{{RefType::Coil0x, 2560, 512}}));
}

TEST(PlanTransfer, AdditionalUnevenGroupsOfSixteen) {
  // 48 4x (3 groups of 16) over 2 scans: 32 then 16; 16 1x over 3 scans: only the first slice.
  TransferConfig c;
  c.mode = Mode::UserDefined;
  c.holding = 32;
  c.additional.enabled = true;
  c.additional.inputs = 16;
  c.additional.holding = 48;
  c.additional.scans = 3;
  const auto r = plan_transfer(c, sizes(0, 64, 0, 128));
  ASSERT_TRUE(r.plan) << r.error;
  ASSERT_EQ(r.plan->additional_slices.size(), 3U);
  EXPECT_EQ(r.plan->additional_slices[0],
            (std::vector<TransferRange>{{RefType::Input1x, 0, 16}, {RefType::Register4x, 32, 16}}));
  EXPECT_EQ(r.plan->additional_slices[1],
            (std::vector<TransferRange>{{RefType::Register4x, 48, 16}}));
  EXPECT_EQ(r.plan->additional_slices[2],
            (std::vector<TransferRange>{{RefType::Register4x, 64, 16}}));
}

TEST(PlanTransfer, AdditionalRefusals) {
  TransferConfig c;
  c.mode = Mode::UserDefined;
  c.holding = 16;
  c.additional.enabled = true;
  auto r = plan_transfer(c, sizes(64, 64, 64, 64));
  EXPECT_EQ(r.error,
            "\"Transfer Additional State RAM\" is enabled with no additional references: the "
            "controller won't start (enter 16 or more of at least one type)");
  c.additional.coils = 16;
  c.additional.scans = 0;
  r = plan_transfer(c, sizes(64, 64, 64, 64));
  EXPECT_EQ(r.error,
            "additional state RAM is spread over 0 scans, the extra transfer time must be 1 to "
            "255 scans");
  c.additional.scans = 256;
  r = plan_transfer(c, sizes(64, 64, 64, 64));
  EXPECT_FALSE(r.plan);
  c.additional.scans = 255;
  EXPECT_TRUE(plan_transfer(c, sizes(64, 64, 64, 64)).plan);
  c.additional.coils = 8;
  r = plan_transfer(c, sizes(64, 64, 64, 64));
  EXPECT_EQ(r.error, "an additional transfer of 8 coils (0x) is not 0 or a multiple of 16");
  c.additional.coils = 0;
  c.additional.holding = 64;  // 16 every scan + 64 = 80 > 64
  r = plan_transfer(c, sizes(64, 64, 64, 64));
  EXPECT_EQ(r.error,
            "the additional holding registers (4x) after the 16 sent every scan end at 80, "
            "beyond the 64 configured in state RAM");
}

TEST(PlanTransfer, TransferAll) {
  TransferConfig c;
  c.mode = Mode::TransferAll;
  auto r = plan_transfer(c, sizes(20000, 9000, 5000, 30000));
  ASSERT_TRUE(r.plan) << r.error;
  const std::vector<TransferRange> want = {{RefType::Coil0x, 0, 20000},
                                           {RefType::Input1x, 0, 9000},
                                           {RefType::Register3x, 0, 5000},
                                           {RefType::Register4x, 0, 30000}};
  EXPECT_EQ(r.plan->every_scan, want);
  c.holding = 16;
  r = plan_transfer(c, sizes(16, 16, 16, 16));
  EXPECT_EQ(r.error,
            "\"Transfer All State RAM\" does not allow a user defined or additional state RAM "
            "range");
  c.holding = 0;
  c.additional.enabled = true;
  EXPECT_FALSE(plan_transfer(c, sizes(16, 16, 16, 16)).plan);
}

TEST(PlanTransfer, IecTransfersEverythingUpTo128KB) {
  // 10K words of state RAM = 20 KB (p. 44): the heap may take 128 − 20 = 108 KB.
  TransferConfig c;
  c.iec = true;
  const StateRamSizes s = sizes(1536, 512, 1000, 8000);  // 96 + 32 + 1000 + 8000 = 9128 words
  c.iec_heap_bytes = 131072 - 2 * 9128;                  // exactly at the limit
  auto r = plan_transfer(c, s);
  ASSERT_TRUE(r.plan) << r.error;
  EXPECT_EQ(r.plan->every_scan.back(), (TransferRange{RefType::Register4x, 0, 8000}));
  c.iec_heap_bytes += 1;
  r = plan_transfer(c, s);
  EXPECT_EQ(r.error,
            "state RAM (18256 B) plus IEC heap (112817 B) is 131073 B, more than the 131072 B "
            "(128 KB) an IEC Hot Standby transfer carries");
  c.iec_heap_bytes = 0;
  c.mode = Mode::UserDefined;
  r = plan_transfer(c, s);
  EXPECT_EQ(r.error,
            "IEC Hot Standby transfers all of state RAM; a user defined or additional transfer "
            "area is not allowed");
}

TEST(PlanTransfer, IecIsNotBoundByTheTwelveKCommandLimit) {
  TransferConfig c;
  c.iec = true;
  c.command_register = 20000;  // 420001
  EXPECT_TRUE(plan_transfer(c, sizes(0, 0, 0, 30000)).plan);
}

TEST(StateRamBytes, WordsTimesTwo) {
  // 17 coils take 2 words; 16 inputs 1 word; + 3 + 4 registers = 10 words = 20 B.
  EXPECT_EQ(state_ram_bytes(sizes(17, 16, 3, 4)), 20U);
}

}  // namespace
}  // namespace pbvbus::quantum
