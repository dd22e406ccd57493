// The paced driver (design.md "Time"): virtual time follows the steady clock. These are the only
// timed tests in the suite; their bounds are tolerant because CI machines are shared and slow.

#include "pbvbus/bus/paced_runner.hpp"

#include <gtest/gtest.h>

#include <boost/asio/io_context.hpp>
#include <boost/asio/post.hpp>
#include <thread>

#include "pbvbus/bus/line.hpp"
#include "probe.hpp"

namespace pbvbus::bus {
namespace {

using namespace std::chrono_literals;
using Clock = std::chrono::steady_clock;

Ticks ms(std::int64_t n) { return n * kTicksPerMs; }
std::chrono::nanoseconds as_wall(Ticks t) { return std::chrono::nanoseconds(ticks_to_ns(t)); }

/// Records the wall time at which each periodic timer fires.
struct Ticker final : EventTarget {
  Ticker(Scheduler& s, Ticks p) : sched(s), period(p) {}
  void on_event(Ticks now, std::uint64_t) override {
    fired.emplace_back(now, Clock::now());
    sched.schedule(now + period, *this);
  }
  Scheduler& sched;
  Ticks period;
  std::vector<std::pair<Ticks, Clock::time_point>> fired;
};

TEST(PacedRunner, ShortRunTakesAtLeastItsVirtualTimeAndNeverRunsEarly) {
  Scheduler sched;
  Ticker ticker(sched, ms(10));
  sched.schedule(ms(10), ticker);
  PacedRunner runner(sched);
  const auto t0 = Clock::now();
  runner.run_for(ms(150));
  const auto wall = Clock::now() - t0;
  EXPECT_EQ(sched.now(), ms(150));
  EXPECT_GE(wall, 150ms);
  EXPECT_LT(wall, 2s) << "tolerant upper bound for a loaded machine";
  ASSERT_EQ(ticker.fired.size(), 15u);
  for (const auto& [v, w] : ticker.fired) {
    EXPECT_GE(w - t0, as_wall(v)) << "event at virtual " << format_duration(v) << " ran early";
  }
  const PacedReport& r = runner.report();
  EXPECT_EQ(r.virtual_elapsed, ms(150));
  EXPECT_GE(r.wall_elapsed, 150ms);
  EXPECT_EQ(r.wakeups, 15u);
  EXPECT_LT(r.max_lag, 1s);
  EXPECT_EQ(r.slips, 0u);
}

TEST(PacedRunner, SpeedRatioScalesWallTime) {
  Scheduler sched;
  PacedRunner runner(sched, Speed{4, 1});  // four times faster than real time
  const auto t0 = Clock::now();
  runner.run_for(ms(400));
  const auto wall = Clock::now() - t0;
  EXPECT_EQ(sched.now(), ms(400));
  EXPECT_GE(wall, 100ms);
  EXPECT_LT(wall, 350ms + 1s);

  runner.set_speed(Speed{1, 2});  // half speed
  const auto t1 = Clock::now();
  runner.run_for(ms(50));
  EXPECT_GE(Clock::now() - t1, 100ms);
  EXPECT_EQ(sched.now(), ms(450));
  EXPECT_THROW(runner.set_speed(Speed{0, 1}), std::invalid_argument);
  EXPECT_THROW(runner.set_speed(Speed{1, 0}), std::invalid_argument);
}

TEST(PacedRunner, PostedInputRunsAtTheVirtualTimeOfItsWallTime) {
  Scheduler sched;
  PacedRunner runner(sched);
  Ticks expected = -1, ran_at = -1;
  std::thread poster([&] {
    while (!runner.running()) std::this_thread::sleep_for(1ms);
    std::this_thread::sleep_for(60ms);
    expected = runner.virtual_now();
    runner.post([&](Ticks now) { ran_at = now; });
  });
  runner.run_for(ms(200));
  poster.join();
  ASSERT_GE(expected, ms(50));
  ASSERT_NE(ran_at, -1);
  EXPECT_GE(ran_at, expected);
  EXPECT_LT(ran_at - expected, ms(50)) << "an input enters close to the wall time it was posted at";
  EXPECT_EQ(runner.report().inputs, 1u);
}

TEST(PacedRunner, InputsPostedBetweenRunsRunAtTheStartOfTheNext) {
  Scheduler sched;
  PacedRunner runner(sched);
  runner.run_for(ms(5));
  std::vector<Ticks> at;
  runner.post([&](Ticks now) { at.push_back(now); });
  runner.post([&](Ticks now) { at.push_back(now); });
  EXPECT_TRUE(at.empty());
  runner.run_for(ms(5));
  EXPECT_EQ(at, (std::vector<Ticks>{ms(5), ms(5)}));
}

TEST(PacedRunner, StopFromAnEventEndsTheRun) {
  Scheduler sched;
  PacedRunner runner(sched);
  bool after = false;
  sched.schedule(ms(20), [&] { runner.stop(); });
  sched.schedule(ms(20), [&] { after = true; });
  const auto t0 = Clock::now();
  runner.run_for(ms(10'000));
  EXPECT_LT(Clock::now() - t0, 5s);
  EXPECT_EQ(sched.now(), ms(20));
  EXPECT_FALSE(after) << "stop() from an event ends the batch after that event";
  EXPECT_FALSE(runner.running());
  // The next run picks up where it stopped.
  runner.run_for(ms(1));
  EXPECT_TRUE(after);
}

TEST(PacedRunner, StopFromAnotherThread) {
  Scheduler sched;
  PacedRunner runner(sched);
  std::thread stopper([&] {
    while (!runner.running()) std::this_thread::sleep_for(1ms);
    std::this_thread::sleep_for(30ms);
    runner.stop();
  });
  const auto t0 = Clock::now();
  runner.run_for(ms(60'000));
  stopper.join();
  EXPECT_LT(Clock::now() - t0, 5s);
  EXPECT_GE(sched.now(), ms(25));
  EXPECT_LT(sched.now(), ms(5'000));
}

TEST(PacedRunner, IoContextHandlersRunInsideTheRun) {
  Scheduler sched;
  PacedRunner runner(sched);
  Ticks seen = -1;
  std::thread t([&] {
    while (!runner.running()) std::this_thread::sleep_for(1ms);
    // A door's handler (here: a plain posted handler) runs on the runner's thread and injects
    // its input through post().
    boost::asio::post(runner.io_context(), [&] { runner.post([&](Ticks now) { seen = now; }); });
  });
  runner.run_for(ms(100));
  t.join();
  EXPECT_GT(seen, 0);
  EXPECT_LE(seen, ms(100));
}

TEST(PacedRunner, SlipsInsteadOfCatchingUpWhenAllowed) {
  Scheduler sched;
  PacedRunner runner(sched);
  runner.set_max_lag(20ms);
  std::vector<std::pair<Ticks, Clock::time_point>> seen;
  // An event that stalls the loop for 100 ms of wall time, then events every 5 ms.
  sched.schedule(ms(10), [&] { std::this_thread::sleep_for(100ms); });
  for (int i = 1; i <= 10; ++i) sched.schedule(ms(10 + 5 * i), [&] { seen.emplace_back(sched.now(), Clock::now()); });
  runner.run_for(ms(70));
  ASSERT_EQ(seen.size(), 10u);
  EXPECT_EQ(runner.report().slips, 1u);
  EXPECT_GE(runner.report().slipped, 80ms);
  // After the slip the events are paced again, not run back to back.
  EXPECT_GE(seen.back().second - seen.front().second, 40ms);
}

TEST(PacedRunner, CatchesUpWithoutSlipByDefault) {
  Scheduler sched;
  PacedRunner runner(sched);
  std::vector<Clock::time_point> seen;
  sched.schedule(ms(10), [&] { std::this_thread::sleep_for(100ms); });
  for (int i = 1; i <= 10; ++i) sched.schedule(ms(10 + 5 * i), [&] { seen.push_back(Clock::now()); });
  const auto t0 = Clock::now();
  runner.run_for(ms(70));
  ASSERT_EQ(seen.size(), 10u);
  EXPECT_EQ(runner.report().slips, 0u);
  EXPECT_GE(runner.report().max_lag, 50ms);
  EXPECT_GE(runner.report().late_wakeups, 1u);
  // Virtual time stayed anchored: the events due while stalled ran back to back.
  EXPECT_LT(seen[8] - seen[0], 40ms);
  EXPECT_GE(Clock::now() - t0, 110ms);
}

TEST(PacedRunner, DrivesALineInRealTime) {
  Scheduler sched;
  Line line(sched, "A", Baud::k9_6);
  test::Probe a, b;
  line.attach(a);
  line.attach(b);
  line.start();
  a.send(ms(10), "10 03 01 49 4D 16");  // 66 bits at 9.6k = 6.875 ms
  PacedRunner runner(sched);
  const auto t0 = Clock::now();
  Clock::time_point got{};
  b.on_rx = [&](const RxFrame&) { got = Clock::now(); };
  runner.run_for(ms(30));
  ASSERT_EQ(b.rx.size(), 1u);
  EXPECT_EQ(b.rx[0].end, ms(10) + 66 * ticks_per_bit(Baud::k9_6));
  EXPECT_GE(got - t0, as_wall(b.rx[0].end));
}

TEST(RunFast, RunsToTheEnd) {
  Scheduler sched;
  int n = 0;
  sched.schedule(ms(1000), [&] { ++n; });
  const auto t0 = Clock::now();
  run_fast(sched, ms(2000));
  EXPECT_LT(Clock::now() - t0, 500ms);
  EXPECT_EQ(n, 1);
  EXPECT_EQ(sched.now(), ms(2000));
}

}  // namespace
}  // namespace pbvbus::bus
