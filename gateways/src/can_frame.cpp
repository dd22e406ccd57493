#include "pbvbus/gateways/can_frame.hpp"

#include <cstdio>

namespace pbvbus::gateways {

std::string to_string(const CanFrame& f) {
  char buf[40];
  int n = f.extended ? std::snprintf(buf, sizeof buf, "%08X#", static_cast<unsigned>(f.id))
                     : std::snprintf(buf, sizeof buf, "%03X#", static_cast<unsigned>(f.id));
  std::string s(buf, static_cast<std::size_t>(n));
  if (f.rtr) return s + "R";
  for (std::size_t i = 0; i < f.dlc && i < 8; ++i) {
    std::snprintf(buf, sizeof buf, "%02X", f.data[i]);
    s += buf;
  }
  return s;
}

CanHub::PortId CanHub::add_port(std::string name, Receiver rx) {
  m_ports.push_back(Port{std::move(name), std::move(rx), true});
  return m_ports.size() - 1;
}

void CanHub::remove_port(PortId id) {
  if (id < m_ports.size()) {
    m_ports[id].live = false;
    m_ports[id].rx = nullptr;
  }
}

void CanHub::send(PortId from, const CanFrame& f, bus::Ticks now) {
  ++m_frames;
  // By index: a receiver may add ports (a client connecting) while we deliver.
  for (std::size_t i = 0; i < m_ports.size(); ++i) {
    if (i == from || !m_ports[i].live || !m_ports[i].rx) continue;
    auto rx = m_ports[i].rx;  // a receiver may remove its own port
    rx(f, now);
  }
}

std::size_t CanHub::ports() const {
  std::size_t n = 0;
  for (const auto& p : m_ports) n += p.live ? 1 : 0;
  return n;
}

}  // namespace pbvbus::gateways
