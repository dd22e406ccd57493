// Switched I/O (docs/redundancy.md): the redundant DP master system on two lines against the same stations
// as plain DP slaves on one line, measured in one run so that the ratio means something on the
// shared 2-core machine. Figures and the command are in docs/benchmarks.md ("Switched I/O").
//
//   BM_SwitchedIo/12M/2x32   two bus::Lines at 12 Mbit/s; devices::RedundantMasterSystemModel
//                            (master address 1 on both lines, redundancy::MasterSystem);
//                            32 devices::SwitchedStationModel (PBVB0A10.gsd, modules
//                            "16DI DC24V" + "16DO DC24V/0.5A": 2 octets in, 2 out) at 2..33,
//                            each attached to both lines.
//   BM_PlainSlaves/12M/32    the same 32 stations as plain DP slaves (devices::SlaveModel from
//                            the same GSD and modules, Set_Prm without a PrmCmd block) on ONE
//                            line, one dp::Master on an fdl::ActiveStation (address 1).
//
// The program is the same in both: at every token receipt of a master it increments one 16-bit
// counter and writes it into the output module of every station (redundant: through
// MasterSystem::write_outputs, i.e. into both lines' images, as
// tests/devices/switched_io/redundant_master_system_test.cpp does; plain: into the master's image). In the
// redundant system it runs at the token receipts of either line.
//
// Bus parameters, both systems: fdl::BusParams::defaults(12M), hsa = 33 (the highest address on
// the line), TTR = tools::dp_ttr for 32 slaves with 2 octets out and 2 in (as the scenario
// loader derives it). PBVB0A10 states MaxTsdr_12M = 800, the 12M default max TSDR.
//
// Set-up: build, start the lines, run in 50 ms steps (at most 2 s of virtual time) until every
// station is in data exchange (redundant: with both masters, with line A the active channel in
// the MasterSystem and the primary interface in the station); state.SkipWithError otherwise.
// Then each iteration simulates 100 ms. After the loop: no station left data exchange, no
// switchover and no S7 event (else SkipWithError).
//
// Counters: `virt_s_per_wall_s` (virtual s per wall s), `virt_s_per_cpu_s` (per CPU s of the
// benchmark thread), `dp_cycle_us` (median DP cycle of station 2 on line A),
// `dp_cycles_per_s` (DP cycles of station 2 per wall second, summed over the lines: one per
// master pass), `dx_per_s` (successful Data_Exchange transactions, all stations and lines, per
// wall second), `startup_ms` (virtual time until the check above first held) and
// `bytes_per_station` (as bench/dp_bench.cpp: heap in use, glibc mallinfo2().uordblks, added by
// building the 32-station system minus the same for a 1-station system, divided by 31; counts
// the station model(s) and the master-side entries and images of both lines, nothing of the
// lines or the scheduler).

#include <benchmark/benchmark.h>
#include <malloc.h>
#include <time.h>

#include <array>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <functional>
#include <memory>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "pbvbus/bus/line.hpp"
#include "pbvbus/bus/scheduler.hpp"
#include "pbvbus/gsd/gsd.hpp"
#include "pbvbus/switched_io/redundant_master_system.hpp"
#include "pbvbus/slaves/slave_model.hpp"
#include "pbvbus/switched_io/switched_station.hpp"
#include "pbvbus/dp/master.hpp"
#include "pbvbus/fdl/active_station.hpp"
#include "pbvbus/scenario/dp_plan.hpp"

