#pragma once
// A DevicePort without a line, for unit tests of one Device (design.md "Stacks": sans-I/O).
//
// The test sets the time and baud, binds the device, feeds it frames and timer expiries by hand
// and inspects what it asked for. Nothing is scheduled: transmit() and set_timer() are only
// recorded, which is exactly what a device under test should observe (it cannot tell).

#include <cstdint>
#include <optional>
#include <span>
#include <vector>

#include "pbvbus/bus/device.hpp"
#include "pbvbus/bus/scheduler.hpp"
#include "pbvbus/bus/time.hpp"

namespace pbvbus::test {

class RecordingPort final : public bus::DevicePort {
 public:
  struct Transmission {
    bus::Ticks start = 0;   ///< as requested (not clamped to now)
    bus::Ticks now = 0;     ///< port time when transmit() was called
    std::vector<std::uint8_t> bytes;
  };

  explicit RecordingPort(bus::Baud baud = bus::Baud::k1_5M, bus::Ticks now = 0)
      : m_baud(baud), m_now(now) {}

  // --- DevicePort ----------------------------------------------------------------------------
  bus::Ticks now() const override { return m_now; }
  bus::Baud baud() const override { return m_baud; }
  void transmit(bus::Ticks start, std::span<const std::uint8_t> bytes) override;
  void set_timer(bus::Ticks at) override;

  // --- test control --------------------------------------------------------------------------
  /// Binds `dev` to this port (Device::bind) so it can be driven by hand.
  void bind(bus::Device& dev) { dev.bind(*this); }
  void set_now(bus::Ticks t) { m_now = t; }
  void advance(bus::Ticks dt) { m_now += dt; }
  void set_baud(bus::Baud b) { m_baud = b; }
  bus::Ticks bit_ticks() const { return bus::ticks_per_bit(m_baud); }

  /// Every transmit() call since construction or the last clear(), in call order.
  const std::vector<Transmission>& transmissions() const { return m_tx; }
  std::size_t transmit_count() const { return m_tx.size(); }
  /// The last transmission; throws std::out_of_range if there was none.
  const Transmission& last() const;
  const std::vector<std::uint8_t>& last_frame() const { return last().bytes; }
  /// Removes and returns the oldest recorded transmission, if any.
  std::optional<Transmission> pop_front();
  /// Forgets recorded transmissions and timer requests (the timer value stays).
  void clear();

  /// Last value passed to set_timer() (kNever if never called or cancelled).
  bus::Ticks timer() const { return m_timer; }
  bool timer_armed() const { return m_timer != bus::kNever; }
  /// How many times set_timer() was called since the last clear().
  std::size_t timer_requests() const { return m_timer_requests; }

  /// If the armed timer is due at or before `until`: advances now to the deadline, disarms it
  /// and calls dev.on_timer(). Returns whether it fired. Convenience for driving a device.
  bool fire_timer_if_due(bus::Device& dev, bus::Ticks until);

 private:
  bus::Baud m_baud;
  bus::Ticks m_now;
  bus::Ticks m_timer = bus::kNever;
  std::size_t m_timer_requests = 0;
  std::vector<Transmission> m_tx;
};

}  // namespace pbvbus::test
