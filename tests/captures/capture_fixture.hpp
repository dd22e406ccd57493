#pragma once
// Shared by the captures tests: golden frames from protocol-facts.md Appendix 1 (written by
// hand, never produced by the code under test), a do-nothing device and a memory sink.

#include <unistd.h>

#include <cstdint>
#include <filesystem>
#include <span>
#include <string>
#include <vector>

#include "pbvbus/bus/device.hpp"
#include "pbvbus/bus/line.hpp"
#include "pbvbus/bus/scheduler.hpp"
#include "pbvbus/bus/tap.hpp"
#include "pbvbus/captures/pcapng_writer.hpp"

namespace pbvbus::captures::test {

using Bytes = std::vector<std::uint8_t>;

// protocol-facts.md Appendix 1
inline const Bytes kFdlStatusReq = {0x10, 0x03, 0x01, 0x49, 0x4D, 0x16};
inline const Bytes kToken_2_to_5 = {0xDC, 0x05, 0x02};
inline const Bytes kSlaveDiagReq = {0x68, 0x05, 0x05, 0x68, 0x8A, 0x81,
                                    0x6D, 0x3C, 0x3E, 0xF2, 0x16};
inline const Bytes kSlaveDiagRes = {0xA2, 0x81, 0x8A, 0x08, 0x3E, 0x3C, 0x02,
                                    0x05, 0x00, 0xFF, 0x12, 0x34, 0xD9, 0x16};
inline const Bytes kSetPrm = {0x68, 0x0C, 0x0C, 0x68, 0x8A, 0x81, 0x5D, 0x3D, 0x3E,
                              0x88, 0x0A, 0x0A, 0x0B, 0x12, 0x34, 0x00, 0xD0, 0x16};
inline const Bytes kSetPrmDpv1 = {0x68, 0x0F, 0x0F, 0x68, 0x8A, 0x81, 0x5D, 0x3D, 0x3E, 0x88, 0x0A,
                                  0x0A, 0x0B, 0x12, 0x34, 0x00, 0x80, 0x00, 0x00, 0x50, 0x16};
inline const Bytes kChkCfg = {0x68, 0x07, 0x07, 0x68, 0x8A, 0x81, 0x7D,
                              0x3E, 0x3E, 0x10, 0x20, 0x34, 0x16};
inline const Bytes kGlobalControlClear = {0x68, 0x07, 0x07, 0x68, 0xFF, 0x81, 0x46,
                                          0x3A, 0x3E, 0x02, 0x00, 0x40, 0x16};
inline const Bytes kDataExchange = {0x68, 0x05, 0x05, 0x68, 0x0A, 0x01,
                                    0x5D, 0xAA, 0x55, 0x67, 0x16};
inline const Bytes kDataExchangeRes = {0x68, 0x04, 0x04, 0x68, 0x01, 0x0A, 0x08, 0x3C, 0x4F, 0x16};
inline const Bytes kDpv1Read = {0x68, 0x09, 0x09, 0x68, 0x8A, 0x81, 0x7D, 0x33,
                                0x33, 0x5E, 0x00, 0x00, 0x40, 0x8C, 0x16};
inline const Bytes kDpv1ReadRes = {0xA2, 0x81, 0x8A, 0x08, 0x33, 0x33, 0x5E,
                                   0x00, 0x00, 0x02, 0xAB, 0xCD, 0x51, 0x16};
inline const Bytes kDpv1ReadNeg = {0x68, 0x09, 0x09, 0x68, 0x81, 0x8A, 0x08, 0x33,
                                   0x33, 0xDE, 0x80, 0xB0, 0x00, 0x87, 0x16};
inline const Bytes kSetSlaveAdd = {0x68, 0x09, 0x09, 0x68, 0xFE, 0x81, 0x6D, 0x37,
                                   0x3E, 0x05, 0x12, 0x34, 0x00, 0xAC, 0x16};
inline const Bytes kSc = {0xE5};

/// A file name in the temp directory unique to this process: test binaries of several
/// worktrees and ctest -j run at the same time.
inline std::string temp_capture_path(const std::string& stem) {
  return (std::filesystem::temp_directory_path() /
          (stem + "_" + std::to_string(::getpid()) + ".pcapng"))
      .string();
}

/// A station that does nothing: gives the line attachments with labels.
class IdleDevice final : public bus::Device {
 public:
  void on_power_on(bus::Ticks) override {}
  void on_frame(const bus::RxFrame&) override {}
  void on_timer(bus::Ticks) override {}
};

/// Collects everything the writer emits.
struct MemorySink {
  Bytes data;
  PcapngWriter::Sink sink() {
    return [this](std::span<const std::uint8_t> b) {
      data.insert(data.end(), b.begin(), b.end());
      return true;
    };
  }
};

inline bus::TapFrame tap_frame(const bus::Line& line, const Bytes& bytes, bus::Ticks start,
                               std::uint16_t flags = 0, std::uint32_t sent_len = 0) {
  bus::TapFrame f;
  f.line = &line;
  f.bytes = bytes;
  f.start = start;
  f.end = start + bus::chars_to_ticks(static_cast<std::int64_t>(bytes.size()), line.baud());
  f.flags = flags;
  f.sent_len = sent_len ? sent_len : static_cast<std::uint32_t>(bytes.size());
  return f;
}

}  // namespace pbvbus::captures::test
