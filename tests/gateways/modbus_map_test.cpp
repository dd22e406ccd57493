// ModbusMap: the register layout (each module on a new register, bit addresses over the
// unpadded telegram, word orders per slave and module), the unit list (slaves, standby units,
// address 0 refused with a warning) and the three printed forms, checked against hand-written
// expectations.
#include "pbvbus/gateways/modbus_map.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <string>

#include "fake_source.hpp"
#include "pbvbus/gateways/modbus_image.hpp"

namespace pbvbus::gateways::test {
namespace {

// Slave 3 "IO", ident 0x1234: m0 "AI3" 3 in; m1 "DO1" 1 out; m2 "IO4" 4 in / 4 out.
//   Inputs: m0 octets 0..2 -> IR 0..1 (2 registers), m2 octets 3..6 -> IR 2..3.
//   Outputs: m1 octet 0 -> HR 0, m2 octets 1..4 -> HR 1..2.
//   Discrete inputs 0..55 (7 octets), coils 0..39 (5 octets).
SourceSlave& add_io(FakeSource& src) {
  return src.add_slave(3, 0x1234,
                {{"AI3", 0, 3, 0, 0, false}, {"DO1", 0, 0, 0, 1, false}, {"IO4", 0, 4, 0, 4, true}},
                "IO");
}

TEST(ModbusMap, LayoutEachModuleOnANewRegister) {
  FakeSource src;
  add_io(src);
  ModbusGatewayOptions opt;
  opt.slaves[3].word_order = WordOrder::ByteSwap;
  opt.slaves[3].module_word_order[2] = WordOrder::WordSwap;
  ModbusMap map(src, opt);
  ASSERT_EQ(map.units().size(), 1u);
  const ModbusUnitMap* u = map.unit(3);
  ASSERT_NE(u, nullptr);
  EXPECT_EQ(u->input_registers, 4);
  EXPECT_EQ(u->holding_registers, 3);
  EXPECT_EQ(u->input_len, 7u);
  EXPECT_EQ(u->output_len, 5u);
  ASSERT_EQ(u->modules.size(), 3u);
  EXPECT_EQ(u->modules[0].input_register, 0);
  EXPECT_EQ(u->modules[0].input_registers, 2);
  EXPECT_EQ(u->modules[2].input_register, 2);
  EXPECT_EQ(u->modules[1].holding_register, 0);
  EXPECT_EQ(u->modules[1].holding_registers, 1);
  EXPECT_EQ(u->modules[2].holding_register, 1);
  EXPECT_EQ(u->modules[2].holding_registers, 2);
  EXPECT_EQ(u->modules[0].order, WordOrder::ByteSwap);
  EXPECT_EQ(u->modules[2].order, WordOrder::WordSwap);
  EXPECT_EQ(u->input_register_module, (std::vector<std::uint16_t>{0, 0, 2, 2}));
  EXPECT_EQ(u->holding_register_module, (std::vector<std::uint16_t>{1, 2, 2}));
  EXPECT_TRUE(u->writable);
  EXPECT_EQ(map.unit(0), nullptr);
  EXPECT_EQ(map.unit(4), nullptr);
  EXPECT_EQ(map.unit(131), nullptr);
}

TEST(ModbusMap, AddressZeroIsNotMappedAndStandbyUnitsOnlyForSwitchedStations) {
  FakeSource src;
  src.set_redundant(true);
  src.add_slave(0, 1, {{"DI1", 0, 1, 0, 0, false}});
  add_io(src);
  src.add_slave(7, 2, {{"DI1", 0, 1, 0, 0, false}}).switched = true;
  ModbusGatewayOptions opt;
  opt.standby_units = true;
  ModbusMap map(src, opt);
  ASSERT_EQ(map.warnings().size(), 1u);
  EXPECT_NE(map.warnings()[0].find("address 0"), std::string::npos);
  EXPECT_EQ(map.unit(0), nullptr);
  ASSERT_NE(map.unit(7 + 128), nullptr);
  EXPECT_EQ(map.unit(135)->side, Side::Standby);
  EXPECT_FALSE(map.unit(135)->writable);
  EXPECT_EQ(map.unit(3 + 128), nullptr);
  EXPECT_EQ(map.units().size(), 3u);  // 3, 7, 135
}

TEST(ModbusMap, StandbyUnitsOnlyUpToAddress119) {
  // Seed 003 p. 93: primary addresses 1..119, standby at + 128 with 247 the maximum. So 119
  // has its standby at 247; 120 (and up to 125) would land on the reserved 248..253: none.
  FakeSource src;
  src.set_redundant(true);
  src.add_slave(119, 1, {{"DI1", 0, 1, 0, 0, false}}).switched = true;
  src.add_slave(120, 2, {{"DI1", 0, 1, 0, 0, false}}).switched = true;
  src.add_slave(125, 3, {{"DI1", 0, 1, 0, 0, false}}).switched = true;
  ModbusGatewayOptions opt;
  opt.standby_units = true;
  ModbusMap map(src, opt);
  ASSERT_NE(map.unit(247), nullptr);
  EXPECT_EQ(map.unit(247)->address, 119);
  EXPECT_EQ(map.unit(247)->side, Side::Standby);
  ASSERT_NE(map.unit(120), nullptr);  // reachable at its primary unit
  ASSERT_NE(map.unit(125), nullptr);
  for (int u = 248; u <= 255; ++u) EXPECT_EQ(map.unit(static_cast<std::uint8_t>(u)), nullptr) << u;
  EXPECT_EQ(map.units().size(), 4u);  // 119, 120, 125, 247
  ASSERT_EQ(map.warnings().size(), 2u);
  EXPECT_NE(map.warnings()[0].find("address 120 has no standby unit"), std::string::npos);
  EXPECT_NE(map.warnings()[1].find("address 125 has no standby unit"), std::string::npos);
}

TEST(ModbusMap, ReadOnlySlave) {
  FakeSource src;
  add_io(src).outputs_writable = false;
  ModbusMap map(src, {});
  EXPECT_FALSE(map.unit(3)->writable);
}

TEST(ModbusMap, ImageConversions) {
  FakeSource src;
  add_io(src);
  ModbusGatewayOptions opt;
  opt.slaves[3].module_word_order[2] = WordOrder::ByteWordSwap;
  ModbusMap map(src, opt);
  const ModbusUnitMap& u = *map.unit(3);
  // Inputs 11 22 33 | 44 55 66 77: m0 -> 1122 3300; m2 DC BA -> 77 66 55 44 -> 7766 5544.
  const std::vector<std::uint8_t> in{0x11, 0x22, 0x33, 0x44, 0x55, 0x66, 0x77};
  EXPECT_EQ(telegram_to_registers(u, in, false),
            (std::vector<std::uint16_t>{0x1122, 0x3300, 0x7766, 0x5544}));
  // Outputs: HR 2 := ABCD is m2's second register: view octets 2,3 -> after DC BA back to the
  // telegram the view "00 00 AB CD" is octets "CD AB 00 00" at m2 (octets 1..4).
  std::vector<std::uint8_t> out(5, 0);
  EXPECT_EQ(patch_output_register(u, 2, 0xABCD, out), 2);
  EXPECT_EQ(out, (std::vector<std::uint8_t>{0x00, 0xCD, 0xAB, 0x00, 0x00}));
  // HR 0 = m1 (1 octet): the low byte is dropped.
  EXPECT_EQ(patch_output_register(u, 0, 0x9988, out), 1);
  EXPECT_EQ(out[0], 0x99);
  EXPECT_EQ(patch_output_register(u, 3, 1, out), -1);
  // apply_word_order is its own inverse for every order and length.
  for (auto o : {WordOrder::HighByteFirst, WordOrder::ByteSwap, WordOrder::WordSwap,
                 WordOrder::ByteWordSwap})
    for (std::size_t n = 0; n < 11; ++n) {
      std::vector<std::uint8_t> v(n);
      for (std::size_t i = 0; i < n; ++i) v[i] = static_cast<std::uint8_t>(i + 1);
      auto w = v;
      apply_word_order(w, o);
      apply_word_order(w, o);
      EXPECT_EQ(w, v) << to_string(o) << " " << n;
    }
}

TEST(ModbusMap, CsvRowsPerModuleAndStatusField) {
  FakeSource src;
  add_io(src);
  ModbusGatewayOptions opt;
  opt.gateway_units = false;
  ModbusMap map(src, opt);
  const std::string csv = map.to_csv();
  const std::string want =
      "unit,table,first_address,count,slave,slot,module,data_type,description\n"
      "3,input_register,0,2,3,0,AI3,BYTES AB CD,3 input octets from octet 0\n"
      "3,discrete_input,0,24,3,0,AI3,BIT,\"input bits, octet x 8 + bit\"\n"
      "3,holding_register,0,1,3,1,DO1,BYTES AB CD,1 output octets from octet 0\n"
      "3,coil,0,8,3,1,DO1,BIT,\"output bits, octet x 8 + bit\"\n"
      "3,input_register,2,2,3,2,IO4,BYTES AB CD,4 input octets from octet 3\n"
      "3,discrete_input,24,32,3,2,IO4,BIT,\"input bits, octet x 8 + bit\"\n"
      "3,holding_register,1,2,3,2,IO4,BYTES AB CD,4 output octets from octet 1\n"
      "3,coil,8,32,3,2,IO4,BIT,\"output bits, octet x 8 + bit\"\n"
      "3,input_register,4096,1,3,,status,UINT16,DP state: 1 Inactive 2 Diag 3 Prm 4 Cfg 5 "
      "CheckDiag 6 DataExchange 7 NotPresent 8 Locked\n";
  ASSERT_GE(csv.size(), want.size());
  EXPECT_EQ(csv.substr(0, want.size()), want);
  EXPECT_NE(csv.find("3,input_register,4104,122,3,,status,BYTES AB CD,"), std::string::npos);
  EXPECT_NE(csv.find("3,holding_register,4096,130,3,,status,"), std::string::npos);
  // 1 header + 8 module rows + 9 status fields + 1 mirror row.
  EXPECT_EQ(std::count(csv.begin(), csv.end(), '\n'), 19);
}

TEST(ModbusMap, GatewayRowsTextAndJson) {
  FakeSource src;
  add_io(src);
  ModbusMap map(src, {});
  const std::string csv = map.to_csv();
  EXPECT_NE(csv.find("0,input_register,18,2,,,gateway,UINT32 AB CD,station failures\n"),
            std::string::npos);
  EXPECT_NE(csv.find("255,holding_register,0,1,,,gateway,UINT16,"), std::string::npos);
  const std::string text = map.to_text();
  EXPECT_NE(text.find("unit 3: slave 3 IO (ident 0x1234), stale data: exception"),
            std::string::npos);
  EXPECT_NE(text.find("module 2 IO4 [AB CD]: IR 2..3 (4 octets), DI 24..55 HR 1..2 (4 octets), "
                      "coils 8..39"),
            std::string::npos)
      << text;
  const std::string json = map.to_json();
  EXPECT_EQ(json.rfind("{\"source\":\"fake master system\",\"gateway_units\":true,\"units\":[{"
                       "\"unit\":3,\"slave\":3,\"side\":\"primary\",\"model\":\"IO\",",
                       0),
            0u)
      << json;
  EXPECT_NE(json.find("{\"slot\":1,\"name\":\"DO1\",\"word_order\":\"AB CD\",\"in_octets\":0,"
                      "\"out_octets\":1,\"holding_register\":0,\"holding_register_count\":1,"
                      "\"coil\":0}"),
            std::string::npos);
  EXPECT_EQ(json.substr(json.size() - 14), "\"warnings\":[]}");
}

}  // namespace
}  // namespace pbvbus::gateways::test
