// The per-scan state RAM transfer of the Hot Standby pair (seed 003 "per-scan transfer",
// pp. 82, 94-100; seeds-digest.md §8): the snapshot taken at the primary's scan start reaches
// the standby when the fibre transfer completes (transfer_time later), the non-transfer area is
// skipped, its registers 1-2 flow standby -> primary, register 3 is each unit's own status
// register, the "additional" slices ride along one per scan. Times in ticks.
#include <gtest/gtest.h>

#include "hsby_test_support.hpp"

namespace pbvbus::quantum {
namespace {

using namespace hsby_test;

Rig& running_pair(Rig& g) {
  g.pair.power_on(0);
  g.pair.power_on(1);
  return g;
}

TEST(HsbyTransfer, StandbyHoldsTheLastCompletedTransfersScanStartValues) {
  Rig g;
  running_pair(g);
  // The primary's logic writes 4x 1 = k + 1 in the scan started at 10 k ms. The snapshot of the
  // scan started at 10 k ms (value k) lands at 10 k + 2 ms.
  for (int k = 0; k < 6; ++k) {
    g.at(10 * k * kMs + kXfer - 1);
    EXPECT_EQ(g.pair.ram(1).holding(1), k == 0 ? 0 : k - 1) << "k=" << k;
    g.at(10 * k * kMs + kXfer);
    EXPECT_EQ(g.pair.ram(1).holding(1), k) << "k=" << k;
    EXPECT_EQ(g.pair.last_transfer_scan_start(), 10 * k * kMs);
    EXPECT_EQ(g.pair.ram(0).holding(1), k + 1);
  }
  EXPECT_EQ(g.pair.transfers_completed(), 6u);
  EXPECT_EQ(g.pair.transfers_lost(), 0u);
}

TEST(HsbyTransfer, AValueWrittenInScanNAppearsAfterScanNPlusOnesTransfer) {
  Rig g;
  running_pair(g);
  // The logic of the scan started at 20 ms (scan n) writes 4x 7 = 1234.
  g.pair.set_logic(0, [](StateRam& ram, bus::Ticks now) {
    count_scans(ram, now);
    if (now == 20 * kMs) ram.set_holding(7, 1234);
  });
  g.at(20 * kMs + kXfer);  // scan n's own transfer carried the value from before its logic
  EXPECT_EQ(g.pair.ram(0).holding(7), 1234);
  EXPECT_EQ(g.pair.ram(1).holding(7), 0);
  g.at(30 * kMs + kXfer - 1);
  EXPECT_EQ(g.pair.ram(1).holding(7), 0);
  g.at(30 * kMs + kXfer);  // scan n+1's transfer
  EXPECT_EQ(g.pair.ram(1).holding(7), 1234);
}

TEST(HsbyTransfer, AllFourTablesCarriedOutsideWritesAtTheNextScanStart) {
  Rig g;
  running_pair(g);
  g.at(13 * kMs);
  // A Modbus-like write into the primary between scans: taken at the 20 ms scan start.
  StateRam& p = g.pair.ram(0);
  p.set_coil(31, true);
  p.set_input(5, true);
  p.set_input_reg(15, 0xBEEF);
  p.set_holding(39, 0x1111);
  p.set_holding(44, 0x2222);  // 4x 44-47: transferred every scan (the plan's 0-47)
  g.h0.input = 77;            // the head's input into 3x 0 at each scan start
  g.at(20 * kMs + kXfer - 1);
  EXPECT_FALSE(g.pair.ram(1).coil(31));
  g.at(20 * kMs + kXfer);
  EXPECT_TRUE(g.pair.ram(1).coil(31));
  EXPECT_TRUE(g.pair.ram(1).input(5));
  EXPECT_EQ(g.pair.ram(1).input_reg(15), 0xBEEF);
  EXPECT_EQ(g.pair.ram(1).holding(39), 0x1111);
  EXPECT_EQ(g.pair.ram(1).holding(44), 0x2222);
  // read_inputs comes after the snapshot: 3x 0 = 77 reaches the standby one scan later.
  EXPECT_EQ(g.pair.ram(0).input_reg(0), 77);
  EXPECT_EQ(g.pair.ram(1).input_reg(0), 0);
  g.at(30 * kMs + kXfer);
  EXPECT_EQ(g.pair.ram(1).input_reg(0), 77);
}

TEST(HsbyTransfer, OutsideThePlanNothingMoves) {
  Rig g;
  running_pair(g);
  g.pair.ram(0).set_holding(48, 5);  // 4x 48-63 are not in the plan
  g.at(50 * kMs);
  EXPECT_EQ(g.pair.ram(1).holding(48), 0);
}

TEST(HsbyTransfer, NonTransferAreaSkippedReverseTransferStandbyToPrimary) {
  Rig g;
  running_pair(g);
  g.pair.ram(0).set_holding(kNonTransferLast, 5);
  g.pair.ram(1).set_holding(kNonTransferLast, 9);
  g.at(13 * kMs);
  // Registers 1-2: what the standby holds (e.g. a STAT of its diagnostics) goes to the primary.
  g.pair.ram(1).set_holding(kReverse0, 0x0123);
  g.pair.ram(1).set_holding(kReverse1, 0x4567);
  g.pair.ram(0).set_holding(kReverse0, 0xAAAA);
  g.at(20 * kMs + kXfer - 1);
  EXPECT_EQ(g.pair.ram(0).holding(kReverse0), 0xAAAA);
  g.at(20 * kMs + kXfer);
  EXPECT_EQ(g.pair.ram(0).holding(kReverse0), 0x0123);
  EXPECT_EQ(g.pair.ram(0).holding(kReverse1), 0x4567);
  EXPECT_EQ(g.pair.ram(1).holding(kReverse0), 0x0123);  // not overwritten by the forward copy
  // Register 4 of the area: untouched both ways.
  EXPECT_EQ(g.pair.ram(0).holding(kNonTransferLast), 5);
  EXPECT_EQ(g.pair.ram(1).holding(kNonTransferLast), 9);
  // Register 3: each unit's own status register, never copied.
  EXPECT_EQ(g.pair.ram(0).holding(kStatus) & 0x3, 0b10);
  EXPECT_EQ(g.pair.ram(1).holding(kStatus) & 0x3, 0b11);
}

TEST(HsbyTransfer, AdditionalSlicesOnePerScanInTurn) {
  HsbyPairParams p = small_params();
  p.plan.additional_slices = {{{RefType::Register4x, 48, 8}}, {{RefType::Register4x, 56, 8}}};
  Rig g(p);
  running_pair(g);
  g.at(5 * kMs);
  g.pair.ram(0).set_holding(50, 1);  // slice 0: scans 1, 3, 5 ... (started at 0, 20, 40 ms)
  g.pair.ram(0).set_holding(60, 2);  // slice 1: scans 2, 4 ... (started at 10, 30 ms)
  g.at(10 * kMs + kXfer);
  EXPECT_EQ(g.pair.ram(1).holding(50), 0);
  EXPECT_EQ(g.pair.ram(1).holding(60), 2);
  g.at(20 * kMs + kXfer);
  EXPECT_EQ(g.pair.ram(1).holding(50), 1);
}

TEST(HsbyTransfer, NoStandbyNoTransferOfflineKeepsItsRam) {
  HsbyPairParams p = small_params();
  p.racks[1].key = KeySwitch::OffLine;
  Rig g(p);
  running_pair(g);
  g.pair.ram(1).set_holding(3, 42);
  g.at(100 * kMs);
  EXPECT_EQ(g.pair.transfers_completed(), 0u);
  EXPECT_EQ(g.pair.ram(1).holding(3), 42);
  EXPECT_EQ(g.pair.ram(1).holding(1), 0);
  EXPECT_EQ(g.pair.last_transfer_scan_start(), bus::kNever);
}

}  // namespace
}  // namespace pbvbus::quantum
