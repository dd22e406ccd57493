#pragma once
// The paced driver (design.md "Time": fast and paced drivers; "Doors to the outside").
//
// A PacedRunner runs a Scheduler so that virtual time follows std::chrono::steady_clock, scaled
// by an integer speed ratio num/den (1/1 = real time, 1/10 = ten times slower, 10/1 = ten times
// faster). It owns a Boost.Asio io_context on which the doors (pseudo-terminals, sockets)
// register their I/O; everything — scheduler events, door handlers, posted inputs — runs on the
// thread that calls run_for()/run_until(), so devices and stacks never see a second thread.
//
// What is guaranteed, and what is not:
//  - Events run in virtual-time order, exactly as in the fast driver (same queue, FIFO at equal
//    ticks). Given the same external inputs at the same virtual times, a paced run is identical
//    to a fast run.
//  - No event runs early: an event due at virtual time v runs when the wall clock has reached
//    the wall time of v (anchor + v scaled), never before.
//  - Events can run late. A timer wakes the loop with some microseconds of latency, and at high
//    baud rates a single bit time (83 ns at 12 Mbit/s) is far below what any software timer or
//    scheduler can keep, so a paced run does NOT reproduce bit timing in wall time: a station's
//    reply that is due 11 bit times after a request is due ~1 us later in wall time and will be
//    processed in the same wake-up batch. Virtual timestamps (captures, reports) stay exact;
//    only their relation to the wall clock is approximate. report().max_lag says how late the
//    worst wake-up was.
//  - Virtual time stays anchored to the wall clock: after falling behind (a slow batch, a
//    stalled machine) the runner catches up by running the due events back to back, so virtual
//    time does not drift. With set_max_lag(d), a lag beyond d instead moves the anchor (virtual
//    time "slips", as after a debugger pause); slips are counted in the report.
//  - External inputs (post()) are thread-safe. An input enters at the virtual time that
//    corresponds to the wall time at which it was posted (or at the scheduler's current time if
//    that has already passed), so inputs posted by one thread run in their post order, at
//    non-decreasing virtual times. Inputs posted while no run is active run at the start of
//    the next run.

#include <chrono>
#include <cstdint>
#include <deque>
#include <functional>
#include <memory>
#include <mutex>

#include "pbvbus/bus/scheduler.hpp"
#include "pbvbus/bus/time.hpp"

namespace boost::asio {
class io_context;
}

namespace pbvbus::bus {

/// The fast driver: runs as fast as the CPU allows until `until` (tests, benchmarks, offline
/// scenarios). Spelled out for symmetry with PacedRunner.
inline void run_fast(Scheduler& sched, Ticks until) { sched.run_until(until); }

/// Speed of virtual time relative to wall time, as an exact fraction.
struct Speed {
  std::uint32_t num = 1;
  std::uint32_t den = 1;
};

/// How well the last run kept pace.
struct PacedReport {
  Ticks virtual_elapsed = 0;                 ///< virtual time covered by the run
  std::chrono::nanoseconds wall_elapsed{0};  ///< wall time the run took
  /// Worst delay between the wall time an event was due and the wall time it ran.
  std::chrono::nanoseconds max_lag{0};
  std::uint64_t wakeups = 0;       ///< loop iterations that ran scheduler events
  std::uint64_t late_wakeups = 0;  ///< of those, how many were more than 1 ms late
  std::uint64_t inputs = 0;        ///< posted inputs run
  std::uint64_t slips = 0;         ///< re-anchorings after a lag beyond max_lag
  std::chrono::nanoseconds slipped{0};  ///< total wall time given up by slips
};

class PacedRunner {
 public:
  using Clock = std::chrono::steady_clock;
  using Input = std::function<void(Ticks now)>;

  explicit PacedRunner(Scheduler& sched, Speed speed = {});
  ~PacedRunner();
  PacedRunner(const PacedRunner&) = delete;
  PacedRunner& operator=(const PacedRunner&) = delete;

  Scheduler& scheduler() { return m_sched; }
  /// Doors register their descriptors and sockets here; their handlers run inside run_*().
  boost::asio::io_context& io_context() { return *m_io; }

  /// Changes the speed; takes effect at the next run. Throws std::invalid_argument for 0.
  void set_speed(Speed s);
  Speed speed() const { return m_speed; }
  /// A lag beyond `d` re-anchors virtual time instead of catching up; zero (default) = never.
  void set_max_lag(std::chrono::nanoseconds d) { m_max_lag = d; }

  /// Thread-safe. Runs `fn(now)` on the runner's thread at the virtual time matching the wall
  /// clock now (see the header comment).
  void post(Input fn);

  /// Runs until virtual time has advanced by `d` (or stop()). Returns early only on stop().
  void run_for(Ticks d);
  /// Runs until virtual time `t` (or stop()). Blocks the calling thread, which becomes the
  /// runner's thread for the duration.
  void run_until(Ticks t);
  /// Thread-safe: makes the current run return soon. From inside an event, the run returns
  /// after that event; from another thread, after virtual time has caught up with the wall
  /// clock (events and inputs already due still run). A stop requested while no run is active
  /// makes the next run return at once.
  void stop();
  bool running() const;

  /// Thread-safe: the virtual time the wall clock corresponds to now (during a run), else the
  /// scheduler's time when the last run ended.
  Ticks virtual_now() const;

  /// Statistics of the current or last run (read it from the runner's thread or after a run).
  const PacedReport& report() const { return m_report; }

 private:
  struct Pending {
    bool anchored;  // false: posted outside a run, enters at the run's start
    Ticks at;
    Input fn;
  };
  class FnEvent;

  void service();  // one loop iteration: inputs in, events up to the wall clock, re-arm
  void arm(Ticks next);
  Ticks virtual_at_locked(Clock::time_point w) const;
  Clock::time_point wall_at_locked(Ticks v) const;

  Scheduler& m_sched;
  std::unique_ptr<boost::asio::io_context> m_io;
  struct Timer;
  std::unique_ptr<Timer> m_timer;
  Speed m_speed;
  std::chrono::nanoseconds m_max_lag{0};

  mutable std::mutex m_mutex;  // guards everything below until m_report
  std::deque<Pending> m_inputs;
  bool m_wake_posted = false;
  bool m_running = false;
  bool m_stop = false;
  Clock::time_point m_wall0{};
  Ticks m_virt0 = 0;
  Ticks m_until = 0;
  Ticks m_last_now = 0;

  PacedReport m_report;
  Clock::time_point m_run_started{};
  bool m_done = false;
};

}  // namespace pbvbus::bus
