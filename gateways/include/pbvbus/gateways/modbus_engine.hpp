#pragma once
// libmodbus as a PDU engine (tools-and-formats §1.2/§1.3 Pattern A; docs/gateway-modbus.md),
// shared by every Modbus core of this layer (the DP gateway, the Quantum state-RAM handler).
//
// One never-connected `modbus_new_tcp(nullptr, 0)` context, its socket one end of an AF_UNIX
// socketpair, and a full-size `modbus_mapping_t` (every address 0..65535 of the four tables).
// The caller pre-checks a request (modbus_pdu.hpp) against its own tables, fills only the
// requested ranges of mapping(), and calls reply(): the PDU is wrapped in an MBAP header,
// `modbus_reply()` writes the answer into the pair, the answer is read back and the MBAP header
// stripped. After a write the written values are in mapping(), where the caller copies them
// back. libmodbus therefore never sees a request that is not well-formed. The context's
// MODBUS_ERROR_RECOVERY_LINK is never set; `modbus_set_socket(ctx, -1)` before `modbus_free`
// (the engine closes the pair itself).

#include <cstddef>
#include <cstdint>
#include <span>

#include "pbvbus/gateways/modbus_handler.hpp"

struct _modbus;
struct _modbus_mapping_t;

namespace pbvbus::gateways {

class ModbusEngine {
 public:
  /// Never throws for resource failures: if libmodbus or the socketpair cannot be set up, ok()
  /// is false (reply() and exception() then answer by hand, 0x04 resp. the given code).
  ModbusEngine();
  ~ModbusEngine();
  ModbusEngine(const ModbusEngine&) = delete;
  ModbusEngine& operator=(const ModbusEngine&) = delete;

  bool ok() const { return m_ctx != nullptr && m_mapping != nullptr; }
  /// The full-size mapping. Only while ok().
  _modbus_mapping_t& mapping() { return *m_mapping; }

  /// Runs modbus_reply for a pre-checked request PDU (1..253 octets) of `unit` and copies the
  /// answer PDU into `rsp`; returns its length. An engine failure (cannot happen for
  /// pre-checked requests) is answered 0x04 by hand.
  std::size_t reply(std::uint8_t unit, std::span<const std::uint8_t> pdu,
                    std::span<std::uint8_t, kModbusMaxPdu> rsp);
  /// The exception response FC|0x80 + `code` (modbus_reply_exception). `pdu` must not be empty.
  std::size_t exception(std::uint8_t unit, std::span<const std::uint8_t> pdu, std::uint8_t code,
                        std::span<std::uint8_t, kModbusMaxPdu> rsp);

 private:
  std::size_t run(std::uint8_t unit, std::span<const std::uint8_t> pdu, std::uint8_t exception_code,
                  std::span<std::uint8_t, kModbusMaxPdu> rsp);

  _modbus* m_ctx = nullptr;
  _modbus_mapping_t* m_mapping = nullptr;
  int m_pair[2] = {-1, -1};
};

}  // namespace pbvbus::gateways
