// Keyswitch override and the run bits of the command register, logic mismatch and the program
// update of the Hot Standby pair (seed 003 pp. 21-22, 88-92; seeds-digest.md §8, Q5). The
// command register is 4x 0 (400001); run bits: 0x0002 = bit 15 = A, 0x0004 = bit 14 = B
// (Modicon numbering, bit 1 = MSB). Times in ticks.
#include <gtest/gtest.h>

#include "hsby_test_support.hpp"

namespace pbvbus::quantum {
namespace {

using namespace hsby_test;

constexpr std::uint16_t kRunA = 0x0002, kRunB = 0x0004;

HsbyPairParams override_params() {
  HsbyPairParams p = small_params();
  p.keyswitch_override = true;
  return p;
}

void start_with_bits(Rig& g, std::uint16_t bits) {
  g.pair.ram(0).set_holding(0, bits);  // battery-backed state RAM read at power-on
  g.pair.ram(1).set_holding(0, bits);
  g.pair.power_on(0);
  g.pair.power_on(1);
}

TEST(HsbyOverride, RunBitsDecideAtStartupKeysIgnored) {
  Rig g(override_params());
  start_with_bits(g, kRunA | kRunB);
  EXPECT_EQ(g.pair.state(0), CpuState::Primary);
  EXPECT_EQ(g.pair.state(1), CpuState::Standby);
  g.pair.set_key(1, KeySwitch::OffLine);
  EXPECT_EQ(g.pair.state(1), CpuState::Standby);
  EXPECT_TRUE(g.has_event(PairEventKind::Ignored, 1));
}

TEST(HsbyOverride, RunBitBZeroAtStartupKeepsBOffline) {
  Rig g(override_params());
  start_with_bits(g, kRunA);
  EXPECT_EQ(g.pair.state(0), CpuState::Primary);
  EXPECT_EQ(g.pair.state(1), CpuState::Offline);
  // Option 2 of p. 91: set bit 14 in the primary's command register -> B to Run.
  g.at(5 * kMs);
  g.pair.ram(0).set_holding(0, kRunA | kRunB);
  g.at(10 * kMs);  // read at the scan start
  EXPECT_EQ(g.pair.state(1), CpuState::Standby);
}

TEST(HsbyOverride, Q5BothRunBitsZeroSwitchoverOldPrimaryOffline) {
  Rig g(override_params());
  start_with_bits(g, kRunA | kRunB);
  g.at(13 * kMs);
  g.pair.ram(0).set_holding(0, 0);  // both bits 0, written into the primary
  g.at(20 * kMs);                   // read at the 20 ms scan start: handover requested
  EXPECT_EQ(g.pair.state(0), CpuState::Primary);
  g.at(30 * kMs);  // at the scan boundary
  EXPECT_EQ(g.pair.state(0), CpuState::Offline);
  EXPECT_EQ(g.pair.state(1), CpuState::Primary);
  ASSERT_EQ(g.pair.switchovers().size(), 1u);
  EXPECT_EQ(g.pair.switchovers()[0].cause, SwitchoverCause::CommandRegister);
  EXPECT_EQ(g.pair.switchovers()[0].cause_time, 20 * kMs);
  EXPECT_EQ(g.pair.switchovers()[0].takeover_ticks, kScan);
  // The new primary continues (its own bit is 0 too, in its transferred command register).
  EXPECT_EQ(g.pair.ram(1).holding(0), 0);
  g.at(100 * kMs);
  EXPECT_EQ(g.pair.state(1), CpuState::Primary);
  EXPECT_EQ(g.pair.state(0), CpuState::Offline);
  EXPECT_EQ(g.pair.switchovers().size(), 1u);
}

TEST(HsbyOverride, StandbyRunBitZeroGoesOffline) {
  Rig g(override_params());
  start_with_bits(g, kRunA | kRunB);
  g.at(13 * kMs);
  g.pair.ram(0).set_holding(0, kRunA);
  g.at(20 * kMs);
  EXPECT_EQ(g.pair.state(1), CpuState::Offline);
  EXPECT_EQ(g.pair.state(0), CpuState::Primary);
}

TEST(HsbyOverride, EnablingAtRunTimeReadsTheBitsAtOnce) {
  Rig g;  // override disabled: keys at Run decide
  g.pair.power_on(0);
  g.pair.power_on(1);
  g.at(13 * kMs);
  g.pair.ram(0).set_holding(0, kRunB);  // A (the primary) offline, B run
  g.pair.set_keyswitch_override(true);
  EXPECT_TRUE(g.has_event(PairEventKind::Override));
  g.at(20 * kMs);  // the handover at the boundary
  EXPECT_EQ(g.pair.state(1), CpuState::Primary);
  EXPECT_EQ(g.pair.state(0), CpuState::Offline);
  EXPECT_EQ(g.pair.switchovers()[0].cause_time, 13 * kMs);
}

TEST(HsbyOverride, NoProgramUpdateAtTheModule) {
  HsbyPairParams p = override_params();
  p.racks[1].logic_checksum = 2;
  Rig g(p);
  start_with_bits(g, kRunA | kRunB);
  g.pair.press_update(1);
  g.pair.set_key(1, KeySwitch::Xfer);
  EXPECT_EQ(g.pair.update_phase(1), UpdatePhase::None);
  EXPECT_TRUE(g.has_event(PairEventKind::Ignored, 1));
}

TEST(HsbyLogicMismatch, Q5DefaultStandbyOfflineNoSwitchover) {
  HsbyPairParams p = small_params();
  p.racks[1].logic_checksum = 0x5A5A;
  Rig g(p);
  g.pair.power_on(0);
  g.pair.power_on(1);
  EXPECT_FALSE(g.pair.logic_match());
  EXPECT_EQ(g.pair.state(1), CpuState::Offline);
  EXPECT_TRUE(g.has_event(PairEventKind::LogicMismatch, 1));
  EXPECT_EQ(g.pair.ram(0).holding(kStatus) & 0x0010, 0x0010);  // bit 12: no matching logic
  g.at(15 * kMs);
  g.pair.power_off(0);
  g.at(60 * kMs);
  EXPECT_EQ(g.pair.primary(), -1);
  EXPECT_TRUE(g.pair.switchovers().empty());
  // Nor does the primary's key hand over.
  g.pair.power_on(0);
  g.pair.set_key(0, KeySwitch::OffLine);
  g.at(100 * kMs);
  EXPECT_EQ(g.pair.primary(), 0);
}

TEST(HsbyLogicMismatch, LoadingADifferentProgramOnTheStandbyTakesItOffline) {
  Rig g;
  g.pair.power_on(0);
  g.pair.power_on(1);
  g.at(5 * kMs);
  g.pair.load_program(1, 7, count_scans);
  EXPECT_EQ(g.pair.state(1), CpuState::Offline);
}

TEST(HsbyLogicMismatch, Q5OptionStandbyStaysAndTakesOverWithItsOwnProgram) {
  HsbyPairParams p = small_params();
  p.racks[1].logic_checksum = 0x5A5A;
  p.standby_stays_on_logic_mismatch = true;
  Rig g(p);
  g.pair.set_logic(1, [](StateRam& ram, bus::Ticks) { ram.set_holding(2, 0xB0B0); });
  g.pair.power_on(0);
  g.pair.power_on(1);
  EXPECT_EQ(g.pair.state(1), CpuState::Standby);
  g.at(15 * kMs);
  g.pair.power_off(0);
  g.at(20 * kMs);
  EXPECT_EQ(g.pair.state(1), CpuState::Primary);
  EXPECT_EQ(g.pair.ram(1).holding(2), 0xB0B0);  // its own program runs
  EXPECT_EQ(g.pair.ram(1).holding(1), 1);       // not the old primary's counter
  // Switching the option off takes a mismatching standby offline.
  g.pair.power_on(0);
  EXPECT_EQ(g.pair.state(0), CpuState::Standby);
  g.pair.set_standby_stays_on_logic_mismatch(false);
  EXPECT_EQ(g.pair.state(0), CpuState::Offline);
}

TEST(HsbyUpdate, XferAndUpdateButtonCopyProgramAndAllStateRamThenRun) {
  HsbyPairParams p = small_params();
  p.racks[1].logic_checksum = 0x5A5A;
  Rig g(p);
  g.pair.power_on(0);
  g.pair.power_on(1);
  ASSERT_EQ(g.pair.state(1), CpuState::Offline);
  g.pair.ram(0).set_holding(60, 0x6060);  // outside the per-scan plan: only the update copies it
  g.at(12 * kMs);
  // Seed p. 21: hold the update button, key to Xfer (Com Act off), key to the mode wanted
  // (Standby flashes), release the button; the Standby LED flashes until the update is done.
  g.pair.press_update(1);
  g.pair.set_key(1, KeySwitch::Xfer);
  EXPECT_EQ(g.pair.update_phase(1), UpdatePhase::Armed);
  EXPECT_EQ(g.pair.leds(1).com_act, Led::Off);
  g.pair.set_key(1, KeySwitch::Run);
  EXPECT_EQ(g.pair.update_phase(1), UpdatePhase::Requested);
  EXPECT_EQ(g.pair.leds(1).standby, Led::Blinking);
  g.at(13 * kMs);
  g.pair.release_update(1);
  EXPECT_EQ(g.pair.update_phase(1), UpdatePhase::Running);
  EXPECT_EQ(g.pair.leds(1).standby, Led::Blinking);
  g.at(63 * kMs - 1);
  EXPECT_EQ(g.pair.state(1), CpuState::Offline);
  g.at(63 * kMs);  // update_time 50 ms after the release
  EXPECT_EQ(g.pair.update_phase(1), UpdatePhase::None);
  EXPECT_TRUE(g.pair.logic_match());
  EXPECT_EQ(g.pair.ram(1).holding(60), 0x6060);
  EXPECT_EQ(g.pair.ram(1).holding(1), g.pair.ram(0).holding(1));
  EXPECT_EQ(g.pair.state(1), CpuState::Standby);
  EXPECT_EQ(g.pair.leds(1).standby, Led::On);
  EXPECT_EQ(g.pair.leds(1).com_act, Led::On);
}

TEST(HsbyUpdate, KeyToOffLineAfterTheUpdateLeavesTheUnitOffline) {
  Rig g;
  g.pair.power_on(0);
  g.pair.power_on(1);
  g.at(12 * kMs);
  g.pair.press_update(1);
  g.pair.set_key(1, KeySwitch::Xfer);
  EXPECT_EQ(g.pair.state(1), CpuState::Offline);  // a standby leaves to be updated
  g.pair.set_key(1, KeySwitch::OffLine);
  g.pair.release_update(1);
  g.at(70 * kMs);
  EXPECT_EQ(g.pair.state(1), CpuState::Offline);
  EXPECT_EQ(g.pair.leds(1).standby, Led::Off);
}

TEST(HsbyUpdate, PrimaryFailureAbortsTheUpdate) {
  Rig g;
  g.pair.power_on(0);
  g.pair.power_on(1);
  g.pair.press_update(1);
  g.pair.set_key(1, KeySwitch::Xfer);
  g.pair.set_key(1, KeySwitch::Run);
  g.pair.release_update(1);
  g.at(20 * kMs);
  g.pair.power_off(0);
  EXPECT_EQ(g.pair.update_phase(1), UpdatePhase::None);
  g.at(100 * kMs);
  EXPECT_EQ(g.pair.primary(), -1);  // an offline unit does not take over
  EXPECT_TRUE(g.has_event(PairEventKind::Update, 1));
}

TEST(HsbyUpdate, XferWithoutTheButtonChangesNothing) {
  Rig g;
  g.pair.power_on(0);
  g.pair.power_on(1);
  g.pair.set_key(1, KeySwitch::Xfer);
  EXPECT_EQ(g.pair.state(1), CpuState::Standby);
  EXPECT_EQ(g.pair.update_phase(1), UpdatePhase::None);
}

}  // namespace
}  // namespace pbvbus::quantum
