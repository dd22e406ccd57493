// Seeded mutation test of the FDL telegram codec: the libFuzzer target's oracle
// (telegram_oracle_helpers.hpp) over ~200 000 inputs derived from the Appendix 1 frames, with a
// fixed-seed splitmix64 generator so that every run checks the same inputs, under gcc and under
// ASan+UBSan. Mutations: bit flips, truncations, insertions, deletions, LE/LEr changes, body
// changes with the FCS fixed up (so that decoding gets past the FCS into the address, FC and
// extension checks), splices of two frames, and random bytes.
#include <gtest/gtest.h>

#include <array>
#include <map>
#include <vector>

#include "hex.hpp"
#include "pbvbus/fdl/telegram.hpp"
#include "telegram_golden.hpp"
#include "telegram_oracle_helpers.hpp"

namespace pbvbus::fdl {
namespace {

using Bytes = std::vector<std::uint8_t>;

class SplitMix64 {
 public:
  explicit SplitMix64(std::uint64_t seed) : m_state(seed) {}
  std::uint64_t next() {
    std::uint64_t z = (m_state += 0x9E3779B97F4A7C15ull);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return z ^ (z >> 31);
  }
  /// Uniform enough in [0, n) for a test (n small).
  std::size_t below(std::size_t n) { return n == 0 ? 0 : static_cast<std::size_t>(next() % n); }
  std::uint8_t octet() { return static_cast<std::uint8_t>(next() & 0xFF); }

