// The H-system fault campaign with the IM's own switchover time (seeds-digest §2 S5, 000 L1832;
// docs/h-campaign.md "With the IM's own switchover time"): every switchover of PBVB0A10 (T_SLAVE_UM
// 30 ms) and PBVB0A11 (820 ms) takes a drawn IM time in [T/2, T]; the observer checks each ends
// no earlier than its drawn time and within the planner's bound from its fault, and that the
// backplane outputs stay frozen meanwhile. Small runs only (CI budget); the >= 1 000-injection
// figures come from DISABLED_FiguresFromTheEnvironment (see its comment).
#include "pbvbus/s7h/h_campaign.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdlib>
#include <iostream>
#include <string>

namespace pbvbus::devices {
namespace {

constexpr bus::Ticks kMs = bus::kTicksPerMs;

HCampaignOptions base(std::uint64_t seed, int steps) {
  HCampaignOptions o;
  o.seed = seed;
  o.steps = steps;
  o.gsd_dir = std::string(PBVBUS_SOURCE_DIR) + "/examples/gsd";
  return o;
}

/// Only the kinds that make the switched stations switch over: a lost master CPU (F1), one
/// side's STOP, the active IM (F10), a short circuit (F14), a DP master module (F9), the
/// operator swap.
HCampaignOptions switching(std::uint64_t seed, int steps) {
  HCampaignOptions o = base(seed, steps);
  o.weights = {};
  for (HFault f : {HFault::MasterPower, HFault::MasterStop, HFault::ActiveIm, HFault::ShortCircuit,
                   HFault::DpMasterFailure, HFault::MasterSwap})
    o.weights[static_cast<int>(f)] = 1;
  return o;
}

void print(const HCampaignResult& r) {
  std::cout << r.summary() << "\n";
  for (std::size_t i = 0; i < r.mismatches.size() && i < 15; ++i)
    std::cout << "  mismatch: " << r.mismatches[i] << "\n";
  for (const auto& p : r.pulse_reports) std::cout << "  pulse: " << p << "\n";
}

// 40 switching injections: every switchover takes the IM's time, none early or late, outputs
// frozen through it (1 s Output_Hold_Time >= the slow IM's 820 ms), no pulse, no mismatch.
TEST(HCampaignIm, SwitchoversTakeTheImsTimeWithinTheBound) {
  const HCampaignResult r = run_h_campaign(switching(3, 40));
  print(r);
  EXPECT_EQ(r.pulses, 0u);
  for (const auto& m : r.mismatches) ADD_FAILURE() << m;
  EXPECT_EQ(r.late_switchovers, 0);
  EXPECT_EQ(r.early_switchovers, 0);
  EXPECT_GT(r.im_switchovers, 10u);
  EXPECT_GT(r.frozen_samples, 1000u);
  // Each way a switchover comes about took the IM's time: a stopped side / failed DP master
  // module, a short circuit, one interface.
  for (int n : r.im_by_cause) EXPECT_GT(n, 0);
  // PBVB0A11: T_SLAVE_UM = 82 x 10 ms = 820 ms (its GSD), drawn in [410, 820] ms; with 40
  // injections it switched at least once, so the longest draw is at least 410 ms.
  EXPECT_GE(r.max_im_drawn, 410 * kMs);
  EXPECT_LE(r.max_im_drawn, 820 * kMs);
  EXPECT_GE(r.max_im_switchover, 410 * kMs);
  // PRIMARY at max(trigger + drawn, the link steps: <= the 10 ms switch timeout).
  EXPECT_LE(r.max_im_switchover, 820 * kMs);
  EXPECT_EQ(r.observed_events, r.expected_events);
  // The default Output_Hold_Time (100 x 10 ms = 1 s) covers the planner's worst bound, which
  // holds the slow IM's 820 ms (and lies below the hold, else the run would have pulses).
  EXPECT_GT(r.worst_bound, 820 * kMs);
  EXPECT_LE(r.worst_bound, 1000 * kMs);
}

// Without the IM's time (im_time = false) no switchover records a draw (the link steps only).
TEST(HCampaignIm, WithoutTheImTimeNothingIsDrawn) {
  HCampaignOptions o = switching(3, 12);
  o.im_time = false;
  const HCampaignResult r = run_h_campaign(o);
  print(r);
  EXPECT_EQ(r.pulses, 0u);
  for (const auto& m : r.mismatches) ADD_FAILURE() << m;
  EXPECT_EQ(r.im_switchovers, 0u);
  EXPECT_EQ(r.max_im_drawn, 0);
}

// The observer can fail: an Output_Hold_Time of 200 ms (20 x 10 ms) is shorter than the slow
// IM's drawn time (>= 410 ms), so its outputs go to 0 at the hold's expiry during the
// switchover - caught as pulses. Only short circuits (each switches both stations).
TEST(HCampaignIm, ObserverCatchesAnOutputHoldShorterThanTheImTime) {
  HCampaignOptions o = base(3, 6);
  o.weights = {};
  o.weights[static_cast<int>(HFault::ShortCircuit)] = 1;
  o.output_hold_time = 20;
  const HCampaignResult r = run_h_campaign(o);
  print(r);
  EXPECT_GT(r.pulses, 0u);
}

// The observer can fail: its planner told T_SLAVE_UM = 0 (the IMs still draw from their GSDs'
// 30 / 820 ms), every switchover whose IM time exceeds the remaining bound (recognition +
// T_DP_UM + the 10 ms switch timeout) is late - the slow station's (>= 410 ms) always.
TEST(HCampaignIm, ObserverCatchesASwitchoverBeyondThePlannersBound) {
  HCampaignOptions o = base(3, 6);
  o.weights = {};
  o.weights[static_cast<int>(HFault::ShortCircuit)] = 1;
  o.tamper.planned_t_slave_um = 0;
  const HCampaignResult r = run_h_campaign(o);
  print(r);
  EXPECT_GT(r.late_switchovers, 0);
  EXPECT_EQ(r.early_switchovers, 0);
  EXPECT_TRUE(std::any_of(r.mismatches.begin(), r.mismatches.end(), [](const std::string& m) {
    return m.find("station 21 switchover") != std::string::npos &&
           m.find(" late: ") != std::string::npos;
  }));
}

// The documented figures (docs/h-campaign.md "With the IM's own switchover time"), not a CI
// test: build/bin/test_controllers_s7h --gtest_also_run_disabled_tests
//   --gtest_filter='HCampaignIm.DISABLED_*' with PBVBUS_HCAMPAIGN_SEED (default 1) and
// PBVBUS_HCAMPAIGN_STEPS (default 1000).
TEST(HCampaignIm, DISABLED_FiguresFromTheEnvironment) {
  std::uint64_t seed = 1;
  int steps = 1000;
  if (const char* e = std::getenv("PBVBUS_HCAMPAIGN_SEED")) seed = std::strtoull(e, nullptr, 10);
  if (const char* e = std::getenv("PBVBUS_HCAMPAIGN_STEPS")) steps = std::atoi(e);
  const HCampaignResult r = run_h_campaign(base(seed, steps));
  std::cout << "seed " << seed << ": injections " << r.injections() << ", virtual "
            << static_cast<double>(r.simulated) / bus::kTicksPerSecond << " s, IM switchovers "
            << r.im_switchovers << ", max IM " << static_cast<double>(r.max_im_switchover) / kMs
            << " ms, late " << r.late_switchovers << ", early " << r.early_switchovers
            << ", pulses " << r.pulses << ", mismatches " << r.mismatches.size() << "\n";
  print(r);
  EXPECT_EQ(r.pulses, 0u);
  EXPECT_TRUE(r.mismatches.empty());
}

}  // namespace
}  // namespace pbvbus::devices
