// The H-system model: SFC 90 H_CTRL from the user program, the watchdog OBs across an update
// (R7) and the S7 jobs held by the update. h_system.hpp's block "SFC 90 H_CTRL ..." has the
// rules, docs/h-sfc90.md the sources.
#include <algorithm>
#include <stdexcept>
#include <vector>

#include "pbvbus/s7h/h_system.hpp"

namespace pbvbus::devices {

// ---- SFC 90 ------------------------------------------------------------------------------

std::uint16_t HSystemModel::h_ctrl(std::uint8_t mode, std::uint8_t submode) {
  const bus::Ticks now = m_sched.now();
  const std::uint16_t rv = devices::h_ctrl(m_pair, m_self_test, mode, submode, now);
  m_hctrl_calls.push_back({now, mode, submode, rv});
  if (m_in_scan)
    m_hctrl_after_scan = true;  // the pair's reaction after this OB 1 (update step 3)
  else
    after_op();
  return rv;
}

void HSystemModel::run_program_h_ctrl(bus::Ticks now) {
  const ProgramSpec* spec = m_exec ? m_s7_spec.get() : nullptr;
  if (spec != m_hctrl_spec) {  // a new program: its calls start afresh
    m_hctrl_spec = spec;
    m_hctrl_done.assign(spec != nullptr ? spec->h_ctrl_calls.size() : 0, false);
  }
  if (spec == nullptr) return;
  for (std::size_t i = 0; i < spec->h_ctrl_calls.size(); ++i) {
    const HCtrlCall& c = spec->h_ctrl_calls[i];
    if (m_hctrl_done[i] || c.at > now) continue;
    m_hctrl_done[i] = true;
    h_ctrl(c.mode, c.submode);
  }
}

void HSystemModel::after_scan_h_ctrl() {
  m_in_scan = false;
  if (!m_hctrl_after_scan) return;
  m_hctrl_after_scan = false;
  after_op();
}

// ---- watchdog OBs ------------------------------------------------------------------------

void HSystemModel::set_watchdog_ob(int ob, bus::Ticks period, std::function<void(bus::Ticks)> body) {
  if (ob < 30 || ob > 38) throw std::invalid_argument("watchdog OB must be OB 30..38");
  if (period <= 0) throw std::invalid_argument("watchdog OB period must be > 0");
  std::size_t i = 0;
  while (i < m_wd.size() && m_wd[i].ob != ob) ++i;
  if (i == m_wd.size()) m_wd.emplace_back();
  WatchdogOb& w = m_wd[i];
  w.ob = ob;
  w.period = period;
  w.body = std::move(body);
  w.lost = false;
  w.next = m_sched.now() + period;
  wd_arm(i);
}

void HSystemModel::wd_arm(std::size_t i) {
  WatchdogOb& w = m_wd[i];
  const std::uint64_t gen = ++w.gen;
  m_sched.schedule(w.next, [this, i, gen] { wd_fire(i, gen); });
}

void HSystemModel::wd_run(WatchdogOb& w, bus::Ticks now, bool after_update) {
  m_wd_runs.push_back({w.ob, now, after_update});
  if (w.body) w.body(now);
}

void HSystemModel::wd_fire(std::size_t i, std::uint64_t gen) {
  WatchdogOb& w = m_wd[i];
  if (w.gen != gen) return;  // re-armed since
  const bus::Ticks now = m_sched.now();
  if (m_pair.interrupts_held())
    w.lost = true;  // step 3: no new request during the update
  else if (program_runs())
    wd_run(w, now, false);
  w.next = now + w.period;
  wd_arm(i);
}

void HSystemModel::sfc90_reconcile(bus::Ticks now) {
  // OB 72 "redundancy restored" on entering Redundant mode (before the OB 1 due then).
  const bool red = m_pair.system_mode() == SystemMode::Redundant;
  if (red && !m_was_redundant) {
    m_returns.push_back(now);
    if (m_ob72_return) m_ob72_return(now);
  }
  m_was_redundant = red;
  if (m_pair.interrupts_held()) return;
  // The update ended (t5 or the abort): at most one request per watchdog OB that lost any,
  // its cycle restarting from here (the clock was stopped: synchronism lost).
  for (std::size_t i = 0; i < m_wd.size(); ++i) {
    WatchdogOb& w = m_wd[i];
    if (!w.lost) continue;
    w.lost = false;
    if (program_runs()) wd_run(w, now, true);
    w.next = now + w.period;
    wd_arm(i);
  }
  // The held S7 jobs, in arrival order (000 L1673-1680: after Redundant, after the swap, or
  // after an abort back in Solo).
  if (m_held_jobs.empty()) return;
  std::vector<HeldJob> jobs;
  jobs.swap(m_held_jobs);
  for (HeldJob& j : jobs) {
    if (s7_find(j.id) == nullptr) {  // released meanwhile: nobody to answer
      std::erase_if(m_sinks, [&](const auto& p) { return p.first == j.id; });
      continue;
    }
    std::vector<std::uint8_t> answer = s7_handle(j.id, j.pdu);
    for (auto& [id, sink] : m_sinks)
      if (id == j.id && sink) sink(std::move(answer));
  }
}

// ---- SFC 27 UPDAT_PO ----------------------------------------------------------------------

std::uint16_t HSystemModel::updat_po(int part) {
  if (part < 1 || part > 15) return 0x8090;  // PART outside the CPU's partitions
  for (std::size_t k = 0; k < m_racks.size(); ++k) {
    if (!rack_reachable(k)) continue;
    const HExpansionRack& cfg = m_rack_cfg[k];
    for (std::size_t m = 0; m < cfg.modules.size(); ++m) {
      if (cfg.modules[m].partition != part) continue;
      const HIoEntry* e = m_map.find_central(cfg.number, m);
      if (e == nullptr || e->out_len == 0 || e->out_addr + e->out_len > m_piq.size()) continue;
      const auto from = m_piq.begin() + static_cast<std::ptrdiff_t>(e->out_addr);
      std::copy(from, from + static_cast<std::ptrdiff_t>(e->out_len), m_racks[k].out[m].begin());
    }
  }
  return 0;
}

// ---- held S7 jobs --------------------------------------------------------------------------

bool HSystemModel::s7_holds(std::uint32_t id) const {
  if (!m_pair.interrupts_held()) return false;
  for (const auto& [sid, sink] : m_sinks)
    if (sid == id && sink) return true;
  return false;
}

bool HSystemModel::s7_hold(std::uint32_t id, std::span<const std::uint8_t> pdu) {
  if (!s7_holds(id)) return false;
  m_held_jobs.push_back({id, std::vector<std::uint8_t>(pdu.begin(), pdu.end())});
  return true;
}

void HSystemModel::s7_set_sink(std::uint32_t id,
                               std::function<void(std::vector<std::uint8_t>)> sink) {
  for (auto& [sid, s] : m_sinks)
    if (sid == id) {
      s = std::move(sink);
      return;
    }
  m_sinks.emplace_back(id, std::move(sink));
}

void HS7Session::on_late_answer(std::function<void(std::vector<std::uint8_t>)> sink) {
  if (m_model != nullptr) m_model->s7_set_sink(m_id, std::move(sink));
}

bool HS7Session::holds_jobs_now() const {
  return alive() && m_model->s7_holds(m_id);  // alive(): s7_handle stores only then
}

}  // namespace pbvbus::devices
