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

// Inlined into its callers in this file (its only users).
[[gnu::always_inline]] inline void Scheduler::push_heap(const Entry& e) {
  // The new entry has the highest sequence number, so it goes before a parent only if it is
  // due strictly earlier.
  std::size_t i = m_heap.size();
  m_heap.push_back(e);
  Entry* h = m_heap.data();
  if (i > 0 && h[(i - 1) / kArity].when > e.when) {
    do {
      const std::size_t parent = (i - 1) / kArity;
      if (h[parent].when <= e.when) break;
      place(h, i, h[parent]);
      i = parent;
    } while (i > 0);
    h[i] = e;
  }
  if (e.slot) e.slot->m_pos = i;
}

// flatten: the vector's push_back fast path inlined too (it is most of the cost of a call).
[[gnu::flatten]] void Scheduler::schedule(Ticks when, EventTarget& target, std::uint64_t tag) {
  if (when <= m_now) {
    // Due now: after everything queued so far at this tick, which a FIFO keeps in order.
    m_fifo.push_back(Entry{m_now, m_seq++, &target, tag, nullptr});
    return;
  }
  push_heap(Entry{when, m_seq++, &target, tag, nullptr});
}

void Scheduler::sift_up(std::size_t i, const Entry& e) {
  // Goes before a parent only if due earlier, or at the same tick but scheduled first.
  Entry* h = m_heap.data();
  const Key k = key_of(e);
  while (i > 0) {
    const std::size_t parent = (i - 1) / kArity;
    if (key_of(h[parent]) < k) break;
    place(h, i, h[parent]);
    i = parent;
  }
  place(h, i, e);
}

void Scheduler::sift_down(std::size_t i, const Entry& e, std::size_t n) {
  // Sift `e` down from the hole at `i` over the first n entries.
  Entry* h = m_heap.data();
  const Key k = key_of(e);
  for (;;) {
    const std::size_t first = i * kArity + 1;
    if (first >= n) break;
    std::size_t best = first;
    Key best_key = key_of(h[first]);
    const std::size_t end = std::min(first + kArity, n);
    for (std::size_t c = first + 1; c < end; ++c) {
      const Key ck = key_of(h[c]);
      const bool earlier = ck < best_key;
      best_key = earlier ? ck : best_key;
      best = earlier ? c : best;
    }
    if (k < best_key) break;
    place(h, i, h[best]);
    i = best;
  }
  place(h, i, e);
}

void Scheduler::remove_at(std::size_t i) {
  const std::size_t n = m_heap.size() - 1;
  if (i != n) {
    const Entry last = m_heap[n];
    // The last entry fills the hole: up if it is earlier than the hole's parent, else down.
    if (i > 0 && key_of(last) < key_of(m_heap[(i - 1) / kArity]))
      sift_up(i, last);
    else
      sift_down(i, last, n);
  }
  m_heap.pop_back();
}

[[gnu::flatten]] void Scheduler::schedule(TimerSlot& slot, Ticks when, EventTarget& target,
                                          std::uint64_t tag) {
  if (when < m_now) when = m_now;
  const Entry e{when, m_seq++, &target, tag, &slot};
  if (!slot.queued()) {
    push_heap(e);
    return;
  }
  // Move the queued entry: the same as withdrawing it and scheduling anew. Earlier: up (it has
  // the highest sequence number, so only strictly earlier parents stay above it); else down.
  std::size_t i = slot.m_pos;
  Entry* h = m_heap.data();
  if (e.when < h[i].when) {
    while (i > 0) {
      const std::size_t parent = (i - 1) / kArity;
      if (h[parent].when <= e.when) break;
      place(h, i, h[parent]);
      i = parent;
    }
    place(h, i, e);
  } else {
    sift_down(i, e, m_heap.size());
  }
}

void Scheduler::cancel(TimerSlot& slot) {
  if (!slot.queued()) return;
  const std::size_t i = slot.m_pos;
  slot.m_pos = TimerSlot::kNone;
  remove_at(i);
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

// Inlined into both callers: run_until's loop pays no call per event for the queue itself.
[[gnu::always_inline]] inline bool Scheduler::pop_due(Ticks until, Entry& e) {
  if (m_fifo_head != m_fifo.size() &&
      (m_heap.empty() || m_fifo[m_fifo_head].when < m_heap.front().when ||
       (m_fifo[m_fifo_head].when == m_heap.front().when &&
        m_fifo[m_fifo_head].seq < m_heap.front().seq))) {
    if (m_fifo[m_fifo_head].when > until) return false;
    e = m_fifo[m_fifo_head];
    if (++m_fifo_head == m_fifo.size()) {
      m_fifo.clear();
      m_fifo_head = 0;
    }
    return true;
  }
  if (m_heap.empty() || m_heap.front().when > until) return false;
  Entry* h = m_heap.data();
  e = h[0];
  if (e.slot) e.slot->m_pos = TimerSlot::kNone;
  const std::size_t n = m_heap.size() - 1;
  if (n == 1)
    place(h, 0, h[1]);
  else if (n > 1)
    sift_down(0, h[n], n);
  m_heap.pop_back();
  return true;
}

bool Scheduler::step() {
  Entry e;
  if (!pop_due(kNever, e)) return false;
  m_now = e.when;
  ++m_events_run;
  e.target->on_event(e.when, e.tag);
  return true;
}

void Scheduler::run_until(Ticks until) {
  // The same as calling step() while next_time() <= until.
  m_stop = false;
  Entry e;
  while (pop_due(until, e)) {
    m_now = e.when;
    ++m_events_run;
    e.target->on_event(e.when, e.tag);
    if (m_stop) return;
  }
  if (until > m_now) m_now = until;
}

void Scheduler::advance_to(Ticks t) {
  assert(t <= next_time());
  if (t > m_now) m_now = t;
}

}  // namespace pbvbus::bus
