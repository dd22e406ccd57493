// S7Server against hand-worked octets (protocol-facts.md §H.4; tools-and-formats.md §3.4;
// docs/s7.md "Byte layouts"; choices in docs/s7cpu.md).
#include "pbvbus/s7cpu/s7_server.hpp"

#include <gtest/gtest.h>

#include "hex.hpp"
#include "pbvbus/s7/s7_read_var.hpp"
#include "pbvbus/s7/s7_szl.hpp"
#include "pbvbus/s7/s7_write_var.hpp"

namespace pbvbus::s7cpu {
namespace {

using Bytes = std::vector<std::uint8_t>;
using s7::VarItem;
namespace ts = s7::transport;
namespace ar = s7::area;

Bytes hex(std::string_view s) {
  std::string clean;
  for (const char c : s) {
    if (c != '|') clean.push_back(c);
  }
  return test::bytes_from_hex(clean);
}

// §3.4: the client asks AmQ 1/1 and PDU 480; the CPU answers 1/1 and 240.
const Bytes kSetupRequest = hex("32 01 00 00 00 00 00 08 00 00 | F0 00 00 01 00 01 01 E0");
const Bytes kSetupResponse =
    hex("32 03 00 00 00 00 00 08 00 00 00 00 | F0 00 00 01 00 01 00 F0");

struct S7ServerTest : ::testing::Test {
  CpuMemory memory{CpuMemorySizes{16, 16, 16, 8, 8}};
  CpuInfo info;
  S7Server server{memory, info};

