#pragma once
// An MPI station on a line (docs/mpi.md "MPI stations on a line"; protocol-facts.md §H.2, §H.3):
// an FDL active station (fdl::ActiveStation, in the same token ring as DP masters) whose
// initiator user carries stacks/mpi connections.
//
// Roles, either or both:
//  - client (PG/OP): open(cpu_address) -> a handle; submit(handle, s7_pdu) queues S7 PDUs, sent
//    one at a time per connection (stop and wait, docs/mpi.md decision 6); close(handle).
//    Events: Connected, Refused, Reply(pdu), Broken(reason), Closed(reason).
//  - server (a CPU's MPI interface): a mpi::ConnectionPool (max connections configurable;
//    beyond it the connect request's SRD is answered RR, docs/mpi.md decision 4); each accepted
//    connection gets an S7Session from the owner's S7SessionFactory; each S7 PDU received is
//    handed to it and its answer goes back as a data message of its own. Events: Accepted,
//    Connected, Broken, Closed.
//
// On the wire (§H.2, §H.3): every MPI PDU travels as SD2 with SAP extensions in an SRD the
// receiver's FDL answers at once with SC (E5); FC, FCB/FCV and repeats are the FDL layer's
// (ActiveStation). Frames of connections this station opened go as SRD high, those of
// connections it accepted as SRD low, as the §H.3 trace shows (6D from the PG, 6C from the
// PLC). A frame waits in the station's queue until the station holds the token; so the data
// ack (B0 01 nr) goes as its own SRD when the receiver next holds the token, and an answer PDU
// follows it as its own data message (the S7 session answers inside the indication, so ack and
// answer usually leave in the same token visit, ack first).
//
// Late answers (s7_session.hpp; an H CPU holds the jobs arriving during an update, 000
// L1673-1680): the job's data message is acknowledged at once all the same (B0 01 nr: the MPI
// layer acks the message, not the job), so the client's connection stays up however long the
// job is held (stacks/mpi times only the connect and the data ack, mpi::ConnectionTiming; the
// wait for the answer is the client's S7 job timeout, not an MPI matter). The answer goes out,
// when the session hands it over, as a data message of its own like any answer (queued behind
// the connection's other answers, sent when the previous one is acked, at the station's next
// token). A connection that ended meanwhile drops it.
//
// Broken connections (reported once, as Broken with a reason): the mpi layer's (no confirm, no
// data ack in time, FDL NoResponse = PeerGone, FDL refusal, sequence error); a peer that leaves
// the token ring (our LAS loses it: cut, power off) for `peer_absent_timeout` -> PeerLeftRing,
// or TokenLost when our own station claimed the token meanwhile and is still alone in its ring
// (the line is dead or we are cut off alone: token loss); our own power loss
// -> PowerLoss (every connection, at once). A connection whose peer left the ring is also
// released towards the peer (80), in case it still holds it.
//
// Time: the station is the bus::Device; it wraps the ActiveStation behind a port of its own so
// that the connections' deadlines (mpi::ConnectionTiming) and the ring watch share the one timer
// with the MAC.

#include <array>
#include <cstdint>
#include <deque>
#include <functional>
#include <memory>
#include <optional>
#include <span>
#include <string_view>
#include <vector>

#include "pbvbus/bus/device.hpp"
#include "pbvbus/fdl/active_station.hpp"
#include "pbvbus/fdl/bus_params.hpp"
#include "pbvbus/fdl/station.hpp"
#include "pbvbus/mpi/connection.hpp"
#include "pbvbus/mpi/connection_pool.hpp"
#include "pbvbus/mpi/io.hpp"
#include "pbvbus/mpi_station/mpi_bus_params.hpp"
#include "pbvbus/mpi_station/s7_session.hpp"

