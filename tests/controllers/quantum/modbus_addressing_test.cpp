// The Modbus and Modbus Plus address swap (modbus_addressing.hpp; seed 003 p. 93;
// seeds-digest.md §11 Q3): 1 / 129 before and after a switchover, the swap disabled (both keep
// their address), a change applying only at the next switchover, MB+ 1 ↔ 33 and 50 ↔ 18.
#include "pbvbus/quantum/modbus_addressing.hpp"

#include <gtest/gtest.h>

namespace pbvbus::quantum {
namespace {

TEST(ModbusSwap, SeedExampleTwoPorts) {
  // A primary with ports 1 and 2 at 1 and 2: B's comparable ports at 129 and 130; after the
  // switchover B has 1 and 2, A 129 and 130.
  ModbusPortAddressing p1(1, 1, true), p2(2, 2, true);
  EXPECT_EQ(p1.address(kRackA, true), 1);
  EXPECT_EQ(p2.address(kRackA, true), 2);
  EXPECT_EQ(p1.address(kRackB, false), 129);
  EXPECT_EQ(p2.address(kRackB, false), 130);
  p1.on_switchover();
  p2.on_switchover();
  EXPECT_EQ(p1.address(kRackB, true), 1);
  EXPECT_EQ(p2.address(kRackB, true), 2);
  EXPECT_EQ(p1.address(kRackA, false), 129);
  EXPECT_EQ(p2.address(kRackA, false), 130);
}

TEST(ModbusSwap, DisabledBothKeepTheirAddress) {
  ModbusPortAddressing p(1, 1, false);
  EXPECT_EQ(p.address(kRackA, true), 1);
  EXPECT_EQ(p.address(kRackB, false), 1);
  p.on_switchover();
  EXPECT_EQ(p.address(kRackB, true), 1);
  EXPECT_EQ(p.address(kRackA, false), 1);
}

TEST(ModbusSwap, ChangeAppliesAtTheNextSwitchover) {
  ModbusPortAddressing p(1, 1, true);
  p.request_swap(false);  // the command register's "does not swap" bit set while A is primary
  EXPECT_TRUE(p.swap_enabled());
  EXPECT_FALSE(p.swap_pending());
  EXPECT_EQ(p.address(kRackB, false), 129);  // not affected yet
  p.on_switchover();                         // B becomes primary
  EXPECT_FALSE(p.swap_enabled());
  EXPECT_EQ(p.address(kRackB, true), 1);
  EXPECT_EQ(p.address(kRackA, false), 1);
  p.request_swap(true);
  EXPECT_EQ(p.address(kRackA, false), 1);
  p.on_switchover();  // A primary again, the offset back
  EXPECT_EQ(p.address(kRackA, true), 1);
  EXPECT_EQ(p.address(kRackB, false), 129);
}

TEST(ModbusSwap, DifferentConfiguredAddresses) {
  // A at 5, B at 7 (they should match, may differ): each uses its own, the non-primary + 128.
  ModbusPortAddressing p(5, 7, true);
  EXPECT_EQ(p.address(kRackA, true), 5);
  EXPECT_EQ(p.address(kRackB, false), 135);
  EXPECT_EQ(p.address(kRackB, true), 7);
  EXPECT_EQ(p.address(kRackA, false), 133);
}

TEST(ModbusSwap, AddressCheck) {
  EXPECT_EQ(check_modbus_address(1, true), "");
  EXPECT_EQ(check_modbus_address(119, true), "");
  EXPECT_EQ(check_modbus_address(120, true),
            "Modbus address 120 is outside 1..119, which a Hot Standby port with the address "
            "swap needs (the standby answers at +128, at most 247)");
  EXPECT_NE(check_modbus_address(0, true), "");
  EXPECT_EQ(check_modbus_address(120, false), "");
  EXPECT_EQ(check_modbus_address(247, false), "");
  EXPECT_EQ(check_modbus_address(248, false), "Modbus address 248 is outside 1..247");
}

TEST(ModbusPlus, PlusThirtyTwoWrapping) {
  EXPECT_EQ(mbplus_standby_address(1), 33);
  EXPECT_EQ(mbplus_standby_address(33), 1);
  EXPECT_EQ(mbplus_standby_address(50), 18);
  EXPECT_EQ(mbplus_standby_address(18), 50);
  EXPECT_EQ(mbplus_standby_address(32), 64);
  EXPECT_EQ(mbplus_standby_address(64), 32);
  EXPECT_EQ(mbplus_standby_address(0), 0);
  EXPECT_EQ(mbplus_standby_address(65), 0);
  for (int a = 1; a <= 64; ++a)
    EXPECT_EQ(mbplus_standby_address(mbplus_standby_address(static_cast<std::uint8_t>(a))), a);
}

}  // namespace
}  // namespace pbvbus::quantum
