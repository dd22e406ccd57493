// Simulation speed: virtual seconds simulated per wall-clock second (design.md "Time": the fast
// driver runs as fast as the CPU allows). Figures and the command that produced them are in
// docs/benchmarks.md.
//
//   BM_SimSpeed/12M/32       one master polling 32 passive stations with 32-octet SRD at
//                            12 Mbit/s, pcapng capture on (to an in-memory sink)
//   BM_SimSpeed/187.5k/32    the same at 187.5 kbit/s
//   BM_SimSpeed/1.5M/125     126 stations on one line: 1 master + 125 passive stations
//   BM_SimSpeed/12M/32/nocapture   (a) without the capture, to see what the capture costs
//
// Counter `virt_s_per_wall_s`: virtual seconds per wall second (goal for 12M/32: >= 100);
// `virt_s_per_cpu_s`: the same per CPU second of the benchmark thread (unaffected by other
// processes competing for the cores).
// Also `frames_per_s` (frames on the wire per wall second) and `events_per_s` (scheduler
// events per wall second).

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

std::string polling_scenario(const char* baud, int passives, int length) {
  std::ostringstream s;
  s << "name: \"bench\"\nseed: 1\nline { name: \"A\" baud: \"" << baud << "\" }\n";
  s << "master { address: 1 line: \"A\" poll { address: [";
  for (int i = 0; i < passives; ++i) s << (i ? ", " : "") << 2 + i;
  s << "] length: " << length << " } }\n";
  for (int i = 0; i < passives; ++i)
    s << "passive_station { address: " << 2 + i << " line: \"A\" response_length: " << length
      << " }\n";
  return s.str();
}

void run_bench(benchmark::State& state, const std::string& text, bool capture) {
  const auto loaded = tools::parse_scenario(text, "bench");
  if (!loaded.ok()) {
    state.SkipWithError(loaded.errors.front().str().c_str());
    return;
  }
  std::uint64_t capture_octets = 0;
  std::unique_ptr<captures::PcapngWriter> writer;
  if (capture) {
    // In-memory sink: counts what would be written, so the encoding cost is measured but not
    // the disk.
    writer = std::make_unique<captures::PcapngWriter>(
        [&capture_octets](std::span<const std::uint8_t> b) {
          capture_octets += b.size();
          return true;
        });
  }
  tools::SimulationOptions opts;
  opts.capture = writer.get();
  tools::Simulation sim(*loaded.plan, opts);
  sim.start();
  // Let the ring form before measuring (claim token, GAP scan of the first rotations).
  sim.run_until(50 * bus::kTicksPerMs);
  const bus::Ticks slice = 100 * bus::kTicksPerMs;
  const std::uint64_t frames0 = sim.stats(0).frames;
  const std::uint64_t events0 = sim.scheduler().events_run();
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
  // The same per CPU second of this thread: what an unloaded core would give (the shared
  // build machine's wall clock includes time the thread waited for a core).
  if (cpu > 0) state.counters["virt_s_per_cpu_s"] = virt / cpu;
  state.counters["frames_per_s"] = benchmark::Counter(
      static_cast<double>(sim.stats(0).frames - frames0), benchmark::Counter::kIsRate);
  state.counters["events_per_s"] = benchmark::Counter(
      static_cast<double>(sim.scheduler().events_run() - events0), benchmark::Counter::kIsRate);
  if (writer) writer->flush();
  benchmark::DoNotOptimize(capture_octets);
}

void BM_SimSpeed_12M_32(benchmark::State& state) {
  run_bench(state, polling_scenario("12M", 32, 32), true);
}
void BM_SimSpeed_187k5_32(benchmark::State& state) {
  run_bench(state, polling_scenario("187.5k", 32, 32), true);
}
void BM_SimSpeed_1M5_125(benchmark::State& state) {
  run_bench(state, polling_scenario("1.5M", 125, 32), true);
}
void BM_SimSpeed_12M_32_nocapture(benchmark::State& state) {
  run_bench(state, polling_scenario("12M", 32, 32), false);
}

}  // namespace

BENCHMARK(BM_SimSpeed_12M_32)->Name("BM_SimSpeed/12M/32")->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_SimSpeed_187k5_32)->Name("BM_SimSpeed/187.5k/32")->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_SimSpeed_1M5_125)->Name("BM_SimSpeed/1.5M/125")->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_SimSpeed_12M_32_nocapture)->Name("BM_SimSpeed/12M/32/nocapture")->Unit(benchmark::kMillisecond)->UseRealTime();
