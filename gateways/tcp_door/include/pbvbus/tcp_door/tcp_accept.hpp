#pragma once
// The listening side every TCP door shares: the listen backlog, the kernel send buffer of
// accepted connections, and what accept() does when it fails. Modbus TCP and the ISO-on-TCP
// door (asio acceptors) and the CAN doors (door_stream::TcpListener) all use it, so the rules
// are written once.
//
// Decisions (also in docs/gateway-modbus-doors.md, docs/gateway-can-doors.md):
//  - Backlog SOMAXCONN (4096 in glibc; the kernel clamps it to net.core.somaxconn): a burst of
//    connects waits in the kernel while the bus thread is busy, instead of having its SYNs
//    dropped (the clients then retry only after a second or more).
//  - Accepted connections get a fixed kernel send buffer (SO_SNDBUF 32 KiB; the kernel doubles
//    it for its bookkeeping). Left to autotuning, Linux buffered megabytes for a loopback client
//    that never reads (measured: 2.8 MB of stale CAN frames; 4.2 MB, ~16000 Modbus replies),
//    so the door's own bound (max_output) applied only long after.
//  - accept() failing for any reason but "nothing pending" (EMFILE/ENFILE: out of descriptors;
//    ENOBUFS/ENOMEM) leaves the connection in the backlog and the listener readable, so waiting
//    for readability again wakes at once: the door spun a whole core until a descriptor was
//    freed. Instead the door stops accepting and retries after kAcceptRetry (a timer): clients
//    wait in the backlog (their connect already succeeded) and are served once descriptors are
//    free again. One line is logged when such an episode starts and one when it ends, never one
//    per retry.

#include <sys/socket.h>

#include <boost/asio/io_context.hpp>
#include <boost/asio/steady_timer.hpp>
#include <chrono>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>

#include "pbvbus/tcp_door/tcp_door_limits.hpp"

namespace pbvbus::gateways::tcp_accept {

/// listen() backlog of every TCP door.
inline constexpr int kListenBacklog = SOMAXCONN;
/// SO_SNDBUF of accepted connections.
inline constexpr int kKernelSendBuffer = 32 * 1024;
/// Pause before accept() is tried again after it failed.
inline constexpr std::chrono::milliseconds kAcceptRetry{100};

/// Sets SO_SNDBUF = kKernelSendBuffer on an accepted socket.
void cap_send_buffer(int fd);

/// accept() failures of one listener: pauses and retries, logs episodes, counts them.
class AcceptBackoff {
 public:
  /// `who` starts each logged line (e.g. "socketcand 127.0.0.1:29536").
  AcceptBackoff(boost::asio::io_context& io, std::string who, DoorLog log);
  ~AcceptBackoff();
  AcceptBackoff(const AcceptBackoff&) = delete;
  AcceptBackoff& operator=(const AcceptBackoff&) = delete;

  /// accept() failed with errno `err` (not EAGAIN/EINTR): `retry` runs after kAcceptRetry
  /// (never once this object is gone). The first failure after a success logs a line.
  void failed(int err, std::function<void()> retry);
  /// accept() succeeded: ends an episode (logged).
  void succeeded();
  void set_who(std::string who) { m_who = std::move(who); }
  /// Episodes so far: runs of failed accepts that made the door pause.
  std::uint64_t episodes() const { return m_episodes; }
  /// Pauses so far (retries), over all episodes.
  std::uint64_t pauses() const { return m_pauses; }

 private:
  boost::asio::steady_timer m_timer;
  std::string m_who;
  DoorLog m_log;
  bool m_in_episode = false;
  std::chrono::steady_clock::time_point m_since{};
  std::uint64_t m_episodes = 0;
  std::uint64_t m_pauses = 0;
  std::shared_ptr<bool> m_alive = std::make_shared<bool>(true);
};

}  // namespace pbvbus::gateways::tcp_accept
