#include "pbvbus/gateways/can_frame.hpp"

#include <gtest/gtest.h>

#include <vector>

namespace pbvbus::gateways {
namespace {

TEST(CanFrame, CandumpNotation) {
  CanFrame f{0x205, false, false, 2, {0xAA, 0xBB}};
  EXPECT_EQ(to_string(f), "205#AABB");
  CanFrame e{0x18FF0001, true, false, 3, {1, 2, 3}};
  EXPECT_EQ(to_string(e), "18FF0001#010203");
  CanFrame r{0x705, false, true, 1, {}};
  EXPECT_EQ(to_string(r), "705#R");
}

TEST(CanHub, EveryOtherPortHearsAFrameNeverTheSender) {
  CanHub hub;
  std::vector<std::pair<int, std::uint32_t>> got;
  auto a = hub.add_port("gateway", [&](const CanFrame& f, bus::Ticks) { got.push_back({0, f.id}); });
  auto b = hub.add_port("slcan", [&](const CanFrame& f, bus::Ticks) { got.push_back({1, f.id}); });
  auto c = hub.add_port("socketcand", [&](const CanFrame& f, bus::Ticks) { got.push_back({2, f.id}); });
  hub.send(a, CanFrame{0x185, false, false, 0, {}}, 0);
  hub.send(b, CanFrame{0x205, false, false, 0, {}}, 0);
  hub.remove_port(c);
  hub.send(a, CanFrame{0x705, false, false, 0, {}}, 0);
  const std::vector<std::pair<int, std::uint32_t>> want{
      {1, 0x185}, {2, 0x185}, {0, 0x205}, {2, 0x205}, {1, 0x705}};
  EXPECT_EQ(got, want);
  EXPECT_EQ(hub.frames(), 3u);
  EXPECT_EQ(hub.ports(), 2u);
}

}  // namespace
}  // namespace pbvbus::gateways
