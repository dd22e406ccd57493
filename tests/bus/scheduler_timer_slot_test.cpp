// Scheduler: the FIFO for events due now and re-armable timers (Scheduler::TimerSlot) keep the
// order a single (when, seq) queue gives, with a re-armed timer ordered as a fresh schedule().

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <functional>
#include <map>
#include <random>
#include <tuple>
#include <vector>

#include "pbvbus/bus/scheduler.hpp"

namespace pbvbus::bus {
namespace {

using Seen = std::vector<std::pair<Ticks, std::uint64_t>>;

struct Rec final : EventTarget {
  void on_event(Ticks now, std::uint64_t tag) override { seen.emplace_back(now, tag); }
  Seen seen;
};

TEST(SchedulerTimerSlot, DueNowRunsBeforeLaterEventsAndAfterEarlierOnesOfItsTick) {
  Scheduler s;
  Rec r;
  s.schedule(5, r, 1);
  s.schedule(0, r, 2);  // due now: the FIFO
  EXPECT_EQ(s.pending(), 2u);
  EXPECT_EQ(s.next_time(), 0);
  s.run_until(5);
  EXPECT_EQ(r.seen, (Seen{{0, 2}, {5, 1}}));
  EXPECT_TRUE(s.empty());
}

TEST(SchedulerTimerSlot, EarlierReArmReplacesTheQueuedEntry) {
  Scheduler s;
  Rec r;
  Scheduler::TimerSlot slot;
  s.schedule(slot, 100, r, 1);
  EXPECT_TRUE(slot.queued());
  s.schedule(slot, 50, r, 2);
  EXPECT_EQ(s.pending(), 1u);
  EXPECT_EQ(s.next_time(), 50);
  s.run_until(200);
  EXPECT_EQ(r.seen, (Seen{{50, 2}}));
  EXPECT_EQ(s.events_run(), 1u);
  EXPECT_FALSE(slot.queued());
}

TEST(SchedulerTimerSlot, LaterReArmMovesTheEntryBack) {
  Scheduler s;
  Rec r;
  Scheduler::TimerSlot slot;
  s.schedule(slot, 50, r, 1);
  s.schedule(70, r, 9);
  s.schedule(slot, 100, r, 2);
  s.run_until(200);
  EXPECT_EQ(r.seen, (Seen{{70, 9}, {100, 2}}));
}

TEST(SchedulerTimerSlot, ReArmIsOrderedAsAFreshSchedule) {
  Scheduler s;
  Rec r;
  Scheduler::TimerSlot slot;
  s.schedule(slot, 10, r, 1);
  s.schedule(10, r, 2);
  s.schedule(slot, 10, r, 3);  // same tick, but now after tag 2
  s.run_until(10);
  EXPECT_EQ(r.seen, (Seen{{10, 2}, {10, 3}}));
}

TEST(SchedulerTimerSlot, CancelWithdrawsTheEntry) {
  Scheduler s;
  Rec r;
  Scheduler::TimerSlot slot;
  s.schedule(20, r, 1);
  s.schedule(slot, 10, r, 2);
  s.schedule(30, r, 3);
  s.cancel(slot);
  EXPECT_FALSE(slot.queued());
  EXPECT_EQ(s.pending(), 2u);
  s.cancel(slot);  // nothing queued: no-op
  s.run_until(100);
  EXPECT_EQ(r.seen, (Seen{{20, 1}, {30, 3}}));
}

// Many timers re-armed and cancelled at random among plain events, against a reference that
// keeps every entry with its (when, seq) and drops withdrawn ones.
struct Model final : EventTarget {
  void on_event(Ticks now, std::uint64_t tag) override {
    seen.emplace_back(now, tag);
    if (hook) hook(now, tag);
  }
  Seen seen;
  std::function<void(Ticks, std::uint64_t)> hook;
};

TEST(SchedulerTimerSlot, RandomReArmsMatchASingleQueue) {
  std::mt19937_64 rng(7);
  for (int round = 0; round < 20; ++round) {
    Scheduler s;
    Model m;
    constexpr int kSlots = 40;
    std::vector<Scheduler::TimerSlot> slots(kSlots);
    // Reference: (when, seq) -> tag, and each slot's live key.
    std::map<std::pair<Ticks, std::uint64_t>, std::uint64_t> ref;
    std::vector<std::pair<Ticks, std::uint64_t>> slot_key(kSlots, {-1, 0});
    std::uint64_t seq = 0;
    std::uint64_t next_tag = 1;
    auto plain = [&](Ticks when) {
      when = std::max(when, s.now());
      const std::uint64_t tag = next_tag++;
      s.schedule(when, m, tag);
      ref[{when, seq++}] = tag;
    };
    auto arm = [&](int k, Ticks when) {
      when = std::max(when, s.now());
      const std::uint64_t tag = next_tag++;
      if (slot_key[static_cast<std::size_t>(k)].first >= 0) ref.erase(slot_key[static_cast<std::size_t>(k)]);
      s.schedule(slots[static_cast<std::size_t>(k)], when, m, tag);
      slot_key[static_cast<std::size_t>(k)] = {when, seq};
      ref[{when, seq++}] = tag;
    };
    auto cancel = [&](int k) {
      if (slot_key[static_cast<std::size_t>(k)].first >= 0) ref.erase(slot_key[static_cast<std::size_t>(k)]);
      slot_key[static_cast<std::size_t>(k)] = {-1, 0};
      s.cancel(slots[static_cast<std::size_t>(k)]);
    };
    Seen expected;
    m.hook = [&](Ticks now, std::uint64_t tag) {
      // The reference's front is what ran.
      ASSERT_FALSE(ref.empty());
      const auto it = ref.begin();
      EXPECT_EQ(it->first.first, now);
      EXPECT_EQ(it->second, tag);
      for (auto& k : slot_key)
        if (k == it->first) k = {-1, 0};
      ref.erase(it);
      // Schedule more from inside a handler, some due now.
      for (int j = 0; j < 3; ++j) {
        const auto op = rng() % 4;
        const Ticks when = now + static_cast<Ticks>(rng() % 3 == 0 ? 0 : rng() % 50);
        const int k = static_cast<int>(rng() % kSlots);
        if (op == 0) plain(when);
        else if (op == 3) cancel(k);
        else arm(k, when);
      }
    };
    for (int j = 0; j < 60; ++j) {
      const int k = static_cast<int>(rng() % kSlots);
      if (j % 3 == 0) plain(static_cast<Ticks>(rng() % 100));
      else arm(k, static_cast<Ticks>(rng() % 100));
    }
    while (!s.empty() && m.seen.size() < 3000) s.step();
    EXPECT_GT(m.seen.size(), 100u);
    EXPECT_EQ(s.pending(), ref.size());
    for (auto& k : slots) s.cancel(k);
  }
}

}  // namespace
}  // namespace pbvbus::bus
