// The H-system's user program (docs/h-system.md; devices/h_program.hpp,
// devices/h_redundant_execution.hpp). Figures go to docs/benchmarks.md ("H programs").
//
//   BM_HProgramScan          one devices::Program::scan() (one OB 1) of a program with
//                            64 copy networks (8 octets each: IB 8i → QB 8i, 512 octets),
//                            16 counters (width 2 at QB 512 + 2i, period 100 ms, each with a
//                            pulse bit in QB 544/545) and 16 discrepancy monitors (4 octets:
//                            IB 512 + 4i vs IB 576 + 4i → QB 576 + 4i), PII and PIQ 1 KB each;
//                            virtual time advances 10 ms per scan (a counter boundary every
//                            10th scan, the pulses switch). Inputs of the monitors agree except
//                            monitor 0, which differs every other 64 scans (7960 raised/gone).
//   BM_HRedundantScan        devices::RedundantExecution::scan() of the same program on both
//                            CPUs, PII and PIQ 2 KB each (memory 576 octets), with the
//                            comparison of PIQ and memory (2 624 octets) after every scan.
//
// Counters: `scans_per_s` (wall). Each iteration is one scan call.
#include <benchmark/benchmark.h>

#include <algorithm>
#include <cstdint>
#include <vector>

#include "pbvbus/s7h/h_program.hpp"
#include "pbvbus/s7h/h_redundant_execution.hpp"

namespace {

using namespace pbvbus;
using devices::ProgramSpec;

ProgramSpec bench_program() {
  ProgramSpec s;
  s.scan_time = 10 * bus::kTicksPerMs;
  for (std::uint32_t i = 0; i < 64; ++i) s.copies.push_back({8 * i, 8 * i, 8});
  for (std::uint32_t i = 0; i < 16; ++i) {
    devices::CounterNetwork c;
    c.output = 512 + 2 * i;
    c.width = 2;
    c.period = 100 * bus::kTicksPerMs;
    c.step = i + 1;
    c.pulse_output = 544 + i / 8;
    c.pulse_bit = static_cast<std::uint8_t>(i % 8);
    c.pulse_high = 20 * bus::kTicksPerMs;
    s.counters.push_back(c);
  }
  for (std::uint32_t i = 0; i < 16; ++i) {
    devices::DiscrepancyNetwork m;
    m.input_a = 512 + 4 * i;
    m.input_b = 576 + 4 * i;
    m.length = 4;
    m.to_output = 576 + 4 * i;
    m.discrepancy_time = 30 * bus::kTicksPerMs;
    s.monitors.push_back(m);
  }
  return s;
}

std::vector<std::uint8_t> inputs(std::size_t size, std::int64_t scan) {
  std::vector<std::uint8_t> in(size);
  for (std::size_t i = 0; i < size; ++i) in[i] = static_cast<std::uint8_t>(i * 7);
  for (std::size_t i = 0; i < 64; ++i) in[576 + i] = in[512 + i];  // monitors agree
  if ((scan / 64) % 2 == 1) in[576] ^= 0x01;                      // monitor 0 differs
  return in;
}

void BM_HProgramScan(benchmark::State& state) {
  const devices::Program p(bench_program(), 1024, 1024);
  auto img = p.make_image();
  const auto agree = inputs(1024, 0);
  const auto differ = inputs(1024, 64);
  std::vector<devices::ProgramEvent> events;
  std::int64_t n = 0;
  for (auto _ : state) {
    const auto& in = (n / 64) % 2 == 1 ? differ : agree;
    std::copy(in.begin(), in.end(), img.pii().begin());
    events.clear();
    benchmark::DoNotOptimize(p.scan(img, n * 10 * bus::kTicksPerMs, events));
    benchmark::DoNotOptimize(img.piq().data());
    ++n;
  }
  state.counters["scans_per_s"] = benchmark::Counter(static_cast<double>(n),
                                                     benchmark::Counter::kIsRate);
}
BENCHMARK(BM_HProgramScan);

void BM_HRedundantScan(benchmark::State& state) {
  devices::RedundantExecution x(bench_program(), 2048, 2048);
  const auto agree = inputs(2048, 0);
  const auto differ = inputs(2048, 64);
  std::int64_t n = 0;
  bool ok = true;
  for (auto _ : state) {
    x.set_inputs((n / 64) % 2 == 1 ? differ : agree);
    const auto r = x.scan(n * 10 * bus::kTicksPerMs, {true, true}, 0);
    ok = ok && r.compared && !r.comparison_error;
    benchmark::DoNotOptimize(r);
    ++n;
  }
  if (!ok) state.SkipWithError("comparison error in a clean run");
  state.counters["scans_per_s"] = benchmark::Counter(static_cast<double>(n),
                                                     benchmark::Counter::kIsRate);
}
BENCHMARK(BM_HRedundantScan);

}  // namespace
