// Redundant two-channel I/O with passivation (controllers/s7h h_redundant_io.hpp,
// docs/h-redundant-io.md; 001 §7.4 L5766-6716). Times are written by hand in ticks
// (1 ms = 3 636 000 ticks); the tolerance window, the AO halves and the status words are worked
// out by hand in each test from the manual's rules.
#include "pbvbus/s7h/h_redundant_io.hpp"

#include <gtest/gtest.h>

#include <array>
#include <cstdint>
#include <stdexcept>
#include <vector>

namespace pbvbus::devices {
namespace {

using bus::Ticks;
constexpr Ticks kMs = 3'636'000;
static_assert(kMs == bus::kTicksPerMs);
using B = std::vector<std::uint8_t>;

// A DI pair: module_L at IB 0, module_H at IB 4, one octet each, discrepancy time 100 ms.
RedIoPairSpec di_pair(DiReaction r = DiReaction::LastValidValue) {
  RedIoPairSpec s;
  s.kind = RedIoKind::DI;
  s.address_low = 0;
  s.address_high = 4;
  s.length = 1;
  s.discrepancy_time = 100 * kMs;
  s.di_reaction = r;
  return s;
}

// One RED_IN on a fresh 8-octet PII holding the raw readings; returns module_L's octet (the
// value the program sees).
std::uint8_t read_di(RedundantIo& io, Ticks t, std::uint8_t raw_l, std::uint8_t raw_h) {
  B pii(8, 0);
  pii[0] = raw_l;
  pii[4] = raw_h;
  io.red_in(t, pii);
  EXPECT_EQ(pii[4], raw_h) << "module_H's octet keeps its raw reading";
  return pii[0];
}

// --- DI (001 L5925-5962) -------------------------------------------------------------------

// Channel 2 (module_H) stuck at 0 while channel 1 goes 1 at t = 1000 ms, discrepancy time
// 100 ms. The manual: during the time the last agreeing value (0) is kept; at its expiry error
// 7960 "not yet localized", NO passivation (L5949-5954); the NEXT signal change localizes: the
// module that changed stays, the other is passivated (L5957-5959).
TEST(HRedundantIoDi, StuckChannelIs7960AtExpiryThenPassivatedAtTheNextChange) {
  RedundantIo io({di_pair()});
  for (Ticks t = 0; t < 1000 * kMs; t += 10 * kMs) EXPECT_EQ(read_di(io, t, 0, 0), 0);
  EXPECT_EQ(read_di(io, 1000 * kMs, 0x01, 0x00), 0x00);  // last agreeing value
  EXPECT_TRUE(io.pair(0).discrepant);
  EXPECT_EQ(read_di(io, 1090 * kMs, 0x01, 0x00), 0x00);
  EXPECT_TRUE(io.events().empty());
  // 1099.999... ms: one tick short of the 100 ms.
  EXPECT_EQ(read_di(io, 1100 * kMs - 1, 0x01, 0x00), 0x00);
  EXPECT_TRUE(io.events().empty());
  // 1100 ms: expired → 7960 for IB 0 bit 0, nobody passivated, the reaction "last valid value".
  EXPECT_EQ(read_di(io, 1100 * kMs, 0x01, 0x00), 0x00);
  ASSERT_EQ(io.events().size(), 1U);
  EXPECT_EQ(io.events()[0].code, 0x7960);
  EXPECT_EQ(io.events()[0].time, 1100 * kMs);
  EXPECT_EQ(io.events()[0].address, 0U);
  EXPECT_EQ(io.events()[0].bit, 0U);
  EXPECT_FALSE(io.passivated(0, RedModule::L));
  EXPECT_FALSE(io.passivated(0, RedModule::H));
  EXPECT_TRUE(io.pair(0).expired);
  // Later scans without a change: still not localized, no second 7960.
  EXPECT_EQ(read_di(io, 1400 * kMs, 0x01, 0x00), 0x00);
  EXPECT_EQ(io.events().size(), 1U);
  // 1500 ms: channel 1 changes back to 0 → module_L changed, module_H (stuck) is passivated.
  EXPECT_EQ(read_di(io, 1500 * kMs, 0x00, 0x00), 0x00);
  ASSERT_EQ(io.events().size(), 2U);
  EXPECT_EQ(io.events()[1].code, 0x7961);
  EXPECT_EQ(io.events()[1].module, 1);
  EXPECT_EQ(io.events()[1].address, 4U);
  EXPECT_FALSE(io.passivated(0, RedModule::L));
  EXPECT_TRUE(io.passivated(0, RedModule::H));
  EXPECT_EQ(io.pair(0).cause[1], RedIoCause::DiDiscrepancy);
  // From now on module_L alone gives the value.
  EXPECT_EQ(read_di(io, 1600 * kMs, 0x01, 0x00), 0x01);
  EXPECT_EQ(read_di(io, 1700 * kMs, 0x81, 0x00), 0x81);
  EXPECT_EQ(io.events().size(), 2U);
}

// The reaction "value 1": from the expiry until the next change the bit reads 1.
TEST(HRedundantIoDi, ReactionValue1GivesOneAfterTheExpiry) {
  RedundantIo io({di_pair(DiReaction::Value1)});
  EXPECT_EQ(read_di(io, 0, 0, 0), 0);
  EXPECT_EQ(read_di(io, 1000 * kMs, 0x01, 0x00), 0x00);  // during the time: last agreeing
  EXPECT_EQ(read_di(io, 1100 * kMs, 0x01, 0x00), 0x01);  // expired: value 1
  EXPECT_EQ(io.events().size(), 1U);
  EXPECT_FALSE(io.passivated(0, RedModule::H));
}

// Agreeing again within the discrepancy time: no error, the analysis goes on (L5936-5938).
TEST(HRedundantIoDi, AgreeingWithinTheTimeRaisesNothing) {
  RedundantIo io({di_pair()});
  EXPECT_EQ(read_di(io, 0, 0, 0), 0);
  EXPECT_EQ(read_di(io, 1000 * kMs, 0x01, 0x00), 0x00);
  EXPECT_EQ(read_di(io, 1100 * kMs - 1, 0x01, 0x01), 0x01);  // module_H follows in time
  EXPECT_EQ(read_di(io, 1200 * kMs, 0x01, 0x01), 0x01);
  EXPECT_TRUE(io.events().empty());
  EXPECT_FALSE(io.pair(0).discrepant);
  // A new episode starts its own time: 2000 → 2100 ms.
  EXPECT_EQ(read_di(io, 2000 * kMs, 0x00, 0x01), 0x01);
  EXPECT_EQ(read_di(io, 2099 * kMs, 0x00, 0x01), 0x01);
  EXPECT_TRUE(io.events().empty());
  EXPECT_EQ(read_di(io, 2100 * kMs, 0x00, 0x01), 0x01);
  ASSERT_EQ(io.events().size(), 1U);
  EXPECT_EQ(io.events()[0].time, 2100 * kMs);
}

// The change after the expiry is in module_H: module_H stays, module_L is passivated — the
// rule of L5957-5959 read literally (the module in which the change happened is kept).
TEST(HRedundantIoDi, ChangeInModuleHPassivatesModuleL) {
  RedundantIo io({di_pair()});
  EXPECT_EQ(read_di(io, 0, 0x00, 0x00), 0x00);
  EXPECT_EQ(read_di(io, 10 * kMs, 0x00, 0x04), 0x00);   // IB 4 bit 2 differs
  EXPECT_EQ(read_di(io, 110 * kMs, 0x00, 0x04), 0x00);  // 7960, bit 2
  ASSERT_EQ(io.events().size(), 1U);
  EXPECT_EQ(io.events()[0].bit, 2U);
  // 200 ms: module_H's bit 2 changes (back to 0, agreeing with module_L again): the change is
  // in module_H, so module_L is passivated and module_H gives the value.
  EXPECT_EQ(read_di(io, 200 * kMs, 0x00, 0x00), 0x00);
  ASSERT_EQ(io.events().size(), 2U);
  EXPECT_EQ(io.events()[1].code, 0x7961);
  EXPECT_EQ(io.events()[1].module, 0);
  EXPECT_TRUE(io.passivated(0, RedModule::L));
  EXPECT_FALSE(io.passivated(0, RedModule::H));
}

// Both modules passivated → "zeros" in the process image (L5961-5962), whatever they read.
TEST(HRedundantIoDi, BothPassivatedGiveZero) {
  RedundantIo io({di_pair()});
  EXPECT_EQ(read_di(io, 0, 0xFF, 0xFF), 0xFF);
  ASSERT_TRUE(io.module_fault(5 * kMs, 0, RedModule::L, RedIoCause::Ob85, true));
  EXPECT_EQ(read_di(io, 10 * kMs, 0x00, 0xF0), 0xF0);  // module_H alone
  ASSERT_TRUE(io.module_fault(15 * kMs, 0, RedModule::H, RedIoCause::Ob82, true));
  EXPECT_EQ(read_di(io, 20 * kMs, 0xFF, 0xFF), 0x00);
  ASSERT_EQ(io.events().size(), 2U);
  EXPECT_EQ(io.events()[0].code, 0x7965);
  EXPECT_EQ(io.events()[0].module, 0);
  EXPECT_EQ(io.events()[1].code, 0x7964);
  EXPECT_EQ(io.events()[1].module, 1);
  // Table 7-4: bit 3 (OB 85 passivated) + bit 4 (OB 82) + bit 6 (a module passivated) = 0x58.
  EXPECT_EQ(io.status_byte(), 0x58);
  // A second incoming fault on a passivated module: no second entry.
  EXPECT_TRUE(io.module_fault(30 * kMs, 0, RedModule::H, RedIoCause::Ob82, true));
  EXPECT_EQ(io.events().size(), 2U);
  EXPECT_FALSE(io.module_fault(30 * kMs, 0, RedModule::H, RedIoCause::DiDiscrepancy, true));
  EXPECT_FALSE(io.module_fault(30 * kMs, 7, RedModule::H, RedIoCause::Ob82, true));
}

// MODUL_STATUS_WORD (001 Table 7-5), byte 1 in the high octet. Worked out bit by bit:
//   all fine:        byte 1 = 1111 1111 (no OB 82, no overflow, no channel info, not
//                    expired, not discrepant, L and H depassivated); byte 2 = 1100 0000
//                    (bits 6, 7: OB 85 did not passivate) → 0xFFC0
//   discrepant:      byte 1 bit 5 = 0 → 0xDF;  and expired: bit 4 = 0 too → 0xCF
//   H passivated:    byte 1 bit 7 = 0 → 0x7F
TEST(HRedundantIoDi, ModulStatusWordFollowsTable7_5) {
  RedundantIo io({di_pair()});
  read_di(io, 0, 0, 0);
  EXPECT_EQ(io.modul_status_word(0), 0xFFC0);
  read_di(io, 10 * kMs, 1, 0);
  EXPECT_EQ(io.modul_status_word(0), 0xDFC0);
  read_di(io, 110 * kMs, 1, 0);
  EXPECT_EQ(io.modul_status_word(0), 0xCFC0);
  read_di(io, 120 * kMs, 0, 0);  // module_L's bit 0 changes back → H passivated
  EXPECT_EQ(io.modul_status_word(0), 0x7FC0);
  EXPECT_EQ(io.status_byte(), 0x40);
  EXPECT_THROW((void)io.modul_status_word(1), std::out_of_range);
}

// --- AI (001 L6136-6182) -------------------------------------------------------------------

// AI 4..20 mA, end value 27648 (S7 nominal range), tolerance window 5 % of it:
// 27648 · 5 / 100 = 1382.4, so a difference of 1382 is inside and 1383 outside.
// Discrepancy time 500 ms. Accepted value: max.
RedIoPairSpec ai_pair(AiAcceptedValue a) {
  RedIoPairSpec s;
  s.kind = RedIoKind::AI;
  s.address_low = 256;  // PIW 256 / PIW 272: one channel each
  s.address_high = 272;
  s.length = 2;
  s.discrepancy_time = 500 * kMs;
  s.tolerance_permille = 50;
  s.end_value = 27648;
  s.accepted = a;
  return s;
}

std::int32_t read_ai(RedundantIo& io, Ticks t, std::int16_t l, std::int16_t h) {
  B pii(512, 0);
  const auto ul = static_cast<std::uint16_t>(l), uh = static_cast<std::uint16_t>(h);
  pii[256] = static_cast<std::uint8_t>(ul >> 8);
  pii[257] = static_cast<std::uint8_t>(ul & 0xFF);
  pii[272] = static_cast<std::uint8_t>(uh >> 8);
  pii[273] = static_cast<std::uint8_t>(uh & 0xFF);
  io.red_in(t, pii);
  return static_cast<std::int16_t>(static_cast<std::uint16_t>((pii[256] << 8) | pii[257]));
}

TEST(HRedundantIoAi, ToleranceWindowIsFivePercentOfTheEndValue) {
  RedundantIo io({ai_pair(AiAcceptedValue::Max)});
  // 13824 = 12 mA; 13824 + 1382 = 15206 inside the window: the accepted (max) value.
  EXPECT_EQ(read_ai(io, 0, 13824, 15206), 15206);
  EXPECT_FALSE(io.pair(0).discrepant);
  // 13824 + 1383 = 15207 outside: the last valid value (15206) during the discrepancy time.
  EXPECT_EQ(read_ai(io, 2000 * kMs, 13824, 15207), 15206);
  EXPECT_TRUE(io.pair(0).discrepant);
  EXPECT_EQ(read_ai(io, 2500 * kMs - 1, 13824, 15207), 15206);
  EXPECT_TRUE(io.events().empty());
  // 2500 ms: expired. Max configured → module_H (the max) is valid, module_L passivated.
  EXPECT_EQ(read_ai(io, 2500 * kMs, 13824, 15207), 15207);
  ASSERT_EQ(io.events().size(), 1U);
  EXPECT_EQ(io.events()[0].code, 0x7962);
  EXPECT_EQ(io.events()[0].module, 0);
  EXPECT_EQ(io.events()[0].address, 256U);
  EXPECT_TRUE(io.passivated(0, RedModule::L));
  // module_H alone from now on, whatever module_L reads.
  EXPECT_EQ(read_ai(io, 2600 * kMs, 0, 20000), 20000);
}

TEST(HRedundantIoAi, MinConfiguredPassivatesTheModuleWithTheMax) {
  RedundantIo io({ai_pair(AiAcceptedValue::Min)});
  EXPECT_EQ(read_ai(io, 0, 15206, 13824), 13824);  // inside: the min
  EXPECT_EQ(read_ai(io, 100 * kMs, 15207, 13824), 13824);
  EXPECT_EQ(read_ai(io, 600 * kMs, 15207, 13824), 13824);
  ASSERT_EQ(io.events().size(), 1U);
  EXPECT_EQ(io.events()[0].module, 0);  // module_L holds the max (15207)
  EXPECT_TRUE(io.passivated(0, RedModule::L));
  EXPECT_FALSE(io.passivated(0, RedModule::H));
}

TEST(HRedundantIoAi, BackInsideTheWindowWithinTheTimeRaisesNothing) {
  RedundantIo io({ai_pair(AiAcceptedValue::Max)});
  EXPECT_EQ(read_ai(io, 0, 100, 100), 100);
  EXPECT_EQ(read_ai(io, 100 * kMs, 100, 5000), 100);
  EXPECT_EQ(read_ai(io, 599 * kMs, 100, 1482), 1482);  // 1382 apart: inside again
  EXPECT_EQ(read_ai(io, 2000 * kMs, 100, 1482), 1482);
  EXPECT_TRUE(io.events().empty());
}

// Overflow 7FFF (wire break of AI 8x12bit, 001 L6330) passivates that module at once.
TEST(HRedundantIoAi, OverflowPassivatesTheModuleAtOnce) {
  RedundantIo io({ai_pair(AiAcceptedValue::Max)});
  EXPECT_EQ(read_ai(io, 0, 0x7FFF, 13824), 13824);
  ASSERT_EQ(io.events().size(), 1U);
  EXPECT_EQ(io.events()[0].code, 0x7966);
  EXPECT_TRUE(io.passivated(0, RedModule::L));
  // Table 7-5 byte 1: bit 2 = 0 (overflow), bit 6 = 0 (module_L passivated): 1011 1011 = 0xBB.
  EXPECT_EQ(io.modul_status_word(0), 0xBBC0);
  EXPECT_EQ(read_ai(io, 10 * kMs, -0x8000, -0x8000), 0);  // module_H underflows too: both → 0
  EXPECT_TRUE(io.passivated(0, RedModule::H));
}

// --- DO / AO -------------------------------------------------------------------------------

RedIoPairSpec out_pair(RedIoKind k) {
  RedIoPairSpec s;
  s.kind = k;
  s.address_low = 0;  // QB 0.. / QB 8..
  s.address_high = 8;
  s.length = k == RedIoKind::DO ? 1 : 4;  // AO: two channels
  return s;
}

TEST(HRedundantIoOut, DoPairIsDrivenAlikeAndAPassivatedModuleGetsZero) {
  RedundantIo io({out_pair(RedIoKind::DO)});
  B piq(16, 0);
  piq[0] = 0xA5;
  piq[8] = 0x11;  // the program's bytes at the higher address have no meaning
  B out = io.red_out(piq);
  EXPECT_EQ(out[0], 0xA5);
  EXPECT_EQ(out[8], 0xA5);
  EXPECT_EQ(piq[0], 0xA5);  // the program's PIQ is not changed
  ASSERT_TRUE(io.module_fault(0, 0, RedModule::H, RedIoCause::Ob82, true));
  out = io.red_out(piq);
  EXPECT_EQ(out[0], 0xA5);
  EXPECT_EQ(out[8], 0x00);
  ASSERT_TRUE(io.module_fault(0, 0, RedModule::L, RedIoCause::Ob85, true));
  out = io.red_out(piq);
  EXPECT_EQ(out[0], 0x00);
  EXPECT_EQ(out[8], 0x00);
  EXPECT_EQ(io.find_pair(8, true), 0U);
  EXPECT_FALSE(io.find_pair(8, false).has_value());
  EXPECT_EQ(io.module_at(0, 8), RedModule::H);
}

// AO outputs in parallel add their currents: each drives half (decision). Halves by hand:
//   27648 → 13824 + 13824;  27647 → 13823 + 13824;  −3 → −1 + −2.
TEST(HRedundantIoOut, AoPairHalvesTheValueAndALoneModuleDrivesAll) {
  RedundantIo io({out_pair(RedIoKind::AO)});
  // Status byte, Table 7-4 bit 2: an AO pair exists.
  EXPECT_EQ(io.status_byte(), 0x04);
  B piq(16, 0);
  piq[0] = 0x6C;  // 27648
  piq[1] = 0x00;
  piq[2] = 0xFF;  // −3
  piq[3] = 0xFD;
  B out = io.red_out(piq);
  EXPECT_EQ((B{out[0], out[1], out[2], out[3]}), (B{0x36, 0x00, 0xFF, 0xFF}));    // 13824, −1
  EXPECT_EQ((B{out[8], out[9], out[10], out[11]}), (B{0x36, 0x00, 0xFF, 0xFE}));  // 13824, −2
  piq[0] = 0x6B;  // 27647
  piq[1] = 0xFF;
  out = io.red_out(piq);
  EXPECT_EQ((B{out[0], out[1]}), (B{0x35, 0xFF}));  // 13823
  EXPECT_EQ((B{out[8], out[9]}), (B{0x36, 0x00}));  // 13824
  ASSERT_TRUE(io.module_fault(0, 0, RedModule::L, RedIoCause::Ob82, true));
  out = io.red_out(piq);
  EXPECT_EQ((B{out[0], out[1], out[2], out[3]}), (B{0, 0, 0, 0}));
  EXPECT_EQ((B{out[8], out[9], out[10], out[11]}), (B{0x6B, 0xFF, 0xFF, 0xFD}));
}

// --- Depassivation (001 L6585-6603) --------------------------------------------------------

// Passivates module_H of the DI pair by the stuck-channel sequence (7960, then 7961).
void passivate_h(RedundantIo& io) {
  read_di(io, 0, 0, 0);
  read_di(io, 10 * kMs, 1, 0);
  read_di(io, 110 * kMs, 1, 0);
  read_di(io, 120 * kMs, 0, 0);
  ASSERT_TRUE(io.passivated(0, RedModule::H));
}

TEST(HRedundantIoDepassivation, EachTriggerDepassivatesAtTheNextRedIn) {
  for (DepassivationTrigger t :
       {DepassivationTrigger::Startup, DepassivationTrigger::Redundant,
        DepassivationTrigger::Modification, DepassivationTrigger::Fc451}) {
    SCOPED_TRACE(std::string(to_string(t)));
    RedundantIo io({di_pair()});
    passivate_h(io);
    const auto n = io.events().size();
    ASSERT_TRUE(io.request_depassivation(200 * kMs, t));
    EXPECT_TRUE(io.depassivation_pending());
    EXPECT_TRUE(io.passivated(0, RedModule::H));  // carried out in RED_IN, not at once
    EXPECT_EQ(read_di(io, 210 * kMs, 0x01, 0x01), 0x01);
    EXPECT_FALSE(io.depassivation_pending());
    EXPECT_FALSE(io.passivated(0, RedModule::H));
    ASSERT_EQ(io.events().size(), n + 1);
    EXPECT_EQ(io.events()[n].code, 0x7963);
    EXPECT_EQ(io.events()[n].time, 210 * kMs);
    EXPECT_EQ(io.events()[n].count, 1U);
    EXPECT_EQ(io.modul_status_word(0), 0xFFC0);
    // Both modules evaluated again: a new discrepancy is 7960 after 100 ms.
    EXPECT_EQ(read_di(io, 300 * kMs, 0x00, 0x01), 0x01);
    EXPECT_EQ(read_di(io, 400 * kMs, 0x00, 0x01), 0x01);
    EXPECT_EQ(io.events().back().code, 0x7960);
  }
}

TEST(HRedundantIoDepassivation, Fc451IsRefusedWithNothingPassivated) {
  RedundantIo io({di_pair()});
  EXPECT_FALSE(io.request_depassivation(0, DepassivationTrigger::Fc451));
  EXPECT_FALSE(io.depassivation_pending());
  // Start-up is always taken, but with nothing passivated writes no entry.
  EXPECT_TRUE(io.request_depassivation(0, DepassivationTrigger::Startup));
  read_di(io, 10 * kMs, 0, 0);
  EXPECT_TRUE(io.events().empty());
}

// A module passivated by OB 85 stays passivated while its fault is present; after the outgoing
// event the status word shows the depassivation enable (Table 7-5 byte 2 bit 2), and the next
// depassivation takes it back.
TEST(HRedundantIoDepassivation, APresentFaultKeepsTheModulePassivated) {
  RedundantIo io({di_pair()});
  read_di(io, 0, 0, 0);
  ASSERT_TRUE(io.module_fault(5 * kMs, 0, RedModule::L, RedIoCause::Ob85, true));
  // byte 1: bit 6 = 0 (L passivated) → 1011 1111 = 0xBF; byte 2: bit 6 = 0 (OB 85 passivated
  // L), bit 7 = 1 → 1000 0000 = 0x80.
  EXPECT_EQ(io.modul_status_word(0), 0xBF80);
  ASSERT_TRUE(io.request_depassivation(10 * kMs, DepassivationTrigger::Redundant));
  read_di(io, 20 * kMs, 0, 0);
  EXPECT_TRUE(io.passivated(0, RedModule::L));
  EXPECT_EQ(io.events().size(), 1U);  // only the 7965: nothing was depassivated
  ASSERT_TRUE(io.module_fault(30 * kMs, 0, RedModule::L, RedIoCause::Ob85, false));
  // byte 2 bit 2 = 1: depassivation of module_L enabled after the outgoing OB 85 → 0x84.
  EXPECT_EQ(io.modul_status_word(0), 0xBF84);
  ASSERT_TRUE(io.request_depassivation(40 * kMs, DepassivationTrigger::Fc451));
  read_di(io, 50 * kMs, 0, 0);
  EXPECT_FALSE(io.passivated(0, RedModule::L));
  EXPECT_EQ(io.events().back().code, 0x7963);
}

// --- Configuration and texts ----------------------------------------------------------------

TEST(HRedundantIoConfig, ValidateRejectsBadPairs) {
  auto ai = ai_pair(AiAcceptedValue::Max);
  ai.length = 3;
  EXPECT_NE(RedundantIo::validate({ai}).find("whole number of words"), std::string::npos);
  auto swapped = di_pair();
  swapped.address_low = 4;
  swapped.address_high = 0;
  EXPECT_NE(RedundantIo::validate({swapped}).find("lower address"), std::string::npos);
  auto wide = di_pair();
  wide.length = 5;  // IB 0..4 and IB 4..8 overlap
  EXPECT_NE(RedundantIo::validate({wide}).find("overlap"), std::string::npos);
  auto other = di_pair();
  other.address_low = 2;
  other.address_high = 3;  // IB 4 of the first pair is free, IB 2/3 too: fine
  EXPECT_EQ(RedundantIo::validate({di_pair(), other}), "");
  other.address_high = 4;
  EXPECT_NE(RedundantIo::validate({di_pair(), other}).find("overlaps pair 0"),
            std::string::npos);
  // Inputs and outputs are separate images: a DO at QB 0 / QB 4 is fine next to the DI.
  auto dq = di_pair();
  dq.kind = RedIoKind::DO;
  EXPECT_EQ(RedundantIo::validate({di_pair(), dq}), "");
  EXPECT_THROW({ RedundantIo bad({wide}); }, std::invalid_argument);
}

TEST(HRedundantIoConfig, EventTexts) {
  RedIoEvent e;
  e.code = 0x7960;
  e.kind = RedIoKind::DI;
  e.address = 0;
  e.bit = 9;
  EXPECT_EQ(describe(e),
            "W#16#7960 redundant DI pair 0: discrepancy time at digital input expired, error "
            "not yet localized (IB 1 bit 1)");
  e.code = 0x7961;
  e.module = 1;
  e.address = 4;
  e.bit = 0;
  EXPECT_EQ(describe(e), "W#16#7961 redundant DI pair 0: module_H (IB 4) passivated: no signal "
                         "change (bit 0)");
  e.code = 0x7963;
  e.count = 2;
  EXPECT_EQ(describe(e),
            "W#16#7963 redundant I/O: depassivation completed, 2 module(s) depassivated");
}

}  // namespace
}  // namespace pbvbus::devices
