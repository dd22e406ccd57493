// What the fault campaigns share (devices/campaign/campaign_support.hpp): the seeded draw must
// replay the sequence the campaigns drew before it was shared (same engine, same distributions,
// same order), the event table counts exactly the six system event codes, and the counter watch
// applies the pulse rule of docs/redundancy.md "Switchover campaign" / docs/h-campaign.md.
#include <gtest/gtest.h>

#include <random>

#include "pbvbus/campaign/campaign_support.hpp"

namespace pbvbus::campaign {
namespace {

TEST(CampaignDraw, ReplaysTheEngineAndDistributionsInProgramOrder) {
  Draw d(42);
  std::mt19937_64 ref(42);
  for (int k = 0; k < 50; ++k) {
    EXPECT_EQ(d.ticks(0, 3 * bus::kTicksPerMs),
              std::uniform_int_distribution<bus::Ticks>(0, 3 * bus::kTicksPerMs)(ref));
    EXPECT_EQ(d.integer(0, 1), std::uniform_int_distribution<int>(0, 1)(ref));
    EXPECT_EQ(d.chance(0.5), std::uniform_real_distribution<double>(0, 1)(ref) < 0.5);
  }
  // The engine itself is the same generator, for the campaigns' discrete distributions.
  EXPECT_EQ(d.engine()(), ref());
}

TEST(CampaignDraw, TheSameSeedGivesTheSameCampaign) {
  Draw a(7), b(7), c(8);
  bool differs = false;
  for (int k = 0; k < 20; ++k) {
    const auto x = a.ticks(0, 1'000'000);
    EXPECT_EQ(x, b.ticks(0, 1'000'000));
    differs |= x != c.ticks(0, 1'000'000);
  }
  EXPECT_TRUE(differs);
}

TEST(CampaignEvents, CountsTheSixSystemEventCodesOnly) {
  EventCounts c = zero_event_counts();
  EXPECT_EQ(format_counts(c), " 73A3=0 72A3=0 39C4=0 38C4=0 39C3=0 38C3=0");
  count_event(c, 0x73A3);
  count_event(c, 0x73A3);
  count_event(c, 0x38C3);
  count_event(c, 0x4242);  // not in the table: not counted
  EXPECT_EQ(count_of(c, 0x73A3), 2);
  EXPECT_EQ(count_of(c, 0x38C3), 1);
  EXPECT_EQ(count_of(c, 0x39C4), 0);
  EXPECT_EQ(count_of(c, 0x4242), 0);
  EXPECT_EQ(format_counts(c), " 73A3=2 72A3=0 39C4=0 38C4=0 39C3=0 38C3=1");
}

TEST(CampaignTime, MillisecondsWithThreeDecimals) {
  EXPECT_EQ(format_ms(0), "0.000 ms");
  EXPECT_EQ(format_ms(1234 * bus::kTicksPerUs), "1.234 ms");
  EXPECT_EQ(format_ms(2 * bus::kTicksPerSecond), "2000.000 ms");
}

TEST(CounterWatch, NothingCountsUntilTheCounterStarts) {
  CounterWatch w;
  EXPECT_FALSE(w.sample(0, false).counted);
  EXPECT_FALSE(w.sample(0, false).counted);
  EXPECT_FALSE(w.sample(5, false).counted);  // the first value other than 0 starts it
  const auto s = w.sample(6, false);
  EXPECT_TRUE(s.counted);
  EXPECT_TRUE(s.bad.empty());
  EXPECT_EQ(s.previous, 5);
}

TEST(CounterWatch, ZeroIsAPulseUnlessTheSafeStateIsAllowed) {
  CounterWatch w;
  w.sample(10, false);
  auto s = w.sample(0, false);
  EXPECT_EQ(s.bad, "outputs 0");
  EXPECT_FALSE(s.safe_state);
  s = w.sample(0, true);  // no channel reaches the station now
  EXPECT_TRUE(s.bad.empty());
  EXPECT_TRUE(s.safe_state);
  s = w.sample(0, false);  // channel back, no new value yet: still allowed
  EXPECT_TRUE(s.safe_state);
  EXPECT_TRUE(w.sample(11, false).bad.empty());  // the first new value ends the allowance
  EXPECT_EQ(w.sample(0, false).bad, "outputs 0");
}

TEST(CounterWatch, AHeldOldValueDoesNotEndTheAllowance) {
  CounterWatch w;
  w.sample(10, false);
  w.sample(10, true);                       // safe state allowed, the old value still held
  EXPECT_TRUE(w.sample(10, false).bad.empty());  // the same value again: allowance stays
  EXPECT_TRUE(w.sample(0, false).safe_state);    // its hold may still run out
}

TEST(CounterWatch, AnOlderValueModulo65536IsAPulse) {
  CounterWatch w;
  w.sample(0xFFF0, false);
  EXPECT_TRUE(w.sample(0x0005, false).bad.empty());  // wrapped forward: 0xFFF0 + 0x15
  auto s = w.sample(0x0004, false);
  EXPECT_EQ(s.bad, "older value");
  EXPECT_EQ(s.previous, 0x0005);
  // 0x8000 ahead counts as behind (the half-range rule of the campaigns).
  CounterWatch h;
  h.sample(1, false);
  EXPECT_EQ(h.sample(0x8001, false).bad, "older value");
  CounterWatch f;
  f.sample(1, false);
  EXPECT_TRUE(f.sample(0x8000, false).bad.empty());
}

}  // namespace
}  // namespace pbvbus::campaign
