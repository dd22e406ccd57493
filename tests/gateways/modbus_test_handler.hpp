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

#include <array>
#include <cstdint>
#include <span>
#include <vector>

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
      default: return exception(fc, kExIllegalFunction, rsp);
    }
  }
};

}  // namespace pbvbus::gateways::test
