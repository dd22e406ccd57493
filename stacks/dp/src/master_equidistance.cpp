// DP master equidistance: the constant bus cycle time T_DP (docs/dp-equidistance.md; the
// structure of the equidistant cycle after the PROFIBUS guideline: global control, cyclic data,
// acyclic services, token, then the pause up to the next cycle).
#include "pbvbus/dp/master.hpp"

#include <algorithm>

namespace pbvbus::dp {

bool Master::equidistant_start(bus::Ticks now) {
  const bus::Ticks period = m_p.equidistant_cycle;
  bool late = false;
  if (m_eq_due == bus::kNever) {
    m_eq_due = now;  // grid origin: the first pass
  } else if (now < m_eq_due) {
    return false;
  } else if (now > m_eq_due) {
    late = true;
    const bus::Ticks lateness = now - m_eq_due;
    ++m_eq.overruns;
    m_eq.max_lateness = std::max(m_eq.max_lateness, lateness);
    m_eq.last_lateness = lateness;
    const auto skipped = static_cast<std::uint64_t>(lateness / period);
    m_eq.missed += skipped;
    m_eq_due += static_cast<bus::Ticks>(skipped) * period;  // the last due time passed
  }
  // Jitter: intervals between two consecutive on-time starts.
  if (!late && !m_eq_last_late && m_eq.last_start != bus::kNever) {
    const bus::Ticks dt = now - m_eq.last_start;
    m_eq.interval_min = m_eq.intervals == 0 ? dt : std::min(m_eq.interval_min, dt);
    m_eq.interval_max = m_eq.intervals == 0 ? dt : std::max(m_eq.interval_max, dt);
    ++m_eq.intervals;
    m_eq.jitter = m_eq.interval_max - m_eq.interval_min;
  }
  m_eq_last_late = late;
  m_eq.last_start = now;
  ++m_eq.cycles;
  m_eq_due += period;
  start_pass();
  return true;
}

bus::Ticks Master::pause_until(bus::Ticks now) {
  if (m_p.equidistant_cycle <= 0 || m_pass_active || m_standby || m_eq_due == bus::kNever)
    return 0;
  if (m_mode != MasterMode::Clear && m_mode != MasterMode::Operate) return 0;
  return m_eq_due > now ? m_eq_due : 0;
}

}  // namespace pbvbus::dp
