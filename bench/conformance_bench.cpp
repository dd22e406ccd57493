// docs/conformance.md: what device testing costs (docs/benchmarks.md "Replay and conformance").
//
//   BM_ConformanceBattery/<gsd>  one whole battery (every group, every test) on a shipped GSD's
//                                slave model — fast mode, a fresh model per test
//   BM_MutationScore             `pbvbus conformance --mutation-score` (four GSDs: each battery
//                                once unbroken, then every mutant against its targeted tests)
//   BM_RunDpBasic                `pbvbus run examples/dp-basic.textproto --duration 300ms
//                                --capture F` (the recording)
//   BM_ReplayDpBasic             `pbvbus replay F --scenario examples/dp-basic.textproto --fast`
//                                (the same 300 ms replayed against the same scenario)
// The last two, measured in one run, give the cost of a replay relative to the simulation that
// recorded it; both go through the commands (scenario loading and the report included), as a
// user runs them.

#include <benchmark/benchmark.h>
#include <unistd.h>

#include <cstdio>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include "pbvbus/conformance/battery.hpp"
#include "pbvbus/gsd/gsd.hpp"
#include "pbvbus/tools/commands.hpp"

namespace {

using namespace pbvbus;

const std::string kSrc = PBVBUS_SOURCE_DIR;

struct Dut {
  const char* gsd;
  std::vector<const char*> modules;
};
// The shipped GSDs with the module lists of examples/dp-basic.textproto and gateway.textproto.
const Dut kDuts[] = {
    {"PBVB0A01.gsd", {}},
    {"PBVB0A02.gsd", {"8DI DC24V", "8DO DC24V/0.5A", "2AO U/I 16 bit"}},
    {"PBVB0A03.gsd", {"8DI with process alarm", "8DO DC24V/0.5A", "2AI U/I consistent"}},
    {"PBVB0A04.gsd", {}},
};

void BM_ConformanceBattery(benchmark::State& state) {
  const Dut& d = kDuts[state.range(0)];
  auto loaded = devices::load_gsd(kSrc + "/examples/gsd/" + d.gsd);
  if (!loaded.ok()) {
    state.SkipWithError("GSD does not load");
    return;
  }
  conformance::DutSpec spec;
  spec.gsd = std::make_shared<const devices::GsdFile>(std::move(*loaded.file));
  spec.gsd_path = d.gsd;
  for (const char* m : d.modules) spec.modules.push_back(devices::ModuleChoice::named(m));
  std::size_t tests = 0;
  bool passed = true;
  for (auto _ : state) {
    const auto rep = conformance::run_battery(spec);
    tests = rep.results.size();
    passed = passed && rep.passed();
  }
  if (!passed) state.SkipWithError("the unbroken model failed a test");
  state.SetLabel(std::string(d.gsd) + ", " + std::to_string(tests) + " tests");
  state.counters["tests/s"] =
      benchmark::Counter(static_cast<double>(tests), benchmark::Counter::kIsIterationInvariantRate);
}
BENCHMARK(BM_ConformanceBattery)->DenseRange(0, 3)->Unit(benchmark::kMillisecond);

int command(int (*cmd)(const tools::Args&, std::ostream&, std::ostream&), const tools::Args& args) {
  std::ostringstream out, err;
  return cmd(args, out, err);
}

void BM_MutationScore(benchmark::State& state) {
  int rc = 0;
  for (auto _ : state) rc = command(tools::cmd_conformance, {"--mutation-score"});
  if (rc != 0) state.SkipWithError("mutation score below 100 % or an unbroken model failed");
}
BENCHMARK(BM_MutationScore)->Unit(benchmark::kMillisecond);

std::string capture_path() {
  return "/tmp/pbvbus-bench-dp-basic-" + std::to_string(::getpid()) + ".pcapng";
}

void BM_RunDpBasic(benchmark::State& state) {
  const std::string cap = capture_path();
  int rc = 0;
  for (auto _ : state)
    rc = command(tools::cmd_run, {kSrc + "/examples/dp-basic.textproto", "--fast", "--duration",
                                  "300ms", "--capture", cap, "--quiet"});
  if (rc != 0) state.SkipWithError("pbvbus run failed");
}
BENCHMARK(BM_RunDpBasic)->Unit(benchmark::kMillisecond);

void BM_ReplayDpBasic(benchmark::State& state) {
  const std::string cap = capture_path();
  // The recording BM_RunDpBasic made (made here too when run alone with a filter).
  if (command(tools::cmd_run, {kSrc + "/examples/dp-basic.textproto", "--fast", "--duration",
                               "300ms", "--capture", cap, "--quiet"}) != 0) {
    state.SkipWithError("pbvbus run failed");
    return;
  }
  int rc = 0;
  for (auto _ : state)
    rc = command(tools::cmd_replay,
                 {cap, "--scenario", kSrc + "/examples/dp-basic.textproto", "--fast", "--json"});
  std::remove(cap.c_str());
  if (rc != 0) state.SkipWithError("replay found differences");
}
BENCHMARK(BM_ReplayDpBasic)->Unit(benchmark::kMillisecond);

}  // namespace
