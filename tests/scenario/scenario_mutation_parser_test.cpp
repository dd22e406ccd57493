// Seeded mutation test of the scenario loader: damaged variants of the shipped scenarios (the
// examples and the built-in default), with fixed-seed splitmix64 so that every run sees the same
// inputs. The loader must never crash or abort (this file also runs under ASan+UBSan), and every
// error it reports carries FILE:LINE:COLUMN. The mutations favour what once aborted: module
// lists too long or wrong for the station kind, references by index past the end, repeated
// fields given where a single value is expected.
#include <gtest/gtest.h>

#include <cstdint>
#include <fstream>
#include <regex>
#include <sstream>
#include <string>
#include <vector>

#include "pbvbus/scenario/scenario.hpp"

namespace pbvbus::tools {
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

std::string read(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

std::vector<std::string> split_lines(const std::string& s) {
  std::vector<std::string> out;
  std::istringstream in(s);
  for (std::string l; std::getline(in, l);) out.push_back(l + "\n");
  return out;
}

// Fragments spliced into a line: values at and past the limits, module references, and whole
// fields that are known to be checked late (after the protobuf parse).
const char* const kTokens[] = {
    (" modules: [\"8DI DC24V\", \"8DI DC24V\", \"8DI DC24V\", \"8DI DC24V\", \"8DI DC24V\", "
     "\"8DI DC24V\", \"8DI DC24V\", \"8DI DC24V\", \"8DI DC24V\"] "),  // one token (nine modules)
    " modules: \"16DI/16DO DC24V\" ", " modules: \"16DI/16DO DC24V\" modules: \"8DI DC24V\" ",
    " modules: \"no such module\" ", " modules: [] ", " gsd: \"gsd/PBVB0A01.gsd\" ",
    " gsd: \"gsd/PBVB0A02.gsd\" ", " gsd: \"gsd/PBVB0A03.gsd\" ", " gsd: \"/nonexistent.gsd\" ",
    " gsd: \"\" ", " master: 99 ", " master: 127 ", " address: 126 ", " address: 127 ",
    " address: 4294967295 ", " module_index: 4294967295 ", " module_index: 9 ", " module: \"x\" ",
    " io { module_index: 12 constant { value: 1 } } ",
    " io { module: \"8DI DC24V\" offset: 300 width: 9 counter { } } ",
    " io { module_index: 0 echo { from_module_index: 40 } } ",
    " io { module_index: 0 table { repeat: true period: \"1ms\" row { at: \"2ms\" value: 1 } } } ",
    " io { module_index: 0 ramp { min: 5 max: -5 } } ", " tsdr_bits: 0 ", " tsdr_bits: 100000 ",
    " watchdog: \"off\" ", " watchdog: \"0ms\" ", " watchdog: \"700s\" ",
    " data_control_time: \"1ms\" ", " at: \"-1s\" ", " repair_at: \"0s\" ", " baud: \"7M\" ",
    " bus_params { tsl: 0 hsa: 200 ttr: 1 } ", " line: \"Z\" ", " between_a: 200 ",
    " channel: 64 error_type: 0 ", "}", "{", "\"", ":", "[", "]", "#", "\n", " 0x", " -1 ",
};

std::string mutate(const std::string& src, SplitMix64& rng) {
  auto lines = split_lines(src);
  if (lines.empty()) return src;
  const int n = 1 + static_cast<int>(rng.below(3));
  for (int k = 0; k < n; ++k) {
    std::string& l = lines[rng.below(lines.size())];
    switch (rng.below(6)) {
      case 0: {  // splice a token before the last '}' of the line, or at a random place
        const std::string tok = kTokens[rng.below(std::size(kTokens))];
        const auto brace = l.rfind('}');
        const std::size_t at = brace != std::string::npos && rng.below(2) ? brace : rng.below(l.size());
        l.insert(at, tok);
        break;
      }
      case 1: l.clear(); break;                                  // delete a line
      case 2: lines.push_back(lines[rng.below(lines.size())]); break;  // repeat a line at the end
      case 3:  // change a number
        for (char& c : l)
          if (c >= '0' && c <= '9' && rng.below(3) == 0) c = static_cast<char>('0' + rng.below(10));
        break;
      case 4:  // change a character
        if (!l.empty()) l[rng.below(l.size())] = static_cast<char>(32 + rng.below(95));
        break;
      default: std::swap(l, lines[rng.below(lines.size())]); break;
    }
  }
  std::string out;
  for (const auto& l : lines) out += l;
  return out;
}

TEST(ScenarioMutation, NeverAbortsAndEveryErrorIsLocated) {
  const std::string dir = PBVBUS_SOURCE_DIR "/examples/";
  struct Source {
    std::string file, text;
  };
  std::vector<Source> sources;
  sources.push_back({dir + "default.textproto", std::string(default_scenario_text())});
  for (const char* f : {"dp-basic.textproto", "dp-faults.textproto", "multimaster.textproto"})
    sources.push_back({dir + f, read(dir + f)});
  for (const auto& s : sources) ASSERT_FALSE(s.text.empty()) << s.file;

  SplitMix64 rng{0x5CE7A210};
  int refused = 0, accepted = 0;
  for (int i = 0; i < 1500; ++i) {
    const Source& s = sources[rng.below(sources.size())];
    const std::string text = mutate(s.text, rng);
    const LoadResult r = parse_scenario(text, s.file);
    ASSERT_EQ(r.ok(), r.errors.empty()) << "case " << i;
    if (r.ok()) {
      ++accepted;
      continue;
    }
    ++refused;
    const std::regex located("^" + std::regex_replace(s.file, std::regex(R"([.^$|()\[\]{}*+?\\])"),
                                                      R"(\$&)") +
                             R"(:[1-9][0-9]*:[1-9][0-9]*: .+)");
    for (const auto& e : r.errors)
      ASSERT_TRUE(std::regex_match(e.str(), located)) << "case " << i << ": " << e.str() << "\n"
                                                      << text;
  }
  // Both outcomes must occur, or the mutations test nothing.
  EXPECT_GT(refused, 300);
  EXPECT_GT(accepted, 50);
}

}  // namespace
}  // namespace pbvbus::tools
