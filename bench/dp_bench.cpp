// DP master system speed and footprint (docs/benchmarks.md): one DP master class 1 (address 0)
// and 125 DP slaves (addresses 1..125), each with 32 octets of inputs and 32 of outputs
// (one configuration identifier 0xFF: 16 words in and out, consistent; a minimal GSD with that
// one module is parsed from text below; inputs = a DP cycle counter), at 12 Mbit/s, built
// from the same tools::DpMasterNode / DpSlaveNode the scenario runner uses. Bus parameters:
// the 12 Mbit/s defaults with the TTR the scenario loader derives (tools::dp_ttr).
//
//   BM_DpSystem/12M/125x32   counter `virt_s_per_wall_s` = virtual seconds per wall second
//                            (goal >= 50), `dp_cycle_us` = median DP cycle of slave 1,
//                            `bytes_per_slave` = memory per slave (method below).
//
// Memory per slave, method: heap bytes in use (glibc mallinfo2().uordblks, net of frees, incl.
// malloc's per-chunk overhead) added by building one master and 125 slaves, minus the same for
// one master and 1 slave, divided by 124. This counts
// everything a slave adds (slave node, engine, application with its process image, passive
// station, master-side slave entry and image) and nothing of the line or the scheduler.
// `virt_s_per_cpu_s`: virtual seconds per CPU second of the process (std::clock), the figure of
// one unloaded core on the shared build machine.
//
// Figures and the command that produced them are in docs/benchmarks.md.

#include <benchmark/benchmark.h>

#include <malloc.h>

#include <ctime>
#include <stdexcept>
#include <memory>
#include <vector>

#include "pbvbus/bus/line.hpp"
#include "pbvbus/bus/scheduler.hpp"
#include "pbvbus/gsd/gsd.hpp"
#include "pbvbus/scenario/dp_plan.hpp"
#include "pbvbus/simulation/dp_system.hpp"

namespace {
/// Heap bytes in use (glibc mallinfo2: allocated chunks, net of frees).
std::uint64_t heap_in_use() { return mallinfo2().uordblks; }
}  // namespace

namespace {

using namespace pbvbus;

constexpr const char* kGsd =
    "#Profibus_DP\nGSD_Revision = 5\nVendor_Name = \"pbvbus\"\nModel_Name = \"bench 32/32\"\n"
    "Ident_Number = 0x0AFF\nProtocol_Ident = 0\nStation_Type = 0\n12M_supp = 1\n"
    "MaxTsdr_12M = 800\nMin_Slave_Intervall = 1\nModular_Station = 0\n"
    "Module = \"32 in/32 out\" 0xFF\nEndModule\n";

struct DpSystem {
  bus::Scheduler sched;
  std::unique_ptr<bus::Line> line;
  std::vector<tools::DpSlavePlan> plans;
  std::unique_ptr<tools::DpMasterNode> master;
  std::vector<std::unique_ptr<tools::DpSlaveNode>> slaves;

  explicit DpSystem(int n) {
    auto parsed = devices::parse_gsd(kGsd, "bench.gsd");
    if (!parsed.ok()) throw std::runtime_error(parsed.errors.front().to_string());
    auto gsd = std::make_shared<const devices::GsdFile>(std::move(*parsed.file));
    fdl::BusParams bp = fdl::BusParams::defaults(bus::Baud::k12M);
    std::vector<std::pair<std::size_t, std::size_t>> io(static_cast<std::size_t>(n), {32, 32});
    bp.ttr = tools::dp_ttr(bp, io);
    line = std::make_unique<bus::Line>(sched, "DP", bus::Baud::k12M, 1);
    tools::DpMasterPlan mp;
    mp.params.address = 0;
    for (int i = 0; i < n; ++i) {
      tools::DpSlavePlan sp;
      sp.address = static_cast<std::uint8_t>(1 + i);
      sp.master = 0;
      sp.gsd = gsd;
      sp.gsd_modules = {0};
      sp.config.ident = 0x0AFF;
      sp.config.modules = {{{0xFF}, "32 in/32 out"}};
      sp.config.min_slave_interval = 1;
      sp.params.address = sp.address;
      sp.params.ident = sp.config.ident;
      sp.params.modules = sp.config.modules;
      sp.params.min_tsdr = static_cast<std::uint8_t>(bp.min_tsdr);
      sp.inputs = sp.outputs = 32;
      plans.push_back(std::move(sp));
      mp.slaves.push_back(i);
    }
    master = std::make_unique<tools::DpMasterNode>(mp, plans, bp);
    line->attach(master->station(), "dp master 0");
    for (const auto& sp : plans) {
      slaves.push_back(std::make_unique<tools::DpSlaveNode>(sp, bp));
      line->attach(slaves.back()->station(), "dp slave");
    }
  }
};

void BM_DpSystem(benchmark::State& state) {
  // Memory: 125 slaves versus 1.
  const std::uint64_t a0 = heap_in_use();
  auto one = std::make_unique<DpSystem>(1);
  const std::uint64_t a1 = heap_in_use();
  const std::uint64_t b0 = heap_in_use();
  DpSystem sys(125);
  const std::uint64_t b1 = heap_in_use();
  one.reset();
  const double bytes_per_slave =
      static_cast<double>((b1 - b0) - (a1 - a0)) / 124.0;

  sys.line->start();
  // Start-up of 125 slaves: 4 passes of start-up requests, then data exchange everywhere.
  sys.sched.run_until(200 * bus::kTicksPerMs);
  int in_dx = 0;
  for (const auto& s : sys.slaves) in_dx += s->engine().state() == dp::SlaveState::DataExch;
  if (in_dx != 125) {
    state.SkipWithError("not every slave reached Data_Exch");
    return;
  }
  const bus::Ticks slice = 100 * bus::kTicksPerMs;
  bus::Ticks t = sys.sched.now();
  const std::clock_t c0 = std::clock();
  for (auto _ : state) {
    t += slice;
    sys.sched.run_until(t);
  }
  const double cpu_s = static_cast<double>(std::clock() - c0) / CLOCKS_PER_SEC;
  const double virt = static_cast<double>(state.iterations()) * static_cast<double>(slice) /
                      static_cast<double>(bus::kTicksPerSecond);
  state.counters["virt_s_per_wall_s"] = benchmark::Counter(virt, benchmark::Counter::kIsRate);
  state.counters["dp_cycle_us"] =
      static_cast<double>(bus::ticks_to_ns(sys.master->master().cycle_median(1))) / 1000.0;
  state.counters["bytes_per_slave"] = bytes_per_slave;
  if (cpu_s > 0) state.counters["virt_s_per_cpu_s"] = virt / cpu_s;
}

}  // namespace

BENCHMARK(BM_DpSystem)->Name("BM_DpSystem/12M/125x32")->Unit(benchmark::kMillisecond)->UseRealTime();
