#pragma once
// A byte pipe for serial doors (Modbus RTU now, SLCAN may share it): a pseudo-terminal the door
// owns, or a real serial device set up with termios, read and written asynchronously on a
// Boost.Asio io_context (the paced run's). Never blocks.
//
// Pty (tools-and-formats.md §1.4; bus/src/pty_station.cpp does the same): posix_openpt, raw
// mode, and the port keeps its own handle on the slave side open, so a client may close and
// reopen path() without the master side reporting EIO/POLLHUP (which would make the event loop
// spin). An optional symlink `link` points at the slave path; it is replaced if it exists as a
// symlink and removed when the port closes. Baud rate and parity mean nothing on a pty (clients
// still set them; that succeeds).
//
// Device: opened O_NONBLOCK|O_NOCTTY, raw, 8 data bits, the given baud rate, parity (N, E, O) and
// stop bits (1, 2): 8N1, 8E1, 8O1, 8N2 (Modbus over Serial Line §2.5.1 requires 11 bits per
// character; 8N1 is accepted because tools use it).
//
// Output: write() tries at once; what the kernel does not take waits (up to `max_backlog`
// octets, then whole writes are refused and counted) and goes out when the descriptor is
// writable. Construction errors throw std::system_error / std::invalid_argument; nothing after
// that throws.

#include <boost/asio/io_context.hpp>
#include <chrono>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <string_view>

namespace pbvbus::gateways {

struct SerialSettings {
  std::uint32_t baud = 115200;
  char parity = 'N';  ///< 'N', 'E' or 'O'
  int stop_bits = 1;  ///< 1 or 2
};

/// "8N1", "8E1", "8O1", "8N2" (case-insensitive) -> parity and stop bits into `s`; false for
/// anything else (only 8 data bits exist in Modbus RTU).
bool parse_serial_format(std::string_view fmt, SerialSettings& s);

/// Time of `chars` characters of 11 bits (start, 8 data, parity or second stop, stop) at `baud`,
/// rounded up to whole microseconds.
std::chrono::microseconds serial_char_time(std::uint32_t baud, double chars = 1.0);

class SerialPort {
 public:
  using OnBytes = std::function<void(std::span<const std::uint8_t>)>;
  struct Stats {
    std::uint64_t bytes_in = 0;
    std::uint64_t bytes_out = 0;
    std::uint64_t writes_refused = 0;  ///< backlog full: the client is not reading
  };

  /// A new pty; `link` (may be empty) becomes a symlink to its slave path.
  static std::unique_ptr<SerialPort> open_pty(boost::asio::io_context& io, std::string link = {});
  /// A serial device (e.g. /dev/ttyUSB0) with the given settings.
  static std::unique_ptr<SerialPort> open_device(boost::asio::io_context& io, std::string path,
                                                 const SerialSettings& s);
  ~SerialPort();
  SerialPort(const SerialPort&) = delete;
  SerialPort& operator=(const SerialPort&) = delete;

  /// The path a client opens: the pty's slave (/dev/pts/N) or the device.
  const std::string& path() const { return m_path; }
  const std::string& link() const { return m_link; }
  bool is_pty() const { return m_slave >= 0; }

  /// Starts reading: `on_bytes` gets every chunk read, on the io_context's thread.
  void start(OnBytes on_bytes);
  /// Queues `bytes` for output without blocking; false (nothing queued) when the backlog is full.
  bool write(std::span<const std::uint8_t> bytes);
  /// Stops reading and writing; closes the descriptors and removes the link. Idempotent.
  void close();
  const Stats& stats() const { return m_stats; }
  void set_max_backlog(std::size_t n) { m_max_backlog = n; }

 private:
  SerialPort(boost::asio::io_context& io, int fd, int slave, std::string path, std::string link);
  struct Io;
  void read_loop();
  void flush();

  int m_fd = -1;     // master side or device
  int m_slave = -1;  // pty only: our handle on the slave side
  std::string m_path;
  std::string m_link;
  std::unique_ptr<Io> m_io;
  OnBytes m_on_bytes;
  std::string m_out;  // octets waiting for the descriptor to become writable
  std::size_t m_max_backlog = 64 * 1024;
  Stats m_stats;
};

}  // namespace pbvbus::gateways
