#pragma once
// An in-memory ProcessSource for the gateway tests: slaves with modules, states, images and
// counters set by the test; records every module write. Plain data, no bus.

#include <map>
#include <optional>
#include <span>
#include <utility>
#include <vector>

#include "pbvbus/gateways/process_source.hpp"

namespace pbvbus::gateways::test {

class FakeSource final : public ProcessSource {
 public:
  struct SideData {
    SlaveStatus status;
    std::vector<std::uint8_t> inputs;
    std::vector<std::uint8_t> outputs;
  };
  struct Write {
    std::uint8_t address;
    std::size_t module;
    std::vector<std::uint8_t> data;
  };

  /// Adds a slave; module offsets are computed from the lengths in slot order.
  SourceSlave& add_slave(std::uint8_t address, std::uint16_t ident,
                         std::vector<SourceModule> modules, std::string name = "fake") {
    SourceSlave s;
    s.address = address;
    s.ident = ident;
    s.name = std::move(name);
    for (auto& m : modules) {
      m.in_offset = s.input_len;
      m.out_offset = s.output_len;
      s.input_len += m.in_len;
      s.output_len += m.out_len;
    }
    s.modules = std::move(modules);
    auto it = m_slaves.begin();
    while (it != m_slaves.end() && it->address < address) ++it;
    it = m_slaves.insert(it, std::move(s));
    for (int side = 0; side < 2; ++side) {
      auto& d = m_data[{address, side}];
      d.inputs.assign(it->input_len, 0);
      d.outputs.assign(it->output_len, 0);
      d.status.state = dp::SlaveStatusState::DataExchange;
      d.status.data_valid = true;
      d.status.side_line = side;
    }
    return *it;
  }
  SideData& data(std::uint8_t address, Side side = Side::Primary) {
    return m_data.at({address, static_cast<int>(side)});
  }
  /// Swaps the two sides' data (a changeover).
  void swap_sides(std::uint8_t address) {
    std::swap(m_data.at({address, 0}), m_data.at({address, 1}));
  }
  void set_redundant(bool r) { m_redundant = r; }
  void set_h_status(std::optional<HStatus> h) { m_h = h; }
  void set_counters(MasterCounters c) { m_counters = c; }
  void set_accept_commands(bool a) { m_accept = a; }
  const std::vector<Write>& writes() const { return m_writes; }
  const std::vector<dp::MasterMode>& commands() const { return m_commands; }

  std::string name() const override { return "fake master system"; }
  std::span<const SourceSlave> slaves() const override { return m_slaves; }
  bool redundant() const override { return m_redundant; }
  std::optional<SlaveStatus> status(std::uint8_t a, Side side) const override {
    const auto* d = find(a, side);
    if (!d) return std::nullopt;
    return d->status;
  }
  bool read_inputs(std::uint8_t a, Side side, std::span<std::uint8_t> out) const override {
    const auto* d = find(a, side);
    if (!d || out.size() != d->inputs.size()) return false;
    std::copy(d->inputs.begin(), d->inputs.end(), out.begin());
    return true;
  }
  bool read_outputs(std::uint8_t a, Side side, std::span<std::uint8_t> out) const override {
    const auto* d = find(a, side);
    if (!d || out.size() != d->outputs.size()) return false;
    std::copy(d->outputs.begin(), d->outputs.end(), out.begin());
    return true;
  }
  bool write_module_outputs(std::uint8_t a, std::size_t module,
                            std::span<const std::uint8_t> data) override {
    const SourceSlave* s = slave(a);
    if (!s || !s->outputs_writable || module >= s->modules.size() ||
        data.size() != s->modules[module].out_len)
      return false;
    auto& d = m_data.at({a, 0});
    std::copy(data.begin(), data.end(),
              d.outputs.begin() + static_cast<std::ptrdiff_t>(s->modules[module].out_offset));
    m_writes.push_back({a, module, {data.begin(), data.end()}});
    return true;
  }
  dp::MasterMode mode() const override { return m_mode; }
  bool command(dp::MasterMode m) override {
    m_commands.push_back(m);
    if (!m_accept || m == dp::MasterMode::Offline) return false;
    m_mode = m;
    return true;
  }
  MasterCounters counters() const override { return m_counters; }
  std::uint8_t master_address() const override { return 1; }
  std::optional<HStatus> h_status() const override { return m_h; }

  const SourceSlave* slave(std::uint8_t a) const {
    for (const auto& s : m_slaves)
      if (s.address == a) return &s;
    return nullptr;
  }

 private:
  const SideData* find(std::uint8_t a, Side side) const {
    if (side == Side::Standby && !m_redundant) return nullptr;
    auto it = m_data.find({a, static_cast<int>(side)});
    return it == m_data.end() ? nullptr : &it->second;
  }
  std::vector<SourceSlave> m_slaves;
  std::map<std::pair<std::uint8_t, int>, SideData> m_data;
  bool m_redundant = false;
  bool m_accept = true;
  dp::MasterMode m_mode = dp::MasterMode::Operate;
  MasterCounters m_counters;
  std::optional<HStatus> m_h;
  std::vector<Write> m_writes;
  std::vector<dp::MasterMode> m_commands;
};

}  // namespace pbvbus::gateways::test
