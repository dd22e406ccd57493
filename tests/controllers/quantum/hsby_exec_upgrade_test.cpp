// Executive (firmware) upgrades of the pair (seed 003 pp. 30, 86 "Allows exec upgrade only after
// application stops = 0 / without stopping application = 1", p. 96 "Advanced Options").
#include <gtest/gtest.h>

#include "hsby_test_support.hpp"
#include "pbvbus/quantum/command_register.hpp"

namespace pbvbus::quantum {
namespace {

using namespace hsby_test;

void xu_set_exec_bit(HsbyPair& pair, int rack, bool while_running) {
  CommandRegister c = decode_command(pair.ram(rack).holding(0));
  c.exec_upgrade_while_running = while_running;
  pair.ram(rack).set_holding(0, encode_command(c));
}

TEST(HsbyExecUpgrade, OnlyAfterTheApplicationStopsByDefault) {
  Rig g;
  g.pair.power_on(0);
  g.pair.power_on(1);
  g.at(25 * kMs);
  ASSERT_EQ(g.pair.standby(), 1);
  // Command register bit 12 = 0: refused while rack 0 runs the application.
  EXPECT_NE(g.pair.upgrade_executive(1, 2).find("only after the application stops"), std::string::npos);
  EXPECT_EQ(g.pair.firmware(1), 1u);
  EXPECT_EQ(g.pair.standby(), 1);
  // The application stopped (the standby's key Off Line, then the primary's CPU stopped: nobody
  // is primary): allowed.
  g.pair.set_key(1, KeySwitch::OffLine);
  g.pair.stop_cpu(0);
  g.at(45 * kMs);
  ASSERT_EQ(g.pair.primary(), -1);
  EXPECT_EQ(g.pair.upgrade_executive(1, 2), "");
  EXPECT_EQ(g.pair.firmware(1), 2u);
}

TEST(HsbyExecUpgrade, WhileRunningTheStandbyLeavesAndStaysOfflineWithADifferentExecutive) {
  Rig g;
  g.pair.power_on(0);
  g.pair.power_on(1);
  g.at(25 * kMs);
  xu_set_exec_bit(g.pair, 0, true);
  // The primary is never upgraded in place.
  EXPECT_EQ(g.pair.upgrade_executive(0, 2), "the unit is primary: hand control over first");
  EXPECT_EQ(g.pair.upgrade_executive(1, 2), "");
  // Seed p. 96: by default a standby with another executive does not go online.
  EXPECT_EQ(g.pair.state(1), CpuState::Offline);
  EXPECT_EQ(g.pair.primary(), 0);
  g.at(60 * kMs);
  EXPECT_EQ(g.pair.state(1), CpuState::Offline);
}

TEST(HsbyExecUpgrade, AdvancedOptionsUpgradeStepByStepWithoutStopping) {
  HsbyPairParams p = small_params();
  p.allow_different_firmware = true;
  Rig g(p);
  g.pair.power_on(0);
  g.pair.power_on(1);
  g.at(25 * kMs);
  xu_set_exec_bit(g.pair, 0, true);
  ASSERT_EQ(g.pair.upgrade_executive(1, 2), "");
  g.at(35 * kMs);
  EXPECT_EQ(g.pair.state(1), CpuState::Standby);  // back online with executive 2
  // Hand control to the upgraded unit, then upgrade the other one.
  g.pair.set_key(0, KeySwitch::OffLine);
  g.at(75 * kMs);
  ASSERT_EQ(g.pair.primary(), 1);
  g.pair.set_key(0, KeySwitch::Run);
  g.at(95 * kMs);
  ASSERT_EQ(g.pair.standby(), 0);
  EXPECT_EQ(g.pair.upgrade_executive(0, 2), "");
  g.at(125 * kMs);
  EXPECT_EQ(g.pair.state(0), CpuState::Standby);
  EXPECT_EQ(g.pair.firmware(0), 2u);
  EXPECT_EQ(g.pair.firmware(1), 2u);
}

}  // namespace
}  // namespace pbvbus::quantum
