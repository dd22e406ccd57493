#pragma once
// One end of an MPI connection, sans-I/O (protocol-facts.md §H.3; docs/mpi.md).
//
// Initiator (PG/OP side)                         Responder (CPU side, made by ConnectionPool)
//   connect()      -> E0 to DSAP 0x00  ConnectSent
//                                                 E0 in  -> D0 from its own SAP   ConfirmSent
//   D0 in          -> 05 01            AckSent
//                                                 05 01 in -> 05 01               Connected
//   05 01 in                           Connected
//   either way: F1 nr <S7 PDU> -> the receiver answers B0 01 nr; one data message
//   outstanding per direction (libnodave waits for each ack before the next message)
//   disconnect()   -> 80              Disconnecting -> Closed when the FDL layer confirms it
//
// Message numbers (§H.3): the sender counts 0, 1, ..., 255, 1, 2, ... (next_message_number()).
// The receiver takes the first number it sees (§H.3 says 0; a real peer attached through a pty
// may start elsewhere), then requires each next one; the previous number again is a repeat
// (its ack was lost) and is acknowledged again without a second DataIndication; any other
// number is a SequenceError. A data ack must carry the outstanding number; the last acked
// number again is a repeat and ignored.
//
// Broken connections: no confirm or connection ack within `connect_timeout`, no data ack within
// `ack_timeout`, an FDL NoAnswer (peer gone) or refusal for any frame of the connection, a
// sequence error. When the peer may still hold the connection (timeouts, sequence errors) a
// disconnect request 80 goes to it so it frees its resources (our choice: §H.3 shows 80 only
// from the PG). A silent, idle peer is noticed at the next frame we send (§H.3 has no alive
// check).

#include <cstdint>
#include <deque>
#include <optional>
#include <span>
#include <string_view>

#include "pbvbus/bus/time.hpp"
#include "pbvbus/mpi/io.hpp"
#include "pbvbus/mpi/pdu.hpp"

namespace pbvbus::mpi {

/// Timeouts, as ticks (design: 1 s = 3 636 000 000 ticks). §H gives none; the defaults are
/// libnodave's adapter timeout (`di->timeout = 1000000` µs, 1 s) for both.
struct ConnectionTiming {
  bus::Ticks connect_timeout = bus::kTicksPerSecond;
  bus::Ticks ack_timeout = bus::kTicksPerSecond;
};

enum class Role : std::uint8_t { Initiator, Responder };
enum class State : std::uint8_t {
  Closed,
  ConnectSent,    ///< initiator: E0 sent, waiting for D0
  ConfirmSent,    ///< responder: D0 sent, waiting for 05 01
  AckSent,        ///< initiator: 05 01 sent, waiting for the responder's 05 01
  Connected,
  Disconnecting,  ///< initiator or responder: 80 sent, waiting for the FDL layer's confirmation
};
std::string_view to_string(State s);

enum class RequestError : std::uint8_t {
  None = 0,
  WrongState,  ///< the request does not fit the connection's state
  Busy,        ///< a data message is still waiting for its ack
  EmptyData,   ///< a data message without an S7 PDU
  TooLong,     ///< more than kMaxDataLen octets
};
std::string_view to_string(RequestError e);

class Connection {
 public:
  /// The PG/OP end: `local_sap` is its own SAP (libnodave: 0x14), `peer` the CPU's address.
  static Connection initiator(std::uint8_t peer, std::uint8_t local_sap, ConnectionTiming timing = {},
                              const ConnectParams& params = kTraceConnectParams);
  /// The CPU end for a connect request from `peer`/`peer_sap`; call accept() next.
  static Connection responder(std::uint8_t peer, std::uint8_t peer_sap, std::uint8_t local_sap,
                              ConnectionTiming timing = {});

