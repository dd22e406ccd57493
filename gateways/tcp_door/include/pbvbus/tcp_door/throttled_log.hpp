#pragma once
// A DoorLog that passes at most one line per interval (shared by the TCP doors). A door
// logs each client it refuses or evicts, but a hostile client can cause thousands of those a
// second: the first line goes out at once, the ones in the rest of the interval are only
// counted, and the next line that goes out says how many were held back. The door's counters
// keep the exact totals.

#include <chrono>
#include <cstdint>
#include <string>

#include "pbvbus/tcp_door/tcp_door_limits.hpp"

namespace pbvbus::gateways {

class ThrottledLog {
 public:
  explicit ThrottledLog(DoorLog log, std::chrono::milliseconds interval = std::chrono::seconds(10))
      : m_log(std::move(log)), m_interval(interval) {}
  void operator()(const std::string& line);

 private:
  DoorLog m_log;
  std::chrono::milliseconds m_interval;
  std::chrono::steady_clock::time_point m_last{};
  bool m_logged = false;
  std::uint64_t m_held = 0;
};

}  // namespace pbvbus::gateways