namespace pbvbus::mpi_station {

struct MpiStationConfig {
  std::uint8_t address = 0;                  ///< MPI address (defaults PG 0, OP 1, CPU 2, §H.1)
  fdl::BusParams bus = mpi_bus_params();     ///< the line's MPI bus parameters
  mpi::ConnectionTiming timing;              ///< client connections' timeouts
  /// First SAP of client connections (libnodave's 0x14, §H.3 trace). With the server role on,
  /// client SAPs end below `pool.first_sap` (the pool's SAPs run from there to 63).
  std::uint8_t client_first_sap = mpi::kFirstConnectionSap;
  /// Server role: connection resources and timeouts (the S7-400H seed: MPI 32 for a 414-4H,
  /// 44 for a 417-4H; seeds-digest §3.2).
  mpi::PoolConfig pool;
  /// A peer that has been seen in the token ring and is missing from our LAS this long breaks
  /// its connections (PeerLeftRing / TokenLost). Our choice; as long as libnodave's timeout.
  bus::Ticks peer_absent_timeout = bus::kTicksPerSecond;
};

using Handle = std::uint32_t;

enum class Role : std::uint8_t { Client, Server };

enum class EventKind : std::uint8_t {
  Accepted,   ///< server: a connect request was accepted (confirm queued), session opened
  Connected,  ///< both: the connection acks were exchanged
  Refused,    ///< client: the CPU's FDL refused the connect request (RR, RS or UE)
  Reply,      ///< client: an S7 PDU from the peer (`pdu`)
  Broken,     ///< both: the connection failed (`reason`)
  Closed,     ///< both: the connection ended in order (`reason`: Local, ByPeer, PeerReconnected)
};
std::string_view to_string(EventKind k);

enum class EndReason : std::uint8_t {
  None,
  Local,            ///< our close(), confirmed by the FDL layer
  ByPeer,           ///< the peer's disconnect request (80)
  PeerReconnected,  ///< server: the same peer SAP sent a new connect request
  ConnectTimeout,   ///< no confirm / connection ack in time (mpi layer)
  AckTimeout,       ///< no data ack in time (mpi layer)
  PeerGone,         ///< the FDL layer got no answer from the peer after its retries
  PeerRefused,      ///< the peer's FDL refused a frame (RR/RS/UE)
  SequenceError,    ///< message number out of sequence (mpi layer)
  PeerLeftRing,     ///< the peer left the token ring for peer_absent_timeout
  TokenLost,        ///< the peer missing, our station alone after claiming a lost token
  PowerLoss,        ///< our own station lost power
  Refused,          ///< server: the session factory refused the connection
  SessionEnded,     ///< server: the session answers nothing more (S7Session::ended)
};
inline constexpr std::size_t kEndReasonCount = static_cast<std::size_t>(EndReason::SessionEnded) + 1;
std::string_view to_string(EndReason r);

struct StationEvent {
  bus::Ticks at = 0;
  EventKind kind = EventKind::Connected;
  Role role = Role::Client;
  Handle handle = 0;            ///< client connections; 0 for server connections
  std::uint8_t local_sap = 0;   ///< our SAP of the connection
  std::uint8_t peer = 0;        ///< the peer's MPI address
  EndReason reason = EndReason::None;
  std::vector<std::uint8_t> pdu;  ///< Reply: the S7 PDU
};

struct MpiStationStats {
  std::uint64_t frames_sent = 0;        ///< MPI PDUs handed to the MAC (without FDL repeats)
  std::uint64_t frames_delivered = 0;   ///< ... acknowledged by the peer's FDL (SC)
  std::uint64_t frames_refused = 0;     ///< ... answered RR/RS/UE
  std::uint64_t frames_unanswered = 0;  ///< ... without answer after the FDL retries
  std::uint64_t frames_received = 0;    ///< MPI frames addressed to us (SRD with SAPs)
  std::uint64_t replies_not_sc = 0;     ///< of those, answered RR/RS/UE instead of SC
  std::uint64_t connects_opened = 0;    ///< client: open() calls that sent a connect request
  std::uint64_t connects_accepted = 0;  ///< server: connections accepted
  std::uint64_t connects_refused = 0;   ///< server: connect requests refused with RR
  std::uint64_t refusals_received = 0;  ///< client: connect requests the peer refused
  std::uint64_t connected = 0;          ///< connections that reached Connected (both roles)
  std::uint64_t pdus_sent = 0;          ///< S7 PDUs sent in data messages
  std::uint64_t pdus_received = 0;      ///< S7 PDUs received in data messages
  std::uint64_t answers_none = 0;       ///< server: sessions that gave no answer
  std::uint64_t answers_too_long = 0;   ///< server: answers over 242 octets, dropped
  std::uint64_t answers_held = 0;       ///< server: jobs a session held to answer later
  std::uint64_t answers_late = 0;       ///< server: late answers queued on their connection
  std::uint64_t late_answers_dropped = 0;  ///< server: late answers of connections gone
  std::uint64_t closed = 0;             ///< connections closed in order
  std::array<std::uint64_t, kEndReasonCount> broken{};  ///< Broken events by EndReason
};

class MpiStation final : public bus::Device {
 public:
  /// `server` non-null: the station serves S7 over MPI (a CPU's MPI interface) with sessions
  /// from it; it must outlive the station.
  explicit MpiStation(const MpiStationConfig& config, S7SessionFactory* server = nullptr);
  ~MpiStation() override;
  MpiStation(const MpiStation&) = delete;
  MpiStation& operator=(const MpiStation&) = delete;

