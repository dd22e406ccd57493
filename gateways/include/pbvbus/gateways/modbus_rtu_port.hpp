#pragma once
// The Modbus RTU door (docs/gateway-modbus.md): a serial line (a pty the door owns, or a real serial device)
// on the paced run's io_context; requests are framed by the RtuFramer (modbus_frame.hpp) and
// handed to a ModbusHandler (the gateway core); its response PDU goes back as unit + PDU + CRC.
//
// Decisions (also in docs/gateway-modbus-doors.md):
//  - Every unit 1..255 is handed to the handler (it knows which units exist and answers 0x0A /
//    0x0B as a gateway does). Unit 0 is the broadcast address (Modbus over Serial Line §2.2):
//    handle(0, pdu, rsp, broadcast=true); whatever it returns, nothing is sent (no_reply).
//  - A frame with a bad CRC gets no reply (the spec's rule: the master times out) and counts in
//    bad_frames, as do overlong candidates and leftovers that silence ends. Resync rule: see
//    modbus_frame.hpp.
//  - t3.5 silence ends a frame of unknown length: a wall-time timer (the client's timing is
//    wall time) armed after every read that leaves octets pending. Its default is 3.5
//    character times at the configured baud rate, but at least 1.75 ms (the spec's fixed value
//    above 19200 baud); on a pty, where a client's write() can reach us in pieces scheduled
//    milliseconds apart, at least 20 ms. Configurable (`silence`).
//  - Requests are answered one at a time in arrival order; the reply goes out without blocking
//    (SerialPort backlog). A client that never reads cannot stall the bus: once 64 KiB of replies
//    wait, further replies are dropped (counted by the SerialPort).
//  - The door reads on the io_context like the TCP door; one turn handles what the line holds
//    at that moment (a pty buffers about 4 KiB: at most a few hundred requests, each a handler
//    call of microseconds), then the io_context runs the bus's timer again.

#include <boost/asio/io_context.hpp>
#include <chrono>
#include <memory>
#include <string>

#include "pbvbus/gateways/modbus_frame.hpp"
#include "pbvbus/gateways/modbus_handler.hpp"
#include "pbvbus/gateways/serial_port.hpp"

namespace pbvbus::gateways {

struct ModbusRtuOptions {
  std::string device;     ///< a serial device path; empty = a new pty
  std::string link;       ///< pty only: a symlink to its slave path (e.g. "./ttyMB0"); may be empty
  SerialSettings serial;  ///< device only (a pty ignores it, except for the silence default)
  std::chrono::microseconds silence{0};  ///< t3.5; zero = the default described above
};

class ModbusRtuPort {
 public:
  /// Opens the pty or device at once; throws std::system_error / std::invalid_argument.
  ModbusRtuPort(boost::asio::io_context& io, ModbusHandler& handler, ModbusRtuOptions opt = {});
  ~ModbusRtuPort();
  ModbusRtuPort(const ModbusRtuPort&) = delete;
  ModbusRtuPort& operator=(const ModbusRtuPort&) = delete;

  /// What a client opens: the pty's slave path or the device.
  const std::string& path() const;
  /// The t3.5 silence in use.
  std::chrono::microseconds silence() const;
  const ModbusDoorStats& stats() const;
  const RtuFramer::Stats& framer_stats() const;
  const SerialPort::Stats& port_stats() const;
  /// Stops the door and closes the line (and removes the link). Idempotent.
  void close();

 private:
  struct Impl;
  std::unique_ptr<Impl> m;
};

}  // namespace pbvbus::gateways
