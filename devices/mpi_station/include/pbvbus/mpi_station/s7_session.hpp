#pragma once
// What a CPU's MPI interface hands the S7 PDUs of each connection to (docs/mpi.md "MPI stations
// on a line"). The station's owner (a CPU model) provides the factory; MpiStation opens one
// session per accepted MPI connection and drops it when the connection ends. Every call is on
// the station's thread, inside a bus event (the CPU model's one thread: s7cpu/cpu_memory.hpp).

#include <cstdint>
#include <functional>
#include <memory>
#include <span>
#include <vector>

namespace pbvbus::mpi_station {

/// Where a session hands an answer it gives later (S7Session::on_late_answer).
using LateAnswerSink = std::function<void(std::vector<std::uint8_t>)>;

/// One S7 server session: one MPI connection's S7 PDUs in, the answer PDUs out.
///
/// Late answers (an H CPU holds the jobs that arrive during an update and answers them after
/// it, 000 L1673-1680; docs/h-sfc90.md "Communication jobs held by the update"): a session
/// that holds a job says so with holds_jobs_now() before handle(), returns nothing from
/// handle(), and later hands the answer to the sink the station gave it with on_late_answer();
/// the station sends it on the session's connection then, after the answers still queued there
/// (arrival order). The sink may be called at any time on the station's thread, inside a
/// station call or not; it does nothing once the connection has ended. A session must not call
/// it after its destruction (the station destroys it when the connection ends).
class S7Session {
 public:
  virtual ~S7Session() = default;
  /// The answer to one S7 PDU from the client; empty = no answer (or, when holds_jobs_now()
  /// said so just before, an answer that comes later through the sink).
  virtual std::vector<std::uint8_t> handle(std::span<const std::uint8_t> pdu) = 0;
  /// True when a PDU handed to handle() now would be held and answered later. Default: never.
  virtual bool holds_jobs_now() const { return false; }
  /// The station's sink for late answers, given once when the session opens, before the
  /// first handle(). Default: ignored (the session never answers later).
  virtual void on_late_answer(LateAnswerSink /*sink*/) {}
  /// True once the session answers nothing more (an H CPU's connection lost with its CPU or at
  /// a link-up, R8): when a job then gets no answer, the station releases the connection (80)
  /// and reports it Broken/SessionEnded. Default: never.
  virtual bool ended() const { return false; }
};

class S7SessionFactory {
 public:
  virtual ~S7SessionFactory() = default;
  /// A session for a connection from the station at `peer_address`; nullptr refuses it (the
  /// station then disconnects the connection at once).
  virtual std::unique_ptr<S7Session> open(std::uint8_t peer_address) = 0;
};

}  // namespace pbvbus::mpi_station
