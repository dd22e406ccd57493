#pragma once
// The stream plumbing the SLCAN and socketcand doors share (private to the gateways layer):
// a non-blocking TCP listener with its accept loop, and one connection's descriptor with its
// bounded, non-blocking output queue and its read loop. The doors keep only their protocol.
//
// Decisions (also in docs/gateway-can-doors.md):
//  - Everything runs on the paced runner's thread and never blocks: the io_context tells when a
//    descriptor is readable/writable; the bytes read enter through PacedRunner::post(), so a
//    client's data is handled at the virtual time that matches the wall clock when it was read.
//  - A read wake-up takes at most 64 KiB, so one flooding client cannot hold the loop.
//  - Output waits in a per-connection queue bounded by the door's max_output; what does not fit
//    is dropped and counted (Stream::dropped) — a client that never reads never delays the bus.
//  - Accepted connections get TCP_NODELAY and a fixed kernel send buffer; the backlog and what
//    a failing accept() does are tcp_accept.hpp's, shared with the Modbus door.
//  - A door refuses a connection (its client limit) by returning false from OnAccept: the
//    listener closes it at once, so the client learns it at connect time, and counts it.
//  - A write error on a socket (the peer is gone) or a read of 0/an error closes the connection
//    on the next turn (Stream::gone(), posted: we may be inside the hub's delivery).

#include <boost/asio/io_context.hpp>
#include <boost/asio/posix/stream_descriptor.hpp>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <string_view>

#include "pbvbus/bus/time.hpp"
#include "pbvbus/tcp_door/tcp_accept.hpp"

namespace pbvbus::bus {
class PacedRunner;
}

namespace pbvbus::gateways::door_stream {

using Descriptor = boost::asio::posix::stream_descriptor;

/// At most this many octets are read per wake-up of one connection.
constexpr std::size_t kMaxReadPerWake = 64 * 1024;

/// "what: strerror(errno)".
std::string errno_text(const std::string& what);

/// A non-blocking IPv4 TCP listener on address:port (backlog tcp_accept::kListenBacklog).
/// Returns the fd (and the port actually bound in `bound`) or -1 with `err` set.
int listen_tcp(const std::string& address, std::uint16_t port, std::uint16_t& bound,
               std::string& err);

/// A listening socket on the io_context: accepts every pending connection on each readiness,
/// tunes it (TCP_NODELAY, SO_SNDBUF) and hands it to `on_accept(fd, n)` (n = 1, 2, ...: the
/// count of connections taken so far, including this one). `on_accept` returns false to refuse
/// it: the listener then closes it and counts it in refused(). A failing accept() pauses the
/// listener (tcp_accept::AcceptBackoff, logged through `log` with `who`). Destroying it stops
/// accepting.
class TcpListener {
 public:
  using OnAccept = std::function<bool(int fd, std::uint64_t n)>;
  TcpListener(boost::asio::io_context& io, int fd, std::string who, DoorLog log,
              OnAccept on_accept);
  TcpListener(const TcpListener&) = delete;
  TcpListener& operator=(const TcpListener&) = delete;
  std::uint64_t accepted() const { return m_accepted; }
  std::uint64_t refused() const { return m_refused; }
  const tcp_accept::AcceptBackoff& backoff() const { return m_backoff; }

 private:
  void start_accept();

  Descriptor m_sd;  // owns the listening fd
  OnAccept m_on_accept;
  tcp_accept::AcceptBackoff m_backoff;
  std::uint64_t m_accepted = 0;
  std::uint64_t m_refused = 0;
  std::shared_ptr<bool> m_alive = std::make_shared<bool>(true);
};

/// One connection (a TCP socket or a pty master): the descriptor and its bounded output queue.
/// A door derives its link from it and says what to do with the bytes read and when it is gone.
struct Stream : std::enable_shared_from_this<Stream> {
  Stream(boost::asio::io_context& io, int fd_, bool is_socket_)
      : fd(fd_), is_socket(is_socket_), sd(io, fd_) {}
  virtual ~Stream() = default;
  Stream(const Stream&) = delete;
  Stream& operator=(const Stream&) = delete;

  /// Bytes read from the peer, at the virtual time `now` (called via PacedRunner::post()).
  virtual void received(const std::string& bytes, bus::Ticks now) = 0;
  /// The peer is gone (EOF, a read or write error): the door drops the link (posted).
  virtual void gone() = 0;
  /// False while the door holds output back (queued, not written).
  virtual bool may_write() const { return true; }

  int fd;
  bool is_socket;
  Descriptor sd;  // owns fd
  std::string out;
  bool write_armed = false;
  bool closed = false;
  std::uint64_t frames_out = 0;  ///< frames the door queued (the door counts them)
  std::uint64_t dropped = 0;     ///< octet strings dropped: the queue was full
};

/// Waits until `s` is readable, reads what is there (kMaxReadPerWake at most), posts it to
/// Stream::received() (or Stream::gone() at EOF/error) and waits again.
void start_read(const std::shared_ptr<Stream>& s, bus::PacedRunner& runner);
/// Queues `text` if the queue stays within `max_output` octets and writes what the kernel takes
/// (unless a write is pending or the door holds output); else counts it in `dropped` and
/// returns false.
bool queue(Stream& s, std::string_view text, std::size_t max_output, bus::PacedRunner& runner);
/// Writes what the kernel takes now; arms a wait for writability if something is left.
void flush(Stream& s, bus::PacedRunner& runner);
/// Marks `s` closed, cancels its waits and closes the descriptor.
void close(Stream& s);

}  // namespace pbvbus::gateways::door_stream
