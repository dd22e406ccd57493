// The Hot Standby fault campaign on a real DP line (hsby_campaign.hpp,
// docs/quantum-hsby-campaign.md): 2 000 injections (1 000 faults, each with its repair) over
// eight slaves at 1.5 Mbit/s with nothing found by the independent observer (0 output pulses,
// 0 values older than one scan at the slaves and through Modbus unit 1, every switchover within
// one scan, no slave out of data exchange); every fault kind alone; the same seed replays the
// same campaign; and the observer's own tests: a program writing 0 once and a stale standby at a
// primary failure are found.
#include <gtest/gtest.h>

#include <stdexcept>

#include "pbvbus/quantum/hsby_campaign.hpp"

namespace pbvbus::quantum {
namespace {

constexpr bus::Ticks kHcTestMs = bus::kTicksPerMs;

void hc_expect_clean(const HsbyCampaignResult& r) {
  EXPECT_TRUE(r.clean()) << r.summary();
  EXPECT_EQ(r.pulses, 0u);
  EXPECT_EQ(r.stale_outputs, 0u);
  EXPECT_EQ(r.stale_reads, 0u);
  EXPECT_EQ(r.late_switchovers, 0);
  EXPECT_EQ(r.dx_exits, 0u);
  EXPECT_EQ(r.wrong_rack, 0u);
  EXPECT_TRUE(r.mismatches.empty());
  EXPECT_EQ(r.switchovers, r.expected_switchovers);
}

TEST(HsbyCampaign, ThousandFaultsOnTheLineFindNothing) {
  HsbyCampaignOptions o;
  o.seed = 1;
  o.steps = 2000;
  o.slaves = 8;
  const HsbyCampaignResult r = run_hsby_campaign(o);
  RecordProperty("summary", r.summary());
  hc_expect_clean(r);
  EXPECT_GE(r.faults, 1000);
  EXPECT_EQ(r.faults, r.repairs);
  for (int k = 0; k < kHsbyFaultKinds; ++k) EXPECT_GT(r.drawn[static_cast<std::size_t>(k)], 50) << k;
  EXPECT_GT(r.switchovers, 300);
  EXPECT_EQ(static_cast<int>(r.takeover_ticks.size()), r.switchovers);
  EXPECT_LE(r.takeover_all.max_scans, 1.0);
  EXPECT_GT(r.takeover_unplanned.count, 150);
  EXPECT_GT(r.slave_samples, 1000000u);
  EXPECT_GT(r.modbus_answers, 100000u);
  // Unit 1 unanswered only in the takeover window: within one scan, as the polls see it (the
  // first poll after the window may come one poll period later).
  EXPECT_GT(r.modbus_no_answer, 0u);
  EXPECT_LE(r.longest_no_answer, o.scan_time + o.poll_period);
}

TEST(HsbyCampaign, EveryFaultKindAloneFindsNothing) {
  for (int k = 0; k < kHsbyFaultKinds; ++k) {
    SCOPED_TRACE(to_string(static_cast<HsbyFault>(k)));
    HsbyCampaignOptions o;
    o.seed = 10 + static_cast<std::uint64_t>(k);
    o.steps = 60;
    o.weights.fill(0);
    o.weights[static_cast<std::size_t>(k)] = 1;
    const HsbyCampaignResult r = run_hsby_campaign(o);
    hc_expect_clean(r);
    EXPECT_EQ(r.drawn[static_cast<std::size_t>(k)], 30);
    const auto f = static_cast<HsbyFault>(k);
    const bool swaps = f == HsbyFault::PrimaryPower || f == HsbyFault::PrimaryCpuStop ||
                       f == HsbyFault::KeyOffLine || f == HsbyFault::Override;
    EXPECT_EQ(r.switchovers, swaps ? 30 : 0);
  }
}

TEST(HsbyCampaign, SameSeedSameCampaign) {
  HsbyCampaignOptions o;
  o.seed = 42;
  o.steps = 200;
  o.keep_log = true;
  const HsbyCampaignResult a = run_hsby_campaign(o);
  const HsbyCampaignResult b = run_hsby_campaign(o);
  EXPECT_EQ(a.log, b.log);
  EXPECT_EQ(a.drawn, b.drawn);
  EXPECT_EQ(a.takeover_ticks, b.takeover_ticks);
  EXPECT_EQ(a.slave_samples, b.slave_samples);
  EXPECT_EQ(a.modbus_polls, b.modbus_polls);
  EXPECT_EQ(a.simulated, b.simulated);
  o.seed = 43;
  const HsbyCampaignResult c = run_hsby_campaign(o);
  EXPECT_NE(a.log, c.log);
}

TEST(HsbyCampaign, ObserverFindsAProgramWritingZeroOnce) {
  HsbyCampaignOptions o;
  o.steps = 100;
  o.tamper.zero_output_at = 3000 * kHcTestMs;
  const HsbyCampaignResult r = run_hsby_campaign(o);
  EXPECT_FALSE(r.clean());
  EXPECT_GT(r.pulses, 0u);
  ASSERT_FALSE(r.reports.empty());
  EXPECT_NE(r.reports.front().find("outputs 0"), std::string::npos) << r.reports.front();
}

TEST(HsbyCampaign, ObserverFindsAStaleStandbyAtATakeover) {
  HsbyCampaignOptions o;
  o.steps = 100;
  o.tamper.stale_takeover_at = 4;
  const HsbyCampaignResult r = run_hsby_campaign(o);
  EXPECT_FALSE(r.clean());
  EXPECT_GT(r.stale_outputs, 0u);
  EXPECT_GT(r.stale_reads, 0u);
  EXPECT_EQ(r.pulses, 0u);
  EXPECT_EQ(r.late_switchovers, 0);
}

TEST(HsbyCampaign, TakeoverDistributionNearestRank) {
  // 1..100 ms against a 20 ms scan: median 50 ms (rank 50), p99 99 ms (rank 99).
  std::vector<bus::Ticks> t;
  for (int k = 100; k >= 1; --k) t.push_back(k * kHcTestMs);
  const TakeoverDistribution d = takeover_distribution(t, 20 * kHcTestMs);
  EXPECT_EQ(d.count, 100);
  EXPECT_DOUBLE_EQ(d.min_ms, 1.0);
  EXPECT_DOUBLE_EQ(d.median_ms, 50.0);
  EXPECT_DOUBLE_EQ(d.p99_ms, 99.0);
  EXPECT_DOUBLE_EQ(d.max_ms, 100.0);
  EXPECT_DOUBLE_EQ(d.median_scans, 2.5);
  EXPECT_EQ(takeover_distribution({}, 20 * kHcTestMs).count, 0);
}

TEST(HsbyCampaign, UnusableOptionsAreRefused) {
  HsbyCampaignOptions o;
  o.weights.fill(0);
  EXPECT_THROW(run_hsby_campaign(o), std::invalid_argument);
  o = HsbyCampaignOptions{};
  o.weights[2] = -1;
  EXPECT_THROW(run_hsby_campaign(o), std::invalid_argument);
  o = HsbyCampaignOptions{};
  o.fault_min = 2 * o.scan_time;  // a fibre cut would not be noticed
  EXPECT_THROW(run_hsby_campaign(o), std::invalid_argument);
  o = HsbyCampaignOptions{};
  o.poll_period = 0;
  EXPECT_THROW(run_hsby_campaign(o), std::invalid_argument);
  o = HsbyCampaignOptions{};
  o.slaves = 0;
  EXPECT_THROW(run_hsby_campaign(o), std::invalid_argument);
}

}  // namespace
}  // namespace pbvbus::quantum
