// The update phases of the CPU pair acting on the H-system's I/O (h_system.hpp has the
// decisions, docs/h-system.md "Update phases on the I/O" the reasons): the measures and the
// update's copy of the images at t4.
#include "pbvbus/s7h/h_system.hpp"

namespace pbvbus::devices {

void HSystemModel::track_update(bus::Ticks now) {
  const auto w = m_pair.update_window();
  if (!w) return;
  if (m_measures.empty() || m_measures.back().t1 != w->t1) {
    UpdateMeasure m;
    m.t1 = w->t1;
    for (int r = 0; r < 2; ++r)
      if (m_pair.state(r) == CpuState::Update) m.standby = r;
    m.last_scan_before = m_last_scan;
    m_measures.push_back(m);
    m_update_copied = false;
  }
  UpdateMeasure& m = m_measures.back();
  if (m.done) return;
  m.t3 = w->t3;
  m.t4 = w->t4;
  m.t5 = w->t5;
  m.aborted = w->aborted;
  const bool running = m_pair.interrupts_held();  // [t1, t5) of the running update
  if (!m.aborted && now >= w->t4 && !m_update_copied && m.standby >= 0) {
    // t4: the output copy. The update copies the images and the program's memory (digest §4
    // step 9), so both CPUs start T_PH with the same PIQ: both drive the same outputs.
    m_update_copied = true;
    m.standby_operate_from = now;
    if (m_exec) m_exec->copy_state(1 - m.standby, m.standby);
    s7_copy_update(1 - m.standby, m.standby);  // counters, timers (and M/DBs without a spec)
    cc_apply_db_copy(1 - m.standby, m.standby);  // 000 §5.2.3 (h_system_db_copy.cpp)
  }
  if (!running) m.done = true;
}

}  // namespace pbvbus::devices
