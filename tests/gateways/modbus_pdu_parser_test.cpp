// The request-PDU decoder (modbus_pdu.hpp): every length, quantity and value check of the
// Modbus Application Protocol V1.1b3 §6, and the round trip through the test encoders. Runs
// under ASan+UBSan (sanitize_gateways): truncated PDUs must never be read past their end.
#include "pbvbus/gateways/modbus_pdu.hpp"

#include <gtest/gtest.h>

#include <random>
#include <vector>

#include "pbvbus/gateways/modbus_handler.hpp"

namespace pbvbus::gateways {
namespace {

using Bytes = std::vector<std::uint8_t>;

std::uint8_t ex(const Bytes& pdu) { return decode_modbus_request(pdu).error.exception; }

TEST(ModbusPdu, ReadRequestsHandDecoded) {
  // FC03, start 0x006B, quantity 3: the spec's §6.3 example "03 00 6B 00 03".
  auto d = decode_modbus_request(Bytes{0x03, 0x00, 0x6B, 0x00, 0x03});
  ASSERT_TRUE(d.ok());
  EXPECT_EQ(d.request.function, 0x03);
  EXPECT_EQ(d.request.read_address, 0x006B);
  EXPECT_EQ(d.request.read_quantity, 3);
  EXPECT_FALSE(d.request.writes());
  // FC01 §6.1 example "01 00 13 00 13": coils 20..38.
  d = decode_modbus_request(Bytes{0x01, 0x00, 0x13, 0x00, 0x13});
  ASSERT_TRUE(d.ok());
  EXPECT_EQ(d.request.read_address, 19);
  EXPECT_EQ(d.request.read_quantity, 19);
  EXPECT_TRUE(d.request.reads_bits());
}

TEST(ModbusPdu, ReadQuantityLimits) {
  EXPECT_EQ(ex({0x01, 0, 0, 0x07, 0xD0}), 0);                    // 2000 bits
  EXPECT_EQ(ex({0x01, 0, 0, 0x07, 0xD1}), kExIllegalDataValue);  // 2001
  EXPECT_EQ(ex({0x02, 0, 0, 0x00, 0x00}), kExIllegalDataValue);  // 0
  EXPECT_EQ(ex({0x03, 0, 0, 0x00, 0x7D}), 0);                    // 125 registers
  EXPECT_EQ(ex({0x04, 0, 0, 0x00, 0x7E}), kExIllegalDataValue);  // 126
  EXPECT_EQ(ex({0x04, 0, 0, 0x00, 0x00}), kExIllegalDataValue);
  // 0xFFFF + 1 = 65536 still inside; 0xFFFF + 2 leaves the address space -> 0x02.
  EXPECT_EQ(ex({0x03, 0xFF, 0xFF, 0x00, 0x01}), 0);
  EXPECT_EQ(ex({0x03, 0xFF, 0xFF, 0x00, 0x02}), kExIllegalDataAddress);
}

TEST(ModbusPdu, LengthErrorsAreIllegalDataValue) {
  EXPECT_EQ(ex({0x03, 0, 0, 0}), kExIllegalDataValue);           // short
  EXPECT_EQ(ex({0x03, 0, 0, 0, 1, 0}), kExIllegalDataValue);     // trailing octet
  EXPECT_EQ(ex({0x05, 0, 0, 0xFF}), kExIllegalDataValue);
  EXPECT_EQ(ex({0x06, 0, 0, 0, 0, 0}), kExIllegalDataValue);
  EXPECT_EQ(ex({0x10, 0, 0, 0, 1}), kExIllegalDataValue);
  EXPECT_EQ(ex({0x17, 0, 0, 0, 1, 0, 0, 0, 1}), kExIllegalDataValue);
  EXPECT_EQ(ex({0x2B, 0x0E, 0x01}), kExIllegalDataValue);
}

TEST(ModbusPdu, SingleWrites) {
  // FC05 §6.5 example "05 00 AC FF 00": coil 173 ON.
  const Bytes fc05{0x05, 0x00, 0xAC, 0xFF, 0x00};  // `values` points into it: keep it alive
  auto d = decode_modbus_request(fc05);
  ASSERT_TRUE(d.ok());
  EXPECT_EQ(d.request.write_address, 0x00AC);
  EXPECT_EQ(d.request.write_quantity, 1);
  EXPECT_EQ(d.request.write_value(0), 1);
  EXPECT_EQ(ex({0x05, 0, 0, 0x00, 0x00}), 0);
  EXPECT_EQ(ex({0x05, 0, 0, 0x00, 0xFF}), kExIllegalDataValue);  // only 0000 / FF00
  EXPECT_EQ(ex({0x05, 0, 0, 0x00, 0x01}), kExIllegalDataValue);
  EXPECT_EQ(ex({0x05, 0, 0, 0xFF, 0xFF}), kExIllegalDataValue);
  // FC06 §6.6 example "06 00 01 00 03": register 2 := 3; any value is fine.
  const Bytes fc06{0x06, 0x00, 0x01, 0x00, 0x03};
  d = decode_modbus_request(fc06);
  ASSERT_TRUE(d.ok());
  EXPECT_EQ(d.request.write_address, 1);
  EXPECT_EQ(d.request.write_value(0), 3);
}

TEST(ModbusPdu, MultipleWrites) {
  // FC15 §6.11 example "0F 00 13 00 0A 02 CD 01": 10 coils from 20, byte count 2 = ceil(10/8).
  const Bytes fc15{0x0F, 0x00, 0x13, 0x00, 0x0A, 0x02, 0xCD, 0x01};
  auto d = decode_modbus_request(fc15);
  ASSERT_TRUE(d.ok());
  EXPECT_EQ(d.request.write_quantity, 10);
  // 0xCD = 1100 1101: coils 0..7 (LSB first) = 1 0 1 1 0 0 1 1; 0x01: coil 8 = 1, coil 9 = 0.
  const int want[10] = {1, 0, 1, 1, 0, 0, 1, 1, 1, 0};
  for (int i = 0; i < 10; ++i) EXPECT_EQ(d.request.write_value(static_cast<std::size_t>(i)), want[i]) << i;
  EXPECT_EQ(ex({0x0F, 0, 0x13, 0, 0x0A, 0x01, 0xCD}), kExIllegalDataValue);  // byte count 1 ≠ 2
  EXPECT_EQ(ex({0x0F, 0, 0x13, 0, 0x0A, 0x02, 0xCD}), kExIllegalDataValue);  // one octet missing
  // FC16 §6.12 example "10 00 01 00 02 04 00 0A 01 02".
  const Bytes fc16{0x10, 0x00, 0x01, 0x00, 0x02, 0x04, 0x00, 0x0A, 0x01, 0x02};
  d = decode_modbus_request(fc16);
  ASSERT_TRUE(d.ok());
  EXPECT_EQ(d.request.write_value(0), 0x000A);
  EXPECT_EQ(d.request.write_value(1), 0x0102);
  EXPECT_EQ(ex({0x10, 0, 1, 0, 2, 0x03, 0, 0x0A, 1}), kExIllegalDataValue);
  EXPECT_EQ(ex({0x10, 0, 1, 0, 0, 0x00}), kExIllegalDataValue);  // quantity 0
}

TEST(ModbusPdu, WriteQuantityLimits) {
  // FC15: 1968 coils = 246 octets is the largest; 1969 is refused before the byte count.
  EXPECT_EQ(ex(encode_modbus_write_coils(0, std::vector<bool>(1968, true))), 0);
  EXPECT_EQ(ex(encode_modbus_write_coils(0, std::vector<bool>(1969, true))), kExIllegalDataValue);
  EXPECT_EQ(ex(encode_modbus_write_registers(0, std::vector<std::uint16_t>(123, 7))), 0);
  EXPECT_EQ(ex(encode_modbus_write_registers(0, std::vector<std::uint16_t>(124, 7))),
            kExIllegalDataValue);
  // FC23: 121 written, 125 read.
  EXPECT_EQ(ex(encode_modbus_read_write(0, 125, 0, std::vector<std::uint16_t>(121, 1))), 0);
  EXPECT_EQ(ex(encode_modbus_read_write(0, 126, 0, std::vector<std::uint16_t>(1, 1))),
            kExIllegalDataValue);
  EXPECT_EQ(ex(encode_modbus_read_write(0, 1, 0, std::vector<std::uint16_t>(122, 1))),
            kExIllegalDataValue);
  EXPECT_EQ(ex(encode_modbus_write_registers(0xFFFF, std::vector<std::uint16_t>(2, 1))),
            kExIllegalDataAddress);
}

TEST(ModbusPdu, ReadWriteMultiple) {
  // FC23 §6.17 example: read 6 from 0x0003, write 3 to 0x000E: 00FF 00FF 00FF.
  const Bytes pdu{0x17, 0x00, 0x03, 0x00, 0x06, 0x00, 0x0E, 0x00, 0x03, 0x06,
                  0x00, 0xFF, 0x00, 0xFF, 0x00, 0xFF};
  auto d = decode_modbus_request(pdu);
  ASSERT_TRUE(d.ok());
  EXPECT_EQ(d.request.read_address, 3);
  EXPECT_EQ(d.request.read_quantity, 6);
  EXPECT_EQ(d.request.write_address, 14);
  EXPECT_EQ(d.request.write_quantity, 3);
  EXPECT_EQ(d.request.write_value(2), 0x00FF);
  EXPECT_EQ(encode_modbus_read_write(3, 6, 14, std::vector<std::uint16_t>{0xFF, 0xFF, 0xFF}),
            pdu);
}

TEST(ModbusPdu, DeviceIdentificationAndUnknownFunctions) {
  auto d = decode_modbus_request(Bytes{0x2B, 0x0E, 0x01, 0x00});
  ASSERT_TRUE(d.ok());
  EXPECT_EQ(d.request.read_device_id_code, 1);
  EXPECT_EQ(ex({0x2B, 0x0E, 0x05, 0x00}), kExIllegalDataValue);  // code outside 1..4
  EXPECT_EQ(ex({0x2B, 0x0D, 0x01, 0x00}), kExIllegalFunction);   // CANopen MEI: not served
  EXPECT_EQ(ex({0x11}), kExIllegalFunction);                     // report server id
  EXPECT_EQ(ex({0x08, 0, 0, 0, 0}), kExIllegalFunction);         // diagnostics
  EXPECT_EQ(ex({0x83, 0, 0, 0, 1}), kExIllegalFunction);
  EXPECT_EQ(ex({}), kExIllegalFunction);
  EXPECT_FALSE(decode_modbus_request(Bytes{0x16, 0, 0, 0, 0, 0, 0}).error.reason.empty());
}

TEST(ModbusPdu, RoundTripThroughTheEncoders) {
  EXPECT_EQ(encode_modbus_read(0x04, 0x1000, 8), (Bytes{0x04, 0x10, 0x00, 0x00, 0x08}));
  EXPECT_EQ(encode_modbus_write_single(0x06, 2, 0xBEEF), (Bytes{0x06, 0, 2, 0xBE, 0xEF}));
  const std::vector<std::uint16_t> regs{0x1234, 0x5678};
  const Bytes w = encode_modbus_write_registers(9, regs);
  auto d = decode_modbus_request(w);
  ASSERT_TRUE(d.ok());
  EXPECT_EQ(d.request.write_address, 9);
  EXPECT_EQ(d.request.write_value(0), 0x1234);
  EXPECT_EQ(d.request.write_value(1), 0x5678);
  const std::vector<bool> coils{true, false, false, true, true, false, false, false, true};
  const Bytes wc = encode_modbus_write_coils(3, coils);
  d = decode_modbus_request(wc);
  ASSERT_TRUE(d.ok());
  for (std::size_t i = 0; i < coils.size(); ++i) EXPECT_EQ(d.request.write_value(i), coils[i] ? 1 : 0);
}

TEST(ModbusPdu, EveryTruncationOfValidRequestsIsRefusedWithoutOverread) {
  const std::vector<Bytes> valid = {
      encode_modbus_read(0x01, 0, 8), encode_modbus_write_single(0x05, 1, 0xFF00),
      encode_modbus_write_coils(0, std::vector<bool>(17, true)),
      encode_modbus_write_registers(0, std::vector<std::uint16_t>(5, 3)),
      encode_modbus_read_write(0, 2, 0, std::vector<std::uint16_t>(3, 3)),
      encode_modbus_read_device_id(1, 0)};
  for (const auto& v : valid) {
    ASSERT_TRUE(decode_modbus_request(v).ok());
    for (std::size_t n = 1; n < v.size(); ++n) {
      // A heap copy of exactly n octets so ASan sees any read past the end.
      Bytes cut(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(n));
      EXPECT_NE(ex(cut), 0) << "FC " << int(v[0]) << " cut to " << n;
    }
  }
  std::mt19937 rng(9);
  for (int i = 0; i < 20000; ++i) {
    Bytes b(1 + rng() % 20);
    for (auto& x : b) x = static_cast<std::uint8_t>(rng());
    if (rng() % 2) b[0] = static_cast<std::uint8_t>(std::vector<int>{1, 2, 3, 4, 5, 6, 15, 16, 23, 43}[rng() % 10]);
    auto d = decode_modbus_request(b);
    if (d.ok()) {
      for (std::size_t k = 0; k < d.request.write_quantity; ++k) (void)d.request.write_value(k);
    } else {
      EXPECT_TRUE(d.error.exception == 1 || d.error.exception == 2 || d.error.exception == 3);
    }
  }
}

}  // namespace
}  // namespace pbvbus::gateways
