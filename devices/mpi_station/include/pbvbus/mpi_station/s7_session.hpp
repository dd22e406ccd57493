#pragma once
// What a CPU's MPI interface hands the S7 PDUs of each connection to (docs/mpi.md "MPI stations
// on a line"). The station's owner (a CPU model) provides the factory; MpiStation opens one
// session per accepted MPI connection and drops it when the connection ends. Every call is on
// the station's thread, inside a bus event (the CPU model's one thread: s7cpu/cpu_memory.hpp).

#include <cstdint>
#include <memory>
#include <span>
#include <vector>

namespace pbvbus::mpi_station {

/// One S7 server session: one MPI connection's S7 PDUs in, the answer PDUs out.
class S7Session {
 public:
  virtual ~S7Session() = default;
  /// The answer to one S7 PDU from the client; empty = no answer.
  virtual std::vector<std::uint8_t> handle(std::span<const std::uint8_t> pdu) = 0;
};

class S7SessionFactory {
 public:
  virtual ~S7SessionFactory() = default;
  /// A session for a connection from the station at `peer_address`; nullptr refuses it (the
  /// station then disconnects the connection at once).
  virtual std::unique_ptr<S7Session> open(std::uint8_t peer_address) = 0;
};

}  // namespace pbvbus::mpi_station
