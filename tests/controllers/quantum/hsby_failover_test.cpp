// Failures of the Hot Standby pair (seed 003 p. 16 "ready to assume control within one scan",
// p. 24 the fibre, seeds-digest.md §8, Q7): the primary's power or CPU fails -> the standby
// takes over at the primary's next due scan start (the transfer it expected does not begin and
// the remote I/O line is silent); a transfer in flight is lost; the standby fails -> the
// primary runs alone; the fibre fails -> the standby, still hearing the primary's head on the
// line, goes offline (Com Err). Times in ticks.
#include <gtest/gtest.h>

#include "hsby_test_support.hpp"

namespace pbvbus::quantum {
namespace {

using namespace hsby_test;

TEST(HsbyFailover, Q7PrimaryPowerOffTakeoverWithinOneScan) {
  Rig g;
  g.pair.power_on(0);
  g.pair.power_on(1);
  g.at(25 * kMs);  // scan 3 started at 20 ms, its transfer (value 2) completed at 22 ms
  g.pair.power_off(0);
  EXPECT_EQ(g.pair.state(0), CpuState::Off);
  EXPECT_EQ(g.h0.role, HeadRole::Off);
  EXPECT_EQ(g.pair.state(1), CpuState::Standby);  // it learns at the next due transfer
  g.at(30 * kMs - 1);
  EXPECT_EQ(g.pair.state(1), CpuState::Standby);
  g.at(30 * kMs);
  EXPECT_EQ(g.pair.state(1), CpuState::Primary);
  EXPECT_EQ(g.h1.role, HeadRole::Active);
  ASSERT_EQ(g.pair.switchovers().size(), 1u);
  const SwitchoverRecord& r = g.pair.switchovers()[0];
  EXPECT_EQ(r.cause, SwitchoverCause::PrimaryPowerOff);
  EXPECT_EQ(r.cause_time, 25 * kMs);
  EXPECT_EQ(r.time, 30 * kMs);
  EXPECT_EQ(r.takeover_ticks, 5 * kMs);
  EXPECT_DOUBLE_EQ(r.takeover_scans, 0.5);
  // The new primary's first scan started from the last transfer (2): it wrote 3, one scan on.
  EXPECT_EQ(g.pair.scans(1), 1u);
  EXPECT_EQ(g.pair.ram(1).holding(1), 3);
  ASSERT_FALSE(g.h1.outputs.empty());
  EXPECT_EQ(g.h1.outputs.front(), 3);
  EXPECT_EQ(g.h0.outputs.back(), 3);  // the old primary's last output: no value went back
  EXPECT_EQ(g.pair.transfers_lost(), 0u);
  EXPECT_EQ(g.pair.leds(1).primary, Led::On);
  EXPECT_EQ(g.pair.leds(1).com_act, Led::Off);
  // The old primary comes back: it joins as standby, roles are not taken back.
  g.at(33 * kMs);
  g.pair.power_on(0);
  EXPECT_EQ(g.pair.state(0), CpuState::Standby);
  EXPECT_EQ(g.pair.primary(), 1);
}

TEST(HsbyFailover, TransferInFlightAtTheFailureIsLost) {
  Rig g;
  g.pair.power_on(0);
  g.pair.power_on(1);
  g.at(21 * kMs);  // the snapshot of the 20 ms scan (2) is on the fibre until 22 ms
  g.pair.power_off(0);
  EXPECT_EQ(g.pair.transfers_lost(), 1u);
  EXPECT_TRUE(g.has_event(PairEventKind::TransferLost));
  g.at(30 * kMs);
  ASSERT_EQ(g.pair.switchovers().size(), 1u);
  EXPECT_EQ(g.pair.switchovers()[0].takeover_ticks, 9 * kMs);
  // Started from the 10 ms scan's snapshot (1): wrote 2 at its first scan.
  EXPECT_EQ(g.pair.ram(1).holding(1), 2);
  EXPECT_EQ(g.pair.last_transfer_scan_start(), 10 * kMs);
}

TEST(HsbyFailover, Q7PrimaryCpuStopIsAFailureToo) {
  Rig g;
  g.pair.power_on(0);
  g.pair.power_on(1);
  g.at(40 * kMs);  // just after the 40 ms scan
  g.pair.stop_cpu(0);
  EXPECT_EQ(g.pair.state(0), CpuState::Offline);
  EXPECT_FALSE(g.pair.cpu_running(0));
  EXPECT_EQ(g.h0.role, HeadRole::Passive);
  g.at(50 * kMs);
  ASSERT_EQ(g.pair.switchovers().size(), 1u);
  EXPECT_EQ(g.pair.switchovers()[0].cause, SwitchoverCause::PrimaryCpuStop);
  EXPECT_EQ(g.pair.switchovers()[0].takeover_ticks, kScan);  // the worst case: one scan
  EXPECT_DOUBLE_EQ(g.pair.switchovers()[0].takeover_scans, 1.0);
  // The stopped CPU runs again: standby.
  g.pair.start_cpu(0);
  EXPECT_EQ(g.pair.state(0), CpuState::Standby);
}

TEST(HsbyFailover, TakeoverWithinOneScanForEveryFailureInstant) {
  for (bus::Ticks t = 20 * kMs; t < 30 * kMs; t += kMs / 2) {
    Rig g;
    g.pair.power_on(0);
    g.pair.power_on(1);
    g.at(t);
    g.pair.power_off(0);
    g.at(45 * kMs);
    ASSERT_EQ(g.pair.switchovers().size(), 1u) << t;
    const auto& r = g.pair.switchovers()[0];
    EXPECT_GT(r.takeover_ticks, 0) << t;
    EXPECT_LE(r.takeover_ticks, kScan) << t;
    // No value older than one scan: the new primary's first scan starts from the snapshot of
    // the old primary's last completed transfer, at most one scan before its last scan start.
    const bus::Ticks last_scan_start = (t / kScan) * kScan;
    const bool carried = t >= last_scan_start + kXfer;
    EXPECT_EQ(g.pair.last_transfer_scan_start(),
              carried ? last_scan_start : last_scan_start - kScan)
        << t;
  }
}

TEST(HsbyFailover, Q7StandbyFailurePrimaryRunsAlone) {
  Rig g;
  g.pair.power_on(0);
  g.pair.power_on(1);
  g.at(17 * kMs);
  g.pair.power_off(1);
  EXPECT_EQ(g.pair.state(0), CpuState::Primary);
  EXPECT_EQ(g.pair.leds(0).com_act, Led::Off);
  EXPECT_EQ(g.pair.leds(0).primary, Led::On);
  const auto done = g.pair.transfers_completed();
  g.at(80 * kMs);
  EXPECT_EQ(g.pair.transfers_completed(), done);
  EXPECT_EQ(g.pair.scans(0), 9u);  // 0 .. 80 ms, uninterrupted
  EXPECT_TRUE(g.pair.switchovers().empty());
  // Standby CPU stop: the same.
  g.pair.power_on(1);
  EXPECT_EQ(g.pair.state(1), CpuState::Standby);
  g.pair.stop_cpu(1);
  g.at(120 * kMs);
  EXPECT_EQ(g.pair.primary(), 0);
  EXPECT_TRUE(g.pair.switchovers().empty());
}

TEST(HsbyFailover, NoStandbyNoTakeover) {
  HsbyPairParams p = small_params();
  p.racks[1].key = KeySwitch::OffLine;
  Rig g(p);
  g.pair.power_on(0);
  g.pair.power_on(1);
  g.at(15 * kMs);
  g.pair.power_off(0);
  g.at(100 * kMs);
  EXPECT_EQ(g.pair.primary(), -1);
  EXPECT_EQ(g.pair.state(1), CpuState::Offline);
  EXPECT_TRUE(g.pair.switchovers().empty());
}

TEST(HsbyFailover, FibreCutStandbyHearsThePrimaryGoesOfflineComErr) {
  Rig g;
  g.pair.power_on(0);
  g.pair.power_on(1);
  g.at(25 * kMs);
  g.pair.set_fibre(FibreState::Cut);
  EXPECT_EQ(g.pair.state(1), CpuState::Standby);
  g.at(30 * kMs);  // the transfer due at 30 ms does not come; the primary's head is heard
  EXPECT_EQ(g.pair.state(1), CpuState::Offline);
  EXPECT_EQ(g.pair.state(0), CpuState::Primary);
  EXPECT_TRUE(g.pair.switchovers().empty());
  EXPECT_EQ(g.pair.leds(1).com_err, Led::On);
  EXPECT_EQ(g.pair.leds(0).com_err, Led::On);
  EXPECT_TRUE(g.has_event(PairEventKind::Fibre, 1));
  // Now the primary fails: the offline unit does not take over.
  g.at(33 * kMs);
  g.pair.power_off(0);
  g.at(60 * kMs);
  EXPECT_EQ(g.pair.primary(), -1);
  // The fibre repaired with the primary alive: the unit joins again.
  g.pair.power_on(0);
  EXPECT_EQ(g.pair.state(0), CpuState::Primary);  // alone: rack 1 is offline, not standby
  g.pair.set_fibre(FibreState::Ok);
  EXPECT_EQ(g.pair.state(1), CpuState::Standby);
}

TEST(HsbyFailover, FibreCutAndLineSilentBothBecomePrimary) {
  Rig g;
  g.h1.hears = false;  // the standby's head hears nothing (its line is down too)
  g.pair.power_on(0);
  g.pair.power_on(1);
  g.at(25 * kMs);
  g.pair.set_fibre(FibreState::Cut);
  g.at(30 * kMs);
  EXPECT_EQ(g.pair.state(0), CpuState::Primary);
  EXPECT_EQ(g.pair.state(1), CpuState::Primary);
  ASSERT_EQ(g.pair.switchovers().size(), 1u);
  EXPECT_EQ(g.pair.switchovers()[0].cause, SwitchoverCause::LinkSilent);
  EXPECT_EQ(g.pair.switchovers()[0].cause_time, 25 * kMs);
  // The fibre repaired: the later primary goes offline, then joins as standby (key at Run).
  g.at(47 * kMs);
  g.pair.set_fibre(FibreState::Ok);
  EXPECT_EQ(g.pair.state(0), CpuState::Primary);
  EXPECT_EQ(g.pair.state(1), CpuState::Standby);
}

TEST(HsbyFailover, HeadHearingTheLineAfterAPowerFailureMeansNoTakeover) {
  Rig g;
  g.h1.hears = true;  // e.g. another master still talking: the standby must not take over
  g.pair.power_on(0);
  g.pair.power_on(1);
  g.at(25 * kMs);
  g.pair.power_off(0);
  g.at(30 * kMs);
  EXPECT_EQ(g.pair.state(1), CpuState::Offline);
  EXPECT_TRUE(g.pair.switchovers().empty());
}

}  // namespace
}  // namespace pbvbus::quantum

