// The serial attachment splits a byte stream into telegrams with bus::telegram_length, a copy
// of the FDL length rule kept in the bus layer (which must not depend on fdl). Here both rules
// are held against each other: for every prefix of every golden frame, for every header an
// SD2 can have, and for random byte strings, they must give the same answer.

#include <gtest/gtest.h>

#include <cstdint>
#include <vector>

#include "hex.hpp"
#include "pbvbus/bus/frame_splitter.hpp"
#include "pbvbus/fdl/telegram.hpp"

namespace {

using pbvbus::bus::telegram_length;
using pbvbus::fdl::frame_length;

void expect_same(const std::vector<std::uint8_t>& b) {
  for (std::size_t n = 0; n <= b.size(); ++n) {
    std::span<const std::uint8_t> head(b.data(), n);
    ASSERT_EQ(telegram_length(head), frame_length(head))
        << "prefix of " << n << " octets of " << pbvbus::test::to_hex(b);
  }
}

TEST(FrameLengthAgreement, GoldenFramesAndEveryPrefix) {
  // protocol-facts.md Appendix 1.
  for (const char* h : {"10 03 01 49 4D 16", "10 01 03 00 04 16", "DC 05 02", "E5",
                        "68 05 05 68 8A 81 6D 3C 3E F2 16",
                        "A2 81 8A 08 3E 3C 02 05 00 FF 12 34 D9 16",
                        "68 0C 0C 68 8A 81 5D 3D 3E 88 0A 0A 0B 12 34 00 D0 16",
                        "68 07 07 68 FF 81 46 3A 3E 02 00 40 16",
                        "A2 0A 01 7D 01 02 03 04 05 06 07 08 AC 16"}) {
    expect_same(pbvbus::test::bytes_from_hex(h));
  }
}

TEST(FrameLengthAgreement, EverySd2HeaderUpToFourOctets) {
  // 68 LE LEr 68: both rules must agree on every LE/LEr pair and second delimiter.
  for (unsigned le = 0; le < 256; ++le) {
    for (unsigned ler : {le, (le + 1) & 0xFFu, 0u, 255u}) {
      for (unsigned sd : {0x68u, 0x69u, 0x10u}) {
        expect_same({0x68, static_cast<std::uint8_t>(le), static_cast<std::uint8_t>(ler),
                     static_cast<std::uint8_t>(sd)});
      }
    }
  }
}

TEST(FrameLengthAgreement, RandomBytes) {
  std::uint64_t x = 0x5EED;
  auto next = [&x] {
    // splitmix64: fixed seed, the same on every platform.
    std::uint64_t z = (x += 0x9E3779B97F4A7C15ULL);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ULL;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBULL;
    return z ^ (z >> 31);
  };
  const std::uint8_t starts[] = {0x10, 0x68, 0xA2, 0xDC, 0xE5, 0x16, 0x00};
  for (int i = 0; i < 20000; ++i) {
    std::vector<std::uint8_t> b(1 + next() % 8);
    for (auto& o : b) o = static_cast<std::uint8_t>(next());
    if (next() % 2) b[0] = starts[next() % 7];
    expect_same(b);
  }
}

}  // namespace
