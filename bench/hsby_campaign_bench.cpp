// The seeded Quantum Hot Standby fault campaign on a real DP line (docs/quantum-hsby-campaign.md;
// controllers/quantum hsby_campaign.hpp): primary power / CPU stop, standby power, the primary's
// key to Off Line (planned handover) and to Xfer (ignored), the override's run bits 0/0, fibre
// cut, logic mismatch and standby program update, each with its repair, checked by the
// campaign's independent observer (slave side, a Modbus host on unit 1, the switchover records).
//
//   BM_HsbyCampaign/<seed>/<steps>/<slaves>/<baud>   baud 0 = 1.5 Mbit/s, 1 = 12 Mbit/s,
//     2 = 187.5 kbit/s. Counters: faults, repairs, switchovers, late, pulses, stale_outputs,
//     stale_reads, no_answer, wrong_rack, dx_exits, mismatches, samples, polls, the takeover
//     distribution (takeover_{min,median,p99,max}_ms over every switchover, failure_* over the
//     primary failures), virt_s, virt_s_per_wall_s, virt_s_per_cpu_s (std::clock).
//   One iteration; the summary (with any finding) goes to stderr.
//
// PBVBUS_QCAMPAIGN_SEED and PBVBUS_QCAMPAIGN_STEPS override the seed and the injections.
#include <benchmark/benchmark.h>

#include <cstdlib>
#include <ctime>
#include <exception>
#include <iostream>
#include <string>

#include "pbvbus/quantum/hsby_campaign.hpp"

namespace {

bool qc_env_number(const char* name, long long lo, long long hi, long long& out) {
  const char* e = std::getenv(name);
  if (e == nullptr) return true;
  char* end = nullptr;
  const long long v = std::strtoll(e, &end, 10);
  if (end == e || *end != '\0' || v < lo || v > hi) return false;
  out = v;
  return true;
}

void BM_HsbyCampaign(benchmark::State& state) {
  using namespace pbvbus;
  quantum::HsbyCampaignOptions o;
  long long seed = state.range(0), steps = state.range(1);
  if (!qc_env_number("PBVBUS_QCAMPAIGN_SEED", 0, (1LL << 62), seed) ||
      !qc_env_number("PBVBUS_QCAMPAIGN_STEPS", 1, 10000000, steps)) {
    state.SkipWithError("PBVBUS_QCAMPAIGN_SEED / _STEPS: not a number in range");
    return;
  }
  o.seed = static_cast<std::uint64_t>(seed);
  o.steps = static_cast<int>(steps);
  o.slaves = static_cast<int>(state.range(2));
  o.baud = state.range(3) == 1   ? bus::Baud::k12M
           : state.range(3) == 2 ? bus::Baud::k187_5
                                 : bus::Baud::k1_5M;
  state.SetLabel("seed " + std::to_string(o.seed) + ", " + std::to_string(o.slaves) + " slaves");
  quantum::HsbyCampaignResult r;
  double cpu_s = 0;
  for (auto _ : state) {
    const std::clock_t c0 = std::clock();
    try {
      r = quantum::run_hsby_campaign(o);
    } catch (const std::exception& e) {
      state.SkipWithError(e.what());
      return;
    }
    cpu_s = static_cast<double>(std::clock() - c0) / CLOCKS_PER_SEC;
    benchmark::DoNotOptimize(r.pulses);
  }
  std::cerr << r.summary() << "\n";
  const double virt = static_cast<double>(r.simulated) / bus::kTicksPerSecond;
  state.counters["faults"] = r.faults;
  state.counters["repairs"] = r.repairs;
  state.counters["switchovers"] = r.switchovers;
  state.counters["late"] = r.late_switchovers;
  state.counters["pulses"] = static_cast<double>(r.pulses);
  state.counters["stale_outputs"] = static_cast<double>(r.stale_outputs);
  state.counters["stale_reads"] = static_cast<double>(r.stale_reads);
  state.counters["no_answer"] = static_cast<double>(r.modbus_no_answer);
  state.counters["wrong_rack"] = static_cast<double>(r.wrong_rack);
  state.counters["dx_exits"] = static_cast<double>(r.dx_exits);
  state.counters["mismatches"] = static_cast<double>(r.mismatches.size());
  state.counters["samples"] = static_cast<double>(r.slave_samples);
  state.counters["polls"] = static_cast<double>(r.modbus_polls);
  state.counters["takeover_min_ms"] = r.takeover_all.min_ms;
  state.counters["takeover_median_ms"] = r.takeover_all.median_ms;
  state.counters["takeover_p99_ms"] = r.takeover_all.p99_ms;
  state.counters["takeover_max_ms"] = r.takeover_all.max_ms;
  state.counters["failure_median_ms"] = r.takeover_unplanned.median_ms;
  state.counters["failure_p99_ms"] = r.takeover_unplanned.p99_ms;
  state.counters["failure_max_ms"] = r.takeover_unplanned.max_ms;
  state.counters["virt_s"] = virt;
  state.counters["virt_s_per_wall_s"] = r.wall_seconds > 0 ? virt / r.wall_seconds : 0;
  state.counters["virt_s_per_cpu_s"] = cpu_s > 0 ? virt / cpu_s : 0;
}
BENCHMARK(BM_HsbyCampaign)
    ->Args({1, 2000, 8, 0})
    ->Iterations(1)
    ->Unit(benchmark::kSecond)
    ->UseRealTime();

}  // namespace
