// The S7-1500R/H profile (R10) with I/O: the HSystemModel (h_system.hpp) driving the redundant
// DP master system of h_system_fixture.hpp in HProfile::S7_1500RH. The pair's own rules (STOP ->
// STARTUP on the primary only -> RUN-Solo -> SYNCUP -> RUN-Redundant) are in
// h_cpu_pair_test.cpp; this file asserts what the DP lines and the program do meanwhile.
//
// Timing (defaults, docs/h-system.md rule 14): power_on_both at t0 = 12 ms; the primary's
// STARTUP 1 s -> RUN-Solo at 1.012 s; both switches are RUN, so the backup goes to SYNCUP with
// the primary at once; SYNCUP lasts link_up_time + W = 2 s + (75 ms + 0.7 ms x 100 KB) = 2.145 s
// (no H parameters: W is the update time) -> RUN-Redundant at 3.157 s. SYNCUP has no update
// phases: no no-I/O window, no output hold, no held interrupts.
#include "h_system_fixture.hpp"

namespace pbvbus::devices {
namespace {

HCpuPairParams profile_1500() {
  HCpuPairParams p;
  p.profile = HProfile::S7_1500RH;
  return p;
}

constexpr bus::Ticks kSyncUp = kT0 + 1000 * kMs;               // 1.012 s
constexpr bus::Ticks kRed1500 = kSyncUp + 2000 * kMs + 145 * kMs;  // 3.157 s

// R10 with I/O: only the primary runs STARTUP; its line exchanges data from RUN-Solo; the
// backup's line stays idle (no 39C3, no 73A3) until SYNCUP starts, then both lines carry
// Data_Exchange with the same outputs; OB 1 never pauses (SYNCUP has no no-I/O window).
TEST(HSystem1500, SyncUpStartsTheBackupLineWithoutEventsOrGaps) {
  HSys s(profile_1500());
  Sampler smp(s);
  s.at(kT0);
  s.h->power_on_both();
  EXPECT_EQ(s.h->pair().state(0), CpuState::Startup);
  EXPECT_EQ(s.h->pair().state(1), CpuState::Stop);  // STARTUP on the primary only
  EXPECT_EQ(s.h->side_mode(0, 0), Mode::Clear);
  EXPECT_EQ(s.h->side_mode(0, 1), Mode::Stop);
  EXPECT_TRUE(s.ms().line_idle(1));
  s.run_until(kSyncUp - 1);
  EXPECT_EQ(s.h->scans(), 0u);
  s.run_until(kSyncUp);
  EXPECT_EQ(s.h->pair().state(0), CpuState::SyncUp);
  EXPECT_EQ(s.h->pair().state(1), CpuState::SyncUp);
  EXPECT_EQ(s.h->pair().system_mode(), SystemMode::SyncUp);
  EXPECT_FALSE(s.h->pair().io_frozen());
  EXPECT_FALSE(s.h->pair().interrupts_held());
  // The backup's DP master runs from SYNCUP on (dp_master_operate: SyncUp), the line is started.
  EXPECT_EQ(s.h->side_mode(0, 0), Mode::Operate);
  EXPECT_EQ(s.h->side_mode(0, 1), Mode::Operate);
  EXPECT_FALSE(s.ms().line_idle(1));
  s.run_until(kRed1500 - 1);
  EXPECT_EQ(s.h->pair().system_mode(), SystemMode::SyncUp);
  // OB 1 every 10 ms from 1.012 s without a pause: 1.012, ..., 3.152 s = 215 scans before 3.157.
  EXPECT_EQ(s.h->scans(), 215u);
  s.run_until(kRed1500);
  EXPECT_EQ(s.h->pair().system_mode(), SystemMode::Redundant);
  EXPECT_EQ(s.h->pair().role(0), CpuRole::Master);
  EXPECT_EQ(s.h->pair().role(1), CpuRole::Standby);
  EXPECT_EQ(to_string(s.h->pair().role(1), HProfile::S7_1500RH), "backup");
  s.run_until(kRed1500 + 500 * kMs);
  for (std::uint8_t a : {kFast, kSlow}) {
    EXPECT_EQ(s.sys->master(0).slave_state(a), dp::SlaveStatusState::DataExchange) << int(a);
    EXPECT_EQ(s.sys->master(1).slave_state(a), dp::SlaveStatusState::DataExchange) << int(a);
    EXPECT_EQ(s.ms().active(a), 0) << int(a);  // the preferred line A
    EXPECT_TRUE(s.ms().channel_up(a, 1)) << int(a);
  }
  // The backup's one-sided slave gets the program's outputs from SYNCUP on.
  EXPECT_EQ(s.one_outputs(1), s.counter);
  EXPECT_TRUE(s.s7().empty());  // the backup's line started silently: no 39C3/38C3/73A3/72A3
  EXPECT_TRUE(s.events(Src::Io).empty());
  smp.expect_no_pulse(0);
}

// R10 failure: the primary fails in RUN-Redundant -> the backup becomes primary (RUN-Solo), its
// line carries the switched stations at once: one W#16#39C3 for line A, OB 86 on the new
// primary only, no pulse on the switched outputs.
TEST(HSystem1500, PrimaryFailureBackupTakesOverWithoutPulse) {
  HSys s(profile_1500());
  Sampler smp(s);
  s.at(kT0);
  s.h->power_on_both();
  s.run_until(kRed1500 + 300 * kMs);
  ASSERT_EQ(s.h->pair().system_mode(), SystemMode::Redundant);
  const bus::Ticks tf = 4000 * kMs;
  s.at(tf);
  s.h->power_off(0);
  EXPECT_EQ(s.h->pair().master(), 1);
  EXPECT_EQ(to_string(s.h->pair().role(1), HProfile::S7_1500RH), "primary");
  EXPECT_EQ(to_string(s.h->pair().system_mode(), HProfile::S7_1500RH), "RUN-Solo");
  const auto io = s.events(Src::Io);
  ASSERT_EQ(io.size(), 1u);
  EXPECT_EQ(io[0].ob, 86);
  EXPECT_EQ(io[0].code, 0x39C3);
  EXPECT_EQ(io[0].line, 0);
  EXPECT_EQ(io[0].rack, 1);
  EXPECT_EQ(io[0].time, tf);
  s.run_until(tf + 2000 * kMs);
  for (std::uint8_t a : {kFast, kSlow}) {
    EXPECT_EQ(s.ms().active(a), 1) << int(a);
    EXPECT_EQ(s.station(a).primary(), 1) << int(a);
  }
  EXPECT_EQ(s.s7().size(), 1u);
  EXPECT_EQ(s.one_outputs(1), s.counter);
  smp.expect_no_pulse(0);
}

}  // namespace
}  // namespace pbvbus::devices
