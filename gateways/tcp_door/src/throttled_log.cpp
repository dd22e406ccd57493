#include "pbvbus/tcp_door/throttled_log.hpp"

namespace pbvbus::gateways {

void ThrottledLog::operator()(const std::string& line) {
  if (!m_log) return;
  const auto now = std::chrono::steady_clock::now();
  if (m_logged && now - m_last < m_interval) {
    ++m_held;
    return;
  }
  m_logged = true;
  m_last = now;
  if (m_held == 0) {
    m_log(line);
    return;
  }
  m_log(line + " (" + std::to_string(m_held) + " more like it not logged)");
  m_held = 0;
}

}  // namespace pbvbus::gateways
