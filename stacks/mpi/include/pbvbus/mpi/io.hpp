#pragma once
// What goes into and comes out of the sans-I/O MPI connection layer (docs/mpi.md).
//
// In: MPI PDUs received in FDL frames (`Received`), the FDL layer's confirmation of each frame
// this layer handed it (`FdlResult`, in the order the frames were handed out), user requests,
// and the current virtual time with every call (timer expiry = a call of on_timer() once
// `deadline()` is reached). Out: frames to send (`Outgoing`, the station's FDL layer picks FC,
// FCB/FCV and priority), events for the user (`Event`), and for every received frame the FDL
// reply the station gives at once (`FdlReply`).

#include <cstdint>
#include <span>
#include <string_view>
#include <vector>

#include "pbvbus/bus/time.hpp"
#include "pbvbus/mpi/pdu.hpp"

namespace pbvbus::mpi {

/// An MPI PDU that arrived in an FDL request frame (§H.2: SD2 with SAP extensions, SRD).
struct Received {
  std::uint8_t peer = 0;  ///< the frame's SA
  std::uint8_t dsap = 0;  ///< the frame's DSAP: our SAP
  std::uint8_t ssap = 0;  ///< the frame's SSAP: the peer's SAP
  std::span<const std::uint8_t> pdu;  ///< the DU after the SAP octets
};

/// What the station's FDL layer answers to a received frame (§B.3 response status; §H.2: a
/// frame taken is acknowledged with SC E5). Not in §H: refusing with RR/RS/UE is our choice
/// (docs/mpi.md "Decisions").
enum class FdlReply : std::uint8_t {
  Ack,             ///< SC (E5): taken
  NoResources,     ///< status RR: connect refused, no free connection
  SapNotActivated, ///< status RS: no connection on this SAP pair
  UserError,       ///< status UE: the DU is no valid MPI PDU
};
std::string_view to_string(FdlReply r);

/// How the FDL layer's transmission of one frame this layer handed out ended.
enum class FdlResult : std::uint8_t {
  Delivered,  ///< SC or status OK
  Refused,    ///< the peer answered RR, RS or UE
  NoAnswer,   ///< no reply after the FDL retries (§C.6): the peer is gone
};

/// A frame to send: SRD to `peer` with DSAP/SSAP and the encoded MPI PDU.
struct Outgoing {
  std::uint8_t peer = 0;
  std::uint8_t dsap = 0;
  std::uint8_t ssap = 0;
  PduType type = PduType::DisconnectRequest;
  PduBuffer pdu;
};

enum class EventKind : std::uint8_t {
  ConnectIndication,  ///< responder: a connect request was accepted (confirm sent)
  Connected,          ///< both ends: the connection acks were exchanged
  ConnectRefused,     ///< initiator: the peer's FDL answered the connect request with RR/RS/UE
  DataIndication,     ///< a new data message arrived (`data`, `message_number`)
  DataConfirm,        ///< our data message `message_number` was acknowledged
  Disconnected,       ///< closed in order (`reason`: Local or ByPeer)
  Broken,             ///< closed by a failure (`reason`)
};
std::string_view to_string(EventKind k);

enum class Reason : std::uint8_t {
  None,
  Local,            ///< our user's disconnect, confirmed by the FDL layer
  ByPeer,           ///< the peer's disconnect request
  PeerReconnected,  ///< responder: the same peer SAP sent a new connect request
  ConnectTimeout,   ///< no confirm / connection ack within the connect timeout
  AckTimeout,       ///< no data ack within the ack timeout
  PeerGone,         ///< the FDL layer got no answer from the peer
  PeerRefused,      ///< the peer's FDL refused a frame of the connection (RR/RS/UE)
  SequenceError,    ///< a data message or data ack with a message number out of sequence
};
std::string_view to_string(Reason r);

struct Event {
  EventKind kind = EventKind::Connected;
  std::uint8_t local_sap = 0;
  std::uint8_t peer = 0;
  std::uint8_t peer_sap = 0;
  std::uint8_t message_number = 0;
  Reason reason = Reason::None;
  std::vector<std::uint8_t> data;  ///< DataIndication: the S7 PDU
};

/// Collects one call's outputs. The caller empties it when it has acted on them.
struct Outbox {
  std::vector<Outgoing> frames;
  std::vector<Event> events;
  void clear() {
    frames.clear();
    events.clear();
  }
};

}  // namespace pbvbus::mpi
