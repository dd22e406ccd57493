// libFuzzer target for the Modbus request-PDU decoder and the gateway core behind it: input =
// unit id (first octet) + request PDU. The decoder must never read past the PDU and must give a
// spec exception for every refusal; the gateway must answer every request with a well-formed
// PDU (same function code, or FC|0x80 + the decoder's exception for a refused one) and never
// crash, whatever libmodbus is handed.
//   build-fuzz/bin/fuzz_modbus_pdu -max_total_time=60 <scratch corpus dir> tests/fuzz/corpus/modbus_pdu
#include <array>
#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

#include "fake_source.hpp"
#include "pbvbus/gateways/modbus_gateway.hpp"
#include "pbvbus/gateways/modbus_pdu.hpp"

namespace {

using namespace pbvbus::gateways;

struct Rig {
  test::FakeSource src;
  std::unique_ptr<ModbusGateway> gw;
  Rig() {
    src.set_redundant(true);
    src.add_slave(5, 0x80E0, {{"AI3", 0, 3, 0, 0, false}, {"IO4", 0, 4, 0, 4, true},
                              {"DO1", 0, 0, 0, 1, false}});
    src.add_slave(6, 0x0001, {{"AO2", 0, 0, 0, 2, false}}).switched = true;
    src.data(6).status.state = pbvbus::dp::SlaveStatusState::NotPresent;
    src.data(6).status.data_valid = false;
    ModbusGatewayOptions opt;
    opt.standby_units = true;
    opt.slaves[5].word_order = WordOrder::WordSwap;
    opt.slaves[6].stale = StaleReaction::Value;
    opt.slaves[6].stale_value = 0x1234;
    gw = std::make_unique<ModbusGateway>(src, opt);
  }
};

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static Rig rig;
  if (size < 2 || size > 1 + kModbusMaxPdu) return 0;
  const std::uint8_t unit = data[0];
  // An exact-size heap copy so ASan sees any read past the PDU's end.
  const std::vector<std::uint8_t> pdu(data + 1, data + size);
  const ModbusDecoded d = decode_modbus_request(pdu);
  if (!d.ok() && d.error.exception != kExIllegalFunction &&
      d.error.exception != kExIllegalDataAddress && d.error.exception != kExIllegalDataValue)
    __builtin_trap();
  if (!d.ok() && d.error.reason.empty()) __builtin_trap();
  std::array<std::uint8_t, kModbusMaxPdu> rsp{};
  const std::size_t n = rig.gw->handle(unit, pdu, rsp, false);
  if (n < 2 || n > kModbusMaxPdu) __builtin_trap();
  if ((rsp[0] & 0x7F) != (pdu[0] & 0x7F)) __builtin_trap();
  const bool known = unit == 0 || unit == 255 || unit == 5 || unit == 6 || unit == 134;
  if (known && !d.ok() && (rsp[0] & 0x80) == 0) __builtin_trap();
  if (known && !d.ok() && rsp[1] != d.error.exception) __builtin_trap();
  if (!known && (rsp[0] & 0x80) == 0) __builtin_trap();
  return 0;
}
