#include "pbvbus/bus/pty_station.hpp"

#include "pbvbus/bus/pty.hpp"

#include <dirent.h>
#include <fcntl.h>
#include <poll.h>
#include <sys/inotify.h>
#include <termios.h>
#include <unistd.h>

#include <algorithm>
#include <boost/asio/io_context.hpp>
#include <boost/asio/posix/stream_descriptor.hpp>
#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <functional>
#include <mutex>
#include <optional>
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

/// The longest telegram: SD2 with LE 249, 255 octets of 11 bits.
constexpr std::int64_t kLongestFrameBits = 255 * 11;

/// Octets read at most when the last program closes (about what a pty buffers).
constexpr std::size_t kCloseReadLimit = 64 * 1024;
/// Octets poll_input() reads and feeds at most per call.
constexpr std::size_t kPollReadLimit = 64 * 1024;

bool fcs_ok(std::span<const std::uint8_t> body, std::uint8_t fcs) {
  unsigned sum = 0;
  for (std::uint8_t b : body) sum += b;
  return static_cast<std::uint8_t>(sum) == fcs;
}

/// A Set_Slave_Add request to `to` (protocol-facts.md §D.7): the new address 0..126, else -1.
/// `master` gets the requester's address.
int set_slave_add_request(std::span<const std::uint8_t> b, int to, int& master) {
  std::size_t body = 0, len = 0;
  if (b.size() >= 9 && b[0] == 0x68) {
    len = b[1];
    if (b.size() != len + 6 || b[2] != len || b[3] != 0x68) return -1;
    body = 4;
  } else if (b.size() == 14 && b[0] == 0xA2) {
    body = 1;
    len = 11;
  } else {
    return -1;
  }
  if (b.back() != 0x16 || !fcs_ok(b.subspan(body, len), b[body + len])) return -1;
  const std::uint8_t da = b[body], sa = b[body + 1], fc = b[body + 2];
  if ((da & 0x80) == 0 || (da & 0x7F) != to) return -1;  // needs the DSAP
  if ((fc & 0x40) == 0 || ((fc & 0x0F) != 0x0C && (fc & 0x0F) != 0x0D)) return -1;  // SRD
  std::size_t at = body + 3;
  if ((b[at++] & 0x3F) != 55) return -1;  // DSAP 55: Set_Slave_Add
  if (sa & 0x80) ++at;                    // SSAP
  if (at + 4 > body + len) return -1;     // New_Slave_Address, Ident_Number, No_Add_Chg
  if (b[at] > 126) return -1;
  master = sa & 0x7F;
  return b[at];
}

/// A positive acknowledgement from `from` to `to`: SC, or SD1 response with status OK.
bool positive_ack(std::span<const std::uint8_t> t, int from, int to) {
  if (t.size() == 1) return t[0] == 0xE5;
  return t.size() == 6 && t[0] == 0x10 && (t[1] & 0x7F) == to && (t[2] & 0x7F) == from &&
         (t[3] & 0x40) == 0 && (t[3] & 0x0F) == 0x00 && fcs_ok(t.subspan(1, 3), t[4]) &&
         t[5] == 0x16;
}

/// Descriptors of `path` held by processes (this one's `own_fd` excepted) as far as /proc
/// shows them; -1 if /proc cannot be read.
int count_openers(const std::string& path, int own_fd) {
  DIR* proc = ::opendir("/proc");
  if (proc == nullptr) return -1;
  const std::string self = std::to_string(::getpid());
  int n = 0;
  while (const dirent* p = ::readdir(proc)) {
    if (p->d_name[0] < '0' || p->d_name[0] > '9') continue;
    const std::string dir = std::string("/proc/") + p->d_name + "/fd";
    DIR* fds = ::opendir(dir.c_str());
    if (fds == nullptr) continue;  // gone, or not ours to see
    while (const dirent* f = ::readdir(fds)) {
      if (f->d_name[0] < '0' || f->d_name[0] > '9') continue;
      if (self == p->d_name && std::atoi(f->d_name) == own_fd) continue;
      char target[256];
      const std::string link = dir + "/" + f->d_name;
      const ssize_t len = ::readlink(link.c_str(), target, sizeof target - 1);
      if (len > 0 && static_cast<std::size_t>(len) == path.size() &&
          std::memcmp(target, path.data(), path.size()) == 0)
        ++n;
    }
    ::closedir(fds);
  }
  ::closedir(proc);
  return n;
}

}  // namespace

