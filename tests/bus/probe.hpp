#pragma once
// A scriptable Device for line tests: records what it observes, transmits what it is told.

#include <functional>
#include <string_view>
#include <vector>

#include "hex.hpp"
#include "pbvbus/bus/device.hpp"

namespace pbvbus::test {

class Probe final : public bus::Device {
 public:
  struct Rx {
    std::vector<std::uint8_t> bytes;
    bus::Ticks start, end, idle_before;
    std::uint16_t flags;
    std::string hex() const { return to_hex(bytes); }
  };

  explicit Probe(int filter = bus::kReceiveAll) : m_filter(filter) {}

  void on_power_on(bus::Ticks now) override { power_ons.push_back(now); }
  void on_power_off(bus::Ticks now) override { power_offs.push_back(now); }
  void on_frame(const bus::RxFrame& f) override {
    rx.push_back(Rx{{f.bytes.begin(), f.bytes.end()}, f.start, f.end, f.idle_before, f.flags});
    if (on_rx) on_rx(f);
  }
  void on_timer(bus::Ticks now) override {
    timers.push_back(now);
    if (on_tick) on_tick(now);
  }
  int receive_filter() const override { return m_filter; }
  /// Changes the filter without telling the line (as from inside a callback).
  void set_filter(int f) { m_filter = f; }

  void send(bus::Ticks at, std::string_view hex) { port().transmit(at, bytes_from_hex(hex)); }
  void send(bus::Ticks at, const std::vector<std::uint8_t>& b) { port().transmit(at, b); }
  void timer(bus::Ticks at) { port().set_timer(at); }
  bus::DevicePort& the_port() { return port(); }

  std::vector<Rx> rx;
  std::vector<bus::Ticks> timers, power_ons, power_offs;
  std::function<void(const bus::RxFrame&)> on_rx;
  std::function<void(bus::Ticks)> on_tick;

 private:
  int m_filter;
};

}  // namespace pbvbus::test
