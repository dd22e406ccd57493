// The S7 PDU header (protocol-facts.md §H.4; stacks/s7 s7_pdu.hpp).
#include "pbvbus/s7/s7_pdu.hpp"

#include <gtest/gtest.h>

#include "hex.hpp"

namespace pbvbus::s7 {
namespace {

using test::hex;
using Bytes = std::vector<std::uint8_t>;

TEST(S7Pdu, JobHeaderIsTenOctets) {
  const auto pdu = hex("32 01 00 00 12 34 00 02 00 01 | 04 01 | AA");
  const auto d = decode_s7_pdu(pdu);
  ASSERT_TRUE(d.ok()) << to_string(d.error);
  EXPECT_EQ(d.value.header, (S7Header{kS7Job, 0x1234, 0, 0}));
  EXPECT_EQ(Bytes(d.value.params.begin(), d.value.params.end()), hex("04 01"));
  EXPECT_EQ(Bytes(d.value.data.begin(), d.value.data.end()), hex("AA"));
  EXPECT_EQ(params_offset(d.value), 10u);
  EXPECT_EQ(data_offset(d.value), 12u);
}

TEST(S7Pdu, AckAndAckDataCarryErrorClassAndCode) {
  const auto ack = hex("32 02 00 00 00 07 00 00 00 00 85 00");
  const auto a = decode_s7_pdu(ack);
  ASSERT_TRUE(a.ok());
  EXPECT_EQ(a.value.header, (S7Header{kS7Ack, 7, error_class::kSupplies, 0x00}));
  const auto ackd = hex("32 03 00 00 00 01 00 02 00 00 81 04 | 04 01");
  const auto b = decode_s7_pdu(ackd);
  ASSERT_TRUE(b.ok());
  EXPECT_EQ(b.value.header.error_class, error_class::kApplicationRelationship);
  EXPECT_EQ(b.value.header.error_code, 0x04);
  EXPECT_EQ(params_offset(b.value), 12u);
}

TEST(S7Pdu, UserdataHeaderIsTenOctetsAndReservedWordIsIgnored) {
  const auto pdu = hex("32 07 AB CD 00 05 00 00 00 00");
  const auto d = decode_s7_pdu(pdu);
  ASSERT_TRUE(d.ok());
  EXPECT_EQ(d.value.header.type, kS7Userdata);
  EXPECT_EQ(d.value.header.pdu_ref, 5);
}

TEST(S7Pdu, EncodeWritesLengthsAndZeroReservedWord) {
  const auto params = hex("F0 00 00 01 00 01 00 F0");
  const auto e = encode_s7_pdu(S7Header{kS7AckData, 0, 0, 0}, params, {});
  ASSERT_TRUE(e.ok());
  EXPECT_EQ(e.value, hex("32 03 00 00 00 00 00 08 00 00 00 00 F0 00 00 01 00 01 00 F0"));
  const auto j = encode_s7_pdu(S7Header{kS7Job, 0x0102, 0x81, 0x04}, hex("04"), hex("AA BB"));
  EXPECT_EQ(j.value, hex("32 01 00 00 01 02 00 01 00 02 04 AA BB"));  // no error octets in a Job
  const Bytes big(65536, 0);
  EXPECT_EQ(encode_s7_pdu(S7Header{}, big, {}).error, Error::S7PduTooLarge);
  EXPECT_EQ(encode_s7_pdu(S7Header{}, {}, big).error, Error::S7PduTooLarge);
}

TEST(S7Pdu, EveryDecodeError) {
  struct Case {
    const char* octets;
    Error error;
    std::size_t at;
  } cases[] = {
      {"", Error::S7TooShort, 0},
      {"32", Error::S7TooShort, 1},
      {"72 01 00 00 00 00 00 00 00 00", Error::S7BadProtocolId, 0},  // S7comm-plus id
      {"32 04 00 00 00 00 00 00 00 00", Error::S7UnknownPduType, 1},
      {"32 08 00 00 00 00 00 00 00 00", Error::S7UnknownPduType, 1},
      {"32 01 00 00 00 00 00 00 00", Error::S7TooShort, 9},
      {"32 03 00 00 00 00 00 00 00 00 00", Error::S7TooShort, 11},
      {"32 01 00 00 00 00 00 02 00 00 04", Error::S7LengthMismatch, 6},
      {"32 01 00 00 00 00 00 00 00 00 04", Error::S7LengthMismatch, 6},
      {"32 03 00 00 00 00 00 00 00 01 00 00", Error::S7LengthMismatch, 6},
  };
  for (const auto& c : cases) {
    const auto d = decode_s7_pdu(hex(c.octets));
    EXPECT_EQ(d.error, c.error) << c.octets << ": " << to_string(d.error);
    EXPECT_EQ(d.at, c.at) << c.octets;
  }
}

TEST(S7Pdu, EveryErrorHasItsOwnText) {
  for (int i = 0; i <= static_cast<int>(Error::S7BadSzlResponse); ++i) {
    for (int j = 0; j < i; ++j) {
      EXPECT_NE(to_string(static_cast<Error>(i)), to_string(static_cast<Error>(j)))
          << i << " " << j;
    }
    EXPECT_NE(to_string(static_cast<Error>(i)), "unknown error") << i;
  }
}

}  // namespace
}  // namespace pbvbus::s7
