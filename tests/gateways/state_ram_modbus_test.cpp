// The Quantum state-RAM Modbus core (state_ram_modbus.hpp; docs/quantum-hsby-modbus.md):
// golden request/response PDUs worked out by hand from the Modbus Application Protocol
// V1.1b3 §6 for every function code, the exceptions, unit resolution switching between two
// racks' state RAMs (the address swap of seed 003: 1 = primary, 129 = standby), Silent vs
// 0x0B for an unknown unit, broadcast and the write hook.
//
// Tables used here: 0x 32 coils, 1x 16 inputs, 3x 8 input registers, 4x 16 holding registers.

#include "pbvbus/gateways/state_ram_modbus.hpp"

#include <gtest/gtest.h>

#include <map>
#include <tuple>

#include "hex.hpp"

namespace pbvbus::gateways {
namespace {

using pbvbus::test::bytes_from_hex;
using pbvbus::test::to_hex;
using quantum::RefType;
using quantum::StateRam;
using quantum::StateRamSizes;

constexpr StateRamSizes kSizes{32, 16, 8, 16};

using Write = std::tuple<int, RefType, std::uint32_t, std::uint32_t>;

class StateRamModbus : public ::testing::Test {
 protected:
  StateRamModbus() {
    units[1] = &a;
    units[129] = &b;
  }
  StateRamModbusHandler make(StateRamModbusOptions o = {}) {
    o.revision = [this](std::uint8_t u) {
      return units.count(u) && units[u] == &a ? std::string("HSBY unit A")
                                              : std::string("HSBY unit B");
    };
    return StateRamModbusHandler(
        [this](std::uint8_t u) -> StateRam* {
          auto it = units.find(u);
          return it == units.end() ? nullptr : it->second;
        },
        std::move(o),
        [this](std::uint8_t u, RefType t, std::uint32_t first, std::uint32_t count) {
          writes.emplace_back(u, t, first, count);
        });
  }
  /// One request; the response as hex ("" when nothing is answered).
  std::string ask(StateRamModbusHandler& h, std::uint8_t unit, const std::string& req,
                  bool broadcast = false) {
    std::array<std::uint8_t, kModbusMaxPdu> rsp{};
    const auto pdu = bytes_from_hex(req);
    const std::size_t n = h.handle(unit, pdu, rsp, broadcast);
    return to_hex(std::span<const std::uint8_t>(rsp.data(), n));
  }

