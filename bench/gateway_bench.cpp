// Gateway benchmarks (docs/gateway-modbus.md): what a Modbus client costs the bus and how fast its writes
// reach a slave. Both run a real master system at 1.5 Mbit/s paced at real time (speed 1/1):
// bus::Line + fdl::ActiveStation + dp::Master + one devices::SlaveModel from PBVB0A01.gsd
// (module "16DI/16DO DC24V": 2 octets in, 2 out, as the first slave of examples/dp-basic),
// DpMasterSource + ModbusGateway + ModbusTcpServer on the PacedRunner's io_context.
//
//   BM_GatewayWriteLatency  a libmodbus client (benchmark thread) writes HR 0 with FC16, a new
//                           value each time, 2 000 times; the bus runs on its own thread. A
//                           scheduler event every 50 us virtual reads the slave model's outputs
//                           and, when they change, stamps steady_clock. Latency = stamp - the
//                           client's wall time just before modbus_write_registers(). Counters:
//                           p50_us, p99_us, max_us, dp_cycle_us (virtual median from
//                           dp::Master::cycle_median). Goal: p99 <= one DP cycle + 1 ms. The
//                           50 us observer adds up to 50 us (plus the pacing's wake-up
//                           granularity) to each figure.
//   BM_GatewayBusLoad/N     2 s of paced run on the benchmark thread with N (0 or 4) flooding
//                           clients: raw TCP sockets, 8 pipelined FC03 (1 register of unit 4)
//                           per send, as fast as the door answers. Counters: cycle_median_us,
//                           cycle_max_us (virtual, dp::Master), max_lag_us, late_wakeups,
//                           wakeups (PacedReport), req_per_s. The virtual DP cycle must be the
//                           same with and without clients; the lag figures comparable.
// Figures and command: docs/benchmarks.md, "Gateways (docs/gateway-modbus.md)".

#include <arpa/inet.h>
#include <benchmark/benchmark.h>
#include <modbus.h>
#include <netinet/in.h>
#include <netinet/tcp.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdint>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include "pbvbus/bus/line.hpp"
#include "pbvbus/bus/paced_runner.hpp"
#include "pbvbus/bus/scheduler.hpp"
#include "pbvbus/gsd/gsd.hpp"
#include "pbvbus/slaves/slave_model.hpp"
#include "pbvbus/fdl/active_station.hpp"
#include "pbvbus/gateways/dp_master_source.hpp"
#include "pbvbus/gateways/modbus_gateway.hpp"
#include "pbvbus/gateways/modbus_tcp_server.hpp"

namespace {

using namespace pbvbus;
using Clock = std::chrono::steady_clock;

constexpr bus::Baud kBaud = bus::Baud::k1_5M;
constexpr std::uint8_t kSlave = 4;

/// The master system + gateway + TCP door, paced at 1/1.
struct GatewayRig {
  bus::Scheduler sched;
  bus::Line line{sched, "dp", kBaud};
  fdl::BusParams bp = fdl::BusParams::defaults(kBaud);
  std::unique_ptr<dp::Master> master;
  std::unique_ptr<fdl::ActiveStation> station;
  std::unique_ptr<devices::SlaveModel> slave;
  std::unique_ptr<gateways::DpMasterSource> source;
  std::unique_ptr<gateways::ModbusGateway> gateway;
  std::unique_ptr<bus::PacedRunner> runner;
  std::unique_ptr<gateways::ModbusTcpServer> door;
  std::string error;

