#include "pbvbus/bus/scheduler.hpp"

#include <algorithm>
#include <cassert>

namespace pbvbus::bus {

void Scheduler::schedule(Ticks when, EventTarget& target, std::uint64_t tag) {
  if (when < m_now) when = m_now;
  m_heap.push_back(Entry{when, m_seq++, &target, tag});
  std::push_heap(m_heap.begin(), m_heap.end(), Later{});
}

void Scheduler::schedule(Ticks when, std::function<void()> fn) {
  std::uint32_t slot;
  if (!m_free_fns.empty()) {
    slot = m_free_fns.back();
    m_free_fns.pop_back();
    m_fns[slot] = std::move(fn);
  } else {
    slot = static_cast<std::uint32_t>(m_fns.size());
    m_fns.push_back(std::move(fn));
  }
  schedule(when, m_fn_target, slot);
}

void Scheduler::FnTarget::on_event(Ticks, std::uint64_t tag) {
  // Move out first: the function may schedule more functions and reuse the slot vector.
  auto fn = std::move(m_s.m_fns[tag]);
  m_s.m_fns[tag] = nullptr;
  m_s.m_free_fns.push_back(static_cast<std::uint32_t>(tag));
  if (fn) fn();
}

bool Scheduler::step() {
  if (m_heap.empty()) return false;
  std::pop_heap(m_heap.begin(), m_heap.end(), Later{});
  Entry e = m_heap.back();
  m_heap.pop_back();
  m_now = e.when;
  ++m_events_run;
  e.target->on_event(e.when, e.tag);
  return true;
}

void Scheduler::run_until(Ticks until) {
  m_stop = false;
  while (!m_heap.empty() && m_heap.front().when <= until) {
    step();
    if (m_stop) return;
  }
  if (until > m_now) m_now = until;
}

void Scheduler::advance_to(Ticks t) {
  assert(m_heap.empty() || t <= m_heap.front().when);
  if (t > m_now) m_now = t;
}

}  // namespace pbvbus::bus