  // --- client role -------------------------------------------------------------------------
  /// Opens a connection to the CPU at `cpu_address`: the connect request waits for the token.
  /// nullopt: no free client SAP, or an address that is ours or not 0..126.
  std::optional<Handle> open(std::uint8_t cpu_address);
  /// Queues an S7 PDU on the connection (sent once connected, each after the previous one's
  /// data ack). WrongState: unknown or ended connection; EmptyData; TooLong (> 242 octets).
  mpi::RequestError submit(Handle h, std::span<const std::uint8_t> s7_pdu);
  /// Sends the disconnect request (80); Closed/Local follows when the FDL layer delivered it.
  mpi::RequestError close(Handle h);
  /// The connection's state (Closed also for unknown handles).
  mpi::State state(Handle h) const;
  /// PDUs queued on the connection and not yet sent.
  std::size_t queued(Handle h) const;

  // --- events --------------------------------------------------------------------------------
  /// Each event is handed to `handler` as it happens (inside a bus event; the handler may call
  /// open/submit/close). Without a handler events are kept for take_events().
  void set_event_handler(std::function<void(const StationEvent&)> handler) { handler_ = std::move(handler); }
  std::vector<StationEvent> take_events();

  // --- observation ---------------------------------------------------------------------------
  const MpiStationStats& stats() const { return stats_; }
  const fdl::ActiveStation& mac() const { return mac_; }
  std::uint8_t address() const { return mac_.address(); }
  bool serves() const { return server_ != nullptr; }
  /// Server role: connections open in the pool (what counts against max_connections).
  std::size_t server_connections() const { return pool_.open_connections(); }
  /// Server role: jobs held by the sessions (S7Session::holds_jobs_now), not yet answered.
  std::size_t held_jobs() const;
  /// MPI frames waiting for the token.
  std::size_t frames_queued() const { return tx_high_.size() + tx_low_.size(); }

  // --- bus::Device -------------------------------------------------------------------------
  void on_power_on(bus::Ticks now) override;
  void on_power_off(bus::Ticks now) override;
  void on_frame(const bus::RxFrame& frame) override;
  void on_timer(bus::Ticks now) override;
  const char* kind() const override { return "MPI station"; }

