// The 000 §5.2.3 copy plan (L1239-1269; h_config_change.hpp plan_modified_configuration_copy)
// applied to the model's DBs at a "switch to CPU with modified configuration"
// (docs/h-changes.md "In the H-system model"):
//   - at the request the plan is made from the blocks of set_db_blocks(); an aborted plan (an
//     SFC DB of the master in the standby's load memory, too little standby work memory) refuses
//     the switch like a failed check: the entry in both buffers, the standby stays in STOP
//     (decision: the model has no link-up abort of its own; the outcome is the same);
//   - the standby's memory area is kept aside at the request (it is in STOP: its DBs are the
//     new configuration's start values);
//   - at the update's copy (t4, h_system_update.cpp; the swap follows) the new master's DBs are: "copied" and "created" ones = the old master's
//     contents, "sfb_reset" and "deleted" ones = 0 (instances reset, DB deleted), every other
//     DB = the standby's own (kept aside) contents: 000 L1251 "contents of all the data blocks
//     having the same interface time stamp" are transferred, L1254 SFC DBs reset, L1265 SFB
//     instances returned to their state before the first call; modified DBs keep the values of
//     the new configuration.
#include <algorithm>
#include <cstddef>
#include <span>
#include <stdexcept>
#include <string>
#include <utility>

#include "pbvbus/s7h/h_system.hpp"

namespace pbvbus::devices {

void HSystemModel::set_db_blocks(int rack, std::vector<HDbBlock> blocks) {
  if (!valid_rack(rack)) throw std::out_of_range("rack " + std::to_string(rack) + " (0 or 1)");
  const auto i = static_cast<std::size_t>(rack);
  m_cc_blocks[i] = std::move(blocks);
  m_cc_blocks_set[i] = true;
}

std::span<std::uint8_t> HSystemModel::s7_work_area(int rack) {
  s7_prepare();
  if (m_exec) return m_exec->image(rack).memory();
  return m_s7_work[static_cast<std::size_t>(rack)];
}

std::span<std::uint8_t> HSystemModel::s7_db(int rack, std::uint16_t number) {
  if (!valid_rack(rack)) throw std::out_of_range("rack " + std::to_string(rack) + " (0 or 1)");
  const auto work = s7_work_area(rack);
  for (const auto& d : m_s7_layout.dbs)
    if (d.number == number && d.offset + d.size <= work.size())
      return work.subspan(d.offset, d.size);
  return {};
}

bool HSystemModel::cc_plan_db_copy(const HCpuConfig& standby) {
  m_cc_plan.reset();
  m_cc_standby_mem.clear();
  if (!m_cc_blocks_set[0] || !m_cc_blocks_set[1]) return true;
  const int m = m_pair.master();
  if (m < 0) return true;
  const int s = 1 - m;
  const auto& sb = m_cc_blocks[static_cast<std::size_t>(s)];
  std::uint64_t used = 0;
  for (const auto& b : sb) used += b.kb;
  const auto free_kb = static_cast<std::uint32_t>(
      used >= standby.work_memory_kb ? 0 : standby.work_memory_kb - used);
  auto plan = plan_modified_configuration_copy(m_cc_blocks[static_cast<std::size_t>(m)], sb,
                                               free_kb, diag_buffer(m).size(),
                                               diag_buffer(s).size() + 1);
  if (plan.aborted) {
    const std::string t = "PG/ES: switch to CPU with modified configuration refused: standby "
                          "CPU stays in STOP: " + plan.abort_text + " (000 L1256, L1263)";
    log_entry(0, t);
    log_entry(1, t);
    return false;
  }
  const auto w = s7_work_area(s);
  m_cc_standby_mem.assign(w.begin(), w.end());
  m_cc_plan = std::move(plan);
  return true;
}

void HSystemModel::cc_apply_db_copy(int old_master, int new_master) {
  if (!m_cc_plan || m_cc_standby_mem.empty() || old_master < 0 || new_master < 0 || old_master == new_master) return;
  const auto from = s7_work_area(old_master);
  const auto to = s7_work_area(new_master);
  auto has = [](const std::vector<int>& v, int n) {
    return std::find(v.begin(), v.end(), n) != v.end();
  };
  for (const auto& d : m_s7_layout.dbs) {
    if (d.offset + d.size > to.size() || d.offset + d.size > from.size()) continue;
    const int n = d.number;
    auto dst = to.subspan(d.offset, d.size);
    if (has(m_cc_plan->copied, n) || has(m_cc_plan->created, n)) {
      const auto src = from.subspan(d.offset, d.size);
      std::copy(src.begin(), src.end(), dst.begin());
    } else if (has(m_cc_plan->sfb_reset, n) || has(m_cc_plan->deleted, n)) {
      std::fill(dst.begin(), dst.end(), std::uint8_t{0});
    } else if (d.offset + d.size <= m_cc_standby_mem.size()) {
      std::copy_n(m_cc_standby_mem.begin() + static_cast<std::ptrdiff_t>(d.offset), d.size,
                  dst.begin());
    }
  }
  m_cc_standby_mem.clear();
}

}  // namespace pbvbus::devices
