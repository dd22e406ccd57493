// Every scenario file in examples/ loads without an error (the loader's checks, GSD files
// relative to the file): a new example that the loader refuses, or a loader change that breaks
// an example, fails here with the example's FILE:LINE:COLUMN messages.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <string>
#include <vector>

#include "pbvbus/scenario/scenario.hpp"

namespace pbvbus::tools {
namespace {

TEST(ExamplesLoad, EveryExampleLoads) {
  std::vector<std::string> files;
  for (const auto& e : std::filesystem::directory_iterator(PBVBUS_SOURCE_DIR "/examples"))
    if (e.is_regular_file() && e.path().extension() == ".textproto") files.push_back(e.path().string());
  ASSERT_FALSE(files.empty());
  for (const auto& f : files) {
    const LoadResult r = load_scenario_file(f);
    std::string why;
    for (const auto& d : r.errors) why += d.str() + "\n";
    EXPECT_TRUE(r.ok()) << why;
  }
  // The Quantum scan-time examples (timing-only files) are among them.
  EXPECT_NE(std::find(files.begin(), files.end(),
                      std::string(PBVBUS_SOURCE_DIR "/examples/quantum-scan-984.textproto")),
            files.end());
}

}  // namespace
}  // namespace pbvbus::tools
