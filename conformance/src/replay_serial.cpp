// `replay --to PTY`: a capture played raw into a serial port (replay_serial.hpp).

#include "pbvbus/conformance/replay_serial.hpp"

#include <fcntl.h>
#include <poll.h>
#include <sys/ioctl.h>
#include <sys/stat.h>
#include <termios.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <cstring>
#include <system_error>
#include <thread>
#include <vector>

#include "pbvbus/bus/pty.hpp"
#include "pbvbus/captures/pcapng_format.hpp"
#include "pbvbus/captures/pcapng_reader.hpp"

namespace pbvbus::conformance {

namespace {

using Clock = std::chrono::steady_clock;

std::string errno_text(const std::string& what) { return what + ": " + std::strerror(errno); }

void make_raw(int fd) {
  termios t{};
  if (::tcgetattr(fd, &t) != 0) return;  // not a terminal: nothing to set
  ::cfmakeraw(&t);
  ::tcsetattr(fd, TCSANOW, &t);
}

}  // namespace

SerialTarget::~SerialTarget() {
  if (m_fd >= 0) ::close(m_fd);
  if (m_slave >= 0) ::close(m_slave);
  if (!m_link.empty()) {
    struct stat st {};
    if (::lstat(m_link.c_str(), &st) == 0 && S_ISLNK(st.st_mode)) ::unlink(m_link.c_str());
  }
}

std::unique_ptr<SerialTarget> open_serial_target(const std::string& path, bool create_pty,
                                                 std::string& error) {
  std::unique_ptr<SerialTarget> t(new SerialTarget());
  if (!create_pty) {
    t->m_fd = ::open(path.c_str(), O_RDWR | O_NOCTTY | O_NONBLOCK | O_CLOEXEC);
    if (t->m_fd < 0) {
      error = errno_text("cannot open " + path);
      return nullptr;
    }
    make_raw(t->m_fd);
    t->m_path = path;
    return t;
  }
  // Our own handle on the slave side (bus::open_pty): a reader may open and close the path
  // freely, and the slave's termios (raw: no CR/LF mapping of the octets we write) stays set.
  try {
    const bus::Pty pty = bus::open_pty();
    t->m_fd = pty.master;
    t->m_slave = pty.slave;
    t->m_path = pty.path;
  } catch (const std::system_error& e) {
    error = std::string("cannot set up the pseudo-terminal: ") + e.what();
    return nullptr;
  }
  if (!path.empty()) {
    error = bus::make_pty_link(t->m_path, path);
    if (!error.empty()) return nullptr;
    t->m_link = path;
  }
  return t;
}

std::optional<SerialPlayStats> play_to_serial(std::span<const std::uint8_t> data,
                                              SerialTarget& target, const SerialPlayOptions& opts,
                                              std::string& error) {
  captures::PcapngError perr;
  auto cap = captures::read_pcapng(data, perr);
  if (!cap) {
    error = perr.to_string();
    return std::nullopt;
  }
  if (opts.speed_num == 0 || opts.speed_den == 0) {
    error = "speed must be N/M with N, M > 0";
    return std::nullopt;
  }
  std::vector<const captures::PcapngRecord*> frames;
  for (const auto& r : cap->records) {
    if (r.interface >= cap->interfaces.size()) continue;
    const auto& itf = cap->interfaces[r.interface];
    const bool line_if = itf.link_type == static_cast<std::uint16_t>(captures::pcapng::LinkType::User0) ||
                         itf.link_type == static_cast<std::uint16_t>(captures::pcapng::LinkType::ProfibusDl);
    if (line_if && (opts.line.empty() || itf.name == opts.line) && !r.bytes.empty())
      frames.push_back(&r);
  }
  if (frames.empty()) {
    error = opts.line.empty() ? "the capture has no frames to play"
                              : "the capture has no frames on line '" + opts.line + "'";
    return std::nullopt;
  }
  SerialPlayStats st;
  st.frames = frames.size();
  std::vector<std::uint8_t> buf;
  buf.reserve(opts.max_buffer);
  const int fd = target.fd();
  auto flush = [&] {
    while (!buf.empty()) {
      const ssize_t n = ::write(fd, buf.data(), buf.size());
      if (n <= 0) return;  // EAGAIN (reader not reading), EIO: keep it for later
      st.octets_written += static_cast<std::uint64_t>(n);
      buf.erase(buf.begin(), buf.begin() + n);
    }
  };
  const auto t0 = Clock::now();
  const std::int64_t first_ns = frames.front()->ts_ns;
  for (const auto* r : frames) {
    // Wall offset = recorded offset · den / num, in ns; saturating for absurd timestamps.
    std::int64_t rel = r->ts_ns - first_ns;
    if (rel < 0) rel = 0;
    if (rel > (std::int64_t{1} << 50)) rel = std::int64_t{1} << 50;
    const long double wall = static_cast<long double>(rel) * opts.speed_den / opts.speed_num;
    const auto due = t0 + std::chrono::nanoseconds(static_cast<std::int64_t>(wall));
    while (Clock::now() < due) {
      flush();
      const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(due - Clock::now());
      if (!buf.empty()) {
        pollfd p{fd, POLLOUT, 0};
        ::poll(&p, 1, static_cast<int>(std::min<std::int64_t>(left.count() + 1, 50)));
      } else {
        std::this_thread::sleep_until(std::min(due, Clock::now() + std::chrono::milliseconds(50)));
      }
    }
    if (buf.size() + r->bytes.size() > opts.max_buffer) {
      ++st.frames_dropped;
      st.octets_dropped += r->bytes.size();
    } else {
      buf.insert(buf.end(), r->bytes.begin(), r->bytes.end());
      ++st.frames_written;
    }
    flush();
  }
  const auto drain_until = Clock::now() + std::chrono::milliseconds(opts.drain_ms);
  while (!buf.empty() && Clock::now() < drain_until) {
    flush();
    if (buf.empty()) break;
    pollfd p{fd, POLLOUT, 0};
    ::poll(&p, 1, 20);
  }
  // A created pty: give the reader the same time to take what the pty still holds, so that
  // closing our side does not hang up on unread frames.
  // Octets the master took may still be on their way into the slave's input queue (the kernel
  // moves them in a work item), so the queue must stay empty for 50 ms, not just once.
  if (target.slave_fd() >= 0) {
    auto empty_since = Clock::now();
    while (Clock::now() < drain_until && Clock::now() - empty_since < std::chrono::milliseconds(50)) {
      int queued = 0;
      if (::ioctl(target.slave_fd(), FIONREAD, &queued) != 0) break;
      if (queued > 0) empty_since = Clock::now();
      std::this_thread::sleep_for(std::chrono::milliseconds(5));
    }
  }
  st.octets_dropped += buf.size();
  st.wall_ms = std::chrono::duration_cast<std::chrono::milliseconds>(Clock::now() - t0).count();
  return st;
}

}  // namespace pbvbus::conformance
