#include "pbvbus/gateways/modbus_engine.hpp"

#include <modbus/modbus.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <array>

namespace pbvbus::gateways {
namespace {

constexpr std::size_t kMbapLen = 7;
constexpr int kSpace = 0x10000;  // every address 0..65535 in the libmodbus mapping

}  // namespace

ModbusEngine::ModbusEngine() {
  if (::socketpair(AF_UNIX, SOCK_STREAM, 0, m_pair) != 0) {
    m_pair[0] = m_pair[1] = -1;
    return;
  }
  m_ctx = modbus_new_tcp(nullptr, 0);
  if (m_ctx) modbus_set_socket(m_ctx, m_pair[0]);
  m_mapping = modbus_mapping_new_start_address(0, kSpace, 0, kSpace, 0, kSpace, 0, kSpace);
}

ModbusEngine::~ModbusEngine() {
  if (m_ctx) {
    modbus_set_socket(m_ctx, -1);  // we own the pair: libmodbus must not close it
    modbus_free(m_ctx);
  }
  if (m_mapping) modbus_mapping_free(m_mapping);
  for (int fd : m_pair)
    if (fd >= 0) ::close(fd);
}

std::size_t ModbusEngine::reply(std::uint8_t unit, std::span<const std::uint8_t> pdu,
                                std::span<std::uint8_t, kModbusMaxPdu> rsp) {
  return run(unit, pdu, 0, rsp);
}

std::size_t ModbusEngine::exception(std::uint8_t unit, std::span<const std::uint8_t> pdu,
                                    std::uint8_t code, std::span<std::uint8_t, kModbusMaxPdu> rsp) {
  // libmodbus builds FC + 0x80 in an int and truncates: for a function code that already has
  // bit 7 set (never a valid request) answer by hand with bit 7 kept.
  if (pdu[0] >= 0x80 || !m_ctx) {
    rsp[0] = static_cast<std::uint8_t>(pdu[0] | 0x80);
    rsp[1] = code;
    return 2;
  }
  return run(unit, pdu, code, rsp);
}

std::size_t ModbusEngine::run(std::uint8_t unit, std::span<const std::uint8_t> pdu,
                              std::uint8_t exception_code,
                              std::span<std::uint8_t, kModbusMaxPdu> rsp) {
  std::array<std::uint8_t, kMbapLen + kModbusMaxPdu> adu{};
  const auto len = static_cast<std::uint16_t>(pdu.size() + 1);
  adu[4] = static_cast<std::uint8_t>(len >> 8);  // TID 0, protocol 0, length, unit
  adu[5] = static_cast<std::uint8_t>(len & 0xFF);
  adu[6] = unit;
  std::copy(pdu.begin(), pdu.end(), adu.begin() + kMbapLen);
  const int adu_len = static_cast<int>(kMbapLen + pdu.size());
  int rc = -1;
  if (m_ctx && (exception_code != 0 || m_mapping))
    rc = exception_code == 0 ? modbus_reply(m_ctx, adu.data(), adu_len, m_mapping)
                             : modbus_reply_exception(m_ctx, adu.data(), exception_code);
  std::array<std::uint8_t, kMbapLen + kModbusMaxPdu + 8> back{};
  std::size_t got = 0;
  if (rc > 0) {
    // The pair's buffer holds far more than one ADU, so the whole answer is there already.
    while (got < back.size()) {
      const ssize_t r = ::recv(m_pair[1], back.data() + got, back.size() - got, MSG_DONTWAIT);
      if (r <= 0) break;
      got += static_cast<std::size_t>(r);
    }
  }
  if (got <= kMbapLen || got - kMbapLen > kModbusMaxPdu) {
    // The engine failed (cannot happen for pre-checked requests): answer 0x04 by hand.
    rsp[0] = static_cast<std::uint8_t>(pdu[0] | 0x80);
    rsp[1] = kExServerDeviceFailure;
    return 2;
  }
  const std::size_t n = got - kMbapLen;
  std::copy_n(back.begin() + kMbapLen, n, rsp.begin());
  return n;
}

}  // namespace pbvbus::gateways
