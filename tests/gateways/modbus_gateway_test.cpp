// ModbusGateway over a FakeSource: golden PDUs worked out by hand for every function code,
// every exception code, the stale reactions, word orders, the status block, the gateway unit,
// the master-mode command, the standby unit and its swap, write consistency (one set of
// write_module_outputs calls per request) and FC23's write-then-read.
#include "pbvbus/gateways/modbus_gateway.hpp"

#include <gtest/gtest.h>

#include <array>
#include <memory>
#include <random>
#include <vector>

#include "fake_source.hpp"
#include "pbvbus/gateways/modbus_pdu.hpp"

namespace pbvbus::gateways::test {
namespace {

using Bytes = std::vector<std::uint8_t>;

// Slave 5, ident 0x80E0, four modules (slot order):
//   m0 "AI3"  3 in            input octets 0..2   IR 0..1
//   m1 "IO4"  4 in / 4 out    input octets 3..6   IR 2..3   output octets 0..3  HR 0..1
//   m2 "DO1"        1 out                                   output octet 4      HR 2
//   m3 "AO3"        3 out                                   output octets 5..7  HR 3..4
// Inputs  12 34 56 | A1 A2 A3 A4          Outputs B1 B2 B3 B4 | B5 | B6 B7 B8
class ModbusGatewayTest : public ::testing::Test {
 protected:
  void SetUp() override {
    src.add_slave(5, 0x80E0,
                  {{"AI3", 0, 3, 0, 0, false},
                   {"IO4", 0, 4, 0, 4, true},
                   {"DO1", 0, 0, 0, 1, false},
                   {"AO3", 0, 0, 0, 3, false}},
                  "Fake IO");
    src.data(5).inputs = {0x12, 0x34, 0x56, 0xA1, 0xA2, 0xA3, 0xA4};
    src.data(5).outputs = {0xB1, 0xB2, 0xB3, 0xB4, 0xB5, 0xB6, 0xB7, 0xB8};
  }
  ModbusGateway& gw() {
    if (!m_gw) m_gw = std::make_unique<ModbusGateway>(src, opt);
    return *m_gw;
  }
  Bytes ask(std::uint8_t unit, const Bytes& pdu, bool broadcast = false) {
    std::array<std::uint8_t, kModbusMaxPdu> rsp{};
    const std::size_t n = gw().handle(unit, pdu, rsp, broadcast);
    return Bytes(rsp.begin(), rsp.begin() + static_cast<std::ptrdiff_t>(n));
  }
  void make_stale(std::uint8_t a, StaleReaction r, std::uint16_t value = 0) {
    opt.slaves[a].stale = r;
    opt.slaves[a].stale_value = value;
    src.data(a).status.state = dp::SlaveStatusState::NotPresent;
    src.data(a).status.data_valid = false;
  }

