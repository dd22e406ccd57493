#pragma once
// A small register file behind the ModbusHandler seam, so the door tests do not depend on the
// gateway core. Written by hand from the Modbus Application Protocol V1.1b3 (§6.3 FC03, §6.6
// FC06, §6.12 FC16):
//  - unit 1: 16 holding registers (addresses 0..15), FC03 / FC06 / FC16;
//  - unit 2: a configured slave that is not in data exchange -> exception 0x0B;
//  - any other unit -> exception 0x0A (gateway path unavailable);
//  - another function code for unit 1 -> 0x01; an address outside 0..15 -> 0x02; a bad
//    quantity or byte count -> 0x03;
//  - broadcast (RTU unit 0): writes go to unit 1's registers, nothing is answered.
// It records every call so tests can assert what reached the core.
//
// Also here: driving a paced runner on the test thread while a client (a raw socket in a
// thread, or a child process) runs, and blocking raw-socket helpers for clients.

#include <arpa/inet.h>
#include <netinet/in.h>
#include <netinet/tcp.h>
#include <sys/socket.h>
#include <sys/time.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cerrno>
#include <chrono>
#include <cstdint>
#include <functional>
#include <future>
#include <span>
#include <vector>

#include "pbvbus/bus/paced_runner.hpp"
#include "pbvbus/bus/scheduler.hpp"
#include "pbvbus/bus/time.hpp"
#include "pbvbus/gateways/modbus_handler.hpp"

namespace pbvbus::gateways::test {

class RegisterFileHandler final : public ModbusHandler {
 public:
  struct Call {
    std::uint8_t unit;
    std::vector<std::uint8_t> pdu;
    bool broadcast;
  };

  std::array<std::uint16_t, 16> regs{};
  std::vector<Call> calls;
  bool record = true;  ///< off for floods and benchmarks

  std::size_t handle(std::uint8_t unit, std::span<const std::uint8_t> pdu,
                     std::span<std::uint8_t, kModbusMaxPdu> rsp, bool broadcast) override {
    if (record) calls.push_back({unit, {pdu.begin(), pdu.end()}, broadcast});
    if (pdu.empty()) return 0;
    const std::uint8_t fc = pdu[0];
    if (broadcast) {
      apply(pdu, rsp);  // carried out, never answered
      return 0;
    }
    if (unit == 2) return exception(fc, kExGatewayTargetFailed, rsp);
    if (unit != 1) return exception(fc, kExGatewayPathUnavailable, rsp);
    return apply(pdu, rsp);
  }

 private:
  static std::size_t exception(std::uint8_t fc, std::uint8_t code,
                               std::span<std::uint8_t, kModbusMaxPdu> rsp) {
    rsp[0] = static_cast<std::uint8_t>(fc | 0x80);
    rsp[1] = code;
    return 2;
  }
  static std::uint16_t be16(std::span<const std::uint8_t> p, std::size_t at) {
    return static_cast<std::uint16_t>(p[at] << 8 | p[at + 1]);
  }

