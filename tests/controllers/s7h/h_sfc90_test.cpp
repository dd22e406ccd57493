// SFC 90 H_CTRL (h_sfc90.hpp, the pair's blocks in h_cpu_pair_sfc90.cpp) and F5's second part
// (docs/h-sfc90.md). Times are the pair's defaults worked out by hand:
//   STARTUP 1 s, LINK-UP 2 s, UPDATE W = 75 ms + 0.7 ms x 100 KB = 145 ms (digest §3.1, T7).
// CPU 0 powered at 0 → RUN (Solo) at 1 s; CPU 1 powered at 5 s → LINK-UP 5 s .. 7 s →
// UPDATE 7 s .. 7.145 s → Redundant.
#include "pbvbus/s7h/h_sfc90.hpp"

#include <gtest/gtest.h>

#include <string>

#include "pbvbus/s7h/h_cpu_pair.hpp"

namespace pbvbus::devices {
namespace {

using bus::Ticks;
constexpr Ticks ms(std::int64_t v) { return v * bus::kTicksPerMs; }
constexpr Ticks sec(std::int64_t v) { return v * bus::kTicksPerSecond; }
constexpr Ticks kW = ms(75) + 100 * (ms(7) / 10);  // 145 ms
static_assert(kW == ms(145));

bool has_entry(const HCpuPair& p, int r, const std::string& text) {
  for (const DiagEntry& e : p.diag_buffer(r))
    if (e.text.find(text) != std::string::npos) return true;
  return false;
}

// ---- decoding: MODE/SUBMODE → job or RET_VAL (h_sfc90.hpp's table) ----

TEST(HSfc90, DecodeModesAndSubmodes) {
  EXPECT_EQ(decode_h_ctrl(0, 0).job, HCtrlJob::DisableLinkUp);
  EXPECT_EQ(decode_h_ctrl(1, 0).job, HCtrlJob::EnableLinkUp);
  EXPECT_EQ(decode_h_ctrl(3, 0).job, HCtrlJob::DisableUpdate);
  EXPECT_EQ(decode_h_ctrl(4, 0).job, HCtrlJob::EnableUpdate);
  EXPECT_EQ(decode_h_ctrl(10, 0).job, HCtrlJob::RemoveTest);
  EXPECT_EQ(decode_h_ctrl(11, 4).job, HCtrlJob::AddTest);
  EXPECT_EQ(decode_h_ctrl(12, 2).component, 2);
  EXPECT_EQ(decode_h_ctrl(12, 0xFF).component, -1);  // FF: every component
  // W#16#8090: no such MODE (2, 5..9, 13 and up are not jobs of this table).
  for (const int mi : {2, 5, 9, 13, 255}) {
    const auto m = static_cast<std::uint8_t>(mi);
    const HCtrlDecoded d = decode_h_ctrl(m, 0);
    EXPECT_EQ(d.job, HCtrlJob::None) << int(m);
    EXPECT_EQ(d.ret_val, 0x8090) << int(m);
  }
  // W#16#8091: SUBMODE not 0 for MODE 0..4; not 0..4 or FF for MODE 10..12.
  EXPECT_EQ(decode_h_ctrl(3, 1).ret_val, 0x8091);
  EXPECT_EQ(decode_h_ctrl(0, 0xFF).ret_val, 0x8091);
  EXPECT_EQ(decode_h_ctrl(10, 5).ret_val, 0x8091);
  EXPECT_EQ(decode_h_ctrl(12, 0xFE).ret_val, 0x8091);
}

TEST(HSfc90, SelfTestComponentsRemovedAddedStarted) {
  HCpuPair p;
  HSelfTestControl st;
  EXPECT_TRUE(st.included(SelfTestComponent::Ram));
  EXPECT_EQ(h_ctrl(p, st, 10, 0, 0), 0x0000);  // remove the RAM test
  EXPECT_FALSE(st.included(SelfTestComponent::Ram));
  EXPECT_TRUE(st.included(SelfTestComponent::Alu));
  EXPECT_EQ(h_ctrl(p, st, 10, 0, 0), 0x0001);  // already removed
  EXPECT_EQ(h_ctrl(p, st, 11, 0xFF, 0), 0x0000);  // every component back
  EXPECT_TRUE(st.included(SelfTestComponent::Ram));
  EXPECT_EQ(h_ctrl(p, st, 11, 0xFF, 0), 0x0001);
  EXPECT_EQ(h_ctrl(p, st, 12, 2, 0), 0x0000);  // start the OS checksum test once
  EXPECT_EQ(st.started(SelfTestComponent::OsChecksum), 1);
  EXPECT_EQ(st.started(SelfTestComponent::Ram), 0);
  EXPECT_EQ(h_ctrl(p, st, 7, 0, 0), 0x8090);
}

TEST(HSfc90, NotOnThe1500Profile) {
  HCpuPairParams pp;
  pp.profile = HProfile::S7_1500RH;
  HCpuPair p(pp);
  HSelfTestControl st;
  EXPECT_EQ(h_ctrl(p, st, 3, 0, 0), 0x80C1);
  EXPECT_TRUE(p.update_enabled());
  EXPECT_EQ(h_ctrl(p, st, 2, 0, 0), 0x8090);  // a bad MODE is still 8090
}

// ---- link-up blocked (MODE 0) and re-enabled (MODE 1) ----

TEST(HSfc90, LinkUpDisabledStandbyRequestWaitsUntilReEnabled) {
  HCpuPair p;
  HSelfTestControl st;
  p.power_on(0, 0);
  p.on_time(sec(1));  // Solo
  EXPECT_EQ(h_ctrl(p, st, 0, 0, sec(2)), 0x0000);
  EXPECT_EQ(h_ctrl(p, st, 0, 0, sec(2)), 0x0001);  // already disabled
  EXPECT_FALSE(p.link_up_enabled());
  p.power_on(1, sec(5));  // switch at RUN: a start request
  p.on_time(sec(7));
  EXPECT_EQ(p.state(1), CpuState::Stop);
  EXPECT_EQ(p.role(1), CpuRole::Standby);
  EXPECT_EQ(p.system_mode(), SystemMode::Solo);
  EXPECT_TRUE(has_entry(p, 1, "link-up request waits: link-up disabled (SFC 90)"));
  // MODE 1 at 8 s: LINK-UP 8 s .. 10 s, UPDATE 10 s .. 10.145 s, Redundant.
  EXPECT_EQ(h_ctrl(p, st, 1, 0, sec(8)), 0x0000);
  EXPECT_EQ(p.state(1), CpuState::LinkUp);
  p.on_time(sec(10));
  EXPECT_EQ(p.state(1), CpuState::Update);
  p.on_time(sec(10) + kW);
  EXPECT_EQ(p.system_mode(), SystemMode::Redundant);
  EXPECT_EQ(p.update_window()->t1, sec(10));
  EXPECT_EQ(h_ctrl(p, st, 1, 0, sec(11)), 0x0001);
}

TEST(HSfc90, LinkUpDisabledRefusesTheOperatorSwap) {
  HCpuPair p;
  HSelfTestControl st;
  p.power_on(0, 0);
  p.on_time(sec(1));
  p.switch_to_stop(1, sec(1));
  p.power_on(1, sec(2));  // standby in STOP (switch at STOP)
  EXPECT_EQ(h_ctrl(p, st, 0, 0, sec(3)), 0x0000);
  EXPECT_FALSE(p.request_master_swap(sec(4)));
  EXPECT_EQ(p.state(1), CpuState::Stop);
  EXPECT_TRUE(has_entry(p, 0, "master swap refused: link-up disabled (SFC 90)"));
  EXPECT_EQ(h_ctrl(p, st, 1, 0, sec(5)), 0x0000);
  EXPECT_TRUE(p.request_master_swap(sec(6)));
  EXPECT_EQ(p.state(1), CpuState::LinkUp);
}

// ---- update blocked (MODE 3) and re-enabled (MODE 4) ----

TEST(HSfc90, UpdateDisabledStandbyWaitsInLinkUpThenUpdates) {
  HCpuPair p;
  HSelfTestControl st;
  p.power_on(0, 0);
  p.on_time(sec(1));
  EXPECT_EQ(h_ctrl(p, st, 3, 0, sec(2)), 0x0000);
  p.power_on(1, sec(5));
  EXPECT_EQ(p.state(1), CpuState::LinkUp);
  // The link-up is done at 7 s; the update waits: LINK-UP, system mode Link-up, no t1.
  p.on_time(sec(7));
  EXPECT_EQ(p.state(1), CpuState::LinkUp);
  EXPECT_TRUE(p.update_waiting());
  EXPECT_EQ(p.system_mode(), SystemMode::LinkUp);
  EXPECT_FALSE(p.update_window().has_value());
  EXPECT_FALSE(p.interrupts_held());
  EXPECT_EQ(p.next_deadline(), bus::kNever);
  EXPECT_TRUE(has_entry(p, 0, "link-up done: update disabled (SFC 90), waiting"));
  p.on_time(sec(60));  // waits as long as it takes: no timeout while no update runs
  EXPECT_EQ(p.state(1), CpuState::LinkUp);
  // MODE 4 at 60 s: t1 = 60 s, t5 = 60.145 s.
  EXPECT_EQ(h_ctrl(p, st, 4, 0, sec(60)), 0x0000);
  EXPECT_EQ(p.state(1), CpuState::Update);
  EXPECT_FALSE(p.update_waiting());
  ASSERT_TRUE(p.update_window().has_value());
  EXPECT_EQ(p.update_window()->t1, sec(60));
  EXPECT_EQ(p.update_window()->t5, sec(60) + kW);
  p.on_time(sec(60) + kW);
  EXPECT_EQ(p.system_mode(), SystemMode::Redundant);
  EXPECT_EQ(h_ctrl(p, st, 4, 0, sec(61)), 0x0001);
}

TEST(HSfc90, UpdateWaitEndsWithTheLinkUpAbort) {
  HCpuPair p;
  HSelfTestControl st;
  p.power_on(0, 0);
  p.on_time(sec(1));
  h_ctrl(p, st, 3, 0, sec(2));
  p.power_on(1, sec(5));
  p.on_time(sec(7));
  ASSERT_TRUE(p.update_waiting());
  p.switch_to_stop(1, sec(8));  // the waiting standby stopped: link-up over
  EXPECT_FALSE(p.update_waiting());
  EXPECT_EQ(p.system_mode(), SystemMode::Solo);
  h_ctrl(p, st, 4, 0, sec(9));  // nothing waits: no update
  EXPECT_EQ(p.state(1), CpuState::Stop);
  EXPECT_FALSE(p.update_window().has_value());
}

// ---- F5, second part (000 L2594-2597) ----

TEST(HSfc90, F5SecondLinkFailingLaterStandbyRequestsAReset) {
  HCpuPair p;
  p.power_on(0, 0);
  p.on_time(sec(1));
  p.power_on(1, sec(5));
  p.on_time(sec(7) + kW);
  ASSERT_EQ(p.system_mode(), SystemMode::Redundant);
  p.cut_fibre(0, sec(10));  // F5: the standby STOPs, no reset request
  EXPECT_EQ(p.state(1), CpuState::Stop);
  EXPECT_FALSE(p.reset_request(1));
  p.cut_fibre(1, sec(20));  // the second link later: the standby requests a reset
  EXPECT_TRUE(p.reset_request(1));
  EXPECT_FALSE(p.reset_request(0));
  EXPECT_EQ(p.state(0), CpuState::Run);
  EXPECT_TRUE(has_entry(p, 1, "reset request: second sync link failed"));
  // Repaired: STOP -> RUN is refused until MRES (rule 20), then it links up.
  p.repair_fibre(0, sec(30));
  p.repair_fibre(1, sec(30));
  p.switch_to_run(1, sec(31));
  EXPECT_EQ(p.state(1), CpuState::Stop);
  EXPECT_TRUE(p.memory_reset(1, sec(32)));
  p.switch_to_run(1, sec(33));
  EXPECT_EQ(p.state(1), CpuState::LinkUp);
}

TEST(HSfc90, F6BothFibresAtOnceGivesNoResetRequest) {
  HCpuPair p;
  p.power_on(0, 0);
  p.on_time(sec(1));
  p.power_on(1, sec(5));
  p.on_time(sec(7) + kW);
  p.cut_both_fibres(sec(10));
  EXPECT_EQ(p.master_count(), 2);
  EXPECT_FALSE(p.reset_request(0));
  EXPECT_FALSE(p.reset_request(1));
}

}  // namespace
}  // namespace pbvbus::devices