  GatewayRig() {
    bp.hsa = 12;
    auto gsd = devices::load_gsd(std::string(PBVBUS_SOURCE_DIR) + "/examples/gsd/PBVB0A01.gsd");
    if (!gsd.ok()) {
      error = "PBVB0A01.gsd";
      return;
    }
    const std::vector<devices::ModuleChoice> mods{devices::ModuleChoice::named("16DI/16DO DC24V")};
    auto sp = devices::master_slave_params(*gsd.file, mods, kSlave);
    devices::SlaveModelOptions so;
    so.address = kSlave;
    so.bus_params = bp;
    auto b = devices::SlaveModel::build(*gsd.file, mods, so);
    if (!sp.ok() || !b.ok()) {
      error = "slave model";
      return;
    }
    dp::MasterParams mp;
    mp.address = 1;
    master = std::make_unique<dp::Master>(mp, std::vector<dp::SlaveParams>{*sp.value});
    station = std::make_unique<fdl::ActiveStation>(mp.address, bp, *master);
    line.attach(*station, "master 1");
    slave = std::move(b.model);
    slave->set_behaviour(0, devices::IoBehaviour::echo());
    line.attach(*slave, "slave 4");
    source = std::make_unique<gateways::DpMasterSource>(*master, "dp_master 1 on dp");
    gateway = std::make_unique<gateways::ModbusGateway>(*source);
    runner = std::make_unique<bus::PacedRunner>(sched, bus::Speed{1, 1});
    door = std::make_unique<gateways::ModbusTcpServer>(runner->io_context(), *gateway,
                                                       gateways::ModbusTcpOptions{"127.0.0.1", 0});
    line.start();
    sched.run_until(300 * bus::kTicksPerMs);  // start-up, fast
    if (master->slave_stats(kSlave).data_exchanges == 0) error = "no data exchange";
  }
  ~GatewayRig() {
    if (door) door->close();
  }
  double cycle_median_us() const {
    return static_cast<double>(master->cycle_median(kSlave)) / static_cast<double>(bus::kTicksPerUs);
  }
};

/// Every 50 us virtual: the slave's 2 output octets; on a change, the wall time of the change.
class OutputStamp final : public bus::EventTarget {
 public:
  static constexpr bus::Ticks kPeriod = 50 * bus::kTicksPerUs;
  OutputStamp(bus::Scheduler& s, devices::SlaveModel& m) : m_s(s), m_m(m) {
    m_s.schedule(m_s.now() + kPeriod, *this);
  }
  void on_event(bus::Ticks now, std::uint64_t) override {
    std::uint8_t o[2] = {0, 0};
    if (m_m.application().read_outputs(0, o)) {
      const auto v = static_cast<std::uint16_t>(o[0] << 8 | o[1]);
      if (v != value.load(std::memory_order_relaxed)) {
        stamp_ns.store(Clock::now().time_since_epoch().count(), std::memory_order_relaxed);
        value.store(v, std::memory_order_release);
      }
    }
    m_s.schedule(now + kPeriod, *this);
  }
  std::atomic<std::uint16_t> value{0};
  std::atomic<std::int64_t> stamp_ns{0};

