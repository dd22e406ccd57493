// The H-system's I/O map (h_io_map.hpp has the address rules).
#include "pbvbus/s7h/h_io_map.hpp"

#include "pbvbus/switched_io/redundant_master_system.hpp"

namespace pbvbus::devices {

HIoMap::HIoMap(std::span<RedundantMasterSystemModel* const> systems) {
  for (std::size_t s = 0; s < systems.size(); ++s) {
    if (systems[s] == nullptr) continue;
    const redundancy::MasterSystem& ms = systems[s]->system();
    for (std::uint8_t a : ms.addresses()) {  // sorted
      const int l = ms.master(0).has_slave(a) ? 0 : 1;
      if (!ms.master(l).has_slave(a)) continue;
      const dp::MasterImage& img = ms.master(l).image(a);
      for (std::size_t m = 0; m < img.modules(); ++m) {
        HIoEntry e;
        e.system = static_cast<int>(s);
        e.address = a;
        e.module = m;
        e.in_addr = m_pii;
        e.in_len = img.module(m).in_len;
        e.out_addr = m_piq;
        e.out_len = img.module(m).out_len;
        m_pii += e.in_len;
        m_piq += e.out_len;
        m_entries.push_back(e);
      }
    }
  }
}

const HIoEntry& HIoMap::add_central(int rack, std::size_t module, std::size_t in_len,
                                    std::size_t out_len) {
  HIoEntry e;
  e.system = -1;
  e.module = module;
  e.in_addr = m_pii;
  e.in_len = in_len;
  e.out_addr = m_piq;
  e.out_len = out_len;
  e.central = true;
  e.rack = rack;
  m_pii += in_len;
  m_piq += out_len;
  m_entries.push_back(e);
  return m_entries.back();
}

const HIoEntry* HIoMap::find_central(int rack, std::size_t module) const {
  for (const auto& e : m_entries)
    if (e.central && e.rack == rack && e.module == module) return &e;
  return nullptr;
}

const HIoEntry* HIoMap::find(int system, std::uint8_t address, std::size_t module) const {
  for (const auto& e : m_entries)
    if (!e.central && e.system == system && e.address == address && e.module == module) return &e;
  return nullptr;
}

void HIoMap::read_inputs(std::span<RedundantMasterSystemModel* const> systems,
                         std::span<std::uint8_t> pii) const {
  if (pii.size() != m_pii) return;
  for (const auto& e : m_entries) {
    if (e.central || e.in_len == 0 || static_cast<std::size_t>(e.system) >= systems.size()) continue;
    const dp::MasterImage* img = systems[static_cast<std::size_t>(e.system)]->system().active_image(e.address);
    if (img == nullptr) continue;  // no active channel: keep the last values
    (void)img->read_inputs(e.module, pii.subspan(e.in_addr, e.in_len));
  }
}

void HIoMap::write_outputs(std::span<RedundantMasterSystemModel* const> systems,
                           std::span<const std::uint8_t> piq) const {
  if (piq.size() != m_piq) return;
  for (const auto& e : m_entries) {
    if (e.central || e.out_len == 0 || static_cast<std::size_t>(e.system) >= systems.size()) continue;
    systems[static_cast<std::size_t>(e.system)]->system().write_outputs(
        e.address, e.module, piq.subspan(e.out_addr, e.out_len));
  }
}

void HIoMap::write_outputs(std::span<RedundantMasterSystemModel* const> systems,
                           std::span<const std::uint8_t> piq, int line) const {
  if (piq.size() != m_piq) return;
  for (const auto& e : m_entries) {
    if (e.central || e.out_len == 0 || static_cast<std::size_t>(e.system) >= systems.size()) continue;
    // A one-sided slave of the other line is not this line's: write_outputs refuses it.
    (void)systems[static_cast<std::size_t>(e.system)]->system().write_outputs(
        line, e.address, e.module, piq.subspan(e.out_addr, e.out_len));
  }
}

}  // namespace pbvbus::devices
