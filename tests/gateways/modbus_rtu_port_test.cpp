// The Modbus RTU door on a pty (and on a "device": another pty's slave opened with termios),
// with golden frames. Every CRC below was worked out with the bitwise procedure of Modbus over
// Serial Line §6.2.2 (reference_crc() in modbus_frame_parser_test.cpp, pinned there to the
// spec's example), low byte first:
//   01 03 00 00 00 02 -> C4 0B      01 03 04 00 07 00 08 -> 4A 34
//   01 06 00 05 04 D2 -> 1B 56      00 06 00 01 00 07    -> 98 19 (broadcast)
//   01 03 00 01 00 01 -> D5 CA      01 03 02 00 07       -> F9 86
//   01 03 00 00 00 01 -> 84 0A      01 03 02 CA FE       -> 6F 64
// No test waits for the absence of a reply: after a frame that must get none (bad CRC,
// broadcast), the client sends a good request and asserts that the first octets it reads are
// that request's reply.

#include "pbvbus/gateways/modbus_rtu_port.hpp"

#include <fcntl.h>
#include <gtest/gtest.h>
#include <poll.h>
#include <sys/stat.h>
#include <termios.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <thread>

#include "hex.hpp"
#include "modbus_test_handler.hpp"

namespace pbvbus::gateways {
namespace {

using namespace std::chrono_literals;
using pbvbus::test::bytes_from_hex;
using pbvbus::test::to_hex;

/// Opens the pty like a client (raw), writes each frame (`gap` apart), reads `want` octets
/// (10 s upper bound), closes.
std::string rtu_client(const std::string& path, const std::vector<std::string>& frames,
                       std::size_t want, std::chrono::milliseconds gap = 100ms) {
  const int fd = ::open(path.c_str(), O_RDWR | O_NOCTTY);
  if (fd < 0) return "open failed";
  termios t{};
  ::tcgetattr(fd, &t);
  ::cfmakeraw(&t);
  ::tcsetattr(fd, TCSANOW, &t);
  for (std::size_t i = 0; i < frames.size(); ++i) {
    if (i > 0) std::this_thread::sleep_for(gap);
    const auto b = bytes_from_hex(frames[i]);
    if (::write(fd, b.data(), b.size()) != static_cast<ssize_t>(b.size())) {
      ::close(fd);
      return "write failed";
    }
  }
  std::vector<std::uint8_t> got;
  const auto until = std::chrono::steady_clock::now() + 10s;
  while (got.size() < want && std::chrono::steady_clock::now() < until) {
    pollfd p{fd, POLLIN, 0};
    if (::poll(&p, 1, 100) <= 0) continue;
    std::uint8_t buf[256];
    const ssize_t n = ::read(fd, buf, std::min(sizeof buf, want - got.size()));
    if (n > 0) got.insert(got.end(), buf, buf + n);
  }
  ::close(fd);
  return to_hex(got);
}

std::uint16_t crc_bitwise(const std::vector<std::uint8_t>& b) {
  unsigned crc = 0xFFFF;
  for (auto o : b) {
    crc ^= o;
    for (int i = 0; i < 8; ++i) crc = (crc & 1u) ? (crc >> 1) ^ 0xA001u : crc >> 1;
  }
  return static_cast<std::uint16_t>(crc);
}

class ModbusRtuDoor : public ::testing::Test {
 protected:
  void SetUp() override { port = std::make_unique<ModbusRtuPort>(runner.io_context(), handler); }
  std::string exchange(const std::vector<std::string>& frames, std::size_t want) {
    return test::with_client(
        runner, [p = port->path(), frames, want] { return rtu_client(p, frames, want); });
  }
  bus::Scheduler sched;
  bus::PacedRunner runner{sched};
  test::RegisterFileHandler handler;
  std::unique_ptr<ModbusRtuPort> port;
};

TEST_F(ModbusRtuDoor, GoldenFc03OnThePty) {
  handler.regs[0] = 7;
  handler.regs[1] = 8;
  // unit 1, FC03, bc 4, 0007 0008, CRC 4A 34.
  EXPECT_EQ(exchange({"01 03 00 00 00 02 C4 0B"}, 9), "01 03 04 00 07 00 08 4A 34");
  ASSERT_EQ(handler.calls.size(), 1u);
  EXPECT_EQ(to_hex(handler.calls[0].pdu), "03 00 00 00 02");  // unit and CRC stripped
  EXPECT_FALSE(handler.calls[0].broadcast);
  EXPECT_EQ(port->stats().requests, 1u);
  EXPECT_EQ(port->stats().bad_frames, 0u);
}

TEST_F(ModbusRtuDoor, Fc06WriteIsEchoed) {
  EXPECT_EQ(exchange({"01 06 00 05 04 D2 1B 56"}, 8), "01 06 00 05 04 D2 1B 56");
  EXPECT_EQ(handler.regs[5], 1234);
}

TEST_F(ModbusRtuDoor, BadCrcGetsNoReplyAndIsCounted) {
  handler.regs[0] = 0xCAFE;
  // C4 0B -> C4 0C: no reply; the next good request (FC03 reg 0) is answered 01 03 02 CA FE 6F 64.
  EXPECT_EQ(exchange({"01 03 00 00 00 02 C4 0C", "01 03 00 00 00 01 84 0A"}, 7),
            "01 03 02 CA FE 6F 64");
  EXPECT_EQ(handler.calls.size(), 1u);
  EXPECT_EQ(port->stats().requests, 1u);
  EXPECT_GE(port->stats().bad_frames, 1u);
  EXPECT_EQ(port->framer_stats().bad_crc, 1u);
}

TEST_F(ModbusRtuDoor, BroadcastIsCarriedOutAndNotAnswered) {
  // Broadcast FC06 register 1 = 7, then read register 1 of unit 1: 01 03 02 00 07 F9 86.
  EXPECT_EQ(exchange({"00 06 00 01 00 07 98 19", "01 03 00 01 00 01 D5 CA"}, 7),
            "01 03 02 00 07 F9 86");
  ASSERT_EQ(handler.calls.size(), 2u);
  EXPECT_EQ(handler.calls[0].unit, 0);
  EXPECT_TRUE(handler.calls[0].broadcast);
  EXPECT_EQ(port->stats().no_reply, 1u);
  EXPECT_EQ(port->stats().requests, 2u);
}

TEST_F(ModbusRtuDoor, ExceptionForAnUnknownUnitCarriesItsCrc) {
  // 09 83 0A + CRC by the bitwise procedure.
  const std::uint16_t crc = crc_bitwise({0x09, 0x83, 0x0A});
  char want[64];
  std::snprintf(want, sizeof want, "09 83 0A %02X %02X", crc & 0xFF, crc >> 8);
  // Request: 09 03 00 00 00 01 + its CRC (bitwise procedure).
  std::vector<std::uint8_t> req = bytes_from_hex("09 03 00 00 00 01");
  const std::uint16_t rc = crc_bitwise(req);
  req.push_back(static_cast<std::uint8_t>(rc & 0xFF));
  req.push_back(static_cast<std::uint8_t>(rc >> 8));
  EXPECT_EQ(exchange({to_hex(req)}, 5), want);
  EXPECT_EQ(port->stats().exceptions, 1u);
}

TEST_F(ModbusRtuDoor, AClientMayCloseAndReopenThePty) {
  handler.regs[0] = 7;
  handler.regs[1] = 8;
  for (int i = 0; i < 3; ++i)
    EXPECT_EQ(exchange({"01 03 00 00 00 02 C4 0B"}, 9), "01 03 04 00 07 00 08 4A 34") << i;
  EXPECT_EQ(port->stats().requests, 3u);
}

TEST(ModbusRtuPort, LinkPointsAtThePtyAndGoesAwayOnClose) {
  bus::Scheduler sched;
  bus::PacedRunner runner{sched};
  test::RegisterFileHandler handler;
  const auto dir =
      std::filesystem::temp_directory_path() / ("pbvbus-mbrtu-" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  const std::string link = (dir / "ttyMB0").string();
  ModbusRtuOptions o;
  o.link = link;
  auto port = std::make_unique<ModbusRtuPort>(runner.io_context(), handler, o);
  EXPECT_EQ(std::filesystem::read_symlink(link).string(), port->path());
  EXPECT_GE(port->silence(), 20ms);  // the pty default
  handler.regs[0] = 7;
  handler.regs[1] = 8;
  const auto got =
      test::with_client(runner, [&] { return rtu_client(link, {"01 03 00 00 00 02 C4 0B"}, 9); });
  EXPECT_EQ(got, "01 03 04 00 07 00 08 4A 34");
  port->close();
  port->close();
  struct stat st {};
  EXPECT_NE(::lstat(link.c_str(), &st), 0);
  port.reset();
  std::filesystem::remove_all(dir);
}

TEST(ModbusRtuPort, OnADeviceWithTermiosSettings) {
  // The "cable": a pty whose slave the door opens as a serial device with 19200 8N2; the test
  // plays the client on the pty's master side. Everything on the one io_context.
  bus::Scheduler sched;
  bus::PacedRunner runner{sched};
  test::RegisterFileHandler handler;
  handler.regs[0] = 7;
  handler.regs[1] = 8;
  auto cable = SerialPort::open_pty(runner.io_context());
  ModbusRtuOptions o;
  o.device = cable->path();
  ASSERT_TRUE(parse_serial_format("8N2", o.serial));
  o.serial.baud = 19200;
  ModbusRtuPort door(runner.io_context(), handler, o);
  EXPECT_EQ(door.path(), cable->path());
  // t3.5 at 19200 baud: 3.5 * 11 bits / 19200 = 2005.2 us -> 2006 us (above the 1750 us floor).
  EXPECT_EQ(door.silence(), std::chrono::microseconds(2006));
  std::vector<std::uint8_t> got;
  cable->start([&](std::span<const std::uint8_t> b) { got.insert(got.end(), b.begin(), b.end()); });
  ASSERT_TRUE(cable->write(bytes_from_hex("01 03 00 00 00 02 C4 0B")));
  EXPECT_TRUE(test::drive_until(runner, [&] { return got.size() >= 9; }));
  EXPECT_EQ(to_hex(got), "01 03 04 00 07 00 08 4A 34");
  termios t{};
  const int fd = ::open(cable->path().c_str(), O_RDWR | O_NOCTTY | O_NONBLOCK);
  ASSERT_GE(fd, 0);
  ASSERT_EQ(::tcgetattr(fd, &t), 0);
  // A Linux pty forces CS8 and clears PARENB whatever is set (pty_set_termios), so parity can
  // only be seen on a real device; stop bits and speed are kept.
  EXPECT_TRUE(t.c_cflag & CSTOPB);
  EXPECT_EQ(t.c_cflag & CSIZE, static_cast<tcflag_t>(CS8));
  EXPECT_EQ(::cfgetospeed(&t), B19200);
  ::close(fd);
}

TEST(ModbusRtuPort, OpenErrorsThrowAtConstructionOnly) {
  bus::Scheduler sched;
  bus::PacedRunner runner{sched};
  test::RegisterFileHandler handler;
  ModbusRtuOptions o;
  o.device = "/nonexistent/ttyUSB9";
  EXPECT_THROW(ModbusRtuPort(runner.io_context(), handler, o), std::system_error);
  auto cable = SerialPort::open_pty(runner.io_context());
  o.device = cable->path();
  o.serial.baud = 12345;
  EXPECT_THROW(ModbusRtuPort(runner.io_context(), handler, o), std::invalid_argument);
}

TEST(SerialFormat, ParsesTheModbusCharacterFormats) {
  SerialSettings s;
  EXPECT_TRUE(parse_serial_format("8N1", s));
  EXPECT_EQ(s.parity, 'N');
  EXPECT_EQ(s.stop_bits, 1);
  EXPECT_TRUE(parse_serial_format("8e1", s));
  EXPECT_EQ(s.parity, 'E');
  EXPECT_TRUE(parse_serial_format("8O1", s));
  EXPECT_EQ(s.parity, 'O');
  EXPECT_TRUE(parse_serial_format("8N2", s));
  EXPECT_EQ(s.stop_bits, 2);
  for (const char* bad : {"7E1", "8E2", "8X1", "8N3", "", "8N"})
    EXPECT_FALSE(parse_serial_format(bad, s)) << bad;
  // One character of 11 bits at 115200 baud: 95.49 us -> 96 us; t3.5: 334.2 us -> 335 us.
  EXPECT_EQ(serial_char_time(115200), std::chrono::microseconds(96));
  EXPECT_EQ(serial_char_time(115200, 3.5), std::chrono::microseconds(335));
}

}  // namespace
}  // namespace pbvbus::gateways

namespace pbvbus::gateways {
namespace {

TEST(SerialPort, AClientThatNeverReadsGetsWritesRefusedNotABlockedBus) {
  boost::asio::io_context io;
  auto port = SerialPort::open_pty(io);
  port->set_max_backlog(256);
  // Nobody reads the slave side: the pty's buffer fills, then 256 octets wait, then whole
  // writes are refused. Every call returns at once (a blocking write would hang this test).
  const std::vector<std::uint8_t> chunk(64, 0x55);
  int refused = 0;
  for (int i = 0; i < 10'000 && refused == 0; ++i)
    if (!port->write(chunk)) ++refused;
  EXPECT_EQ(refused, 1);
  EXPECT_EQ(port->stats().writes_refused, 1u);
  EXPECT_GT(port->stats().bytes_out, 0u);
}

}  // namespace
}  // namespace pbvbus::gateways
