// I/O behaviour values (devices/io_behaviour.hpp) at given virtual times and DP cycle counts,
// and their big-endian encoding, checked against values worked out by hand.
#include <gtest/gtest.h>

#include <vector>

#include "hex.hpp"
#include "pbvbus/slaves/io_behaviour.hpp"

namespace pbvbus::devices {
namespace {

constexpr bus::Ticks kMs = bus::kTicksPerMs;

std::string encoded(std::int64_t v, std::size_t width) {
  std::vector<std::uint8_t> b(width);
  put_big_endian(v, b.begin(), width);
  return pbvbus::test::to_hex(b);
}

TEST(IoBehaviour, CounterEveryPeriodChangesExactlyAtThePeriodBoundary) {
  const auto c = IoBehaviour::counter_every(2 * kMs, 5, 10);
  EXPECT_EQ(behaviour_value(c, 0, 99), 10);  // the cycle count is irrelevant with a period
  EXPECT_EQ(behaviour_value(c, 2 * kMs - 1, 0), 10);
  EXPECT_EQ(behaviour_value(c, 2 * kMs, 0), 15);
  EXPECT_EQ(behaviour_value(c, 7 * kMs, 0), 25);
  EXPECT_EQ(encoded(behaviour_value(IoBehaviour::counter_every(kMs, 1, 0xFF), kMs, 0), 1), "00");  // wraps
}

TEST(IoBehaviour, CounterPerCycleCountsCycles) {
  const auto c = IoBehaviour::counter_per_cycle(2, 0xFFFE);
  EXPECT_EQ(encoded(behaviour_value(c, 123 * kMs, 0), 2), "FF FE");
  EXPECT_EQ(encoded(behaviour_value(c, 0, 1), 2), "00 00");
  EXPECT_EQ(encoded(behaviour_value(c, 0, 2), 4), "00 01 00 02");
}

TEST(IoBehaviour, RampIsASawtoothFromMinToMax) {
  const auto r = IoBehaviour::ramp(-27648, 27648, 10 * kMs);
  EXPECT_EQ(behaviour_value(r, 0, 0), -27648);
  EXPECT_EQ(behaviour_value(r, 5 * kMs, 0), 0);
  EXPECT_EQ(behaviour_value(r, 10 * kMs, 0), -27648);  // starts again
  EXPECT_EQ(behaviour_value(r, 12 * kMs + kMs / 2, 0), -27648 + 55296 / 4);
  EXPECT_EQ(encoded(-27648, 2), "94 00");
  EXPECT_EQ(encoded(27648, 2), "6C 00");
  // A long period at tick resolution does not overflow.
  const auto slow = IoBehaviour::ramp(0, 2'000'000'000, 3600 * bus::kTicksPerSecond);
  EXPECT_EQ(behaviour_value(slow, 1800 * bus::kTicksPerSecond, 0), 1'000'000'000);
}

TEST(IoBehaviour, TableHoldsTheLastRowAndRepeats) {
  const auto once = IoBehaviour::table({{kMs, 1}, {3 * kMs, 2}});
  EXPECT_EQ(behaviour_value(once, 0, 0), 1);  // before the first row: the first value
  EXPECT_EQ(behaviour_value(once, 3 * kMs - 1, 0), 1);
  EXPECT_EQ(behaviour_value(once, 3 * kMs, 0), 2);
  EXPECT_EQ(behaviour_value(once, 100 * kMs, 0), 2);
  const auto rep = IoBehaviour::table({{0, 7}, {3 * kMs, 8}}, true, 4 * kMs);
  EXPECT_EQ(behaviour_value(rep, 3 * kMs, 0), 8);
  EXPECT_EQ(behaviour_value(rep, 4 * kMs, 0), 7);
  EXPECT_EQ(behaviour_value(rep, 7 * kMs, 0), 8);
}

TEST(IoBehaviour, Checks) {
  EXPECT_EQ(check_behaviour(IoBehaviour::echo(2), 3), "");
  EXPECT_NE(check_behaviour(IoBehaviour::echo(3), 3), "");
  EXPECT_NE(check_behaviour(IoBehaviour::ramp(0, 1, 0), 1), "");
  EXPECT_NE(check_behaviour(IoBehaviour::table({{2, 1}, {1, 2}}), 1), "");
  EXPECT_NE(check_behaviour(IoBehaviour::counter_every(-1), 1), "");
}

}  // namespace
}  // namespace pbvbus::devices
