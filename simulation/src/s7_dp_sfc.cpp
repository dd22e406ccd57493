// A single S7 CPU's DP system functions (docs/h-dp-sfc.md): its DP interfaces attached before
// the run (the module addresses SFC 14/15 look up), SFC 11 DPSYC_FR and SFC 12 D_ACT_DP acting
// on the interface's DP master.
#include <algorithm>

#include "pbvbus/s7h/h_dp_sfc.hpp"
#include "pbvbus/simulation/s7_nodes.hpp"

namespace pbvbus::tools {

void S7CpuNode::attach_dp(const std::string& line, dp::Master& master, bool x1) {
  m_dp.push_back({line, &master, x1});
  std::stable_sort(m_dp.begin(), m_dp.end(),
                   [](const DpInterface& a, const DpInterface& b) { return a.x1 && !b.x1; });
  // The addresses again from IB 0/QB 0, X1's slaves first (s7_nodes.hpp).
  m_maps.clear();
  m_next_in = m_next_out = m_unmapped = 0;
  for (const DpInterface& d : m_dp) map(*d.master);
  if (!m_program) return;
  std::vector<devices::IoModuleExtent> mods;
  for (const auto& [master_ptr, slots] : m_maps)
    for (const Slot& s : slots)
      mods.push_back({s.in_at, s.in_len, s.out_at, s.out_len, true});
  m_program->set_io_modules(std::move(mods));
}

dp::Master* S7CpuNode::dp_master_on(const std::string& line) const {
  for (const DpInterface& d : m_dp)
    if (d.line == line) return d.master;
  return nullptr;
}

void S7CpuNode::run_dp_sfcs(bus::Ticks now) {
  const devices::ProgramSpec& spec = m_program->spec();
  const std::size_t n11 = spec.dpsyc_fr.size();
  m_dp_sfc_done.resize(n11 + spec.d_act_dp.size(), false);
  const auto mem = m_image->memory();
  for (std::size_t i = 0; i < n11; ++i) {
    const auto& c = spec.dpsyc_fr[i];
    if (m_dp_sfc_done[i] || c.at > now) continue;
    m_dp_sfc_done[i] = true;
    dp::Master* m = dp_master_on(c.line);
    std::uint16_t rv = devices::check_dpsyc_fr(c.group, c.mode);
    if (m == nullptr)
      rv = devices::kSfcNoModule;
    else if (rv == 0) {
      // Control_Command = MODE, Group_Select = GROUP (protocol-facts.md §D.6): the master
      // sends it as SDN to DA 127, SAP 62 -> 58, at the start of its next pass.
      m->global_control(c.mode, c.group);
      rv = devices::kSfcOk;
    }
    if (c.ret_val) devices::store_ret_val(mem, *c.ret_val, rv);
    m_dp_sfc.push_back({now, 11, i, rv});
  }
  for (std::size_t i = 0; i < spec.d_act_dp.size(); ++i) {
    const auto& c = spec.d_act_dp[i];
    if (m_dp_sfc_done[n11 + i] || c.at > now) continue;
    m_dp_sfc_done[n11 + i] = true;
    dp::Master* m = dp_master_on(c.line);
    std::uint16_t rv = devices::kSfcNoModule;
    if (m != nullptr && m->has_slave(c.station)) {
      switch (c.mode) {
        case 0:
          rv = m->slave_params(c.station).active ? devices::kDActIsActive : devices::kDActIsInactive;
          break;
        case 1:
        case 2:
          m->set_slave_active(c.station, c.mode == 1);
          rv = devices::kSfcOk;
          break;
        default:
          rv = devices::kDActBadMode;
      }
    }
    if (c.ret_val) devices::store_ret_val(mem, *c.ret_val, rv);
    m_dp_sfc.push_back({now, 12, i, rv});
  }
}

}  // namespace pbvbus::tools