namespace {

using namespace pbvbus;

constexpr bus::Baud kBaud = bus::Baud::k12M;
constexpr bus::Ticks kMs = bus::kTicksPerMs;
constexpr int kStations = 32;
constexpr std::uint8_t kFirst = 2;  // station addresses 2..33
constexpr std::uint8_t kMaster = 1;
constexpr std::size_t kOutModule = 1;  // "16DO DC24V/0.5A"

std::uint64_t heap_in_use() {
  return mallinfo2().uordblks;
}

double thread_cpu_seconds() {
  timespec ts{};
  ::clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return static_cast<double>(ts.tv_sec) + static_cast<double>(ts.tv_nsec) * 1e-9;
}

/// examples/gsd of the source tree: $PBVBUS_GSD_DIR, else next to the binary's build tree
/// (build/bin/pbvbus_bench -> ../../examples/gsd), else relative to the working directory.
std::string gsd_path(const char* name) {
  namespace fs = std::filesystem;
  std::vector<fs::path> dirs;
  if (const char* env = std::getenv("PBVBUS_GSD_DIR")) dirs.emplace_back(env);
  std::error_code ec;
  const fs::path exe = fs::read_symlink("/proc/self/exe", ec);
  if (!ec) dirs.push_back(exe.parent_path().parent_path().parent_path() / "examples" / "gsd");
  dirs.emplace_back("examples/gsd");
  dirs.emplace_back("../examples/gsd");
  for (const auto& d : dirs)
    if (fs::exists(d / name, ec)) return (d / name).string();
  throw std::runtime_error(std::string("GSD not found (set PBVBUS_GSD_DIR): ") + name);
}

const devices::GsdFile& switched_gsd() {
  static const devices::GsdFile gsd = [] {
    auto r = devices::load_gsd(gsd_path("PBVB0A10.gsd"));
    if (!r.ok()) throw std::runtime_error(r.errors.front().to_string());
    return *r.file;
  }();
  return gsd;
}

std::vector<devices::ModuleChoice> modules() {
  return {devices::ModuleChoice::named("16DI DC24V"),
          devices::ModuleChoice::named("16DO DC24V/0.5A")};
}

fdl::BusParams bus_params() {
  fdl::BusParams bp = fdl::BusParams::defaults(kBaud);
  bp.hsa = kFirst + kStations - 1;
  const std::vector<std::pair<std::size_t, std::size_t>> io(kStations, {2, 2});
  bp.ttr = tools::dp_ttr(bp, io);
  return bp;
}

std::uint8_t addr(int i) {
  return static_cast<std::uint8_t>(kFirst + i);
}

dp::SlaveParams slave_params(std::uint8_t a, bool prm_cmd) {
  auto sp = devices::master_slave_params(switched_gsd(), modules(), a);
  if (!sp.ok()) throw std::runtime_error("master_slave_params failed");
  dp::SlaveParams p = *sp.value;
  if (prm_cmd) p.prm_cmd.assign(8, 0);  // the MasterSystem writes the block
  return p;
}

std::array<std::uint8_t, 2> counter_bytes(std::uint16_t c) {
  return {static_cast<std::uint8_t>(c >> 8), static_cast<std::uint8_t>(c)};
}

// --- the redundant system ----------------------------------------------------------------------

struct Redundant {
  bus::Scheduler sched;
  bus::Line line[2] = {bus::Line{sched, "A", kBaud}, bus::Line{sched, "B", kBaud}};
  fdl::BusParams bp = bus_params();
  std::unique_ptr<devices::RedundantMasterSystemModel> sys;
  std::vector<std::unique_ptr<devices::SwitchedStationModel>> st;
  std::uint16_t counter = 0;