  StateRam a{kSizes};
  StateRam b{kSizes};
  std::map<std::uint8_t, StateRam*> units;
  std::vector<Write> writes;
};

TEST_F(StateRamModbus, EngineIsUp) {
  auto h = make();
  EXPECT_TRUE(h.engine_ok());
}

TEST_F(StateRamModbus, Fc03ReadsHoldingRegisters) {
  auto h = make();
  a.set_holding(0, 0x1234);
  a.set_holding(1, 0x0007);
  // 03 addr 0000 qty 0002 -> 03, byte count 04, 12 34, 00 07.
  EXPECT_EQ(ask(h, 1, "03 00 00 00 02"), "03 04 12 34 00 07");
  // The last register (15) alone.
  a.set_holding(15, 0xFFFE);
  EXPECT_EQ(ask(h, 1, "03 00 0F 00 01"), "03 02 FF FE");
}

TEST_F(StateRamModbus, Fc01ReadsCoilsLsbFirst) {
  auto h = make();
  a.set_coil(0, true);
  a.set_coil(2, true);
  a.set_coil(9, true);
  // 10 coils from 0: octet 1 = coils 0..7 -> bits 0 and 2 = 05; octet 2 = coils 8..9 -> bit 1
  // (coil 9) = 02. Byte count 02.
  EXPECT_EQ(ask(h, 1, "01 00 00 00 0A"), "01 02 05 02");
}

TEST_F(StateRamModbus, Fc02ReadsDiscreteInputs) {
  auto h = make();
  a.set_input(0, true);
  a.set_input(15, true);
  // 16 inputs from 0: 01 (input 0), 80 (input 15).
  EXPECT_EQ(ask(h, 1, "02 00 00 00 10"), "02 02 01 80");
}

TEST_F(StateRamModbus, Fc04ReadsInputRegisters) {
  auto h = make();
  a.set_input_reg(7, 0xBEEF);
  EXPECT_EQ(ask(h, 1, "04 00 07 00 01"), "04 02 BE EF");
}

TEST_F(StateRamModbus, Fc05WritesOneCoilAndTheHookSeesIt) {
  auto h = make();
  // FF 00 = ON; the response echoes the request.
  EXPECT_EQ(ask(h, 1, "05 00 03 FF 00"), "05 00 03 FF 00");
  EXPECT_TRUE(a.coil(3));
  EXPECT_EQ(ask(h, 1, "05 00 03 00 00"), "05 00 03 00 00");
  EXPECT_FALSE(a.coil(3));
  EXPECT_EQ(writes, (std::vector<Write>{{1, RefType::Coil0x, 3, 1}, {1, RefType::Coil0x, 3, 1}}));
  EXPECT_EQ(h.stats().units[1].writes, 2u);
}

TEST_F(StateRamModbus, Fc06WritesOneRegister) {
  auto h = make();
  EXPECT_EQ(ask(h, 1, "06 00 05 04 D2"), "06 00 05 04 D2");
  EXPECT_EQ(a.holding(5), 1234);
  EXPECT_EQ(writes, (std::vector<Write>{{1, RefType::Register4x, 5, 1}}));
}

TEST_F(StateRamModbus, Fc15WritesCoils) {
  auto h = make();
  // Coils 20..29 = 1 0 1 1 0 0 0 0 1 1: octet 1 (coils 20..27) bits 0, 2, 3 = 0D; octet 2
  // (coils 28..29) bits 0, 1 = 03. 0F addr 0014 qty 000A bc 02 -> response 0F 0014 000A.
  EXPECT_EQ(ask(h, 1, "0F 00 14 00 0A 02 0D 03"), "0F 00 14 00 0A");
  const bool want[10] = {1, 0, 1, 1, 0, 0, 0, 0, 1, 1};
  for (int i = 0; i < 10; ++i) EXPECT_EQ(a.coil(20 + i), want[i]) << "coil " << 20 + i;
  EXPECT_FALSE(a.coil(19));
  EXPECT_FALSE(a.coil(30));
  EXPECT_EQ(writes, (std::vector<Write>{{1, RefType::Coil0x, 20, 10}}));
}

TEST_F(StateRamModbus, Fc16WritesRegisters) {
  auto h = make();
  // The last two registers 14..15 = 0007 0008: 10 000E 0002 bc 04 -> 10 000E 0002.
  EXPECT_EQ(ask(h, 1, "10 00 0E 00 02 04 00 07 00 08"), "10 00 0E 00 02");
  EXPECT_EQ(a.holding(14), 7);
  EXPECT_EQ(a.holding(15), 8);
  EXPECT_EQ(writes, (std::vector<Write>{{1, RefType::Register4x, 14, 2}}));
}

TEST_F(StateRamModbus, Fc23WritesThenReads) {
  auto h = make();
  a.set_holding(4, 0x0044);
  a.set_holding(5, 0x0055);
  // Read 3 from 4, write 2 at 5 = AAAA BBBB: 17 0004 0003 0005 0002 bc 04 AAAA BBBB.
  // The write comes first, so the read shows 0044 AAAA BBBB: 17, byte count 06, 6 octets.
  EXPECT_EQ(ask(h, 1, "17 00 04 00 03 00 05 00 02 04 AA AA BB BB"), "17 06 00 44 AA AA BB BB");
  EXPECT_EQ(a.holding(5), 0xAAAA);
  EXPECT_EQ(a.holding(6), 0xBBBB);
  EXPECT_EQ(writes, (std::vector<Write>{{1, RefType::Register4x, 5, 2}}));
}

TEST_F(StateRamModbus, Fc43DeviceIdentification) {
  auto h = make();
  // 2B 0E code 01 object 00 -> 2B 0E 01, conformity 81, more 00, next 00, 3 objects:
  // 00 len 06 "pbvbus" = 70 62 76 62 75 73;
  // 01 len 0E "140 CPU 434 12" = 31 34 30 20 43 50 55 20 34 33 34 20 31 32;
  // 02 len 0B "HSBY unit A" = 48 53 42 59 20 75 6E 69 74 20 41.
  EXPECT_EQ(ask(h, 1, "2B 0E 01 00"),
            "2B 0E 01 81 00 00 03 "
            "00 06 70 62 76 62 75 73 "
            "01 0E 31 34 30 20 43 50 55 20 34 33 34 20 31 32 "
            "02 0B 48 53 42 59 20 75 6E 69 74 20 41");
  // Individual access (code 4) to object 2 of unit 129 (rack B): "HSBY unit B" ends in 42.
  EXPECT_EQ(ask(h, 129, "2B 0E 04 02"),
            "2B 0E 04 81 00 00 01 02 0B 48 53 42 59 20 75 6E 69 74 20 42");
  // Individual access to an object that does not exist: AB 02.
  EXPECT_EQ(ask(h, 1, "2B 0E 04 07"), "AB 02");
}

TEST_F(StateRamModbus, ExceptionsForBadFunctionQuantityAndAddress) {
  auto h = make();
  EXPECT_EQ(ask(h, 1, "07"), "87 01");              // FC07 not served
  EXPECT_EQ(ask(h, 1, "90 00 00"), "90 01");        // bit 7 already set: kept
  EXPECT_EQ(ask(h, 1, "2B 0D 01 00"), "AB 01");     // MEI type 13
  EXPECT_EQ(ask(h, 1, "03 00 00 00 00"), "83 03");  // quantity 0
  EXPECT_EQ(ask(h, 1, "03 00 00 00 7E"), "83 03");  // quantity 126 > 125
  EXPECT_EQ(ask(h, 1, "03 00 00 00"), "83 03");     // short PDU
  EXPECT_EQ(ask(h, 1, "05 00 00 12 34"), "85 03");  // coil value neither 0000 nor FF00
  // Beyond a table's configured count: 0x02.
  EXPECT_EQ(ask(h, 1, "03 00 0F 00 02"), "83 02");                             // 4x: 15 + 2 > 16
  EXPECT_EQ(ask(h, 1, "01 00 1E 00 03"), "81 02");                             // 0x: 30 + 3 > 32
  EXPECT_EQ(ask(h, 1, "02 00 10 00 01"), "82 02");                             // 1x: 16 + 1 > 16
  EXPECT_EQ(ask(h, 1, "04 00 08 00 01"), "84 02");                             // 3x: 8 + 1 > 8
  EXPECT_EQ(ask(h, 1, "05 00 20 FF 00"), "85 02");                             // coil 32
  EXPECT_EQ(ask(h, 1, "06 00 10 00 01"), "86 02");                             // register 16
  EXPECT_EQ(ask(h, 1, "0F 00 1F 00 02 01 03"), "8F 02");                       // coils 31..32
  EXPECT_EQ(ask(h, 1, "10 00 0F 00 02 04 00 01 00 02"), "90 02");              // registers 15..16
  EXPECT_EQ(ask(h, 1, "17 00 00 00 01 00 0F 00 02 04 00 01 00 02"), "97 02");  // write part
  EXPECT_EQ(ask(h, 1, "17 00 0F 00 02 00 00 00 01 02 00 01"), "97 02");        // read part
  EXPECT_EQ(ask(h, 1, "03 FF FF 00 02"), "83 02");  // beyond 65535 (the PDU check)
  EXPECT_TRUE(writes.empty());                      // no refused write reached the state RAM
  for (std::uint32_t i = 0; i < 16; ++i) EXPECT_EQ(a.holding(i), 0u);
  EXPECT_EQ(h.stats().exceptions, 18u);
  EXPECT_EQ(h.stats().exceptions_by_code[1], 3u);
  EXPECT_EQ(h.stats().exceptions_by_code[2], 11u);
  EXPECT_EQ(h.stats().exceptions_by_code[3], 4u);
  EXPECT_EQ(h.stats().units[1].exceptions, 18u);
}

TEST_F(StateRamModbus, NoModbusFunctionWrites1xOr3x) {
  auto h = make();
  for (std::uint32_t i = 0; i < 16; ++i) a.set_input(i, i % 3 == 0);
  for (std::uint32_t i = 0; i < 8; ++i) a.set_input_reg(i, static_cast<std::uint16_t>(0x3000 + i));
  const StateRam before = a;
  // Every write function at address 0 with all-ones values.
  EXPECT_EQ(ask(h, 1, "05 00 00 FF 00"), "05 00 00 FF 00");
  EXPECT_EQ(ask(h, 1, "06 00 00 FF FF"), "06 00 00 FF FF");
  EXPECT_EQ(ask(h, 1, "0F 00 00 00 10 02 FF FF"), "0F 00 00 00 10");
  EXPECT_EQ(ask(h, 1, "10 00 00 00 02 04 FF FF FF FF"), "10 00 00 00 02");
  EXPECT_EQ(ask(h, 1, "17 00 00 00 01 00 00 00 01 02 FF FF"), "17 02 FF FF");
  EXPECT_EQ(a.inputs(), before.inputs());
  EXPECT_EQ(a.input_regs(), before.input_regs());
  // And reads of 1x / 3x still show them.
  EXPECT_EQ(ask(h, 1, "04 00 00 00 01"), "04 02 30 00");
  EXPECT_EQ(ask(h, 1, "02 00 00 00 08"), "02 01 49");  // inputs 0, 3, 6: bits 0, 3, 6 = 49
}

TEST_F(StateRamModbus, UnitResolutionFollowsTheAddressSwap) {
  auto h = make();
  a.set_holding(0, 0x000A);  // rack A
  b.set_holding(0, 0x000B);  // rack B
  // A primary at 1, B standby at 129.
  EXPECT_EQ(ask(h, 1, "03 00 00 00 01"), "03 02 00 0A");
  EXPECT_EQ(ask(h, 129, "03 00 00 00 01"), "03 02 00 0B");
  // Switchover with the swap on: B (now primary) at 1, A (now standby) at 129.
  units[1] = &b;
  units[129] = &a;
  EXPECT_EQ(ask(h, 1, "03 00 00 00 01"), "03 02 00 0B");
  EXPECT_EQ(ask(h, 129, "03 00 00 00 01"), "03 02 00 0A");
  // A write to unit 1 now lands in rack B's state RAM.
  EXPECT_EQ(ask(h, 1, "06 00 01 00 2A"), "06 00 01 00 2A");
  EXPECT_EQ(b.holding(1), 42);
  EXPECT_EQ(a.holding(1), 0);
  EXPECT_EQ(h.stats().units[1].requests, 3u);
  EXPECT_EQ(h.stats().units[129].requests, 2u);
}

TEST_F(StateRamModbus, UnknownUnitSilentOrGatewayTargetFailed) {
  auto silent = make();
  EXPECT_EQ(ask(silent, 9, "03 00 00 00 01"), "");
  EXPECT_EQ(ask(silent, 9, "FF FF"), "");  // garbage for nobody: still nobody answers
  EXPECT_EQ(silent.stats().silent, 2u);
  EXPECT_EQ(silent.stats().exceptions, 0u);
  StateRamModbusOptions o;
  o.unknown_unit = UnknownUnit::GatewayNoResponse;
  auto gw = make(o);
  EXPECT_EQ(ask(gw, 9, "03 00 00 00 01"), "83 0B");
  EXPECT_EQ(ask(gw, 9, "10 00 00 00 01 02 00 01"), "90 0B");
  EXPECT_EQ(gw.stats().exceptions_by_code[0x0B], 2u);
  EXPECT_EQ(gw.stats().silent, 0u);
}

TEST_F(StateRamModbus, BroadcastIsCarriedOutOnTheResolvedUnitAndNotAnswered) {
  auto h = make();
  EXPECT_EQ(ask(h, 0, "06 00 02 00 63", true), "");  // nobody holds 0: nothing happens
  EXPECT_TRUE(writes.empty());
  units[0] = &a;  // the pair resolves 0 to its primary
  EXPECT_EQ(ask(h, 0, "06 00 02 00 63", true), "");
  EXPECT_EQ(a.holding(2), 0x63);
  EXPECT_EQ(b.holding(2), 0);
  EXPECT_EQ(writes, (std::vector<Write>{{0, RefType::Register4x, 2, 1}}));
  EXPECT_EQ(ask(h, 0, "03 00 00 00 01", true), "");  // a read: nothing answered
  EXPECT_EQ(h.stats().silent, 0u);
}

TEST_F(StateRamModbus, EmptyTablesAnswer02) {
  StateRam z{StateRamSizes{0, 0, 0, 0}};
  units[1] = &z;
  auto h = make();
  EXPECT_EQ(ask(h, 1, "01 00 00 00 01"), "81 02");
  EXPECT_EQ(ask(h, 1, "02 00 00 00 01"), "82 02");
  EXPECT_EQ(ask(h, 1, "03 00 00 00 01"), "83 02");
  EXPECT_EQ(ask(h, 1, "04 00 00 00 01"), "84 02");
  EXPECT_EQ(ask(h, 1, "06 00 00 00 01"), "86 02");
}

}  // namespace
}  // namespace pbvbus::gateways
