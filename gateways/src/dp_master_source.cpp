#include "pbvbus/gateways/dp_master_source.hpp"

#include <algorithm>

namespace pbvbus::gateways {

const SlaveNaming* find_naming(const std::vector<SlaveNaming>& list, std::uint8_t address) {
  for (const auto& n : list)
    if (n.address == address) return &n;
  return nullptr;
}

SourceSlave make_source_slave(const dp::Master& master, std::uint8_t address,
                              const SlaveNaming* naming) {
  SourceSlave s;
  s.address = address;
  const dp::SlaveParams& p = master.slave_params(address);
  s.ident = p.ident;
  s.name = naming && !naming->model.empty() ? naming->model : p.name;
  const dp::MasterImage& img = master.image(address);
  for (std::size_t m = 0; m < img.modules(); ++m) {
    const dp::ModuleLayout& l = img.module(m);
    SourceModule sm;
    sm.name = naming && m < naming->modules.size() && !naming->modules[m].empty()
                  ? naming->modules[m]
                  : "module " + std::to_string(m);
    sm.in_offset = l.in_offset;
    sm.in_len = l.in_len;
    sm.out_offset = l.out_offset;
    sm.out_len = l.out_len;
    sm.consistent = l.consistent;
    s.modules.push_back(std::move(sm));
  }
  s.input_len = img.input_length();
  s.output_len = img.output_length();
  return s;
}

SlaveStatus master_slave_status(const dp::Master& master, std::uint8_t address) {
  SlaveStatus st;
  st.state = master.slave_state(address);
  st.data_valid = master.image(address).data_valid();
  const auto diag = master.slave_diag(address);
  st.diag.assign(diag.begin(), diag.end());
  const dp::MasterSlaveStats& s = master.slave_stats(address);
  st.data_exchanges = s.data_exchanges;
  st.failures = s.failures;
  st.returns = s.returns;
  return st;
}

bool master_read_inputs(const dp::Master& master, std::uint8_t address,
                        std::span<std::uint8_t> out) {
  return master.image(address).read_all_inputs(out) == dp::ImageAccess::Ok;
}

bool master_read_outputs(const dp::Master& master, std::uint8_t address,
                         std::span<std::uint8_t> out) {
  const dp::MasterImage& img = master.image(address);
  if (out.size() != img.output_length()) return false;
  for (std::size_t m = 0; m < img.modules(); ++m) {
    const dp::ModuleLayout& l = img.module(m);
    if (l.out_len == 0) continue;
    if (img.read_outputs(m, out.subspan(l.out_offset, l.out_len)) != dp::ImageAccess::Ok)
      return false;
  }
  return true;
}

MasterCounters master_counters(const dp::Master& master) {
  MasterCounters c;
  for (std::uint8_t a : master.addresses()) {
    const dp::MasterSlaveStats& s = master.slave_stats(a);
    c.station_failures += s.failures;
    c.station_returns += s.returns;
    c.diagnoses += s.diag_reads;
    c.alarms += s.alarms;
  }
  return c;
}

DpMasterSource::DpMasterSource(dp::Master& master, std::string name,
                               std::vector<SlaveNaming> naming)
    : m_master(master), m_name(std::move(name)) {
  auto addresses = master.addresses();
  std::sort(addresses.begin(), addresses.end());
  for (std::uint8_t a : addresses)
    m_slaves.push_back(make_source_slave(master, a, find_naming(naming, a)));
}

bool DpMasterSource::known(std::uint8_t address, Side side) const {
  return side == Side::Primary && m_master.has_slave(address);
}

std::optional<SlaveStatus> DpMasterSource::status(std::uint8_t address, Side side) const {
  if (!known(address, side)) return std::nullopt;
  return master_slave_status(m_master, address);
}

bool DpMasterSource::read_inputs(std::uint8_t address, Side side,
                                 std::span<std::uint8_t> out) const {
  return known(address, side) && master_read_inputs(m_master, address, out);
}

bool DpMasterSource::read_outputs(std::uint8_t address, Side side,
                                  std::span<std::uint8_t> out) const {
  return known(address, side) && master_read_outputs(m_master, address, out);
}

bool DpMasterSource::write_module_outputs(std::uint8_t address, std::size_t module,
                                          std::span<const std::uint8_t> data) {
  if (!m_master.has_slave(address)) return false;
  return m_master.image(address).write_outputs(module, data) == dp::ImageAccess::Ok;
}

bool DpMasterSource::command(dp::MasterMode m) {
  if (m == dp::MasterMode::Offline) return false;
  m_master.set_mode(m);
  return true;
}

}  // namespace pbvbus::gateways
