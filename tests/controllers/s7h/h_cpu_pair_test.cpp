// HCpuPair (devices/h_cpu_pair.hpp): the S7-400H CPU pair's states, roles, system modes, OB 72,
// diagnostic buffer and LEDs (seeds-digest.md §1, §4, §6, §7, §11 R1-R5, R10;
// docs/h-system.md).
// Every time below is written as the arithmetic of the default parameters:
//   STARTUP 1 s, LINK-UP 2 s, UPDATE 75 ms + 0.7 ms x 100 KB = 145 ms, role window 3 s,
//   self-test (ERROR-SEARCH) 90 s, F17 window 7 days.
#include "pbvbus/s7h/h_cpu_pair.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <random>
#include <string>
#include <vector>

namespace pbvbus::devices {
namespace {

using bus::Ticks;
constexpr Ticks ms(std::int64_t v) {
  return v * bus::kTicksPerMs;
}
constexpr Ticks sec(std::int64_t v) {
  return v * bus::kTicksPerSecond;
}
constexpr Ticks kStartup = sec(1);
constexpr Ticks kLinkUp = sec(2);
constexpr Ticks kUpdate = ms(75) + 100 * (ms(7) / 10);  // 145 ms
static_assert(kUpdate == ms(145));
constexpr Ticks kSelfTest = sec(90);
constexpr Us ms_us(std::int64_t v) {
  return v * kUsPerMs;
}
constexpr Ticks kDay = sec(24 * 3600);

// Power-on CPU0 at 0 and CPU1 at 5 s; Redundant at 5 s + 2 s + 145 ms = 7.145 s.
constexpr Ticks kCpu1On = sec(5);
constexpr Ticks kRedundantAt = kCpu1On + kLinkUp + kUpdate;

void bring_up(HCpuPair& p) {
  p.power_on(0, 0);
  p.on_time(kStartup);
  p.power_on(1, kCpu1On);
  p.on_time(kCpu1On + kLinkUp);
  p.on_time(kRedundantAt);
  ASSERT_EQ(p.system_mode(), SystemMode::Redundant);
}

std::vector<HEvent> obs(const HCpuPair& p, int nr) {
  std::vector<HEvent> v;
  for (const HEvent& e : p.events())
    if (e.kind == HEvent::Kind::Ob && e.ob == nr) v.push_back(e);
  return v;
}

std::vector<std::pair<Ticks, SystemMode>> modes(const HCpuPair& p) {
  std::vector<std::pair<Ticks, SystemMode>> v;
  for (const HEvent& e : p.events())
    if (e.kind == HEvent::Kind::SystemMode) v.emplace_back(e.at, e.to_mode);
  return v;
}

bool has_diag(const HCpuPair& p, int r, Ticks at, const std::string& text) {
  return std::any_of(p.diag_buffer(r).begin(), p.diag_buffer(r).end(), [&](const DiagEntry& d) {
    return d.at == at && d.text.find(text) != std::string::npos;
  });
}

TEST(HCpuPair, R1PowerOnCpu0ThenCpu1FullSequence) {
  HCpuPair p;
  EXPECT_EQ(p.update_time(), kUpdate);
  // t = 0: CPU 0 powers on alone (first ever): master, switch at RUN -> STARTUP at once.
  p.power_on(0, 0);
  EXPECT_EQ(p.state(0), CpuState::Startup);
  EXPECT_EQ(p.role(0), CpuRole::Master);
  EXPECT_EQ(p.state(1), CpuState::Off);
  EXPECT_EQ(p.system_mode(), SystemMode::Startup);
  EXPECT_EQ(p.leds(0).redf, Redf::On);
  EXPECT_TRUE(p.leds(0).mstr);
  EXPECT_TRUE(p.leds(0).rack0);
  EXPECT_FALSE(p.leds(0).rack1);
  EXPECT_TRUE(p.leds(0).ifm1f);  // no partner on the fibres
  EXPECT_TRUE(p.leds(0).ifm2f);
  EXPECT_EQ(p.leds(1).redf, Redf::Off);  // off CPU: all dark
  EXPECT_FALSE(p.leds(1).rack1);
  EXPECT_EQ(p.next_deadline(), kStartup);  // 0 + 1 s
  p.on_time(kStartup - 1);
  EXPECT_EQ(p.state(0), CpuState::Startup);
  // t = 1 s: STARTUP done -> RUN, Solo.
  p.on_time(kStartup);
  EXPECT_EQ(p.state(0), CpuState::Run);
  EXPECT_EQ(p.system_mode(), SystemMode::Solo);
  EXPECT_EQ(p.leds(0).redf, Redf::On);
  EXPECT_TRUE(p.dp_master_operate(0));
  // t = 5 s: CPU 1 powers on: standby, LINK-UP at once (master in Solo RUN). REDF 0.5 Hz.
  p.power_on(1, kCpu1On);
  EXPECT_EQ(p.role(1), CpuRole::Standby);
  EXPECT_EQ(p.state(1), CpuState::LinkUp);
  EXPECT_EQ(p.state(0), CpuState::Run);
  EXPECT_EQ(p.system_mode(), SystemMode::LinkUp);
  EXPECT_EQ(p.leds(0).redf, Redf::Flash0_5Hz);
  EXPECT_EQ(p.leds(1).redf, Redf::Flash0_5Hz);
  EXPECT_FALSE(p.leds(1).mstr);
  EXPECT_TRUE(p.leds(1).rack1);
  EXPECT_FALSE(p.leds(1).ifm1f);
  EXPECT_FALSE(p.dp_master_running(1));
  EXPECT_EQ(p.next_deadline(), kCpu1On + kLinkUp);  // 5 s + 2 s = 7 s
  // t = 7 s: UPDATE, REDF 2 Hz.
  p.on_time(kCpu1On + kLinkUp);
  EXPECT_EQ(p.state(1), CpuState::Update);
  EXPECT_EQ(p.system_mode(), SystemMode::Update);
  EXPECT_EQ(p.leds(0).redf, Redf::Flash2Hz);
  EXPECT_EQ(p.leds(1).redf, Redf::Flash2Hz);
  EXPECT_TRUE(p.dp_master_running(1));
  EXPECT_EQ(p.next_deadline(), kRedundantAt);  // 7 s + 145 ms
  p.on_time(kRedundantAt - 1);
  EXPECT_EQ(p.state(1), CpuState::Update);
  // t = 7.145 s: Redundant, both RUN, REDF off.
  p.on_time(kRedundantAt);
  EXPECT_EQ(p.state(0), CpuState::Run);
  EXPECT_EQ(p.state(1), CpuState::Run);
  EXPECT_EQ(p.system_mode(), SystemMode::Redundant);
  EXPECT_EQ(p.leds(0).redf, Redf::Off);
  EXPECT_EQ(p.leds(1).redf, Redf::Off);
  EXPECT_TRUE(p.accesses_switched_io(0));
  EXPECT_FALSE(p.accesses_switched_io(1));
  EXPECT_EQ(p.next_deadline(), bus::kNever);

  const std::vector<std::pair<Ticks, SystemMode>> want = {{0, SystemMode::Startup},
                                                          {kStartup, SystemMode::Solo},
                                                          {kCpu1On, SystemMode::LinkUp},
                                                          {kCpu1On + kLinkUp, SystemMode::Update},
                                                          {kRedundantAt, SystemMode::Redundant}};
  EXPECT_EQ(modes(p), want);
  // STARTUP ran on the master only.
  for (const HEvent& e : p.events()) {
    if (e.kind == HEvent::Kind::State && e.to_state == CpuState::Startup) {
      EXPECT_EQ(e.rack, 0);
    }
  }
  EXPECT_TRUE(has_diag(p, 1, kCpu1On + kLinkUp, "LINK-UP -> UPDATE"));
  EXPECT_TRUE(obs(p, 72).empty());
}

TEST(HCpuPair, R2StandbyStartedLessThan3sBeforeKeepsRoles) {
  HCpuPair p;
  bring_up(p);
  p.power_off(1, sec(10));  // standby first, so the remembered roles stay 0 master / 1 standby
  p.power_off(0, sec(10));
  // CPU 1 (remembered standby) at 20 s: waits for its master until 20 s + 3 s.
  p.power_on(1, sec(20));
  EXPECT_EQ(p.role(1), CpuRole::None);
  EXPECT_EQ(p.next_deadline(), sec(23));
  // CPU 0 at 20 s + 2.999 s < 23 s: the assignment stays.
  p.power_on(0, sec(20) + ms(2999));
  EXPECT_EQ(p.role(0), CpuRole::Master);
  EXPECT_EQ(p.role(1), CpuRole::Standby);
  EXPECT_EQ(p.state(0), CpuState::Startup);  // it was in RUN when it lost power
  p.on_time(sec(20) + ms(2999) + kStartup);  // 23.999 s: RUN, CPU 1 links up
  EXPECT_EQ(p.state(1), CpuState::LinkUp);
}

TEST(HCpuPair, R2StandbyStarted3sBeforeSwapsRoles) {
  HCpuPair p;
  bring_up(p);
  p.power_off(1, sec(10));
  p.power_off(0, sec(10));
  p.power_on(1, sec(20));
  // CPU 0 at exactly 20 s + 3 s: the window is over, CPU 1 became master at 23 s.
  p.power_on(0, sec(23));
  EXPECT_EQ(p.role(1), CpuRole::Master);
  EXPECT_EQ(p.role(0), CpuRole::Standby);
  EXPECT_EQ(p.state(1), CpuState::Startup);
  EXPECT_EQ(p.state(0), CpuState::Stop);
  bool role_event = false;
  for (const HEvent& e : p.events())
    if (e.kind == HEvent::Kind::Role && e.rack == 1 && e.role == CpuRole::Master) {
      EXPECT_EQ(e.at, sec(23));
      role_event = true;
    }
  EXPECT_TRUE(role_event);
  p.on_time(sec(23) + kStartup);  // 24 s: CPU 1 in RUN, CPU 0 links up as standby
  EXPECT_EQ(p.state(0), CpuState::LinkUp);
  p.on_time(sec(24) + kLinkUp + kUpdate);  // 24 s + 2 s + 145 ms
  EXPECT_EQ(p.system_mode(), SystemMode::Redundant);
  EXPECT_EQ(p.master(), 1);
}

TEST(HCpuPair, R2SimultaneousPowerOnKeepsAssignment) {
  // Remembered 0 master / 1 standby; both at the same instant, CPU 1's call first.
  HCpuPair p;
  bring_up(p);
  p.power_off(1, sec(10));
  p.power_off(0, sec(10));
  p.power_on(1, sec(20));
  p.power_on(0, sec(20));
  EXPECT_EQ(p.master(), 0);
  EXPECT_EQ(p.role(1), CpuRole::Standby);
  // First-ever simultaneous power-on: rack 0 master.
  HCpuPair q;
  q.power_on_both(0);
  EXPECT_EQ(q.master(), 0);
  EXPECT_EQ(q.role(1), CpuRole::Standby);
  // First-ever, CPU 1 first: the first to start is master.
  HCpuPair r;
  r.power_on(1, 0);
  r.power_on(0, ms(500));
  EXPECT_EQ(r.master(), 1);
  EXPECT_EQ(r.role(0), CpuRole::Standby);
}

TEST(HCpuPair, R3OneFibreCutStandbyStops) {
  HCpuPair p;
  bring_up(p);
  p.cut_fibre(0, sec(10));
  EXPECT_EQ(p.state(0), CpuState::Run);
  EXPECT_EQ(p.state(1), CpuState::Stop);
  EXPECT_EQ(p.role(1), CpuRole::Standby);
  EXPECT_EQ(p.system_mode(), SystemMode::Solo);
  const auto o = obs(p, 72);
  ASSERT_EQ(o.size(), 1u);
  EXPECT_EQ(o[0].at, sec(10));
  EXPECT_EQ(o[0].rack, 0);
  EXPECT_EQ(o[0].role, CpuRole::Master);
  EXPECT_EQ(o[0].reason, HReason::LinkLost);
  for (int r = 0; r < 2; ++r) {
    EXPECT_EQ(p.leds(r).redf, Redf::On);
    EXPECT_TRUE(p.leds(r).ifm1f);
    EXPECT_FALSE(p.leds(r).ifm2f);
  }
  // Repair: no link-up by itself; the standby needs STOP -> RUN.
  p.repair_fibre(0, sec(11));
  EXPECT_EQ(p.state(1), CpuState::Stop);
  p.switch_to_run(1, sec(12));
  EXPECT_EQ(p.state(1), CpuState::LinkUp);
  p.on_time(sec(12) + kLinkUp + kUpdate);  // 14.145 s
  EXPECT_EQ(p.system_mode(), SystemMode::Redundant);
}

TEST(HCpuPair, R3BothFibresAtOnceTwoMasters) {
  HCpuPair p;
  bring_up(p);
  p.cut_both_fibres(sec(10));
  EXPECT_EQ(p.master_count(), 2);
  EXPECT_EQ(p.state(0), CpuState::Run);
  EXPECT_EQ(p.state(1), CpuState::Run);
  EXPECT_TRUE(p.accesses_switched_io(0));
  EXPECT_TRUE(p.accesses_switched_io(1));
  EXPECT_EQ(p.system_mode(0), SystemMode::Solo);
  EXPECT_EQ(p.system_mode(1), SystemMode::Solo);
  const auto o = obs(p, 72);
  ASSERT_EQ(o.size(), 2u);
  for (const HEvent& e : o) {
    EXPECT_EQ(e.at, sec(10));
    EXPECT_EQ(e.role, CpuRole::Master);
    EXPECT_EQ(e.reason, HReason::LinkLost);
  }
  EXPECT_NE(o[0].rack, o[1].rack);
  for (int r = 0; r < 2; ++r) {
    EXPECT_TRUE(p.leds(r).mstr);
    EXPECT_TRUE(p.leds(r).ifm1f);
    EXPECT_TRUE(p.leds(r).ifm2f);
  }
  // Split ends when one master is switched to STOP over a repaired link.
  p.repair_fibre(0, sec(20));
  p.repair_fibre(1, sec(20));
  p.switch_to_stop(1, sec(21));
  EXPECT_EQ(p.role(1), CpuRole::Standby);
  EXPECT_EQ(p.master_count(), 1);
}

TEST(HCpuPair, F7FibresMissingAtPowerOnBothRunAsMaster) {
  HCpuPair p;
  p.cut_both_fibres(0);
  p.power_on_both(0);
  EXPECT_EQ(p.master_count(), 2);
  p.on_time(kStartup);
  EXPECT_EQ(p.state(0), CpuState::Run);
  EXPECT_EQ(p.state(1), CpuState::Run);
  EXPECT_TRUE(obs(p, 72).empty());  // nothing was lost: no OB 72
}

TEST(HCpuPair, R4HoldBlocksLinkUp) {
  HCpuPairParams prm;
  prm.switch_run = {true, false};
  HCpuPair p(prm);
  p.power_on_both(0);
  p.on_time(kStartup);
  ASSERT_EQ(p.system_mode(), SystemMode::Solo);
  EXPECT_TRUE(p.hold(0, sec(2)));
  EXPECT_EQ(p.state(0), CpuState::Hold);
  EXPECT_EQ(p.system_mode(), SystemMode::Hold);
  p.switch_to_run(1, sec(3));
  EXPECT_EQ(p.state(1), CpuState::Stop);
  EXPECT_TRUE(has_diag(p, 1, sec(3), "link-up not possible: master CPU in HOLD"));
  EXPECT_TRUE(p.release_hold(0, sec(4)));
  EXPECT_EQ(p.system_mode(), SystemMode::Solo);
  EXPECT_EQ(p.state(1), CpuState::Stop);  // the refused request is gone
  p.switch_to_run(1, sec(5));
  EXPECT_EQ(p.state(1), CpuState::LinkUp);
  EXPECT_FALSE(p.hold(0, sec(6)));  // not from Link-up
  p.on_time(sec(5) + kLinkUp + kUpdate);
  EXPECT_FALSE(p.hold(0, sec(8)));  // not in Redundant
  EXPECT_FALSE(p.hold(1, sec(8)));  // not the standby
}

TEST(HCpuPair, HoldDuringStartupPausesIt) {
  HCpuPair p;
  p.power_on(0, 0);
  EXPECT_TRUE(p.hold(0, ms(400)));
  EXPECT_EQ(p.next_deadline(), bus::kNever);
  p.release_hold(0, sec(2));
  // 600 ms of STARTUP left: RUN at 2 s + (1 s - 400 ms) = 2.6 s.
  EXPECT_EQ(p.next_deadline(), sec(2) + kStartup - ms(400));
  p.on_time(ms(2600));
  EXPECT_EQ(p.state(0), CpuState::Run);
}

TEST(HCpuPair, R5F16ComparisonErrorSearchFindsNothingRelinksAndSwaps) {
  HCpuPair p;
  bring_up(p);
  EXPECT_TRUE(p.inject_comparison_error(sec(10)));
  EXPECT_EQ(p.state(1), CpuState::ErrorSearch);
  EXPECT_EQ(p.state(0), CpuState::Run);
  EXPECT_EQ(p.system_mode(), SystemMode::Solo);
  EXPECT_EQ(p.leds(1).redf, Redf::On);
  EXPECT_FALSE(p.dp_master_running(1));
  auto o = obs(p, 72);
  ASSERT_EQ(o.size(), 1u);
  EXPECT_EQ(o[0].rack, 0);
  EXPECT_EQ(o[0].at, sec(10));
  EXPECT_EQ(o[0].reason, HReason::ComparisonError);
  EXPECT_EQ(p.next_deadline(), sec(10) + kSelfTest);  // 100 s
  // 100 s: no fault found -> LINK-UP, 102 s UPDATE, 102.145 s Redundant with roles swapped.
  p.on_time(sec(100));
  EXPECT_EQ(p.state(1), CpuState::LinkUp);
  EXPECT_TRUE(has_diag(p, 1, sec(100), "self-test: no fault found"));
  const Ticks back = sec(100) + kLinkUp + kUpdate;
  p.on_time(back);
  EXPECT_EQ(p.system_mode(), SystemMode::Redundant);
  EXPECT_EQ(p.master(), 1);
  EXPECT_EQ(p.role(0), CpuRole::Standby);
  o = obs(p, 72);
  ASSERT_EQ(o.size(), 3u);
  for (int i = 1; i < 3; ++i) {
    EXPECT_EQ(o[i].at, back);
    EXPECT_EQ(o[i].reason, HReason::MasterSwap);
  }
  // Again within the first cyclic self-test period (90 min): the standby (now CPU 0) STOPs.
  EXPECT_TRUE(p.inject_comparison_error(back + sec(60)));
  EXPECT_EQ(p.state(0), CpuState::Stop);
  EXPECT_EQ(p.system_mode(), SystemMode::Solo);
}

TEST(HCpuPair, F16FaultFoundGoesDefective) {
  HCpuPair p;
  bring_up(p);
  p.inject_hardware_fault(1, sec(9));
  p.inject_comparison_error(sec(10));
  p.on_time(sec(100));
  EXPECT_EQ(p.state(1), CpuState::Defective);
  EXPECT_EQ(p.system_mode(), SystemMode::Solo);
  // A power cycle does not cure it.
  p.power_off(1, sec(110));
  p.power_on(1, sec(120));
  EXPECT_EQ(p.state(1), CpuState::Defective);
  p.repair_cpu(1, sec(130));
  EXPECT_EQ(p.state(1), CpuState::Stop);
}

TEST(HCpuPair, F16ConfiguredStopReaction) {
  HCpuPairParams prm;
  prm.comparison_reaction = ComparisonReaction::Stop;
  HCpuPair p(prm);
  bring_up(p);
  EXPECT_TRUE(p.inject_comparison_error(sec(10)));
  EXPECT_EQ(p.state(1), CpuState::Stop);
  EXPECT_FALSE(p.inject_comparison_error(sec(11)));  // only in Redundant mode
}

TEST(HCpuPair, F1MasterPowerOffStandbyTakesOverAndReturnLinksUp) {
  HCpuPair p;
  bring_up(p);
  p.power_off(0, sec(10));
  EXPECT_EQ(p.master(), 1);
  EXPECT_EQ(p.state(1), CpuState::Run);
  EXPECT_EQ(p.system_mode(), SystemMode::Solo);
  const auto o = obs(p, 72);
  ASSERT_EQ(o.size(), 1u);
  EXPECT_EQ(o[0].at, sec(10));
  EXPECT_EQ(o[0].rack, 1);
  EXPECT_EQ(o[0].role, CpuRole::Master);
  EXPECT_EQ(o[0].reason, HReason::MasterLost);
  const CpuLeds l = p.leds(1);
  EXPECT_TRUE(l.mstr);
  EXPECT_EQ(l.redf, Redf::On);
  EXPECT_TRUE(l.ifm1f);
  EXPECT_TRUE(l.ifm2f);
  // Return at 20 s: standby, link-up 20..22 s, update until 22.145 s.
  p.power_on(0, sec(20));
  EXPECT_EQ(p.role(0), CpuRole::Standby);
  EXPECT_EQ(p.state(0), CpuState::LinkUp);
  p.on_time(sec(20) + kLinkUp);
  EXPECT_EQ(p.state(0), CpuState::Update);
  p.on_time(sec(20) + kLinkUp + kUpdate);
  EXPECT_EQ(p.system_mode(), SystemMode::Redundant);
  EXPECT_EQ(p.master(), 1);
}

TEST(HCpuPair, MasterStopInRedundantStandbyTakesOver) {
  HCpuPair p;
  bring_up(p);
  p.switch_to_stop(0, sec(10));
  EXPECT_EQ(p.master(), 1);
  EXPECT_EQ(p.role(0), CpuRole::Standby);
  EXPECT_EQ(p.state(0), CpuState::Stop);
  const auto o = obs(p, 72);
  ASSERT_EQ(o.size(), 1u);
  EXPECT_EQ(o[0].reason, HReason::MasterStop);
  EXPECT_EQ(o[0].rack, 1);
  p.switch_to_run(0, sec(11));
  EXPECT_EQ(p.state(0), CpuState::LinkUp);
}

TEST(HCpuPair, F17OneSidedOb121ErrorSearchThenDefectiveWithin7Days) {
  HCpuPair p;
  bring_up(p);
  // On the master: OB 121 on CPU 0 only, CPU 0 -> ERROR-SEARCH, CPU 1 master (OB 72).
  EXPECT_TRUE(p.one_sided_ob121(0, sec(10)));
  EXPECT_EQ(p.state(0), CpuState::ErrorSearch);
  EXPECT_EQ(p.master(), 1);
  EXPECT_EQ(p.system_mode(), SystemMode::Solo);
  ASSERT_EQ(obs(p, 121).size(), 1u);
  EXPECT_EQ(obs(p, 121)[0].rack, 0);
  auto o = obs(p, 72);
  ASSERT_EQ(o.size(), 1u);
  EXPECT_EQ(o[0].rack, 1);
  EXPECT_EQ(o[0].reason, HReason::OneSidedOb121);
  // 10 s + 90 s: nothing found; re-link and automatic swap at 100 s + 2 s + 145 ms.
  p.on_time(sec(10) + kSelfTest + kLinkUp + kUpdate);
  EXPECT_EQ(p.system_mode(), SystemMode::Redundant);
  EXPECT_EQ(p.master(), 0);
  // Again on CPU 0 exactly 7 days after the first (inclusive): DEFECTIVE.
  EXPECT_TRUE(p.one_sided_ob121(0, sec(10) + 7 * kDay));
  EXPECT_EQ(p.state(0), CpuState::Defective);
  EXPECT_EQ(p.master(), 1);
  EXPECT_EQ(p.system_mode(), SystemMode::Solo);
}

TEST(HCpuPair, F17RepeatAfter7DaysIsErrorSearchAgain) {
  HCpuPair p;
  bring_up(p);
  p.one_sided_ob121(1, sec(10));  // the standby this time: master stays
  EXPECT_EQ(p.master(), 0);
  EXPECT_EQ(p.state(1), CpuState::ErrorSearch);
  p.on_time(sec(10) + kSelfTest + kLinkUp + kUpdate);
  EXPECT_EQ(p.master(), 1);                                   // automatic swap
  EXPECT_TRUE(p.one_sided_ob121(1, sec(10) + 7 * kDay + 1));  // one tick later than 7 days
  EXPECT_EQ(p.state(1), CpuState::ErrorSearch);
  EXPECT_EQ(p.master(), 0);
}

TEST(HCpuPair, OperatorMasterSwap) {
  HCpuPairParams prm;
  prm.switch_run = {true, false};
  HCpuPair p(prm);
  p.power_on_both(0);
  p.on_time(kStartup);
  EXPECT_TRUE(p.request_master_swap(sec(10)));
  EXPECT_EQ(p.state(1), CpuState::LinkUp);
  p.on_time(sec(10) + kLinkUp + kUpdate);
  EXPECT_EQ(p.master(), 1);
  EXPECT_EQ(p.state(1), CpuState::Run);
  EXPECT_EQ(p.state(0), CpuState::Stop);
  EXPECT_EQ(p.role(0), CpuRole::Standby);
  EXPECT_EQ(p.system_mode(), SystemMode::Solo);
  const auto o = obs(p, 72);
  ASSERT_EQ(o.size(), 1u);
  EXPECT_EQ(o[0].rack, 1);
  EXPECT_EQ(o[0].reason, HReason::MasterSwap);
}

TEST(HCpuPair, R10S7_1500Profile) {
  HCpuPairParams prm;
  prm.profile = HProfile::S7_1500RH;
  prm.switch_run = {true, false};
  HCpuPair p(prm);
  p.power_on_both(0);
  EXPECT_EQ(p.state(0), CpuState::Startup);
  EXPECT_EQ(p.state(1), CpuState::Stop);
  p.on_time(kStartup);
  EXPECT_EQ(p.system_mode(), SystemMode::Solo);
  EXPECT_EQ(to_string(p.system_mode(), HProfile::S7_1500RH), "RUN-Solo");
  EXPECT_EQ(to_string(p.role(0), HProfile::S7_1500RH), "primary");
  EXPECT_EQ(to_string(p.role(1), HProfile::S7_1500RH), "backup");
  EXPECT_FALSE(p.hold(0, sec(2)));
  // Backup's selector to RUN at 5 s: both SYNCUP for 2 s + 145 ms.
  p.switch_to_run(1, sec(5));
  EXPECT_EQ(p.state(0), CpuState::SyncUp);
  EXPECT_EQ(p.state(1), CpuState::SyncUp);
  EXPECT_EQ(p.system_mode(), SystemMode::SyncUp);
  EXPECT_EQ(p.next_deadline(), sec(5) + kLinkUp + kUpdate);
  p.on_time(sec(5) + kLinkUp + kUpdate);
  EXPECT_EQ(p.state(0), CpuState::Run);
  EXPECT_EQ(p.state(1), CpuState::Run);
  EXPECT_EQ(to_string(p.system_mode(), HProfile::S7_1500RH), "RUN-Redundant");
  for (const HEvent& e : p.events()) {
    if (e.kind == HEvent::Kind::State && e.to_state == CpuState::Startup) {
      EXPECT_EQ(e.rack, 0);
    }
  }
  const std::vector<std::pair<Ticks, SystemMode>> want = {
      {0, SystemMode::Startup},
      {kStartup, SystemMode::Solo},
      {sec(5), SystemMode::SyncUp},
      {sec(5) + kLinkUp + kUpdate, SystemMode::Redundant}};
  EXPECT_EQ(modes(p), want);
}

TEST(HCpuPair, StandbyLostDuringLinkUpAndMasterLostDuringUpdate) {
  HCpuPair p;
  p.power_on(0, 0);
  p.on_time(kStartup);
  p.power_on(1, kCpu1On);
  p.power_off(1, kCpu1On + sec(1));  // during LINK-UP
  EXPECT_EQ(p.system_mode(), SystemMode::Solo);
  EXPECT_TRUE(has_diag(p, 0, kCpu1On + sec(1), "link-up aborted: standby CPU lost"));
  EXPECT_TRUE(obs(p, 72).empty());
  // F20: power lost during LINK-UP leaves a reset request: no start before the memory reset.
  p.power_on(1, sec(10));
  EXPECT_EQ(p.state(1), CpuState::Stop);
  EXPECT_TRUE(p.memory_reset(1, sec(10)));
  p.switch_to_run(1, sec(10));
  p.on_time(sec(10) + kLinkUp);  // UPDATE
  EXPECT_EQ(p.state(1), CpuState::Update);
  p.power_off(0, sec(12) + ms(50));
  EXPECT_EQ(p.state(1), CpuState::Stop);
  EXPECT_EQ(p.master(), 1);
  EXPECT_EQ(p.system_mode(), SystemMode::Stop);
}

TEST(HCpuPair, DiagBufferHasVirtualTimestampsAndRoles) {
  HCpuPair p;
  bring_up(p);
  const auto& d = p.diag_buffer(1);
  ASSERT_FALSE(d.empty());
  EXPECT_EQ(d.front().at, kCpu1On);
  EXPECT_TRUE(has_diag(p, 1, kRedundantAt, "UPDATE -> RUN"));
  EXPECT_EQ(d.back().role, CpuRole::Standby);
}

TEST(HCpuPair, LoneDefectiveCpuRepairedBecomesMaster) {
  HCpuPair p;
  bring_up(p);
  p.inject_hardware_fault(1, sec(9));
  p.inject_comparison_error(sec(10));
  p.on_time(sec(100));  // 10 s + 90 s: DEFECTIVE
  p.power_off(0, sec(110));
  EXPECT_EQ(p.role(1), CpuRole::Standby);  // a DEFECTIVE CPU is never master
  p.repair_cpu(1, sec(120));
  EXPECT_EQ(p.role(1), CpuRole::Master);
  p.switch_to_run(1, sec(121));
  EXPECT_EQ(p.state(1), CpuState::Startup);
}

TEST(HCpuPair, OneFibreCutDuringLinkUpAbortsIt) {
  HCpuPair p;
  p.power_on(0, 0);
  p.on_time(kStartup);
  p.power_on(1, kCpu1On);
  p.cut_fibre(1, kCpu1On + sec(1));  // during LINK-UP (5 s .. 7 s)
  EXPECT_EQ(p.state(1), CpuState::Stop);
  EXPECT_EQ(p.system_mode(), SystemMode::Solo);
  EXPECT_TRUE(obs(p, 72).empty());
  EXPECT_TRUE(p.leds(0).ifm2f);
  EXPECT_FALSE(p.leds(0).ifm1f);
}

// Seeded random operations; after each: the invariants the rules promise.
TEST(HCpuPair, RandomOperationsKeepInvariants) {
  for (std::uint32_t seed : {1u, 2u, 3u, 4u}) {
    SCOPED_TRACE(seed);
    std::mt19937 rng(seed);
    HCpuPairParams prm;
    if (seed == 4) prm.profile = HProfile::S7_1500RH;
    // Seed 3 with the manual's H parameters (T_PH 90 ms, T_P15 194 ms): DB changes above
    // 170 KB make the update time out (F19).
    if (seed == 3) prm.h_parameters = HParameters{ms_us(1940), ms_us(776), ms_us(194), ms_us(90)};
    HCpuPair p(prm);
    Ticks now = 0;
    bool split_seen = false;
    for (int step = 0; step < 10000; ++step) {
      const int r = static_cast<int>(rng() % 2);
      const auto op = static_cast<unsigned>(rng() % 28);  // 16..27: time passes with a RUN request
      if (rng() % 50 == 0) {
        now += 3 * kDay;
      } else {
        now += static_cast<Ticks>(rng() % 5000) * ms(1);
      }
      p.on_time(now);
      switch (op) {
        case 0:
        case 1:
          if (!p.link_whole()) split_seen = true;
          p.power_on(r, now);
          break;
        case 2:
          p.power_off(r, now);
          break;
        case 3:
        case 4:
          p.switch_to_run(r, now);
          break;
        case 5:
          p.switch_to_stop(r, now);
          break;
        case 6:
          p.cut_fibre(r, now);
          break;
        case 7:
          if (p.link_whole()) split_seen = true;
          p.cut_both_fibres(now);
          break;
        case 8:
        case 9:
          p.repair_fibre(r, now);
          break;
        case 10:
          p.hold(r, now);
          break;
        case 11:
          p.release_hold(r, now);
          break;
        case 12:
          p.inject_comparison_error(now);
          break;
        case 13:
          p.one_sided_ob121(r, now);
          break;
        case 14:
          if (rng() % 4 == 0) p.inject_hardware_fault(r, now);
          p.repair_cpu(1 - r, now);
          break;
        case 15:
          if (rng() % 8 == 0) p.set_standby_parameter_change(rng() % 2 == 0);
          p.request_master_swap(now);
          break;
        case 16:
          p.memory_reset(r, now);
          p.switch_to_run(r, now);
          break;
        case 17:
          p.connect(r, now);
          break;
        case 18:
          if (rng() % 4 == 0) p.load_change(static_cast<HChange>(rng() % 3), now);
          break;
        case 19:
          p.set_changed_db_kb(static_cast<std::uint32_t>(rng() % 300), now);
          break;
        default:
          p.switch_to_run(r, now);
          break;
      }
      EXPECT_GT(p.next_deadline(), now);
      // The update model: the no-I/O window only while a CPU is in UPDATE; the output hold
      // lies inside it; data-record jobs are refused exactly while interrupts are held.
      const bool in_update = p.state(0) == CpuState::Update || p.state(1) == CpuState::Update;
      if (p.io_frozen()) {
        EXPECT_TRUE(in_update);
      }
      if (p.outputs_held_by_both()) {
        EXPECT_TRUE(p.io_frozen());
      }
      EXPECT_EQ(p.record_job_result(51, now), p.interrupts_held() ? 0x8085 : 0);
      EXPECT_LE(p.update_tries(), kUpdateMaxTries);
      for (int i = 0; i < 2; ++i) {
        const int o = 1 - i;
        const CpuState st = p.state(i);
        if (st == CpuState::Off) {
          EXPECT_EQ(p.role(i), CpuRole::None);
        }
        if (st == CpuState::Defective) {
          EXPECT_NE(p.role(i), CpuRole::Master);
        }
        if (p.reset_request(i)) {  // F20: no start before the memory reset
          EXPECT_TRUE(st == CpuState::Off || st == CpuState::Stop || st == CpuState::Defective);
        }
        const bool syncing_standby =
            st == CpuState::LinkUp || st == CpuState::Update ||
            (p.role(i) == CpuRole::Standby && (st == CpuState::Run || st == CpuState::SyncUp));
        if (syncing_standby) {
          EXPECT_EQ(p.role(i), CpuRole::Standby);
          EXPECT_TRUE(p.link_whole());
          EXPECT_EQ(p.role(o), CpuRole::Master);
          EXPECT_TRUE(p.state(o) == CpuState::Run || p.state(o) == CpuState::SyncUp);
        }
      }
      if (p.master_count() == 2) {
        EXPECT_TRUE(split_seen);
      }
      if (p.accesses_switched_io(0) && p.accesses_switched_io(1)) {
        EXPECT_EQ(p.master_count(), 2);
      }
      if (::testing::Test::HasFailure()) return;
    }
    Ticks last = 0;
    int redundant = 0, two_masters = 0, error_search = 0, defective = 0, ob72 = 0, timeouts = 0;
    for (const HEvent& e : p.events()) {
      EXPECT_GE(e.at, last);
      last = e.at;
      if (e.kind == HEvent::Kind::SystemMode && e.to_mode == SystemMode::Redundant) ++redundant;
      if (e.kind == HEvent::Kind::Role && e.role == CpuRole::Master &&
          e.from_role == CpuRole::Standby)
        ++two_masters;
      if (e.kind == HEvent::Kind::State && e.to_state == CpuState::ErrorSearch) ++error_search;
      if (e.kind == HEvent::Kind::State && e.to_state == CpuState::Defective) ++defective;
      if (e.kind == HEvent::Kind::Ob && e.ob == 72) ++ob72;
      if (e.kind == HEvent::Kind::Ob && e.reason == HReason::UpdateTimeout) ++timeouts;
    }
    // The walk reaches the interesting states (not only the invariants' trivial cases).
    EXPECT_GE(redundant, 10);
    EXPECT_GE(two_masters, 5);
    EXPECT_GE(ob72, 10);
    if (prm.profile == HProfile::S7_400H) {
      EXPECT_GE(error_search, 3);
    }
    if (seed == 3) {
      EXPECT_GE(timeouts, 3);
    }
    std::printf(
        "seed %u: Redundant %d, standby->master %d, ERROR-SEARCH %d, DEFECTIVE %d, "
        "OB 72 %d, update timeouts %d\n",
        seed, redundant, two_masters, error_search, defective, ob72, timeouts);
  }
}

}  // namespace
}  // namespace pbvbus::devices
