#include "pbvbus/gateways/serial_port.hpp"

#include "pbvbus/bus/pty.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <termios.h>
#include <unistd.h>

#include <boost/asio/posix/stream_descriptor.hpp>
#include <cctype>
#include <cerrno>
#include <cmath>
#include <stdexcept>
#include <system_error>

namespace pbvbus::gateways {

namespace {

[[noreturn]] void throw_errno(const std::string& what) {
  throw std::system_error(errno, std::generic_category(), what);
}

std::optional<speed_t> baud_constant(std::uint32_t baud) {
  switch (baud) {
    case 1200:
      return B1200;
    case 2400:
      return B2400;
    case 4800:
      return B4800;
    case 9600:
      return B9600;
    case 19200:
      return B19200;
    case 38400:
      return B38400;
    case 57600:
      return B57600;
    case 115200:
      return B115200;
    case 230400:
      return B230400;
    case 460800:
      return B460800;
    case 921600:
      return B921600;
    default:
      return std::nullopt;
  }
}

void make_raw(int fd, const SerialSettings* s, const std::string& what) {
  termios t{};
  if (::tcgetattr(fd, &t) != 0) throw_errno("tcgetattr " + what);
  ::cfmakeraw(&t);  // 8 bits, no echo, no line editing, no CR/LF mapping
  t.c_cc[VMIN] = 1;
  t.c_cc[VTIME] = 0;
  if (s) {
    const auto sp = baud_constant(s->baud);
    if (!sp)
      throw std::invalid_argument("serial port " + what + ": unsupported baud rate " +
                                  std::to_string(s->baud));
    ::cfsetispeed(&t, *sp);
    ::cfsetospeed(&t, *sp);
    t.c_cflag |= CLOCAL | CREAD;
    t.c_cflag &= ~static_cast<tcflag_t>(PARENB | PARODD | CSTOPB | CRTSCTS);
    if (s->parity == 'E') t.c_cflag |= PARENB;
    if (s->parity == 'O') t.c_cflag |= PARENB | PARODD;
    if (s->stop_bits == 2) t.c_cflag |= CSTOPB;
  }
  if (::tcsetattr(fd, TCSANOW, &t) != 0) throw_errno("tcsetattr " + what);
}

}  // namespace

bool parse_serial_format(std::string_view fmt, SerialSettings& s) {
  if (fmt.size() != 3 || fmt[0] != '8') return false;
  const char p = static_cast<char>(std::toupper(static_cast<unsigned char>(fmt[1])));
  if (p != 'N' && p != 'E' && p != 'O') return false;
  if (fmt[2] != '1' && fmt[2] != '2') return false;
  const int stop = fmt[2] - '0';
  if (stop == 2 && p != 'N') return false;  // 8E2/8O2 would be 12 bits: not Modbus RTU
  s.parity = p;
  s.stop_bits = stop;
  return true;
}

std::chrono::microseconds serial_char_time(std::uint32_t baud, double chars) {
  if (baud == 0) return std::chrono::microseconds(0);
  return std::chrono::microseconds(
      static_cast<std::int64_t>(std::ceil(chars * 11.0 * 1e6 / static_cast<double>(baud))));
}

struct SerialPort::Io {
  Io(boost::asio::io_context& io, int fd) : sd(io, fd) {}
  ~Io() {
    boost::system::error_code ec;
    sd.cancel(ec);
    sd.close(ec);  // closes our dup only
  }
  boost::asio::posix::stream_descriptor sd;
  std::shared_ptr<bool> alive = std::make_shared<bool>(true);
  bool write_armed = false;
  bool reading = false;
};

SerialPort::SerialPort(boost::asio::io_context& io, int fd, int slave, std::string path,
                       std::string link)
    : m_fd(fd), m_slave(slave), m_path(std::move(path)), m_link(std::move(link)) {
  const int dup = ::fcntl(m_fd, F_DUPFD_CLOEXEC, 0);
  if (dup < 0) {
    const int e = errno;
    if (m_slave >= 0) ::close(m_slave);
    ::close(m_fd);
    throw std::system_error(e, std::generic_category(), "dup serial descriptor");
  }
  m_io = std::make_unique<Io>(io, dup);
}

std::unique_ptr<SerialPort> SerialPort::open_pty(boost::asio::io_context& io, std::string link) {
  const bus::Pty pty = bus::open_pty();
  if (!link.empty()) {
    const std::string e = bus::make_pty_link(pty.path, link);
    if (!e.empty()) {
      ::close(pty.slave);
      ::close(pty.master);
      throw std::runtime_error(e);
    }
  }
  return std::unique_ptr<SerialPort>(new SerialPort(io, pty.master, pty.slave, pty.path, link));
}

std::unique_ptr<SerialPort> SerialPort::open_device(boost::asio::io_context& io, std::string path,
                                                    const SerialSettings& s) {
  if ((s.parity != 'N' && s.parity != 'E' && s.parity != 'O') ||
      (s.stop_bits != 1 && s.stop_bits != 2))
    throw std::invalid_argument("serial port " + path + ": parity N/E/O and 1 or 2 stop bits");
  const int fd = ::open(path.c_str(), O_RDWR | O_NOCTTY | O_NONBLOCK | O_CLOEXEC);
  if (fd < 0) throw_errno("open " + path);
  try {
    make_raw(fd, &s, path);
  } catch (...) {
    ::close(fd);
    throw;
  }
  return std::unique_ptr<SerialPort>(new SerialPort(io, fd, -1, path, {}));
}

SerialPort::~SerialPort() {
  close();
}

void SerialPort::close() {
  m_io.reset();
  if (m_slave >= 0) ::close(m_slave);
  if (m_fd >= 0) ::close(m_fd);
  m_slave = m_fd = -1;
  if (!m_link.empty()) {
    struct stat st {};
    if (::lstat(m_link.c_str(), &st) == 0 && S_ISLNK(st.st_mode)) ::unlink(m_link.c_str());
    m_link.clear();
  }
}

void SerialPort::start(OnBytes on_bytes) {
  m_on_bytes = std::move(on_bytes);
  if (m_io && !m_io->reading) {
    m_io->reading = true;
    read_loop();
  }
}

void SerialPort::read_loop() {
  std::weak_ptr<bool> alive = m_io->alive;
  m_io->sd.async_wait(
      boost::asio::posix::stream_descriptor::wait_read,
      [this, alive](const boost::system::error_code& ec) {
        if (ec || alive.expired()) return;
        std::uint8_t buf[1024];
        for (;;) {
          const ssize_t n = ::read(m_fd, buf, sizeof buf);
          if (n > 0) {
            m_stats.bytes_in += static_cast<std::size_t>(n);
            if (m_on_bytes)
              m_on_bytes(std::span<const std::uint8_t>(buf, static_cast<std::size_t>(n)));
            if (alive.expired()) return;  // the callback closed the port
            continue;
          }
          if (n < 0 && errno == EINTR) continue;
          if (n < 0 && (errno == EAGAIN || errno == EWOULDBLOCK)) break;
          // EOF or an error (device gone): stop instead of spinning.
          m_io->reading = false;
          return;
        }
        read_loop();
      });
}

bool SerialPort::write(std::span<const std::uint8_t> bytes) {
  if (m_fd < 0) return false;
  if (m_out.size() + bytes.size() > m_max_backlog) {
    flush();
    if (m_out.size() + bytes.size() > m_max_backlog) {
      ++m_stats.writes_refused;
      return false;
    }
  }
  m_out.append(reinterpret_cast<const char*>(bytes.data()), bytes.size());
  flush();
  return true;
}

void SerialPort::flush() {
  std::size_t done = 0;
  while (done < m_out.size()) {
    const ssize_t n = ::write(m_fd, m_out.data() + done, m_out.size() - done);
    if (n > 0) {
      done += static_cast<std::size_t>(n);
      continue;
    }
    if (n < 0 && errno == EINTR) continue;
    break;  // EAGAIN: the client is not reading; anything else: try again when writable
  }
  m_stats.bytes_out += done;
  m_out.erase(0, done);
  if (!m_out.empty() && m_io && !m_io->write_armed) {
    m_io->write_armed = true;
    std::weak_ptr<bool> alive = m_io->alive;
    m_io->sd.async_wait(boost::asio::posix::stream_descriptor::wait_write,
                        [this, alive](const boost::system::error_code& ec) {
                          if (ec || alive.expired()) return;
                          m_io->write_armed = false;
                          flush();
                        });
  }
}

}  // namespace pbvbus::gateways
