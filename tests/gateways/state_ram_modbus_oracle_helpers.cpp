#include <array>
#include <vector>

#include "state_ram_modbus_oracle.hpp"

#include "pbvbus/gateways/modbus_pdu.hpp"

namespace pbvbus::gateways::test {
namespace {

using quantum::StateRam;
using quantum::StateRamSizes;

// Odd sizes: table ends that fall inside a coil octet and inside a request.
constexpr StateRamSizes kSizes{40, 24, 10, 20};

StateRam* resolve(StateRamModbusRig& r, std::uint8_t unit) {
  if (unit == 1 || unit == 0) return &r.a;
  if (unit == 129) return &r.b;
  return nullptr;
}

}  // namespace

StateRamModbusRig::StateRamModbusRig() : a(kSizes), b(kSizes) {
  for (std::uint32_t i = 0; i < kSizes.inputs; ++i) {
    a.set_input(i, i % 3 == 0);
    b.set_input(i, i % 5 == 0);
  }
  for (std::uint32_t i = 0; i < kSizes.input_regs; ++i) {
    a.set_input_reg(i, static_cast<std::uint16_t>(0xA300 + i));
    b.set_input_reg(i, static_cast<std::uint16_t>(0xB300 + i));
  }
  auto hook = [this](std::uint8_t, quantum::RefType, std::uint32_t, std::uint32_t) {
    ++hook_calls;
  };
  silent = std::make_unique<StateRamModbusHandler>(
      [this](std::uint8_t u) { return resolve(*this, u); }, StateRamModbusOptions{}, hook);
  StateRamModbusOptions o;
  o.unknown_unit = UnknownUnit::GatewayNoResponse;
  gateway = std::make_unique<StateRamModbusHandler>(
      [this](std::uint8_t u) { return resolve(*this, u); }, o, hook);
}

std::string check_state_ram_modbus(StateRamModbusRig& rig, std::span<const std::uint8_t> input) {
  if (input.size() < 2 || input.size() > 1 + kModbusMaxPdu) return {};
  const std::uint8_t unit = input[0];
  // An exact-size heap copy so ASan sees any read past the PDU's end.
  const std::vector<std::uint8_t> pdu(input.begin() + 1, input.end());
  const auto in_a = rig.a.inputs();
  const auto ir_a = rig.a.input_regs();
  const auto in_b = rig.b.inputs();
  const auto ir_b = rig.b.input_regs();
  const ModbusDecoded d = decode_modbus_request(pdu);
  const bool known = unit == 0 || unit == 1 || unit == 129;  // the rig's resolver
  for (StateRamModbusHandler* h : {rig.silent.get(), rig.gateway.get()}) {
    std::array<std::uint8_t, kModbusMaxPdu> rsp{};
    const std::size_t n = h->handle(unit, pdu, rsp, false);
    const bool is_silent = h == rig.silent.get();
    if (n > kModbusMaxPdu) return "answer longer than 253 octets";
    if (!known) {
      if (is_silent && n != 0) return "an unknown unit was answered on a Silent port";
      if (!is_silent && (n != 2 || rsp[0] != (pdu[0] | 0x80) || rsp[1] != kExGatewayTargetFailed))
        return "an unknown unit did not get FC|80 0B";
      continue;
    }
    if (n < 2) return "a known unit was not answered";
    if ((rsp[0] & 0x7F) != (pdu[0] & 0x7F)) return "answer has another function code";
    const bool exception = (rsp[0] & 0x80) != 0;
    if (exception && n != 2) return "exception answer is not 2 octets";
    if (!d.ok() && (!exception || rsp[1] != d.error.exception))
      return "a refused request did not get the decoder's exception";
    if (d.ok() && !exception) {
      const ModbusRequest& q = d.request;
      std::size_t want = 0;
      if (q.reads_bits())
        want = 2 + (q.read_quantity + 7u) / 8u;
      else if (q.function == kFcReadHoldingRegisters || q.function == kFcReadInputRegisters ||
               q.function == kFcReadWriteMultipleRegisters)
        want = 2 + 2u * q.read_quantity;
      if (want != 0 && n != want) return "read answer has the wrong length";
    }
  }
  if (rig.a.inputs() != in_a || rig.a.input_regs() != ir_a || rig.b.inputs() != in_b ||
      rig.b.input_regs() != ir_b)
    return "a Modbus request changed 1x or 3x";
  return {};
}

}  // namespace pbvbus::gateways::test
