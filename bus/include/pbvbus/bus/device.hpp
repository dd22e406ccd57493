#pragma once
// The seam between the medium and everything that talks on it (design.md "Stacks").
//
// A Device is a sans-I/O participant: the line hands it received frames and timer expiries
// with the current virtual time; the device answers by asking its DevicePort to transmit bytes
// at a given time or to wake it at a given time. Devices never read a clock or touch a socket,
// so the same object runs in the fast simulator, in paced real time and in a unit test that
// drives it by hand with a recording port.

#include <cstdint>
#include <span>

#include "pbvbus/bus/frame_memo.hpp"
#include "pbvbus/bus/time.hpp"

namespace pbvbus::bus {

/// Error flags of a received frame, as a receiver's UART and the line would know them.
enum RxFlag : std::uint16_t {
  kRxCollision = 1u << 0,  ///< overlapped another transmitter: overlapping characters corrupted
  kRxParity = 1u << 1,     ///< at least one character failed even parity (noise)
  kRxFraming = 1u << 2,    ///< at least one character had a bad start or stop bit (noise)
  kRxPartial = 1u << 3,    ///< cut short by a fault: fewer characters than were sent
  kRxBabble = 1u << 4,     ///< produced by a babbling transmitter
};

/// A frame as one receiver observed it. Delivered once, at `end`.
struct RxFrame {
  std::span<const std::uint8_t> bytes;  ///< octets as received (possibly corrupted, see flags)
  Ticks start = 0;                      ///< start bit of the first character
  Ticks end = 0;                        ///< end of the stop bit of the last character
  /// Idle time on the receiver's segment between the previous activity and `start`;
  /// kIdleForever if the receiver has seen no activity since power-on.
  Ticks idle_before = 0;
  std::uint16_t flags = 0;  ///< RxFlag bits; 0 = every character arrived intact
  /// The transmission's slot for a decoded view of `bytes`, shared with every other receiver
  /// and tap of the same frame (frame_memo.hpp); nullptr for frames that come from no line
  /// (a unit test driving a device by hand). Valid only during the call.
  FrameMemo* memo = nullptr;
  bool intact() const { return flags == 0; }
};
inline constexpr Ticks kIdleForever = INT64_MAX / 4;

/// What a device may ask of the medium. Provided by the line for each attachment.
class DevicePort {
 public:
  virtual Ticks now() const = 0;
  virtual Baud baud() const = 0;
  /// Sends `bytes` as one telegram whose first start bit goes out at `start` (>= now).
  /// The bytes are copied. A transmission always runs to its end; PROFIBUS has no
  /// collision detection, so a device cannot know whether anyone heard it.
  virtual void transmit(Ticks start, std::span<const std::uint8_t> bytes) = 0;
  /// Asks for one on_timer() call at `at`, replacing any earlier request; kNever cancels.
  virtual void set_timer(Ticks at) = 0;
  /// Carrier sense: whether a frame that this device is going to receive is on the line now
  /// (its first start bit has gone out; it has not been delivered yet). A UART sees the start
  /// bit; with whole-frame delivery the device asks instead, e.g. a master whose slot time
  /// expires while a long reply is still arriving. Default for ports without a line: false.
  virtual bool receiving() const { return false; }
  /// Tells the medium that Device::receive_filter() now returns something else. The line reads
  /// the filter again after every call it makes into the device (on_power_on, on_power_off,
  /// on_frame, on_timer), so this is only needed for a change made from outside those calls
  /// (a management action, a scenario step). Until then the line may use the old filter.
  virtual void receive_filter_changed() {}
  /// The RS-485 driver's read-back: true while what this device would send cannot reach the
  /// cable intact (the line is short-circuited). A PROFIBUS ASIC compares what it sends with
  /// what it reads back and reports a bus fault (S7: BUSF on, a master system failure); a
  /// device whose own transceiver is dead cannot tell (it reads back nothing, like silence).
  virtual bool medium_fault() const { return false; }

 protected:
  ~DevicePort() = default;
};

/// Receive filter: passive stations only need frames addressed to them, which lets the line
/// skip them for all other traffic (what they observe is unchanged: they would drop them).
inline constexpr int kReceiveAll = -1;

class Device {
 public:
  virtual ~Device() = default;

  /// Called by the line when the device is attached.
  void bind(DevicePort& port) { m_port = &port; }
  bool bound() const { return m_port != nullptr; }

  /// Power applied (at start, or after a power-loss fault is repaired): start from scratch.
  virtual void on_power_on(Ticks now) = 0;
  /// Power lost: the line has already dropped pending transmissions and the timer.
  virtual void on_power_off(Ticks /*now*/) {}
  /// A frame seen on the line (never the device's own transmissions).
  virtual void on_frame(const RxFrame& frame) = 0;
  /// The time requested with DevicePort::set_timer() has come.
  virtual void on_timer(Ticks now) = 0;
  /// kReceiveAll, or an FDL address 0..126: then only frames whose DA is that address or 127
  /// are delivered (frames without a DA, SC and garbage, are not). Any other value counts as
  /// kReceiveAll. See DevicePort::receive_filter_changed() for changing it at run time.
  virtual int receive_filter() const { return kReceiveAll; }
  /// Short label for reports and logs, e.g. "master 1" or "slave 10".
  virtual const char* kind() const { return "device"; }

 protected:
  DevicePort& port() { return *m_port; }
  const DevicePort& port() const { return *m_port; }

 private:
  DevicePort* m_port = nullptr;
};

}  // namespace pbvbus::bus
