#pragma once
// A PG's initiator Connection and a CPU's ConnectionPool joined by a perfect FDL layer: every
// frame one side hands out reaches the other side as a Received, and the sender gets the FDL
// result that the receiver's FdlReply implies (SC -> Delivered, RR/RS/UE -> Refused), in order.
// A test can cut the line (`line_up = false`): frames are then lost and the sender's FDL layer
// reports NoAnswer.
#include <cstdint>
#include <vector>

#include "pbvbus/mpi/connection.hpp"
#include "pbvbus/mpi/connection_pool.hpp"

namespace pbvbus::mpi::test {

using Bytes = std::vector<std::uint8_t>;

struct WireFrame {
  bool from_pg = true;
  std::uint8_t dsap = 0;
  std::uint8_t ssap = 0;
  Bytes pdu;
};

struct MpiLink {
  static constexpr std::uint8_t kPg = 0;
  static constexpr std::uint8_t kCpu = 2;

  explicit MpiLink(PoolConfig config = {}, std::uint8_t pg_sap = kFirstConnectionSap)
      : pg(Connection::initiator(kCpu, pg_sap, config.timing)), cpu(config) {}

  Connection pg;
  ConnectionPool cpu;
  Outbox pg_out;
  Outbox cpu_out;
  std::vector<WireFrame> wire;   ///< every frame sent, in order
  std::vector<Event> pg_events;  ///< everything the PG's user was told
  std::vector<Event> cpu_events;
  std::vector<FdlReply> cpu_replies;
  bool line_up = true;

  static Received received(std::uint8_t peer, const Outgoing& f) {
    return Received{peer, f.dsap, f.ssap, f.pdu.bytes()};
  }

  /// Moves frames both ways until none is left.
  void run(bus::Ticks now) {
    for (int guard = 0; guard < 100; ++guard) {
      collect();
      if (pg_out.frames.empty() && cpu_out.frames.empty()) return;
      const std::vector<Outgoing> from_pg = std::move(pg_out.frames);
      const std::vector<Outgoing> from_cpu = std::move(cpu_out.frames);
      pg_out.frames.clear();
      cpu_out.frames.clear();
      for (const Outgoing& f : from_pg) {
        wire.push_back({true, f.dsap, f.ssap, Bytes(f.pdu.bytes().begin(), f.pdu.bytes().end())});
        if (!line_up) {
          pg.on_fdl_result(now, FdlResult::NoAnswer, pg_out);
          continue;
        }
        const FdlReply r = cpu.on_frame(now, received(kPg, f), cpu_out);
        cpu_replies.push_back(r);
        pg.on_fdl_result(now, r == FdlReply::Ack ? FdlResult::Delivered : FdlResult::Refused, pg_out);
      }
      for (const Outgoing& f : from_cpu) {
        wire.push_back({false, f.dsap, f.ssap, Bytes(f.pdu.bytes().begin(), f.pdu.bytes().end())});
        if (!line_up) {
          cpu.on_fdl_result(now, f.ssap, FdlResult::NoAnswer, cpu_out);
          continue;
        }
        const FdlReply r = pg.on_frame(now, received(kCpu, f), pg_out);
        cpu.on_fdl_result(now, f.ssap, r == FdlReply::Ack ? FdlResult::Delivered : FdlResult::Refused,
                          cpu_out);
      }
    }
  }

  void collect() {
    for (Event& e : pg_out.events) pg_events.push_back(std::move(e));
    for (Event& e : cpu_out.events) cpu_events.push_back(std::move(e));
    pg_out.events.clear();
    cpu_out.events.clear();
  }

  /// Connects and runs the handshake to the end.
  void connect(bus::Ticks now = 0) {
    pg.connect(now, pg_out);
    run(now);
  }

  /// The CPU's SAP of the PG's connection.
  std::uint8_t cpu_sap() const { return pg.peer_sap().value_or(0xFF); }
};

}  // namespace pbvbus::mpi::test
