// HSystemNode's part of docs/h-scenario-changes.md: the RAM test (HCpu.battery, ram_mb), the
// watchdog OBs (HProgram.watchdog_ob), OB 72 calling SFC 27 (ob72_updat_po), the fault
// switch_to_cpu and what the report shows of them.
#include <algorithm>
#include <string>

#include "pbvbus/scenario/h_plan.hpp"
#include "pbvbus/simulation/h_system_node.hpp"

namespace pbvbus::tools {

namespace {

std::string list(const std::vector<int>& v) {
  std::string s;
  for (int x : v) s += (s.empty() ? "" : ", ") + std::to_string(x);
  return s;
}

}  // namespace

void HSystemNode::setup_changes() {
  const HChangesPlan& c = plan().runtime->changes;
  // Before the first power-on (HSystemModel::set_rack_power's rule).
  if (c.rack_power) m_model->set_rack_power(*c.rack_power);
  if (!c.ob72_updat_po.empty()) {
    // OB 72 "redundancy restored" refreshes the output partitions with SFC 27 (000 L1752).
    const std::vector<int> parts = c.ob72_updat_po;
    devices::HSystemModel* m = m_model.get();
    m_model->set_ob72_return([m, parts](bus::Ticks) {
      for (int p : parts) m->updat_po(p);
    });
  }
}

void HSystemNode::start_changes() {
  const HChangesPlan& c = plan().runtime->changes;
  if (c.rack_power && c.rack_power->ram_kb > 0) {
    const bus::Ticks t = devices::ram_test_time(c.rack_power->ram_kb);
    note("RAM test at every unbuffered POWER ON: " + std::to_string(t / bus::kTicksPerMs) + " ms (" +
         std::to_string(c.rack_power->ram_kb / 1024) + " MB x 8 s; 000 L640)");
  }
  for (const HWatchdogPlan& w : c.watchdogs) {
    devices::HSystemModel* m = m_model.get();
    // The OB counts its executions in its DB on every CPU in RUN (both in Redundant mode).
    auto body = [m, w](bus::Ticks) {
      if (w.db == 0) return;
      for (int r = 0; r < 2; ++r) {
        if (m->pair().state(r) != devices::CpuState::Run) continue;
        const std::span<std::uint8_t> db = m->s7_db(r, w.db);
        if (db.size() < w.offset + w.width) continue;
        for (std::size_t k = w.width; k-- > 0;)
          if (++db[w.offset + k] != 0) break;  // big-endian + 1 with carry
      }
    };
    // Requests at phase + n x cycle (n >= 1) from the start of the run.
    const bus::Ticks at = m_sched.now() + w.phase;
    if (w.phase == 0) m_model->set_watchdog_ob(w.ob, w.cycle, body);
    else m_sched.schedule(at, [m, w, body] { m->set_watchdog_ob(w.ob, w.cycle, body); });
  }
}

std::string HSystemNode::apply_switch(const PlanFault& f) {
  if (!f.cpu_switch) return ": refused (no plan)";
  const HSwitchPlan& s = *f.cpu_switch;
  devices::HSystemModel& m = *m_model;
  const HChangesPlan& c = plan().runtime->changes;
  const int master = m.pair().master();
  // The DBs' 5.2.3 attributes (000 L1239-1269): the standby holds the new configuration, whose
  // changed DBs have another interface time stamp.
  if (master >= 0 && !c.db_blocks.empty()) {
    std::vector<devices::HDbBlock> standby = c.db_blocks;
    for (devices::HDbBlock& b : standby)
      if (std::find(s.changed_db.begin(), s.changed_db.end(), b.number) != s.changed_db.end())
        b.interface_stamp = 2;
    m.set_db_blocks(master, c.db_blocks);
    m.set_db_blocks(1 - master, std::move(standby));
    m_db_blocks_set = true;
  }
  // Added switched modules: OB 83's MDL_ADDR is the module's logical address (its first PII
  // octet, or PIQ octet for an output-only module) in the model's I/O map.
  std::vector<int> added;
  for (const HSwitchPlan::Module& a : s.added)
    for (const devices::HIoEntry& e : m.io_map().entries())
      if (!e.central && e.system == a.system && e.address == a.station && e.module == a.module)
        added.push_back(static_cast<int>(e.in_len > 0 ? e.in_addr : e.out_addr));
  std::string text;
  if (!added.empty()) text += " (added modules at " + list(added) + ")";
  if (!s.changed_db.empty()) text += " (changed DBs " + list(s.changed_db) + ")";
  if (!m.switch_to_cpu(s.variant, s.master, s.standby, added))
    text += ": refused (the reason is in the diagnostic buffers)";
  return text;
}

void HSystemNode::equal_db_blocks() {
  // After a switch_to_cpu both CPUs run the new configuration: a later swap (the switch with
  // nothing changed, 000 L1120) sees the same interface stamps on both sides.
  const HChangesPlan& c = plan().runtime->changes;
  if (!m_db_blocks_set || c.db_blocks.empty()) return;
  for (int r = 0; r < 2; ++r) m_model->set_db_blocks(r, c.db_blocks);
}

void HSystemNode::report_changes(HSystemReport& r) const {
  const devices::HConfigChange* cc = m_model->config_change();
  const std::size_t before = r.io_events.size();
  for (bus::Ticks t : m_model->first_ob1_after_swap()) {
    HIoEvent x;
    x.at = t;
    if (cc != nullptr && cc->new_master() >= 0) x.racks = {cc->new_master()};
    x.ob = 1;
    x.text = "first OB 1 of the new master after the switch-over: OB1_SCAN_1 = B#16#05, its central "
             "outputs 0 for this cycle (000 L1209, L3388)";
    r.io_events.push_back(std::move(x));
  }
  const HChangesPlan& c = plan().runtime->changes;
  if (!c.ob72_updat_po.empty())
    for (bus::Ticks t : m_model->redundancy_returns()) {
      HIoEvent x;
      x.at = t;
      x.racks = {0, 1};
      x.ob = 72;
      x.text = "OB 72 redundancy restored: SFC 27 UPDAT_PO partitions " + list(c.ob72_updat_po) + " (000 L1752)";
      r.io_events.push_back(std::move(x));
    }
  if (r.io_events.size() == before) return;  // an unchanged report otherwise
  std::stable_sort(r.io_events.begin(), r.io_events.end(),
                   [](const HIoEvent& a, const HIoEvent& b) { return a.at < b.at; });
}

}  // namespace pbvbus::tools
