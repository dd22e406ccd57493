#pragma once
// Discrete-event scheduler on virtual ticks (design.md "Time").
//
// Events at the same tick run in the order they were scheduled, so a run is a pure function of
// its inputs. There is no cancel: owners that may change their mind keep a generation counter
// in the tag and ignore stale events, which keeps the queue a plain (4-ary) heap.

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
  /// Convenience for rare events (scenario actions, faults); slower than EventTarget.
  void schedule(Ticks when, std::function<void()> fn);

  /// Time of the earliest pending event, or kNever.
  Ticks next_time() const { return m_heap.empty() ? kNever : m_heap.front().when; }
  bool empty() const { return m_heap.empty(); }
  std::size_t pending() const { return m_heap.size(); }

  /// Runs the earliest event. Returns false if there was none.
  bool step();
  /// Runs every event with time <= `until`, then advances now to `until` (unless stopped).
  void run_until(Ticks until);
  /// Makes a running run_until() return after the current event.
  void stop() { m_stop = true; }
  /// Advances the clock without running anything; `t` must not pass a pending event.
  void advance_to(Ticks t);

  std::uint64_t events_run() const { return m_events_run; }

 private:
  struct Entry {
    Ticks when;
    std::uint64_t seq;
    EventTarget* target;
    std::uint64_t tag;
  };
  struct Later {
    bool operator()(const Entry& a, const Entry& b) const {
      return a.when != b.when ? a.when > b.when : a.seq > b.seq;
    }
  };
  class FnTarget final : public EventTarget {
   public:
    explicit FnTarget(Scheduler& s) : m_s(s) {}
    void on_event(Ticks now, std::uint64_t tag) override;

   private:
    Scheduler& m_s;
  };

  std::vector<Entry> m_heap;
  std::vector<std::function<void()>> m_fns;
  std::vector<std::uint32_t> m_free_fns;
  FnTarget m_fn_target{*this};
  Ticks m_now = 0;
  std::uint64_t m_seq = 0;
  std::uint64_t m_events_run = 0;
  bool m_stop = false;
};

}  // namespace pbvbus::bus
