// A plant in one process: 24 DP lines at 1.5 Mbit/s, each with one DP master class 1 (address 1,
// OPERATE) and 60 DP slaves (addresses 2..61, examples/gsd/PBVB0A01.gsd, its default module),
// built by the scenario loader and tools::Simulation like `pbvbus run` (line statistics on every
// line, no capture). Figures and commands are in docs/benchmarks.md ("Twice the simulation
// speed").
//
//   BM_Plant/1.5M/24x60         fast driver; each iteration simulates 100 ms after 1 s of
//                               start-up. Counters: virt_s_per_wall_s, virt_s_per_cpu_s (CPU
//                               time of the benchmark thread), frames_per_s (all lines),
//                               maxrss_mb (getrusage: the process's peak resident set, so run
//                               this benchmark alone for a figure of the plant itself),
//                               heap_mb (glibc mallinfo2 heap in use after the build).
//   BM_Plant/1.5M/24x60/paced   the same plant under bus::PacedRunner at 1x for 3 s of virtual
//                               time (one iteration). Lag = how far virtual time is behind the
//                               wall clock when an event runs: a probe event every virtual
//                               millisecond records PacedRunner::virtual_now() - now.
//                               Counters lag_min_us, lag_median_us, lag_p99_us, lag_max_us over
//                               those samples, report_max_lag_us (the runner's own worst
//                               wake-up), late_wakeups (> 1 ms late), wakeups_per_s (loop
//                               iterations that ran events, per wall second) and cpu_share (CPU
//                               time of the thread / wall time: the part of one core the plant
//                               needs at 1x).

#include <benchmark/benchmark.h>
#include <malloc.h>
#include <sys/resource.h>

#include <algorithm>
#include <chrono>
#include <ctime>
#include <sstream>
#include <string>
#include <vector>

#include "pbvbus/bus/paced_runner.hpp"
#include "pbvbus/scenario/scenario.hpp"
#include "pbvbus/simulation/simulation.hpp"

namespace {

using namespace pbvbus;

constexpr int kLines = 24;
constexpr int kSlaves = 60;

double thread_cpu_seconds() {
  timespec ts{};
  ::clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return static_cast<double>(ts.tv_sec) + static_cast<double>(ts.tv_nsec) * 1e-9;
}

double maxrss_mb() {
  rusage ru{};
  ::getrusage(RUSAGE_SELF, &ru);
  return static_cast<double>(ru.ru_maxrss) / 1024.0;  // Linux: kilobytes
}

std::string plant_scenario() {
  std::ostringstream s;
  s << "name: \"plant\"\nseed: 1\n";
  for (int l = 0; l < kLines; ++l) {
    s << "line { name: \"DP" << l << "\" baud: \"1.5M\" }\n";
    s << "dp_master { address: 1 line: \"DP" << l << "\" mode: OPERATE }\n";
    for (int i = 0; i < kSlaves; ++i)
      s << "dp_slave { address: " << 2 + i << " line: \"DP" << l
        << "\" gsd: \"gsd/PBVB0A01.gsd\" master: 1 }\n";
  }
  return s.str();
}

std::uint64_t all_frames(tools::Simulation& sim) {
  std::uint64_t n = 0;
  for (std::size_t i = 0; i < sim.line_count(); ++i) n += sim.stats(i).frames;
  return n;
}

/// Samples the paced runner's lag once per virtual millisecond.
class LagProbe final : public bus::EventTarget {
 public:
  LagProbe(bus::PacedRunner& runner, bus::Ticks until) : m_runner(runner), m_until(until) {}
  void start(bus::Ticks at) { m_runner.scheduler().schedule(at, *this); }
  void on_event(bus::Ticks now, std::uint64_t) override {
    lags.push_back(m_runner.virtual_now() - now);
    if (now + bus::kTicksPerMs <= m_until) m_runner.scheduler().schedule(now + bus::kTicksPerMs, *this);
  }
  std::vector<bus::Ticks> lags;

