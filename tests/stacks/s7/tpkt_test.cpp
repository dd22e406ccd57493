// TPKT framing and the streaming reassembler (RFC 1006; stacks/s7 tpkt.hpp).
#include "pbvbus/s7/tpkt.hpp"

#include <gtest/gtest.h>

#include <random>

#include "hex.hpp"

namespace pbvbus::s7 {
namespace {

using test::hex;

// Three TPKTs as a client sends them back to back (tools-and-formats.md §3.4): nodes7's CR,
// the Setup Communication job and the Read Var job.
const std::vector<std::uint8_t> kCr =
    hex("03 00 00 16 11 E0 00 00 00 01 00 C0 01 0A C1 02 01 00 C2 02 01 02");
const std::vector<std::uint8_t> kSetup =
    hex("03 00 00 19 02 F0 80 32 01 00 00 00 00 00 08 00 00 F0 00 00 01 00 01 01 E0");
const std::vector<std::uint8_t> kRead = hex(
    "03 00 00 1F 02 F0 80 32 01 00 00 00 01 00 0E 00 00 04 01 12 0A 10 02 00 04 00 01 84 00 00 00");

std::vector<std::uint8_t> stream() {
  std::vector<std::uint8_t> s = kCr;
  s.insert(s.end(), kSetup.begin(), kSetup.end());
  s.insert(s.end(), kRead.begin(), kRead.end());
  return s;
}

// Feeds `chunks` in order; returns the whole TPKTs that came out.
std::vector<std::vector<std::uint8_t>> run(
    TpktReassembler& r, const std::vector<std::span<const std::uint8_t>>& chunks) {
  std::vector<std::vector<std::uint8_t>> out;
  for (auto c : chunks) {
    while (!c.empty()) {
      const std::size_t n = r.feed(c);
      c = c.subspan(n);
      if (r.ready()) {
        out.emplace_back(r.tpkt().begin(), r.tpkt().end());
        r.pop();
      } else if (n == 0) {
        return out;  // error: nothing more is taken
      }
    }
  }
  return out;
}

TEST(Tpkt, AppendWritesVersionReservedAndTotalLength) {
  std::vector<std::uint8_t> out;
  const auto cotp = hex("02 F0 80 32 01");
  ASSERT_EQ(append_tpkt(out, cotp), Error::None);
  EXPECT_EQ(out, hex("03 00 00 09 02 F0 80 32 01"));
}

TEST(Tpkt, AppendRefusesTooSmallAndTooLargeAndLeavesOutputAlone) {
  std::vector<std::uint8_t> out{0xAA};
  EXPECT_EQ(append_tpkt(out, hex("02 F0")), Error::TpktLengthTooSmall);
  const std::vector<std::uint8_t> big(65532, 0);
  EXPECT_EQ(append_tpkt(out, big), Error::TpktPayloadTooLarge);
  EXPECT_EQ(out, std::vector<std::uint8_t>{0xAA});
  const std::vector<std::uint8_t> max(65531, 0);
  EXPECT_EQ(append_tpkt(out, max), Error::None);
  EXPECT_EQ(out.size(), 1u + 65535u);
}

TEST(Tpkt, WholeStreamInOneChunkGivesThreeTpkts) {
  TpktReassembler r;
  const auto s = stream();
  const auto got = run(r, {s});
  ASSERT_EQ(got.size(), 3u);
  EXPECT_EQ(got[0], kCr);
  EXPECT_EQ(got[1], kSetup);
  EXPECT_EQ(got[2], kRead);
  EXPECT_EQ(r.error(), Error::None);
  EXPECT_EQ(r.pending(), 0u);
}

TEST(Tpkt, PayloadIsTheCotpTpdu) {
  TpktReassembler r;
  EXPECT_EQ(r.feed(kSetup), kSetup.size());
  ASSERT_TRUE(r.ready());
  EXPECT_EQ(std::vector<std::uint8_t>(r.payload().begin(), r.payload().end()),
            std::vector<std::uint8_t>(kSetup.begin() + 4, kSetup.end()));
}

// Property: every way of cutting the stream in two gives the same TPKTs.
TEST(Tpkt, EverySingleSplitPointGivesTheSameTpkts) {
  const auto s = stream();
  const std::span<const std::uint8_t> all(s);
  for (std::size_t cut = 0; cut <= s.size(); ++cut) {
    TpktReassembler r;
    const auto got = run(r, {all.first(cut), all.subspan(cut)});
    ASSERT_EQ(got.size(), 3u) << "cut at " << cut;
    EXPECT_EQ(got[0], kCr) << "cut at " << cut;
    EXPECT_EQ(got[1], kSetup) << "cut at " << cut;
    EXPECT_EQ(got[2], kRead) << "cut at " << cut;
  }
}

// Property: every pair of cut points (three chunks, empty ones included) gives the same TPKTs.
TEST(Tpkt, EveryPairOfSplitPointsGivesTheSameTpkts) {
  const auto s = stream();
  const std::span<const std::uint8_t> all(s);
  for (std::size_t a = 0; a <= s.size(); ++a) {
    for (std::size_t b = a; b <= s.size(); ++b) {
      TpktReassembler r;
      const auto got = run(r, {all.first(a), all.subspan(a, b - a), all.subspan(b)});
      ASSERT_EQ(got.size(), 3u) << a << "/" << b;
      ASSERT_EQ(got[2], kRead) << a << "/" << b;
    }
  }
}

TEST(Tpkt, OctetByOctetAndSeededRandomChunkings) {
  const auto s = stream();
  std::vector<std::span<const std::uint8_t>> ones;
  for (std::size_t i = 0; i < s.size(); ++i) ones.push_back(std::span(s).subspan(i, 1));
  TpktReassembler r1;
  EXPECT_EQ(run(r1, ones).size(), 3u);

  std::mt19937 rng(1006);
  for (int round = 0; round < 200; ++round) {
    std::vector<std::span<const std::uint8_t>> chunks;
    std::size_t at = 0;
    while (at < s.size()) {
      const std::size_t n = std::min<std::size_t>(s.size() - at, rng() % 9);
      chunks.push_back(std::span(s).subspan(at, n));
      at += n;
    }
    TpktReassembler r;
    const auto got = run(r, chunks);
    ASSERT_EQ(got.size(), 3u) << "round " << round;
    EXPECT_EQ(got[1], kSetup);
  }
}

TEST(Tpkt, NothingIsTakenWhileATpktIsReady) {
  TpktReassembler r;
  const auto s = stream();
  EXPECT_EQ(r.feed(s), kCr.size());
  EXPECT_TRUE(r.ready());
  EXPECT_EQ(r.feed(std::span(s).subspan(kCr.size())), 0u);
  r.pop();
  EXPECT_FALSE(r.ready());
  EXPECT_TRUE(r.tpkt().empty());
  EXPECT_EQ(r.feed(std::span(s).subspan(kCr.size())), kSetup.size());
}

TEST(Tpkt, BadVersionIsAnErrorAtItsOffsetAndSticky) {
  TpktReassembler r;
  const auto s = hex("03 00 00 07 02 F0 80 04 00 00 07");
  EXPECT_EQ(r.feed(s), 7u);  // the first TPKT; the next octet waits for pop()
  EXPECT_TRUE(r.ready());
  r.pop();
  EXPECT_EQ(r.feed(std::span(s).subspan(7)), 1u);
  EXPECT_EQ(r.error(), Error::TpktBadVersion);
  EXPECT_EQ(r.error_offset(), 7u);
  EXPECT_EQ(r.feed(kCr), 0u);
  EXPECT_FALSE(r.ready());
}

TEST(Tpkt, LengthBelowSevenIsAnError) {
  for (std::uint8_t len = 0; len < 7; ++len) {
    TpktReassembler r;
    const std::vector<std::uint8_t> s{3, 0, 0, len, 2, 0xF0, 0x80};
    EXPECT_EQ(r.feed(s), 4u);
    EXPECT_EQ(r.error(), Error::TpktLengthTooSmall) << int(len);
    EXPECT_EQ(r.error_offset(), 2u);
  }
  TpktReassembler ok;
  ok.feed(hex("03 00 00 07 02 F0 80"));
  EXPECT_TRUE(ok.ready());
}

TEST(Tpkt, LengthAboveTheMaximumIsAnErrorWithoutAllocating) {
  TpktReassembler r;  // default bound 2052
  EXPECT_EQ(r.max_length(), kTpktDefaultMaxLength);
  EXPECT_EQ(r.feed(hex("03 00 08 05")), 4u);
  EXPECT_EQ(r.error(), Error::TpktLengthTooLarge);
  EXPECT_EQ(r.pending(), 0u);

  TpktReassembler edge;
  std::vector<std::uint8_t> s{3, 0, 0x08, 0x04};
  s.resize(2052, 0x55);
  EXPECT_EQ(edge.feed(s), s.size());
  EXPECT_TRUE(edge.ready());
}

TEST(Tpkt, NegotiatedMaximumIsClampedAndApplied) {
  TpktReassembler r;
  r.set_max_length(4 + 1024);  // after a CC with TPDU size 0x0A
  EXPECT_EQ(r.max_length(), 1028u);
  r.feed(hex("03 00 04 05"));
  EXPECT_EQ(r.error(), Error::TpktLengthTooLarge);
  TpktReassembler c(1);
  EXPECT_EQ(c.max_length(), kTpktMinLength);
  TpktReassembler d(1u << 20);
  EXPECT_EQ(d.max_length(), kTpktMaxLength);
}

// Garbage: whatever is fed, the buffer never exceeds the bound and nothing crashes.
TEST(Tpkt, SeededGarbageStaysWithinTheBound) {
  std::mt19937 rng(102);
  for (int round = 0; round < 500; ++round) {
    std::vector<std::uint8_t> g(rng() % 3000);
    for (auto& b : g) b = static_cast<std::uint8_t>(rng());
    if (!g.empty() && round % 2 == 0) g[0] = 3;  // get past the version check half the time
    TpktReassembler r(64);
    std::span<const std::uint8_t> rest(g);
    while (!rest.empty()) {
      const std::size_t n = r.feed(rest.first(std::min<std::size_t>(rest.size(), 1 + rng() % 50)));
      ASSERT_LE(r.pending(), 64u);
      rest = rest.subspan(n);
      if (r.ready()) {
        ASSERT_LE(r.tpkt().size(), 64u);
        ASSERT_GE(r.tpkt().size(), 7u);
        r.pop();
      } else if (n == 0) {
        break;
      }
    }
  }
}

}  // namespace
}  // namespace pbvbus::s7
