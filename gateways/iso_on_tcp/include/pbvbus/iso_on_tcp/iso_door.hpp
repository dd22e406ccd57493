#pragma once
// The ISO-on-TCP door (docs/iso-on-tcp.md): a listening TCP socket on the owner's Boost.Asio
// io_context (the paced runner's, so the door and the simulation share one thread); each
// connection is an IsoSession (iso_session.hpp) routed through the owner's S7Router.
//
// Bounded like the Modbus TCP door (docs/gateway-modbus-doors.md), decisions in
// docs/iso-on-tcp.md "Limits":
//  - At most `max_clients` connections (32). One more is accepted and closed at once, counted
//    and logged (throttled): every connection holds a CPU connection resource, so the door does
//    not evict an open S7 connection for a newcomer (the Modbus door does, having none).
//  - Flow control: while a quarter of `max_output` (64 KiB) or more of answers waits for the
//    client, the door takes no more of its input (TCP then holds the client back) and goes on
//    once the output has drained. A client that pipelines faster than it reads is slowed, not
//    closed; input is handed to the session 256 octets at a time, so the output overshoots the
//    quarter by at most 8 answers.
//  - A connection that brings no progress (a CR confirmed or a whole S7 job) for
//    `idle_timeout` (60 s wall time; zero = never) is closed: half-open sockets and
//    byte-dribbling clients (closed_idle), and a client that does not read, whose input the
//    door no longer takes (closed_stalled).
//  - Output beyond `max_output` (possible only with a channel that answers later, for jobs
//    queued before the pause) closes the connection at once (closed_stalled). Accepted sockets
//    also get the shared 32 KiB SO_SNDBUF (tcp_accept.hpp).
//  - Garbage (TPKT framing lost, a TPDU or S7 PDU the session refuses) closes the connection;
//    pipelined jobs beyond AmQ + max_queued_jobs close it too. One log line each, throttled
//    (ThrottledLog), and counted.
//  - Reads take at most 4 KiB per wake-up (one async_read_some), so a flooding client holds the
//    thread for at most the jobs in 4 KiB before the io_context runs something else.
//  - A client that half-closes (EOF) after its last job gets the answers still owed by a channel
//    that answers at once, then the connection closes.
//  - Backlog SOMAXCONN and a pause on a failing accept() (out of descriptors), as every TCP door
//    (tcp_accept.hpp).
// close() and the destructor close the listener and every connection (channels are destroyed,
// the routes end). The io_context must outlive the door.
#include <boost/asio/io_context.hpp>
#include <chrono>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>

#include "pbvbus/iso_on_tcp/iso_session.hpp"
#include "pbvbus/iso_on_tcp/pdu_capture.hpp"
#include "pbvbus/iso_on_tcp/s7_router.hpp"
#include "pbvbus/tcp_door/tcp_door_limits.hpp"

namespace pbvbus::iso_on_tcp {

/// The IANA port of ISO-TSAP (RFC 1006); binding it needs root, CAP_NET_BIND_SERVICE or
/// `sysctl net.ipv4.ip_unprivileged_port_start=102` (docs/iso-on-tcp.md "Port 102").
inline constexpr std::uint16_t kIsoTsapPort = 102;

struct IsoDoorOptions {
  std::string address = "127.0.0.1";  ///< loopback unless told otherwise
  std::uint16_t port = kIsoTsapPort;  ///< 0 = an ephemeral port (see port())
  std::size_t max_clients = gateways::kDefaultMaxClients;
  std::size_t max_output = 64 * 1024;              ///< octets of unsent answers per connection
  std::chrono::milliseconds idle_timeout{60'000};  ///< zero = never
  SessionLimits session{};
  gateways::DoorLog log{};  ///< refusals, bad closes, accept() failures (empty: none)
  PduCapture capture{};     ///< every S7 PDU in and out (empty: none)
};

struct IsoDoorStats {
  std::uint64_t clients_accepted = 0;   ///< TCP connections taken
  std::uint64_t clients_now = 0;        ///< open now
  std::uint64_t clients_refused = 0;    ///< closed at once: max_clients reached
  std::uint64_t connects = 0;           ///< CRs confirmed (CC sent)
  std::uint64_t connects_refused = 0;   ///< CRs the router refused (DR sent)
  std::uint64_t disconnects = 0;        ///< DRs from clients (DC sent)
  std::uint64_t routes_closed = 0;      ///< channels that closed (DR sent)
  std::uint64_t closed_garbage = 0;     ///< framing, TPDU or S7 PDU refused; no answer
  std::uint64_t closed_queue_full = 0;  ///< pipelined past AmQ + max_queued_jobs
  std::uint64_t closed_stalled = 0;     ///< a client that does not read (held back, or max_output)
  std::uint64_t closed_idle = 0;        ///< no progress for idle_timeout
  std::uint64_t accept_pauses = 0;      ///< accept() failed (out of descriptors): paused
  std::uint64_t jobs = 0;               ///< S7 jobs from clients
  std::uint64_t answers = 0;            ///< S7 answers to clients
};

class IsoOnTcpDoor {
 public:
  /// Listens at once; throws boost::system::system_error when it cannot (address in use, port
  /// 102 without the right to bind it, a bad address).
  IsoOnTcpDoor(boost::asio::io_context& io, S7Router& router, IsoDoorOptions opt = {});
  ~IsoOnTcpDoor();
  IsoOnTcpDoor(const IsoOnTcpDoor&) = delete;
  IsoOnTcpDoor& operator=(const IsoOnTcpDoor&) = delete;

  std::uint16_t port() const;
  const IsoDoorStats& stats() const;
  /// Closes the listener and every connection. Idempotent.
  void close();

 private:
  struct Impl;
  std::shared_ptr<Impl> m;
};

}  // namespace pbvbus::iso_on_tcp