 private:
  bus::Scheduler& m_s;
  devices::SlaveModel& m_m;
};

double percentile(std::vector<double> v, double p) {
  if (v.empty()) return 0;
  std::sort(v.begin(), v.end());
  const auto i = static_cast<std::size_t>(p * static_cast<double>(v.size() - 1) + 0.5);
  return v[std::min(i, v.size() - 1)];
}

void BM_GatewayWriteLatency(benchmark::State& state) {
  GatewayRig rig;
  if (!rig.error.empty()) {
    state.SkipWithError(rig.error.c_str());
    return;
  }
  OutputStamp obs(rig.sched, *rig.slave);
  std::thread bus_thread([&] { rig.runner->run_for(3600 * bus::kTicksPerSecond); });
  modbus_t* ctx = modbus_new_tcp("127.0.0.1", rig.door->port());
  modbus_set_slave(ctx, kSlave);
  std::vector<double> lat_us;
  std::string err;
  if (modbus_connect(ctx) != 0) err = "connect failed";
  constexpr int kWrites = 2000;
  for (auto _ : state) {
    for (int i = 0; i < kWrites && err.empty(); ++i) {
      const auto v = static_cast<std::uint16_t>(0x1000 + i);
      const auto t0 = Clock::now();
      if (modbus_write_registers(ctx, 0, 1, &v) != 1) {
        err = modbus_strerror(errno);
        break;
      }
      // Wait (generous 1 s upper bound) for the observer to see the value in the slave.
      const auto give_up = t0 + std::chrono::seconds(1);
      while (obs.value.load(std::memory_order_acquire) != v && Clock::now() < give_up)
        std::this_thread::sleep_for(std::chrono::microseconds(20));
      if (obs.value.load(std::memory_order_acquire) != v) {
        err = "write did not reach the slave within 1 s";
        break;
      }
      const auto t1 = Clock::time_point(Clock::duration(obs.stamp_ns.load(std::memory_order_relaxed)));
      lat_us.push_back(std::chrono::duration<double, std::micro>(t1 - t0).count());
    }
  }
  modbus_close(ctx);
  modbus_free(ctx);
  rig.runner->stop();
  bus_thread.join();
  if (!err.empty()) {
    state.SkipWithError(err.c_str());
    return;
  }
  state.counters["p50_us"] = percentile(lat_us, 0.50);
  state.counters["p99_us"] = percentile(lat_us, 0.99);
  state.counters["max_us"] = percentile(lat_us, 1.0);
  state.counters["dp_cycle_us"] = rig.cycle_median_us();
  state.counters["writes"] = static_cast<double>(lat_us.size());
  state.counters["max_lag_us"] =
      std::chrono::duration<double, std::micro>(rig.runner->report().max_lag).count();
}
BENCHMARK(BM_GatewayWriteLatency)->UseRealTime()->Iterations(1)->Unit(benchmark::kMillisecond);

/// A flooding client: 8 pipelined FC03 (HR 0, 1 register, unit 4) per send, then reads the 8
/// responses (11 octets each: MBAP 7 + FC + byte count + 2) before the next burst.
void flood(std::uint16_t port, const std::atomic<bool>& stop, std::atomic<std::uint64_t>& answered) {
  const int fd = ::socket(AF_INET, SOCK_STREAM, 0);
  if (fd < 0) return;
  sockaddr_in a{};
  a.sin_family = AF_INET;
  a.sin_port = htons(port);
  a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  timeval tv{1, 0};
  ::setsockopt(fd, SOL_SOCKET, SO_RCVTIMEO, &tv, sizeof tv);
  int one = 1;
  ::setsockopt(fd, IPPROTO_TCP, TCP_NODELAY, &one, sizeof one);
  if (::connect(fd, reinterpret_cast<sockaddr*>(&a), sizeof a) != 0) {
    ::close(fd);
    return;
  }
  constexpr int kDepth = 8, kRsp = 11;
  std::uint8_t req[kDepth * 12];
  std::uint16_t tid = 0;
  std::uint8_t buf[kDepth * kRsp];
  while (!stop.load(std::memory_order_relaxed)) {
    for (int i = 0; i < kDepth; ++i) {
      ++tid;
      const std::uint8_t r[12] = {static_cast<std::uint8_t>(tid >> 8), static_cast<std::uint8_t>(tid),
                                  0, 0, 0, 6, kSlave, 0x03, 0, 0, 0, 1};
      std::copy(r, r + 12, req + 12 * i);
    }
    if (::send(fd, req, sizeof req, MSG_NOSIGNAL) != static_cast<ssize_t>(sizeof req)) break;
    std::size_t got = 0;
    while (got < sizeof buf) {
      const ssize_t n = ::recv(fd, buf + got, sizeof buf - got, 0);
      if (n <= 0) break;
      got += static_cast<std::size_t>(n);
    }
    if (got < sizeof buf) break;
    answered.fetch_add(kDepth, std::memory_order_relaxed);
  }
  ::close(fd);
}

void BM_GatewayBusLoad(benchmark::State& state) {
  GatewayRig rig;
  if (!rig.error.empty()) {
    state.SkipWithError(rig.error.c_str());
    return;
  }
  const auto clients = static_cast<int>(state.range(0));
  std::atomic<bool> stop{false};
  std::atomic<std::uint64_t> answered{0};
  std::vector<std::thread> threads;
  for (int i = 0; i < clients; ++i)
    threads.emplace_back(flood, rig.door->port(), std::cref(stop), std::ref(answered));
  const bus::Ticks v0 = rig.sched.now();
  const auto w0 = Clock::now();
  for (auto _ : state) rig.runner->run_for(2 * bus::kTicksPerSecond);
  const double wall_s = std::chrono::duration<double>(Clock::now() - w0).count();
  const bus::PacedReport rep = rig.runner->report();
  stop = true;
  rig.door->close();  // clients blocked in recv() see the close
  for (auto& t : threads) t.join();
  const auto& st = rig.master->slave_stats(kSlave);
  state.counters["cycle_median_us"] = rig.cycle_median_us();
  state.counters["cycle_max_us"] = static_cast<double>(st.cycle_max) / static_cast<double>(bus::kTicksPerUs);
  state.counters["cycle_min_us"] = static_cast<double>(st.cycle_min) / static_cast<double>(bus::kTicksPerUs);
  state.counters["max_lag_us"] = std::chrono::duration<double, std::micro>(rep.max_lag).count();
  state.counters["late_wakeups"] = static_cast<double>(rep.late_wakeups);
  state.counters["wakeups"] = static_cast<double>(rep.wakeups);
  state.counters["slips"] = static_cast<double>(rep.slips);
  state.counters["virtual_s"] =
      static_cast<double>(rig.sched.now() - v0) / static_cast<double>(bus::kTicksPerSecond);
  state.counters["req_per_s"] = static_cast<double>(answered.load()) / wall_s;
}
BENCHMARK(BM_GatewayBusLoad)->Arg(0)->Arg(4)->UseRealTime()->Iterations(1)->Unit(benchmark::kMillisecond);

}  // namespace
