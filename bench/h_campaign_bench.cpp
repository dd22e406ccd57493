// The full seeded H-system fault campaign (docs/h-system.md; devices/h_campaign.hpp): >= 1000
// injections of CPU (power, STOP, comparison error, one-sided OB 121, operator swap), sync-link
// (one fibre, both fibres at once), IM, line (short circuit) and DP master module faults, the
// link-up/update faults (master HOLD, load-memory error, sync error, update timeout, standby
// lost in LINK-UP, structural change, swap with a changed parameter) and their repairs, on two
// lines with the CPU pair, two switched stations (PBVB0A10, PBVB0A11) and one one-sided slave
// per line, checked by the campaign's independent observer.
//
//   BM_HCampaign/<seed>/<steps>/<baud>   baud 0 = 1.5 Mbit/s, 1 = 12 Mbit/s (PBVB0A11's GSD has
//     no 12M_supp: the station model refuses it and the run is skipped). Counters: faults,
//     repairs, pulses, mismatches, events (observed) and expected_events, samples, dx,
//     split_frames, second_master_frames, stray_dx, role_swaps, defective, comparison_stops,
//     update_timeouts, refusals, diag_checks, virt_s, virt_s_per_wall_s, virt_s_per_cpu_s
//     (std::clock), max_settle_ms, im_switchovers, late_switchovers, early_switchovers,
//     max_im_ms (the IM's own switchover time, S5).
//   One iteration (the campaign is one long run); mismatches and pulses are printed to stderr.
//
// PBVBUS_HCAMPAIGN_SEED and PBVBUS_HCAMPAIGN_STEPS override the seed and the number of
// injections (sweeps, reproductions). The GSD files are found as in switchover_campaign_bench.
#include <benchmark/benchmark.h>

#include <cstdlib>
#include <ctime>
#include <exception>
#include <filesystem>
#include <iostream>
#include <string>

#include "pbvbus/s7h/h_campaign.hpp"

namespace {

std::string h_gsd_dir() {
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

void BM_HCampaign(benchmark::State& state) {
  using namespace pbvbus;
  devices::HCampaignOptions o;
  o.seed = static_cast<std::uint64_t>(state.range(0));
  o.steps = static_cast<int>(state.range(1));
  o.baud = state.range(2) == 1 ? bus::Baud::k12M : bus::Baud::k1_5M;
  // Bad values are reported, not thrown.
  if (const char* e = std::getenv("PBVBUS_HCAMPAIGN_SEED")) {
    char* end = nullptr;
    const unsigned long long v = std::strtoull(e, &end, 10);
    if (end == e || *end != '\0') {
      state.SkipWithError("PBVBUS_HCAMPAIGN_SEED is not a number");
      return;
    }
    o.seed = v;
  }
  if (const char* e = std::getenv("PBVBUS_HCAMPAIGN_STEPS")) {
    char* end = nullptr;
    const long v = std::strtol(e, &end, 10);
    if (end == e || *end != '\0' || v < 1 || v > 1000000) {
      state.SkipWithError("PBVBUS_HCAMPAIGN_STEPS is not a number in 1..1000000");
      return;
    }
    o.steps = static_cast<int>(v);
  }
  state.SetLabel("seed " + std::to_string(o.seed) + (o.baud == bus::Baud::k12M ? " 12M" : " 1.5M"));
  o.gsd_dir = h_gsd_dir();
  devices::HCampaignResult r;
  double cpu_s = 0;
  for (auto _ : state) {
    const std::clock_t c0 = std::clock();
    try {
      r = devices::run_h_campaign(o);
    } catch (const std::exception& e) {
      state.SkipWithError(e.what());
      return;
    }
    cpu_s = static_cast<double>(std::clock() - c0) / CLOCKS_PER_SEC;
    benchmark::DoNotOptimize(r.pulses);
  }
  std::cerr << r.summary() << "\n";
  for (const auto& m : r.mismatches) std::cerr << "  mismatch: " << m << "\n";
  for (const auto& p : r.pulse_reports) std::cerr << "  pulse: " << p << "\n";
  const double virt = static_cast<double>(r.simulated) / bus::kTicksPerSecond;
  state.counters["faults"] = r.faults;
  state.counters["repairs"] = r.repairs;
  state.counters["pulses"] = static_cast<double>(r.pulses);
  state.counters["mismatches"] = static_cast<double>(r.mismatches.size());
  state.counters["events"] = r.observed_events;
  state.counters["expected_events"] = r.expected_events;
  state.counters["samples"] = static_cast<double>(r.output_samples);
  state.counters["dx"] = static_cast<double>(r.dx_requests);
  state.counters["split_frames"] = static_cast<double>(r.split_frames);
  state.counters["second_master_frames"] = static_cast<double>(r.second_master_frames);
  state.counters["stray_dx"] = static_cast<double>(r.stray_dx);
  state.counters["role_swaps"] = r.role_swaps;
  state.counters["defective"] = r.defective;
  state.counters["comparison_stops"] = r.comparison_stops;
  state.counters["update_timeouts"] = r.update_timeouts;
  state.counters["refusals"] = r.refusals;
  state.counters["diag_checks"] = r.diag_checks;
  state.counters["virt_s"] = virt;
  state.counters["virt_s_per_wall_s"] = r.wall_seconds > 0 ? virt / r.wall_seconds : 0;
  state.counters["virt_s_per_cpu_s"] = cpu_s > 0 ? virt / cpu_s : 0;
  state.counters["max_settle_ms"] = static_cast<double>(r.max_settle) / bus::kTicksPerMs;
  // The IM's own switchover time (S5, docs/h-campaign.md "With the IM's own switchover time").
  state.counters["im_switchovers"] = static_cast<double>(r.im_switchovers);
  state.counters["late_switchovers"] = r.late_switchovers;
  state.counters["early_switchovers"] = r.early_switchovers;
  state.counters["max_im_ms"] = static_cast<double>(r.max_im_switchover) / bus::kTicksPerMs;
}
BENCHMARK(BM_HCampaign)->Args({1, 1000, 0})->Iterations(1)->Unit(benchmark::kSecond)->UseRealTime();

}  // namespace