  std::size_t apply(std::span<const std::uint8_t> pdu, std::span<std::uint8_t, kModbusMaxPdu> rsp) {
    const std::uint8_t fc = pdu[0];
    switch (fc) {
      case 0x03: {  // addr(2) qty(2) -> fc, byte count, registers
        if (pdu.size() != 5) return exception(fc, kExIllegalDataValue, rsp);
        const unsigned addr = be16(pdu, 1), qty = be16(pdu, 3);
        if (qty < 1 || qty > 125) return exception(fc, kExIllegalDataValue, rsp);
        if (addr + qty > regs.size()) return exception(fc, kExIllegalDataAddress, rsp);
        rsp[0] = fc;
        rsp[1] = static_cast<std::uint8_t>(2 * qty);
        for (unsigned i = 0; i < qty; ++i) {
          rsp[2 + 2 * i] = static_cast<std::uint8_t>(regs[addr + i] >> 8);
          rsp[3 + 2 * i] = static_cast<std::uint8_t>(regs[addr + i]);
        }
        return 2 + 2 * qty;
      }
      case 0x06: {  // addr(2) value(2) -> echo
        if (pdu.size() != 5) return exception(fc, kExIllegalDataValue, rsp);
        const unsigned addr = be16(pdu, 1);
        if (addr >= regs.size()) return exception(fc, kExIllegalDataAddress, rsp);
        regs[addr] = be16(pdu, 3);
        std::copy(pdu.begin(), pdu.end(), rsp.begin());
        return 5;
      }
      case 0x10: {  // addr(2) qty(2) bc(1) values -> fc addr qty
        if (pdu.size() < 6) return exception(fc, kExIllegalDataValue, rsp);
        const unsigned addr = be16(pdu, 1), qty = be16(pdu, 3), bc = pdu[5];
        if (qty < 1 || qty > 123 || bc != 2 * qty || pdu.size() != 6 + bc)
          return exception(fc, kExIllegalDataValue, rsp);
        if (addr + qty > regs.size()) return exception(fc, kExIllegalDataAddress, rsp);
        for (unsigned i = 0; i < qty; ++i) regs[addr + i] = be16(pdu, 6 + 2 * i);
        std::copy(pdu.begin(), pdu.begin() + 5, rsp.begin());
        return 5;
      }
      default:
        return exception(fc, kExIllegalFunction, rsp);
    }
  }
};

/// Runs the paced runner in 5 ms virtual slices until `done()` or `limit` of wall time passed
/// (a generous upper bound for a client to finish, never an assertion on speed).
inline bool drive_until(bus::PacedRunner& runner, const std::function<bool()>& done,
                        std::chrono::milliseconds limit = std::chrono::seconds(20)) {
  const auto until = std::chrono::steady_clock::now() + limit;
  while (!done()) {
    if (std::chrono::steady_clock::now() > until) return false;
    runner.run_for(5 * bus::kTicksPerMs);
  }
  return true;
}

/// Runs `client` on its own thread while the test thread drives the runner; returns its result.
template <class F>
auto with_client(bus::PacedRunner& runner, F client,
                 std::chrono::milliseconds limit = std::chrono::seconds(20)) {
  auto fut = std::async(std::launch::async, std::move(client));
  drive_until(
      runner, [&] { return fut.wait_for(std::chrono::seconds(0)) == std::future_status::ready; },
      limit);
  return fut.get();  // if the limit passed, the client's own receive timeout ends it
}

/// A blocking TCP client socket to 127.0.0.1:port with a 10 s receive/send timeout; -1 on error.
inline int tcp_connect(std::uint16_t port, int rcvbuf = 0) {
  const int fd = ::socket(AF_INET, SOCK_STREAM | SOCK_CLOEXEC, 0);
  if (fd < 0) return -1;
  timeval tv{10, 0};
  ::setsockopt(fd, SOL_SOCKET, SO_RCVTIMEO, &tv, sizeof tv);
  ::setsockopt(fd, SOL_SOCKET, SO_SNDTIMEO, &tv, sizeof tv);
  if (rcvbuf > 0) ::setsockopt(fd, SOL_SOCKET, SO_RCVBUF, &rcvbuf, sizeof rcvbuf);
  sockaddr_in a{};
  a.sin_family = AF_INET;
  a.sin_port = htons(port);
  a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  if (::connect(fd, reinterpret_cast<sockaddr*>(&a), sizeof a) != 0) {
    ::close(fd);
    return -1;
  }
  return fd;
}

inline bool send_all(int fd, std::span<const std::uint8_t> b) {
  while (!b.empty()) {
    const ssize_t n = ::send(fd, b.data(), b.size(), MSG_NOSIGNAL);
    if (n <= 0) return false;
    b = b.subspan(static_cast<std::size_t>(n));
  }
  return true;
}

/// Receives exactly n octets; fewer on EOF, error or timeout.
inline std::vector<std::uint8_t> recv_n(int fd, std::size_t n) {
  std::vector<std::uint8_t> out(n);
  std::size_t got = 0;
  while (got < n) {
    const ssize_t r = ::recv(fd, out.data() + got, n - got, 0);
    if (r <= 0) break;
    got += static_cast<std::size_t>(r);
  }
  out.resize(got);
  return out;
}

/// True when the peer has closed (EOF or reset) within the socket's receive timeout; octets
/// that still arrive before the close are skipped.
inline bool wait_closed(int fd) {
  std::uint8_t b[512];
  for (;;) {
    const ssize_t r = ::recv(fd, b, sizeof b, 0);
    if (r == 0) return true;
    if (r < 0) return errno == ECONNRESET || errno == EPIPE;
  }
}

}  // namespace pbvbus::gateways::test
