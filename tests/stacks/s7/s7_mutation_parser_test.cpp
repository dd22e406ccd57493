// Seeded mutations of the golden exchanges through every decoder, with the oracles the fuzz
// targets use (s7_oracle_helpers.hpp). Named *_parser_test so the ASan/UBSan builds run it.
#include <gtest/gtest.h>

#include <random>

#include "hex.hpp"
#include "s7_oracle_helpers.hpp"

namespace pbvbus::s7 {
namespace {

using test::hex;
using Bytes = std::vector<std::uint8_t>;

// S7 PDUs from tools-and-formats.md §3.4, protocol-facts.md §H.4 and the tests beside this one.
const std::vector<Bytes>& pdus() {
  static const std::vector<Bytes> all = {
      hex("32 01 00 00 00 00 00 08 00 00 F0 00 00 01 00 01 01 E0"),
      hex("32 03 00 00 00 00 00 08 00 00 00 00 F0 00 00 01 00 01 00 F0"),
      hex("32 01 00 00 00 01 00 0E 00 00 04 01 12 0A 10 02 00 04 00 01 84 00 00 00"),
      hex("32 03 00 00 00 01 00 02 00 08 00 00 04 01 FF 04 00 20 DE AD BE EF"),
      hex("32 03 00 00 00 09 00 02 00 18 00 00 04 05 FF 03 00 01 01 00 FF 04 00 08 5A 00 0A 00 00 "
          "00"
          "05 00 00 00 06 00 00 00"),
      hex("32 01 00 00 00 04 00 1A 00 0B 05 02 12 0A 10 01 00 01 00 00 83 00 00 01 12 0A 10 02 00 "
          "01"
          "00 00 83 00 00 08 00 03 00 01 01 00 00 04 00 08 7F"),
      hex("32 03 00 00 00 04 00 02 00 02 00 00 05 02 FF 05"),
      hex("32 07 00 00 00 05 00 08 00 08 00 01 12 04 11 44 01 00 FF 09 00 04 00 11 00 00"),
      hex("32 07 00 00 00 05 00 0C 00 14 00 01 12 08 12 84 01 03 00 00 00 00 FF 09 00 10 00 11 00 "
          "00"
          "00 04 00 02 AA BB CC DD 11 22 33 44"),
      hex("32 07 00 00 00 06 00 0C 00 04 00 01 12 08 12 84 01 00 00 00 D4 02 0A 00 00 00"),
  };
  return all;
}

// A client's stream and a server's answers as TPKTs, with the chunking octet in front.
const std::vector<Bytes>& streams() {
  static const std::vector<Bytes> all = {
      hex("03 | 03 00 00 16 11 E0 00 00 00 01 00 C0 01 0A C1 02 01 00 C2 02 01 02"
          "03 00 00 19 02 F0 80 32 01 00 00 00 00 00 08 00 00 F0 00 00 01 00 01 01 E0"),
      hex("15 | 03 00 00 16 11 D0 00 01 00 01 00 C0 01 0A C1 02 01 00 C2 02 01 02"
          "03 00 00 1D 02 F0 80 32 03 00 00 00 01 00 02 00 08 00 00 04 01 FF 04 00 20 DE AD BE EF"),
      hex("00 | 03 00 00 16 11 E0 00 00 00 01 00 C1 02 01 00 C2 02 01 02 C0 01 09"
          "03 00 00 0B 06 80 00 01 00 02 03 03 00 00 0A 05 C0 00 02 00 01"
          "03 00 00 0E 09 70 00 01 02 C1 03 02 F7 80"),
  };
  return all;
}

Bytes mutate(const Bytes& in, std::mt19937& rng) {
  Bytes b = in;
  const int edits = 1 + static_cast<int>(rng() % 4);
  for (int e = 0; e < edits; ++e) {
    switch (rng() % 5) {
      case 0:
        if (!b.empty()) b[rng() % b.size()] = static_cast<std::uint8_t>(rng());
        break;
      case 1:
        if (!b.empty()) b[rng() % b.size()] ^= static_cast<std::uint8_t>(1u << (rng() % 8));
        break;
      case 2:
        if (!b.empty()) b.erase(b.begin() + static_cast<std::ptrdiff_t>(rng() % b.size()));
        break;
      case 3:
        b.insert(b.begin() + static_cast<std::ptrdiff_t>(rng() % (b.size() + 1)),
                 static_cast<std::uint8_t>(rng()));
        break;
      default:
        b.resize(rng() % (b.size() + 1));
        break;
    }
  }
  return b;
}

TEST(S7Mutation, GoldenInputsSatisfyTheOracles) {
  for (const auto& p : pdus()) EXPECT_EQ(test::s7_pdu_oracle(p), nullptr);
  for (const auto& s : streams()) EXPECT_EQ(test::iso_transport_oracle(s), nullptr);
}

TEST(S7Mutation, MutatedPdusNeverBreakAnOracle) {
  std::mt19937 rng(0x32);
  for (int round = 0; round < 20000; ++round) {
    const auto& seed = pdus()[rng() % pdus().size()];
    const Bytes m = mutate(seed, rng);
    const char* why = test::s7_pdu_oracle(m);
    ASSERT_EQ(why, nullptr) << why << " in round " << round;
  }
}

TEST(S7Mutation, MutatedStreamsNeverBreakAnOracle) {
  std::mt19937 rng(1006);
  for (int round = 0; round < 20000; ++round) {
    const auto& seed = streams()[rng() % streams().size()];
    const Bytes m = mutate(seed, rng);
    const char* why = test::iso_transport_oracle(m);
    ASSERT_EQ(why, nullptr) << why << " in round " << round;
  }
}

}  // namespace
}  // namespace pbvbus::s7
