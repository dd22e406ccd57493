#include "pbvbus/bus/scheduler.hpp"

#include <algorithm>
#include <cassert>

namespace pbvbus::bus {

// The queue is a 4-ary min-heap on (when, seq) in m_heap: half the depth of a binary heap, and
// the four children of a node share a cache line or two. (when, seq) is a total order, so the
// order in which events run is the same as with any other correct priority queue.
namespace {
constexpr std::size_t kArity = 4;
/// (when, seq) as one unsigned 128-bit number with the same order (when's sign bit flipped), so
/// that choosing the earliest of four children is a chain of plain compares the compiler can
/// make branch-free: with thousands of pending timers (a plant of many lines) the sift-down is
/// a third of all instructions, and its data-dependent branches are hard to predict.
__extension__ using Key = unsigned __int128;
template <class E>
Key key_of(const E& e) {
  return (static_cast<Key>(static_cast<std::uint64_t>(e.when) ^ (std::uint64_t{1} << 63)) << 64) |
         e.seq;
}
}  // namespace

void Scheduler::schedule(Ticks when, EventTarget& target, std::uint64_t tag) {
  if (when < m_now) when = m_now;
  // The new entry has the highest sequence number, so it goes before a parent only if it is
  // due strictly earlier.
  std::size_t i = m_heap.size();
  m_heap.emplace_back();
  Entry* h = m_heap.data();
  while (i > 0) {
    const std::size_t parent = (i - 1) / kArity;
    if (h[parent].when <= when) break;
    h[i] = h[parent];
    i = parent;
  }
  h[i] = Entry{when, m_seq++, &target, tag};
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
  Entry* h = m_heap.data();
  const Entry e = h[0];
  if (const std::size_t n = m_heap.size() - 1; n > 0) {
    // Sift the last entry down from the root (over the first n entries).
    const Entry last = h[n];
    const Key last_key = key_of(last);
    std::size_t i = 0;
    for (;;) {
      const std::size_t first = i * kArity + 1;
      if (first >= n) break;
      std::size_t best = first;
      Key best_key = key_of(h[first]);
      const std::size_t end = std::min(first + kArity, n);
      for (std::size_t c = first + 1; c < end; ++c) {
        const Key k = key_of(h[c]);
        const bool earlier = k < best_key;
        best_key = earlier ? k : best_key;
        best = earlier ? c : best;
      }
      if (last_key < best_key) break;
      h[i] = h[best];
      i = best;
    }
    h[i] = last;
  }
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
