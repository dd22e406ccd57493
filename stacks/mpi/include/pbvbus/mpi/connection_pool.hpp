#pragma once
// The CPU side's connection resources (protocol-facts.md §H.3; docs/mpi.md "Decisions").
//
// A connect request (E0 to DSAP 0x00, kConnectSap) opens a responder Connection on the first
// free SAP from `first_sap` (0x14, the SAP the CPU answers from in the §H.3 trace) upward to 63.
// Beyond `max_connections` open connections, or with no free SAP, the request is refused by
// the FDL reply RR "no resources" (§B.3) instead of SC: §H gives no refusal bytes, and RR is
// what a PROFIBUS station answers when it cannot take a frame for lack of resources; the
// initiator's FDL layer reports it as FdlResult::Refused, its Connection as ConnectRefused.
// A new connect request from a peer SAP that already holds a connection releases the old one
// first (the PG restarted): Disconnected/PeerReconnected.
// Frames for no open connection are answered RS "SAP not activated"; a DU that is no MPI PDU
// is answered UE. A SAP is reused only when its old connection is closed and every frame it
// handed out has its FDL result back, so a late result never reaches a new connection.

#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>
#include <vector>

#include "pbvbus/bus/time.hpp"
#include "pbvbus/mpi/connection.hpp"
#include "pbvbus/mpi/io.hpp"

namespace pbvbus::mpi {

struct PoolConfig {
  /// Connection resources of the CPU (S7-300/400 CPUs have a handful to a few dozen; §H gives
  /// no number). The scenario sets it; 8 is our default.
  std::size_t max_connections = 8;
  std::uint8_t first_sap = kFirstConnectionSap;
  ConnectionTiming timing;
};

class ConnectionPool {
 public:
  explicit ConnectionPool(PoolConfig config = {}) : config_(config) {}

  /// A frame received by the CPU's station; returns the FDL reply for it.
  FdlReply on_frame(bus::Ticks now, const Received& r, Outbox& out);
  /// The FDL result of the oldest unconfirmed frame sent from `local_sap`.
  void on_fdl_result(bus::Ticks now, std::uint8_t local_sap, FdlResult result, Outbox& out);
  /// Runs every connection whose deadline has come.
  void on_timer(bus::Ticks now, Outbox& out);
  /// The earliest deadline of all connections.
  std::optional<bus::Ticks> deadline() const;

  RequestError send_data(bus::Ticks now, std::uint8_t local_sap, std::span<const std::uint8_t> s7_pdu,
                         Outbox& out);
  RequestError disconnect(bus::Ticks now, std::uint8_t local_sap, Outbox& out);

  /// Connections not closed.
  std::size_t open_connections() const;
  /// The open connection on `local_sap`, if any.
  const Connection* find(std::uint8_t local_sap) const;

 private:
  Connection* open_on(std::uint8_t local_sap);
  /// Drops connections that are closed and have no FDL result outstanding.
  void sweep();
  std::optional<std::uint8_t> free_sap() const;

  PoolConfig config_;
  std::vector<Connection> slots_;
};

}  // namespace pbvbus::mpi
