// Read Var and the item codecs (protocol-facts.md §H.4; tools-and-formats.md §3.4; stacks/s7).
#include "pbvbus/s7/s7_read_var.hpp"

#include <gtest/gtest.h>

#include "hex.hpp"

#include "pbvbus/s7/cotp_data.hpp"

namespace pbvbus::s7 {
namespace {

using test::hex;
using Bytes = std::vector<std::uint8_t>;

Bytes bytes(std::span<const std::uint8_t> s) {
  return Bytes(s.begin(), s.end());
}

// The S7 PDU inside a TPKT + DT frame.
Bytes s7_of(const Bytes& frame) {
  return Bytes(frame.begin() + 7, frame.end());
}

Decoded<std::vector<VarItem>> request_of(const Bytes& pdu) {
  const auto d = decode_s7_pdu(pdu);
  if (!d.ok()) return {{}, d.error, d.at};
  return decode_read_var_request(d.value);
}

Decoded<std::vector<DataItem>> response_of(const Bytes& pdu) {
  const auto d = decode_s7_pdu(pdu);
  if (!d.ok()) return {{}, d.error, d.at};
  return decode_read_var_response(d.value);
}

// §3.4: nodes7 merged DB1,B0.4 and DB1,INT2 into one read of 4 bytes.
const Bytes kNodes7Read = hex(
    "03 00 00 1F 02 F0 80 32 01 00 00 00 01 00 0E 00 00 04 01 12 0A 10 02 00 04 00 01 84 00 00 00");
const Bytes kNodes7Answer =
    hex("03 00 00 1D 02 F0 80 32 03 00 00 00 01 00 02 00 08 00 00 04 01 FF 04 00 20 DE AD BE EF");

TEST(S7ReadVar, Nodes7RequestDecodes) {
  const auto r = request_of(s7_of(kNodes7Read));
  ASSERT_TRUE(r.ok()) << to_string(r.error);
  ASSERT_EQ(r.value.size(), 1u);
  EXPECT_EQ(r.value[0], (VarItem{transport::kByte, 4, 1, area::kDataBlock, 0}));
  const auto again = encode_read_var_request(1, r.value);
  ASSERT_TRUE(again.ok());
  EXPECT_EQ(encode_tpkt_data(again.value).value, kNodes7Read);
}

TEST(S7ReadVar, Nodes7AnswerIsEncodedByteForByte) {
  const Bytes value = hex("DE AD BE EF");
  const ReadVarResult result{return_code::kSuccess, data_transport::kByte, value};
  const auto pdu = encode_read_var_response(1, std::span(&result, 1));
  ASSERT_TRUE(pdu.ok());
  EXPECT_EQ(encode_tpkt_data(pdu.value).value, kNodes7Answer);
  const auto back = response_of(pdu.value);
  ASSERT_TRUE(back.ok());
  ASSERT_EQ(back.value.size(), 1u);
  EXPECT_EQ(back.value[0].length, 0x20);  // 32 bits
  EXPECT_EQ(bytes(back.value[0].data), value);
}

// DB1.DBW0 worked out by hand: transport size WORD (04), count 1, DB 1, area 84, bit address 0;
// the answer: FF, data transport size 04 (length in bits), 0x0010 = 16 bits, the word 12 34.
TEST(S7ReadVar, Db1Dbw0RequestAndAnswer) {
  const VarItem dbw0{transport::kWord, 1, 1, area::kDataBlock, 0};
  const auto job = encode_read_var_request(2, std::span(&dbw0, 1));
  ASSERT_TRUE(job.ok());
  EXPECT_EQ(job.value,
            hex("32 01 00 00 00 02 00 0E 00 00 | 04 01 | 12 0A 10 04 00 01 00 01 84 00 00 00"));
  EXPECT_EQ(element_size(dbw0.transport_size) * dbw0.count, 2u);
  EXPECT_EQ(data_transport_for(dbw0.transport_size), data_transport::kByte);

  const Bytes word = hex("12 34");
  const ReadVarResult ok{return_code::kSuccess, data_transport_for(dbw0.transport_size), word};
  const auto ack = encode_read_var_response(2, std::span(&ok, 1));
  ASSERT_TRUE(ack.ok());
  EXPECT_EQ(ack.value, hex("32 03 00 00 00 02 00 02 00 06 00 00 | 04 01 | FF 04 00 10 12 34"));
  EXPECT_EQ(
      encode_tpkt_data(ack.value).value,
      hex("03 00 00 1B 02 F0 80 32 03 00 00 00 02 00 02 00 06 00 00 04 01 FF 04 00 10 12 34"));
}

// protocol-facts.md §H.4 "Example read, DB1.DBB0, 10 bytes".
TEST(S7ReadVar, ProtocolFactsTenByteExample) {
  const auto job = hex("32 01 00 00 00 01 00 0E 00 00 | 04 01 12 0A 10 02 00 0A 00 01 84 00 00 00");
  const auto r = request_of(job);
  ASSERT_TRUE(r.ok());
  EXPECT_EQ(r.value[0].count, 10);
  const Bytes ten = hex("00 01 02 03 04 05 06 07 08 09");
  const ReadVarResult res{return_code::kSuccess, data_transport::kByte, ten};
  const auto ack = encode_read_var_response(1, std::span(&res, 1));
  EXPECT_EQ(ack.value, hex("32 03 00 00 00 01 00 02 00 0E 00 00 | 04 01 | FF 04 00 50 00 01 02 03 "
                           "04 05 06 07 08 09"));
}

// Several items: a bit (M10.3), a byte (MB5), a missing DB, an address out of range and a bad
// transport size. Odd data lengths get a fill octet when another item follows; failed items are
// `RC 00 00 00`.
TEST(S7ReadVar, MixedItemsWithFillOctetsAndReturnCodes) {
  const VarItem items[] = {{transport::kBit, 1, 0, area::kFlags, 10 * 8 + 3},
                           {transport::kByte, 1, 0, area::kFlags, 5 * 8},
                           {transport::kWord, 1, 9, area::kDataBlock, 0},
                           {transport::kWord, 1, 1, area::kDataBlock, 60000 * 8},
                           {0x0E, 1, 1, area::kDataBlock, 0}};
  const auto job = encode_read_var_request(9, items);
  ASSERT_TRUE(job.ok());
  const auto back = request_of(job.value);
  ASSERT_TRUE(back.ok());
  ASSERT_EQ(back.value.size(), 5u);
  EXPECT_EQ(back.value[0].byte_offset(), 10u);
  EXPECT_EQ(back.value[0].bit(), 3);
  EXPECT_EQ(back.value[3].address, 480000u);
  EXPECT_EQ(element_size(back.value[4].transport_size), 0u);  // unknown: the server answers 06

  const Bytes bit = hex("01"), byte = hex("5A");
  const ReadVarResult results[] = {{return_code::kSuccess, data_transport::kBit, bit},
                                   {return_code::kSuccess, data_transport::kByte, byte},
                                   {return_code::kObjectDoesNotExist, data_transport::kByte, {}},
                                   {return_code::kAddressOutOfRange, data_transport::kByte, byte},
                                   {return_code::kDataTypeNotSupported, data_transport::kNull, {}}};
  const auto ack = encode_read_var_response(9, results);
  ASSERT_TRUE(ack.ok());
  EXPECT_EQ(ack.value, hex("32 03 00 00 00 09 00 02 00 18 00 00 | 04 05 |"
                           "FF 03 00 01 01 00 | FF 04 00 08 5A 00 | 0A 00 00 00 | 05 00 00 00 |"
                           "06 00 00 00"));
  const auto d = response_of(ack.value);
  ASSERT_TRUE(d.ok()) << to_string(d.error);
  ASSERT_EQ(d.value.size(), 5u);
  EXPECT_EQ(bytes(d.value[0].data), bit);
  EXPECT_EQ(d.value[0].length, 1);
  EXPECT_EQ(bytes(d.value[1].data), byte);
  EXPECT_EQ(d.value[2].return_code, return_code::kObjectDoesNotExist);
  EXPECT_TRUE(d.value[2].data.empty());
  EXPECT_EQ(d.value[3].return_code, return_code::kAddressOutOfRange);
  EXPECT_EQ(d.value[4].return_code, return_code::kDataTypeNotSupported);
}

TEST(S7ReadVar, LastOddItemHasNoFillOctet) {
  const Bytes a = hex("11 22"), b = hex("33");
  const ReadVarResult results[] = {{return_code::kSuccess, data_transport::kByte, a},
                                   {return_code::kSuccess, data_transport::kByte, b}};
  const auto ack = encode_read_var_response(3, results);
  EXPECT_EQ(
      ack.value,
      hex("32 03 00 00 00 03 00 02 00 0B 00 00 | 04 02 | FF 04 00 10 11 22 | FF 04 00 08 33"));
}

TEST(S7ReadVar, LengthUnitsFollowTheDataTransportSize) {
  // REAL and OCTET STRING count octets, INTEGER counts bits; a snap7-style failed item with a
  // length of 4 and no data decodes too.
  const auto pdu =
      hex("32 03 00 00 00 04 00 02 00 18 00 00 | 04 04 |"
          "FF 07 00 04 41 20 00 00 | FF 05 00 10 00 2A | FF 09 00 02 00 05 |"
          "0A 00 00 04");
  const auto d = response_of(pdu);
  ASSERT_TRUE(d.ok()) << to_string(d.error) << " at " << d.at;
  EXPECT_EQ(bytes(d.value[0].data), hex("41 20 00 00"));
  EXPECT_EQ(bytes(d.value[1].data), hex("00 2A"));
  EXPECT_EQ(bytes(d.value[2].data), hex("00 05"));
  EXPECT_TRUE(d.value[3].data.empty());
  EXPECT_EQ(data_octets(data_transport::kBit, 1).value, 1u);
  EXPECT_EQ(data_octets(data_transport::kByte, 12).value, 2u);  // 12 bits round up
  EXPECT_EQ(data_octets(data_transport::kDInteger, 4).value, 4u);
  EXPECT_EQ(data_octets(0x08, 4).error, Error::S7BadDataTransportSize);
  EXPECT_EQ(length_field(data_transport::kReal, 4).value, 4);
  EXPECT_EQ(length_field(data_transport::kInteger, 2).value, 16);
  EXPECT_EQ(length_field(data_transport::kNull, 0).error, Error::S7BadDataTransportSize);
}

TEST(S7ReadVar, TransportSizeTables) {
  EXPECT_EQ(element_size(transport::kBit), 1u);
  EXPECT_EQ(element_size(transport::kChar), 1u);
  EXPECT_EQ(element_size(transport::kInt), 2u);
  EXPECT_EQ(element_size(transport::kCounter), 2u);
  EXPECT_EQ(element_size(transport::kTimer), 2u);
  EXPECT_EQ(element_size(transport::kDWord), 4u);
  EXPECT_EQ(element_size(transport::kDInt), 4u);
  EXPECT_EQ(element_size(transport::kReal), 4u);
  EXPECT_EQ(data_transport_for(transport::kBit), data_transport::kBit);
  EXPECT_EQ(data_transport_for(transport::kInt), data_transport::kInteger);
  EXPECT_EQ(data_transport_for(transport::kDInt), data_transport::kInteger);
  EXPECT_EQ(data_transport_for(transport::kReal), data_transport::kReal);
  EXPECT_EQ(data_transport_for(transport::kChar), data_transport::kOctetString);
  EXPECT_EQ(data_transport_for(transport::kTimer), data_transport::kOctetString);
  EXPECT_EQ(data_transport_for(transport::kDWord), data_transport::kByte);
}

struct Bad {
  const char* octets;
  Error error;
  std::size_t at;
};

TEST(S7ReadVar, EveryRequestDecodeError) {
  const Bad cases[] = {
      {"32 03 00 00 00 01 00 02 00 00 00 00 | 04 01", Error::S7WrongPduType, 1},
      {"32 01 00 00 00 01 00 01 00 00 | 04", Error::S7BadParameterLength, 6},
      {"32 01 00 00 00 01 00 0E 00 00 | 05 01 12 0A 10 02 00 04 00 01 84 00 00 00",
       Error::S7UnexpectedFunction, 10},
      {"32 01 00 00 00 01 00 02 00 00 | 04 00", Error::S7NoItems, 11},
      {"32 01 00 00 00 01 00 0E 00 00 | 04 02 12 0A 10 02 00 04 00 01 84 00 00 00",
       Error::S7BadParameterLength, 6},
      {"32 01 00 00 00 01 00 0E 00 00 | 04 01 11 0A 10 02 00 04 00 01 84 00 00 00",
       Error::S7BadItemHeader, 12},
      {"32 01 00 00 00 01 00 0E 00 00 | 04 01 12 0A B2 02 00 04 00 01 84 00 00 00",
       Error::S7UnsupportedSyntaxId, 14},
      {"32 01 00 00 00 01 00 0E 00 00 | 04 01 12 0B 10 02 00 04 00 01 84 00 00 00",
       Error::S7BadItemLength, 13},
      {"32 01 00 00 00 01 00 0E 00 01 | 04 01 12 0A 10 02 00 04 00 01 84 00 00 00 | 00",
       Error::S7UnexpectedData, 24},
  };
  for (const auto& c : cases) {
    const auto r = request_of(hex(c.octets));
    EXPECT_EQ(r.error, c.error) << c.octets << ": " << to_string(r.error);
    EXPECT_EQ(r.at, c.at) << c.octets;
  }
}

TEST(S7ReadVar, EveryResponseDecodeError) {
  const Bad cases[] = {
      {"32 01 00 00 00 01 00 02 00 00 | 04 01", Error::S7WrongPduType, 1},
      {"32 03 00 00 00 01 00 03 00 00 00 00 | 04 01 00", Error::S7BadParameterLength, 6},
      {"32 03 00 00 00 01 00 02 00 00 00 00 | 05 01", Error::S7UnexpectedFunction, 12},
      {"32 03 00 00 00 01 00 02 00 00 00 00 | 04 00", Error::S7NoItems, 13},
      {"32 03 00 00 00 01 00 02 00 03 00 00 | 04 01 | FF 04 00", Error::S7DataTruncated, 14},
      {"32 03 00 00 00 01 00 02 00 05 00 00 | 04 01 | FF 04 00 10 12", Error::S7DataTruncated, 16},
      {"32 03 00 00 00 01 00 02 00 05 00 00 | 04 02 | FF 04 00 08 12", Error::S7DataTruncated, 19},
      {"32 03 00 00 00 01 00 02 00 06 00 00 | 04 01 | FF 04 00 08 12 00", Error::S7TrailingData,
       19},
      {"32 03 00 00 00 01 00 02 00 05 00 00 | 04 01 | FF 08 00 04 12",
       Error::S7BadDataTransportSize, 15},
  };
  for (const auto& c : cases) {
    const auto r = response_of(hex(c.octets));
    EXPECT_EQ(r.error, c.error) << c.octets << ": " << to_string(r.error);
    EXPECT_EQ(r.at, c.at) << c.octets;
  }
}

TEST(S7ReadVar, EncoderErrors) {
  EXPECT_EQ(encode_read_var_request(1, {}).error, Error::S7NoItems);
  const std::vector<VarItem> many(256);
  EXPECT_EQ(encode_read_var_request(1, many).error, Error::S7TooManyItems);
  EXPECT_TRUE(encode_read_var_request(1, std::span(many).first(255)).ok());
  const VarItem far{transport::kByte, 1, 1, area::kDataBlock, 0x1000000};
  const auto e = encode_read_var_request(1, std::span(&far, 1));
  EXPECT_EQ(e.error, Error::S7AddressTooLarge);
  EXPECT_TRUE(e.value.empty());

  EXPECT_EQ(encode_read_var_response(1, {}).error, Error::S7NoItems);
  const Bytes two = hex("01 01"), big(8192, 0);
  const ReadVarResult twobits{return_code::kSuccess, data_transport::kBit, two};
  EXPECT_EQ(encode_read_var_response(1, std::span(&twobits, 1)).error, Error::S7ItemLengthMismatch);
  const ReadVarResult toolong{return_code::kSuccess, data_transport::kByte, big};
  EXPECT_EQ(encode_read_var_response(1, std::span(&toolong, 1)).error, Error::S7ItemTooLong);
  const ReadVarResult octets{return_code::kSuccess, data_transport::kOctetString, big};
  EXPECT_TRUE(encode_read_var_response(1, std::span(&octets, 1)).ok());
  const ReadVarResult unknown{return_code::kSuccess, 0x08, two};
  const auto u = encode_read_var_response(7, std::span(&unknown, 1));
  EXPECT_EQ(u.error, Error::S7BadDataTransportSize);
  EXPECT_EQ(u.at, 0u);  // the index of the item
}

}  // namespace
}  // namespace pbvbus::s7
