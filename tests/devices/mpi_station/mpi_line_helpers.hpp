#pragma once
// Test helpers for MPI stations on a real bus::Line (tests/devices/mpi_station): a line at the
// MPI bus parameters with a recording tap, stations attached in cable order, a CPU memory served
// through S7CpuSessionFactory, and small helpers to find frames on the wire.

#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "frame_recorder.hpp"
#include "hex.hpp"
#include "pbvbus/bus/line.hpp"
#include "pbvbus/bus/scheduler.hpp"
#include "pbvbus/mpi_station/mpi_bus_params.hpp"
#include "pbvbus/mpi_station/mpi_station.hpp"
#include "pbvbus/mpi_station/s7cpu_sessions.hpp"
#include "pbvbus/s7cpu/cpu_memory.hpp"
#include "pbvbus/s7cpu/s7_server.hpp"

namespace pbvbus::mpi_station::test {

using Bytes = std::vector<std::uint8_t>;
using pbvbus::test::bytes_from_hex;
using pbvbus::test::FrameRecorder;
using pbvbus::test::to_hex;

/// One MPI line at 187.5 kbit/s, HSA 31 (mpi_bus_params()).
class MpiLine {
 public:
  MpiLine() { line.add_tap(rec); }

  /// A PG/OP (client only) at `address`, attached next along the cable.
  MpiStation& add_client(std::uint8_t address) {
    MpiStationConfig c;
    c.address = address;
    c.bus = params;
    return attach(c, nullptr);
  }
  /// A CPU at `address` serving `memory` (max connections `max_conn`).
  MpiStation& add_cpu(std::uint8_t address, std::size_t max_conn = 8) {
    MpiStationConfig c;
    c.address = address;
    c.bus = params;
    c.pool.max_connections = max_conn;
    return attach(c, &factory);
  }
  MpiStation& attach(const MpiStationConfig& c, S7SessionFactory* server) {
    stations.push_back(std::make_unique<MpiStation>(c, server));
    ids.push_back(line.attach(*stations.back(), "mpi " + std::to_string(c.address)));
    return *stations.back();
  }
  bus::AttachmentId id_of(const MpiStation& s) const {
    for (std::size_t i = 0; i < stations.size(); ++i)
      if (stations[i].get() == &s) return ids[i];
    return -1;
  }

  void start() { line.start(); }
  void run_ms(std::int64_t ms) { sched.run_until(sched.now() + ms * bus::kTicksPerMs); }
  /// Runs in steps of 1 ms until `done` or `limit_ms`; true when done.
  bool run_until(const std::function<bool()>& done, std::int64_t limit_ms = 5000) {
    for (std::int64_t i = 0; i < limit_ms; ++i) {
      if (done()) return true;
      run_ms(1);
    }
    return done();
  }
  /// Whether every station is in the ring and sees all of them in its LAS.
  bool ring_formed() const {
    for (const auto& s : stations) {
      if (!s->mac().in_ring()) return false;
      for (const auto& o : stations)
        if (!s->mac().las_contains(o->address())) return false;
    }
    return true;
  }

  /// Index of the first frame at or after `from` whose hex is `hex`; rec.size() if none.
  std::size_t find(const std::string& hex, std::size_t from = 0) const {
    for (std::size_t i = from; i < rec.size(); ++i)
      if (rec.hex(i) == hex) return i;
    return rec.size();
  }
  /// Index of the first frame at or after `from` that starts with the octets `prefix`.
  std::size_t find_prefix(const std::string& prefix, std::size_t from = 0) const {
    for (std::size_t i = from; i < rec.size(); ++i)
      if (rec.hex(i).rfind(prefix, 0) == 0) return i;
    return rec.size();
  }
  /// The frames from `from` on that are no token and no GAP poll or its answer (SD1 FDL status).
  std::vector<std::string> traffic(std::size_t from = 0) const {
    std::vector<std::string> out;
    for (std::size_t i = from; i < rec.size(); ++i) {
      const auto& b = rec.frame(i).bytes;
      if (b.empty() || b[0] == 0xDC) continue;
      if (b[0] == 0x10 && b.size() == 6 && ((b[3] & 0x4F) == 0x49 || (b[3] & 0x40) == 0)) {
        if ((b[3] & 0x0F) == 0x09 || (b[3] & 0x0F) == 0x00) continue;  // FDL status request/reply OK
      }
      out.push_back(rec.hex(i));
    }
    return out;
  }

  fdl::BusParams params = mpi_bus_params();
  bus::Scheduler sched;
  bus::Line line{sched, "mpi", bus::Baud::k187_5};
  FrameRecorder rec;
  s7cpu::CpuMemory memory;
  s7cpu::CpuInfo info;
  S7CpuSessionFactory factory{memory, info};
  std::vector<std::unique_ptr<MpiStation>> stations;
  std::vector<bus::AttachmentId> ids;
};

/// Events of one kind from a list.
inline std::vector<StationEvent> of_kind(const std::vector<StationEvent>& evs, EventKind k) {
  std::vector<StationEvent> out;
  for (const auto& e : evs)
    if (e.kind == k) out.push_back(e);
  return out;
}

}  // namespace pbvbus::mpi_station::test