  explicit Redundant(int n) {
    std::vector<dp::SlaveParams> cfg[2];
    std::vector<redundancy::SwitchedStationRef> refs;
    // T_SLAVE_UM from the GSD (Slave_Max_Switch_Over_Time, unit 10 ms): 30 ms.
    const bus::Ticks t_um = switched_gsd().redundancy().switch_over_time();
    for (int i = 0; i < n; ++i) {
      for (auto& c : cfg) c.push_back(slave_params(addr(i), true));
      refs.push_back({addr(i), t_um, false});
    }
    devices::RedundantMasterSystemOptions o;
    o.master[0].address = o.master[1].address = kMaster;
    o.bus_params = bp;
    sys = std::make_unique<devices::RedundantMasterSystemModel>(o, cfg[0], cfg[1], refs);
    sys->set_cycle_hook([this, n](devices::RedundantMasterSystemModel& m, int, bus::Ticks) {
      const auto v = counter_bytes(++counter);
      for (int i = 0; i < n; ++i) m.system().write_outputs(addr(i), kOutModule, v);
    });
    for (int l = 0; l < 2; ++l) sys->attach(l, line[l], "master 1");
    for (int i = 0; i < n; ++i) {
      devices::SwitchedStationOptions so;
      so.address = addr(i);
      so.bus_params = bp;
      auto b = devices::SwitchedStationModel::build(switched_gsd(), modules(), so);
      if (!b.ok()) throw std::runtime_error(b.errors.empty() ? "switched station" : b.errors[0]);
      st.push_back(std::move(b.model));
      for (int l = 0; l < 2; ++l) st.back()->attach(l, line[l]);
    }
  }
  void start() {
    line[0].start();
    line[1].start();
  }
  /// Every station in data exchange with both masters, line A active and primary.
  bool ready() const {
    for (const auto& s : st) {
      const std::uint8_t a = s->address();
      for (int l = 0; l < 2; ++l)
        if (sys->master(l).slave_state(a) != dp::SlaveStatusState::DataExchange) return false;
      if (sys->system().active(a) != 0 || s->primary() != 0) return false;
    }
    return true;
  }
  bool quiet() const {
    if (sys->system().switchovers() != 0) return false;
    for (const auto& e : sys->system().events())
      if (e.s7()) return false;
    return true;
  }
  std::uint64_t cycles() const {
    return sys->master(0).slave_stats(kFirst).cycle_count +
           sys->master(1).slave_stats(kFirst).cycle_count;
  }
  std::uint64_t dx() const {
    std::uint64_t n = 0;
    for (int l = 0; l < 2; ++l)
      for (const auto& s : st) n += sys->master(l).slave_stats(s->address()).data_exchanges;
    return n;
  }
  bus::Ticks cycle_median() const { return sys->master(0).cycle_median(kFirst); }
};

// --- the plain system --------------------------------------------------------------------------

/// dp::Master on an fdl::ActiveStation with the program at every token receipt (as
/// RedundantMasterSystemModel's Node does, without the redundancy).
class PlainMaster final : public fdl::InitiatorUser {
 public:
  using Hook = std::function<void(dp::Master&)>;
  PlainMaster(const dp::MasterParams& mp, std::vector<dp::SlaveParams> slaves,
              const fdl::BusParams& bp, Hook hook)
      : m_master(mp, std::move(slaves)),
        m_station(mp.address, bp, *this),
        m_hook(std::move(hook)) {}
  dp::Master& master() { return m_master; }
  const dp::Master& master() const { return m_master; }
  fdl::ActiveStation& station() { return m_station; }

  void on_power_on(bus::Ticks now) override { m_master.on_power_on(now); }
  bool next_request(fdl::Priority prio, bus::Ticks now, fdl::Request& out) override {
    return m_master.next_request(prio, now, out);
  }
  void on_confirmation(const fdl::Confirmation& con) override { m_master.on_confirmation(con); }
  void on_request(const fdl::Indication& ind, fdl::Reply& reply) override {
    m_master.on_request(ind, reply);
  }
  void on_token(bus::Ticks now, bus::Ticks trr) override {
    m_hook(m_master);
    m_master.on_token(now, trr);
  }

 private:
  dp::Master m_master;
  fdl::ActiveStation m_station;
  Hook m_hook;
};

struct Plain {
  bus::Scheduler sched;
  bus::Line line{sched, "A", kBaud};
  fdl::BusParams bp = bus_params();
  std::unique_ptr<PlainMaster> master;
  std::vector<std::unique_ptr<devices::SlaveModel>> st;
  std::uint16_t counter = 0;

