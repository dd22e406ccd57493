// Seeded mutation test of the GSD reader: thousands of damaged variants of the repository's GSD
// files (fixed-seed splitmix64, so every run sees the same inputs). The reader must never crash
// (this file also runs under ASan+UBSan), and every result is either a model or errors that each
// carry a line number within the file.

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "pbvbus/gsd/gsd.hpp"

using namespace pbvbus::devices;

namespace {

struct SplitMix64 {
  std::uint64_t state;
  std::uint64_t next() {
    std::uint64_t z = (state += 0x9E3779B97F4A7C15ULL);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ULL;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBULL;
    return z ^ (z >> 31);
  }
  std::size_t below(std::size_t n) { return n == 0 ? 0 : static_cast<std::size_t>(next() % n); }
};

std::string read(const std::string& rel) {
  std::ifstream in(std::string(PBVBUS_SOURCE_DIR) + "/" + rel, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

std::vector<std::string> split_lines(const std::string& s) {
  std::vector<std::string> out;
  std::size_t start = 0;
  for (std::size_t i = 0; i < s.size(); ++i)
    if (s[i] == '\n') {
      out.push_back(s.substr(start, i + 1 - start));
      start = i + 1;
    }
  if (start < s.size()) out.push_back(s.substr(start));
  return out;
}

std::string join(const std::vector<std::string>& v) {
  std::string s;
  for (const auto& l : v) s += l;
  return s;
}

// Fragments that hit the reader's corners: quotes, continuations, blocks, numbers at the limits.
const char* const kTokens[] = {
    "\"", "\\", ";", "=", "(", ")", ",", "-", "0x", "0X1FF", "#", "\r", "\n", "\\\n", " ",
    "EndModule", "Module = \"x\" ", "EndPrmText", "PrmText = 1\n", "ExtUserPrmData = 1 \"p\"\n",
    "EndExtUserPrmData", "Bit(9) 1 0-1", "BitArea(7-0) 0 0-3", "Signed32 -2147483648 -2147483648-2147483647",
    "Unsigned32 4294967295", "99999999999999999999", "-1", "0xC3", "0xFF,0xFF", "Ext_User_Prm_Data_Ref(236)=1",
    "Ext_User_Prm_Data_Const(236)=0xFF,0xFF,0xFF", "Unit_Diag_Area = 5-1", "SlotDefinition\n",
    "Slot(1) = \"s\" 1 9-1", "Data_Area_Beg\n", "#Profibus_DP\n", "User_Prm_Data_Len = 237",
    "Max_User_Prm_Data_Len = 0", "DPV1_Slave = 1", "Modular_Station = 0", "Max_Module = 0",
    "Station_Type = 1", "F_ExtUserPrmData = 1 \"f\"\n", "EndF_ExtUserPrmData",
    "F_Ext_Module_Prm_Data_Len = 10", "F_Ext_User_Prm_Data_Ref(9)=8", "Min_Slave_Interval = 1",
    "Max_Input_Len = 249", "\xDC", "\xEF\xBB\xBF",
    "",  // a NUL byte (mutate() inserts one for the empty token)
};

std::string mutate(std::string s, SplitMix64& rng) {
  const std::size_t n = 1 + rng.below(4);
  for (std::size_t k = 0; k < n; ++k) {
    switch (rng.below(8)) {
      case 0:  // flip a byte
        if (!s.empty()) s[rng.below(s.size())] = static_cast<char>(rng.next() & 0xFF);
        break;
      case 1: {  // delete a run
        if (s.empty()) break;
        const std::size_t at = rng.below(s.size());
        s.erase(at, 1 + rng.below(std::min<std::size_t>(40, s.size() - at)));
        break;
      }
      case 2: {  // insert a token
        const std::string tok = kTokens[rng.below(std::size(kTokens))];
        s.insert(rng.below(s.size() + 1), tok.empty() ? std::string(1, '\0') : tok);
        break;
      }
      case 3: {  // delete a line
        auto lines = split_lines(s);
        if (!lines.empty()) lines.erase(lines.begin() + static_cast<std::ptrdiff_t>(rng.below(lines.size())));
        s = join(lines);
        break;
      }
      case 4: {  // duplicate a line elsewhere
        auto lines = split_lines(s);
        if (lines.empty()) break;
        const std::string l = lines[rng.below(lines.size())];
        lines.insert(lines.begin() + static_cast<std::ptrdiff_t>(rng.below(lines.size() + 1)), l);
        s = join(lines);
        break;
      }
      case 5: {  // swap two lines
        auto lines = split_lines(s);
        if (lines.size() < 2) break;
        std::swap(lines[rng.below(lines.size())], lines[rng.below(lines.size())]);
        s = join(lines);
        break;
      }
      case 6: {  // change a digit
        std::vector<std::size_t> digits;
        for (std::size_t i = 0; i < s.size(); ++i)
          if (s[i] >= '0' && s[i] <= '9') digits.push_back(i);
        if (!digits.empty()) s[digits[rng.below(digits.size())]] = static_cast<char>('0' + rng.below(10));
        break;
      }
      default:  // truncate
        s.resize(rng.below(s.size() + 1));
        break;
    }
  }
  return s;
}

std::size_t count_lines(const std::string& s) {
  // Upper bound on line numbers: every \n and every \r may end a line.
  return 1 + static_cast<std::size_t>(std::count(s.begin(), s.end(), '\n') + std::count(s.begin(), s.end(), '\r'));
}

}  // namespace

TEST(GsdMutation, NeverCrashesAndAlwaysLocatesErrors) {
  const std::vector<std::string> seeds = {
      read("examples/gsd/PBVB0A01.gsd"), read("examples/gsd/PBVB0A02.gsd"),
      read("examples/gsd/PBVB0A03.gsd"), read("tests/data/gsd/VNDR4711.gsd"),
      read("tests/data/gsd/vendor-quirks/profisafe-module.gsd"), read("examples/gsd/PBVB0A10.gsd")};
  for (const auto& s : seeds) ASSERT_FALSE(s.empty());

  SplitMix64 rng{0x5EED'0000'0122ULL};
  std::size_t accepted = 0;
  std::size_t rejected = 0;
  constexpr std::size_t kVariants = 6000;
  for (std::size_t v = 0; v < kVariants; ++v) {
    const std::string input = mutate(seeds[v % seeds.size()], rng);
    const GsdParseResult r = parse_gsd(input, "m.gsd");
    const std::size_t lines = count_lines(input);
    if (r.ok()) {
      ++accepted;
      EXPECT_TRUE(r.errors.empty());
      const GsdFile& f = *r.file;
      // Every model operation works on whatever the reader accepted.
      std::vector<std::size_t> all(f.modules().size());
      for (std::size_t i = 0; i < all.size(); ++i) all[i] = i;
      auto p = f.user_prm_data(all);
      ASSERT_TRUE(p.ok());
      EXPECT_LE(p.value->size(), f.max_user_prm_data_len());
      auto c = f.cfg_data(all);
      ASSERT_TRUE(c.ok());
      (void)f.check_modules(all);
      (void)f.check_modules({rng.below(all.size() + 2)});
      for (const auto& m : f.modules()) ASSERT_TRUE(gsd_cfg_lengths(m.config).has_value());
    } else {
      ++rejected;
      ASSERT_FALSE(r.errors.empty()) << "variant " << v;
      for (const auto& e : r.errors) {
        if (e.line == 0) {
          EXPECT_EQ(e.reason, "#Profibus_DP section missing") << "variant " << v;
        } else {
          EXPECT_LE(e.line, lines) << "variant " << v << ": " << e.to_string();
        }
        EXPECT_FALSE(e.reason.empty());
      }
    }
    for (const auto& w : r.warnings) EXPECT_LE(w.line, lines) << "variant " << v;
  }
  // The mutations must exercise both outcomes, otherwise the test proves nothing.
  EXPECT_GT(accepted, kVariants / 20);
  EXPECT_GT(rejected, kVariants / 4);
}

TEST(GsdMutation, RandomBytesAfterTheSectionHeader) {
  SplitMix64 rng{42};
  for (int v = 0; v < 2000; ++v) {
    std::string s = "#Profibus_DP\n";
    const std::size_t n = rng.below(300);
    for (std::size_t i = 0; i < n; ++i) s += static_cast<char>(rng.next() & 0xFF);
    const GsdParseResult r = parse_gsd(s, "r.gsd");
    EXPECT_NE(r.ok(), !r.errors.empty());
    for (const auto& e : r.errors) EXPECT_GE(e.line, 1u) << e.to_string();
  }
}
