#include "pbvbus/gateways/modbus_rtu_port.hpp"

#include <algorithm>
#include <array>
#include <boost/asio/steady_timer.hpp>

namespace pbvbus::gateways {

struct ModbusRtuPort::Impl {
  Impl(boost::asio::io_context& io, ModbusHandler& h, const ModbusRtuOptions& opt)
      : handler(h), timer(io) {
    port = opt.device.empty() ? SerialPort::open_pty(io, opt.link)
                              : SerialPort::open_device(io, opt.device, opt.serial);
    silence = opt.silence;
    if (silence.count() <= 0) {
      using std::chrono::microseconds;
      silence = std::max(serial_char_time(opt.serial.baud, 3.5), microseconds(1750));
      if (port->is_pty()) silence = std::max(silence, microseconds(20'000));
    }
    sink = [this](const RtuFrame& f) { on_frame(f); };
    port->start([this](std::span<const std::uint8_t> b) { on_bytes(b); });
  }

  void on_bytes(std::span<const std::uint8_t> b) {
    framer.feed(b, sink);
    sync_bad();
    if (framer.pending() > 0) arm_silence();
  }

  void arm_silence() {
    // Re-armed on every read: the silence counts from the last octet received.
    timer.expires_after(silence);
    std::weak_ptr<bool> w = alive;
    timer.async_wait([this, w](const boost::system::error_code& ec) {
      if (ec || w.expired()) return;
      framer.silence(sink);
      sync_bad();
    });
  }

  void on_frame(const RtuFrame& f) {
    ++stats.requests;
    std::array<std::uint8_t, kModbusMaxPdu> rsp{};
    const bool broadcast = f.unit == 0;
    std::size_t n = handler.handle(f.unit, f.pdu, rsp, broadcast);
    if (broadcast || n == 0) {
      ++stats.no_reply;
      return;
    }
    if (n > kModbusMaxPdu) {  // a handler bug must not overrun: answer "server device failure"
      rsp[0] = static_cast<std::uint8_t>(f.pdu[0] | 0x80);
      rsp[1] = kExServerDeviceFailure;
      n = 2;
    }
    if (rsp[0] & 0x80) ++stats.exceptions;
    std::array<std::uint8_t, kModbusRtuMaxAdu> adu{};
    const std::size_t len =
        encode_rtu_adu(f.unit, std::span<const std::uint8_t>(rsp.data(), n), adu);
    if (port && len > 0) port->write(std::span<const std::uint8_t>(adu.data(), len));
  }

  void sync_bad() {
    const auto& s = framer.stats();
    stats.bad_frames = s.bad_crc + s.overlong + s.incomplete;
  }

  void close() {
    alive.reset();
    timer.cancel();
    if (port) port->close();
  }

  ModbusHandler& handler;
  std::unique_ptr<SerialPort> port;
  boost::asio::steady_timer timer;
  std::chrono::microseconds silence{0};
  RtuFramer framer;
  RtuFramer::Sink sink;
  ModbusDoorStats stats;
  std::shared_ptr<bool> alive = std::make_shared<bool>(true);
};

ModbusRtuPort::ModbusRtuPort(boost::asio::io_context& io, ModbusHandler& handler,
                             ModbusRtuOptions opt)
    : m(std::make_unique<Impl>(io, handler, opt)) {}

ModbusRtuPort::~ModbusRtuPort() {
  m->close();
}

const std::string& ModbusRtuPort::path() const {
  return m->port->path();
}
std::chrono::microseconds ModbusRtuPort::silence() const {
  return m->silence;
}
const ModbusDoorStats& ModbusRtuPort::stats() const {
  return m->stats;
}
const RtuFramer::Stats& ModbusRtuPort::framer_stats() const {
  return m->framer.stats();
}
const SerialPort::Stats& ModbusRtuPort::port_stats() const {
  return m->port->stats();
}
void ModbusRtuPort::close() {
  m->close();
}

}  // namespace pbvbus::gateways
