#pragma once
// Test helpers for the FDL station tests: a scripted device that sends given bytes at given
// times (a stand-in for a master or a slave whose frames are written by hand in the test).

#include <cstdint>
#include <string>
#include <vector>

#include "pbvbus/bus/device.hpp"
#include "pbvbus/bus/line.hpp"

namespace pbvbus::fdl::test {

using Bytes = std::vector<std::uint8_t>;

/// Sends what the test tells it to, when told; records what it hears.
class ScriptDevice final : public bus::Device {
 public:
  void on_power_on(bus::Ticks) override {}
  struct Heard {
    Bytes bytes;
    bus::Ticks start = 0;
    bus::Ticks end = 0;
    bus::Ticks idle_before = 0;
    std::uint16_t flags = 0;
  };
  void on_frame(const bus::RxFrame& f) override {
    heard.push_back({Bytes(f.bytes.begin(), f.bytes.end()), f.start, f.end, f.idle_before, f.flags});
  }
  void on_timer(bus::Ticks) override {}
  void send(bus::Ticks at, const Bytes& bytes) { port().transmit(at, bytes); }
  std::vector<Heard> heard;
};

}  // namespace pbvbus::fdl::test
