#pragma once
// Test helpers for the FDL station tests: a scripted device that sends given bytes at given
// times (a stand-in for a master or a slave whose frames are written by hand in the test), and
// a tap that records every frame on the wire with its times.

#include <cstdint>
#include <string>
#include <vector>

#include "pbvbus/bus/device.hpp"
#include "pbvbus/bus/line.hpp"
#include "pbvbus/bus/tap.hpp"

namespace pbvbus::fdl::test {

using Bytes = std::vector<std::uint8_t>;

struct WireFrame {
  Bytes bytes;
  bus::Ticks start = 0;
  bus::Ticks end = 0;
  std::uint16_t flags = 0;
  int sender = -1;
};

class WireLog final : public bus::Tap {
 public:
  void on_frame(const bus::TapFrame& f) override {
    frames.push_back({Bytes(f.bytes.begin(), f.bytes.end()), f.start, f.end, f.flags, f.sender});
  }
  /// Frames sent by attachment `sender`.
  std::vector<WireFrame> from(int sender) const {
    std::vector<WireFrame> out;
    for (const auto& f : frames)
      if (f.sender == sender) out.push_back(f);
    return out;
  }
  /// Token frames (SD4) only, in order.
  std::vector<WireFrame> tokens() const {
    std::vector<WireFrame> out;
    for (const auto& f : frames)
      if (!f.bytes.empty() && f.bytes[0] == 0xDC) out.push_back(f);
    return out;
  }
  std::vector<WireFrame> frames;
};

/// Sends what the test tells it to, when told; records what it hears.
class ScriptDevice final : public bus::Device {
 public:
  void on_power_on(bus::Ticks) override {}
  void on_frame(const bus::RxFrame& f) override {
    heard.push_back({Bytes(f.bytes.begin(), f.bytes.end()), f.start, f.end, f.flags, -1});
  }
  void on_timer(bus::Ticks) override {}
  void send(bus::Ticks at, const Bytes& bytes) { port().transmit(at, bytes); }
  std::vector<WireFrame> heard;
};

inline std::string hex(const Bytes& b) {
  static const char* d = "0123456789ABCDEF";
  std::string s;
  for (std::size_t i = 0; i < b.size(); ++i) {
    if (i) s += ' ';
    s += d[b[i] >> 4];
    s += d[b[i] & 15];
  }
  return s;
}

}  // namespace pbvbus::fdl::test
