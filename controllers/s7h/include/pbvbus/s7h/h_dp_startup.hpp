#pragma once
// The start-up monitoring "transfer of parameters to modules" (001 L8094-8113: set on the
// "Startup" tab in units of 100 ms, recommended 600 = 60 s; too short -> the CPU enters
// W#16#6547 in its diagnostic buffer). docs/h-changes.md. Sans-I/O, built on HCpuPair: the
// owner starts it when a CPU's DP master(s) begin to parameterise the stations (the master's
// start-up; the standby's at the end of its link-up, 001 Fig. 6-1), reports each station that
// reaches data exchange, and calls on_time() at next_deadline().
#include <cstdint>
#include <functional>
#include <string>
#include <optional>
#include <vector>

#include "pbvbus/bus/time.hpp"
#include "pbvbus/s7h/h_cpu_pair.hpp"

namespace pbvbus::devices {

inline constexpr std::uint16_t kParamTransferExceeded = 0x6547;

/// The parameter in ticks (100 ms units; 001 L8113: 600 = 60 s).
constexpr bus::Ticks param_transfer_time(std::uint32_t units_100ms) {
  return static_cast<bus::Ticks>(units_100ms) * 100 * bus::kTicksPerMs;
}

/// One station and when it entered data exchange (empty: not yet).
struct HStationStart {
  std::uint8_t address = 0;
  std::optional<bus::Ticks> data_exchange_at;
};

/// The stations not in data exchange at `start` + the monitoring time (a station entering at
/// exactly the end is in time). Empty = the time sufficed.
std::vector<std::uint8_t> late_stations(bus::Ticks start, std::uint32_t units_100ms,
                                        const std::vector<HStationStart>& stations);

class HDpStartupMonitor {
 public:
  /// Where the entry goes: (rack, time, text, code), e.g. HSystemModel::log_entry.
  using Sink = std::function<void(int, bus::Ticks, std::string, std::uint16_t)>;
  HDpStartupMonitor(Sink sink, std::uint32_t units_100ms, std::vector<std::uint8_t> stations);
  /// The entry into the pair's buffer (none when the CPU is off).
  HDpStartupMonitor(HCpuPair& pair, std::uint32_t units_100ms, std::vector<std::uint8_t> stations);
  /// CPU `rack`'s DP master(s) start parameterising every station at `now`.
  void start(int rack, bus::Ticks now);
  /// A station entered data exchange at `now`.
  void data_exchange(std::uint8_t address, bus::Ticks now);
  bus::Ticks next_deadline() const { return m_deadline; }
  /// At the end of the monitoring time: W#16#6547 on that CPU if a station is late (decision:
  /// the start-up continues; the late stations come up by themselves, docs/h-changes.md).
  void on_time(bus::Ticks now);
  /// The late stations of the last monitoring (empty: in time, or not ended yet).
  const std::vector<std::uint8_t>& late() const { return m_late; }
  bool exceeded() const { return !m_late.empty(); }

 private:
  Sink m_sink;
  std::uint32_t m_units;
  std::vector<HStationStart> m_st;
  int m_rack = -1;
  bus::Ticks m_start = 0;
  bus::Ticks m_deadline = bus::kNever;
  std::vector<std::uint8_t> m_late;
};

}  // namespace pbvbus::devices
