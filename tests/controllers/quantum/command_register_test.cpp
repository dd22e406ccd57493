// The command and status registers (command_register.hpp; seed 003 pp. 75-95): bit positions
// in Modicon numbering worked out by hand (bit n = 1 << (16 − n)), exhaustive round trips over
// all 65536 words, the non-transfer area's roles (the seed's 40010..40039 example) and the
// placement refusals, alone and through plan_transfer (seeds-digest.md §11 Q4, Q5).
#include "pbvbus/quantum/command_register.hpp"

#include <gtest/gtest.h>

#include "pbvbus/quantum/transfer_area.hpp"

namespace pbvbus::quantum {
namespace {

TEST(CommandRegister, BitPositionsByHand) {
  // Bit 16 = 0x0001 (the public IEC note), 15 = 0x0002 (A), 14 = 0x0004 (B), 13 = 0x0008,
  // 12 = 0x0010, ports 1..3 = bits 8, 7, 6 = 0x0100, 0x0200, 0x0400.
  CommandRegister c;
  c.keyswitch_override = true;
  EXPECT_EQ(encode_command(c), 0x0001);
  c = {};
  c.run_a = true;
  EXPECT_EQ(encode_command(c), 0x0002);
  c = {};
  c.run_b = true;
  EXPECT_EQ(encode_command(c), 0x0004);
  c = {};
  c.standby_stays_on_logic_mismatch = true;
  EXPECT_EQ(encode_command(c), 0x0008);
  c = {};
  c.exec_upgrade_while_running = true;
  EXPECT_EQ(encode_command(c), 0x0010);
  c = {};
  c.swap_disabled = {true, false, false};
  EXPECT_EQ(encode_command(c), 0x0100);
  c.swap_disabled = {false, true, false};
  EXPECT_EQ(encode_command(c), 0x0200);
  c.swap_disabled = {false, false, true};
  EXPECT_EQ(encode_command(c), 0x0400);
}

TEST(CommandRegister, OverrideWithBothRunBitsZero) {
  // Override on, A and B offline: the word the seed's switchover command writes (p. 76).
  const CommandRegister c = decode_command(0x0001);
  EXPECT_TRUE(c.keyswitch_override);
  EXPECT_FALSE(c.run_a);
  EXPECT_FALSE(c.run_b);
  // Override on, both running: 0x0007.
  const CommandRegister r = decode_command(0x0007);
  EXPECT_TRUE(r.run_a && r.run_b && r.keyswitch_override);
}

TEST(CommandRegister, ExhaustiveRoundTrip) {
  for (std::uint32_t w = 0; w <= 0xFFFF; ++w) {
    const auto word = static_cast<std::uint16_t>(w);
    const CommandRegister c = decode_command(word);
    ASSERT_EQ(encode_command(c), word & kCommandMask) << w;
    ASSERT_EQ(decode_command(encode_command(c)), c) << w;
  }
  EXPECT_EQ(kCommandMask, 0x071F);
}

TEST(StatusRegister, BitPositionsByHand) {
  // This unit bits 15-16 (primary 10 → bit 15 = 0x0002), other 13-14 (standby 11 → 0x000C),
  // logic mismatch bit 12 = 0x0010, B bit 11 = 0x0020, interface error bit 2 = 0x4000,
  // HSBY active bit 1 = 0x8000.
  StatusRegister s;
  s.this_unit = UnitCode::Primary;
  s.other_unit = UnitCode::Standby;
  EXPECT_EQ(encode_status(s), 0x000E);
  s = {};
  s.this_unit = UnitCode::Standby;  // bits 15 and 16: the seed's STAT enable (p. 83-84)
  EXPECT_EQ(encode_status(s), 0x0003);
  s = {};
  s.this_unit = UnitCode::Offline;
  s.other_unit = UnitCode::Primary;
  EXPECT_EQ(encode_status(s), 0x0001 | 0x0008);
  s = {};
  s.logic_mismatch = true;
  EXPECT_EQ(encode_status(s), 0x0010);
  s = {};
  s.designation_b = true;
  EXPECT_EQ(encode_status(s), 0x0020);
  s = {};
  s.chs_interface_error = true;
  EXPECT_EQ(encode_status(s), 0x4000);
  s = {};
  s.hsby_active = true;
  EXPECT_EQ(encode_status(s), 0x8000);
}

TEST(StatusRegister, ExhaustiveRoundTrip) {
  for (std::uint32_t w = 0; w <= 0xFFFF; ++w) {
    const auto word = static_cast<std::uint16_t>(w);
    const StatusRegister s = decode_status(word);
    ASSERT_EQ(encode_status(s), word & kStatusMask) << w;
    ASSERT_EQ(decode_status(encode_status(s)), s) << w;
  }
  EXPECT_EQ(kStatusMask, 0xC03F);
}

TEST(NonTransferArea, SeedExample40010To40039) {
  // Area from 40010, 30 long → last 40039; status register 40012; reverse 40010, 40011.
  const NonTransferArea a{9, 30};
  EXPECT_EQ(status_register_index(a), 11U);
  EXPECT_EQ(reverse_transfer_index(a, 0), 9U);
  EXPECT_EQ(reverse_transfer_index(a, 1), 10U);
  EXPECT_EQ(check_non_transfer_area(a, 1872), "");
  // Command register 400005 outside it, as the seed's example places it.
  EXPECT_EQ(check_command_register(4, 1872, true, a), "");
}

TEST(NonTransferArea, Refusals) {
  EXPECT_EQ(check_non_transfer_area({0, 0}, 100), "");
  EXPECT_EQ(check_non_transfer_area({9, 3}, 100),
            "the non-transfer area 400010 has 3 registers, it must have at least 4 (2 reverse "
            "transfer, the status register, one more)");
  EXPECT_EQ(check_non_transfer_area({96, 4}, 100), "");
  EXPECT_EQ(check_non_transfer_area({97, 4}, 100),
            "the non-transfer area 400098..400101 does not lie entirely inside the 4x "
            "registers transferred every scan (400001..400100)");
}

TEST(CommandRegisterPlacement, Refusals) {
  EXPECT_EQ(check_command_register(0, 16, false, {}), "");
  EXPECT_EQ(check_command_register(16, 16, false, {}),
            "command register 400017 lies outside the 4x registers transferred every scan "
            "(400001..400016)");
  EXPECT_EQ(check_command_register(8999, 9008, true, {}), "");
  EXPECT_EQ(check_command_register(9000, 9008, true, {}),
            "command register 409001 is not one of the first 9000 4x registers "
            "(400001..409000), which the 12K option requires");
  EXPECT_EQ(check_command_register(9000, 9008, false, {}), "");
  EXPECT_EQ(check_command_register(11, 100, false, {9, 30}),
            "command register 400012 lies inside the non-transfer area (400010..400039); it "
            "must be outside it");
}

TEST(CommandRegisterPlacement, ThroughPlanTransfer) {
  StateRamSizes s;
  s.input_regs = 3200;
  s.holding = 9600;
  TransferConfig c;  // 12K: 9008 4x every scan
  c.command_register = 9000;
  EXPECT_EQ(plan_transfer(c, s).error,
            "command register 409001 is not one of the first 9000 4x registers "
            "(400001..409000), which the 12K option requires");
  c.command_register = 9500;
  EXPECT_EQ(plan_transfer(c, s).error,
            "command register 409501 lies outside the 4x registers transferred every scan "
            "(400001..409008)");
  c.mode = TransferConfig::Mode::UserDefined;
  c.holding = 9008;
  c.command_register = 9007;
  EXPECT_TRUE(plan_transfer(c, s).plan);
  c.command_register = 20;
  c.non_transfer = {19, 4};
  EXPECT_EQ(plan_transfer(c, s).error,
            "command register 400021 lies inside the non-transfer area (400020..400023); it "
            "must be outside it");
  c.non_transfer = {9006, 4};
  EXPECT_EQ(plan_transfer(c, s).error,
            "the non-transfer area 409007..409010 does not lie entirely inside the 4x "
            "registers transferred every scan (400001..409008)");
  c.non_transfer = {100, 30};
  const auto r = plan_transfer(c, s);
  ASSERT_TRUE(r.plan) << r.error;
  EXPECT_EQ(r.plan->non_transfer, (NonTransferArea{100, 30}));
}

}  // namespace
}  // namespace pbvbus::quantum
