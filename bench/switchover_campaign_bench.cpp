// The full seeded random fault campaign for switched I/O (docs/redundancy.md;
// devices/switchover_campaign.hpp): >= 1000 faults and repairs drawn over interfaces (F10, F11,
// F24), masters (F9, F14 stop), lines (F13 cut, F14 short) and their repairs, on two lines at
// 1.5 Mbit/s with 4 switched stations (one of them PBVB0A11) and one one-sided slave per line,
// checked by the campaign's observer (its own reachability model, the S7 event rules, the
// backplane sampled after every frame on both lines).
//
//   BM_SwitchoverCampaign/<seed>/<faults>   counters: faults, repairs, pulses, mismatches,
//     events, expected_events, samples, switchovers, alarms raised/delivered/lost/duplicated,
//     virt_s (virtual seconds simulated), virt_s_per_wall_s, virt_s_per_cpu_s (std::clock), max
//     fault/repair latency (ms).
//   One iteration (the campaign is one long run); mismatches are printed to stderr.
//
// PBVBUS_CAMPAIGN_SEED and PBVBUS_CAMPAIGN_FAULTS override the seed and the number of
// injections (sweeps, reproductions).
// The GSD files are found through PBVBUS_GSD_DIR, else examples/gsd under the current
// directory, else <executable>/../../examples/gsd (build/bin/pbvbus_bench in the source tree).
// Figures and the command are in docs/benchmarks.md.
#include <benchmark/benchmark.h>

#include <cstdlib>
#include <ctime>
#include <filesystem>
#include <iostream>
#include <string>

#include "pbvbus/switched_io/switchover_campaign.hpp"

namespace {

std::string gsd_dir() {
  namespace fs = std::filesystem;
  if (const char* e = std::getenv("PBVBUS_GSD_DIR")) return e;
  if (fs::exists("examples/gsd/PBVB0A10.gsd")) return "examples/gsd";
  std::error_code ec;
  const fs::path exe = fs::read_symlink("/proc/self/exe", ec);
  if (!ec) {
    const fs::path d = exe.parent_path().parent_path().parent_path() / "examples" / "gsd";
    if (fs::exists(d / "PBVB0A10.gsd")) return d.string();
  }
  return "examples/gsd";
}

void BM_SwitchoverCampaign(benchmark::State& state) {
  using namespace pbvbus;
  devices::CampaignOptions o;
  o.seed = static_cast<std::uint64_t>(state.range(0));
  o.faults = static_cast<int>(state.range(1));
  // Reproductions and sweeps without rebuilding: PBVBUS_CAMPAIGN_SEED / _FAULTS override.
  if (const char* e = std::getenv("PBVBUS_CAMPAIGN_SEED")) o.seed = std::stoull(e);
  if (const char* e = std::getenv("PBVBUS_CAMPAIGN_FAULTS")) o.faults = std::stoi(e);
  state.SetLabel("seed " + std::to_string(o.seed));
  o.gsd_dir = gsd_dir();
  devices::CampaignResult r;
  double cpu_s = 0;
  for (auto _ : state) {
    const std::clock_t c0 = std::clock();
    r = devices::run_campaign(o);
    cpu_s = static_cast<double>(std::clock() - c0) / CLOCKS_PER_SEC;
    benchmark::DoNotOptimize(r.pulses);
  }
  std::cerr << r.summary() << "\n";
  for (const auto& m : r.mismatches) std::cerr << "  mismatch: " << m << "\n";
  for (const auto& p : r.pulse_reports) std::cerr << "  pulse: " << p << "\n";
  int events = 0;
  for (const auto& [c, n] : r.events) events += n;
  const double virt = static_cast<double>(r.simulated) / bus::kTicksPerMs / 1000.0;
  state.counters["faults"] = r.faults;
  state.counters["repairs"] = r.repairs;
  state.counters["pulses"] = static_cast<double>(r.pulses);
  state.counters["mismatches"] = static_cast<double>(r.mismatches.size());
  state.counters["events"] = events;
  state.counters["expected_events"] = r.expected_events;
  state.counters["samples"] = static_cast<double>(r.output_samples);
  state.counters["switchovers"] = static_cast<double>(r.switchovers);
  state.counters["alarms_raised"] = r.alarms_raised;
  state.counters["alarms_delivered"] = r.alarms_delivered;
  state.counters["alarms_lost"] = r.alarms_lost;
  state.counters["alarms_dup"] = r.alarms_duplicated;
  state.counters["virt_s"] = virt;
  state.counters["virt_s_per_wall_s"] = r.wall_seconds > 0 ? virt / r.wall_seconds : 0;
  state.counters["virt_s_per_cpu_s"] = cpu_s > 0 ? virt / cpu_s : 0;
  state.counters["max_fault_lat_ms"] = static_cast<double>(r.max_fault_latency) / bus::kTicksPerMs;
  state.counters["max_repair_lat_ms"] =
      static_cast<double>(r.max_repair_latency) / bus::kTicksPerMs;
}
BENCHMARK(BM_SwitchoverCampaign)
    ->Args({1, 1000})
    ->Iterations(1)
    ->Unit(benchmark::kSecond)
    ->UseRealTime();

}  // namespace
