#include "pbvbus/campaign/campaign_support.hpp"

#include <cstdio>
#include <filesystem>
#include <stdexcept>

namespace pbvbus::campaign {

std::string format_ms(bus::Ticks t) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.3f ms",
                static_cast<double>(t) / static_cast<double>(bus::kTicksPerMs));
  return buf;
}

EventCounts zero_event_counts() {
  EventCounts c{};
  for (std::size_t k = 0; k < c.size(); ++k) c[k] = {kSystemEventCodes[k], 0};
  return c;
}

void count_event(EventCounts& counts, std::uint16_t code) {
  for (auto& [c, n] : counts)
    if (c == code) ++n;
}

int count_of(std::span<const std::pair<std::uint16_t, int>> counts, std::uint16_t code) {
  for (const auto& [c, n] : counts)
    if (c == code) return n;
  return 0;
}

std::string format_counts(std::span<const std::pair<std::uint16_t, int>> counts) {
  std::string s;
  for (const auto& [c, n] : counts) {
    char buf[24];
    std::snprintf(buf, sizeof buf, " %04X=%d", c, n);
    s += buf;
  }
  return s;
}

CounterWatch::Sample CounterWatch::sample(std::uint16_t value, bool allowed_safe_state) {
  Sample s;
  s.previous = m_last;
  if (!m_started) {
    m_started = value != 0;
    m_last = value;
    return s;
  }
  s.counted = true;
  if (allowed_safe_state) m_exempt = true;
  if (value == 0) {
    if (m_exempt)
      s.safe_state = true;
    else
      s.bad = "outputs 0";
    return s;
  }
  if (static_cast<std::uint16_t>(value - m_last) >= 0x8000) s.bad = "older value";
  // A new value while the station may not be in its safe state ends the allowance (a held old
  // value does not: its hold may still run out).
  if (!allowed_safe_state && value != m_last) m_exempt = false;
  m_last = value;
  return s;
}

devices::GsdFile load_gsd_or_throw(const std::string& dir, const char* name, std::string_view who) {
  auto r = devices::load_gsd(std::filesystem::path(dir) / name);
  if (!r.ok() || !r.file)
    throw std::runtime_error(std::string(who) + ": cannot load " + name);
  return *r.file;
}

}  // namespace pbvbus::campaign
