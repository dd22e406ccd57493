// Cost per frame as the number of stations on a line grows: what each attachment adds to the
// per-frame path (receiver masks, idle-time bookkeeping, filters). One FDL master polling N
// passive stations with 32-octet SRD at 12 Mbit/s, capture on (in-memory sink), as case (a) of
// bench/sim_speed_bench.cpp but for N = 1, 8, 32, 64, 125. Figures and the command are in
// docs/benchmarks.md ("Twice the simulation speed").
//
//   BM_StationSweep/12M/N   counters: cpu_ns_per_frame (CPU time of the benchmark thread per
//                           frame on the wire; the slope over N is the per-attachment cost),
//                           virt_s_per_cpu_s, frames_per_s (per wall second).

#include <benchmark/benchmark.h>

#include <ctime>
#include <memory>
#include <sstream>
#include <string>

#include "pbvbus/captures/pcapng_writer.hpp"
#include "pbvbus/scenario/scenario.hpp"
#include "pbvbus/simulation/simulation.hpp"

namespace {

using namespace pbvbus;

double thread_cpu_seconds() {
  timespec ts{};
  ::clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return static_cast<double>(ts.tv_sec) + static_cast<double>(ts.tv_nsec) * 1e-9;
}

void BM_StationSweep(benchmark::State& state) {
  const int n = static_cast<int>(state.range(0));
  std::ostringstream s;
  s << "name: \"sweep\"\nseed: 1\nline { name: \"A\" baud: \"12M\" }\n";
  s << "master { address: 1 line: \"A\" poll { address: [";
  for (int i = 0; i < n; ++i) s << (i ? ", " : "") << 2 + i;
  s << "] length: 32 } }\n";
  for (int i = 0; i < n; ++i)
    s << "passive_station { address: " << 2 + i << " line: \"A\" response_length: 32 }\n";
  const auto loaded = tools::parse_scenario(s.str(), "sweep");
  if (!loaded.ok()) {
    state.SkipWithError(loaded.errors.front().str().c_str());
    return;
  }
  std::uint64_t octets = 0;
  captures::PcapngWriter writer([&octets](std::span<const std::uint8_t> b) {
    octets += b.size();
    return true;
  });
  tools::SimulationOptions opts;
  opts.capture = &writer;
  tools::Simulation sim(*loaded.plan, opts);
  sim.start();
  sim.run_until(50 * bus::kTicksPerMs);
  const bus::Ticks slice = 100 * bus::kTicksPerMs;
  const std::uint64_t frames0 = sim.stats(0).frames;
  bus::Ticks t = sim.scheduler().now();
  const double cpu0 = thread_cpu_seconds();
  for (auto _ : state) {
    t += slice;
    sim.run_until(t);
  }
  const double cpu = thread_cpu_seconds() - cpu0;
  const auto frames = static_cast<double>(sim.stats(0).frames - frames0);
  const double virt = static_cast<double>(state.iterations()) * static_cast<double>(slice) /
                      static_cast<double>(bus::kTicksPerSecond);
  if (frames > 0) state.counters["cpu_ns_per_frame"] = cpu * 1e9 / frames;
  if (cpu > 0) state.counters["virt_s_per_cpu_s"] = virt / cpu;
  state.counters["frames_per_s"] = benchmark::Counter(frames, benchmark::Counter::kIsRate);
  writer.flush();
  benchmark::DoNotOptimize(octets);
}

}  // namespace

BENCHMARK(BM_StationSweep)
    ->Name("BM_StationSweep/12M")
    ->Arg(1)
    ->Arg(8)
    ->Arg(32)
    ->Arg(64)
    ->Arg(125)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