std::int64_t default_max_age_bits(std::int64_t slot_bits) {
  return 2 * (kLongestFrameBits + kTsynBits + slot_bits + kLongestFrameBits + kTsynBits);
}

/// The inotify watch on the slave side's node and what it has shown. Read from any thread
/// (under `mutex`); the station's thread acts on it in sync_program().
struct PtyStation::Watch {
  int fd = -1;
  std::string path;
  int own_fd = -1;  // the station's own handle on the slave side
  termios pristine{};
  mutable std::mutex mutex;
  int open_count = 0;       // open descriptions of the node by programs
  std::uint64_t opens = 0;  // IN_OPEN events seen
  std::uint64_t zeros = 0;  // times open_count went down to 0
  // With attach_io(): posts sync_program() to the runner (another thread drained the events, so
  // the runner's wait may not fire).
  std::function<void()> wake;

  ~Watch() {
    if (fd >= 0) ::close(fd);
  }

  /// Reads every pending event; true if there were any. Call with `mutex` held.
  bool drain_locked() {
    bool any = false, closed = false;
    int opened_after_close = 0;
    alignas(inotify_event) char buf[4096];
    for (;;) {
      const ssize_t n = ::read(fd, buf, sizeof buf);
      if (n < 0 && errno == EINTR) continue;
      if (n <= 0) break;
      any = true;
      for (ssize_t at = 0; at < n;) {
        const auto* e = reinterpret_cast<const inotify_event*>(buf + at);
        if (e->mask & IN_Q_OVERFLOW) {
          closed = true;  // events lost: /proc decides below
        } else if (e->mask & IN_OPEN) {
          ++open_count;
          ++opens;
          ++opened_after_close;
        } else if (e->mask & (IN_CLOSE_WRITE | IN_CLOSE_NOWRITE)) {
          closed = true;
          opened_after_close = 0;
          if (open_count > 0 && --open_count == 0) ++zeros;
        }
        at += static_cast<ssize_t>(sizeof(inotify_event) + e->len);
      }
    }
    if (closed) {
      // inotify merges identical events that follow each other unread (two closes, two opens):
      // after a close, /proc tells how many are open. An open's event comes before its
      // descriptor is installed, so opens after the last close count at least themselves.
      const int seen = count_openers(path, own_fd);
      if (seen >= 0) {
        const int now = std::max(seen, opened_after_close);
        if (open_count > 0 && now == 0) ++zeros;
        open_count = now;
      }
    }
    return any;
  }
};

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
    if (watch) {
      watch->cancel(ec);
      watch->close(ec);  // our dup of the inotify descriptor
    }
  }
  PacedRunner& runner;
  boost::asio::posix::stream_descriptor sd;
  std::optional<boost::asio::posix::stream_descriptor> watch;
  std::shared_ptr<bool> alive = std::make_shared<bool>(true);
  bool write_armed = false;
};

