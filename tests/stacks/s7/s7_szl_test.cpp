// Read SZL in Userdata PDUs (layouts from snap7 and Wireshark's s7comm; stacks/s7 s7_szl.hpp).
#include "pbvbus/s7/s7_szl.hpp"

#include <gtest/gtest.h>

#include "hex.hpp"

namespace pbvbus::s7 {
namespace {

using test::hex;
using Bytes = std::vector<std::uint8_t>;

Decoded<SzlRequest> request_of(const Bytes& pdu) {
  const auto d = decode_s7_pdu(pdu);
  if (!d.ok()) return {{}, d.error, d.at};
  return decode_szl_request(d.value);
}

Decoded<SzlResponse> response_of(const Bytes& pdu) {
  const auto d = decode_s7_pdu(pdu);
  if (!d.ok()) return {{}, d.error, d.at};
  return decode_szl_response(d.value);
}

// Read SZL-ID W#16#0011 index 0: params 00 01 12 04 | 11 (request) | 44 (type request, group
// CPU functions) | 01 (read SZL) | 00 (sequence); data FF 09 0004 0011 0000.
TEST(S7Szl, RequestLayout) {
  const auto pdu = encode_szl_request(5, SzlRequest{0, 0x0011, 0x0000});
  ASSERT_TRUE(pdu.ok());
  EXPECT_EQ(
      pdu.value,
      hex("32 07 00 00 00 05 00 08 00 08 | 00 01 12 04 11 44 01 00 | FF 09 00 04 00 11 00 00"));
  const auto r = request_of(pdu.value);
  ASSERT_TRUE(r.ok()) << to_string(r.error);
  EXPECT_EQ(r.value, (SzlRequest{0, 0x0011, 0x0000}));
}

// The answer: params 00 01 12 08 | 12 (response) | 84 | 01 | seq | 00 (data unit 0) | 00 (last)
// | 0000 (no error); data FF 09 <len> ID INDEX LENTHDR N_DR records (len = 8 + records).
// The list is W#16#0000 (the SZL-IDs a module has, one word per record); tshark 4.0.17's s7comm
// dissector shows these octets as four records 0000, 0011, 001C, 0091 (docs/s7.md).
TEST(S7Szl, ResponseLayoutAndRoundTrip) {
  const Bytes records = hex("00 00 00 11 00 1C 00 91");
  SzlResponse r;
  r.sequence = 3;
  r.id = 0x0000;
  r.index = 0x0000;
  r.record_length = 2;
  r.record_count = 4;
  r.records = records;
  const auto pdu = encode_szl_response(5, r);
  ASSERT_TRUE(pdu.ok());
  EXPECT_EQ(pdu.value, hex("32 07 00 00 00 05 00 0C 00 14 | 00 01 12 08 12 84 01 03 00 00 00 00 |"
                           "FF 09 00 10 00 00 00 00 00 02 00 04 00 00 00 11 00 1C 00 91"));
  const auto back = response_of(pdu.value);
  ASSERT_TRUE(back.ok()) << to_string(back.error);
  EXPECT_EQ(back.value.sequence, 3);
  EXPECT_EQ(back.value.error_code, 0);
  EXPECT_EQ(back.value.id, 0x0000);
  EXPECT_EQ(back.value.record_length, 2);
  EXPECT_EQ(back.value.record_count, 4);
  EXPECT_EQ(Bytes(back.value.records.begin(), back.value.records.end()), records);
}

// snap7's SZLNotAvailable: error code D4 02 in the parameters, data 0A 00 00 00.
TEST(S7Szl, NotAvailableAnswer) {
  SzlResponse r;
  r.error_code = kSzlNotAvailable;
  const auto pdu = encode_szl_response(6, r);
  ASSERT_TRUE(pdu.ok());
  EXPECT_EQ(
      pdu.value,
      hex("32 07 00 00 00 06 00 0C 00 04 | 00 01 12 08 12 84 01 00 00 00 D4 02 | 0A 00 00 00"));
  const auto back = response_of(pdu.value);
  ASSERT_TRUE(back.ok());
  EXPECT_EQ(back.value.error_code, kSzlNotAvailable);
  EXPECT_TRUE(back.value.records.empty());
}

TEST(S7Szl, UserdataParamsRoundTrip) {
  const UserdataParams u{kUserdataMethodResponse,
                         kUserdataTypeResponse,
                         kUserdataGroupCpu,
                         kSubfunctionReadSzl,
                         9,
                         true,
                         1,
                         kLastDataUnitNo,
                         0x1234};
  Bytes params;
  append_userdata_params(params, u);
  EXPECT_EQ(params, hex("00 01 12 08 12 84 01 09 01 01 12 34"));
  const auto pdu = encode_s7_pdu(S7Header{kS7Userdata, 1, 0, 0}, params, {});
  const auto d = decode_s7_pdu(pdu.value);
  ASSERT_TRUE(d.ok());
  const auto back = decode_userdata_params(d.value);
  ASSERT_TRUE(back.ok());
  EXPECT_EQ(back.value, u);
}

// A list split into data units: a middle unit carries part of the records.
TEST(S7Szl, PartOfAListInOneDataUnitDecodes) {
  const auto pdu =
      hex("32 07 00 00 00 05 00 0C 00 10 | 00 01 12 08 12 84 01 03 00 01 00 00 |"
          "FF 09 00 0C 00 11 00 00 00 04 00 03 AA BB CC DD");
  const auto r = response_of(pdu);
  ASSERT_TRUE(r.ok()) << to_string(r.error);
  EXPECT_EQ(r.value.records.size(), 4u);
  EXPECT_EQ(r.value.record_count, 3);
}

struct Bad {
  const char* octets;
  Error error;
  std::size_t at;
};

TEST(S7Szl, EveryRequestDecodeError) {
  const Bad cases[] = {
      {"32 01 00 00 00 05 00 08 00 08 | 00 01 12 04 11 44 01 00 | FF 09 00 04 00 11 00 00",
       Error::S7WrongPduType, 1},
      {"32 07 00 00 00 05 00 03 00 00 | 00 01 12", Error::S7BadUserdataLength, 6},
      {"32 07 00 00 00 05 00 08 00 00 | 00 01 13 04 11 44 01 00", Error::S7BadUserdataHead, 10},
      {"32 07 00 00 00 05 00 08 00 00 | 00 01 12 05 11 44 01 00", Error::S7BadUserdataLength, 13},
      {"32 07 00 00 00 05 00 0C 00 00 | 00 01 12 04 11 44 01 00 00 00 00 00",
       Error::S7BadUserdataLength, 13},
      {"32 07 00 00 00 05 00 08 00 08 | 00 01 12 04 12 44 01 00 | FF 09 00 04 00 11 00 00",
       Error::S7UnexpectedUserdata, 14},
      {"32 07 00 00 00 05 00 08 00 08 | 00 01 12 04 11 43 01 00 | FF 09 00 04 00 11 00 00",
       Error::S7UnexpectedUserdata, 15},
      {"32 07 00 00 00 05 00 08 00 08 | 00 01 12 04 11 44 02 00 | FF 09 00 04 00 11 00 00",
       Error::S7UnexpectedUserdata, 16},
      {"32 07 00 00 00 05 00 08 00 06 | 00 01 12 04 11 44 01 00 | FF 09 00 04 00 11",
       Error::S7BadSzlRequest, 8},
      {"32 07 00 00 00 05 00 08 00 08 | 00 01 12 04 11 44 01 00 | 0A 09 00 04 00 11 00 00",
       Error::S7BadSzlRequest, 18},
      {"32 07 00 00 00 05 00 08 00 08 | 00 01 12 04 11 44 01 00 | FF 04 00 04 00 11 00 00",
       Error::S7BadSzlRequest, 19},
      {"32 07 00 00 00 05 00 08 00 08 | 00 01 12 04 11 44 01 00 | FF 09 00 05 00 11 00 00",
       Error::S7BadSzlRequest, 20},
  };
  for (const auto& c : cases) {
    const auto r = request_of(hex(c.octets));
    EXPECT_EQ(r.error, c.error) << c.octets << ": " << to_string(r.error);
    EXPECT_EQ(r.at, c.at) << c.octets;
  }
}

TEST(S7Szl, EveryResponseDecodeError) {
  const Bad cases[] = {
      {"32 07 00 00 00 05 00 0C 00 03 | 00 01 12 08 12 84 01 00 00 00 00 00 | FF 09 00",
       Error::S7BadSzlResponse, 8},
      {"32 07 00 00 00 05 00 0C 00 04 | 00 01 12 08 12 84 01 00 00 00 00 00 | FF 09 00 01",
       Error::S7BadSzlResponse, 24},
      {"32 07 00 00 00 05 00 0C 00 05 | 00 01 12 08 12 84 01 00 00 00 D4 02 | 0A 00 00 01 00",
       Error::S7BadSzlResponse, 26},
      {"32 07 00 00 00 05 00 0C 00 0C | 00 01 12 08 12 84 01 00 00 00 00 00 | FF 04 00 08 00 11 00 "
       "00 00 04 00 00",
       Error::S7BadSzlResponse, 23},
      {"32 07 00 00 00 05 00 0C 00 08 | 00 01 12 08 12 84 01 00 00 00 00 00 | FF 09 00 04 00 11 00 "
       "00",
       Error::S7BadSzlResponse, 8},
      {"32 07 00 00 00 05 00 0C 00 0E | 00 01 12 08 12 84 01 00 00 00 00 00 | FF 09 00 0A 00 11 00 "
       "00 00 04 00 02 AA BB",
       Error::S7BadSzlResponse, 30},
      {"32 07 00 00 00 05 00 0C 00 14 | 00 01 12 08 12 84 01 00 01 01 00 00 | FF 09 00 10 00 11 00 "
       "00 00 02 00 02 AA BB CC DD EE FF 00 11",
       Error::S7BadSzlResponse, 30},
      {"32 07 00 00 00 05 00 08 00 08 | 00 01 12 04 11 44 01 00 | FF 09 00 04 00 11 00 00",
       Error::S7UnexpectedUserdata, 14},
  };
  for (const auto& c : cases) {
    const auto r = response_of(hex(c.octets));
    EXPECT_EQ(r.error, c.error) << c.octets << ": " << to_string(r.error);
    EXPECT_EQ(r.at, c.at) << c.octets;
  }
}

TEST(S7Szl, EncoderErrors) {
  const Bytes three = hex("01 02 03");
  SzlResponse r;
  r.record_length = 2;
  r.record_count = 2;
  r.records = three;
  EXPECT_EQ(encode_szl_response(1, r).error, Error::S7BadSzlResponse);
  const Bytes huge(65530, 0);
  r.record_length = 1;
  r.record_count = 65530;
  r.records = huge;
  EXPECT_EQ(encode_szl_response(1, r).error, Error::S7PduTooLarge);
}

}  // namespace
}  // namespace pbvbus::s7
