#include "pbvbus/bus/paced_runner.hpp"

#include <algorithm>
#include <atomic>
#include <boost/asio/io_context.hpp>
#include <boost/asio/post.hpp>
#include <boost/asio/steady_timer.hpp>
#include <stdexcept>
#include <thread>

namespace pbvbus::bus {

namespace {
__extension__ typedef __int128 Wide128;
constexpr auto kLateThreshold = std::chrono::milliseconds(1);
}  // namespace

struct PacedRunner::Timer {
  explicit Timer(boost::asio::io_context& io) : timer(io) {}
  boost::asio::steady_timer timer;
  std::atomic<std::thread::id> runner_thread{};
};

PacedRunner::PacedRunner(Scheduler& sched, Speed speed)
    : m_sched(sched), m_io(std::make_unique<boost::asio::io_context>(1)),
      m_timer(std::make_unique<Timer>(*m_io)) {
  set_speed(speed);
  m_last_now = sched.now();
}

PacedRunner::~PacedRunner() = default;

void PacedRunner::set_speed(Speed s) {
  if (s.num == 0 || s.den == 0) throw std::invalid_argument("PacedRunner: speed must be a positive fraction");
  std::lock_guard lock(m_mutex);
  m_speed = s;
}

// Virtual ticks elapsed for a wall duration: ns * 3.636 * num / den, rounded down, so that the
// runner never runs an event before its wall time.
Ticks PacedRunner::virtual_at_locked(Clock::time_point w) const {
  const auto ns = std::chrono::duration_cast<std::chrono::nanoseconds>(w - m_wall0).count();
  if (ns <= 0) return m_virt0;
  const Wide128 t = static_cast<Wide128>(ns) * 3636 * m_speed.num / (static_cast<Wide128>(1000) * m_speed.den);
  const Wide128 v = static_cast<Wide128>(m_virt0) + t;
  return v > static_cast<Wide128>(kNever / 2) ? kNever / 2 : static_cast<Ticks>(v);
}

// Wall time of a virtual time, rounded up (the inverse of the above).
PacedRunner::Clock::time_point PacedRunner::wall_at_locked(Ticks v) const {
  if (v <= m_virt0) return m_wall0;
  const Wide128 num = static_cast<Wide128>(v - m_virt0) * 1000 * m_speed.den;
  const Wide128 den = static_cast<Wide128>(3636) * m_speed.num;
  Wide128 ns = (num + den - 1) / den;
  constexpr Wide128 kMaxNs = static_cast<Wide128>(365) * 24 * 3600 * 1'000'000'000LL;  // a year is "never"
  if (ns > kMaxNs) ns = kMaxNs;
  return m_wall0 + std::chrono::nanoseconds(static_cast<std::int64_t>(ns));
}

void PacedRunner::post(Input fn) {
  bool wake = false;
  {
    std::lock_guard lock(m_mutex);
    Pending p{m_running, 0, std::move(fn)};
    if (m_running) p.at = std::min(virtual_at_locked(Clock::now()), m_until);
    m_inputs.push_back(std::move(p));
    if (m_running && !m_wake_posted) wake = m_wake_posted = true;
  }
  if (wake) boost::asio::post(*m_io, [this] { service(); });
}

void PacedRunner::stop() {
  bool wake = false;
  {
    std::lock_guard lock(m_mutex);
    m_stop = true;
    if (m_running && !m_wake_posted) wake = m_wake_posted = true;
  }
  // From inside an event: end the batch now rather than at its end.
  if (std::this_thread::get_id() == m_timer->runner_thread) m_sched.stop();
  if (wake) boost::asio::post(*m_io, [this] { service(); });
}

bool PacedRunner::running() const {
  std::lock_guard lock(m_mutex);
  return m_running;
}

Ticks PacedRunner::virtual_now() const {
  std::lock_guard lock(m_mutex);
  if (!m_running) return m_last_now;
  return std::min(virtual_at_locked(Clock::now()), m_until);
}

void PacedRunner::run_for(Ticks d) { run_until(m_sched.now() + std::max<Ticks>(d, 0)); }

void PacedRunner::run_until(Ticks t) {
  {
    std::lock_guard lock(m_mutex);
    if (m_running) throw std::logic_error("PacedRunner: run_until() while already running");
    if (m_stop) {  // a stop that arrived between runs
      m_stop = false;
      return;
    }
    m_running = true;
    m_until = std::max(t, m_sched.now());
    m_virt0 = m_sched.now();
    m_wall0 = Clock::now();
    m_wake_posted = true;
  }
  m_timer->runner_thread = std::this_thread::get_id();
  m_report = PacedReport{};
  m_run_started = m_wall0;
  const Ticks virt_start = m_sched.now();
  m_done = false;
  m_io->restart();
  boost::asio::post(*m_io, [this] { service(); });
  try {
    while (!m_done)
      if (m_io->run_one() == 0) break;  // someone stopped the io_context itself
  } catch (...) {
    std::lock_guard lock(m_mutex);
    m_running = false;
    m_last_now = m_sched.now();
    m_timer->runner_thread = std::thread::id{};
    throw;
  }
  m_timer->timer.cancel();
  m_report.wall_elapsed = Clock::now() - m_run_started;
  std::lock_guard lock(m_mutex);
  m_report.virtual_elapsed = m_sched.now() - virt_start;
  m_running = false;
  m_stop = false;
  m_last_now = m_sched.now();
  m_timer->runner_thread = std::thread::id{};
}

void PacedRunner::service() {
  if (m_done) return;  // a stale wake-up after the run ended
  std::deque<Pending> inputs;
  Clock::time_point wall;
  Ticks target;
  {
    std::lock_guard lock(m_mutex);
    inputs.swap(m_inputs);
    m_wake_posted = false;
    wall = Clock::now();
    target = std::min(virtual_at_locked(wall), m_until);
  }
  // Even when stopping, catch up to the wall clock first: a stop from outside means "at this
  // moment", and whatever was due before it still happens.
  for (auto& p : inputs) {
    // FIFO at equal ticks keeps each thread's inputs in post order.
    const Ticks at = p.anchored ? std::max(p.at, m_sched.now()) : m_sched.now();
    m_sched.schedule(at, [this, fn = std::move(p.fn)] {
      ++m_report.inputs;
      fn(m_sched.now());
    });
  }

  const Ticks due = m_sched.next_time();
  if (due <= target) {
    std::chrono::nanoseconds lag;
    {
      std::lock_guard lock(m_mutex);
      lag = std::max(std::chrono::nanoseconds(0),
                     std::chrono::duration_cast<std::chrono::nanoseconds>(wall - wall_at_locked(due)));
      if (m_max_lag.count() > 0 && lag > m_max_lag) {
        // Give up the lost wall time: the due event runs now and virtual time carries on from it.
        ++m_report.slips;
        m_report.slipped += lag;
        m_virt0 = std::max(due, m_sched.now());
        m_wall0 = wall;
        target = std::min(m_virt0, m_until);
        lag = std::chrono::nanoseconds(0);
      }
    }
    ++m_report.wakeups;
    if (lag > kLateThreshold) ++m_report.late_wakeups;
    m_report.max_lag = std::max(m_report.max_lag, lag);
  }
  m_sched.run_until(target);

  {
    std::lock_guard lock(m_mutex);
    m_last_now = m_sched.now();
    if (m_stop) {
      m_done = true;
      return;
    }
  }
  if (m_sched.now() >= m_until) {
    m_done = true;
    return;
  }
  arm(std::min(m_sched.next_time(), m_until));
}

void PacedRunner::arm(Ticks next) {
  Clock::time_point at;
  {
    std::lock_guard lock(m_mutex);
    at = wall_at_locked(next);
  }
  m_timer->timer.expires_at(at);
  m_timer->timer.async_wait([this](const boost::system::error_code& ec) {
    if (!ec) service();
  });
}

}  // namespace pbvbus::bus
