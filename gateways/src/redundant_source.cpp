#include "pbvbus/gateways/redundant_source.hpp"

#include <algorithm>

namespace pbvbus::gateways {

RedundantSource::RedundantSource(devices::RedundantMasterSystemModel& model, std::string name,
                                 std::vector<SlaveNaming> naming, const devices::HSystemModel* h)
    : m_model(model), m_name(std::move(name)), m_h(h) {
  std::vector<std::uint8_t> all;
  for (int line = 0; line < 2; ++line)
    for (std::uint8_t a : model.master(line).addresses())
      if (std::find(all.begin(), all.end(), a) == all.end()) all.push_back(a);
  std::sort(all.begin(), all.end());
  for (std::uint8_t a : all) {
    const int line = model.master(0).has_slave(a) ? 0 : 1;
    SourceSlave s = make_source_slave(model.master(line), a, find_naming(naming, a));
    s.switched = model.system().is_switched(a);
    s.outputs_writable = h == nullptr;
    m_slaves.push_back(std::move(s));
  }
}

int RedundantSource::line_of(std::uint8_t address, Side side) const {
  const auto& sys = m_model.system();
  if (sys.is_switched(address)) {
    int primary = sys.active(address);
    if (primary < 0) primary = sys.switching_to(address);
    if (primary < 0) primary = 0;
    return side == Side::Primary ? primary : 1 - primary;
  }
  if (side == Side::Standby) return -1;
  for (int line = 0; line < 2; ++line)
    if (m_model.master(line).has_slave(address)) return line;
  return -1;
}

std::optional<SlaveStatus> RedundantSource::status(std::uint8_t address, Side side) const {
  const int line = line_of(address, side);
  if (line < 0 || !m_model.master(line).has_slave(address)) return std::nullopt;
  SlaveStatus st = master_slave_status(m_model.master(line), address);
  st.side_line = line;
  const auto& sys = m_model.system();
  if (sys.is_switched(address)) {
    st.active_channel = sys.active(address);
    st.redundancy_lost = sys.redundancy_lost(address);
  }
  return st;
}

bool RedundantSource::read_inputs(std::uint8_t address, Side side,
                                  std::span<std::uint8_t> out) const {
  const int line = line_of(address, side);
  return line >= 0 && m_model.master(line).has_slave(address) &&
         master_read_inputs(m_model.master(line), address, out);
}

bool RedundantSource::read_outputs(std::uint8_t address, Side side,
                                   std::span<std::uint8_t> out) const {
  const int line = line_of(address, side);
  return line >= 0 && m_model.master(line).has_slave(address) &&
         master_read_outputs(m_model.master(line), address, out);
}

bool RedundantSource::write_module_outputs(std::uint8_t address, std::size_t module,
                                           std::span<const std::uint8_t> data) {
  if (m_h) return false;
  return m_model.system().write_outputs(address, module, data);
}

int RedundantSource::primary_master_line() const {
  if (m_h) {
    const int r = m_h->pair().master();
    if (r == 0 || r == 1) return r;
  }
  if (m_model.master_failed(0) || m_model.system().line_is_lost(0)) return 1;
  return 0;
}

dp::MasterMode RedundantSource::mode() const {
  return m_model.master(primary_master_line()).mode();
}

bool RedundantSource::command(dp::MasterMode m) {
  if (m_h || m == dp::MasterMode::Offline) return false;
  m_model.master(0).set_mode(m);
  m_model.master(1).set_mode(m);
  return true;
}

MasterCounters RedundantSource::counters() const {
  MasterCounters c = master_counters(m_model.master(primary_master_line()));
  c.switchovers = m_model.system().switchovers();
  return c;
}

std::uint8_t RedundantSource::master_address() const {
  return m_model.master(primary_master_line()).address();
}

std::optional<HStatus> RedundantSource::h_status() const {
  if (!m_h) return std::nullopt;
  const devices::HCpuPair& p = m_h->pair();
  HStatus h;
  for (int r = 0; r < 2; ++r) {
    h.cpu_state[static_cast<std::size_t>(r)] = static_cast<std::uint8_t>(p.state(r));
    h.cpu_role[static_cast<std::size_t>(r)] = static_cast<std::uint8_t>(p.role(r));
  }
  h.system_mode = static_cast<std::uint8_t>(p.system_mode());
  h.master_rack = p.master();
  return h;
}

}  // namespace pbvbus::gateways
