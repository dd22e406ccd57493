// The "switch to CPU with modified configuration" driven by the H-system model (h_system.hpp
// block "switch to CPU with modified configuration"; docs/h-changes.md "In the H-system
// model"): HConfigChange (h_config_change.hpp) follows the pair at every reconcile(), the model
// applies what it can express: OB1_SCAN_1, the new master's central outputs at 0 for its first
// OB 1 cycle, OB 83 for the added switched modules on the return to Redundant.
#include <algorithm>
#include <memory>
#include <string>
#include <utility>

#include "pbvbus/s7h/h_event_ids.hpp"
#include "pbvbus/s7h/h_system.hpp"

namespace pbvbus::devices {

using h_event::kOb83Inserted;  // OB 83 "module inserted", W#16#3861 (h_event_ids.hpp)

bool HSystemModel::switch_to_cpu(HSwitchVariant v, const HCpuConfig& master,
                                 const HCpuConfig& standby, std::vector<int> added_switched) {
  HConfigChangeParams p;
  // "Briefly" 0 (000 L3388): one OB 1 cycle of this model (h_config_change.hpp's decision).
  p.first_cycle_time = m_scan_time;
  auto cc = std::make_unique<HConfigChange>(m_pair, p);
  // 000 §5.2.3: the DB copy plan (h_system_db_copy.cpp); aborted = refused.
  if (v == HSwitchVariant::ModifiedConfiguration && !cc_plan_db_copy(standby)) {
    after_op();
    return false;
  }
  const bool ok = cc->request(v, master, standby, m_sched.now(), std::move(added_switched));
  if (ok || !m_cc) {  // a refusal keeps a switch still running (its OB 83 is owed)
    m_cc = std::move(cc);
    m_cc_swap_done = false;
    m_cc_ob83_done = false;
  }
  after_op();
  return ok;
}

void HSystemModel::cc_observe() {
  if (!m_cc) return;
  m_cc->observe();
  if (!m_cc_swap_done && m_cc->swap_time()) {
    m_cc_swap_done = true;
    // 000 L3388: the new master's central output modules are first reset (output 0), then
    // re-parameterised and updated; its first OB 1 leaves them at 0 (cc_ob1, write_racks).
    const int nm = m_cc->new_master();
    for (std::size_t k = 0; k < m_racks.size(); ++k) {
      if (m_rack_cfg[k].side != nm) continue;
      for (auto& out : m_racks[k].out) std::fill(out.begin(), out.end(), std::uint8_t{0});
    }
  }
  if (!m_cc_ob83_done && m_cc->ob83_time() >= 0) {
    m_cc_ob83_done = true;
    // 000 L3412: each added switched module raises a plug interrupt, OB 83 on both CPUs (the
    // entries are HConfigChange's); the OB runs where the program runs (both in Redundant).
    const bus::Ticks at = m_cc->ob83_time();
    const bool run0 = m_pair.dp_master_operate(0), run1 = m_pair.dp_master_operate(1);
    if (!run0 && !run1) return;
    for (int a : m_cc->ob83_modules()) {
      HSystemEvent h;
      h.time = at;
      h.original_time = at;
      h.rack = run0 && run1 ? -1 : (run0 ? 0 : 1);
      h.role = h.rack < 0 ? CpuRole::Master : m_pair.role(h.rack);
      h.ob = 83;
      h.code = kOb83Inserted;
      h.source = HSystemEvent::Source::Alarm;
      h.mdl_addr = static_cast<std::uint16_t>(a);
      h.text = "OB 83 W#16#3861 module inserted (switched, address " + std::to_string(a) +
               "): new configuration after the switch to CPU with modified configuration, "
               "ignore (000 L3412)";
      add_event(std::move(h));
    }
  }
}

void HSystemModel::cc_ob1(bus::Ticks now) {
  m_cc_zero_side = -1;
  m_ob1_scan_1 = kOb1ScanFreeCycle;
  const int m = m_pair.master();
  if (!m_cc || m < 0) return;
  m_ob1_scan_1 = m_cc->ob1_scan_1(m, now);
  if (m_ob1_scan_1 != kOb1ScanAfterSwap) return;
  m_cc_zero_side = m;
  m_ob1_after_swap.push_back(now);
}

}  // namespace pbvbus::devices