namespace pbvbus::quantum {
namespace {

using namespace hsby_test;

// A head that still hears the failed primary's last frames for 1 ms (its silence bound).
TEST(HsbyFailover, LineCheckDelayLetsTheHeadsSilenceBoundPass) {
  for (const bus::Ticks delay : {bus::Ticks{0}, 2 * kMs}) {
    HsbyPairParams p = small_params();
    p.line_check_delay = delay;
    Rig g(p);
    bus::Ticks failed_at = bus::kNever;
    g.h1.hears.reset();
    g.pair.power_on(0);
    g.pair.power_on(1);
    g.at(29 * kMs + kMs / 2);  // 0.5 ms before the due transfer
    failed_at = g.sched.now();
    g.pair.power_off(0);
    // Emulate the bound: heard until 1 ms after the failure.
    g.h1.hears = true;
    g.sched.schedule(failed_at + kMs, [&g] { g.h1.hears = false; });
    g.at(60 * kMs);
    if (delay == 0) {
      EXPECT_EQ(g.pair.state(1), CpuState::Offline);  // mistaken for a fibre fault
      EXPECT_TRUE(g.pair.switchovers().empty());
    } else {
      ASSERT_EQ(g.pair.switchovers().size(), 1u);
      EXPECT_EQ(g.pair.switchovers()[0].time, 32 * kMs);
      EXPECT_EQ(g.pair.switchovers()[0].takeover_ticks, 2 * kMs + kMs / 2);
    }
  }
}

}  // namespace
}  // namespace pbvbus::quantum
