#include "pbvbus/s7h/h_diag_address.hpp"

#include <algorithm>
#include <utility>

namespace pbvbus::devices {

HDiagAddresses::HDiagAddresses(std::uint16_t top,
                               const std::vector<std::vector<std::uint8_t>>& stations) {
  int next = top;
  for (const auto& st : stations) {
    std::vector<std::uint8_t> sorted = st;
    std::sort(sorted.begin(), sorted.end());
    sorted.erase(std::unique(sorted.begin(), sorted.end()), sorted.end());
    System s;
    s.master = static_cast<std::uint16_t>(std::max(next--, 0));
    for (std::uint8_t a : sorted) s.slaves.emplace_back(a, static_cast<std::uint16_t>(std::max(next--, 0)));
    m_systems.push_back(std::move(s));
  }
}

std::optional<std::uint16_t> HDiagAddresses::master(std::size_t system) const {
  if (system >= m_systems.size()) return std::nullopt;
  return m_systems[system].master;
}

std::optional<std::uint16_t> HDiagAddresses::slave(std::size_t system, std::uint8_t station) const {
  if (system >= m_systems.size()) return std::nullopt;
  for (const auto& [a, d] : m_systems[system].slaves)
    if (a == station) return d;
  return std::nullopt;
}

}  // namespace pbvbus::devices