  Bytes answer(const Bytes& request) {
    const auto r = server.handle(request);
    EXPECT_TRUE(r.ok()) << s7::to_string(r.error) << " at " << r.at;
    return r.value;
  }
  void setup() { ASSERT_EQ(answer(kSetupRequest), kSetupResponse); }
  Bytes read(std::uint16_t ref, std::vector<VarItem> items) {
    const auto req = s7::encode_read_var_request(ref, items);
    EXPECT_TRUE(req.ok());
    return answer(req.value);
  }
};

TEST_F(S7ServerTest, SetupCommunicationIsTheReferenceExchange) {
  EXPECT_FALSE(server.setup_done());
  EXPECT_EQ(answer(kSetupRequest), kSetupResponse);
  EXPECT_TRUE(server.setup_done());
  EXPECT_EQ(server.negotiated(), (s7::SetupCommunication{1, 1, 240}));
}

TEST_F(S7ServerTest, SetupAnswersTheLowerOfEachValue) {
  S7Server big(memory, info, {4, 4, 960});
  // libnodave's request: AmQ 1/1, PDU 960 (protocol-facts.md §H.4); pdu-ref 0x0102.
  const auto r = big.handle(hex("32 01 00 00 01 02 00 08 00 00 | F0 00 00 01 00 01 03 C0"));
  ASSERT_TRUE(r.ok());
  EXPECT_EQ(r.value, hex("32 03 00 00 01 02 00 08 00 00 00 00 | F0 00 00 01 00 01 03 C0"));
  const auto r2 = big.handle(hex("32 01 00 00 01 03 00 08 00 00 | F0 00 00 08 00 02 00 F0"));
  EXPECT_EQ(r2.value, hex("32 03 00 00 01 03 00 08 00 00 00 00 | F0 00 00 04 00 02 00 F0"));
  EXPECT_EQ(big.negotiated().pdu_length, 240);
}

// §3.4: Read Var of DB1, 4 bytes from 0, answered DE AD BE EF (what the owner put there).
TEST_F(S7ServerTest, ReadVarIsTheReferenceExchange) {
  memory.create_db(1, 16);
  ASSERT_TRUE(set_dword(*memory.db(1), 0, 0xDEADBEEF));
  setup();
  EXPECT_EQ(answer(hex("32 01 00 00 00 01 00 0E 00 00 | 04 01 12 0A 10 02 00 04 00 01 84 00 00 00")),
            hex("32 03 00 00 00 01 00 02 00 08 00 00 | 04 01 | FF 04 00 20 DE AD BE EF"));
}

// DB1.DBW0 by hand: item 12 0A 10 | 04 WORD | 0001 count | 0001 DB | 84 | 000000; the answer
// FF | 04 | 0010 (16 bits) | the word the owner wrote.
TEST_F(S7ServerTest, ReadVarDb1Dbw0ShowsWhatTheOwnerWrote) {
  memory.create_db(1, 16);
  setup();
  ASSERT_TRUE(set_word(*memory.db(1), 0, 0x1234));
  const Bytes req = hex("32 01 00 00 00 02 00 0E 00 00 | 04 01 12 0A 10 04 00 01 00 01 84 00 00 00");
  EXPECT_EQ(answer(req), hex("32 03 00 00 00 02 00 02 00 06 00 00 | 04 01 | FF 04 00 10 12 34"));
  // The owner's next cycle changes it; the next Read Var shows the new value.
  ASSERT_TRUE(set_word(*memory.db(1), 0, 0xABCD));
  EXPECT_EQ(answer(req), hex("32 03 00 00 00 02 00 02 00 06 00 00 | 04 01 | FF 04 00 10 AB CD"));
}

// Ten items, every variable transport size and the return codes 0A and 05, worked by hand:
// data transport per s7_item.hpp data_transport_for, fill octets after odd data when another
// item follows, failed items as RC 00 00 00.
TEST_F(S7ServerTest, ReadVarMultiItemEveryTransportSize) {
  memory.create_db(1, 16);
  auto db1 = *memory.db(1);
  auto mb = memory.area(Area::Flags);
  ASSERT_TRUE(set_bit(mb, 5, 3, true));
  ASSERT_TRUE(set_byte(mb, 0, 0xA5));
  memory.counters()[3] = 0x0042;
  memory.timers()[2] = 0x1234;
  memory.timers()[3] = 0x5678;
  ASSERT_TRUE(set_dword(db1, 4, 0x3F800000));  // REAL 1.0
  ASSERT_TRUE(set_word(db1, 8, 0xFFFE));       // INT -2
  ASSERT_TRUE(set_dword(db1, 10, 100000));     // DINT 100000 = 0x000186A0
  db1[14] = 'O';
  db1[15] = 'K';
  setup();
  const Bytes got = read(7, {
                                VarItem{ts::kBit, 1, 0, ar::kFlags, 5 * 8 + 3},   // M5.3
                                VarItem{ts::kByte, 1, 0, ar::kFlags, 0},          // MB0
                                VarItem{ts::kByte, 1, 9, ar::kDataBlock, 0},      // DB9 missing
                                VarItem{ts::kWord, 1, 1, ar::kDataBlock, 100 * 8},  // past DB1
                                VarItem{ts::kCounter, 1, 0, ar::kCounter, 3},     // C3
                                VarItem{ts::kTimer, 2, 0, ar::kTimer, 2},         // T2, T3
                                VarItem{ts::kReal, 1, 1, ar::kDataBlock, 4 * 8},  // DB1.DBD4
                                VarItem{ts::kInt, 1, 1, ar::kDataBlock, 8 * 8},   // DB1.DBW8
                                VarItem{ts::kDInt, 1, 1, ar::kDataBlock, 10 * 8},  // DB1.DBD10
                                VarItem{ts::kChar, 2, 1, ar::kDataBlock, 14 * 8},  // DB1.DBB14
                            });
  EXPECT_EQ(got, hex("32 03 00 00 00 07 00 02 00 3E 00 00 | 04 0A"
                     "| FF 03 00 01 01 00"
                     "| FF 04 00 08 A5 00"
                     "| 0A 00 00 00"
                     "| 05 00 00 00"
                     "| FF 09 00 02 00 42"
                     "| FF 09 00 04 12 34 56 78"
                     "| FF 07 00 04 3F 80 00 00"
                     "| FF 05 00 10 FF FE"
                     "| FF 05 00 20 00 01 86 A0"
                     "| FF 09 00 02 4F 4B"));
}

TEST_F(S7ServerTest, ReadVarWordAndDwordCounts) {
  memory.create_db(1, 16);
  ASSERT_TRUE(set_dword(*memory.db(1), 0, 0x01020304));
  ASSERT_TRUE(set_dword(*memory.db(1), 4, 0x05060708));
  ASSERT_TRUE(set_word(memory.area(Area::Inputs), 2, 0xCAFE));
  ASSERT_TRUE(set_byte(memory.area(Area::Outputs), 15, 0x7E));
  setup();
  EXPECT_EQ(read(1, {VarItem{ts::kDWord, 2, 1, ar::kDataBlock, 0},
                     VarItem{ts::kWord, 1, 0, ar::kInputs, 2 * 8},
                     VarItem{ts::kByte, 1, 0, ar::kOutputs, 15 * 8}}),
            hex("32 03 00 00 00 01 00 02 00 17 00 00 | 04 03"
                "| FF 04 00 40 01 02 03 04 05 06 07 08"
                "| FF 04 00 10 CA FE"
                "| FF 04 00 08 7E"));
}

// 06: transport sizes this server cannot serve for the address given.
TEST_F(S7ServerTest, ReadVarDataTypeNotSupported) {
  memory.create_db(1, 16);
  setup();
  EXPECT_EQ(read(2, {VarItem{ts::kWord, 1, 0, ar::kCounter, 0},       // WORD on counters
                     VarItem{ts::kCounter, 1, 1, ar::kDataBlock, 0},  // COUNTER on a DB
                     VarItem{ts::kTimer, 1, 0, ar::kCounter, 0},      // TIMER on counters
                     VarItem{0x0B, 1, 1, ar::kDataBlock, 0},          // unknown size
                     VarItem{ts::kBit, 2, 1, ar::kDataBlock, 0}}),    // two bits
            hex("32 03 00 00 00 02 00 02 00 14 00 00 | 04 05"
                "| 06 00 00 00 | 06 00 00 00 | 06 00 00 00 | 06 00 00 00 | 06 00 00 00"));
}

// 05 and 0A for the edges of every area.
TEST_F(S7ServerTest, ReadVarAddressOutOfRangeAndObjectDoesNotExist) {
  memory.create_db(1, 16);
  setup();
  EXPECT_EQ(read(3, {VarItem{ts::kByte, 16, 1, ar::kDataBlock, 0},       // whole DB1: fine
                     VarItem{ts::kByte, 17, 1, ar::kDataBlock, 0},       // one past
                     VarItem{ts::kBit, 1, 0, ar::kInputs, 16 * 8},       // I16.0
                     VarItem{ts::kByte, 1, 1, ar::kDataBlock, 1},        // DB1.DBB0 bit .1
                     VarItem{ts::kByte, 0, 1, ar::kDataBlock, 0},        // count 0
                     VarItem{ts::kCounter, 2, 0, ar::kCounter, 7},       // C7, C8
                     VarItem{ts::kTimer, 1, 0, ar::kTimer, 8},           // T8
                     VarItem{ts::kByte, 1, 0, ar::kPeripheral, 0},       // P: no such area
                     VarItem{ts::kByte, 1, 1, ar::kInstanceDataBlock, 0}}),  // DI
            hex("32 03 00 00 00 03 00 02 00 34 00 00 | 04 09"
                "| FF 04 00 80 00 00 00 00 00 00 00 00 00 00 00 00 00 00 00 00"
                "| 05 00 00 00 | 05 00 00 00 | 05 00 00 00 | 05 00 00 00 | 05 00 00 00"
                "| 05 00 00 00 | 0A 00 00 00 | 0A 00 00 00"));
}

// Write Var of DB1.DBW2 by hand: params 05 01 + item (04 WORD, count 1, DB 1, 84, bit address
// 2*8 = 0x10), data 00 | 04 | 0010 | BE EF; the answer's data is the one return code FF.
TEST_F(S7ServerTest, WriteVarDb1Dbw2ByHandAndTheOwnerSeesIt) {
  memory.create_db(1, 16);
  setup();
  EXPECT_EQ(answer(hex("32 01 00 00 00 03 00 0E 00 06 | 05 01 12 0A 10 04 00 01 00 01 84 00 00 10"
                       "| 00 04 00 10 BE EF")),
            hex("32 03 00 00 00 03 00 02 00 01 00 00 | 05 01 | FF"));
  EXPECT_EQ(get_word(*memory.db(1), 2), 0xBEEF);
  EXPECT_EQ(read(4, {VarItem{ts::kWord, 1, 1, ar::kDataBlock, 2 * 8}}),
            hex("32 03 00 00 00 04 00 02 00 06 00 00 | 04 01 | FF 04 00 10 BE EF"));
}

TEST_F(S7ServerTest, WriteVarMultiItemWithEveryReturnCode) {
  memory.create_db(1, 16);
  ASSERT_TRUE(set_word(*memory.db(1), 0, 0x5555));
  setup();
  const Bytes one{0x01}, beef{0xBE, 0xEF}, b11{0x11}, three{1, 2, 3}, seven{0x00, 0x07},
      pi{0x40, 0x49, 0x0F, 0xDB};
  const std::vector<s7::WriteVarItem> items{
      {VarItem{ts::kBit, 1, 0, ar::kFlags, 5 * 8 + 3}, s7::data_transport::kBit, one},
      {VarItem{ts::kWord, 1, 1, ar::kDataBlock, 2 * 8}, s7::data_transport::kByte, beef},
      {VarItem{ts::kByte, 1, 9, ar::kDataBlock, 0}, s7::data_transport::kByte, b11},
      {VarItem{ts::kByte, 2, 1, ar::kDataBlock, 0}, s7::data_transport::kByte, three},
      {VarItem{ts::kCounter, 1, 0, ar::kCounter, 1}, s7::data_transport::kOctetString, seven},
      {VarItem{ts::kByte, 1, 0, ar::kFlags, 0}, s7::data_transport::kBit, one},
      {VarItem{ts::kReal, 1, 1, ar::kDataBlock, 4 * 8}, s7::data_transport::kReal, pi},
      {VarItem{ts::kByte, 1, 0, ar::kOutputs, 16 * 8}, s7::data_transport::kByte, b11},
  };
  const auto req = s7::encode_write_var_request(8, items);
  ASSERT_TRUE(req.ok());
  EXPECT_EQ(answer(req.value),
            hex("32 03 00 00 00 08 00 02 00 08 00 00 | 05 08 | FF FF 0A 07 FF 06 FF 05"));
  EXPECT_EQ(get_bit(memory.area(Area::Flags), 5, 3), true);
  EXPECT_EQ(get_byte(memory.area(Area::Flags), 0), 0);  // the refused BIT-as-byte write
  EXPECT_EQ(get_word(*memory.db(1), 0), 0x5555);        // the refused 3-octet write
  EXPECT_EQ(get_word(*memory.db(1), 2), 0xBEEF);
  EXPECT_EQ(memory.counters()[1], 7);
  EXPECT_EQ(get_dword(*memory.db(1), 4), 0x40490FDBU);
}

TEST_F(S7ServerTest, WriteVarBitClearsOnlyItsBitAndTimersAreWords) {
  memory.create_db(1, 4);
  (*memory.db(1))[1] = 0xFF;
  setup();
  const Bytes zero{0x00}, t{0x21, 0x43};
  const std::vector<s7::WriteVarItem> items{
      {VarItem{ts::kBit, 1, 1, ar::kDataBlock, 1 * 8 + 6}, s7::data_transport::kBit, zero},
      {VarItem{ts::kTimer, 1, 0, ar::kTimer, 7}, s7::data_transport::kOctetString, t},
  };
  const auto req = s7::encode_write_var_request(9, items);
  ASSERT_TRUE(req.ok());
  EXPECT_EQ(answer(req.value), hex("32 03 00 00 00 09 00 02 00 02 00 00 | 05 02 | FF FF"));
  EXPECT_EQ((*memory.db(1))[1], 0xBF);
  EXPECT_EQ(memory.timers()[7], 0x2143);
  EXPECT_EQ(read(10, {VarItem{ts::kBit, 1, 1, ar::kDataBlock, 1 * 8 + 6},
                      VarItem{ts::kBit, 1, 1, ar::kDataBlock, 1 * 8 + 7}}),
            hex("32 03 00 00 00 0A 00 02 00 0B 00 00 | 04 02 | FF 03 00 01 00 00 | FF 03 00 01 01"));
}

// Negotiated PDU 240: 12 header + 2 params + 4 item header + 222 octets is exactly 240.
TEST_F(S7ServerTest, ReadVarStaysWithinTheNegotiatedPdu) {
  memory.create_db(1, 300);
  setup();
  const auto fits = read(11, {VarItem{ts::kByte, 222, 1, ar::kDataBlock, 0}});
  EXPECT_EQ(fits.size(), 240U);
  EXPECT_EQ(fits[14], 0xFF);
  EXPECT_EQ(read(12, {VarItem{ts::kByte, 223, 1, ar::kDataBlock, 0}}),
            hex("32 03 00 00 00 0C 00 02 00 04 00 00 | 04 01 | 85 00 00 00"));
  // Item by item: 200 octets fit (218), 30 more would not (252) and get 85, one more octet
  // after it still fits (218 + 4 + 5 = 227).
  const auto mixed = read(13, {VarItem{ts::kByte, 200, 1, ar::kDataBlock, 0},
                               VarItem{ts::kByte, 30, 1, ar::kDataBlock, 0},
                               VarItem{ts::kByte, 1, 1, ar::kDataBlock, 299 * 8}});
  ASSERT_EQ(mixed.size(), 227U);
  EXPECT_EQ(Bytes(mixed.begin() + 218, mixed.end()), hex("85 00 00 00 FF 04 00 08 00"));
}

// The PDU size is per session: two sessions on one CpuMemory.
TEST_F(S7ServerTest, PduSizeIsRememberedPerSession) {
  memory.create_db(1, 300);
  setup();
  S7Server small(memory, info);
  ASSERT_TRUE(small.handle(hex("32 01 00 00 00 00 00 08 00 00 | F0 00 00 01 00 01 00 80")).ok());
  EXPECT_EQ(small.negotiated().pdu_length, 128);
  const auto req = s7::encode_read_var_request(1, std::vector{VarItem{ts::kByte, 120, 1, ar::kDataBlock, 0}});
  EXPECT_EQ(small.handle(req.value).value,
            hex("32 03 00 00 00 01 00 02 00 04 00 00 | 04 01 | 85 00 00 00"));
  EXPECT_EQ(answer(req.value).size(), 12U + 2 + 4 + 120);
}

// Refused: a Job before Setup Communication and an unknown function get an Ack with error
// class 81, code 04 (snap7's Code7FunNotAvailable), no parameters, no data.
TEST_F(S7ServerTest, JobBeforeSetupIsRefused) {
  memory.create_db(1, 16);
  const Bytes req = hex("32 01 00 00 00 01 00 0E 00 00 | 04 01 12 0A 10 02 00 04 00 01 84 00 00 00");
  EXPECT_EQ(answer(req), hex("32 02 00 00 00 01 00 00 00 00 81 04"));
  EXPECT_EQ(answer(s7::encode_szl_request(2, {0, 0x0011, 0}).value),
            hex("32 02 00 00 00 02 00 00 00 00 81 04"));
  setup();
  EXPECT_EQ(answer(req)[13], 0x01);
  EXPECT_EQ(answer(req)[14], 0xFF);
}

TEST_F(S7ServerTest, UnknownFunctionAndMalformedBodiesAreRefused) {
  setup();
  // 1A request download, 28 PI service: not served.
  EXPECT_EQ(answer(hex("32 01 00 00 00 09 00 02 00 00 | 1A 00")),
            hex("32 02 00 00 00 09 00 00 00 00 81 04"));
  EXPECT_EQ(answer(hex("32 01 00 00 00 0A 00 00 00 00")),
            hex("32 02 00 00 00 0A 00 00 00 00 81 04"));
  // Read Var with no items; an item that is not 12 0A 10; data in a Read Var Job.
  EXPECT_EQ(answer(hex("32 01 00 00 00 0B 00 02 00 00 | 04 00")),
            hex("32 02 00 00 00 0B 00 00 00 00 81 04"));
  EXPECT_EQ(answer(hex("32 01 00 00 00 0C 00 0E 00 00 | 04 01 13 0A 10 02 00 04 00 01 84 00 00 00")),
            hex("32 02 00 00 00 0C 00 00 00 00 81 04"));
  EXPECT_EQ(answer(hex("32 01 00 00 00 0D 00 0E 00 01 | 04 01 12 0A 10 02 00 04 00 01 84 00 00 00 | 00")),
            hex("32 02 00 00 00 0D 00 00 00 00 81 04"));
  // Write Var whose data item runs past the data block; a Setup Communication too short.
  EXPECT_EQ(answer(hex("32 01 00 00 00 0E 00 0E 00 05 | 05 01 12 0A 10 04 00 01 00 01 84 00 00 10"
                       "| 00 04 00 10 BE")),
            hex("32 02 00 00 00 0E 00 00 00 00 81 04"));
  EXPECT_EQ(answer(hex("32 01 00 00 00 0F 00 04 00 00 | F0 00 00 01")),
            hex("32 02 00 00 00 0F 00 00 00 00 81 04"));
  // Userdata of another group (4 = CPU functions; 7 = time functions).
  EXPECT_EQ(answer(hex("32 07 00 00 00 10 00 08 00 04 | 00 01 12 04 11 47 01 00 | 0A 00 00 00")),
            hex("32 02 00 00 00 10 00 00 00 00 81 04"));
}

// Octets that are no S7 PDU, or not a Job/Userdata, get no answer: the codec's error.
TEST_F(S7ServerTest, NoAnswerWhenTheHeaderDoesNotDecode) {
  setup();
  struct Case {
    Bytes in;
    s7::Error error;
  };
  const std::vector<Case> cases{
      {{}, s7::Error::S7TooShort},
      {hex("32 01 00 00 00 01 00 00 00"), s7::Error::S7TooShort},
      {hex("33 01 00 00 00 01 00 00 00 00"), s7::Error::S7BadProtocolId},
      {hex("32 05 00 00 00 01 00 00 00 00"), s7::Error::S7UnknownPduType},
      {hex("32 01 00 00 00 01 00 02 00 00 | 04"), s7::Error::S7LengthMismatch},
      {hex("32 03 00 00 00 01 00 02 00 00 00 00 | 04 01"), s7::Error::S7WrongPduType},
      {hex("32 02 00 00 00 01 00 00 00 00 00 00"), s7::Error::S7WrongPduType},
  };
  for (const auto& c : cases) {
    const auto r = server.handle(c.in);
    EXPECT_EQ(r.error, c.error) << test::to_hex(c.in);
    EXPECT_TRUE(r.value.empty());
  }
}

s7::Decoded<s7::SzlResponse> szl(S7Server& server, std::uint16_t id, std::uint16_t index,
                                 Bytes& keep) {
  const auto req = s7::encode_szl_request(20, {3, id, index});
  auto r = server.handle(req.value);
  keep = r.value;
  const auto pdu = s7::decode_s7_pdu(keep);
  if (!pdu.ok()) return {{}, pdu.error, pdu.at};
  return s7::decode_szl_response(pdu.value);
}

TEST_F(S7ServerTest, ReadSzlModuleIdentification) {
  setup();
  info.order_number = "6ES7 315-2EH14-0AB0";
  Bytes keep;
  const auto r = szl(server, 0x0011, 0x0000, keep);
  ASSERT_TRUE(r.ok()) << s7::to_string(r.error);
  EXPECT_EQ(r.value.sequence, 3);
  EXPECT_EQ(r.value.error_code, 0);
  EXPECT_EQ(r.value.id, 0x0011);
  EXPECT_EQ(r.value.record_length, 28);
  EXPECT_EQ(r.value.record_count, 1);
  // index 0001 | "6ES7 315-2EH14-0AB0" + one space (20) | BGTyp | Ausbg | Ausbe
  EXPECT_EQ(Bytes(r.value.records.begin(), r.value.records.end()),
            hex("00 01 | 36 45 53 37 20 33 31 35 2D 32 45 48 31 34 2D 30 41 42 30 20"
                "| 00 00 00 00 00 00"));
}

TEST_F(S7ServerTest, ReadSzlCpuStateFollowsTheOwner) {
  setup();
  Bytes keep;
  auto r = szl(server, 0x0424, 0x0000, keep);
  ASSERT_TRUE(r.ok());
  EXPECT_EQ(r.value.record_length, 20);
  ASSERT_EQ(r.value.records.size(), 20U);
  EXPECT_EQ(r.value.records[3], cpu_state::kRun);
  info.state = cpu_state::kStop;
  r = szl(server, 0x0424, 0x0000, keep);
  ASSERT_TRUE(r.ok());
  EXPECT_EQ(r.value.records[3], cpu_state::kStop);
}

// Any other list: error code D4 01 ("invalid SZL ID", szl_source.hpp) and data 0A 00 00 00
// (docs/s7.md "Read SZL").
TEST_F(S7ServerTest, ReadSzlOtherListsAreUnknown) {
  setup();
  Bytes keep;
  for (const std::uint16_t id : std::vector<std::uint16_t>{0x0000, 0x0131, 0x0C91, 0x0071}) {
    const auto r = szl(server, id, 0x0001, keep);
    ASSERT_TRUE(r.ok());
    EXPECT_EQ(r.value.error_code, 0xD401);
    EXPECT_EQ(Bytes(keep.end() - 4, keep.end()), hex("0A 00 00 00"));
  }
}

}  // namespace
}  // namespace pbvbus::s7cpu