  FakeSource src;
  ModbusGatewayOptions opt;
  std::unique_ptr<ModbusGateway> m_gw;
};

TEST_F(ModbusGatewayTest, EngineIsUp) { EXPECT_TRUE(gw().engine_ok()); }

TEST_F(ModbusGatewayTest, Fc04InputRegistersEachModuleOnANewRegister) {
  // m0 "12 34 56" -> 0x1234, 0x5600 (odd module: low byte 0); m1 -> 0xA1A2, 0xA3A4.
  // Response: FC 04, byte count 4 x 2 = 8, then the registers high byte first.
  EXPECT_EQ(ask(5, encode_modbus_read(0x04, 0, 4)),
            (Bytes{0x04, 0x08, 0x12, 0x34, 0x56, 0x00, 0xA1, 0xA2, 0xA3, 0xA4}));
  EXPECT_EQ(ask(5, encode_modbus_read(0x04, 1, 2)), (Bytes{0x04, 0x04, 0x56, 0x00, 0xA1, 0xA2}));
  // The data area is registers 0..3: 4 is outside, and so is 0..4.
  EXPECT_EQ(ask(5, encode_modbus_read(0x04, 4, 1)), (Bytes{0x84, 0x02}));
  EXPECT_EQ(ask(5, encode_modbus_read(0x04, 0, 5)), (Bytes{0x84, 0x02}));
}

TEST_F(ModbusGatewayTest, Fc03HoldingRegistersAreTheOutputs) {
  // m1 B1B2 B3B4, m2 B5 -> 0xB500, m3 B6B7 B8 -> 0xB6B7, 0xB800: 5 registers, 10 octets.
  EXPECT_EQ(ask(5, encode_modbus_read(0x03, 0, 5)),
            (Bytes{0x03, 0x0A, 0xB1, 0xB2, 0xB3, 0xB4, 0xB5, 0x00, 0xB6, 0xB7, 0xB8, 0x00}));
  EXPECT_EQ(ask(5, encode_modbus_read(0x03, 5, 1)), (Bytes{0x83, 0x02}));
}

TEST_F(ModbusGatewayTest, Fc02DiscreteInputsOverTheUnpaddedTelegram) {
  // Octet 0 = 0x12: bits 0..7 = 0 1 0 0 1 0 0 0 -> packed LSB first again 0x12.
  EXPECT_EQ(ask(5, encode_modbus_read(0x02, 0, 8)), (Bytes{0x02, 0x01, 0x12}));
  // Bits 4..11: 0x12 bits 4..7 = 1 0 0 0, 0x34 = 0011 0100 bits 0..3 = 0 0 1 0
  // -> result bit 0 = 1, bit 6 = 1 -> 0x41.
  EXPECT_EQ(ask(5, encode_modbus_read(0x02, 4, 8)), (Bytes{0x02, 0x01, 0x41}));
  // Bit 24 = octet 3 (0xA1, the padded IR layout would put it elsewhere) bit 0 = 1.
  EXPECT_EQ(ask(5, encode_modbus_read(0x02, 24, 1)), (Bytes{0x02, 0x01, 0x01}));
  // 7 input octets = 56 bits: bit 56 is outside.
  EXPECT_EQ(ask(5, encode_modbus_read(0x02, 56, 1)), (Bytes{0x82, 0x02}));
}

TEST_F(ModbusGatewayTest, Fc01CoilsOverTheOutputTelegram) {
  // Octet 0 = 0xB1; octets 4.. = B5: coils 32..39 = 0xB5.
  EXPECT_EQ(ask(5, encode_modbus_read(0x01, 0, 8)), (Bytes{0x01, 0x01, 0xB1}));
  EXPECT_EQ(ask(5, encode_modbus_read(0x01, 32, 8)), (Bytes{0x01, 0x01, 0xB5}));
  EXPECT_EQ(ask(5, encode_modbus_read(0x01, 64, 1)), (Bytes{0x81, 0x02}));  // 8 octets = 64 bits
}

TEST_F(ModbusGatewayTest, Fc05WritesOneCoilIntoItsModule) {
  // Coil 35 = octet 4 (module m2) bit 3: 0xB5 = 1011 0101 -> bit 3 set -> 1011 1101 = 0xBD.
  EXPECT_EQ(ask(5, Bytes{0x05, 0x00, 0x23, 0xFF, 0x00}), (Bytes{0x05, 0x00, 0x23, 0xFF, 0x00}));
  ASSERT_EQ(src.writes().size(), 1u);
  EXPECT_EQ(src.writes()[0].module, 2u);
  EXPECT_EQ(src.writes()[0].data, (Bytes{0xBD}));
  // Coil 0 OFF: 0xB1 -> 0xB0, module m1 whole.
  EXPECT_EQ(ask(5, Bytes{0x05, 0x00, 0x00, 0x00, 0x00}), (Bytes{0x05, 0x00, 0x00, 0x00, 0x00}));
  EXPECT_EQ(src.writes()[1].module, 1u);
  EXPECT_EQ(src.writes()[1].data, (Bytes{0xB0, 0xB2, 0xB3, 0xB4}));
  EXPECT_EQ(ask(5, Bytes{0x05, 0x00, 0x00, 0x12, 0x34}), (Bytes{0x85, 0x03}));
}

TEST_F(ModbusGatewayTest, Fc06WritesOneRegister) {
  // HR 3 = m3 octets 5,6 -> CA FE; octet 7 (B8) stays: the module goes over whole.
  EXPECT_EQ(ask(5, Bytes{0x06, 0x00, 0x03, 0xCA, 0xFE}), (Bytes{0x06, 0x00, 0x03, 0xCA, 0xFE}));
  ASSERT_EQ(src.writes().size(), 1u);
  EXPECT_EQ(src.writes()[0].module, 3u);
  EXPECT_EQ(src.writes()[0].data, (Bytes{0xCA, 0xFE, 0xB8}));
  // HR 4 = m3's last register, octet 7 in its high byte; the low byte 0x99 has no octet.
  EXPECT_EQ(ask(5, Bytes{0x06, 0x00, 0x04, 0x42, 0x99}), (Bytes{0x06, 0x00, 0x04, 0x42, 0x99}));
  EXPECT_EQ(src.writes()[1].data, (Bytes{0xCA, 0xFE, 0x42}));
  EXPECT_EQ(ask(5, encode_modbus_read(0x03, 4, 1)), (Bytes{0x03, 0x02, 0x42, 0x00}));
}

TEST_F(ModbusGatewayTest, Fc16OverThreeModulesIsOneSetOfModuleWrites) {
  // HR 1..3 := 1111 2233 4455: HR 1 = m1 octets 2,3; HR 2 = m2 (low byte 33 dropped);
  // HR 3 = m3 octets 5,6. Each touched module is written once, whole, in slot order.
  const std::vector<std::uint16_t> regs{0x1111, 0x2233, 0x4455};
  EXPECT_EQ(ask(5, encode_modbus_write_registers(1, regs)),
            (Bytes{0x10, 0x00, 0x01, 0x00, 0x03}));
  ASSERT_EQ(src.writes().size(), 3u);
  EXPECT_EQ(src.writes()[0].module, 1u);
  EXPECT_EQ(src.writes()[0].data, (Bytes{0xB1, 0xB2, 0x11, 0x11}));
  EXPECT_EQ(src.writes()[1].module, 2u);
  EXPECT_EQ(src.writes()[1].data, (Bytes{0x22}));
  EXPECT_EQ(src.writes()[2].module, 3u);
  EXPECT_EQ(src.writes()[2].data, (Bytes{0x44, 0x55, 0xB8}));
  EXPECT_EQ(src.data(5).outputs, (Bytes{0xB1, 0xB2, 0x11, 0x11, 0x22, 0x44, 0x55, 0xB8}));
}

TEST_F(ModbusGatewayTest, Fc15CoilsAcrossTwoModules) {
  // The spec's example data CD 01 for 10 coils, here from coil 28 (octet 3 bit 4):
  // coils 28..37 = 1 0 1 1 0 0 1 1 | 1 0.
  // Octet 3 (0xB4 = 1011 0100): bits 4..7 := 1 0 1 1 -> high nibble 1101 -> 0xD4.
  // Octet 4 (0xB5 = 1011 0101): bits 0..5 := 0 0 1 1 1 0 -> 01 1100 = 0x1C; bits 6,7 of 0xB5
  // (1 0) stay -> 0x80 | 0x1C = 0x9C.
  EXPECT_EQ(ask(5, Bytes{0x0F, 0x00, 0x1C, 0x00, 0x0A, 0x02, 0xCD, 0x01}),
            (Bytes{0x0F, 0x00, 0x1C, 0x00, 0x0A}));
  ASSERT_EQ(src.writes().size(), 2u);
  EXPECT_EQ(src.writes()[0].module, 1u);
  EXPECT_EQ(src.writes()[0].data, (Bytes{0xB1, 0xB2, 0xB3, 0xD4}));
  EXPECT_EQ(src.writes()[1].module, 2u);
  EXPECT_EQ(src.writes()[1].data, (Bytes{0x9C}));
}

TEST_F(ModbusGatewayTest, Fc23WritesBeforeItReads) {
  // Write HR 2 := 77AA (m2: the low byte has no octet), then read HR 0..4 as they are now:
  // B1B2 B3B4 7700 B6B7 B800 — 0x7700, not the written 0x77AA.
  EXPECT_EQ(ask(5, encode_modbus_read_write(0, 5, 2, std::vector<std::uint16_t>{0x77AA})),
            (Bytes{0x17, 0x0A, 0xB1, 0xB2, 0xB3, 0xB4, 0x77, 0x00, 0xB6, 0xB7, 0xB8, 0x00}));
  ASSERT_EQ(src.writes().size(), 1u);
  EXPECT_EQ(src.writes()[0].module, 2u);
  EXPECT_EQ(src.writes()[0].data, (Bytes{0x77}));
  // The read part may be the status mirror; the write part may not.
  EXPECT_EQ(ask(5, encode_modbus_read_write(0x1000, 1, 0, std::vector<std::uint16_t>{1})),
            (Bytes{0x17, 0x02, 0x00, 0x06}));  // state 6 = DataExchange
  EXPECT_EQ(ask(5, encode_modbus_read_write(0, 1, 0x1000, std::vector<std::uint16_t>{1})),
            (Bytes{0x97, 0x02}));
}

TEST_F(ModbusGatewayTest, ExceptionCodes) {
  EXPECT_EQ(ask(7, encode_modbus_read(0x03, 0, 1)), (Bytes{0x83, 0x0A}));   // no slave 7
  EXPECT_EQ(ask(5, Bytes{0x11}), (Bytes{0x91, 0x01}));                      // FC17 unsupported
  EXPECT_EQ(ask(5, Bytes{0x08, 0, 0, 0, 0}), (Bytes{0x88, 0x01}));
  EXPECT_EQ(ask(5, Bytes{0x83, 0, 0, 0, 1}), (Bytes{0x83, 0x01}));         // bit 7 kept
  EXPECT_EQ(ask(5, encode_modbus_read(0x03, 0, 126)), (Bytes{0x83, 0x03})); // quantity
  EXPECT_EQ(ask(5, encode_modbus_read(0x04, 0x0100, 1)), (Bytes{0x84, 0x02}));  // gap
  EXPECT_EQ(ask(5, encode_modbus_read(0x04, 0x1082, 1)), (Bytes{0x84, 0x02}));  // 4226: past
  EXPECT_EQ(ask(5, encode_modbus_read(0x04, 0x0FFF, 2)), (Bytes{0x84, 0x02}));  // straddles
  EXPECT_EQ(ask(5, Bytes{0x06, 0x10, 0x00, 0x00, 0x01}), (Bytes{0x86, 0x02})); // status: r/o
  EXPECT_EQ(ask(5, encode_modbus_write_registers(0x1000, std::vector<std::uint16_t>{1})),
            (Bytes{0x90, 0x02}));
  make_stale(5, StaleReaction::Exception);
  EXPECT_EQ(ask(5, encode_modbus_read(0x04, 0, 1)), (Bytes{0x84, 0x0B}));
  const auto& st = gw().stats();
  EXPECT_EQ(st.exceptions, st.requests);
  EXPECT_EQ(st.exceptions_by_code[0x0A], 1u);
  EXPECT_EQ(st.exceptions_by_code[0x01], 3u);
  EXPECT_EQ(st.exceptions_by_code[0x03], 1u);
  EXPECT_EQ(st.exceptions_by_code[0x02], 5u);
  EXPECT_EQ(st.exceptions_by_code[0x0B], 1u);
  EXPECT_EQ(st.units[7].requests, 1u);
  EXPECT_EQ(st.units[5].requests, 10u);
}

TEST_F(ModbusGatewayTest, ReadOnlySlaveRefusesWritesWithIllegalFunction) {
  src.add_slave(6, 0x1234, {{"AO2", 0, 0, 0, 2, false}}).outputs_writable = false;
  EXPECT_EQ(ask(6, Bytes{0x06, 0, 0, 0, 1}), (Bytes{0x86, 0x01}));
  EXPECT_EQ(ask(6, Bytes{0x05, 0, 0, 0xFF, 0}), (Bytes{0x85, 0x01}));
  EXPECT_EQ(ask(6, encode_modbus_read(0x03, 0, 1)), (Bytes{0x03, 0x02, 0x00, 0x00}));
  EXPECT_TRUE(src.writes().empty());
}

TEST_F(ModbusGatewayTest, StaleExceptionForProcessDataButStatusStaysReadable) {
  make_stale(5, StaleReaction::Exception);
  EXPECT_EQ(ask(5, encode_modbus_read(0x04, 0, 1)), (Bytes{0x84, 0x0B}));
  EXPECT_EQ(ask(5, encode_modbus_read(0x03, 0, 1)), (Bytes{0x83, 0x0B}));
  EXPECT_EQ(ask(5, encode_modbus_read(0x02, 0, 1)), (Bytes{0x82, 0x0B}));
  EXPECT_EQ(ask(5, encode_modbus_read(0x01, 0, 1)), (Bytes{0x81, 0x0B}));
  EXPECT_EQ(ask(5, Bytes{0x06, 0, 0, 0, 1}), (Bytes{0x86, 0x0B}));
  EXPECT_TRUE(src.writes().empty());
  // State 7 = NotPresent; flags: station failure (bit 2) only -> 0x0004.
  EXPECT_EQ(ask(5, encode_modbus_read(0x04, 0x1000, 2)), (Bytes{0x04, 0x04, 0x00, 0x07, 0x00, 0x04}));
}

TEST_F(ModbusGatewayTest, StaleKeepLastZeroAndValue) {
  make_stale(5, StaleReaction::KeepLast);
  EXPECT_EQ(ask(5, encode_modbus_read(0x04, 0, 2)), (Bytes{0x04, 0x04, 0x12, 0x34, 0x56, 0x00}));
  // Data valid (bit 0) cleared, station failure (bit 2) set.
  EXPECT_EQ(ask(5, encode_modbus_read(0x04, 0x1001, 1)), (Bytes{0x04, 0x02, 0x00, 0x04}));
  // Writes go through (the master sends them when the slave is back).
  EXPECT_EQ(ask(5, Bytes{0x06, 0, 2, 0x5A, 0}), (Bytes{0x06, 0, 2, 0x5A, 0}));
  EXPECT_EQ(src.writes().size(), 1u);
  // Holding registers read back the outputs as written, whatever the reaction.
  EXPECT_EQ(ask(5, encode_modbus_read(0x03, 2, 1)), (Bytes{0x03, 0x02, 0x5A, 0x00}));

  m_gw.reset();
  make_stale(5, StaleReaction::Zero);
  EXPECT_EQ(ask(5, encode_modbus_read(0x04, 0, 2)), (Bytes{0x04, 0x04, 0, 0, 0, 0}));
  EXPECT_EQ(ask(5, encode_modbus_read(0x02, 0, 8)), (Bytes{0x02, 0x01, 0x00}));

  m_gw.reset();
  make_stale(5, StaleReaction::Value, 0xBEEF);
  EXPECT_EQ(ask(5, encode_modbus_read(0x04, 0, 3)),
            (Bytes{0x04, 0x06, 0xBE, 0xEF, 0xBE, 0xEF, 0xBE, 0xEF}));
  // Bits: the value's low bit (0xBEEF is odd -> 1) in every bit: 8 bits -> 0xFF.
  EXPECT_EQ(ask(5, encode_modbus_read(0x02, 0, 8)), (Bytes{0x02, 0x01, 0xFF}));
  m_gw.reset();
  make_stale(5, StaleReaction::Value, 0x0100);
  EXPECT_EQ(ask(5, encode_modbus_read(0x02, 0, 3)), (Bytes{0x02, 0x01, 0x00}));
}

TEST_F(ModbusGatewayTest, WordOrdersPerSlaveAndPerModule) {
  // Slave 9: m0 4 octets 11 22 33 44, m1 3 octets 55 66 77, m2 2 octets 88 99.
  src.add_slave(9, 1, {{"A", 0, 4, 0, 4, false}, {"B", 0, 3, 0, 0, false}, {"C", 0, 2, 0, 0, false}});
  src.data(9).inputs = {0x11, 0x22, 0x33, 0x44, 0x55, 0x66, 0x77, 0x88, 0x99};
  auto regs = [&](WordOrder o) {
    m_gw.reset();
    opt.slaves[9].word_order = o;
    return ask(9, encode_modbus_read(0x04, 0, 5));
  };
  // AB CD: 1122 3344 | 5566 7700 | 8899
  EXPECT_EQ(regs(WordOrder::HighByteFirst),
            (Bytes{4, 10, 0x11, 0x22, 0x33, 0x44, 0x55, 0x66, 0x77, 0x00, 0x88, 0x99}));
  // BA DC: 2211 4433 | the 3-octet group gets only the byte part: 66 55 77 -> 6655 7700 | 9988
  EXPECT_EQ(regs(WordOrder::ByteSwap),
            (Bytes{4, 10, 0x22, 0x11, 0x44, 0x33, 0x66, 0x55, 0x77, 0x00, 0x99, 0x88}));
  // CD AB: 3344 1122 | short groups have no word part: 5566 7700 | 8899
  EXPECT_EQ(regs(WordOrder::WordSwap),
            (Bytes{4, 10, 0x33, 0x44, 0x11, 0x22, 0x55, 0x66, 0x77, 0x00, 0x88, 0x99}));
  // DC BA: 4433 2211 | 6655 7700 | 9988
  EXPECT_EQ(regs(WordOrder::ByteWordSwap),
            (Bytes{4, 10, 0x44, 0x33, 0x22, 0x11, 0x66, 0x55, 0x77, 0x00, 0x99, 0x88}));
  // Module wins: slave DC BA, module 1 AB CD.
  m_gw.reset();
  opt.slaves[9].word_order = WordOrder::ByteWordSwap;
  opt.slaves[9].module_word_order[1] = WordOrder::HighByteFirst;
  EXPECT_EQ(ask(9, encode_modbus_read(0x04, 2, 2)), (Bytes{4, 4, 0x55, 0x66, 0x77, 0x00}));
  // Writes go through the same order: DC BA, HR 0..1 := 0102 0304 -> octets 04 03 02 01.
  EXPECT_EQ(ask(9, encode_modbus_write_registers(0, std::vector<std::uint16_t>{0x0102, 0x0304})),
            (Bytes{0x10, 0, 0, 0, 2}));
  ASSERT_EQ(src.writes().size(), 1u);
  EXPECT_EQ(src.writes()[0].data, (Bytes{0x04, 0x03, 0x02, 0x01}));
  EXPECT_EQ(ask(9, encode_modbus_read(0x03, 0, 2)), (Bytes{3, 4, 0x01, 0x02, 0x03, 0x04}));
}

TEST_F(ModbusGatewayTest, StatusBlockFields) {
  auto& d = src.data(5);
  // Slave_Diag: Station_Status_1 0x08 (Ext_Diag), _2 0x0C, _3 0x00, master 0x02, ident 80 E0,
  // one octet of extended diagnosis 0x07: 7 octets.
  d.status.diag = {0x08, 0x0C, 0x00, 0x02, 0x80, 0xE0, 0x07};
  d.status.data_exchanges = 70000;  // 70000 - 65536 = 4464 = 0x1170
  d.status.failures = 3;
  d.status.returns = 65537;         // mod 65536 = 1
  // 4096 state 6 (DX) | 4097 flags data valid + ext diag = 0x0003 | 4098 0x1170 | 4099 0x80E0
  // | 4100 0xFFFF (no channel) | 4101 3 | 4102 1 | 4103 7 | 4104.. 080C 0002 80E0 0700 | 0.
  EXPECT_EQ(ask(5, encode_modbus_read(0x04, 0x1000, 13)),
            (Bytes{0x04, 26,   0x00, 0x06, 0x00, 0x03, 0x11, 0x70, 0x80, 0xE0, 0xFF,
                   0xFF, 0x00, 0x03, 0x00, 0x01, 0x00, 0x07, 0x08, 0x0C, 0x00, 0x02,
                   0x80, 0xE0, 0x07, 0x00, 0x00, 0x00}));
  // The same in holding registers; the block's last register (4225 = 0x1081) is readable.
  EXPECT_EQ(ask(5, encode_modbus_read(0x03, 0x1000, 2)), (Bytes{0x03, 4, 0x00, 0x06, 0x00, 0x03}));
  EXPECT_EQ(ask(5, encode_modbus_read(0x03, 0x1081, 1)), (Bytes{0x03, 2, 0x00, 0x00}));
  // Fault flags: Station_Status_1 = 0x01 non-existent | 0x04 cfg fault | 0x40 prm fault
  // -> bits 2, 4, 3 = 0x0004 | 0x0010 | 0x0008 = 0x001C; data not valid.
  d.status.diag = {0x45};
  d.status.data_valid = false;
  d.status.state = dp::SlaveStatusState::Prm;
  EXPECT_EQ(ask(5, encode_modbus_read(0x04, 0x1000, 2)), (Bytes{0x04, 4, 0x00, 0x03, 0x00, 0x1C}));
}

TEST_F(ModbusGatewayTest, StatusFlagsOfASwitchedStationAndTheStandbyUnit) {
  src.set_redundant(true);
  opt.standby_units = true;
  src.add_slave(20, 0x0B05, {{"DI2", 0, 2, 0, 0, false}}).switched = true;
  src.data(20).inputs = {0x01, 0x02};
  src.data(20).status.active_channel = 1;
  src.data(20).status.redundancy_lost = true;
  src.data(20, Side::Standby).inputs = {0x0A, 0x0B};
  src.data(20, Side::Standby).status.active_channel = 1;
  src.data(20, Side::Standby).status.state = dp::SlaveStatusState::NotPresent;
  src.data(20, Side::Standby).status.data_valid = false;
  opt.slaves[20].stale = StaleReaction::KeepLast;
  // Primary: valid b0 | switched b5 | redundancy lost b6 | channel B b7 = 0x00E1; channel 1.
  EXPECT_EQ(ask(20, encode_modbus_read(0x04, 0x1001, 4)),
            (Bytes{4, 8, 0x00, 0xE1, 0x00, 0x00, 0x0B, 0x05, 0x00, 0x01}));
  // Unit 20 + 128 = 148 is the standby side: its inputs, flags station failure b2 | switched b5
  // | channel B b7 | standby view b8 = 0x01A4.
  EXPECT_EQ(ask(148, encode_modbus_read(0x04, 0, 1)), (Bytes{4, 2, 0x0A, 0x0B}));
  EXPECT_EQ(ask(148, encode_modbus_read(0x04, 0x1001, 1)), (Bytes{4, 2, 0x01, 0xA4}));
  EXPECT_EQ(ask(148, encode_modbus_read(0x04, 0x1000, 1)), (Bytes{4, 2, 0x00, 0x07}));
  // Read-only: any write to a standby unit is 0x01.
  EXPECT_EQ(ask(148, Bytes{0x06, 0, 0, 0, 1}), (Bytes{0x86, 0x01}));
  EXPECT_TRUE(src.writes().empty());
  // Slave 5 is one-sided (not switched): no standby unit 133.
  EXPECT_EQ(ask(133, encode_modbus_read(0x04, 0, 1)), (Bytes{0x84, 0x0A}));
  // A changeover swaps the views for the very next request.
  src.swap_sides(20);
  EXPECT_EQ(ask(148, encode_modbus_read(0x04, 0, 1)), (Bytes{4, 2, 0x01, 0x02}));
  EXPECT_EQ(ask(20, encode_modbus_read(0x04, 0, 1)), (Bytes{4, 2, 0x0A, 0x0B}));
}

TEST_F(ModbusGatewayTest, NoStandbyUnitAboveAddress119) {
  src.set_redundant(true);
  opt.standby_units = true;
  src.add_slave(119, 1, {{"DI2", 0, 2, 0, 0, false}}).switched = true;
  src.add_slave(120, 2, {{"DI2", 0, 2, 0, 0, false}}).switched = true;
  src.data(119, Side::Standby).inputs = {0x11, 0x22};
  src.data(120).inputs = {0x12, 0x34};
  // 119 + 128 = 247: the standby side of 119.
  EXPECT_EQ(ask(247, encode_modbus_read(0x04, 0, 1)), (Bytes{4, 2, 0x11, 0x22}));
  // 120 + 128 = 248 is reserved: unknown unit, 0x0A; 120 answers at its primary unit only.
  EXPECT_EQ(ask(248, encode_modbus_read(0x04, 0, 1)), (Bytes{0x84, 0x0A}));
  EXPECT_EQ(ask(120, encode_modbus_read(0x04, 0, 1)), (Bytes{4, 2, 0x12, 0x34}));
}

TEST_F(ModbusGatewayTest, NoStandbyUnitsOnAPlainMasterSystem) {
  src.add_slave(6, 1, {{"DI2", 0, 2, 0, 0, false}}).switched = true;
  opt.standby_units = true;  // ignored: the source is not redundant
  EXPECT_EQ(ask(134, encode_modbus_read(0x04, 0, 1)), (Bytes{0x84, 0x0A}));
  m_gw.reset();
  src.set_redundant(true);
  EXPECT_EQ(ask(134, encode_modbus_read(0x04, 0, 1)), (Bytes{0x04, 0x02, 0x00, 0x00}));
  m_gw.reset();
  opt.standby_units = false;  // off: unit 134 unknown
  EXPECT_EQ(ask(134, encode_modbus_read(0x04, 0, 1)), (Bytes{0x84, 0x0A}));
}

TEST_F(ModbusGatewayTest, GatewayUnitRegisters) {
  src.add_slave(9, 1, {{"A", 0, 2, 0, 0, false}});
  src.add_slave(20, 2, {{"A", 0, 2, 0, 0, false}});
  src.data(20).status.state = dp::SlaveStatusState::Cfg;
  src.set_counters({0x12345678, 2, 0x00010000, 4, 5});
  // Live list reg 0: stations 5 and 9 -> bits 5, 9 = 0x0220; reg 1: none (20 is in Cfg).
  // Configured reg 0 = 0x0220; reg 1 (stations 16..31): station 20 -> bit 4 = 0x0010.
  EXPECT_EQ(ask(0, encode_modbus_read(0x04, 0, 2)), (Bytes{4, 4, 0x02, 0x20, 0x00, 0x00}));
  EXPECT_EQ(ask(0, encode_modbus_read(0x04, 8, 2)), (Bytes{4, 4, 0x02, 0x20, 0x00, 0x10}));
  // 16 mode Operate = 4, 17 master address 1, 18..19 0x12345678, 20..21 2, 22..23 0x00010000,
  // 24..25 4, 26..27 5, 28..29 requests so far including this one = 3, 30..31 exceptions 0.
  EXPECT_EQ(ask(255, encode_modbus_read(0x04, 16, 16)),
            (Bytes{4,    32,   0x00, 0x04, 0x00, 0x01, 0x12, 0x34, 0x56, 0x78, 0x00, 0x00,
                   0x00, 0x02, 0x00, 0x01, 0x00, 0x00, 0x00, 0x00, 0x00, 0x04, 0x00, 0x00,
                   0x00, 0x05, 0x00, 0x00, 0x00, 0x03, 0x00, 0x00, 0x00, 0x00}));
  // No H-system: 32 present 0, 33..37 0, 38 master rack none = 0xFFFF.
  EXPECT_EQ(ask(0, encode_modbus_read(0x04, 32, 7)),
            (Bytes{4, 14, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0xFF, 0xFF}));
  HStatus h;
  h.cpu_state = {3, 4};
  h.cpu_role = {1, 2};
  h.system_mode = 5;
  h.master_rack = 1;
  src.set_h_status(h);
  EXPECT_EQ(ask(0, encode_modbus_read(0x04, 32, 7)),
            (Bytes{4, 14, 0, 1, 0, 3, 0, 4, 0, 1, 0, 2, 0, 5, 0, 1}));
  EXPECT_EQ(ask(0, encode_modbus_read(0x04, 38, 2)), (Bytes{0x84, 0x02}));  // 39 registers
  EXPECT_EQ(ask(0, encode_modbus_read(0x02, 0, 1)), (Bytes{0x82, 0x02}));   // no bit tables
}

TEST_F(ModbusGatewayTest, GatewayUnitsCanBeSwitchedOff) {
  opt.gateway_units = false;
  EXPECT_EQ(ask(0, encode_modbus_read(0x04, 0, 1)), (Bytes{0x84, 0x0A}));
  EXPECT_EQ(ask(255, encode_modbus_read(0x04, 0, 1)), (Bytes{0x84, 0x0A}));
}

TEST_F(ModbusGatewayTest, MasterModeCommand) {
  EXPECT_EQ(ask(0, encode_modbus_read(0x03, 0, 1)), (Bytes{3, 2, 0x00, 0x04}));  // Operate
  EXPECT_EQ(ask(0, Bytes{0x06, 0, 0, 0, 2}), (Bytes{0x06, 0, 0, 0, 2}));          // Stop
  EXPECT_EQ(ask(0, encode_modbus_read(0x03, 0, 1)), (Bytes{3, 2, 0x00, 0x02}));
  EXPECT_EQ(ask(255, encode_modbus_write_registers(0, std::vector<std::uint16_t>{3})),
            (Bytes{0x10, 0, 0, 0, 1}));  // Clear
  // FC23: write 4 (Operate), read back the mode now in force.
  EXPECT_EQ(ask(0, encode_modbus_read_write(0, 1, 0, std::vector<std::uint16_t>{4})),
            (Bytes{0x17, 2, 0x00, 0x04}));
  EXPECT_EQ(src.commands(), (std::vector<dp::MasterMode>{dp::MasterMode::Stop, dp::MasterMode::Clear,
                                                         dp::MasterMode::Operate}));
  EXPECT_EQ(ask(0, Bytes{0x06, 0, 0, 0, 1}), (Bytes{0x86, 0x03}));  // Offline is no command
  EXPECT_EQ(ask(0, Bytes{0x06, 0, 0, 0, 5}), (Bytes{0x86, 0x03}));
  EXPECT_EQ(ask(0, Bytes{0x06, 0, 1, 0, 2}), (Bytes{0x86, 0x02}));  // only HR 0
  src.set_accept_commands(false);
  EXPECT_EQ(ask(0, Bytes{0x06, 0, 0, 0, 2}), (Bytes{0x86, 0x04}));
  EXPECT_EQ(src.commands().size(), 4u);
}

TEST_F(ModbusGatewayTest, BroadcastIsCarriedOutButNotAnswered) {
  EXPECT_TRUE(ask(0, Bytes{0x06, 0, 0, 0, 2}, true).empty());
  EXPECT_EQ(src.mode(), dp::MasterMode::Stop);
  EXPECT_EQ(gw().stats().requests, 1u);
}

TEST_F(ModbusGatewayTest, ReadDeviceIdentification) {
  // Basic stream from object 0: 2B 0E 01, conformity 81, more 00, next 00, 3 objects:
  // 00 len 6 "pbvbus", 01 len 4 "80E0", 02 len 7 "Fake IO".
  EXPECT_EQ(ask(5, encode_modbus_read_device_id(1, 0)),
            (Bytes{0x2B, 0x0E, 0x01, 0x81, 0x00, 0x00, 0x03, 0x00, 0x06, 'p', 'b', 'v', 'b',
                   'u', 's', 0x01, 0x04, '8', '0', 'E', '0', 0x02, 0x07, 'F', 'a', 'k', 'e',
                   ' ', 'I', 'O'}));
  // Individual access to object 1; object 3 does not exist -> 0x02.
  EXPECT_EQ(ask(5, encode_modbus_read_device_id(4, 1)),
            (Bytes{0x2B, 0x0E, 0x04, 0x81, 0x00, 0x00, 0x01, 0x01, 0x04, '8', '0', 'E', '0'}));
  EXPECT_EQ(ask(5, encode_modbus_read_device_id(4, 3)), (Bytes{0xAB, 0x02}));
  // Answered while the slave is down.
  make_stale(5, StaleReaction::Exception);
  EXPECT_EQ(ask(5, encode_modbus_read_device_id(1, 2)).size(), 7u + 2 + 7);
}

TEST_F(ModbusGatewayTest, RandomRequestsNeverCrashAndAlwaysAnswerWellFormed) {
  src.set_redundant(true);
  opt.standby_units = true;
  src.add_slave(9, 1, {{"A", 0, 4, 0, 4, false}, {"B", 0, 3, 0, 5, false}}).switched = true;
  std::mt19937 rng(42);
  const std::uint8_t fcs[] = {1, 2, 3, 4, 5, 6, 15, 16, 23, 43, 0x11, 0x80, 0};
  for (int i = 0; i < 20000; ++i) {
    Bytes pdu(1 + rng() % kModbusMaxPdu);
    for (auto& b : pdu) b = static_cast<std::uint8_t>(rng());
    pdu[0] = fcs[rng() % std::size(fcs)];
    if (pdu.size() > 4 && rng() % 2) {  // plausible addresses and quantities
      pdu[1] = static_cast<std::uint8_t>(rng() % 2 ? 0x10 : 0x00);
      pdu[3] = 0;
      pdu[4] = static_cast<std::uint8_t>(rng() % 16);
    }
    const std::uint8_t units[] = {0, 5, 9, 133, 137, 255, 7, static_cast<std::uint8_t>(rng())};
    const auto rsp = ask(units[rng() % std::size(units)], pdu);
    ASSERT_GE(rsp.size(), 2u);
    ASSERT_EQ(rsp[0] & 0x7F, pdu[0] & 0x7F);
  }
  EXPECT_EQ(gw().stats().requests, 20000u);
}

}  // namespace
}  // namespace pbvbus::gateways::test
