// The fake itself: the module offsets and the side swap that the gateway tests rely on.
#include "fake_source.hpp"

#include <gtest/gtest.h>

namespace pbvbus::gateways::test {
namespace {

TEST(FakeSource, OffsetsInSlotOrderAndSideSwap) {
  FakeSource src;
  src.set_redundant(true);
  auto& s = src.add_slave(4, 0x0A02, {{"8DI", 0, 1, 0, 0, false}, {"8DO", 0, 0, 0, 1, false},
                                      {"2AO", 0, 0, 0, 4, true}});
  EXPECT_EQ(s.input_len, 1u);
  EXPECT_EQ(s.output_len, 5u);
  EXPECT_EQ(s.modules[2].out_offset, 1u);
  src.data(4, Side::Standby).status.state = dp::SlaveStatusState::NotPresent;
  src.swap_sides(4);
  EXPECT_EQ(src.status(4, Side::Primary)->state, dp::SlaveStatusState::NotPresent);
  EXPECT_EQ(src.status(4, Side::Primary)->side_line, 1);
  const std::uint8_t v[4] = {1, 2, 3, 4};
  EXPECT_TRUE(src.write_module_outputs(4, 2, v));
  EXPECT_FALSE(src.write_module_outputs(4, 2, std::span(v, 3)));
  EXPECT_EQ(src.writes().size(), 1u);
}

}  // namespace
}  // namespace pbvbus::gateways::test
