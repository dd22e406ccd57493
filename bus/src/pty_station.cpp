#include "pbvbus/bus/pty_station.hpp"

#include "pbvbus/bus/pty.hpp"

#include <fcntl.h>
#include <poll.h>
#include <termios.h>
#include <unistd.h>

#include <algorithm>
#include <boost/asio/io_context.hpp>
#include <boost/asio/posix/stream_descriptor.hpp>
#include <cerrno>
#include <cstdlib>
#include <stdexcept>
#include <system_error>

#include "pbvbus/bus/paced_runner.hpp"

namespace pbvbus::bus {

namespace {

/// TSYN: idle before a request or token (protocol-facts.md §A).
constexpr std::int64_t kTsynBits = 33;

[[noreturn]] void throw_errno(const char* what) {
  throw std::system_error(errno, std::generic_category(), what);
}

/// Destination address of a telegram as a station's filter would see it, or -1.
int telegram_da(std::span<const std::uint8_t> b) {
  if (b.empty()) return -1;
  switch (b[0]) {
    case 0x10:
    case 0xA2:
    case 0xDC: return b.size() > 1 ? b[1] & 0x7F : -1;
    case 0x68: return b.size() > 4 ? b[4] & 0x7F : -1;
    default: return -1;
  }
}

/// What the Interface timing needs to know about a telegram from the program.
struct TelegramKind {
  bool needs_sync = false;     ///< a request or token: TSYN idle before it
  bool expects_reply = false;  ///< the next frame from someone else is its reply (or activity)
};

TelegramKind classify(std::span<const std::uint8_t> b) {
  TelegramKind k;
  if (b.empty()) return k;
  std::size_t fc_at = 0;
  switch (b[0]) {
    case 0xDC:  // token: the receiver's activity is awaited, unless passed to itself
      k.needs_sync = true;
      k.expects_reply = b.size() >= 3 && (b[1] & 0x7F) != (b[2] & 0x7F);
      return k;
    case 0x10:
    case 0xA2: fc_at = 3; break;
    case 0x68: fc_at = 6; break;
    default: return k;  // SC: a response
  }
  if (b.size() <= fc_at) return k;
  const std::uint8_t fc = b[fc_at];
  if ((fc & 0x40) == 0) return k;  // a response frame
  k.needs_sync = true;
  const std::uint8_t fn = fc & 0x0F;
  const bool reply_fn = fn == 0x3 || fn == 0x5 || fn == 0x7 || fn == 0x9 || fn >= 0xC;
  k.expects_reply = reply_fn && telegram_da(b) != 127;
  return k;
}

}  // namespace

std::int64_t default_slot_time_bits(Baud baud) {
  switch (baud) {
    case Baud::k500: return 200;
    case Baud::k1_5M: return 300;
    case Baud::k3M: return 400;
    case Baud::k6M: return 600;
    case Baud::k12M: return 1000;
    default: return 100;  // 9.6k .. 187.5k, 45.45k [U in §C.1], 31.25k
  }
}

struct PtyStation::Io {
  Io(PacedRunner& r, int fd) : runner(r), sd(r.io_context(), fd) {}
  ~Io() {
    boost::system::error_code ec;
    sd.cancel(ec);
    sd.close(ec);  // closes our dup of the master side only
  }
  PacedRunner& runner;
  boost::asio::posix::stream_descriptor sd;
  std::shared_ptr<bool> alive = std::make_shared<bool>(true);
  bool write_armed = false;
};

PtyStation::PtyStation(Options options) : m_opt(options) {
  if (m_opt.mode == Mode::Station && (m_opt.address < 0 || m_opt.address > 126))
    throw std::invalid_argument("pty station: an FDL address 0..126 is needed in station mode");
  const Pty pty = open_pty();
  m_master = pty.master;
  m_slave = pty.slave;
  m_path = pty.path;
  m_out.reserve(4096);
}

PtyStation::~PtyStation() {
  m_io.reset();
  if (m_slave >= 0) ::close(m_slave);
  if (m_master >= 0) ::close(m_master);
}

PtyStation::Stats PtyStation::stats() const {
  Stats s = m_stats;
  s.garbage_bytes += m_splitter.garbage();
  return s;
}

void PtyStation::on_power_on(Ticks now) {
  m_powered = true;
  m_tx_free_at = now;
  m_line_free_at = now;  // an interface synchronises from power-on: TSYN before its first request
  m_reply_after = m_reply_until = -1;
  m_await_reply = false;
}

void PtyStation::on_power_off(Ticks) {
  m_powered = false;
  m_reply_after = m_reply_until = -1;
  m_await_reply = false;
  m_stats.discarded += m_queue.size();
  m_queue.clear();
}

void PtyStation::on_timer(Ticks now) { pump(now); }

std::int64_t PtyStation::window_bits() const {
  return m_opt.reply_window_bits > 0 ? m_opt.reply_window_bits
                                     : default_slot_time_bits(port().baud());
}

void PtyStation::pump(Ticks now) {
  if (m_opt.timing != Timing::Interface) return;
  const Ticks bit = ticks_per_bit(port().baud());
  while (!m_queue.empty() && m_powered) {
    if (port().receiving()) {
      // Someone else's frame is on the line: its delivery (on_frame) pumps again. The timer is
      // only a safety net (a frame longer than any telegram cannot be on the line).
      port().set_timer(now + chars_to_ticks(256, port().baud()));
      return;
    }
    if (m_await_reply) {
      if (now < m_await_until) {
        port().set_timer(m_await_until);
        return;
      }
      m_await_reply = false;  // the slot time has passed and no reply has started
    }
    const Held& t = m_queue.front();
    const Ticks earliest = m_line_free_at + (classify(t.bytes).needs_sync ? kTsynBits * bit : 0);
    if (now < earliest) {
      port().set_timer(earliest);
      return;
    }
    send(now, t);
    m_queue.pop_front();
  }
}

void PtyStation::send(Ticks start, const Held& t) {
  const Ticks bit = ticks_per_bit(port().baud());
  port().transmit(start, t.bytes);
  ++m_stats.frames_in;
  m_stats.octets_sent += t.bytes.size();
  if (const Ticks hold = start - t.arrived; hold > 0) {
    ++m_stats.held;
    m_stats.hold_total += hold;
    m_stats.hold_max = std::max(m_stats.hold_max, hold);
  }
  const Ticks end = start + chars_to_ticks(static_cast<std::int64_t>(t.bytes.size()), port().baud());
  m_tx_free_at = end + kTsynBits * bit;
  m_line_free_at = std::max(m_line_free_at, end);
  if (m_opt.mode == Mode::Station) {
    m_reply_after = end;
    m_reply_until = end + window_bits() * bit;
  }
  if (m_opt.timing == Timing::Interface && classify(t.bytes).expects_reply) {
    m_await_reply = true;
    m_await_from = end;
    m_await_until = end + window_bits() * bit;
  }
}

void PtyStation::on_frame(const RxFrame& f) {
  // Interface timing: every frame on the line counts for the idle time, and the first one after
  // our request is its reply (in time or not, the wait is over once it has been heard).
  m_line_free_at = std::max(m_line_free_at, f.end);
  if (m_await_reply && f.start >= m_await_from) m_await_reply = false;
  forward(f);
  pump(f.end);
}

void PtyStation::forward(const RxFrame& f) {
  bool out = m_opt.mode == Mode::Monitor;
  if (!out) {
    const int da = telegram_da(f.bytes);
    out = da == m_opt.address || da == 127;
    if (m_reply_until >= 0 && f.start >= m_reply_after) {
      // The first frame after our telegram: the reply if it started in time, else none came.
      if (f.start <= m_reply_until) out = true;
      m_reply_after = m_reply_until = -1;
    }
  }
  if (out) emit(f.bytes);
}

void PtyStation::emit(std::span<const std::uint8_t> frame) {
  if (m_out.size() + frame.size() > m_opt.max_backlog) {
    flush_output();
    if (m_out.size() + frame.size() > m_opt.max_backlog) {
      ++m_stats.frames_dropped;
      return;
    }
  }
  ++m_stats.frames_out;
  m_stats.bytes_out += frame.size();
  m_out.insert(m_out.end(), frame.begin(), frame.end());
  flush_output();
}

void PtyStation::flush_output() {
  std::size_t done = 0;
  while (done < m_out.size()) {
    const ssize_t n = ::write(m_master, m_out.data() + done, m_out.size() - done);
    if (n > 0) {
      done += static_cast<std::size_t>(n);
      continue;
    }
    if (n < 0 && errno == EINTR) continue;
    break;  // EAGAIN: the program is not reading; anything else: try again later
  }
  m_out.erase(m_out.begin(), m_out.begin() + static_cast<std::ptrdiff_t>(done));
  if (!m_out.empty() && m_io && !m_io->write_armed) {
    m_io->write_armed = true;
    std::weak_ptr<bool> alive = m_io->alive;
    m_io->sd.async_wait(boost::asio::posix::stream_descriptor::wait_write,
                        [this, alive](const boost::system::error_code& ec) {
                          if (ec || alive.expired()) return;
                          m_io->write_armed = false;
                          flush_output();
                        });
  }
}

std::size_t PtyStation::read_available(std::vector<std::uint8_t>& into) {
  std::size_t total = 0;
  std::uint8_t buf[4096];
  for (;;) {
    const ssize_t n = ::read(m_master, buf, sizeof buf);
    if (n > 0) {
      into.insert(into.end(), buf, buf + n);
      total += static_cast<std::size_t>(n);
      continue;
    }
    if (n < 0 && errno == EINTR) continue;
    break;  // EAGAIN (nothing more), 0 or EIO (cannot happen while we hold the slave open)
  }
  return total;
}

std::size_t PtyStation::poll_input(std::chrono::milliseconds wait) {
  pollfd p{m_master, POLLIN, 0};
  const int r = ::poll(&p, 1, static_cast<int>(wait.count()));
  if (r <= 0) return 0;
  std::vector<std::uint8_t> bytes;
  const std::size_t n = read_available(bytes);
  if (n > 0) feed(bytes);
  flush_output();
  return n;
}

void PtyStation::attach_io(PacedRunner& runner) {
  if (m_io) throw std::logic_error("pty station: attach_io() called twice");
  const int fd = ::fcntl(m_master, F_DUPFD_CLOEXEC, 0);
  if (fd < 0) throw_errno("dup pty master");
  m_io = std::make_unique<Io>(runner, fd);
  // The read loop: wait for readability, read everything, hand it to the runner so that it
  // enters at the virtual time matching now, wait again.
  struct Reader {
    PtyStation* self;
    std::weak_ptr<bool> alive;
    void operator()(const boost::system::error_code& ec) const {
      if (ec || alive.expired()) return;
      std::vector<std::uint8_t> bytes;
      self->read_available(bytes);
      if (!bytes.empty()) {
        self->m_io->runner.post([s = self, a = alive, b = std::move(bytes)](Ticks) {
          if (!a.expired()) s->feed(b);
        });
      }
      self->m_io->sd.async_wait(boost::asio::posix::stream_descriptor::wait_read, *this);
    }
  };
  m_io->sd.async_wait(boost::asio::posix::stream_descriptor::wait_read, Reader{this, m_io->alive});
}

void PtyStation::detach_io() { m_io.reset(); }

void PtyStation::feed(std::span<const std::uint8_t> bytes) {
  m_stats.bytes_in += bytes.size();
  if (!bound() || !m_powered) {
    m_stats.garbage_bytes += bytes.size();  // an unpowered station's UART hears nothing
    return;
  }
  const Ticks now = port().now();
  if (m_splitter.pending() > 0 && now - m_first_pending_at > m_opt.resync_after) {
    m_splitter.discard_pending();
    ++m_stats.abandoned;
  }
  const bool was_idle = m_splitter.pending() == 0;
  const std::size_t n = m_splitter.feed(bytes, [&](std::span<const std::uint8_t> f) {
    Held t{{f.begin(), f.end()}, now};
    if (m_opt.timing == Timing::Raw) {
      send(std::max(now, m_tx_free_at), t);
    } else {
      m_queue.push_back(std::move(t));
      m_stats.queue_max = std::max<std::uint64_t>(m_stats.queue_max, m_queue.size());
    }
  });
  if (m_splitter.pending() > 0 && (was_idle || n > 0)) m_first_pending_at = now;
  pump(now);
  flush_output();
}

}  // namespace pbvbus::bus
