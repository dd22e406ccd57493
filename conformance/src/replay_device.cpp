// The Replayer device (replay.hpp: targets, pacing).

#include <algorithm>

#include "pbvbus/conformance/replay.hpp"
#include "pbvbus/fdl/bus_params.hpp"
#include "pbvbus/fdl/telegram.hpp"

namespace pbvbus::conformance {

namespace {
constexpr std::int64_t kTsyn = fdl::BusParams::kTsyn;
}

const char* replay_pacing_name(ReplayPacing p) {
  return p == ReplayPacing::AsRecorded ? "as-recorded" : "fast";
}

std::vector<std::size_t> replay_plan(const ReplayInput& in, std::optional<std::uint8_t> station) {
  std::vector<std::size_t> plan;
  for (std::size_t i = 0; i < in.frames.size(); ++i) {
    const ReplayFrame& f = in.frames[i];
    if (f.role == ReplayRole::Token) {
      if (!station) plan.push_back(i);
    } else if (f.role == ReplayRole::Request) {
      if (!station || f.da == *station || f.da == fdl::kBroadcast) plan.push_back(i);
    }
  }
  return plan;
}

Replayer::Replayer(const ReplayInput& in, ReplayerOptions opts)
    : m_in(in), m_opts(opts), m_plan(replay_plan(in, opts.station)) {
  m_sent.reserve(m_plan.size());
}

void Replayer::on_power_on(bus::Ticks now) {
  m_powered = true;
  m_sent.clear();
  m_heard.clear();
  m_next = 0;
  m_awaiting = m_finishing = m_finished = false;
  m_slips = 0;
  m_t0 = now + bits(kTsyn);
  m_fast_ready = m_t0;
  m_last_end = now;
  schedule_next(now);
}

void Replayer::on_power_off(bus::Ticks) { m_powered = false; }

bus::Ticks Replayer::desired_time() const {
  if (m_opts.pacing == ReplayPacing::Fast) return m_fast_ready;
  const ReplayFrame& first = m_in.frames[m_plan.front()];
  return m_t0 + (m_in.frames[m_plan[m_next]].start - first.start);
}

void Replayer::schedule_next(bus::Ticks now) {
  if (!m_powered || m_awaiting) return;
  if (m_next >= m_plan.size()) {
    if (!m_finishing && !m_finished) {
      // Room for the last frame's reply: TSL to its start, then the longest frame.
      m_finishing = true;
      m_deadline = std::max(now, m_last_end) + bits(m_in.tsl) +
                   bus::chars_to_ticks(fdl::kMaxFrame, m_in.baud);
      port().set_timer(m_deadline);
    }
    return;
  }
  port().set_timer(std::max({now, desired_time(), m_last_end + bits(kTsyn)}));
}

void Replayer::on_frame(const bus::RxFrame& f) {
  Heard h;
  h.bytes.assign(f.bytes.begin(), f.bytes.end());
  h.start = f.start;
  h.end = f.end;
  h.flags = f.flags;
  m_heard.push_back(std::move(h));
  m_last_end = std::max(m_last_end, f.end);
  if (m_awaiting) {
    m_awaiting = false;
    m_fast_ready = f.end + bits(kTsyn);
  }
  if (m_finishing) {
    m_deadline = std::max(m_deadline, f.end + bits(m_in.tsl));
    port().set_timer(m_deadline);
    return;
  }
  schedule_next(port().now());
}

void Replayer::on_timer(bus::Ticks now) {
  if (!m_powered || m_finished) return;
  if (m_finishing) {
    if (now < m_deadline) return port().set_timer(m_deadline);
    if (port().receiving()) return;  // on_frame extends the deadline
    m_finished = true;
    return;
  }
  if (m_awaiting) {
    if (now < m_deadline) return port().set_timer(m_deadline);
    if (port().receiving()) return;  // a reply that started in time: wait for its end
    m_awaiting = false;
    m_fast_ready = m_deadline + bits(kTsyn);
    return schedule_next(now);
  }
  if (m_next >= m_plan.size()) return schedule_next(now);
  if (port().receiving()) return;  // on_frame reschedules after the frame
  const bus::Ticks want = desired_time();
  const bus::Ticks earliest = std::max(want, m_last_end + bits(kTsyn));
  if (now < earliest) return port().set_timer(earliest);
  const ReplayFrame& f = m_in.frames[m_plan[m_next]];
  port().transmit(now, f.bytes);
  Sent s;
  s.frame = m_plan[m_next];
  s.start = now;
  s.end = now + bus::chars_to_ticks(static_cast<std::int64_t>(f.bytes.size()), m_in.baud);
  s.desired = want;
  m_sent.push_back(s);
  if (m_opts.pacing == ReplayPacing::AsRecorded && now > want) ++m_slips;
  m_last_end = s.end;
  ++m_next;
  if (f.role == ReplayRole::Request && f.expects_reply && m_opts.pacing == ReplayPacing::Fast) {
    m_awaiting = true;
    m_deadline = s.end + bits(m_in.tsl);
    port().set_timer(m_deadline);
    return;
  }
  m_fast_ready = s.end + bits(kTsyn);
  schedule_next(now);
}

}  // namespace pbvbus::conformance