 private:
  class Port;
  class MacUser;
  struct Watch {  // the peer's presence in the token ring
    bool seen = false;
    bus::Ticks absent_since = bus::kNever;
    std::uint64_t token_losses = 0;  // our MAC's count when the peer was last seen
  };
  struct Client {
    Handle handle = 0;
    mpi::Connection conn;
    std::deque<std::vector<std::uint8_t>> pending;
    Watch watch;
    bool reported = false;  // a Broken/Closed/Refused event has been given
  };
  struct Served {
    std::uint32_t serial = 0;  // this connection among all the station served (a SAP is reused)
    std::size_t held = 0;      // jobs held by the session, answers still to come
    std::uint8_t sap = 0;
    std::uint8_t peer = 0;
    std::unique_ptr<S7Session> session;
    std::deque<std::vector<std::uint8_t>> pending;
    Watch watch;
    bool reported = false;
  };
  struct Tx {
    mpi::Outgoing frame;
    bool client = false;
    Handle handle = 0;
  };

  // What the MAC asks of its user (fdl::InitiatorUser, through MacUser: Device and
  // InitiatorUser both have an on_power_on(Ticks)).
  bool next_request(fdl::Priority prio, bus::Ticks now, fdl::Request& out);
  void on_confirmation(const fdl::Confirmation& con);
  void on_request(const fdl::Indication& ind, fdl::Reply& reply);
  void on_token(bus::Ticks now);

  bus::Ticks now() const;
  Client* client(Handle h);
  const Client* client(Handle h) const;
  Client* client_by_sap(std::uint8_t sap);
  Served* served(std::uint8_t sap);
  std::optional<std::uint8_t> free_client_sap() const;
  /// Moves the outbox's frames to the queues and turns its events into station events, until
  /// nothing is left (events may produce more output).
  void flush(bus::Ticks now);
  void on_client_event(bus::Ticks now, const mpi::Event& e);
  void on_server_event(bus::Ticks now, const mpi::Event& e);
  void send_pending_client(bus::Ticks now, Client& c);
  void send_pending_served(bus::Ticks now, Served& s);
  /// A session's late answer (its sink): queued on its connection if that is still open.
  void answer_later(std::uint32_t serial, std::vector<std::uint8_t> answer);
  /// No answer from `s`'s session: if it has ended, the connection is released (80) and
  /// reported Broken/SessionEnded (the session itself goes with the connection's end).
  void no_answer(bus::Ticks now, Served& s);
  /// Queues an event; deliver() hands the queue to the handler (or keeps it for take_events()).
  void emit(StationEvent ev);
  void deliver();
  void count_end(EventKind kind, EndReason reason);
  /// Counts and reports the end of a server connection that we disconnected (`reason`).
  void report_server_end(bus::Ticks now, std::uint8_t sap, std::uint8_t peer, EndReason reason);
  /// Ring watch, connection deadlines and absence timeouts; then flush.
  void run_due(bus::Ticks now);
  void watch_ring(bus::Ticks now);
  void watch_one(bus::Ticks now, std::uint8_t peer, Watch& w);
  bool alone_in_ring() const;
  bus::Ticks next_deadline() const;
  void rearm();
  void sweep();

  MpiStationConfig config_;
  S7SessionFactory* server_;
  std::unique_ptr<Port> port_;
  std::unique_ptr<MacUser> user_;
  fdl::ActiveStation mac_;
  bus::Ticks mac_timer_ = bus::kNever;
  bool powered_ = false;
  bool flushing_ = false;

  Handle next_handle_ = 1;
  std::vector<Client> clients_;
  mpi::ConnectionPool pool_;
  std::vector<Served> served_;
  std::uint32_t next_serial_ = 1;

  std::deque<Tx> tx_high_, tx_low_;
  std::optional<Tx> in_flight_;
  mpi::Outbox out_;

  std::function<void(const StationEvent&)> handler_;
  std::vector<StationEvent> pending_events_;
  std::vector<StationEvent> events_;
  bool delivering_ = false;
  MpiStationStats stats_;
};

}  // namespace pbvbus::mpi_station
