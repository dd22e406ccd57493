// ISO-on-TCP door throughput (docs/iso-on-tcp.md, docs/benchmarks.md): S7 Read Var round trips
// per second through IsoOnTcpDoor against one CPU (LocalCpuRouter, an s7cpu::S7Server session
// per connection on one CpuMemory), over loopback.
//
// The door runs on a bus::PacedRunner's io_context paced at real time with a 1 ms scheduler
// event, as in a simulation; the client is plain C++ with blocking sockets on the benchmark
// thread: CR, Setup Communication (PDU 240), then Read Var of DB1.DBB0, 10 bytes (§H.4's
// example), one job at a time per connection.
//   BM_IsoOnTcpRead/1   one connection, request/answer in a loop
//   BM_IsoOnTcpRead/8   eight connections in lockstep: a job on each, then the eight answers
// Counter `reads_per_s` = answered Read Var jobs per wall second, over all connections.
#include <arpa/inet.h>
#include <benchmark/benchmark.h>
#include <netinet/in.h>
#include <netinet/tcp.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cstdint>
#include <thread>
#include <vector>

#include "pbvbus/bus/paced_runner.hpp"
#include "pbvbus/bus/scheduler.hpp"
#include "pbvbus/iso_on_tcp/iso_door.hpp"
#include "pbvbus/iso_on_tcp/local_cpu_router.hpp"

namespace {

using namespace pbvbus;
using Bytes = std::vector<std::uint8_t>;

/// A 1 ms scheduler event, so the paced runner's timer is busy as in a simulation.
class MsTick final : public bus::EventTarget {
 public:
  explicit MsTick(bus::Scheduler& s) : s_(s) { s_.schedule(bus::kTicksPerMs, *this); }
  void on_event(bus::Ticks now, std::uint64_t) override {
    s_.schedule(now + bus::kTicksPerMs, *this);
  }

 private:
  bus::Scheduler& s_;
};

// tools-and-formats.md §3.4: CR to rack 0 slot 2, Setup Communication; §H.4: Read Var DB1.DBB0 x10.
const Bytes kCr = {0x03, 0x00, 0x00, 0x16, 0x11, 0xE0, 0x00, 0x00, 0x00, 0x01, 0x00,
                   0xC0, 0x01, 0x0A, 0xC1, 0x02, 0x01, 0x00, 0xC2, 0x02, 0x01, 0x02};
const Bytes kSetup = {0x03, 0x00, 0x00, 0x19, 0x02, 0xF0, 0x80, 0x32, 0x01, 0x00, 0x00, 0x00, 0x00,
                      0x00, 0x08, 0x00, 0x00, 0xF0, 0x00, 0x00, 0x01, 0x00, 0x01, 0x01, 0xE0};
const Bytes kRead = {0x03, 0x00, 0x00, 0x1F, 0x02, 0xF0, 0x80, 0x32, 0x01, 0x00, 0x00,
                     0x00, 0x01, 0x00, 0x0E, 0x00, 0x00, 0x04, 0x01, 0x12, 0x0A, 0x10,
                     0x02, 0x00, 0x0A, 0x00, 0x01, 0x84, 0x00, 0x00, 0x00};

bool send_all(int fd, const Bytes& b) {
  return ::send(fd, b.data(), b.size(), MSG_NOSIGNAL) == static_cast<ssize_t>(b.size());
}
/// One whole TPKT; false if the door closed.
bool recv_tpkt(int fd) {
  std::uint8_t buf[512];
  std::size_t got = 0, want = 4;
  while (got < want) {
    const ssize_t n = ::recv(fd, buf + got, want - got, 0);
    if (n <= 0) return false;
    got += static_cast<std::size_t>(n);
    if (got == 4) want = (std::size_t{buf[2]} << 8) | buf[3];
    if (want > sizeof buf || want < 4) return false;
  }
  return true;
}

int open_connection(std::uint16_t port) {
  const int fd = ::socket(AF_INET, SOCK_STREAM | SOCK_CLOEXEC, 0);
  sockaddr_in sa{};
  sa.sin_family = AF_INET;
  sa.sin_port = htons(port);
  sa.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  const int one = 1;
  ::setsockopt(fd, IPPROTO_TCP, TCP_NODELAY, &one, sizeof one);
  if (::connect(fd, reinterpret_cast<sockaddr*>(&sa), sizeof sa) != 0 || !send_all(fd, kCr) ||
      !recv_tpkt(fd) || !send_all(fd, kSetup) || !recv_tpkt(fd)) {
    ::close(fd);
    return -1;
  }
  return fd;
}

void BM_IsoOnTcpRead(benchmark::State& state) {
  const auto connections = static_cast<std::size_t>(state.range(0));
  bus::Scheduler sched;
  bus::PacedRunner runner(sched);
  MsTick tick(sched);
  s7cpu::CpuMemory memory;
  memory.create_db(1, 64);
  const s7cpu::CpuInfo info;
  iso_on_tcp::LocalCpu cpu;
  cpu.memory = &memory;
  cpu.info = &info;
  iso_on_tcp::LocalCpuRouter router(cpu);
  iso_on_tcp::IsoDoorOptions opt;
  opt.port = 0;
  iso_on_tcp::IsoOnTcpDoor door(runner.io_context(), router, opt);
  std::thread bus_thread([&] { runner.run_for(3600 * bus::kTicksPerSecond); });

  std::vector<int> fds;
  for (std::size_t i = 0; i < connections; ++i) {
    const int fd = open_connection(door.port());
    if (fd < 0) {
      state.SkipWithError("connect failed");
      break;
    }
    fds.push_back(fd);
  }
  if (fds.size() == connections) {
    for (auto _ : state) {
      bool ok = true;
      for (int fd : fds) ok = ok && send_all(fd, kRead);
      for (int fd : fds) ok = ok && recv_tpkt(fd);
      if (!ok) {
        state.SkipWithError("door closed a connection");
        break;
      }
    }
  }
  for (int fd : fds) ::close(fd);
  runner.stop();
  bus_thread.join();
  door.close();
  state.counters["reads_per_s"] = benchmark::Counter(
      static_cast<double>(state.iterations() * connections), benchmark::Counter::kIsRate);
}
BENCHMARK(BM_IsoOnTcpRead)->Arg(1)->Arg(8)->UseRealTime()->MinTime(2.0);

}  // namespace
