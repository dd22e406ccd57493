// The state-RAM Modbus core on arbitrary bytes (runs under ASan+UBSan in sanitize_gateways):
// random PDUs and mutations of valid requests for every function code, checked by the oracle of
// state_ram_modbus_oracle.hpp (shared with tests/fuzz/fuzz_state_ram_modbus.cpp).
#include <gtest/gtest.h>

#include <random>
#include <vector>

#include "state_ram_modbus_oracle.hpp"

#include "pbvbus/gateways/modbus_pdu.hpp"

namespace pbvbus::gateways {
namespace {

using Bytes = std::vector<std::uint8_t>;

std::string run(test::StateRamModbusRig& rig, std::uint8_t unit, const Bytes& pdu) {
  Bytes in{unit};
  in.insert(in.end(), pdu.begin(), pdu.end());
  return test::check_state_ram_modbus(rig, in);
}

TEST(StateRamModbusParser, RandomPdusOfEveryLength) {
  test::StateRamModbusRig rig;
  std::mt19937 rng(20261128);
  const std::uint8_t units[] = {0, 1, 129, 2, 255};
  for (int i = 0; i < 20000; ++i) {
    Bytes pdu(1 + rng() % kModbusMaxPdu);
    for (auto& b : pdu) b = static_cast<std::uint8_t>(rng());
    // Mostly function codes the handler knows, so the checks behind the first one run too.
    if (i % 4 != 0) {
      static const std::uint8_t fcs[] = {1, 2, 3, 4, 5, 6, 15, 16, 23, 43};
      pdu[0] = fcs[rng() % std::size(fcs)];
    }
    ASSERT_EQ(run(rig, units[i % std::size(units)], pdu), "") << "iteration " << i;
  }
}

TEST(StateRamModbusParser, MutationsOfValidRequests) {
  test::StateRamModbusRig rig;
  const std::uint16_t regs[] = {0x0102, 0x0304};
  const std::vector<Bytes> seeds = {
      encode_modbus_read(kFcReadCoils, 0, 40),
      encode_modbus_read(kFcReadDiscreteInputs, 20, 4),
      encode_modbus_read(kFcReadHoldingRegisters, 18, 2),
      encode_modbus_read(kFcReadInputRegisters, 9, 1),
      encode_modbus_write_single(kFcWriteSingleCoil, 39, 0xFF00),
      encode_modbus_write_single(kFcWriteSingleRegister, 19, 7),
      encode_modbus_write_coils(33, {true, false, true, true, false, true, true}),
      encode_modbus_write_registers(18, regs),
      encode_modbus_read_write(0, 20, 18, regs),
      encode_modbus_read_device_id(1, 0),
  };
  std::mt19937 rng(7);
  for (int i = 0; i < 20000; ++i) {
    Bytes pdu = seeds[static_cast<std::size_t>(i) % seeds.size()];
    const int edits = 1 + static_cast<int>(rng() % 3);
    for (int e = 0; e < edits; ++e) {
      switch (rng() % 4) {
        case 0:
          pdu[rng() % pdu.size()] = static_cast<std::uint8_t>(rng());
          break;
        case 1:
          if (pdu.size() > 1) pdu.pop_back();
          break;
        case 2:
          if (pdu.size() < kModbusMaxPdu) pdu.push_back(static_cast<std::uint8_t>(rng()));
          break;
        default:
          pdu[rng() % pdu.size()] ^= 0x01;
          break;  // one bit
      }
    }
    ASSERT_EQ(run(rig, i % 2 ? 1 : 129, pdu), "") << "iteration " << i;
  }
  EXPECT_GT(rig.hook_calls, 0u);  // some mutated writes went through
}

TEST(StateRamModbusParser, OverlongAndEmptyInputs) {
  test::StateRamModbusRig rig;
  std::array<std::uint8_t, kModbusMaxPdu> rsp{};
  // The doors never hand these over, but the handler must not trust that.
  EXPECT_EQ(rig.gateway->handle(1, {}, rsp, false), 2u);
  EXPECT_EQ(rsp[0], 0x80);
  EXPECT_EQ(rsp[1], kExIllegalFunction);
  const Bytes big(300, 0x03);
  EXPECT_EQ(rig.gateway->handle(1, big, rsp, false), 2u);
  EXPECT_EQ(rsp[0], 0x83);
  EXPECT_EQ(rsp[1], kExIllegalDataValue);
  EXPECT_EQ(rig.silent->handle(7, {}, rsp, false), 0u);
}

}  // namespace
}  // namespace pbvbus::gateways
