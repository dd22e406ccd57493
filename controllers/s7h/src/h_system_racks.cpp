// F8 expansion racks of the H-system model: their configuration check, their one-sided central
// I/O at each OB 1 (inputs, outputs, OB 85) and the rack failure (OB 86 W#16#39C1/38C1).
// h_system.hpp (block "F8 expansion racks, OB 80") has the decisions, h_expansion_rack.hpp the
// configuration rules.
#include <algorithm>
#include <cstdio>
#include <set>
#include <stdexcept>

#include "pbvbus/s7h/h_system.hpp"

namespace pbvbus::devices {

std::vector<std::string> check_expansion_racks(const std::vector<HExpansionRack>& racks) {
  std::vector<std::string> errors;
  std::set<int> seen;
  for (const HExpansionRack& r : racks) {
    const std::string who = "expansion rack " + std::to_string(r.number);
    if (r.number < 1 || r.number > kMaxExpansionRack)
      errors.push_back(who + ": number is not 1.." + std::to_string(kMaxExpansionRack));
    else if (!seen.insert(r.number).second)
      errors.push_back(who + ": number used twice");
    if (r.side != 0 && r.side != 1)
      errors.push_back(who + ": side " + std::to_string(r.side) +
                       " is not 0 or 1 (the central rack it hangs on)");
    if (r.modules.empty()) errors.push_back(who + ": no modules");
    for (std::size_t m = 0; m < r.modules.size(); ++m) {
      const HRackModule& mod = r.modules[m];
      const std::string mw = who + ": module " + std::to_string(m) + " \"" + mod.name + "\"";
      if (mod.in_len == 0 && mod.out_len == 0) errors.push_back(mw + ": no inputs and no outputs");
      if (mod.in_len > kMaxRackModuleOctets || mod.out_len > kMaxRackModuleOctets)
        errors.push_back(mw + ": more than " + std::to_string(kMaxRackModuleOctets) + " octets");
      if (mod.in_len == 0) continue;  // the behaviour is not used
      if (std::string e = check_behaviour(mod.inputs, r.modules.size()); !e.empty())
        errors.push_back(mw + ": " + e);
      else if (mod.inputs.kind == IoBehaviour::Kind::Echo &&
               r.modules[mod.inputs.source_module.value_or(m)].out_len == 0)
        errors.push_back(mw + ": echo source module " +
                         std::to_string(mod.inputs.source_module.value_or(m)) + " has no outputs");
    }
  }
  return errors;
}

std::vector<RedundantMasterSystemModel*> HSystemModel::racks_checked(
    std::vector<RedundantMasterSystemModel*> systems, const std::vector<HExpansionRack>& racks) {
  const auto errors = check_expansion_racks(racks);
  if (!errors.empty()) throw std::invalid_argument("expansion racks: " + errors.front());
  return systems;
}

HSystemModel::HSystemModel(bus::Scheduler& sched, HCpuPairParams params,
                           std::vector<RedundantMasterSystemModel*> systems,
                           std::vector<HExpansionRack> racks)
    // Checked before the delegated constructor schedules anything on `sched`.
    : HSystemModel(sched, std::move(params), racks_checked(std::move(systems), racks)) {
  set_expansion_racks(std::move(racks));
}

void HSystemModel::set_expansion_racks(std::vector<HExpansionRack> racks) {
  const auto errors = check_expansion_racks(racks);
  if (!errors.empty()) throw std::invalid_argument("expansion racks: " + errors.front());
  if (m_exec)
    throw std::invalid_argument("expansion racks: set them before the program (its images' "
                                "sizes are fixed)");
  if (m_cycle_start != bus::kNever)
    throw std::invalid_argument("expansion racks: set them before the run (an OB 1 ran)");
  // The DP part of the map as built at construction, then the central modules.
  m_map = HIoMap(m_systems);
  m_racks.assign(racks.size(), RackState{});
  for (std::size_t k = 0; k < racks.size(); ++k) {
    RackState& st = m_racks[k];
    for (std::size_t m = 0; m < racks[k].modules.size(); ++m) {
      const HRackModule& mod = racks[k].modules[m];
      m_map.add_central(racks[k].number, m, mod.in_len, mod.out_len);
      st.in.emplace_back(mod.in_len, 0);
      st.out.emplace_back(mod.out_len, 0);
    }
  }
  m_rack_cfg = std::move(racks);
  m_pii.assign(m_map.pii_size(), 0);
  m_piq.assign(m_map.piq_size(), 0);
}

int HSystemModel::rack_index(int number) const {
  for (std::size_t k = 0; k < m_rack_cfg.size(); ++k)
    if (m_rack_cfg[k].number == number) return static_cast<int>(k);
  return -1;
}

bool HSystemModel::rack_reachable(std::size_t k) const {
  return m_racks[k].on && m_pair.dp_master_operate(m_rack_cfg[k].side);
}

bool HSystemModel::expansion_rack_is_on(int number) const {
  const int k = rack_index(number);
  return k >= 0 && m_racks[static_cast<std::size_t>(k)].on;
}

bool HSystemModel::expansion_rack_reachable(int number) const {
  const int k = rack_index(number);
  return k >= 0 && rack_reachable(static_cast<std::size_t>(k));
}

bool HSystemModel::expansion_rack_ob85(int number) const {
  const int k = rack_index(number);
  return k >= 0 && m_racks[static_cast<std::size_t>(k)].ob85;
}

std::span<const std::uint8_t> HSystemModel::rack_outputs(int number, std::size_t module) const {
  const int k = rack_index(number);
  if (k < 0 || module >= m_racks[static_cast<std::size_t>(k)].out.size()) return {};
  return m_racks[static_cast<std::size_t>(k)].out[module];
}

std::span<const std::uint8_t> HSystemModel::rack_inputs(int number, std::size_t module) const {
  const int k = rack_index(number);
  if (k < 0 || module >= m_racks[static_cast<std::size_t>(k)].in.size()) return {};
  return m_racks[static_cast<std::size_t>(k)].in[module];
}

bool HSystemModel::expansion_rack_off(int number) {
  m_pair.on_time(m_sched.now());  // deadlines due now first, as every pair operation does
  after_op();
  const int k = rack_index(number);
  if (k < 0 || !m_racks[static_cast<std::size_t>(k)].on) return false;
  m_racks[static_cast<std::size_t>(k)].on = false;
  rack_event(static_cast<std::size_t>(k), true);
  return true;
}

bool HSystemModel::expansion_rack_on(int number) {
  m_pair.on_time(m_sched.now());
  after_op();
  const int k = rack_index(number);
  if (k < 0 || m_racks[static_cast<std::size_t>(k)].on) return false;
  m_racks[static_cast<std::size_t>(k)].on = true;
  rack_event(static_cast<std::size_t>(k), false);
  return true;
}


void HSystemModel::rack_event(std::size_t k, bool failed) {
  const HExpansionRack& cfg = m_rack_cfg[k];
  if (m_pair.state(cfg.side) == CpuState::Off) return;  // its IM 460 is dark: nobody sees it
  const bus::Ticks now = m_sched.now();
  const std::uint16_t code = failed ? kOb86RackFailure : kOb86RackReturn;
  char buf[160];
  std::snprintf(buf, sizeof buf, "OB 86 W#16#%04X expansion rack %s, expansion rack %d (IM 460 of CPU %d)",
                static_cast<unsigned>(code), failed ? "failure" : "operational again", cfg.number,
                cfg.side);
  log_on_powered(now, code, buf);
  // The OB runs where the program runs, if the rack's own CPU is one of them.
  const bool run0 = m_pair.dp_master_operate(0), run1 = m_pair.dp_master_operate(1);
  if (!m_pair.dp_master_operate(cfg.side)) return;
  HSystemEvent h;
  h.time = now;
  h.original_time = now;
  h.rack = run0 && run1 ? -1 : cfg.side;
  h.role = h.rack < 0 ? CpuRole::Master : m_pair.role(h.rack);
  h.ob = 86;
  h.code = code;
  h.text = buf;
  h.source = HSystemEvent::Source::Io;
  h.system = -1;
  h.line = cfg.side;
  h.station = static_cast<std::uint8_t>(cfg.number);
  h.incoming = failed;
  add_event(std::move(h));
}

namespace {

/// The module's inputs now (the behaviour over the whole module, as SlaveModel's channels).
void fill_inputs(const HRackModule& mod, std::size_t self, std::span<std::uint8_t> dst,
                 bus::Ticks now, std::uint64_t reads,
                 const std::vector<std::vector<std::uint8_t>>& outputs) {
  const IoBehaviour& b = mod.inputs;
  switch (b.kind) {
    case IoBehaviour::Kind::Constant:
      for (std::size_t i = 0; i < dst.size(); ++i) dst[i] = i < b.constant.size() ? b.constant[i] : 0;
      return;
    case IoBehaviour::Kind::Echo: {
      const auto& src = outputs[b.source_module.value_or(self)];
      for (std::size_t i = 0; i < dst.size(); ++i) dst[i] = i < src.size() ? src[i] : 0;
      return;
    }
    default: {
      auto u = static_cast<std::uint64_t>(behaviour_value(b, now, reads));
      for (std::size_t i = dst.size(); i-- > 0;) {  // big-endian, as put_big_endian()
        dst[i] = static_cast<std::uint8_t>(u & 0xFF);
        u >>= 8;
      }
      return;
    }
  }
}

}  // namespace

void HSystemModel::read_racks(bus::Ticks now) {
  const bool run0 = m_pair.dp_master_operate(0), run1 = m_pair.dp_master_operate(1);
  for (std::size_t k = 0; k < m_racks.size(); ++k) {
    RackState& st = m_racks[k];
    const HExpansionRack& cfg = m_rack_cfg[k];
    const bool reach = rack_reachable(k);
    if (reach) st.ran = true;
    const bool failed = st.ran && !reach;
    if (failed != st.ob85) {
      st.ob85 = failed;
      HSystemEvent h;
      h.time = now;
      h.original_time = now;
      h.ob = 85;
      h.code = failed ? 0x39B1 : 0x38B1;  // as the DP stations' OB 85 (h_system_alarms.cpp)
      h.incoming = failed;
      h.source = HSystemEvent::Source::Image;
      h.system = -1;
      h.line = cfg.side;
      h.station = static_cast<std::uint8_t>(cfg.number);
      char buf[128];
      std::snprintf(buf, sizeof buf,
                    "OB 85 W#16#%04X process-image transfer error %s, expansion rack %d",
                    static_cast<unsigned>(h.code), failed ? "incoming" : "outgoing", cfg.number);
      h.text = buf;
      h.rack = run0 && run1 ? -1 : (run0 ? 0 : 1);
      h.role = h.rack < 0 ? CpuRole::Master : m_pair.role(h.rack);
      add_event(std::move(h));
    }
    if (!reach) continue;  // the PII keeps the last values
    const std::uint64_t reads = st.reads++;
    for (std::size_t m = 0; m < cfg.modules.size(); ++m) {
      if (cfg.modules[m].in_len == 0) continue;
      fill_inputs(cfg.modules[m], m, st.in[m], now, reads, st.out);
      const HIoEntry* e = m_map.find_central(cfg.number, m);
      if (e == nullptr || e->in_addr + e->in_len > m_pii.size()) continue;
      std::copy(st.in[m].begin(), st.in[m].end(),
                m_pii.begin() + static_cast<std::ptrdiff_t>(e->in_addr));
    }
  }
}

void HSystemModel::write_racks() { write_racks(m_piq, m_piq); }

void HSystemModel::write_racks(std::span<const std::uint8_t> piq0,
                               std::span<const std::uint8_t> piq1) {
  for (std::size_t k = 0; k < m_racks.size(); ++k) {
    if (!rack_reachable(k)) continue;  // its modules keep what they had
    RackState& st = m_racks[k];
    const HExpansionRack& cfg = m_rack_cfg[k];
    if (cfg.side == m_cc_zero_side) continue;  // the new master's first OB 1: still 0
    for (std::size_t m = 0; m < cfg.modules.size(); ++m) {
      if (cfg.modules[m].partition != 0) continue;  // SFC 27 writes it (h_system_sfc90.cpp)
      const HIoEntry* e = m_map.find_central(cfg.number, m);
      const std::span<const std::uint8_t> piq = cfg.side == 0 ? piq0 : piq1;
      if (e == nullptr || e->out_len == 0 || e->out_addr + e->out_len > piq.size()) continue;
      const auto from = piq.begin() + static_cast<std::ptrdiff_t>(e->out_addr);
      std::copy(from, from + static_cast<std::ptrdiff_t>(e->out_len), st.out[m].begin());
    }
  }
}

}  // namespace pbvbus::devices
