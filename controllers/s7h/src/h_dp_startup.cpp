// "Transfer of parameters to modules" monitoring, W#16#6547 (h_dp_startup.hpp).
#include "pbvbus/s7h/h_dp_startup.hpp"

#include <string>
#include <utility>

namespace pbvbus::devices {

std::vector<std::uint8_t> late_stations(bus::Ticks start, std::uint32_t units_100ms,
                                        const std::vector<HStationStart>& stations) {
  const bus::Ticks end = start + param_transfer_time(units_100ms);
  std::vector<std::uint8_t> late;
  for (const auto& s : stations)
    if (!s.data_exchange_at || *s.data_exchange_at > end) late.push_back(s.address);
  return late;
}

HDpStartupMonitor::HDpStartupMonitor(Sink sink, std::uint32_t units_100ms,
                                     std::vector<std::uint8_t> stations)
    : m_sink(std::move(sink)), m_units(units_100ms) {
  for (auto a : stations) m_st.push_back(HStationStart{a, std::nullopt});
}

HDpStartupMonitor::HDpStartupMonitor(HCpuPair& pair, std::uint32_t units_100ms,
                                     std::vector<std::uint8_t> stations)
    : HDpStartupMonitor(
          [&pair](int r, bus::Ticks at, std::string t, std::uint16_t code) {
            if (pair.state(r) != CpuState::Off) pair.log_entry(r, at, std::move(t), code);
          },
          units_100ms, std::move(stations)) {}

void HDpStartupMonitor::start(int rack, bus::Ticks now) {
  on_time(now);
  m_rack = rack;
  m_start = now;
  m_deadline = now + param_transfer_time(m_units);
  m_late.clear();
  for (auto& s : m_st) s.data_exchange_at.reset();
}

void HDpStartupMonitor::data_exchange(std::uint8_t address, bus::Ticks now) {
  on_time(now);
  for (auto& s : m_st)
    if (s.address == address && !s.data_exchange_at) s.data_exchange_at = now;
}

void HDpStartupMonitor::on_time(bus::Ticks now) {
  if (m_deadline == bus::kNever || now < m_deadline) return;
  const bus::Ticks at = m_deadline;
  m_deadline = bus::kNever;
  m_late = late_stations(m_start, m_units, m_st);
  if (m_late.empty() || !m_sink) return;
  std::string t = "transfer of parameters to modules: monitoring time exceeded, stations";
  for (auto a : m_late) t += " " + std::to_string(a);
  m_sink(m_rack, at, std::move(t), kParamTransferExceeded);
}

}  // namespace pbvbus::devices