PtyStation::PtyStation(Options options) : m_opt(options) {
  if (m_opt.mode == Mode::Station && (m_opt.address < 0 || m_opt.address > 126))
    throw std::invalid_argument("pty station: an FDL address 0..126 is needed in station mode");
  m_address = m_opt.mode == Mode::Station ? m_opt.address : -1;
  const Pty pty = open_pty();
  m_master = pty.master;
  m_slave = pty.slave;
  m_path = pty.path;
  m_out.reserve(4096);
  // The watch is in place before anyone learns the path, so no program's open is missed.
  auto w = std::make_unique<Watch>();
  w->path = m_path;
  w->own_fd = m_slave;
  w->fd = ::inotify_init1(IN_NONBLOCK | IN_CLOEXEC);
  if (w->fd >= 0 && ::tcgetattr(m_slave, &w->pristine) == 0 &&
      ::inotify_add_watch(w->fd, m_path.c_str(), IN_OPEN | IN_CLOSE_WRITE | IN_CLOSE_NOWRITE) >= 0)
    m_watch = std::move(w);
  m_present = m_watch == nullptr;  // without a watch: as if a program always had it open
}

PtyStation::~PtyStation() {
  m_io.reset();
  m_watch.reset();
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
  m_raw_starts.clear();  // the line drops what had not started
}

void PtyStation::on_timer(Ticks now) { pump(now); }

std::int64_t PtyStation::window_bits() const {
  return m_opt.reply_window_bits > 0 ? m_opt.reply_window_bits
                                     : default_slot_time_bits(port().baud());
}

