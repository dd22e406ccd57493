#include "pbvbus/gateways/socketcan_door.hpp"

#include <linux/can.h>
#include <linux/can/raw.h>
#include <net/if.h>
#include <sys/ioctl.h>
#include <sys/socket.h>
#include <unistd.h>

#include <boost/asio/io_context.hpp>
#include <boost/asio/posix/stream_descriptor.hpp>
#include <cerrno>
#include <cstring>
#include <vector>

#include "pbvbus/bus/paced_runner.hpp"

namespace pbvbus::gateways {

namespace {

using Descriptor = boost::asio::posix::stream_descriptor;

can_frame to_kernel(const CanFrame& f) {
  can_frame k{};
  k.can_id = f.extended ? ((f.id & CAN_EFF_MASK) | CAN_EFF_FLAG) : (f.id & CAN_SFF_MASK);
  if (f.rtr) k.can_id |= CAN_RTR_FLAG;
  k.can_dlc = f.dlc > 8 ? 8 : f.dlc;
  if (!f.rtr) std::memcpy(k.data, f.data.data(), k.can_dlc);
  return k;
}

CanFrame from_kernel(const can_frame& k) {
  CanFrame f;
  f.extended = (k.can_id & CAN_EFF_FLAG) != 0;
  f.rtr = (k.can_id & CAN_RTR_FLAG) != 0;
  f.id = f.extended ? (k.can_id & CAN_EFF_MASK) : (k.can_id & CAN_SFF_MASK);
  f.dlc = k.can_dlc > 8 ? 8 : k.can_dlc;
  if (!f.rtr) std::memcpy(f.data.data(), k.data, f.dlc);
  return f;
}

}  // namespace

struct SocketcanDoor::Io {
  Io(boost::asio::io_context& io, int fd_) : fd(fd_), sd(io, fd_) {}
  int fd;
  Descriptor sd;  // owns fd
  std::shared_ptr<bool> alive = std::make_shared<bool>(true);
  bool write_armed = false;
};

SocketcanDoor::SocketcanDoor(bus::PacedRunner& runner, CanHub& hub, Options options)
    : m_runner(runner), m_hub(hub), m_opt(std::move(options)) {}

SocketcanDoor::~SocketcanDoor() { close(); }

std::string SocketcanDoor::open() {
  if (m_io) return "socketcan door: already open";
  const int fd = ::socket(PF_CAN, SOCK_RAW | SOCK_NONBLOCK | SOCK_CLOEXEC, CAN_RAW);
  if (fd < 0)
    return "socket(AF_CAN, SOCK_RAW, CAN_RAW): " + std::string(std::strerror(errno)) +
           " (the kernel offers no SocketCAN here)";
  if (m_opt.interface.empty() || m_opt.interface.size() >= IFNAMSIZ) {
    ::close(fd);
    return "socketcan door: bad interface name '" + m_opt.interface + "'";
  }
  ifreq ifr{};
  std::memcpy(ifr.ifr_name, m_opt.interface.c_str(), m_opt.interface.size());
  if (::ioctl(fd, SIOCGIFINDEX, &ifr) != 0) {
    const std::string e = std::strerror(errno);
    ::close(fd);
    return "socketcan door: no interface " + m_opt.interface + ": " + e;
  }
  sockaddr_can addr{};
  addr.can_family = AF_CAN;
  addr.can_ifindex = ifr.ifr_ifindex;
  if (::bind(fd, reinterpret_cast<sockaddr*>(&addr), sizeof addr) != 0) {
    const std::string e = std::strerror(errno);
    ::close(fd);
    return "socketcan door: bind to " + m_opt.interface + ": " + e;
  }
  m_io = std::make_unique<Io>(m_runner.io_context(), fd);
  m_port = m_hub.add_port(m_opt.name + ":" + m_opt.interface,
                          [this](const CanFrame& f, bus::Ticks) { on_hub_frame(f); });
  start_read();
  return {};
}

void SocketcanDoor::close() {
  if (!m_io) return;
  m_hub.remove_port(m_port);
  boost::system::error_code ec;
  m_io->sd.cancel(ec);
  m_io->sd.close(ec);
  m_io.reset();
  m_queue.clear();
}

void SocketcanDoor::start_read() {
  std::weak_ptr<bool> alive = m_io->alive;
  m_io->sd.async_wait(Descriptor::wait_read, [this, alive](const boost::system::error_code& ec) {
    if (ec || alive.expired()) return;
    std::vector<CanFrame> frames;
    for (int i = 0; i < 1024; ++i) {  // bounded per wake-up
      can_frame k{};
      const ssize_t n = ::read(m_io->fd, &k, sizeof k);
      if (n == static_cast<ssize_t>(sizeof k)) {
        if ((k.can_id & CAN_ERR_FLAG) == 0) frames.push_back(from_kernel(k));
        continue;
      }
      if (n < 0 && errno == EINTR) continue;
      if (n < 0 && errno != EAGAIN && errno != EWOULDBLOCK) ++m_stats.errors;
      break;
    }
    if (!frames.empty()) {
      m_runner.post([this, alive, fs = std::move(frames)](bus::Ticks now) {
        if (alive.expired()) return;
        for (const CanFrame& f : fs) {
          ++m_stats.frames_in;
          m_hub.send(m_port, f, now);
        }
      });
    }
    start_read();
  });
}

void SocketcanDoor::on_hub_frame(const CanFrame& f) {
  if (!m_io) return;
  if (m_queue.size() >= m_opt.max_queue) {
    ++m_stats.dropped;
    return;
  }
  m_queue.push_back(f);
  if (!m_io->write_armed) flush();
}

void SocketcanDoor::flush() {
  while (!m_queue.empty()) {
    const can_frame k = to_kernel(m_queue.front());
    const ssize_t n = ::write(m_io->fd, &k, sizeof k);
    if (n == static_cast<ssize_t>(sizeof k)) {
      ++m_stats.frames_out;
      m_queue.pop_front();
      continue;
    }
    if (n < 0 && errno == EINTR) continue;
    if (n < 0 && (errno == EAGAIN || errno == EWOULDBLOCK || errno == ENOBUFS)) break;
    ++m_stats.errors;  // e.g. the interface went down: this frame is lost
    m_queue.pop_front();
  }
  if (!m_queue.empty() && !m_io->write_armed) {
    // ENOBUFS does not make the socket writable later by itself on every kernel; the wait is
    // still the right thing for EAGAIN, and the next hub frame retries either way.
    m_io->write_armed = true;
    std::weak_ptr<bool> alive = m_io->alive;
    m_io->sd.async_wait(Descriptor::wait_write, [this, alive](const boost::system::error_code& ec) {
      if (ec || alive.expired()) return;
      m_io->write_armed = false;
      flush();
    });
  }
}

}  // namespace pbvbus::gateways
