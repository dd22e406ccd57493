// Broken captures into the replay input builder (replay_input.hpp): clear errors or unusable
// records with their reasons, never a crash (this file also runs under ASan+UBSan).
#include <gtest/gtest.h>

#include <random>

#include "../captures/capture_fixture.hpp"

#include "pbvbus/captures/pcapng_reader.hpp"
#include "pbvbus/captures/pcapng_writer.hpp"
#include "pbvbus/conformance/replay_input.hpp"

namespace pbvbus::conformance {
namespace {

using Bytes = std::vector<std::uint8_t>;
using captures::test::tap_frame;

// Data_Exchange and its reply (protocol-facts.md Appendix 1): FCS 0A+01+5D+AA+55 = 0x167 -> 67;
// 01+0A+08+3C = 0x4F.
const Bytes kDx = {0x68, 0x05, 0x05, 0x68, 0x0A, 0x01, 0x5D, 0xAA, 0x55, 0x67, 0x16};
const Bytes kDxRes = {0x68, 0x04, 0x04, 0x68, 0x01, 0x0A, 0x08, 0x3C, 0x4F, 0x16};

// Record offsets come from the reader (PcapngRecord::offset); inside an EPB (pcapng spec):
// +8 interface, +12/+16 timestamp, +20 captured length, +24 original length, +28 data.
Bytes capture(int pairs = 2) {
  bus::Scheduler sched;
  bus::Line line(sched, "dp0", bus::Baud::k1_5M);
  captures::test::MemorySink mem;
  captures::PcapngWriter w(mem.sink());
  w.add_line(line);
  const bus::Ticks bit = 2424;
  for (int i = 0; i < pairs; ++i) {
    w.write_frame(tap_frame(line, kDx, bit * (1000 * i)));
    w.write_frame(tap_frame(line, kDxRes, bit * (1000 * i + 132)));  // DX ends at 121, TSDR 11
  }
  captures::EventRecord e;
  e.text = "an event record, ignored by replay";
  w.write_event(bit * 5000, e);
  w.flush();
  return mem.data;
}

std::vector<std::uint64_t> epb_offsets(const Bytes& file) {
  captures::PcapngError err;
  auto cap = captures::read_pcapng(file, err);
  std::vector<std::uint64_t> v;
  if (cap)
    for (const auto& r : cap->records)
      if (r.interface == 0) v.push_back(r.offset);
  return v;
}

void put32(Bytes& b, std::size_t at, std::uint32_t v) {
  for (int i = 0; i < 4; ++i) b[at + static_cast<std::size_t>(i)] = static_cast<std::uint8_t>(v >> (8 * i));
}

TEST(ReplayInputParser, GoodCaptureIgnoresEvents) {
  std::string err;
  auto in = build_replay_input(capture(), {}, err);
  ASSERT_TRUE(in) << err;
  EXPECT_EQ(in->frames.size(), 4u);
  EXPECT_EQ(in->ignored_records, 1u);  // the event record
  EXPECT_EQ(in->comparable_requests(), 2u);
}

TEST(ReplayInputParser, CutShortFrameIsUnusableWithItsReason) {
  Bytes f = capture();
  const auto offs = epb_offsets(f);
  ASSERT_EQ(offs.size(), 4u);
  put32(f, offs[1] + 24, 13);  // the first reply: 10 octets captured of 13 on the wire
  std::string err;
  auto in = build_replay_input(f, {}, err);
  ASSERT_TRUE(in) << err;
  EXPECT_EQ(in->frames[1].role, ReplayRole::Unusable);
  EXPECT_EQ(in->frames[1].unusable_reason, "cut short: 10 of 13 octets captured");
  EXPECT_TRUE(in->frames[0].reply_unusable);
  EXPECT_EQ(in->comparable_requests(), 1u);
}

TEST(ReplayInputParser, BadFcsIsUnusableWithItsReason) {
  Bytes f = capture();
  const auto offs = epb_offsets(f);
  ASSERT_EQ(offs.size(), 4u);
  f[offs[2] + 28 + 9] ^= 0x01;  // the second Data_Exchange's FCS (octet 9 of 11)
  std::string err;
  auto in = build_replay_input(f, {}, err);
  ASSERT_TRUE(in) << err;
  EXPECT_EQ(in->frames[2].role, ReplayRole::Unusable);
  EXPECT_EQ(in->frames[2].unusable_reason, "not a valid telegram: FCS mismatch");
  // Its reply has no request to belong to.
  EXPECT_EQ(in->frames[3].role, ReplayRole::Response);
  EXPECT_EQ(in->frames[3].request, -1);
}

TEST(ReplayInputParser, TruncatedFileKeepsTheFramesBeforeTheBreak) {
  Bytes f = capture();
  const auto offs = epb_offsets(f);
  f.resize(offs[3] + 10);  // the last reply's block cut in the middle
  std::string err;
  auto in = build_replay_input(f, {}, err);
  ASSERT_TRUE(in) << err;
  EXPECT_EQ(in->frames.size(), 3u);
  EXPECT_EQ(in->read_error.rfind("offset " + std::to_string(offs[3]) + ": truncated block", 0), 0u)
      << in->read_error;
}

TEST(ReplayInputParser, HugeCapturedLengthIsAnError) {
  Bytes f = capture();
  const auto offs = epb_offsets(f);
  put32(f, offs[0] + 20, 0xFFFFFFF0u);  // the first EPB claims 4 GiB captured
  std::string err;
  EXPECT_FALSE(build_replay_input(f, {}, err));
  EXPECT_NE(err.find("captured length 4294967280 exceeds the block"), std::string::npos) << err;
}

TEST(ReplayInputParser, BadInputErrors) {
  std::string err;
  EXPECT_FALSE(build_replay_input(Bytes{}, {}, err));
  EXPECT_NE(err.find("no line"), std::string::npos) << err;
  EXPECT_FALSE(build_replay_input(Bytes(40, 0x41), {}, err));
  EXPECT_NE(err.find("not a pcapng file"), std::string::npos) << err;
  ReplayInputOptions o;
  o.line = "B";
  EXPECT_FALSE(build_replay_input(capture(), o, err));
  EXPECT_EQ(err, "the capture has no line 'B' (lines: dp0)");
}

TEST(ReplayInputParser, SeededMutationsNeverCrash) {
  const Bytes base = capture(3);
  std::mt19937_64 rng(20261126);
  int ok = 0, bad = 0;
  for (int i = 0; i < 5000; ++i) {
    Bytes m = base;
    const int edits = 1 + static_cast<int>(rng() % 4);
    for (int e = 0; e < edits && !m.empty(); ++e) {
      const std::size_t pos = rng() % m.size();
      switch (rng() % 3) {
        case 0: m[pos] = static_cast<std::uint8_t>(rng()); break;
        case 1: m[pos] ^= static_cast<std::uint8_t>(1u << (rng() % 8)); break;
        default: m.resize(pos); break;
      }
    }
    std::string err;
    auto in = build_replay_input(m, {}, err);
    if (!in) {
      ++bad;
      EXPECT_FALSE(err.empty());
      continue;
    }
    ++ok;
    for (std::size_t k = 0; k < in->frames.size(); ++k) {
      const ReplayFrame& f = in->frames[k];
      EXPECT_LT(f.offset, m.size());
      EXPECT_LE(f.start, f.end);
      EXPECT_EQ(f.role == ReplayRole::Unusable, !f.unusable_reason.empty());
      if (f.reply >= 0) {
        EXPECT_EQ(in->frames[static_cast<std::size_t>(f.reply)].request, static_cast<int>(k));
      }
      if (f.role != ReplayRole::Unusable) {
        EXPECT_LE(f.du_offset + f.du_len, f.bytes.size());
      }
    }
  }
  EXPECT_GT(ok, 500);
  EXPECT_GT(bad, 100);
}

}  // namespace
}  // namespace pbvbus::conformance
