#pragma once
// The socketcand door (tools-and-formats.md §2.3; docs/gateway-can-doors.md): a TCP listener
// that speaks socketcand's raw mode (socketcand.hpp), so that python-can
// (`interface='socketcand', channel='can0', host=..., port=...`) and can_logger / can_player
// reach the virtual CAN segment. Each TCP connection is one CanHub port, added on connect and
// removed on disconnect.
//
// Decisions (also in the doc):
//  - Default port 29536 (socketcand's), loopback unless told otherwise; port 0 = ephemeral.
//  - On connect the door sends `< hi >` alone. Frames from the bus go to a client only in raw
//    mode. python-can 4.1 reads the rawmode `< ok >` with one recv(256) and compares it exactly,
//    so frames that arrive within Options::raw_hold (100 ms, wall clock) after that `< ok >` are
//    held back (queued, within the bound) until the client sends something or the hold ends.
//    This is the only wall-clock wait in the door; it never blocks anything.
//  - Everything runs on the paced runner's thread and never blocks: the bytes read enter through
//    PacedRunner::post(), so a client's frames go hub.send(port, frame, now) at the virtual time
//    that matches the wall clock when they were read.
//  - Output per connection is bounded (Options::max_output, 64 KiB queued; the kernel send
//    buffer fixed at 32 KiB): beyond it frames are dropped and counted, never blocking the bus.
//  - Garbage and overlong elements are answered `< error ... >`; after
//    socketcand::kMaxConsecutiveErrors errors in a row the connection is closed (counted).
//  - At most Options::max_clients connections at once: one more is accepted and closed at once
//    (before `< hi >`), counted in Stats::refused and logged (throttled). Refused, not evicting
//    an idle one as the Modbus door does: a client that only listens (can_logger) is idle by
//    nature and must not be thrown out.
//  - A failing accept() (out of descriptors) pauses the listener and retries on a timer instead
//    of spinning; logged once per episode (tcp_accept.hpp).
//  - open() returns an error text instead of throwing. Destroy (or close) the door before the
//    runner whose io_context it uses.

#include <chrono>
#include <cstddef>
#include <cstdint>
#include <map>
#include <memory>
#include <string>

#include "pbvbus/gateways/can_frame.hpp"
#include "pbvbus/gateways/socketcand.hpp"
#include "pbvbus/tcp_door/tcp_door_limits.hpp"

namespace pbvbus::bus {
class PacedRunner;
}

namespace pbvbus::gateways {

struct SocketcandDoorOptions {
  std::string address = "127.0.0.1";           ///< loopback unless told otherwise
  std::uint16_t port = socketcand::kDefaultPort;  ///< 0 = an ephemeral port (see port())
  std::string channel = "can0";                 ///< the bus name `< open NAME >` must give
  std::size_t max_output = 64 * 1024;           ///< per-connection queue bound, octets
  std::size_t max_clients = kDefaultMaxClients; ///< connections at once
  DoorLog log{};                                ///< refused clients, accept() failures
  std::chrono::milliseconds raw_hold{100};      ///< frames held after the rawmode `< ok >`
  std::string name = "socketcand";              ///< hub port names: NAME:N
};

class SocketcandDoor {
 public:
  using Options = SocketcandDoorOptions;
  struct Stats {
    std::uint64_t clients = 0;        ///< connections now
    std::uint64_t clients_total = 0;  ///< connections accepted so far
    std::uint64_t closed_bad = 0;     ///< connections closed for repeated garbage
    std::uint64_t elements = 0;       ///< elements handled
    std::uint64_t frames_in = 0;      ///< frames from clients onto the hub
    std::uint64_t frames_out = 0;     ///< frames queued to clients
    std::uint64_t errors = 0;         ///< `< error >` answers
    std::uint64_t dropped = 0;        ///< frames/replies dropped: a client's queue was full
    std::uint64_t refused = 0;        ///< connections refused: max_clients were open
    std::uint64_t accept_pauses = 0;  ///< accept() failed (e.g. out of descriptors): paused
  };

  SocketcandDoor(bus::PacedRunner& runner, CanHub& hub, Options options = {});
  ~SocketcandDoor();
  SocketcandDoor(const SocketcandDoor&) = delete;
  SocketcandDoor& operator=(const SocketcandDoor&) = delete;

  /// Starts listening. Returns "" on success, else why not. Never throws.
  std::string open();
  /// Closes every connection and the listener (also done by the destructor).
  void close();
  /// The TCP port listened on, 0 while closed.
  std::uint16_t port() const { return m_port; }
  Stats stats() const;

 private:
  struct Link;      // a connection (door_stream::Stream) with its socketcand session
  struct Listener;  // door_stream::TcpListener

  void on_bytes(Link& l, const std::string& bytes, bus::Ticks now);
  void on_hub_frame(Link& l, const CanFrame& f, bus::Ticks now);
  void emit(Link& l, std::string_view s, bool frame);
  void release_hold(Link& l);
  bool accept_link(int fd, std::uint64_t n);
  void drop_link(Link& l);

  bus::PacedRunner& m_runner;
  CanHub& m_hub;
  Options m_opt;
  std::uint16_t m_port = 0;
  std::unique_ptr<Listener> m_listener;
  std::map<std::uint64_t, std::shared_ptr<Link>> m_links;
  std::uint64_t m_next_link = 0;
  Stats m_closed;  // counters of connections already gone
};

}  // namespace pbvbus::gateways
