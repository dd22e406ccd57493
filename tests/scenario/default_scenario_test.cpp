// The built-in default scenario is examples/h-system.textproto word for word, except that its
// GSD paths point into the source tree's examples/ folder (default_scenario.cpp): a change to
// one without the other fails here.
#include <gtest/gtest.h>

#include <fstream>
#include <sstream>
#include <string>

#include "pbvbus/scenario/scenario.hpp"

namespace pbvbus::tools {
namespace {

TEST(DefaultScenario, IsTheHSystemExample) {
  std::ifstream f(std::string(PBVBUS_SOURCE_DIR) + "/examples/h-system.textproto");
  ASSERT_TRUE(f) << "examples/h-system.textproto";
  std::stringstream ss;
  ss << f.rdbuf();
  std::string expected = ss.str();
  const std::string from = "gsd: \"gsd/";
  const std::string to = "gsd: \"" + std::string(PBVBUS_SOURCE_DIR) + "/examples/gsd/";
  int replaced = 0;
  for (std::size_t p = 0; (p = expected.find(from, p)) != std::string::npos; p += to.size()) {
    expected.replace(p, from.size(), to);
    ++replaced;
  }
  EXPECT_EQ(replaced, 4);  // two switched stations, one one-sided slave per line
  EXPECT_EQ(std::string(default_scenario_text()), expected);
}

}  // namespace
}  // namespace pbvbus::tools
