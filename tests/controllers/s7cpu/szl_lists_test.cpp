// Read SZL beyond 0011/0424: module identification 0111, component identification 001C/011C,
// the SzlSource extension point and its error codes, the PDU limit of an answer, and the
// write mirror and views of CpuMemory (szl_lists.hpp, szl_source.hpp, s7_server.hpp,
// cpu_memory.hpp). Every expected octet is worked out by hand below.
#include <gtest/gtest.h>

#include "hex.hpp"
#include "pbvbus/s7/s7_read_var.hpp"
#include "pbvbus/s7/s7_write_var.hpp"
#include "pbvbus/s7cpu/s7_server.hpp"
#include "pbvbus/s7cpu/szl_lists.hpp"
#include "pbvbus/s7cpu/szl_source.hpp"

namespace pbvbus::s7cpu {
namespace {

using Bytes = std::vector<std::uint8_t>;

Bytes hex(std::string_view s) {
  std::string clean;
  for (const char c : s) {
    if (c != '|') clean.push_back(c);
  }
  return test::bytes_from_hex(clean);
}

const Bytes kSetupRequest = hex("32 01 00 00 00 00 00 08 00 00 | F0 00 00 01 00 01 01 E0");

/// Read SZL request, pdu-ref 0x0014, sequence 0, by hand: header (10) | parameters 8 octets
/// `00 01 12 04 11 44 01 00` | data `FF 09 00 04 <id> <index>`.
Bytes szl_request(std::uint16_t id, std::uint16_t index) {
  Bytes b = hex("32 07 00 00 00 14 00 08 00 08 | 00 01 12 04 11 44 01 00 | FF 09 00 04");
  b.push_back(static_cast<std::uint8_t>(id >> 8));
  b.push_back(static_cast<std::uint8_t>(id));
  b.push_back(static_cast<std::uint8_t>(index >> 8));
  b.push_back(static_cast<std::uint8_t>(index));
  return b;
}

/// The answer's head, by hand: Userdata header (10) with the data length `dlen` | parameters
/// `00 01 12 08 12 84 01 00 | 00 00 <error code>`.
Bytes szl_head(std::uint16_t dlen, std::uint16_t error) {
  Bytes b = hex("32 07 00 00 00 14 00 0C");
  b.push_back(static_cast<std::uint8_t>(dlen >> 8));
  b.push_back(static_cast<std::uint8_t>(dlen));
  const Bytes p = hex("00 01 12 08 12 84 01 00 00 00");
  b.insert(b.end(), p.begin(), p.end());
  b.push_back(static_cast<std::uint8_t>(error >> 8));
  b.push_back(static_cast<std::uint8_t>(error));
  return b;
}

Bytes cat(Bytes a, const Bytes& b) {
  a.insert(a.end(), b.begin(), b.end());
  return a;
}

Bytes text(std::string_view s, std::size_t width, std::uint8_t fill = 0) {
  Bytes b(s.begin(), s.end());
  b.resize(width, fill);
  return b;
}

struct SzlTest : ::testing::Test {
  CpuMemory memory{CpuMemorySizes{16, 16, 16, 8, 8}};
  CpuInfo info;
  S7Server server{memory, info};
  void SetUp() override { ASSERT_TRUE(server.handle(kSetupRequest).ok()); }
  Bytes ask(std::uint16_t id, std::uint16_t index) {
    const auto r = server.handle(szl_request(id, index));
    EXPECT_TRUE(r.ok());
    return r.value;
  }
};

// 0111 index 0001: one record of 28 octets; data length 4 + 8 + 28 = 40 = 0x28, list length
// 8 + 28 = 36 = 0x24.
TEST_F(SzlTest, OneModuleIdentificationRecord) {
  info.module_version = 0x0003;
  const Bytes expected = cat(szl_head(0x0028, 0),
                             cat(hex("FF 09 00 24 | 01 11 00 01 | 00 1C 00 01 | 00 01"),
                                 cat(text("6ES7 315-2AG10-0AB0", 20, ' '),
                                     hex("00 00 | 00 03 | 00 00"))));
  EXPECT_EQ(ask(0x0111, 0x0001), expected);
  // Another index of the manual (0006 basic hardware) is not modelled: D4 02.
  EXPECT_EQ(ask(0x0111, 0x0006), cat(szl_head(0x0004, 0xD402), hex("0A 00 00 00")));
}

// 001C: six records of 34 octets = 204; list length 8 + 204 = 212 = 0xD4; data length
// 216 = 0xD8; the PDU 10 + 12 + 216 = 238 (a seventh record would not fit 240).
TEST_F(SzlTest, ComponentIdentificationAllRecords) {
  info.plc_name = "Plant A";
  info.plant_id = "Line 1";
  Bytes records;
  for (const Bytes& r : {cat(hex("00 01"), text("Plant A", 32)),
                         cat(hex("00 02"), text("CPU 315-2 DP", 32)),
                         cat(hex("00 03"), text("Line 1", 32)),
                         cat(hex("00 04"), text("Original Siemens Equipment", 32)),
                         cat(hex("00 05"), text("S C-PBVBUS000001", 32)),
                         cat(hex("00 07"), text("CPU 315-2 DP", 32))})
    records = cat(records, r);
  ASSERT_EQ(records.size(), 204U);
  const Bytes answer = ask(0x001C, 0x0000);
  EXPECT_EQ(answer, cat(szl_head(0x00D8, 0),
                        cat(hex("FF 09 00 D4 | 00 1C 00 00 | 00 22 00 06"), records)));
  EXPECT_EQ(answer.size(), 238U);
}

TEST_F(SzlTest, OneComponentAndItsIndexErrors) {
  // 011C index 0004: 34 octets; list length 42 = 0x2A, data length 46 = 0x2E.
  EXPECT_EQ(ask(0x011C, 0x0004),
            cat(szl_head(0x002E, 0),
                cat(hex("FF 09 00 2A | 01 1C 00 04 | 00 22 00 01 | 00 04"),
                    text("Original Siemens Equipment", 32))));
  // A name longer than its field is cut at 24 characters.
  info.module_name = "ABCDEFGHIJKLMNOPQRSTUVWXYZ";
  const Bytes a = ask(0x011C, 0x0002);
  EXPECT_EQ(Bytes(a.begin() + 34, a.end()),
            cat(hex("00 02"), text("ABCDEFGHIJKLMNOPQRSTUVWX", 32)));
  for (const std::uint16_t i : std::vector<std::uint16_t>{0x0000, 0x0006, 0x0008, 0x000B})
    EXPECT_EQ(ask(0x011C, i), cat(szl_head(0x0004, 0xD402), hex("0A 00 00 00"))) << i;
}

/// A source with one list of its own (W#16#0071, 2 records of 2 octets) that also overrides
/// 0424 and reports the three refusals.
struct TestSource : SzlSource {
  int asked = 0;
  std::optional<SzlList> read_szl(std::uint16_t id, std::uint16_t index) override {
    ++asked;
    if (id == 0x0071 && index == 0) return SzlList{SzlStatus::Ok, 2, 2, {0x12, 0x34, 0x56, 0x78}};
    if (id == 0x0071) return SzlList{SzlStatus::UnknownIndex, 0, 0, {}};
    if (id == 0x0C75) return SzlList{SzlStatus::NotAvailableNow, 0, 0, {}};
    if (id == 0x0019) return SzlList{SzlStatus::UnknownId, 0, 0, {}};
    if (id == 0x0424) return SzlList{SzlStatus::Ok, 20, 1, Bytes(20, 0x0B)};
    if (id == 0x0232) return SzlList{SzlStatus::Ok, 4, 2, {1, 2, 3}};  // does not add up
    return std::nullopt;
  }
};

TEST_F(SzlTest, TheSourceIsAskedFirstAndItsRefusalsAreMapped) {
  TestSource source;
  server.set_szl_source(&source);
  // list length 8 + 4 = 12 = 0x0C, data length 16 = 0x10.
  EXPECT_EQ(ask(0x0071, 0x0000),
            cat(szl_head(0x0010, 0), hex("FF 09 00 0C | 00 71 00 00 | 00 02 00 02 | 12 34 56 78")));
  EXPECT_EQ(ask(0x0071, 0x0001), cat(szl_head(0x0004, 0xD402), hex("0A 00 00 00")));
  EXPECT_EQ(ask(0x0C75, 0x0101), cat(szl_head(0x0004, 0xD406), hex("0A 00 00 00")));
  EXPECT_EQ(ask(0x0019, 0x0000), cat(szl_head(0x0004, 0xD401), hex("0A 00 00 00")));
  EXPECT_EQ(ask(0x0232, 0x0004), cat(szl_head(0x0004, 0xD406), hex("0A 00 00 00")));
  // The source's 0424 wins over the server's own; 0011 falls through to the server.
  const Bytes state = ask(0x0424, 0x0000);
  ASSERT_EQ(state.size(), 22U + 12U + 20U);
  EXPECT_EQ(state[22 + 12 + 3], 0x0B);
  const Bytes module = ask(0x0011, 0x0000);
  EXPECT_EQ(Bytes(module.begin() + 26, module.begin() + 34), hex("00 11 00 00 00 1C 00 01"));
  EXPECT_EQ(source.asked, 7);
  EXPECT_EQ(szl_error_code(SzlStatus::Ok), 0);
}

// A list larger than the negotiated PDU: the records that fit, N_DR counting those.
TEST(SzlPdu, AnswerIsCutToWholeRecordsThatFit) {
  CpuMemory memory;
  CpuInfo info;
  S7Server server(memory, info, {1, 1, 100});
  ASSERT_TRUE(server.handle(kSetupRequest).ok());  // PDU 100
  // 001C: 100 - (10 + 12 + 4 + 8) = 66 octets of room: one record of 34. list length 42, data length 46.
  const auto r = server.handle(szl_request(0x001C, 0x0000));
  ASSERT_TRUE(r.ok());
  EXPECT_EQ(r.value, cat(szl_head(0x002E, 0),
                         cat(hex("FF 09 00 2A | 00 1C 00 00 | 00 22 00 01 | 00 01"),
                             text("SIMATIC 300", 32))));
}

// Write Var: what succeeds on the primary memory is written into the mirror too; a refused
// item nowhere; an item the mirror cannot hold is skipped there.
TEST(S7Mirror, SuccessfulItemsReachTheMirror) {
  CpuMemory a(CpuMemorySizes{4, 4, 4, 2, 2});
  CpuMemory b(CpuMemorySizes{4, 4, 2, 2, 2});
  a.create_db(1, 4);
  b.create_db(1, 4);
  CpuInfo info;
  S7Server server(a, info);
  server.set_mirror(&b);
  ASSERT_TRUE(server.handle(kSetupRequest).ok());
  // Write Var by hand, pdu-ref 7: 3 items: DB1.DBW2 = 12 34, MB3 = 99 (b has 2 flags only),
  // DB2.DBB0 (missing): parameters 2 + 3 * 12 = 38 = 0x26; data 6 + 5 + 1 fill... per item:
  // `00 04 00 10 12 34` (6), `00 04 00 08 99` + fill (6), `00 04 00 08 55` (5) = 17 = 0x11.
  const Bytes req = hex(
      "32 01 00 00 00 07 00 26 00 11 | 05 03"
      "| 12 0A 10 02 00 02 00 01 84 00 00 10"
      "| 12 0A 10 02 00 01 00 00 83 00 00 18"
      "| 12 0A 10 02 00 01 00 02 84 00 00 00"
      "| 00 04 00 10 12 34 | 00 04 00 08 99 00 | 00 04 00 08 55");
  const auto r = server.handle(req);
  ASSERT_TRUE(r.ok());
  EXPECT_EQ(r.value, hex("32 03 00 00 00 07 00 02 00 03 00 00 | 05 03 | FF FF 0A"));
  EXPECT_EQ(get_word(*a.db(1), 2), 0x1234);
  EXPECT_EQ(get_word(*b.db(1), 2), 0x1234);
  EXPECT_EQ(get_byte(a.area(Area::Flags), 3), 0x99);
  EXPECT_EQ(b.area(Area::Flags).size(), 2U);  // nothing written past its end
}

// Views: the memory serves the owner's storage; rebinding follows a reallocation.
TEST(CpuMemoryViews, AreasCellsAndDbsOnTheOwnersStorage) {
  std::vector<std::uint8_t> pii(8), work(12);
  std::vector<std::uint16_t> counters(3);
  CpuMemory m;
  m.create_db(5, 2);
  m.bind(Area::Inputs, pii);
  m.bind(Area::Flags, std::span<std::uint8_t>(work).first(4));
  m.bind_db(1, std::span<std::uint8_t>(work).subspan(4, 8));
  m.bind_counters(counters);
  EXPECT_EQ(m.sizes().inputs, 8U);
  EXPECT_EQ(m.sizes().flags, 4U);
  EXPECT_EQ(m.sizes().counters, 3U);
  ASSERT_TRUE(set_word(*m.db(1), 0, 0xBEEF));
  EXPECT_EQ(work[4], 0xBE);
  EXPECT_EQ(work[5], 0xEF);
  pii[7] = 0x42;
  EXPECT_EQ(get_byte(m.area(Area::Inputs), 7), 0x42);
  m.counters()[2] = 9;
  EXPECT_EQ(counters[2], 9);
  EXPECT_TRUE(m.has_db(5));
  m.clear_dbs();
  EXPECT_FALSE(m.has_db(1));
  EXPECT_FALSE(m.has_db(5));
}

}  // namespace
}  // namespace pbvbus::s7cpu
