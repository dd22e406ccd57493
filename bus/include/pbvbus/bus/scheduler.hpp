#pragma once
// Discrete-event scheduler on virtual ticks (design.md "Time").
//
// Events at the same tick run in the order they were scheduled, so a run is a pure function of
// its inputs. Two queues keep that order between them: events due at the current tick (the
// usual "answer at once") go to a FIFO, later ones to a 4-ary heap on (when, seq); step() takes
// whichever of the two fronts is earlier in (when, seq), so the order is the one a single
// queue would give. A re-armable timer (TimerSlot) keeps at most one entry in the heap:
// arming it again moves that entry instead of leaving a superseded one behind (which would
// run as a no-op event later). Owners may still keep a generation counter in the tag for
// entries they cannot withdraw (plain schedule()).

#include <cstdint>
#include <functional>
#include <limits>
#include <vector>

#include "pbvbus/bus/time.hpp"

namespace pbvbus::bus {

inline constexpr Ticks kNever = std::numeric_limits<Ticks>::max();

/// Something the scheduler can call back. `tag` is the owner's own value from schedule().
class EventTarget {
 public:
  virtual void on_event(Ticks now, std::uint64_t tag) = 0;

 protected:
  ~EventTarget() = default;
};

class Scheduler {
 public:
  Scheduler() = default;
  Scheduler(const Scheduler&) = delete;
  Scheduler& operator=(const Scheduler&) = delete;

  Ticks now() const { return m_now; }

  /// Calls target.on_event(when, tag) at `when` (clamped to now if in the past).
  void schedule(Ticks when, EventTarget& target, std::uint64_t tag = 0);

  /// Where a re-armable timer's one queued entry sits (owned by the timer's owner, which must
  /// outlive the entry or withdraw it with cancel()).
  class TimerSlot {
   public:
    TimerSlot() = default;
    TimerSlot(const TimerSlot&) = delete;
    TimerSlot& operator=(const TimerSlot&) = delete;
    bool queued() const { return m_pos != kNone; }

   private:
    friend class Scheduler;
    static constexpr std::size_t kNone = static_cast<std::size_t>(-1);
    std::size_t m_pos = kNone;
  };
  /// schedule() for a re-armable timer: the entry queued earlier through `slot` (if it has not
  /// run yet) is withdrawn, as if it had never been scheduled; the new one is ordered as a
  /// fresh schedule() call would be (a new sequence number).
  void schedule(TimerSlot& slot, Ticks when, EventTarget& target, std::uint64_t tag = 0);
  /// Withdraws the entry queued through `slot`, if any.
  void cancel(TimerSlot& slot);
  /// Convenience for rare events (scenario actions, faults); slower than EventTarget.
  void schedule(Ticks when, std::function<void()> fn);

  /// Time of the earliest pending event, or kNever.
  Ticks next_time() const {
    if (m_fifo_head != m_fifo.size()) return m_fifo[m_fifo_head].when;  // due now: earliest
    return m_heap.empty() ? kNever : m_heap.front().when;
  }
  bool empty() const { return m_heap.empty() && m_fifo_head == m_fifo.size(); }
  std::size_t pending() const { return m_heap.size() + (m_fifo.size() - m_fifo_head); }

  /// Runs the earliest event. Returns false if there was none.
  bool step();
  /// Runs every event with time <= `until`, then advances now to `until` (unless stopped).
  void run_until(Ticks until);
  /// Makes a running run_until() return after the current event.
  void stop() { m_stop = true; }
  /// Advances the clock without running anything; `t` must not pass a pending event.
  void advance_to(Ticks t);

  /// Events run so far (withdrawn timer entries never run and are not counted).
  std::uint64_t events_run() const { return m_events_run; }

 private:
  struct Entry {
    Ticks when;
    std::uint64_t seq;
    EventTarget* target;
    std::uint64_t tag;
    TimerSlot* slot;  ///< the re-armable timer this entry belongs to (heap only), or nullptr
  };
  /// Puts `e` at heap position `i` (the hole), keeping its slot's position current.
  static void place(Entry* h, std::size_t i, const Entry& e) {
    h[i] = e;
    if (e.slot) e.slot->m_pos = i;
  }
  void push_heap(const Entry& e);
  void sift_up(std::size_t i, const Entry& e);
  void sift_down(std::size_t i, const Entry& e, std::size_t n);
  /// Removes the heap entry at `i`.
  void remove_at(std::size_t i);
  /// Takes the earliest pending entry (FIFO or heap, by (when, seq)) into `e` if it is due by
  /// `until`; false (nothing taken) otherwise.
  bool pop_due(Ticks until, Entry& e);
  class FnTarget final : public EventTarget {
   public:
    explicit FnTarget(Scheduler& s) : m_s(s) {}
    void on_event(Ticks now, std::uint64_t tag) override;

   private:
    Scheduler& m_s;
  };

  std::vector<Entry> m_heap;
  /// Events due at the tick they were scheduled at, in order of scheduling (sorted by (when,
  /// seq): the clock never goes back). m_fifo[m_fifo_head..] are pending.
  std::vector<Entry> m_fifo;
  std::size_t m_fifo_head = 0;
  std::vector<std::function<void()>> m_fns;
  std::vector<std::uint32_t> m_free_fns;
  FnTarget m_fn_target{*this};
  Ticks m_now = 0;
  std::uint64_t m_seq = 0;
  std::uint64_t m_events_run = 0;
  bool m_stop = false;
};

}  // namespace pbvbus::bus