std::int64_t PtyStation::max_age_bits() const {
  return m_opt.max_age_bits > 0 ? m_opt.max_age_bits : default_max_age_bits(window_bits());
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
    if (now - t.arrived > max_age_bits() * bit) {
      ++m_stats.dropped_stale;  // its program has given up on it (see the header comment)
      m_queue.pop_front();
      continue;
    }
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
  check_slave_add_ack(start, t.bytes);
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

void PtyStation::check_slave_add_ack(Ticks start, std::span<const std::uint8_t> t) {
  if (m_ssa_new < 0) return;
  // The program's first telegram after the request decides, if it starts in the reply window.
  if (start >= m_ssa_from && start <= m_ssa_until && positive_ack(t, current_address(), m_ssa_master)) {
    m_address = m_ssa_new;
    ++m_stats.address_changes;
  }
  m_ssa_new = -1;
}

void PtyStation::on_frame(const RxFrame& f) {
  // Interface timing: every frame on the line counts for the idle time, and the first one after
  // our request is its reply (in time or not, the wait is over once it has been heard).
  m_line_free_at = std::max(m_line_free_at, f.end);
  if (m_await_reply && f.start >= m_await_from) m_await_reply = false;
  // Set_Slave_Add: another station spoke before the program answered: no acknowledgement.
  if (m_ssa_new >= 0 && f.start >= m_ssa_from) m_ssa_new = -1;
  if (m_opt.mode == Mode::Station && f.flags == 0) {
    int master = -1;
    const int to = set_slave_add_request(f.bytes, current_address(), master);
    if (to >= 0) {
      m_ssa_new = to;
      m_ssa_master = master;
      m_ssa_from = f.end;
      m_ssa_until = f.end + window_bits() * ticks_per_bit(port().baud());
    }
  }
  forward(f);
  pump(f.end);
}

void PtyStation::forward(const RxFrame& f) {
  bool out = m_opt.mode == Mode::Monitor || m_opt.forward_all;
  if (m_opt.mode == Mode::Station) {
    const int da = telegram_da(f.bytes);
    out = out || da == current_address() || da == 127;
    if (m_reply_until >= 0 && f.start >= m_reply_after) {
      // The first frame after our telegram: the reply if it started in time, else none came.
      if (f.start <= m_reply_until) out = true;
      m_reply_after = m_reply_until = -1;
    }
  }
  if (out) emit(f.bytes);
}

void PtyStation::emit(std::span<const std::uint8_t> frame) {
  sync_program();
  if (!m_present) {
    ++m_stats.frames_no_program;  // nobody to read it; a later program must not see it
    return;
  }
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

std::size_t PtyStation::read_some(std::uint8_t* into, std::size_t max) {
  for (;;) {
    const ssize_t n = ::read(m_master, into, max);
    if (n > 0) return static_cast<std::size_t>(n);
    if (n < 0 && errno == EINTR) continue;
    return 0;  // EAGAIN (nothing more), 0 or EIO (cannot happen while we hold the slave open)
  }
}

std::size_t PtyStation::read_and_feed(std::size_t limit) {
  std::uint8_t buf[kReadChunk];
  std::size_t total = 0;
  while (total < limit) {
    const std::size_t n = read_some(buf, std::min(sizeof buf, limit - total));
    if (n == 0) break;
    feed(std::span<const std::uint8_t>(buf, n));
    total += n;
    if (n < sizeof buf) break;  // drained for now
  }
  return total;
}

std::size_t PtyStation::poll_input(std::chrono::milliseconds wait) {
  sync_program();
  pollfd p{m_master, POLLIN, 0};
  const int r = ::poll(&p, 1, static_cast<int>(wait.count()));
  std::size_t n = 0;
  if (r > 0) {
    sync_program();  // an open or close that came with the bytes is handled first
    n = read_and_feed(kPollReadLimit);
  }
  flush_output();
  return n;
}

void PtyStation::attach_io(PacedRunner& runner) {
  if (m_io) throw std::logic_error("pty station: attach_io() called twice");
  const int fd = ::fcntl(m_master, F_DUPFD_CLOEXEC, 0);
  if (fd < 0) throw_errno("dup pty master");
  m_io = std::make_unique<Io>(runner, fd);
  // The read loop: wait for readability, then on the runner's thread (so the bytes enter at the
  // virtual time matching now) read and feed ONE chunk; wait again only once a read found the
  // pty drained (the descriptor is edge-triggered), else read the next chunk in a new input.
  // So at most one chunk is in flight whatever the program writes.
  struct Reader {
    PtyStation* self;
    std::weak_ptr<bool> alive;
    void read() const {
      self->sync_program();
      const std::size_t n = self->read_and_feed(kReadChunk);
      self->flush_output();
      if (n == kReadChunk) {
        self->m_io->runner.post([r = *this](Ticks) {
          if (!r.alive.expired()) r.read();
        });
      } else {
        self->m_io->sd.async_wait(boost::asio::posix::stream_descriptor::wait_read, *this);
      }
    }
    void operator()(const boost::system::error_code& ec) const {
      if (ec || alive.expired()) return;
      self->m_io->runner.post([r = *this](Ticks) {
        if (!r.alive.expired()) r.read();
      });
    }
  };
  m_io->sd.async_wait(boost::asio::posix::stream_descriptor::wait_read, Reader{this, m_io->alive});
  if (m_watch) {
    const int wfd = ::fcntl(m_watch->fd, F_DUPFD_CLOEXEC, 0);
    if (wfd < 0) throw_errno("dup inotify descriptor");
    m_io->watch.emplace(runner.io_context(), wfd);
    struct Watcher {
      PtyStation* self;
      std::weak_ptr<bool> alive;
      void operator()(const boost::system::error_code& ec) const {
        if (ec || alive.expired()) return;
        self->m_io->runner.post([s = self, a = alive](Ticks) {
          if (!a.expired()) s->sync_program();
        });
        self->m_io->watch->async_wait(boost::asio::posix::stream_descriptor::wait_read, *this);
      }
    };
    m_io->watch->async_wait(boost::asio::posix::stream_descriptor::wait_read,
                            Watcher{this, m_io->alive});
    std::lock_guard lock(m_watch->mutex);
    m_watch->wake = [this, &runner, a = std::weak_ptr<bool>(m_io->alive)] {
      runner.post([this, a](Ticks) {
        if (!a.expired()) sync_program();
      });
    };
  }
}

void PtyStation::detach_io() {
  if (m_watch) {
    std::lock_guard lock(m_watch->mutex);
    m_watch->wake = nullptr;
  }
  m_io.reset();
}

bool PtyStation::program_open() const {
  if (!m_watch) return true;
  std::unique_lock lock(m_watch->mutex);
  if (m_watch->drain_locked() && m_watch->wake) m_watch->wake();
  return m_watch->open_count > 0;
}

std::uint64_t PtyStation::program_opens() const {
  if (!m_watch) return 0;
  std::unique_lock lock(m_watch->mutex);
  if (m_watch->drain_locked() && m_watch->wake) m_watch->wake();
  return m_watch->opens;
}

bool PtyStation::wait_program_open(std::chrono::milliseconds limit) {
  if (!m_watch) return true;
  const auto until = std::chrono::steady_clock::now() + limit;
  for (;;) {
    {
      std::unique_lock lock(m_watch->mutex);
      if (m_watch->drain_locked() && m_watch->wake) m_watch->wake();
      if (m_watch->open_count > 0) return true;
    }
    const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(
        until - std::chrono::steady_clock::now());
    if (left.count() <= 0) return false;
    // The runner's thread may drain the events first (then poll sees nothing): look again at
    // least every 10 ms.
    pollfd p{m_watch->fd, POLLIN, 0};
    ::poll(&p, 1, static_cast<int>(std::min<std::int64_t>(left.count() + 1, 10)));
  }
}

void PtyStation::sync_program() {
  if (!m_watch) return;
  std::uint64_t opens = 0, zeros = 0;
  int count = 0;
  {
    std::lock_guard lock(m_watch->mutex);
    m_watch->drain_locked();
    opens = m_watch->opens;
    zeros = m_watch->zeros;
    count = m_watch->open_count;
  }
  if (zeros != m_applied_zeros) {
    // The last program closed (maybe opened and closed since we last looked).
    m_applied_zeros = zeros;
    on_program_closed();
    if (count == 0) ::tcsetattr(m_slave, TCSANOW, &m_watch->pristine);
  }
  if (opens != m_applied_opens) {
    m_stats.program_opens += opens - m_applied_opens;
    m_applied_opens = opens;
    if (count > 0) on_program_opened();
  }
  m_present = count > 0;
}

void PtyStation::on_program_closed() {
  ++m_stats.program_closes;
  read_and_feed(kCloseReadLimit);  // written while it was open
  m_stats.dropped_closed += m_queue.size();
  m_queue.clear();
  if (m_splitter.pending() > 0) {
    m_splitter.discard_pending();
    ++m_stats.abandoned;
  }
  m_out.clear();
  ::tcflush(m_slave, TCIFLUSH);
  m_reply_after = m_reply_until = -1;
  m_ssa_new = -1;
  m_address = m_opt.mode == Mode::Station ? m_opt.address : -1;
}

void PtyStation::on_program_opened() {
  // Whatever was written towards the program before it opened is not for it.
  m_out.clear();
  ::tcflush(m_slave, TCIFLUSH);
}

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
    if (m_opt.timing == Timing::Raw) {
      // The telegrams handed to the line but not started yet are this timing's queue.
      while (!m_raw_starts.empty() && m_raw_starts.front() <= now) m_raw_starts.pop_front();
      const Ticks start = std::max(now, m_tx_free_at);
      if (start - now > max_age_bits() * ticks_per_bit(port().baud())) {
        ++m_stats.dropped_stale;
      } else if (m_raw_starts.size() >= m_opt.max_queue) {
        ++m_stats.dropped_full;
      } else {
        send(start, Held{{f.begin(), f.end()}, now});
        if (start > now) m_raw_starts.push_back(start);
      }
    } else if (m_queue.size() >= m_opt.max_queue) {
      ++m_stats.dropped_full;  // the interface's job queue is full
    } else {
      m_queue.push_back(Held{{f.begin(), f.end()}, now});
      m_stats.queue_max = std::max<std::uint64_t>(m_stats.queue_max, m_queue.size());
    }
  });
  if (m_splitter.pending() > 0 && (was_idle || n > 0)) m_first_pending_at = now;
  pump(now);
  flush_output();
}

}  // namespace pbvbus::bus
