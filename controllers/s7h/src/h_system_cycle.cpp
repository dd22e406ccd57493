// OB 80 of the H-system model: the cycle monitoring (maximum cycle time), the cycle_overload
// fault and the update's exemption by the "max scan-cycle extension" H parameter. h_system.hpp
// (block "F8 expansion racks, OB 80") has the decisions.
#include <cstdio>
#include <stdexcept>

#include "pbvbus/s7h/h_system.hpp"

namespace pbvbus::devices {

namespace {

std::string ms_text(bus::Ticks t) {
  char buf[32];
  if (t % bus::kTicksPerMs == 0)
    std::snprintf(buf, sizeof buf, "%lld ms", static_cast<long long>(t / bus::kTicksPerMs));
  else
    std::snprintf(buf, sizeof buf, "%.3f ms",
                  static_cast<double>(t) / static_cast<double>(bus::kTicksPerMs));
  return buf;
}

}  // namespace

void HSystemModel::set_max_cycle_time(bus::Ticks t) {
  if (t <= 0) throw std::invalid_argument("max cycle time must be longer than 0");
  m_max_cycle = t;
}

bool HSystemModel::cycle_overload(bus::Ticks extra) {
  if (extra <= 0) return false;
  m_pending_extra += extra;
  return true;
}

bus::Ticks HSystemModel::end_cycle(bus::Ticks start) {
  // Called at every OB 1 instant (also one the I/O gate skipped: the cycle restarts anyway).
  bus::Ticks extra = 0;
  if (m_last_scan == start) {  // an OB 1 ran now: it takes the pending overload
    extra = m_pending_extra;
    m_pending_extra = 0;
  }
  m_cycle_start = start;
  m_cycle_next = start + m_scan_time + extra;
  m_sched.schedule(start + m_max_cycle, [this, start] { cycle_check(start, false); });
  return m_cycle_next;
}

void HSystemModel::cycle_check(bus::Ticks start, bool extended) {
  // A new OB 1 started (the cycle ended in time), or no program runs (no cycle to monitor).
  if (m_cycle_start != start || !has_program() || !program_runs()) return;
  if (!extended) {
    const bool update = m_pair.interrupts_held() ||
                        (!m_measures.empty() && m_measures.back().t1 >= start);
    if (update) {
      // Digest §3.1: during the update the normal cycle monitoring is suspended; the max
      // scan-cycle extension bounds the cycle instead (the pair's F19 timeout bounds the update).
      const auto& ext = m_pair.params().h_parameters.max_cycle_extension;
      if (!ext || *ext <= 0) return;  // not configured: this cycle is not monitored
      m_sched.schedule(start + m_max_cycle + to_ticks(*ext), [this, start] { cycle_check(start, true); });
      return;
    }
  }
  const bus::Ticks now = m_sched.now();
  // The planned OB 1 is due at this very instant: the cycle lasted exactly the maximum.
  if (!extended && m_cycle_next == now) return;
  ++m_ob80;
  const std::string text = "OB 80 W#16#3501 cycle time exceeded: OB 1 started at " +
                           ms_text(start) + ", max cycle time " + ms_text(m_max_cycle) +
                           (extended ? " + max scan-cycle extension (update)" : "");
  log_on_powered(now, kOb80CycleTime, text);
  const bool run0 = m_pair.dp_master_operate(0), run1 = m_pair.dp_master_operate(1);
  HSystemEvent h;
  h.time = now;
  h.original_time = now;
  h.rack = run0 && run1 ? -1 : (run0 ? 0 : 1);
  h.role = h.rack < 0 ? CpuRole::Master : m_pair.role(h.rack);
  h.ob = 80;
  h.code = kOb80CycleTime;
  h.text = text;
  h.source = HSystemEvent::Source::Program;
  add_event(std::move(h));
}

}  // namespace pbvbus::devices