 private:
  std::uint64_t m_state;
};

TEST(SplitMix64, KnownSequence) {
  // Reference values of splitmix64 for seed 0 (Vigna's reference implementation).
  SplitMix64 r(0);
  EXPECT_EQ(r.next(), 0xE220A8397B1DCDAFull);
  EXPECT_EQ(r.next(), 0x6E789E6AA1B965F4ull);
  EXPECT_EQ(r.next(), 0x06C45D188009454Full);
}

// Where the FCS-covered octets of a frame start, and how many there are; {0, 0} if none.
std::pair<std::size_t, std::size_t> checked_range(const Bytes& f) {
  if (f.size() < 2) return {0, 0};
  if (f[0] == kSD2 && f.size() >= 6) return {4, f.size() - 6};
  if ((f[0] == kSD1 || f[0] == kSD3) && f.size() >= 3) return {1, f.size() - 3};
  return {0, 0};
}
void fix_fcs(Bytes& f) {
  const auto [first, n] = checked_range(f);
  if (n == 0) return;
  unsigned s = 0;
  for (std::size_t i = first; i < first + n; ++i) s += f[i];
  f[first + n] = static_cast<std::uint8_t>(s & 0xFF);
}

Bytes mutate(const Bytes& seed, const std::vector<Bytes>& seeds, SplitMix64& r) {
  Bytes m = seed;
  switch (r.below(10)) {
    case 0: {  // 1..3 bit flips
      const std::size_t n = 1 + r.below(3);
      for (std::size_t k = 0; k < n && !m.empty(); ++k)
        m[r.below(m.size())] ^= static_cast<std::uint8_t>(1u << r.below(8));
      break;
    }
    case 1:  // truncation
      m.resize(r.below(m.size() + 1));
      break;
    case 2: {  // insert 1..4 random octets
      const std::size_t n = 1 + r.below(4);
      for (std::size_t k = 0; k < n; ++k)
        m.insert(m.begin() + static_cast<std::ptrdiff_t>(r.below(m.size() + 1)), r.octet());
      if (r.below(2)) fix_fcs(m);
      break;
    }
    case 3:  // delete one octet
      if (!m.empty()) m.erase(m.begin() + static_cast<std::ptrdiff_t>(r.below(m.size())));
      if (r.below(2)) fix_fcs(m);
      break;
    case 4:  // LE / LEr changes (SD2), consistent or not, FCS fixed half of the time
      if (m.size() >= 3) {
        const auto le = static_cast<std::uint8_t>(r.below(3) == 0 ? r.octet()
                                                                  : m[1] + r.below(5) - 2);
        m[1] = le;
        m[2] = r.below(4) == 0 ? r.octet() : le;
        if (r.below(2)) m.resize(std::size_t{le} + 6, r.octet());
        if (r.below(2)) fix_fcs(m);
      }
      break;
    case 5:
    case 6: {  // change address, FC or extension octets (or any body octet), then fix the FCS
      const auto [first, n] = checked_range(m);
      if (n == 0) {
        if (!m.empty()) m[r.below(m.size())] = r.octet();
        break;
      }
      const std::size_t k = 1 + r.below(3);
      for (std::size_t j = 0; j < k; ++j) {
        const std::size_t i = first + (r.below(2) ? r.below(std::min<std::size_t>(n, 6)) : r.below(n));
        switch (r.below(4)) {
          case 0: m[i] = r.octet(); break;
          case 1: m[i] ^= 0x80; break;  // toggle EXT
          case 2: m[i] ^= 0x40; break;  // toggle segment bit / request bit
          default: m[i] = static_cast<std::uint8_t>(m[i] + 1);
        }
      }
      fix_fcs(m);
      break;
    }
    case 7: {  // change the start delimiter to another one
      static constexpr std::uint8_t kDelims[] = {kSD1, kSD2, kSD3, kSD4, kSC, kED};
      if (!m.empty()) m[0] = kDelims[r.below(std::size(kDelims))];
      if (r.below(2)) fix_fcs(m);
      break;
    }
    case 8: {  // splice: a prefix of this frame and a suffix of another
      const Bytes& other = seeds[r.below(seeds.size())];
      m.resize(r.below(m.size() + 1));
      const std::size_t from = r.below(other.size() + 1);
      m.insert(m.end(), other.begin() + static_cast<std::ptrdiff_t>(from), other.end());
      if (r.below(2)) fix_fcs(m);
      break;
    }
    default: {  // random bytes behind a random delimiter, sometimes a well-formed SD2 shell
      m.assign(r.below(kMaxFrame + 4), 0);
      for (auto& b : m) b = r.octet();
      if (r.below(2) && m.size() >= 6) {
        const std::size_t le = m.size() - 6;
        m[0] = m[3] = kSD2;
        m[1] = m[2] = static_cast<std::uint8_t>(le);
        m.back() = kED;
        fix_fcs(m);
      }
    }
  }
  return m;
}

TEST(TelegramMutation, OracleHoldsForTwoHundredThousandMutants) {
  std::vector<Bytes> seeds;
  for (const auto& g : test::kGoldenFrames) seeds.push_back(test::bytes_from_hex(g.hex));
  SplitMix64 r(0x50524F4649425553ull);  // "PROFIBUS"
  constexpr std::size_t kInputs = 200'000;
  std::map<DecodeError, std::size_t> outcomes;
  std::array<std::size_t, 5> accepted_by_type{};
  std::size_t failures = 0;
  for (std::size_t i = 0; i < kInputs; ++i) {
    const Bytes& seed = seeds[r.below(seeds.size())];
    Bytes m = mutate(seed, seeds, r);
    // Stack mutations now and then, so that some inputs are far from any seed.
    if (r.below(4) == 0) m = mutate(m, seeds, r);
    if (const char* why = test::decode_oracle(m)) {
      if (++failures <= 10) ADD_FAILURE() << why << ": " << test::to_hex(m);
    }
    Telegram t;
    const DecodeError e = decode(m, t);
    ++outcomes[e];
    if (e == DecodeError::None) ++accepted_by_type[static_cast<std::size_t>(t.type)];
    // The same bytes as an encoder input (layout in telegram_oracle_helpers.cpp).
    if (const char* why = test::encode_oracle(m)) {
      if (++failures <= 10) ADD_FAILURE() << "encode: " << why << ": " << test::to_hex(m);
    }
  }
  EXPECT_EQ(failures, 0u);
  // The test is only worth something if the mutants reach every check of the decoder and a good
  // share of them decode.
  for (unsigned v = 0; v <= static_cast<unsigned>(DecodeError::BroadcastNotSdn); ++v)
    EXPECT_GT(outcomes[static_cast<DecodeError>(v)], 0u)
        << "no mutant ended in " << to_string(static_cast<DecodeError>(v));
  EXPECT_GT(outcomes[DecodeError::None], kInputs / 20);

  for (std::size_t k = 0; k < accepted_by_type.size(); ++k)
    EXPECT_GT(accepted_by_type[k], 0u) << to_string(static_cast<FrameType>(k));
}

TEST(TelegramMutation, EncoderOracleOverRandomSpecs) {
  // Random FrameSpecs through encode()/encode_as(): whatever is encoded must decode to the same
  // fields with the §B.1 frame type. Inputs are biased towards valid FCs and small addresses.
  SplitMix64 r(42);
  std::size_t encoded = 0, failures = 0;
  for (std::size_t i = 0; i < 50'000; ++i) {
    Bytes in(8 + r.below(260));
    for (auto& b : in) b = r.octet();
    if (r.below(2)) in[0] &= 0x7F;
    if (r.below(2)) in[1] &= 0x7F;
    if (r.below(2)) in[3] &= 0x3F;  // encode()/encode_as() without the SD4/SC branch
    if (r.below(2)) in[4] &= 0x3F, in[5] &= 0x3F, in[6] &= 0x3F, in[7] &= 0x3F;
    if (r.below(3) == 0) in.resize(8 + r.below(12));  // near the SD1/SD3/SD2 boundaries
    if (const char* why = test::encode_oracle(in)) {
      if (++failures <= 10) ADD_FAILURE() << why << ": " << test::to_hex(in);
    }
    // Count successes with the same spec to make sure the oracle is not vacuous.
    FrameSpec s{};
    s.da = in[0];
    s.sa = in[1];
    s.fc = in[2];
    if (in[3] & 1) s.dsap = in[4];
    if (in[3] & 2) s.ssap = in[5];
    if (in[3] & 4) s.da_segment = in[6];
    if (in[3] & 8) s.sa_segment = in[7];
    s.data = std::span(in).subspan(8);
    Frame f;
    if (encode(s, f) == EncodeError::None) ++encoded;
  }
  EXPECT_EQ(failures, 0u);
  EXPECT_GT(encoded, 2000u);
}

}  // namespace
}  // namespace pbvbus::fdl
