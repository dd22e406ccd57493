#include "recording_port.hpp"

#include <stdexcept>

namespace pbvbus::test {

void RecordingPort::transmit(bus::Ticks start, std::span<const std::uint8_t> bytes) {
  m_tx.push_back(Transmission{start, m_now, {bytes.begin(), bytes.end()}});
}

void RecordingPort::set_timer(bus::Ticks at) {
  m_timer = at;
  ++m_timer_requests;
}

const RecordingPort::Transmission& RecordingPort::last() const {
  if (m_tx.empty()) throw std::out_of_range("RecordingPort: nothing was transmitted");
  return m_tx.back();
}

std::optional<RecordingPort::Transmission> RecordingPort::pop_front() {
  if (m_tx.empty()) return std::nullopt;
  Transmission t = std::move(m_tx.front());
  m_tx.erase(m_tx.begin());
  return t;
}

void RecordingPort::clear() {
  m_tx.clear();
  m_timer_requests = 0;
}

bool RecordingPort::fire_timer_if_due(bus::Device& dev, bus::Ticks until) {
  if (m_timer == bus::kNever || m_timer > until) return false;
  if (m_timer > m_now) m_now = m_timer;
  m_timer = bus::kNever;
  dev.on_timer(m_now);
  return true;
}

}  // namespace pbvbus::test
