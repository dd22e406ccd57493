#pragma once
// The Modbus TCP door (docs/gateway-modbus.md): a listening socket on the paced run's Boost.Asio io_context
// (bus::PacedRunner::io_context()); every connection's requests are framed by their MBAP header
// (modbus_frame.hpp) and handed to a ModbusHandler (the gateway core) as unit + PDU; the PDU it
// returns goes back with the request's transaction id and unit.
//
// Everything runs on the io_context's thread (the bus thread). The door has no thread of its
// own and never blocks: reads, writes and accepts are asynchronous, and a misbehaving client
// costs the bus at most `max_requests_per_turn` handler calls before the io_context runs
// something else. Decisions (also in docs/gateway-modbus-doors.md):
//  - Reading: each connection reads whatever has arrived (async_read_some into a 4 KiB buffer)
//    and frames complete ADUs from it: 7-octet MBAP header, then LEN-1 octets of PDU. Several
//    requests in one segment (pipelining) are served in order; a request split over many
//    segments (a slow client sending byte by byte) waits until it is whole.
//  - Fairness: at most `max_requests_per_turn` (16) requests of one connection per io_context
//    turn; the rest is `post`ed, so the paced runner's timer and the other connections run in
//    between. A client flooding pipelined requests therefore never delays the bus by more than
//    16 requests' work.
//  - A bad MBAP header (PID != 0, LEN < 2 or > 254) cannot be skipped (there is no way to find
//    the next header in a byte stream): the connection is closed, counted in bad_frames and
//    clients_closed_bad. Requests already answered stay answered (their responses are flushed
//    before the close when the socket takes them at once).
//  - Responses are queued and written with async_write (first tried at once, non-blocking). A
//    client that does not read its responses, so that more than `max_output` (64 KiB) waits in
//    the door, is closed (clients_closed_bad). The kernel's share is bounded too: accepted
//    sockets get SO_SNDBUF 32 KiB (tcp_accept.hpp). Autotuned, Linux took 4.2 MB from a
//    client that never read (~16000 replies built for nobody) before the door's bound applied.
//  - A connection with no complete request for `idle_timeout` (60 s wall time; zero = never) is
//    closed (half-open or stalled clients; clients_closed_bad). Wall time, not virtual time: it
//    protects the door's resources, not the bus's timing.
//  - At most `max_clients` (32) connections. When a new client comes and the door is full, the
//    connection that has gone longest without a complete request (or since its connect) is
//    closed to make room: counted in clients_evicted, logged (throttled). Refusing the new
//    client instead let 32 idle connections lock every new client out for the idle timeout,
//    and forever if each sent a request now and then; a Modbus client that is still in use
//    reconnects, a forgotten one does not, and many Modbus servers evict the same way.
//    max_clients 0 refuses every client (accepted and closed at once: clients_refused).
//  - Backlog SOMAXCONN; a failing accept() (out of descriptors) pauses the acceptor and retries
//    on a timer instead of spinning, logged once per episode (tcp_accept.hpp; accept_pauses).
//  - The handler returning 0 (no response) for a TCP request: nothing is sent, counted in
//    no_reply. A response that starts with FC|0x80 counts in exceptions.
//  - TCP_NODELAY on every connection: Modbus is request/response, Nagle would only add delay.
//  - close() (and the destructor) closes the acceptor and every connection; handlers still
//    queued on the io_context then find the door gone and do nothing. The io_context must
//    outlive the door's destruction (the Simulation destroys doors first).

#include <boost/asio/io_context.hpp>
#include <chrono>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>

#include "pbvbus/gateways/modbus_handler.hpp"
#include "pbvbus/tcp_door/tcp_door_limits.hpp"

namespace pbvbus::gateways {

struct ModbusTcpOptions {
  std::string address = "127.0.0.1";  ///< listen address (loopback unless told otherwise)
  std::uint16_t port = 502;           ///< 0 = an ephemeral port (see port())
  std::size_t max_clients = kDefaultMaxClients;  ///< beyond: the longest-idle one is evicted
  std::size_t max_requests_per_turn = 16;
  std::size_t max_output = 64 * 1024;              ///< octets of unsent responses per connection
  std::chrono::milliseconds idle_timeout{60'000};  ///< zero = never
  DoorLog log{};  ///< evictions, accept() failures (empty: none)
};

class ModbusTcpServer {
 public:
  /// Opens the listening socket at once; throws boost::system::system_error when it cannot
  /// (address in use, bad address).
  ModbusTcpServer(boost::asio::io_context& io, ModbusHandler& handler, ModbusTcpOptions opt = {});
  ~ModbusTcpServer();
  ModbusTcpServer(const ModbusTcpServer&) = delete;
  ModbusTcpServer& operator=(const ModbusTcpServer&) = delete;

  /// The port listened on (the ephemeral one when the options said 0).
  std::uint16_t port() const;
  const ModbusDoorStats& stats() const;
  /// Connections refused at once (stats().clients_refused; only with max_clients 0: a full
  /// door evicts instead).
  std::uint64_t rejected() const;
  /// Closes the acceptor and every connection. Idempotent.
  void close();

 private:
  struct Impl;
  std::shared_ptr<Impl> m;
};

}  // namespace pbvbus::gateways
