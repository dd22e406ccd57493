// The virtual-time cost of one S7 Read Var over MPI (docs/benchmarks.md "One S7 read over MPI"):
// an MPI line at 187.5 kbit/s, HSA 31 (mpi_station::mpi_bus_params()), with a CPU at address 2
// (S7CpuSessionFactory on a CpuMemory with DB1) and 4 PG/OP stations at 0, 1, 3 and 4, all
// active stations in one token ring. Each PG/OP holds a connection to the CPU (Setup
// Communication done); PG 0 reads DB1.DBB0 x 10 (the §H.4 example job) over and over, each read
// submitted as soon as the previous answer arrived; the other three stay idle.
//
//   BM_MpiRead/187.5k/4clients   counters (all virtual time, not wall time):
//     read_us / read_bits        mean time from submit() to the Reply event, in µs and bit times
//     rotation_bits_predicted    one token rotation of 5 active stations that send only the token:
//                                5 x (token 3 octets x 11 bits + TID1 37) = 350 bits
//                                (mpi_station::idle_rotation_bits), in bit times and µs
//     rotation_bits_predicted_with_gap  the same plus station 4's GAP polls of the empty
//                                addresses 5..31 averaged over a GAP cycle: 27 polls of
//                                TID1 + 6 x 11 + TSL = 518 bits per 27 + 1 + G = 38 rotations
//     rotation_bits_idle         the PG's mean measured rotation (TRR) over 2 s with nobody
//                                reading (GAP polls included)
//     rotation_bits_reading      the PG's mean TRR while it reads
//     reads_per_virt_s           1 / read time
// The wall time of the loop is reported by Google Benchmark as usual and is not the point.

#include <benchmark/benchmark.h>

#include <algorithm>
#include <memory>
#include <numeric>
#include <stdexcept>
#include <vector>

#include "pbvbus/bus/line.hpp"
#include "pbvbus/bus/scheduler.hpp"
#include "pbvbus/mpi_station/mpi_bus_params.hpp"
#include "pbvbus/mpi_station/mpi_station.hpp"
#include "pbvbus/mpi_station/s7cpu_sessions.hpp"

namespace {

using namespace pbvbus;
using namespace pbvbus::mpi_station;

const std::vector<std::uint8_t> kSetup = {0x32, 0x01, 0x00, 0x00, 0x00, 0x00, 0x00, 0x08, 0x00,
                                          0x00, 0xF0, 0x00, 0x00, 0x01, 0x00, 0x01, 0x03, 0xC0};
const std::vector<std::uint8_t> kRead = {0x32, 0x01, 0x00, 0x00, 0x00, 0x01, 0x00, 0x0E, 0x00, 0x00, 0x04, 0x01,
                                         0x12, 0x0A, 0x10, 0x02, 0x00, 0x0A, 0x00, 0x01, 0x84, 0x00, 0x00, 0x00};

struct MpiSubnet {
  fdl::BusParams params = mpi_bus_params();
  bus::Scheduler sched;
  bus::Line line{sched, "MPI", bus::Baud::k187_5};
  s7cpu::CpuMemory memory;
  s7cpu::CpuInfo info;
  S7CpuSessionFactory factory{memory, info};
  std::vector<std::unique_ptr<MpiStation>> stations;  // 0, 1, CPU 2, 3, 4 in cable order
  std::vector<Handle> handles;                        // per client, in the order 0, 1, 3, 4
  std::vector<MpiStation*> clients;
  MpiStation* cpu = nullptr;

