// PcapngReader on hand-made, broken and mutated files: clear errors with file offsets, big-endian
// sections, unknown blocks skipped, and no crash on any seeded mutation (runs under ASan+UBSan).

#include <gtest/gtest.h>

#include <random>

#include "capture_fixture.hpp"

#include "pbvbus/captures/pcapng_reader.hpp"
#include "pbvbus/captures/pcapng_writer.hpp"

namespace pbvbus::captures {
namespace {

using test::Bytes;

// A minimal big-endian file written from the spec: SHB (no options), IDB link type 147 with
// if_tsresol 3 (ms) and if_name "be0", one EPB with an SD4 token at 1500 ms.
const Bytes kBigEndian = {
    0x0A, 0x0D, 0x0D, 0x0A, 0x00, 0x00, 0x00, 0x1C, 0x1A, 0x2B, 0x3C, 0x4D, 0x00, 0x01, 0x00, 0x00,
    0xFF, 0xFF, 0xFF, 0xFF, 0xFF, 0xFF, 0xFF, 0xFF, 0x00, 0x00, 0x00, 0x1C,
    // IDB, length 40
    0x00, 0x00, 0x00, 0x01, 0x00, 0x00, 0x00, 0x28, 0x00, 0x93, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00,
    0x00, 0x02, 0x00, 0x03, 'b', 'e', '0', 0x00, 0x00, 0x09, 0x00, 0x01, 0x03, 0x00, 0x00, 0x00,
    0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x28,
    // EPB, length 36: if 0, ts 1500, caplen 3, origlen 3, DC 05 02 + pad
    0x00, 0x00, 0x00, 0x06, 0x00, 0x00, 0x00, 0x24, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00,
    0x00, 0x00, 0x05, 0xDC, 0x00, 0x00, 0x00, 0x03, 0x00, 0x00, 0x00, 0x03, 0xDC, 0x05, 0x02, 0x00,
    0x00, 0x00, 0x00, 0x24};

TEST(PcapngReader, ReadsBigEndianSections) {
  PcapngError err;
  auto cap = read_pcapng(kBigEndian, err);
  ASSERT_TRUE(cap) << err.to_string();
  ASSERT_EQ(cap->interfaces.size(), 1u);
  EXPECT_EQ(cap->interfaces[0].name, "be0");
  EXPECT_EQ(cap->interfaces[0].link_type, 147);
  EXPECT_EQ(cap->interfaces[0].tsresol, 3);
  ASSERT_EQ(cap->records.size(), 1u);
  EXPECT_EQ(cap->records[0].ts_ns, 1'500'000'000);
  EXPECT_EQ(cap->records[0].bytes, test::kToken_2_to_5);
  EXPECT_EQ(cap->records[0].offset, 68u);
}

Bytes sample_capture() {
  bus::Scheduler sched;
  bus::Line line(sched, "dp0", bus::Baud::k1_5M);
  test::MemorySink mem;
  PcapngWriter w(mem.sink());
  w.on_frame(test::tap_frame(line, test::kSlaveDiagReq, 100));
  w.on_frame(test::tap_frame(line, test::kSlaveDiagRes, 200, bus::kRxCollision));
  EventRecord e;
  e.text = "note";
  w.write_event(300, e);
  w.flush();
  return mem.data;
}

TEST(PcapngReader, SkipsUnknownBlocksAndReadsSeveralSections) {
  Bytes file = sample_capture();
  // A custom block (type 0x00000BAD, length 16) between the IDB and the first EPB.
  const Bytes custom = {0xAD, 0x0B, 0x00, 0x00, 0x10, 0x00, 0x00, 0x00,
                        0x01, 0x02, 0x03, 0x04, 0x10, 0x00, 0x00, 0x00};
  const std::size_t after_idb = 44 + 80;
  Bytes with_custom(file.begin(), file.begin() + after_idb);
  with_custom.insert(with_custom.end(), custom.begin(), custom.end());
  with_custom.insert(with_custom.end(), file.begin() + after_idb, file.end());
  // A second section follows: the big-endian file.
  with_custom.insert(with_custom.end(), kBigEndian.begin(), kBigEndian.end());
  PcapngError err;
  auto cap = read_pcapng(with_custom, err);
  ASSERT_TRUE(cap) << err.to_string();
  ASSERT_EQ(cap->interfaces.size(), 3u);  // dp0, events, be0
  EXPECT_EQ(cap->interfaces[2].section, 1u);
  ASSERT_EQ(cap->records.size(), 4u);
  EXPECT_EQ(cap->records[1].comment, "collision");
  EXPECT_EQ(cap->records[1].flags, pcapng::kFlagSymbolError);
  EXPECT_EQ(cap->records[3].interface, 2u);
  EXPECT_EQ(cap->records[3].bytes, test::kToken_2_to_5);
}

std::string error_of(const Bytes& b) {
  PcapngError err;
  auto cap = read_pcapng(b, err);
  if (cap) return "no error";
  return err.to_string();
}

TEST(PcapngReader, GarbageGetsAClearErrorWithTheOffset) {
  EXPECT_EQ(error_of(Bytes{}), "no error");  // an empty file holds no packets
  EXPECT_EQ(error_of(Bytes(20, 0x41)),
            "offset 0: not a pcapng file: it does not start with a Section Header Block");
  Bytes f = sample_capture();
  EXPECT_EQ(error_of(Bytes(f.begin(), f.begin() + 130)),
            "offset 124: truncated block: 6 octets left, a block needs at least 12");
  Bytes g = f;
  g[8] = 0;  // byte-order magic
  EXPECT_EQ(error_of(g), "offset 8: SHB byte-order magic is not 1A2B3C4D in either byte order");
  g = f;
  g[44 + 4] = 0x51;  // IDB length 81
  EXPECT_EQ(error_of(g), "offset 48: IDB block length 81 is below 12 or not a multiple of 4");
  g = f;
  g[124 + 4] = 0xF0;
  g[124 + 5] = 0xFF;  // EPB length 0xFFF0 runs past the end
  EXPECT_EQ(
      error_of(g).rfind("offset 128: EPB block length 65520 runs past the end of the file", 0), 0u)
      << error_of(g);
  g = f;
  g[124 + 8] = 7;  // interface 7
  EXPECT_EQ(error_of(g), "offset 132: EPB refers to interface 7, but the section declares 1");
  g = f;
  g[124 + 20] = 200;  // caplen 200 in a 44-octet block
  EXPECT_EQ(error_of(g), "offset 144: EPB captured length 200 exceeds the block (44 octets)");
  g = f;
  g[124 + 40] = 0x30;  // trailing length differs
  EXPECT_EQ(error_of(g),
            "offset 164: EPB trailing block length 48 differs from the leading one (44)");
  g = f;
  g[44 + 16 + 2] = 0x40;  // if_name option length 64 runs past the IDB
  EXPECT_EQ(error_of(g), "offset 60: IDB: option 2 of length 64 runs past the block");
  g = f;
  g[12] = 2;  // version 2.0
  EXPECT_EQ(error_of(g), "offset 12: unsupported pcapng major version 2");
}

// Replay's input (docs/replay.md): the four broken-file cases the fuzz target's seeds also hold.
TEST(PcapngReader, ReplayInputCasesGetClearErrors) {
  const Bytes f = sample_capture();
  // An EPB claiming a captured length of 0xFFFFFFF0: an error, never a 4 GiB read or allocation
  // (and no overflow in "28 + captured length").
  Bytes g = f;
  g[124 + 20] = 0xF0;
  g[124 + 21] = 0xFF;
  g[124 + 22] = 0xFF;
  g[124 + 23] = 0xFF;
  EXPECT_EQ(error_of(g), "offset 144: EPB captured length 4294967280 exceeds the block (44 octets)");
  // A block cut inside its body (the first EPB, 44 octets long, ends after 20).
  EXPECT_EQ(error_of(Bytes(f.begin(), f.begin() + 124 + 20)),
            "offset 128: EPB block length 44 runs past the end of the file (20 octets left)");
  // A block length that is not a multiple of 4 (EPB 45).
  g = f;
  g[124 + 4] = 45;
  EXPECT_EQ(error_of(g), "offset 128: EPB block length 45 is below 12 or not a multiple of 4");
  // An unknown block type at the end of the file, with consistent lengths, is skipped.
  g = f;
  const Bytes unknown = {0x0D, 0xF0, 0xAD, 0x0B, 0x10, 0x00, 0x00, 0x00,
                         0xAA, 0xBB, 0xCC, 0xDD, 0x10, 0x00, 0x00, 0x00};
  g.insert(g.end(), unknown.begin(), unknown.end());
  PcapngError err;
  auto cap = read_pcapng(g, err);
  ASSERT_TRUE(cap) << err.to_string();
  EXPECT_EQ(cap->records.size(), 3u);
}

TEST(PcapngReader, MissingFileIsAnError) {
  PcapngError err;
  EXPECT_FALSE(read_pcapng_file("/nonexistent/capture.pcapng", err));
  EXPECT_EQ(err.to_string().rfind("offset 0: cannot open '/nonexistent/capture.pcapng'", 0), 0u);
}

TEST(PcapngReader, SeededMutationsNeverCrash) {
  const Bytes base = sample_capture();
  std::mt19937_64 rng(20261121);
  int errors = 0, parsed = 0;
  for (int i = 0; i < 20000; ++i) {
    Bytes m = base;
    const int edits = 1 + static_cast<int>(rng() % 4);
    for (int e = 0; e < edits; ++e) {
      const std::size_t pos = rng() % m.size();
      switch (rng() % 4) {
        case 0:
          m[pos] = static_cast<std::uint8_t>(rng());
          break;
        case 1:
          m[pos] ^= static_cast<std::uint8_t>(1u << (rng() % 8));
          break;
        case 2:
          m.resize(pos);
          break;
        default:
          m.insert(m.begin() + static_cast<std::ptrdiff_t>(pos), static_cast<std::uint8_t>(rng()));
          break;
      }
      if (m.empty()) break;
    }
    PcapngError err;
    auto cap = read_pcapng(m, err);
    if (cap) {
      ++parsed;
      for (const auto& r : cap->records) EXPECT_LT(r.interface, cap->interfaces.size());
    } else {
      ++errors;
      EXPECT_FALSE(err.message.empty());
      EXPECT_LE(err.offset, m.size());
    }
  }
  // Both outcomes occur: the test exercises the error paths and the happy path.
  EXPECT_GT(errors, 1000);
  EXPECT_GT(parsed, 100);
}

}  // namespace
}  // namespace pbvbus::captures