 private:
  bus::PacedRunner& m_runner;
  bus::Ticks m_until;
};

double ticks_to_us(bus::Ticks t) { return static_cast<double>(bus::ticks_to_ns(t)) / 1000.0; }

void BM_Plant(benchmark::State& state) {
  const auto loaded =
      tools::parse_scenario(plant_scenario(), PBVBUS_SOURCE_DIR "/examples/plant-bench.textproto");
  if (!loaded.ok()) {
    state.SkipWithError(loaded.errors.front().str().c_str());
    return;
  }
  tools::Simulation sim(*loaded.plan, {});
  sim.start();
  const double heap_mb = static_cast<double>(mallinfo2().uordblks) / (1024.0 * 1024.0);
  sim.run_until(bus::kTicksPerSecond);  // every slave in data exchange
  const bus::Ticks slice = 100 * bus::kTicksPerMs;
  const std::uint64_t frames0 = all_frames(sim);
  bus::Ticks t = sim.scheduler().now();
  const double cpu0 = thread_cpu_seconds();
  for (auto _ : state) {
    t += slice;
    sim.run_until(t);
  }
  const double cpu = thread_cpu_seconds() - cpu0;
  const double virt = static_cast<double>(state.iterations()) * static_cast<double>(slice) /
                      static_cast<double>(bus::kTicksPerSecond);
  state.counters["virt_s_per_wall_s"] = benchmark::Counter(virt, benchmark::Counter::kIsRate);
  if (cpu > 0) state.counters["virt_s_per_cpu_s"] = virt / cpu;
  state.counters["frames_per_s"] = benchmark::Counter(static_cast<double>(all_frames(sim) - frames0),
                                                      benchmark::Counter::kIsRate);
  state.counters["maxrss_mb"] = maxrss_mb();
  state.counters["heap_mb"] = heap_mb;
}

void BM_PlantPaced(benchmark::State& state) {
  const auto loaded =
      tools::parse_scenario(plant_scenario(), PBVBUS_SOURCE_DIR "/examples/plant-bench.textproto");
  if (!loaded.ok()) {
    state.SkipWithError(loaded.errors.front().str().c_str());
    return;
  }
  tools::Simulation sim(*loaded.plan, {});
  sim.start();
  sim.run_until(bus::kTicksPerSecond);  // start-up in the fast driver
  bus::PacedRunner& runner = sim.paced_runner(bus::Speed{1, 1});
  const bus::Ticks run = 3 * bus::kTicksPerSecond;
  for (auto _ : state) {
    const bus::Ticks from = sim.scheduler().now();
    LagProbe probe(runner, from + run);
    probe.start(from);
    const double cpu0 = thread_cpu_seconds();
    const auto w0 = std::chrono::steady_clock::now();
    runner.run_for(run);
    const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - w0).count();
    const double cpu = thread_cpu_seconds() - cpu0;
    std::vector<bus::Ticks> v = probe.lags;
    if (v.empty()) {
      state.SkipWithError("no lag samples");
      return;
    }
    std::sort(v.begin(), v.end());
    auto at = [&](double q) { return v[static_cast<std::size_t>(q * static_cast<double>(v.size() - 1))]; };
    state.counters["lag_min_us"] = ticks_to_us(v.front());
    state.counters["lag_median_us"] = ticks_to_us(at(0.5));
    state.counters["lag_p99_us"] = ticks_to_us(at(0.99));
    state.counters["lag_max_us"] = ticks_to_us(v.back());
    state.counters["samples"] = static_cast<double>(v.size());
    state.counters["report_max_lag_us"] =
        static_cast<double>(runner.report().max_lag.count()) / 1000.0;
    state.counters["late_wakeups"] = static_cast<double>(runner.report().late_wakeups);
    state.counters["wakeups_per_s"] =
        wall > 0 ? static_cast<double>(runner.report().wakeups) / wall : 0;
    state.counters["cpu_share"] = wall > 0 ? cpu / wall : 0;
    // No probe event is left in the queue: the last one ran at from + run and scheduled none.
  }
  state.counters["maxrss_mb"] = maxrss_mb();
}

}  // namespace

BENCHMARK(BM_Plant)->Name("BM_Plant/1.5M/24x60")->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_PlantPaced)
    ->Name("BM_Plant/1.5M/24x60/paced")
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime()
    ->Iterations(1);
