#pragma once
// S7 sessions on an H system (docs/h-system.md "S7 communication"): what an outside owner
// (an MPI station, the ISO-on-TCP door) holds for one S7 connection to the H system. One
// session = one s7cpu::S7Server (its negotiated PDU size) answering on the memory of the CPU
// the connection ends on.
//
//   HS7Session s = model.open_s7_adhoc(0);          // or open_s7_connection("name"), ...
//   if (!s.alive()) ... s.close_reason() / s.close_text()   // refused at once (R8, CPU off)
//   std::vector<std::uint8_t> answer = s.handle(pdu);      // empty: no answer
//
// handle() is synchronous, on the simulation's thread, at the scheduler's now, between two
// OB 1 scans (s7cpu.md's consistency rule). A session whose connection is lost answers
// nothing more (empty) and reports why; the owner then closes its side (MPI disconnect, COTP
// DR). The handle is move-only; destroying it (or close()) releases the connection (an
// ad-hoc one gives its CPU's connection resource back). The model must outlive its sessions.
//
// Route kinds (the rules are in docs/h-system.md "S7 communication"):
//   AdHoc          a connection to one CPU (rack 0/1) through its MPI interface, counted
//                  against that CPU's resources (HCpuPair::connect; R8: refused from the start
//                  of a link-up to the end of the update); ends with its CPU (off, ERROR-SEARCH,
//                  DEFECTIVE) and, on the standby, at link-up (R8).
//   Standard       a configured standard connection (HConnections): ends with its CPU or CP.
//   FaultTolerant  a configured fault-tolerant connection: answered by the master, survives
//                  the master's loss and a CP failure while a path remains (F4).
//   Routing        S7 routing through the master to a device behind a switched station's IM
//                  (IM 153-2 / IM 157): the device's own S7 endpoint answers; dropped when the
//                  master changes or the station's active channel switches (seed S7).
#include <cstdint>
#include <functional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

namespace pbvbus::devices {

class HSystemModel;

enum class S7Route : std::uint8_t { AdHoc, Standard, FaultTolerant, Routing };
std::string_view to_string(S7Route r);

enum class S7CloseReason : std::uint8_t {
  None,             ///< alive
  Refused,          ///< never opened (the text says why: R8, CPU off, no such connection ...)
  CpuLost,          ///< its CPU went off, to ERROR-SEARCH or DEFECTIVE
  LinkUp,           ///< R8: the standby's connections break at link-up
  ConnectionLost,   ///< the configured connection was lost (its CPU or CP, every path)
  Switchover,       ///< routing: the master or the IM's active channel changed (seed S7)
  Closed,           ///< closed by its owner
  ProtocolError,    ///< the client sent octets that are not an S7 PDU
};
std::string_view to_string(S7CloseReason r);

/// The S7 endpoint of a device behind a switched IM (routing target): one PDU in, the answer
/// out (empty = none).
using S7Endpoint = std::function<std::vector<std::uint8_t>(std::span<const std::uint8_t>)>;

class HS7Session {
 public:
  HS7Session() = default;
  HS7Session(HSystemModel* model, std::uint32_t id) : m_model(model), m_id(id) {}
  HS7Session(const HS7Session&) = delete;
  HS7Session& operator=(const HS7Session&) = delete;
  HS7Session(HS7Session&& o) noexcept : m_model(o.m_model), m_id(o.m_id) { o.m_model = nullptr; }
  HS7Session& operator=(HS7Session&& o) noexcept;
  ~HS7Session();

  /// The answer to one S7 PDU; empty when there is none (closed, or not an S7 PDU: the
  /// session then closes with ProtocolError).
  std::vector<std::uint8_t> handle(std::span<const std::uint8_t> pdu);
  bool alive() const;
  S7CloseReason close_reason() const;
  std::string close_text() const;
  /// The CPU answering now (-1 for a routing session or a closed one).
  int answering_rack() const;
  S7Route route() const;
  /// The owner takes answers that come later: a job arriving during an update (t1..t5) is
  /// stored, handle() answers nothing, and the answer goes to `sink` when the update ends (000
  /// L1673-1680; docs/h-sfc90.md). Without a sink every job is answered at once.
  void on_late_answer(std::function<void(std::vector<std::uint8_t>)> sink);
  /// True when a job handed to handle() now would be stored and answered through the sink
  /// (the rule of on_late_answer: a sink is registered and the update is in [t1, t5)).
  bool holds_jobs_now() const;
  /// Closes it (Closed) and releases the connection; idempotent.
  void close();
  std::uint32_t id() const { return m_id; }

 private:
  HSystemModel* m_model = nullptr;
  std::uint32_t m_id = 0;
};

}  // namespace pbvbus::devices
