// Discrete-event scheduler (design.md "Time"): order, FIFO at equal ticks, run_until, stop.

#include "pbvbus/bus/scheduler.hpp"

#include <gtest/gtest.h>

#include <vector>

namespace pbvbus::bus {
namespace {

struct Log final : EventTarget {
  explicit Log(Scheduler& s) : sched(s) {}
  void on_event(Ticks now, std::uint64_t tag) override {
    seen.emplace_back(now, tag);
    EXPECT_EQ(sched.now(), now);
    if (tag == 99) sched.stop();
    if (tag == 50) sched.schedule(now, *this, 51);  // same tick: runs after everything queued
  }
  Scheduler& sched;
  std::vector<std::pair<Ticks, std::uint64_t>> seen;
};

using Seen = std::vector<std::pair<Ticks, std::uint64_t>>;

TEST(Scheduler, RunsInTimeOrderAndFifoAtEqualTicks) {
  Scheduler s;
  Log log(s);
  s.schedule(30, log, 1);
  s.schedule(10, log, 2);
  s.schedule(20, log, 3);
  s.schedule(10, log, 4);
  s.schedule(10, log, 5);
  EXPECT_EQ(s.pending(), 5u);
  EXPECT_EQ(s.next_time(), 10);
  s.run_until(100);
  EXPECT_EQ(log.seen, (Seen{{10, 2}, {10, 4}, {10, 5}, {20, 3}, {30, 1}}));
  EXPECT_EQ(s.now(), 100);
  EXPECT_TRUE(s.empty());
  EXPECT_EQ(s.next_time(), kNever);
  EXPECT_EQ(s.events_run(), 5u);
}

TEST(Scheduler, EventScheduledAtSameTickRunsAfterThoseAlreadyQueued) {
  Scheduler s;
  Log log(s);
  s.schedule(10, log, 50);
  s.schedule(10, log, 60);
  s.run_until(10);
  EXPECT_EQ(log.seen, (Seen{{10, 50}, {10, 60}, {10, 51}}));
}

TEST(Scheduler, PastTimesAreClampedToNow) {
  Scheduler s;
  Log log(s);
  s.run_until(1000);
  s.schedule(5, log, 7);
  EXPECT_EQ(s.next_time(), 1000);
  s.run_until(1000);
  EXPECT_EQ(log.seen, (Seen{{1000, 7}}));
}

TEST(Scheduler, RunUntilIsInclusiveAndAdvancesTheClock) {
  Scheduler s;
  Log log(s);
  s.schedule(100, log, 1);
  s.schedule(101, log, 2);
  s.run_until(99);
  EXPECT_TRUE(log.seen.empty());
  EXPECT_EQ(s.now(), 99);
  s.run_until(100);
  EXPECT_EQ(log.seen, (Seen{{100, 1}}));
  EXPECT_EQ(s.now(), 100);
  s.run_until(50);  // never goes backwards
  EXPECT_EQ(s.now(), 100);
  EXPECT_TRUE(s.step());
  EXPECT_EQ(s.now(), 101);
  EXPECT_FALSE(s.step());
}

TEST(Scheduler, StopReturnsAfterTheCurrentEvent) {
  Scheduler s;
  Log log(s);
  s.schedule(10, log, 1);
  s.schedule(20, log, 99);
  s.schedule(20, log, 2);
  s.schedule(30, log, 3);
  s.run_until(1000);
  EXPECT_EQ(log.seen, (Seen{{10, 1}, {20, 99}}));
  EXPECT_EQ(s.now(), 20);  // not advanced to `until` when stopped
  EXPECT_EQ(s.pending(), 2u);
  s.run_until(1000);  // a new run is not stopped by the old request
  EXPECT_EQ(log.seen.size(), 4u);
  EXPECT_EQ(s.now(), 1000);
}

TEST(Scheduler, FunctionEventsInterleaveWithTargets) {
  Scheduler s;
  Log log(s);
  std::vector<int> order;
  s.schedule(10, [&] { order.push_back(1); });
  s.schedule(10, log, 2);
  s.schedule(5, [&] {
    order.push_back(0);
    // A function scheduling functions (slot reuse while running).
    s.schedule(10, [&] { order.push_back(3); });
  });
  s.run_until(10);
  EXPECT_EQ(order, (std::vector<int>{0, 1, 3}));
  EXPECT_EQ(log.seen, (Seen{{10, 2}}));
  // Many short-lived functions: slots are recycled and each runs exactly once.
  int count = 0;
  for (int i = 0; i < 1000; ++i) s.schedule(20 + i % 7, [&] { ++count; });
  s.run_until(100);
  EXPECT_EQ(count, 1000);
}

TEST(Scheduler, AdvanceTo) {
  Scheduler s;
  Log log(s);
  s.schedule(100, log, 1);
  s.advance_to(60);
  EXPECT_EQ(s.now(), 60);
  s.advance_to(10);
  EXPECT_EQ(s.now(), 60);
  EXPECT_TRUE(log.seen.empty());
}

}  // namespace
}  // namespace pbvbus::bus