  // --- user requests ---------------------------------------------------------------------------
  /// Initiator, Closed: sends the connect request. A closed initiator may connect again.
  RequestError connect(bus::Ticks now, Outbox& out);
  /// Responder, Closed (fresh): answers the connect request `cr` with a confirm carrying the same
  /// connect parameters (the §H.3 trace: request and confirm carry the same 11 octets).
  RequestError accept(bus::Ticks now, const Pdu& cr, Outbox& out);
  /// Connected, no data message outstanding: sends F1 <next number> <s7_pdu>.
  RequestError send_data(bus::Ticks now, std::span<const std::uint8_t> s7_pdu, Outbox& out);
  /// Any state but Closed/Disconnecting: sends 80 (before the peer's SAP is known, i.e. in
  /// ConnectSent, nothing can be sent: closes at once with Disconnected/Local).
  RequestError disconnect(bus::Ticks now, Outbox& out);

  /// Closes at once without a frame, reporting Disconnected with `reason` (the pool, when the
  /// peer opens again from the same SAP).
  void release(Reason reason, Outbox& out);

  // --- inputs ----------------------------------------------------------------------------------
  /// Whether a received frame belongs to this connection (peer, our SAP, the peer's SAP once
  /// known; in ConnectSent any peer SAP, since the confirm brings it).
  bool matches(const Received& r) const;
  /// A frame for this connection (matches() holds); returns the FDL reply for it.
  FdlReply on_frame(bus::Ticks now, const Received& r, Outbox& out);
  /// The FDL layer's result for the oldest frame of this connection not yet confirmed.
  void on_fdl_result(bus::Ticks now, FdlResult result, Outbox& out);
  /// Call when now >= deadline().
  void on_timer(bus::Ticks now, Outbox& out);
  std::optional<bus::Ticks> deadline() const { return deadline_; }

  // --- observation -----------------------------------------------------------------------------
  Role role() const { return role_; }
  State state() const { return state_; }
  std::uint8_t peer() const { return peer_; }
  std::uint8_t local_sap() const { return local_sap_; }
  std::optional<std::uint8_t> peer_sap() const { return peer_sap_; }
  /// The number the next data message will carry.
  std::uint8_t next_tx_number() const { return tx_next_; }
  bool awaiting_data_ack() const { return tx_outstanding_.has_value(); }
  /// Frames handed out whose FDL result has not come back yet.
  std::size_t unconfirmed_frames() const { return unconfirmed_.size(); }
  /// Received PDUs that did not fit the state (or did not decode) and were dropped.
  std::uint32_t ignored_pdus() const { return ignored_; }

 private:
  Connection(Role role, std::uint8_t peer, std::uint8_t local_sap, ConnectionTiming timing);
  void emit(const Pdu& pdu, std::uint8_t dsap, Outbox& out);
  void event(EventKind kind, Outbox& out, Reason reason = Reason::None, std::uint8_t nr = 0);
  void close(EventKind kind, Reason reason, Outbox& out);
  /// Closes as Broken; first sends 80 if the peer's SAP is known and the peer may still hold
  /// the connection.
  void abort(Reason reason, bool tell_peer, Outbox& out);
  void on_data(const Pdu& p, Outbox& out);
  void on_data_ack(const Pdu& p, Outbox& out);

  struct Pending {
    PduType type;
    std::uint32_t generation;
  };

  Role role_;
  State state_ = State::Closed;
  std::uint8_t peer_;
  std::uint8_t local_sap_;                ///< S4 `connectionNumber` on the PG side
  std::optional<std::uint8_t> peer_sap_;  ///< S4 `connectionNumber2`: the confirm's SSAP
  ConnectionTiming timing_;
  ConnectParams params_ = kTraceConnectParams;
  std::optional<bus::Ticks> deadline_;
  std::uint8_t tx_next_ = 0;                     ///< S4 `messageNumber`
  std::optional<std::uint8_t> tx_outstanding_;  ///< S4 `needAckNumber`
  std::optional<std::uint8_t> tx_last_acked_;
  std::optional<std::uint8_t> rx_last_;
  std::deque<Pending> unconfirmed_;
  std::uint32_t generation_ = 0;  ///< bumped at every connect: results of older frames are stale
  std::uint32_t ignored_ = 0;
};

}  // namespace pbvbus::mpi
