// Splitting a byte stream into FDL telegrams for serial attachments (protocol-facts.md §B.1).
// Lengths are written by hand here; the lead's cross-check compares with fdl::frame_length.

#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "hex.hpp"
#include "pbvbus/bus/frame_splitter.hpp"

namespace pbvbus::bus {
namespace {

using test::bytes_from_hex;
using test::to_hex;

int len_of(const char* hex) {
  const auto b = bytes_from_hex(hex);
  return telegram_length(b);
}

TEST(TelegramLength, EveryStartDelimiter) {
  EXPECT_EQ(len_of("E5"), 1);
  EXPECT_EQ(len_of("DC"), 3);
  EXPECT_EQ(len_of("10"), 6);
  EXPECT_EQ(len_of("A2"), 14);
  EXPECT_EQ(len_of("68 05 05 68"), 11);   // LE 5: 5 + 6
  EXPECT_EQ(len_of("68 04 04 68"), 10);   // smallest LE
  EXPECT_EQ(len_of("68 F9 F9 68"), 255);  // LE 249: the longest telegram
  EXPECT_EQ(len_of(""), 0);
  EXPECT_EQ(len_of("68"), 0);
  EXPECT_EQ(len_of("68 05"), 0);
  EXPECT_EQ(len_of("68 05 05"), 0);
}

TEST(TelegramLength, RejectsWhatCannotStartATelegram) {
  EXPECT_EQ(len_of("16"), -1);
  EXPECT_EQ(len_of("00"), -1);
  EXPECT_EQ(len_of("FF"), -1);
  EXPECT_EQ(len_of("68 03 03 68"), -1);  // LE below 4
  EXPECT_EQ(len_of("68 FA FA 68"), -1);  // LE above 249
  EXPECT_EQ(len_of("68 05 06 68"), -1);  // LE != LEr
  EXPECT_EQ(len_of("68 05 05 69"), -1);  // second SD wrong
  EXPECT_EQ(len_of("68 05 06"), -1);     // known bad before the 4th octet
  for (int b = 0; b < 256; ++b) {
    const std::uint8_t o = static_cast<std::uint8_t>(b);
    const int l = telegram_length(std::span(&o, 1));
    if (o == 0xE5 || o == 0xDC || o == 0x10 || o == 0xA2 || o == 0x68) EXPECT_GE(l, 0) << b;
    else EXPECT_EQ(l, -1) << b;
  }
}

std::vector<std::string> split(FrameSplitter& s, const char* hex) {
  std::vector<std::string> out;
  s.feed(bytes_from_hex(hex), [&](std::span<const std::uint8_t> f) { out.push_back(to_hex(f)); });
  return out;
}

TEST(FrameSplitter, SplitsBackToBackTelegrams) {
  FrameSplitter s;
  EXPECT_EQ(split(s, "10 03 01 49 4D 16 E5 DC 05 01 68 05 05 68 8A 81 6D 3C 3E F2 16"),
            (std::vector<std::string>{"10 03 01 49 4D 16", "E5", "DC 05 01",
                                      "68 05 05 68 8A 81 6D 3C 3E F2 16"}));
  EXPECT_EQ(s.pending(), 0u);
  EXPECT_EQ(s.garbage(), 0u);
}

TEST(FrameSplitter, WaitsForTheRestAcrossFeeds) {
  FrameSplitter s;
  EXPECT_TRUE(split(s, "68 05").empty());
  EXPECT_TRUE(split(s, "05 68 8A 81").empty());
  EXPECT_EQ(s.pending(), 6u);
  EXPECT_EQ(split(s, "6D 3C 3E F2 16 10 03"), (std::vector<std::string>{"68 05 05 68 8A 81 6D 3C 3E F2 16"}));
  EXPECT_EQ(split(s, "01 49 4D 16"), (std::vector<std::string>{"10 03 01 49 4D 16"}));
  EXPECT_EQ(s.garbage(), 0u);
}

TEST(FrameSplitter, SkipsGarbageAndBadSd2Headers) {
  FrameSplitter s;
  // 3 garbage octets, then an SD2 header with LE != LEr (its 68 is dropped, the 05 06 are
  // garbage too, then "68 10 ..." is not a valid header either: 68 and then 10 starts an SD1).
  EXPECT_EQ(split(s, "FF 00 16 68 05 06 68 10 03 01 49 4D 16"),
            (std::vector<std::string>{"10 03 01 49 4D 16"}));
  EXPECT_EQ(s.garbage(), 7u);
  EXPECT_EQ(s.pending(), 0u);
}

TEST(FrameSplitter, DiscardPendingCountsAsGarbage) {
  FrameSplitter s;
  EXPECT_TRUE(split(s, "10 03 01").empty());
  s.discard_pending();
  EXPECT_EQ(s.garbage(), 3u);
  EXPECT_EQ(split(s, "E5"), (std::vector<std::string>{"E5"}));
}

TEST(FrameSplitter, ArbitraryBytesNeverCrashAndAreAllAccountedFor) {
  std::uint64_t x = 12345;
  FrameSplitter s;
  std::size_t framed = 0, fed = 0;
  for (int round = 0; round < 2000; ++round) {
    std::vector<std::uint8_t> chunk(static_cast<std::size_t>(x % 40));
    for (auto& b : chunk) {
      x = x * 6364136223846793005ULL + 1442695040888963407ULL;
      b = static_cast<std::uint8_t>(x >> 56);
    }
    fed += chunk.size();
    s.feed(chunk, [&](std::span<const std::uint8_t> f) {
      EXPECT_EQ(telegram_length(f), static_cast<int>(f.size()));
      framed += f.size();
    });
  }
  EXPECT_EQ(framed + s.garbage() + s.pending(), fed);
}

}  // namespace
}  // namespace pbvbus::bus
