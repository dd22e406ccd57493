// A seeded random walk over the Hot Standby pair's operations (power, CPU stop/start, keys,
// update button, fibre, override and the run bits, program loads), checking after every step
// the rules of hsby_pair.hpp that hold at all times: never two primaries while the heads can
// hear each other's line; a standby has a powered, running CPU and the other unit is not a
// standby; the heads follow the states (Active = Primary, Off = unpowered); every switchover
// within one scan; event times never go back; LEDs dark while unpowered. The walk must reach
// unplanned and planned switchovers, lost transfers and program updates.
#include <gtest/gtest.h>

#include <iostream>
#include <random>

#include "hsby_test_support.hpp"

namespace pbvbus::quantum {
namespace {

using namespace hsby_test;

void check(const Rig& g, int step) {
  const HsbyPair& p = g.pair;
  const FakeHead* heads[2] = {&g.h0, &g.h1};
  EXPECT_FALSE(p.state(0) == CpuState::Primary && p.state(1) == CpuState::Primary) << step;
  for (int r = 0; r < 2; ++r) {
    const CpuState s = p.state(r);
    EXPECT_EQ(s == CpuState::Off, !p.powered(r)) << step;
    if (s == CpuState::Standby) {
      EXPECT_TRUE(p.cpu_running(r)) << step;
      EXPECT_NE(p.state(1 - r), CpuState::Standby) << step;
    }
    if (s == CpuState::Primary) {
      EXPECT_TRUE(p.cpu_running(r)) << step;
    }
    const HeadRole want = !p.powered(r)            ? HeadRole::Off
                          : s == CpuState::Primary ? HeadRole::Active
                                                   : HeadRole::Passive;
    EXPECT_EQ(p.head_role(r), want) << step;
    EXPECT_EQ(heads[r]->role, want) << step;
    const ChsLeds l = p.leds(r);
    if (!p.powered(r)) {
      EXPECT_EQ(l, ChsLeds{}) << step;
    }
    EXPECT_EQ(l.primary == Led::On, s == CpuState::Primary) << step;
  }
  for (const auto& sw : p.switchovers()) {
    EXPECT_GE(sw.takeover_ticks, 0) << step;
    EXPECT_LE(sw.takeover_ticks, kScan) << step;
    EXPECT_NE(sw.old_rack, sw.new_rack) << step;
  }
  for (std::size_t i = 1; i < p.events().size(); ++i)
    EXPECT_LE(p.events()[i - 1].time, p.events()[i].time) << step;
}

struct WalkStats {
  int unplanned = 0, planned = 0, updates = 0;
  std::uint64_t lost = 0;
};

WalkStats walk(std::uint32_t seed, int steps) {
  Rig g;
  std::mt19937 rng(seed);
  auto pick = [&](int n) { return static_cast<int>(rng() % static_cast<unsigned>(n)); };
  bus::Ticks t = 0;
  g.pair.power_on(0);
  g.pair.power_on(1);
  const bool failed_before = ::testing::Test::HasFailure();
  for (int i = 0; i < steps; ++i) {
    t += static_cast<bus::Ticks>(pick(15'000)) * bus::kTicksPerUs;
    g.at(t);
    const int r = pick(2);
    switch (pick(17)) {
      case 0:
        g.pair.power_off(r);
        break;
      case 1:
      case 2:
        g.pair.power_on(r);
        break;
      case 3:
        g.pair.stop_cpu(r);
        break;
      case 4:
        g.pair.start_cpu(r);
        break;
      case 5:
        g.pair.set_key(r, KeySwitch::OffLine);
        break;
      case 6:
      case 7:
        g.pair.set_key(r, KeySwitch::Run);
        break;
      case 8:
        g.pair.set_key(r, KeySwitch::Xfer);
        break;
      case 9:
        g.pair.press_update(r);
        break;
      case 10:
        // The seed's whole update gesture (p. 21): button, Xfer, the mode wanted, release.
        g.pair.press_update(r);
        g.pair.set_key(r, KeySwitch::Xfer);
        g.pair.set_key(r, pick(4) == 0 ? KeySwitch::OffLine : KeySwitch::Run);
        g.pair.release_update(r);
        break;
      case 11:
        g.pair.set_fibre(pick(4) == 0 ? FibreState::Cut : FibreState::Ok);
        break;
      case 12:
        g.pair.set_keyswitch_override(pick(3) == 0);
        break;
      case 13:
        g.pair.ram(r).set_holding(0, static_cast<std::uint16_t>(pick(4) << 1));
        break;
      case 14:
        g.pair.load_program(r, static_cast<std::uint32_t>(pick(2)), count_scans);
        break;
      case 15:
        g.pair.set_standby_stays_on_logic_mismatch(pick(2) == 0);
        break;
      case 16:
        g.pair.release_update(r);
        break;
    }
    check(g, i);
    if (!failed_before && ::testing::Test::HasFailure()) break;  // one report, not thousands
  }
  WalkStats s;
  for (const auto& sw : g.pair.switchovers()) {
    const bool planned =
        sw.cause == SwitchoverCause::KeyOffLine || sw.cause == SwitchoverCause::CommandRegister;
    (planned ? s.planned : s.unplanned)++;
  }
  for (const auto& e : g.pair.events())
    if (e.kind == PairEventKind::Update && e.text.rfind("program update complete", 0) == 0)
      ++s.updates;
  s.lost = g.pair.transfers_lost();
  return s;
}

TEST(HsbyWalk, RulesHoldOverTenThousandRandomOperations) {
  for (std::uint32_t seed : {1u, 2u, 3u}) {
    const WalkStats s = walk(seed, 10'000);
    std::cout << "seed " << seed << ": " << s.unplanned << " unplanned, " << s.planned
              << " planned switchovers, " << s.lost << " transfers lost, " << s.updates
              << " program updates\n";
    EXPECT_GE(s.unplanned, 5) << seed;
    EXPECT_GE(s.planned, 5) << seed;
    EXPECT_GE(s.lost, 5u) << seed;
    EXPECT_GE(s.updates, 1) << seed;
  }
}

}  // namespace
}  // namespace pbvbus::quantum
