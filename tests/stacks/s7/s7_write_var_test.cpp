// Write Var (protocol-facts.md §H.4; stacks/s7 s7_write_var.hpp).
#include "pbvbus/s7/s7_write_var.hpp"

#include <gtest/gtest.h>

#include "hex.hpp"

namespace pbvbus::s7 {
namespace {

using test::hex;
using Bytes = std::vector<std::uint8_t>;

Bytes bytes(std::span<const std::uint8_t> s) {
  return Bytes(s.begin(), s.end());
}

Decoded<WriteVarRequest> request_of(const Bytes& pdu) {
  const auto d = decode_s7_pdu(pdu);
  if (!d.ok()) return {{}, d.error, d.at};
  return decode_write_var_request(d.value);
}

Decoded<std::vector<std::uint8_t>> response_of(const Bytes& pdu) {
  const auto d = decode_s7_pdu(pdu);
  if (!d.ok()) return {{}, d.error, d.at};
  return decode_write_var_response(d.value);
}

// DB1.DBW2 := W#16#1234 by hand: item 12 0A 10 04 0001 0001 84 000010 (byte 2 = bit 16), data
// item 00 04 0010 1234 (reserved 00, BYTE/WORD/DWORD, 16 bits).
TEST(S7WriteVar, Db1Dbw2RequestAndAnswer) {
  const Bytes word = hex("12 34");
  const WriteVarItem item{
      {transport::kWord, 1, 1, area::kDataBlock, 2 * 8}, data_transport::kByte, word};
  const auto job = encode_write_var_request(3, std::span(&item, 1));
  ASSERT_TRUE(job.ok());
  EXPECT_EQ(job.value,
            hex("32 01 00 00 00 03 00 0E 00 06 | 05 01 12 0A 10 04 00 01 00 01 84 00 00 10 |"
                "00 04 00 10 12 34"));
  const auto r = request_of(job.value);
  ASSERT_TRUE(r.ok()) << to_string(r.error);
  ASSERT_EQ(r.value.items.size(), 1u);
  EXPECT_EQ(r.value.items[0], item.var);
  EXPECT_EQ(r.value.values[0].return_code, return_code::kReserved);
  EXPECT_EQ(r.value.values[0].length, 16);
  EXPECT_EQ(bytes(r.value.values[0].data), word);

  const std::uint8_t ok = return_code::kSuccess;
  const auto ack = encode_write_var_response(3, std::span(&ok, 1));
  ASSERT_TRUE(ack.ok());
  EXPECT_EQ(ack.value, hex("32 03 00 00 00 03 00 02 00 01 00 00 | 05 01 | FF"));
  const auto codes = response_of(ack.value);
  ASSERT_TRUE(codes.ok());
  EXPECT_EQ(codes.value, Bytes{0xFF});
}

// A bit (M0.1 := 1, data transport BIT, length 1 bit in one octet) then a byte: the odd first
// data item gets a fill octet; the answer has one return code per item.
TEST(S7WriteVar, BitAndByteWithFillOctet) {
  const Bytes one = hex("01"), b = hex("7F");
  const WriteVarItem items[] = {
      {{transport::kBit, 1, 0, area::kFlags, 1}, data_transport::kBit, one},
      {{transport::kByte, 1, 0, area::kFlags, 8}, data_transport::kByte, b}};
  const auto job = encode_write_var_request(4, items);
  ASSERT_TRUE(job.ok());
  EXPECT_EQ(job.value,
            hex("32 01 00 00 00 04 00 1A 00 0B | 05 02 |"
                "12 0A 10 01 00 01 00 00 83 00 00 01 | 12 0A 10 02 00 01 00 00 83 00 00 08 |"
                "00 03 00 01 01 00 | 00 04 00 08 7F"));
  const auto r = request_of(job.value);
  ASSERT_TRUE(r.ok());
  ASSERT_EQ(r.value.values.size(), 2u);
  EXPECT_EQ(bytes(r.value.values[0].data), one);
  EXPECT_EQ(bytes(r.value.values[1].data), b);

  const Bytes codes = {return_code::kSuccess, return_code::kAddressOutOfRange};
  const auto ack = encode_write_var_response(4, codes);
  EXPECT_EQ(ack.value, hex("32 03 00 00 00 04 00 02 00 02 00 00 | 05 02 | FF 05"));
  EXPECT_EQ(response_of(ack.value).value, codes);
}

struct Bad {
  const char* octets;
  Error error;
  std::size_t at;
};

TEST(S7WriteVar, EveryRequestDecodeError) {
  const Bad cases[] = {
      {"32 07 00 00 00 01 00 00 00 00", Error::S7WrongPduType, 1},
      {"32 01 00 00 00 01 00 0E 00 06 | 04 01 12 0A 10 04 00 01 00 01 84 00 00 10 | 00 04 00 10 12 "
       "34",
       Error::S7UnexpectedFunction, 10},
      {"32 01 00 00 00 01 00 0E 00 00 | 05 01 12 0A 10 04 00 01 00 01 84 00 00 10",
       Error::S7DataTruncated, 24},
      {"32 01 00 00 00 01 00 0E 00 05 | 05 01 12 0A 10 04 00 01 00 01 84 00 00 10 | 00 04 00 10 12",
       Error::S7DataTruncated, 26},
      {"32 01 00 00 00 01 00 0E 00 07 | 05 01 12 0A 10 04 00 01 00 01 84 00 00 10 | 00 04 00 10 12 "
       "34 00",
       Error::S7TrailingData, 30},
      {"32 01 00 00 00 01 00 0E 00 06 | 05 01 12 0A 10 04 00 01 00 01 84 00 00 10 | 00 01 00 10 12 "
       "34",
       Error::S7BadDataTransportSize, 25},
      {"32 01 00 00 00 01 00 1A 00 05 | 05 02 12 0A 10 02 00 01 00 01 84 00 00 00 12 0A 10 02 00 "
       "01 00 01 84 00 00 08 |"
       "00 04 00 08 12",
       Error::S7DataTruncated, 41},
  };
  for (const auto& c : cases) {
    const auto r = request_of(hex(c.octets));
    EXPECT_EQ(r.error, c.error) << c.octets << ": " << to_string(r.error);
    EXPECT_EQ(r.at, c.at) << c.octets;
  }
}

TEST(S7WriteVar, EveryResponseDecodeError) {
  const Bad cases[] = {
      {"32 01 00 00 00 01 00 02 00 01 | 05 01 | FF", Error::S7WrongPduType, 1},
      {"32 03 00 00 00 01 00 01 00 01 00 00 | 05 | FF", Error::S7BadParameterLength, 6},
      {"32 03 00 00 00 01 00 02 00 01 00 00 | 04 01 | FF", Error::S7UnexpectedFunction, 12},
      {"32 03 00 00 00 01 00 02 00 00 00 00 | 05 00", Error::S7NoItems, 13},
      {"32 03 00 00 00 01 00 02 00 01 00 00 | 05 02 | FF", Error::S7DataTruncated, 15},
      {"32 03 00 00 00 01 00 02 00 02 00 00 | 05 01 | FF FF", Error::S7TrailingData, 15},
  };
  for (const auto& c : cases) {
    const auto r = response_of(hex(c.octets));
    EXPECT_EQ(r.error, c.error) << c.octets << ": " << to_string(r.error);
    EXPECT_EQ(r.at, c.at) << c.octets;
  }
}

TEST(S7WriteVar, EncoderErrors) {
  EXPECT_EQ(encode_write_var_request(1, {}).error, Error::S7NoItems);
  EXPECT_EQ(encode_write_var_response(1, {}).error, Error::S7NoItems);
  const std::vector<WriteVarItem> many(256);
  EXPECT_EQ(encode_write_var_request(1, many).error, Error::S7TooManyItems);
  const Bytes codes(256, 0xFF);
  EXPECT_EQ(encode_write_var_response(1, codes).error, Error::S7TooManyItems);
  const Bytes two = hex("01 00");
  const WriteVarItem bits{{transport::kBit, 1, 0, area::kFlags, 0}, data_transport::kBit, two};
  EXPECT_EQ(encode_write_var_request(1, std::span(&bits, 1)).error, Error::S7ItemLengthMismatch);
  const WriteVarItem far{
      {transport::kByte, 1, 0, area::kFlags, 0x1000000}, data_transport::kByte, two};
  EXPECT_EQ(encode_write_var_request(1, std::span(&far, 1)).error, Error::S7AddressTooLarge);
}

}  // namespace
}  // namespace pbvbus::s7
