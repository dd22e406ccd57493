// Q3 on the pair: the Modbus address swap follows the switchovers (seed 003 p. 93).
#include "pbvbus/quantum/hsby_modbus_port.hpp"

#include <gtest/gtest.h>

#include "hsby_test_support.hpp"
#include "pbvbus/quantum/command_register.hpp"

namespace pbvbus::quantum {
namespace {

using namespace hsby_test;

TEST(HsbyModbusPort, PrimaryAt1StandbyAt129SwappedAtEverySwitchover) {
  Rig g;
  HsbyModbusPort port(g.pair, 1, 1, 1, true);
  EXPECT_EQ(port.rack_for(1), -1);  // nobody powered
  g.pair.power_on(0);
  g.pair.power_on(1);
  g.at(25 * kMs);
  ASSERT_EQ(g.pair.primary(), 0);
  EXPECT_EQ(port.address(0), 1);
  EXPECT_EQ(port.address(1), 129);
  EXPECT_EQ(port.rack_for(1), 0);
  EXPECT_EQ(port.rack_for(129), 1);
  g.pair.power_off(0);
  g.at(45 * kMs);
  ASSERT_EQ(g.pair.primary(), 1);
  EXPECT_EQ(port.rack_for(1), 1);    // the new primary answers 1
  EXPECT_EQ(port.rack_for(129), -1); // rack 0 has no power
  g.pair.power_on(0);
  g.at(75 * kMs);
  ASSERT_EQ(g.pair.standby(), 0);
  EXPECT_EQ(port.rack_for(129), 0);  // the old primary, now standby, at 129
  EXPECT_EQ(port.conflicts(), 0u);
}

TEST(HsbyModbusPort, SwapDisabledInTheCommandRegisterAppliesAtTheNextSwitchover) {
  Rig g;
  HsbyModbusPort port(g.pair, 2, 5, 5, true);
  g.pair.power_on(0);
  g.pair.power_on(1);
  g.at(25 * kMs);
  // The host sets "does not swap Modbus port 2" in the command register (400001).
  CommandRegister c = decode_command(g.pair.ram(0).holding(0));
  c.swap_disabled[1] = true;
  g.pair.ram(0).set_holding(0, encode_command(c));
  g.at(35 * kMs);
  EXPECT_EQ(port.address(1), 133);  // not yet: only at the next switchover
  g.pair.power_off(0);
  g.at(55 * kMs);
  ASSERT_EQ(g.pair.primary(), 1);
  EXPECT_FALSE(port.swap_enabled());
  g.pair.power_on(0);
  g.at(85 * kMs);
  ASSERT_EQ(g.pair.standby(), 0);
  EXPECT_EQ(port.address(0), 5);  // both keep their address: the same one
  EXPECT_EQ(port.address(1), 5);
  EXPECT_EQ(port.rack_for(5), 1);  // a shared network: the primary, and a conflict counted
  EXPECT_EQ(port.conflicts(), 1u);
  EXPECT_EQ(port.rack_only(0, 5), 0);  // point to point: each rack's own door
  EXPECT_EQ(port.rack_only(1, 5), 1);
  EXPECT_EQ(port.rack_for(133), -1);
}

}  // namespace
}  // namespace pbvbus::quantum
