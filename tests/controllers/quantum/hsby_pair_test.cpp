// The Hot Standby pair's power-on order, keyswitch, designation switch and LEDs (seed 003
// pp. 16-22, seeds-digest.md §8, Q6 and the keyswitch half of Q7). Times in ticks.
#include <gtest/gtest.h>

#include <stdexcept>

#include "hsby_test_support.hpp"

namespace pbvbus::quantum {
namespace {

using namespace hsby_test;

TEST(HsbyPair, FirstUnitAtRunIsPrimaryTheSecondStandby) {
  Rig g;
  EXPECT_EQ(g.pair.state(0), CpuState::Off);
  EXPECT_EQ(g.h0.role, HeadRole::Off);
  g.pair.power_on(0);
  EXPECT_EQ(g.pair.state(0), CpuState::Primary);
  EXPECT_EQ(g.h0.role, HeadRole::Active);
  g.at(5 * kMs);
  g.pair.power_on(1);
  EXPECT_EQ(g.pair.state(1), CpuState::Standby);
  EXPECT_EQ(g.h1.role, HeadRole::Passive);
  EXPECT_EQ(g.pair.primary(), 0);
  EXPECT_EQ(g.pair.standby(), 1);
  g.at(35 * kMs);
  EXPECT_EQ(g.pair.scans(0), 4u);  // 0, 10, 20, 30 ms
  EXPECT_EQ(g.pair.scans(1), 0u);  // the standby runs no logic
  EXPECT_EQ(g.h0.reads, 4);
  EXPECT_EQ(g.h1.reads, 0);
  // LEDs (seed p. 19)
  const ChsLeds p = g.pair.leds(0), s = g.pair.leds(1);
  EXPECT_EQ(p, (ChsLeds{Led::On, Led::On, Led::On, Led::Off, Led::Off}));
  EXPECT_EQ(s, (ChsLeds{Led::On, Led::On, Led::Off, Led::Off, Led::On}));
}

TEST(HsbyPair, StatusRegisterCodesThisUnitTheOtherMatchAndDesignation) {
  Rig g;
  g.pair.power_on(0);
  g.pair.power_on(1);
  g.at(1 * kMs);
  // Rack 0 (A) primary: this 10, other 11 (bits 13-14 -> 0b11 << 2), match, A, HSBY active.
  EXPECT_EQ(g.pair.ram(0).holding(kStatus), 0x8000 | 0x0002 | 0x000C);
  // Rack 1 (B) standby: this 11, other 10 (<< 2), B = bit 11 (0x0020).
  EXPECT_EQ(g.pair.ram(1).holding(kStatus), 0x8000 | 0x0003 | 0x0008 | 0x0020);
  g.pair.power_off(1);
  // The other unit unheard: its code is 00.
  EXPECT_EQ(g.pair.ram(0).holding(kStatus), 0x8000 | 0x0002);
}

TEST(HsbyPair, KeyAtOffLineAtPowerOnStaysOfflineRunJoins) {
  HsbyPairParams p = small_params();
  p.racks[1].key = KeySwitch::OffLine;
  Rig g(p);
  g.pair.power_on(0);
  g.pair.power_on(1);
  EXPECT_EQ(g.pair.state(1), CpuState::Offline);
  EXPECT_EQ(g.pair.leds(1).standby, Led::Off);
  g.at(12 * kMs);
  g.pair.set_key(1, KeySwitch::Run);
  EXPECT_EQ(g.pair.state(1), CpuState::Standby);
}

TEST(HsbyPair, BothKeysOffLineThenOneToRunIsPrimaryAlone) {
  HsbyPairParams p = small_params();
  p.racks[0].key = KeySwitch::OffLine;
  p.racks[1].key = KeySwitch::OffLine;
  Rig g(p);
  g.pair.power_on(0);
  g.pair.power_on(1);
  EXPECT_EQ(g.pair.state(0), CpuState::Offline);
  EXPECT_EQ(g.pair.state(1), CpuState::Offline);
  g.at(3 * kMs);
  g.pair.set_key(1, KeySwitch::Run);
  EXPECT_EQ(g.pair.state(1), CpuState::Primary);
  g.pair.set_key(0, KeySwitch::Run);
  EXPECT_EQ(g.pair.state(0), CpuState::Standby);
}

TEST(HsbyPair, Q6SameDesignationSecondStaysOfflineComActBlinking) {
  HsbyPairParams p = small_params();
  p.racks[0].designation = Designation::B;  // both B
  Rig g(p);
  g.pair.power_on(1);  // the first powered: primary, whatever its designation
  g.at(4 * kMs);
  g.pair.power_on(0);
  EXPECT_EQ(g.pair.state(1), CpuState::Primary);
  EXPECT_EQ(g.pair.state(0), CpuState::Offline);
  EXPECT_EQ(g.pair.leds(0).com_act, Led::Blinking);
  EXPECT_EQ(g.pair.leds(1).com_act, Led::Off);  // the pair does not communicate as a pair
  EXPECT_TRUE(g.has_event(PairEventKind::DuplicateDesignation, 0));
  // The slide switch is read at power-on only: moving it changes nothing until then.
  g.pair.set_designation(0, Designation::A);
  g.pair.set_key(0, KeySwitch::OffLine);
  g.pair.set_key(0, KeySwitch::Run);
  EXPECT_EQ(g.pair.state(0), CpuState::Offline);
  g.pair.power_off(0);
  g.pair.power_on(0);
  EXPECT_EQ(g.pair.state(0), CpuState::Standby);
  EXPECT_EQ(g.pair.leds(0).com_act, Led::On);
  // Once running, primary control may pass to either designation (p. 20).
  g.pair.set_key(1, KeySwitch::OffLine);
  g.at(11 * kMs);
  EXPECT_EQ(g.pair.primary(), 0);
}

TEST(HsbyPair, FibreTxRxNotCrossedStandbyStaysOfflineComErr) {
  Rig g;
  g.pair.set_fibre(FibreState::TxRxNotCrossed);
  g.pair.power_on(0);
  g.pair.power_on(1);
  EXPECT_EQ(g.pair.state(0), CpuState::Primary);
  EXPECT_EQ(g.pair.state(1), CpuState::Offline);
  EXPECT_EQ(g.pair.leds(0).com_err, Led::On);
  EXPECT_EQ(g.pair.leds(1).com_err, Led::On);
  EXPECT_EQ(g.pair.leds(1).com_act, Led::Off);
  g.at(50 * kMs);
  EXPECT_EQ(g.pair.transfers_completed(), 0u);
  // Crossed correctly: the CHS modules talk, the offline unit (key at Run) joins.
  g.pair.set_fibre(FibreState::Ok);
  EXPECT_EQ(g.pair.state(1), CpuState::Standby);
  EXPECT_EQ(g.pair.leds(1).com_err, Led::Off);
}

TEST(HsbyPair, Q7PrimaryKeyToXferIsIgnored) {
  Rig g;
  g.pair.power_on(0);
  g.pair.power_on(1);
  g.at(15 * kMs);
  g.pair.set_key(0, KeySwitch::Xfer);
  g.at(45 * kMs);
  EXPECT_EQ(g.pair.state(0), CpuState::Primary);
  EXPECT_EQ(g.pair.state(1), CpuState::Standby);
  EXPECT_TRUE(g.pair.switchovers().empty());
  EXPECT_TRUE(g.has_event(PairEventKind::Ignored, 0));
}

TEST(HsbyPair, PrimaryKeyOffLineHandsControlOverAtTheScanBoundary) {
  Rig g;
  g.pair.power_on(0);
  g.pair.power_on(1);
  g.at(13 * kMs);
  g.pair.set_key(0, KeySwitch::OffLine);
  EXPECT_EQ(g.pair.state(0), CpuState::Primary);  // until its scan ends
  g.at(19 * kMs);
  EXPECT_EQ(g.pair.state(0), CpuState::Primary);
  g.at(20 * kMs);
  EXPECT_EQ(g.pair.state(0), CpuState::Offline);
  EXPECT_EQ(g.pair.state(1), CpuState::Primary);
  ASSERT_EQ(g.pair.switchovers().size(), 1u);
  const SwitchoverRecord& r = g.pair.switchovers()[0];
  EXPECT_EQ(r.cause, SwitchoverCause::KeyOffLine);
  EXPECT_EQ(r.old_rack, 0);
  EXPECT_EQ(r.new_rack, 1);
  EXPECT_EQ(r.cause_time, 13 * kMs);
  EXPECT_EQ(r.time, 20 * kMs);
  EXPECT_EQ(r.takeover_ticks, 7 * kMs);
  EXPECT_DOUBLE_EQ(r.takeover_scans, 0.7);
  EXPECT_EQ(g.h0.role, HeadRole::Passive);
  EXPECT_EQ(g.h1.role, HeadRole::Active);
  // The old primary's head left Active before the new one entered it.
  ASSERT_GE(g.h0.roles.size(), 1u);
  EXPECT_EQ(g.h0.roles.back(), std::make_pair(bus::Ticks{20 * kMs}, HeadRole::Passive));
  EXPECT_EQ(g.h1.roles.back(), std::make_pair(bus::Ticks{20 * kMs}, HeadRole::Active));
  EXPECT_EQ(g.pair.scans(0), 2u);  // 0, 10
  g.at(20 * kMs + 1);
  EXPECT_EQ(g.pair.scans(1), 1u);  // its first scan at 20 ms
  // Back to Run: the old primary becomes the standby.
  g.pair.set_key(0, KeySwitch::Run);
  EXPECT_EQ(g.pair.state(0), CpuState::Standby);
}

TEST(HsbyPair, PrimaryAloneKeepsControlWhenTurnedOffLine) {
  Rig g;
  g.pair.power_on(0);
  g.at(3 * kMs);
  g.pair.set_key(0, KeySwitch::OffLine);
  g.at(40 * kMs);
  EXPECT_EQ(g.pair.state(0), CpuState::Primary);
  EXPECT_TRUE(g.has_event(PairEventKind::Ignored, 0));
  // A standby arrives: the key's request is carried out at the next boundary.
  g.pair.power_on(1);
  EXPECT_EQ(g.pair.state(1), CpuState::Standby);
  g.at(50 * kMs);
  EXPECT_EQ(g.pair.state(1), CpuState::Primary);
  EXPECT_EQ(g.pair.state(0), CpuState::Offline);
  ASSERT_EQ(g.pair.switchovers().size(), 1u);
  EXPECT_EQ(g.pair.switchovers()[0].cause_time, 40 * kMs);  // the standby's arrival
}

TEST(HsbyPair, StandbyKeyToOffLineGoesOfflinePrimaryRunsAlone) {
  Rig g;
  g.pair.power_on(0);
  g.pair.power_on(1);
  g.at(14 * kMs);
  g.pair.set_key(1, KeySwitch::OffLine);
  EXPECT_EQ(g.pair.state(1), CpuState::Offline);
  g.at(60 * kMs);
  EXPECT_EQ(g.pair.state(0), CpuState::Primary);
  EXPECT_TRUE(g.pair.switchovers().empty());
  // Offline units keep their state RAM: the last transfer's value stays.
  EXPECT_EQ(g.pair.ram(1).holding(1), 1);  // the transfer of the 10 ms scan carried 1
}

TEST(HsbyPair, EventLogPowerStatesSwitchover) {
  Rig g;
  g.pair.power_on(0);
  g.pair.power_on(1);
  g.at(25 * kMs);
  g.pair.power_off(0);
  g.at(30 * kMs);
  std::vector<std::pair<int, PairEventKind>> got;
  for (const auto& e : g.pair.events()) got.emplace_back(e.rack, e.kind);
  const std::vector<std::pair<int, PairEventKind>> want = {
      {0, PairEventKind::Power}, {0, PairEventKind::State},  // offline -> primary
      {1, PairEventKind::Power}, {1, PairEventKind::State},  // offline -> standby
      {0, PairEventKind::Power}, {0, PairEventKind::State},  // power off; primary -> off
      {1, PairEventKind::State}, {1, PairEventKind::Switchover}};
  EXPECT_EQ(got, want);
  EXPECT_EQ(g.pair.events().back().time, 30 * kMs);
  EXPECT_EQ(g.pair.events()[1].text, "offline -> primary (no other primary)");
}

TEST(HsbyPair, ConstructionRefusesBadParameters) {
  bus::Scheduler s;
  HsbyPairParams p = small_params();
  p.command_register = 64;
  EXPECT_THROW(HsbyPair(s, p, {nullptr, nullptr}), std::invalid_argument);
  p = small_params();
  p.transfer_time = kScan + 1;
  EXPECT_THROW(HsbyPair(s, p, {nullptr, nullptr}), std::invalid_argument);
  p = small_params();
  p.scan_time = 0;
  EXPECT_THROW(HsbyPair(s, p, {nullptr, nullptr}), std::invalid_argument);
  p = small_params();
  p.line_check_delay = kScan / 2 + 1;
  EXPECT_THROW(HsbyPair(s, p, {nullptr, nullptr}), std::invalid_argument);
  p = small_params();
  p.transfer_time = 0;
  HsbyPair ok(s, p, {nullptr, nullptr});
  EXPECT_EQ(ok.transfer_time(), kScan / 4);
}

}  // namespace
}  // namespace pbvbus::quantum