  MpiSubnet() {
    memory.create_db(1, 16);
    for (std::uint8_t a = 0; a <= 4; ++a) {
      MpiStationConfig c;
      c.address = a;
      c.bus = params;
      stations.push_back(std::make_unique<MpiStation>(c, a == 2 ? &factory : nullptr));
      line.attach(*stations.back());
      if (a == 2) {
        cpu = stations.back().get();
      } else {
        clients.push_back(stations.back().get());
      }
    }
    line.start();
    run_ms(500);
    for (MpiStation* s : clients) {
      const auto h = s->open(2);
      if (!h) throw std::runtime_error("open failed");
      handles.push_back(*h);
      s->submit(*h, kSetup);
    }
    run_ms(500);
    for (std::size_t i = 0; i < clients.size(); ++i) {
      if (clients[i]->state(handles[i]) != mpi::State::Connected || clients[i]->stats().pdus_received != 1)
        throw std::runtime_error("set-up failed");
      (void)clients[i]->take_events();
    }
    if (cpu->server_connections() != 4) throw std::runtime_error("expected 4 connections");
  }
  void run_ms(std::int64_t ms) { sched.run_until(sched.now() + ms * bus::kTicksPerMs); }
};

/// Mean of the rotation samples recorded since the station's count was `count0` (the station
/// keeps the last 4096: at most those).
double mean_bits(const fdl::ActiveStation& mac, std::uint64_t count0, bus::Ticks bit) {
  const std::vector<bus::Ticks> v = mac.rotation_samples();
  const std::size_t n = static_cast<std::size_t>(std::min<std::uint64_t>(mac.rotation_count() - count0, v.size()));
  if (n == 0) return 0;
  const bus::Ticks sum = std::accumulate(v.end() - static_cast<long>(n), v.end(), bus::Ticks{0});
  return static_cast<double>(sum) / static_cast<double>(n) / static_cast<double>(bit);
}

void BM_MpiRead(benchmark::State& state) {
  MpiSubnet net;
  MpiStation& pg = *net.clients[0];
  const bus::Ticks bit = net.line.bit_ticks();

  // The idle rotation, measured at the PG.
  const std::uint64_t idle0 = pg.mac().rotation_count();
  net.run_ms(2000);
  const double idle_bits = mean_bits(pg.mac(), idle0, bit);

  bus::Ticks submitted = 0, total = 0;
  std::uint64_t reads = 0;
  bool waiting = false;
  pg.set_event_handler([&](const StationEvent& e) {
    if (e.kind != EventKind::Reply || !waiting) return;
    total += e.at - submitted;
    ++reads;
    waiting = false;
  });
  const std::uint64_t busy0 = pg.mac().rotation_count();
  for (auto _ : state) {
    for (int i = 0; i < 100; ++i) {
      submitted = net.sched.now();
      waiting = true;
      pg.submit(net.handles[0], kRead);
      while (waiting) net.sched.run_until(net.sched.now() + bit * 11);
    }
  }
  if (reads == 0) return;
  const double read_bits = static_cast<double>(total) / static_cast<double>(reads) / static_cast<double>(bit);
  const double us_per_bit = 1e6 / 187'500.0;
  const double predicted = idle_rotation_bits(net.params, 5);
  state.counters["read_bits"] = read_bits;
  state.counters["read_us"] = read_bits * us_per_bit;
  state.counters["reads_per_virt_s"] = 1e6 / (read_bits * us_per_bit);
  state.counters["rotation_bits_predicted"] = predicted;
  state.counters["rotation_us_predicted"] = predicted * us_per_bit;
  // With GAP polls: station 4's GAP is 5..31 (27 empty addresses), one poll per visit, each
  // adding TID1 + 6 x 11 + TSL (the token follows at slot expiry); then the visit that completes
  // the scan and G = 10 visits without: 27 polls per 38 rotations.
  const double gap_addresses = net.params.hsa - 4;
  const double poll_bits = net.params.tid1() + 66.0 + net.params.tsl;
  state.counters["rotation_bits_predicted_with_gap"] =
      predicted + poll_bits * gap_addresses / (gap_addresses + 1 + net.params.gap_factor);
  state.counters["rotation_bits_idle"] = idle_bits;
  state.counters["rotation_bits_reading"] = mean_bits(pg.mac(), busy0, bit);
}

}  // namespace

BENCHMARK(BM_MpiRead)->Name("BM_MpiRead/187.5k/4clients")->Unit(benchmark::kMillisecond);
