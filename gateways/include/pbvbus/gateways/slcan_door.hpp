#pragma once
// The SLCAN door (tools-and-formats.md §2.2; docs/gateway-can-doors.md): a CanHub port per
// connected client that speaks Lawicel ASCII (slcan.hpp), over a pseudo-terminal and/or a TCP
// listener, so that python-can (`interface='slcan'`, a pty path or `socket://HOST:PORT`),
// can_logger / can_player and, on hosts with SocketCAN, slcand reach the virtual CAN segment.
//
// Decisions (also in the doc):
//  - Each TCP connection is one hub port, added on connect and removed on disconnect; the pty is
//    one hub port for as long as the door is open (a pty has no connect: the door keeps the
//    slave side open itself, so a client may close and reopen it without EIO, §1.4). Every
//    connection has its own channel state (closed until `O`/`L`) and line buffer.
//  - Everything runs on the paced runner's thread and never blocks: the io_context tells when a
//    descriptor is readable; the bytes read enter through PacedRunner::post(), so a client's
//    commands are handled — and its frames hub.send(port, frame, now) — at the virtual time
//    that matches the wall clock when they were read, in order with the bus's own events.
//  - Output to a client is written without blocking; what the client does not read waits in a
//    per-connection queue of at most Options::max_output octets (64 KiB). Beyond that, frames
//    (and replies) are dropped and counted, and the client's `F` shows a data overrun. A client
//    that never reads therefore never delays the bus.
//  - Accepted TCP connections get a fixed kernel send buffer (SO_SNDBUF 32 KiB): left to
//    autotuning, Linux buffers megabytes for a stalled loopback client (measured: 2.8 MB),
//    stale frames the client would read long after, before the door's bound applies.
//  - A write error (the peer is gone) closes a TCP connection; a read of 0 or an error too.
//  - At most Options::max_clients TCP connections at once (the pty is not counted): one more is
//    accepted and closed at once, counted in Stats::refused and logged (throttled). Refused,
//    not evicting an idle one as the Modbus door does: a CAN client that only listens
//    (can_logger, candump through slcand) is idle by nature and must not be thrown out.
//  - A failing accept() (out of descriptors) pauses the listener and retries on a timer instead
//    of spinning; logged once per episode (tcp_accept.hpp).
//  - open() returns an error text instead of throwing (no pty support, port in use, ...).
//  - The door must be destroyed (or closed) before the runner whose io_context it uses.

#include <cstddef>
#include <cstdint>
#include <map>
#include <memory>
#include <string>

#include "pbvbus/gateways/can_frame.hpp"
#include "pbvbus/gateways/slcan.hpp"
#include "pbvbus/tcp_door/tcp_door_limits.hpp"

namespace pbvbus::bus {
class PacedRunner;
}

namespace pbvbus::gateways {

struct SlcanDoorOptions {
  bool pty = true;                    ///< offer a pseudo-terminal
  std::string pty_link;               ///< a symlink to the pty's slave path (replaced) if set
  bool tcp = true;                    ///< offer a TCP listener
  std::string tcp_address = "127.0.0.1";  ///< loopback unless told otherwise
  std::uint16_t tcp_port = 0;         ///< 0 = an ephemeral port (see port())
  std::size_t max_output = 64 * 1024; ///< per-connection queue bound, octets
  std::size_t max_clients = kDefaultMaxClients;  ///< TCP connections at once (the pty aside)
  DoorLog log{};                      ///< refused clients, accept() failures (empty: none)
  std::string serial = "PBV1";        ///< `N` reply (4 characters)
  std::string name = "slcan";         ///< hub port names: NAME:pty, NAME:tcp:N
};

class SlcanDoor {
 public:
  using Options = SlcanDoorOptions;
  struct Stats {
    std::uint64_t clients = 0;         ///< connections now (the pty counts as one while open)
    std::uint64_t clients_total = 0;   ///< TCP connections accepted so far, plus the pty if open
    std::uint64_t lines = 0;           ///< command lines handled
    std::uint64_t frames_in = 0;       ///< frames from clients onto the hub
    std::uint64_t frames_out = 0;      ///< frames queued to clients
    std::uint64_t errors = 0;          ///< lines answered '\a'
    std::uint64_t overlong = 0;        ///< of those, overlong lines
    std::uint64_t dropped = 0;         ///< frames/replies dropped: a client's queue was full
    std::uint64_t refused = 0;         ///< TCP connections refused: max_clients were open
    std::uint64_t accept_pauses = 0;   ///< accept() failed (e.g. out of descriptors): paused
  };

  SlcanDoor(bus::PacedRunner& runner, CanHub& hub, Options options = {});
  ~SlcanDoor();
  SlcanDoor(const SlcanDoor&) = delete;
  SlcanDoor& operator=(const SlcanDoor&) = delete;

  /// Opens the pty and/or the listener. Returns "" on success, else why not (nothing is left
  /// open then). Never throws.
  std::string open();
  /// Closes every connection, the listener and the pty (also done by the destructor).
  void close();

  /// The pty's slave path (/dev/pts/N), "" without a pty.
  const std::string& pty_path() const { return m_pty_path; }
  /// The TCP port listened on (the ephemeral one when Options::tcp_port was 0), 0 without TCP.
  std::uint16_t port() const { return m_port; }
  Stats stats() const;

 private:
  struct Link;      // a connection (door_stream::Stream) with its SLCAN session
  struct Listener;  // door_stream::TcpListener

  std::shared_ptr<Link> add_link(int fd, bool is_socket, std::string name);
  bool accept_tcp(int fd, std::uint64_t n);
  void on_bytes(Link& l, const std::string& bytes, bus::Ticks now);
  void on_hub_frame(Link& l, const CanFrame& f, bus::Ticks now);
  void emit(Link& l, std::string_view s, bool frame);
  void drop_link(Link& l);

  bus::PacedRunner& m_runner;
  CanHub& m_hub;
  Options m_opt;
  std::string m_pty_path;
  int m_pty_slave = -1;
  std::uint16_t m_port = 0;
  std::unique_ptr<Listener> m_listener;
  std::map<std::uint64_t, std::shared_ptr<Link>> m_links;
  std::uint64_t m_next_link = 0;
  Stats m_closed;  // counters of connections already gone
};

}  // namespace pbvbus::gateways
