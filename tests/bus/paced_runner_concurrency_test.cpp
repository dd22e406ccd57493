// PacedRunner::post() from many threads at once (built into sanitize_bus and run under TSan).

#include <gtest/gtest.h>

#include <array>
#include <atomic>
#include <thread>
#include <vector>

#include "pbvbus/bus/paced_runner.hpp"

namespace pbvbus::bus {
namespace {

using namespace std::chrono_literals;

TEST(PacedRunnerConcurrency, EveryInputRunsOnceInPostOrderPerThread) {
  constexpr int kThreads = 4;
  constexpr int kPerThread = 300;
  Scheduler sched;
  PacedRunner runner(sched, Speed{10, 1});
  struct Ran {
    int thread, seq;
    Ticks at;
  };
  std::vector<Ran> ran;  // touched only on the runner's thread
  std::atomic<bool> go{false};
  std::atomic<int> finished{0};

  std::thread run([&] { runner.run_for(600 * kTicksPerSecond); });
  std::vector<std::thread> posters;
  for (int t = 0; t < kThreads; ++t) {
    posters.emplace_back([&, t] {
      while (!go.load()) std::this_thread::yield();
      for (int i = 0; i < kPerThread; ++i) {
        runner.post([&ran, t, i](Ticks now) { ran.push_back({t, i, now}); });
        if (i % 50 == 0) std::this_thread::sleep_for(1ms);
      }
      finished.fetch_add(1);
    });
  }
  while (!runner.running()) std::this_thread::sleep_for(1ms);
  go = true;
  for (auto& p : posters) p.join();
  ASSERT_EQ(finished.load(), kThreads);
  // Posted after every other input: it runs last and ends the run.
  runner.post([&](Ticks) { runner.stop(); });
  run.join();

  ASSERT_EQ(ran.size(), static_cast<std::size_t>(kThreads * kPerThread));
  std::array<int, kThreads> next{};
  std::array<Ticks, kThreads> last{};
  Ticks prev = 0;
  for (const Ran& r : ran) {
    ASSERT_EQ(r.seq, next[static_cast<std::size_t>(r.thread)]) << "thread " << r.thread << " out of order";
    ++next[static_cast<std::size_t>(r.thread)];
    EXPECT_GE(r.at, last[static_cast<std::size_t>(r.thread)]);
    last[static_cast<std::size_t>(r.thread)] = r.at;
    EXPECT_GE(r.at, prev) << "inputs run in virtual-time order";
    prev = r.at;
  }
  for (int n : next) EXPECT_EQ(n, kPerThread);
  EXPECT_EQ(runner.report().inputs, static_cast<std::uint64_t>(kThreads * kPerThread + 1));
}

TEST(PacedRunnerConcurrency, StopAndVirtualNowFromOtherThreads) {
  Scheduler sched;
  PacedRunner runner(sched);
  std::atomic<Ticks> seen{0};
  std::thread watcher([&] {
    while (!runner.running()) std::this_thread::sleep_for(1ms);
    for (int i = 0; i < 20; ++i) {
      seen = std::max<Ticks>(seen.load(), runner.virtual_now());
      std::this_thread::sleep_for(1ms);
    }
    runner.stop();
  });
  runner.run_for(3600 * kTicksPerSecond);
  watcher.join();
  EXPECT_GT(seen.load(), 0);
  EXPECT_FALSE(runner.running());
  EXPECT_GE(runner.virtual_now(), seen.load() - kTicksPerMs * 100);
}

}  // namespace
}  // namespace pbvbus::bus