  explicit Plain(int n) {
    std::vector<dp::SlaveParams> cfg;
    for (int i = 0; i < n; ++i) cfg.push_back(slave_params(addr(i), false));
    dp::MasterParams mp;
    mp.address = kMaster;
    master = std::make_unique<PlainMaster>(mp, cfg, bp, [this, n](dp::Master& m) {
      const auto v = counter_bytes(++counter);
      for (int i = 0; i < n; ++i) m.image(addr(i)).write_outputs(kOutModule, v);
    });
    line.attach(master->station(), "master 1");
    for (int i = 0; i < n; ++i) {
      devices::SlaveModelOptions so;
      so.address = addr(i);
      so.bus_params = bp;
      auto b = devices::SlaveModel::build(switched_gsd(), modules(), so);
      if (!b.ok()) throw std::runtime_error(b.errors.empty() ? "slave model" : b.errors[0]);
      st.push_back(std::move(b.model));
      line.attach(*st.back(), "slave");
    }
  }
  void start() { line.start(); }
  bool ready() const {
    for (int i = 0; i < static_cast<int>(st.size()); ++i)
      if (master->master().slave_state(addr(i)) != dp::SlaveStatusState::DataExchange) return false;
    return true;
  }
  bool quiet() const { return true; }
  std::uint64_t cycles() const { return master->master().slave_stats(kFirst).cycle_count; }
  std::uint64_t dx() const {
    std::uint64_t n = 0;
    for (int i = 0; i < static_cast<int>(st.size()); ++i)
      n += master->master().slave_stats(addr(i)).data_exchanges;
    return n;
  }
  bus::Ticks cycle_median() const { return master->master().cycle_median(kFirst); }
};

// --- the benchmark -----------------------------------------------------------------------------

template <class System>
void run(benchmark::State& state) {
  double bytes_per_station = 0;
  std::unique_ptr<System> sys;
  try {
    const std::uint64_t a0 = heap_in_use();
    auto one = std::make_unique<System>(1);
    const std::uint64_t a1 = heap_in_use();
    const std::uint64_t b0 = heap_in_use();
    sys = std::make_unique<System>(kStations);
    const std::uint64_t b1 = heap_in_use();
    one.reset();
    bytes_per_station = static_cast<double>((b1 - b0) - (a1 - a0)) / (kStations - 1);
  } catch (const std::exception& e) {
    state.SkipWithError(e.what());
    return;
  }

  sys->start();
  bus::Ticks t = 0;
  while (!sys->ready() && t < 2000 * kMs) {
    t += 50 * kMs;
    sys->sched.run_until(t);
  }
  if (!sys->ready()) {
    state.SkipWithError("not every station in data exchange (on both lines, line A primary)");
    return;
  }
  const double startup_ms = static_cast<double>(t) / static_cast<double>(kMs);

  const bus::Ticks slice = 100 * kMs;
  const std::uint64_t cycles0 = sys->cycles();
  const std::uint64_t dx0 = sys->dx();
  const double cpu0 = thread_cpu_seconds();
  for (auto _ : state) {
    t += slice;
    sys->sched.run_until(t);
  }
  const double cpu = thread_cpu_seconds() - cpu0;
  if (!sys->ready() || !sys->quiet()) {
    state.SkipWithError("a station left data exchange or switched over during the run");
    return;
  }
  const double virt = static_cast<double>(state.iterations()) * static_cast<double>(slice) /
                      static_cast<double>(bus::kTicksPerSecond);
  state.counters["virt_s_per_wall_s"] = benchmark::Counter(virt, benchmark::Counter::kIsRate);
  if (cpu > 0) state.counters["virt_s_per_cpu_s"] = virt / cpu;
  state.counters["dp_cycle_us"] =
      static_cast<double>(bus::ticks_to_ns(sys->cycle_median())) / 1000.0;
  state.counters["dp_cycles_per_s"] =
      benchmark::Counter(static_cast<double>(sys->cycles() - cycles0), benchmark::Counter::kIsRate);
  state.counters["dx_per_s"] =
      benchmark::Counter(static_cast<double>(sys->dx() - dx0), benchmark::Counter::kIsRate);
  state.counters["startup_ms"] = startup_ms;
  state.counters["bytes_per_station"] = bytes_per_station;
}

void BM_SwitchedIo(benchmark::State& state) {
  run<Redundant>(state);
}
void BM_PlainSlaves(benchmark::State& state) {
  run<Plain>(state);
}

}  // namespace

BENCHMARK(BM_SwitchedIo)
    ->Name("BM_SwitchedIo/12M/2x32")
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK(BM_PlainSlaves)
    ->Name("BM_PlainSlaves/12M/32")
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
