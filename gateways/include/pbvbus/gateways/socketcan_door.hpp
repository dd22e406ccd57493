#pragma once
// The SocketCAN door (tools-and-formats.md §2.1, §2.5): a raw AF_CAN socket bound to a Linux
// CAN interface (a vcan, or a real adapter), one CanHub port, frames both ways as
// struct can_frame (CAN_EFF_FLAG for extended ids, CAN_RTR_FLAG for remote frames). Then
// candump, cansend, Wireshark and python-can's `socketcan` interface see the virtual segment.
//
// Decisions (also in docs/gateway-can-doors.md):
//  - open() returns an error text — never throws or aborts — when the kernel lacks AF_CAN
//    (errno 97, common in containers and CI) or the interface is missing.
//  - Frames the door writes are not read back by it (CAN_RAW_RECV_OWN_MSGS is off by default),
//    so the hub never hears its own frames twice. Error frames (CAN_ERR_FLAG) are not
//    delivered (the default filter of a raw socket excludes them). CAN FD is not enabled.
//  - Frames from the hub are written without blocking; while the interface's queue is full
//    (ENOBUFS / EAGAIN) they wait in a bounded queue (Options::max_queue frames), beyond which
//    they are dropped and counted.
//  - Frames read from the socket enter through PacedRunner::post(): hub.send(port, frame, now)
//    at the virtual time that matches the wall clock when they were read.
//  - Destroy (or close) the door before the runner whose io_context it uses.

#include <cstddef>
#include <cstdint>
#include <deque>
#include <memory>
#include <string>

#include "pbvbus/gateways/can_frame.hpp"

namespace pbvbus::bus {
class PacedRunner;
}

namespace pbvbus::gateways {

struct SocketcanDoorOptions {
  std::string interface = "vcan0";
  std::size_t max_queue = 1024;  ///< frames waiting for the interface, at most
  std::string name = "socketcan";
};

class SocketcanDoor {
 public:
  using Options = SocketcanDoorOptions;
  struct Stats {
    std::uint64_t frames_in = 0;   ///< frames read from the interface onto the hub
    std::uint64_t frames_out = 0;  ///< frames written to the interface
    std::uint64_t dropped = 0;     ///< frames from the hub dropped: the queue was full
    std::uint64_t errors = 0;      ///< read/write errors other than "try again"
  };

  SocketcanDoor(bus::PacedRunner& runner, CanHub& hub, Options options = {});
  ~SocketcanDoor();
  SocketcanDoor(const SocketcanDoor&) = delete;
  SocketcanDoor& operator=(const SocketcanDoor&) = delete;

  /// Opens and binds the socket. "" on success, else why not. Never throws.
  std::string open();
  void close();
  bool is_open() const { return m_io != nullptr; }
  const Stats& stats() const { return m_stats; }

 private:
  struct Io;
  void start_read();
  void on_hub_frame(const CanFrame& f);
  void flush();

  bus::PacedRunner& m_runner;
  CanHub& m_hub;
  Options m_opt;
  std::unique_ptr<Io> m_io;
  CanHub::PortId m_port = 0;
  std::deque<CanFrame> m_queue;
  Stats m_stats;
};

}  // namespace pbvbus::gateways
