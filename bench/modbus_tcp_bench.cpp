// Modbus TCP door throughput (docs/gateway-modbus.md: requests per second through pbvbus beside a
// minimal libmodbus server with the same client; goal >= 90 % of it).
//
// Both servers run on their own thread in this process, on loopback; the client is libmodbus
// itself (modbus_new_tcp + modbus_read_registers of 10 holding registers of unit 1 in a loop),
// on the benchmark thread, one request at a time (request/response, no pipelining).
//
//   BM_ModbusTcp/pbvbus     ModbusTcpServer on a bus::PacedRunner's io_context (the run is
//                           paced at real time with a 1 ms scheduler event, as a simulation
//                           would be), the register-file handler of the door tests.
//   BM_ModbusTcp/libmodbus  the ~50-line poll() server of tools-and-formats.md §1.3:
//                           modbus_receive() + modbus_reply() on a 16-register mapping.
// Counter `req_per_s` = requests per wall second. The ratio pbvbus/libmodbus and the command
// are in docs/gateway-modbus-doors.md.

#include <benchmark/benchmark.h>
#include <modbus.h>
#include <poll.h>
#include <unistd.h>

#include <atomic>
#include <cstdint>
#include <thread>
#include <vector>

#include "../tests/gateways/modbus_test_handler.hpp"

#include "pbvbus/bus/paced_runner.hpp"
#include "pbvbus/bus/scheduler.hpp"
#include "pbvbus/gateways/modbus_tcp_server.hpp"

namespace {

using namespace pbvbus;

constexpr int kRegisters = 10;

/// Reads 10 registers of unit 1 in a loop; returns false on the first error.
void client_loop(benchmark::State& state, int port) {
  modbus_t* ctx = modbus_new_tcp("127.0.0.1", port);
  modbus_set_slave(ctx, 1);
  if (modbus_connect(ctx) != 0) {
    state.SkipWithError("connect failed");
    modbus_free(ctx);
    return;
  }
  std::uint16_t regs[kRegisters];
  for (auto _ : state) {
    if (modbus_read_registers(ctx, 0, kRegisters, regs) != kRegisters) {
      state.SkipWithError(modbus_strerror(errno));
      break;
    }
    benchmark::DoNotOptimize(regs);
  }
  modbus_close(ctx);
  modbus_free(ctx);
  state.counters["req_per_s"] =
      benchmark::Counter(static_cast<double>(state.iterations()), benchmark::Counter::kIsRate);
}

/// A 1 ms scheduler event, so the paced runner's timer is busy as in a simulation.
class Tick final : public bus::EventTarget {
 public:
  explicit Tick(bus::Scheduler& s) : m_s(s) { m_s.schedule(bus::kTicksPerMs, *this); }
  void on_event(bus::Ticks now, std::uint64_t) override {
    m_s.schedule(now + bus::kTicksPerMs, *this);
  }

 private:
  bus::Scheduler& m_s;
};

void BM_ModbusTcp_pbvbus(benchmark::State& state) {
  bus::Scheduler sched;
  bus::PacedRunner runner(sched);
  Tick tick(sched);
  gateways::test::RegisterFileHandler handler;
  handler.record = false;
  for (std::size_t i = 0; i < handler.regs.size(); ++i)
    handler.regs[i] = static_cast<std::uint16_t>(i);
  gateways::ModbusTcpServer srv(runner.io_context(), handler, {"127.0.0.1", 0});
  std::thread bus_thread([&] { runner.run_for(3600 * bus::kTicksPerSecond); });
  client_loop(state, srv.port());
  runner.stop();
  bus_thread.join();
  srv.close();
}
BENCHMARK(BM_ModbusTcp_pbvbus)->Name("BM_ModbusTcp/pbvbus")->UseRealTime()->MinTime(2.0);

void BM_ModbusTcp_libmodbus(benchmark::State& state) {
  // The minimal poll() server (tools-and-formats.md §1.3).
  modbus_t* srv = modbus_new_tcp("127.0.0.1", 0);
  modbus_mapping_t* map = modbus_mapping_new_start_address(0, 0, 0, 0, 0, 16, 0, 0);
  for (int i = 0; i < 16; ++i) map->tab_registers[i] = static_cast<std::uint16_t>(i);
  // modbus_tcp_listen() binds the context's port; 0 is not accepted by libmodbus's parser as
  // "any", so try a few fixed ports.
  int listen_fd = -1, port = 0;
  for (int p = 15020; p < 15040 && listen_fd < 0; ++p) {
    modbus_free(srv);
    srv = modbus_new_tcp("127.0.0.1", p);
    listen_fd = modbus_tcp_listen(srv, 4);
    port = p;
  }
  if (listen_fd < 0) {
    state.SkipWithError("no free port for the libmodbus server");
    modbus_mapping_free(map);
    modbus_free(srv);
    return;
  }
  std::atomic<bool> stop{false};
  std::thread server([&] {
    std::vector<pollfd> fds{{listen_fd, POLLIN, 0}};
    std::vector<std::uint8_t> q(MODBUS_TCP_MAX_ADU_LENGTH);
    while (!stop) {
      if (::poll(fds.data(), fds.size(), 50) <= 0) continue;
      for (std::size_t i = 0; i < fds.size(); ++i) {
        if (!(fds[i].revents & (POLLIN | POLLHUP | POLLERR))) continue;
        if (fds[i].fd == listen_fd) {
          const int c = ::accept(listen_fd, nullptr, nullptr);
          if (c >= 0) fds.push_back({c, POLLIN, 0});
          continue;
        }
        modbus_set_socket(srv, fds[i].fd);
        const int rc = modbus_receive(srv, q.data());
        if (rc > 0) {
          modbus_reply(srv, q.data(), rc, map);
        } else if (rc < 0) {
          ::close(fds[i].fd);
          fds.erase(fds.begin() + static_cast<std::ptrdiff_t>(i));
          --i;
        }
      }
    }
    for (std::size_t i = 1; i < fds.size(); ++i) ::close(fds[i].fd);
  });
  client_loop(state, port);
  stop = true;
  server.join();
  ::close(listen_fd);
  modbus_set_socket(srv, -1);
  modbus_mapping_free(map);
  modbus_free(srv);
}
BENCHMARK(BM_ModbusTcp_libmodbus)->Name("BM_ModbusTcp/libmodbus")->UseRealTime()->MinTime(2.0);

}  // namespace
