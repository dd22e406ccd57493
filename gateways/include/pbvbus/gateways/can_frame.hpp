#pragma once
// CAN frames and the CAN segment the gateway and its doors share (docs/gateway-canopen.md; tools-and-formats.md
// §2). A CanHub is the virtual CAN bus: the CANopen gateway and every attached transport (a
// SocketCAN interface, SLCAN over a pty or TCP, socketcand over TCP — each connected client is
// one port) are ports on it. A frame sent by one port reaches every other port, as on a real
// CAN bus (a frame a client sends is also seen by the other clients); no port hears its own.
// Everything runs on the bus thread.

#include <array>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "pbvbus/bus/time.hpp"

namespace pbvbus::gateways {

struct CanFrame {
  std::uint32_t id = 0;          ///< 11-bit (standard) or 29-bit (extended) identifier
  bool extended = false;
  bool rtr = false;              ///< remote transmission request (no data)
  std::uint8_t dlc = 0;          ///< 0..8
  std::array<std::uint8_t, 8> data{};
  friend bool operator==(const CanFrame&, const CanFrame&) = default;
};

/// "123#AABB" / "12345678#01" / "123#R" (the candump/cansend notation), for messages and tests.
std::string to_string(const CanFrame& f);

class CanHub {
 public:
  using PortId = std::size_t;
  using Receiver = std::function<void(const CanFrame&, bus::Ticks now)>;

  /// Adds a port; `rx` gets every frame the other ports send. The id stays valid until
  /// remove_port (ids are not reused).
  PortId add_port(std::string name, Receiver rx);
  void remove_port(PortId id);
  /// `from` sends a frame: every other port receives it, in port order.
  void send(PortId from, const CanFrame& f, bus::Ticks now);

  std::uint64_t frames() const { return m_frames; }
  std::size_t ports() const;

 private:
  struct Port {
    std::string name;
    Receiver rx;
    bool live = true;
  };
  std::vector<Port> m_ports;
  std::uint64_t m_frames = 0;
};

}  // namespace pbvbus::gateways
