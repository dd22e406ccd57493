// The seeded H-system fault campaign (devices/h_campaign.hpp), reduced for CI: seed 7, 150
// injections, and seed 7 with 1 000 injections over all 24 fault kinds (CPU power/STOP of
// master and standby, one fibre, both fibres, active/passive IM, short circuit, DP master
// module, comparison error, one-sided OB 121, operator master swap, and the link-up/update
// faults: master HOLD, load-memory error, sync error, update timeout, standby lost in LINK-UP,
// structural change, swap with a changed parameter) on two lines at 1.5 Mbit/s with the CPU
// pair, two switched stations and one one-sided slave per line. Invariants only (the seed's
// figures are in docs/h-campaign.md): 0 output pulses, 0 mismatches between the events the
// observer derives and HSystemModel::events(), never two masters driving the switched outputs
// outside F6, every kind drawn. The observer's own tests: a fault it is not told about, a
// doctored event list, a program writing 0 once and a second master outside F6 must each be
// caught (an update timeout it is not told about: h_campaign_link_test.cpp). The full
// campaign is bench/h_campaign_bench.cpp.
#include "pbvbus/s7h/h_campaign.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <iostream>
#include <stdexcept>
#include <string>

namespace pbvbus::devices {
namespace {

HCampaignOptions reduced(std::uint64_t seed, int steps) {
  HCampaignOptions o;
  o.seed = seed;
  o.steps = steps;
  o.gsd_dir = std::string(PBVBUS_SOURCE_DIR) + "/examples/gsd";
  return o;
}

void print(const HCampaignResult& r) {
  std::cout << r.summary() << "\n";
  for (std::size_t i = 0; i < r.mismatches.size() && i < 15; ++i)
    std::cout << "  mismatch: " << r.mismatches[i] << "\n";
  for (const auto& p : r.pulse_reports) std::cout << "  pulse: " << p << "\n";
}

bool has(const HCampaignResult& r, const char* a, const char* b = "") {
  return std::any_of(r.mismatches.begin(), r.mismatches.end(), [&](const std::string& m) {
    return m.find(a) != std::string::npos && m.find(b) != std::string::npos;
  });
}

TEST(HCampaign, ReducedCampaignHasNoPulseAndNoMismatch) {
  const HCampaignResult r = run_h_campaign(reduced(7, 150));
  print(r);
  EXPECT_GE(r.injections(), 150);
  EXPECT_EQ(r.pulses, 0u);
  for (const auto& m : r.mismatches) ADD_FAILURE() << m;
  EXPECT_EQ(r.second_master_frames, 0u);
  EXPECT_EQ(r.stray_dx, 0u);
  EXPECT_GT(r.dx_requests, 10000u);
  EXPECT_GT(r.output_samples, 100000u);
  // Every event was one the observer expected (the multiset matched, so the counts agree).
  EXPECT_EQ(r.observed_events, r.expected_events);
  EXPECT_GT(r.ob72, 0);
}

// >= 1 000 injections: every one of the 24 kinds is drawn, nothing goes wrong, and the counts
// that follow from the draws agree (invariants, not the seed's figures).
TEST(HCampaign, ThousandInjectionsDrawEveryKindWithoutPulseOrMismatch) {
  HCampaignOptions o = reduced(7, 1000);
  o.update_timeout_failures_max = 1;  // 62 s of virtual time per F19 cycle is enough here
  const HCampaignResult r = run_h_campaign(o);
  print(r);
  EXPECT_GE(r.injections(), 1000);
  EXPECT_EQ(r.pulses, 0u);
  for (const auto& m : r.mismatches) ADD_FAILURE() << m;
  for (int k = 0; k < kHFaultKinds; ++k)
    EXPECT_GE(r.drawn[k], 1) << to_string(static_cast<HFault>(k));
  EXPECT_EQ(r.second_master_frames, 0u);
  EXPECT_EQ(r.stray_dx, 0u);
  EXPECT_GT(r.split_frames, 0u);  // F6 was seen on the wire's time line, and allowed
  EXPECT_EQ(r.observed_events, r.expected_events);
  for (int c : {0x73A3, 0x72A3, 0x39C4, 0x38C4, 0x39C3, 0x38C3})
    EXPECT_GT(r.events_with(static_cast<std::uint16_t>(c)), 0) << std::hex << c;
  EXPECT_GT(r.ob121, 0);
  EXPECT_GT(r.defective, 0);
  EXPECT_GT(r.comparison_stops, 0);
  // One failing update per F19 cycle (failures_max 1).
  EXPECT_EQ(r.update_timeouts, r.drawn[static_cast<int>(HFault::UpdateTimeout)]);
  // Refusals checked: 2 per HOLD cycle (HOLD in Redundant, RUN in HOLD), 1 per F2, F23 and
  // F5's second fibre (RUN with the reset request).
  EXPECT_EQ(r.refusals, 2 * r.drawn[static_cast<int>(HFault::MasterHold)] +
                            r.drawn[static_cast<int>(HFault::LoadMemoryError)] +
                            r.drawn[static_cast<int>(HFault::ParameterChangeSwap)] +
                            r.drawn[static_cast<int>(HFault::SecondFibre)]);
  // Diagnostic entries: HOLD 1, F18 2, F20 1 (6523), F23 2 (5966 on both); the later kinds: PS
  // half 2 (3923, 3823), checksum 1, second fibre 3 (both CPUs' entries, the refused RUN),
  // SFC 90 6 (MODE 3, the wait, MODE 4 on both CPUs).
  EXPECT_EQ(r.diag_checks, r.drawn[static_cast<int>(HFault::MasterHold)] +
                               2 * r.drawn[static_cast<int>(HFault::SyncError)] +
                               r.drawn[static_cast<int>(HFault::StandbyLostDuringLinkUp)] +
                               2 * r.drawn[static_cast<int>(HFault::ParameterChangeSwap)] +
                               2 * r.drawn[static_cast<int>(HFault::PsHalf)] +
                               r.drawn[static_cast<int>(HFault::ChecksumError)] +
                               3 * r.drawn[static_cast<int>(HFault::SecondFibre)] +
                               6 * r.drawn[static_cast<int>(HFault::UpdateBlocked)]);
}

// Only comparison errors (seed 5, 10 injections): each cycle without a repeat settles at
// self_test_time + link_up_time + update = 2000 + 2000 + (75 + 0.7 x 100) = 4145 ms after the
// fault (the campaign polls every 5 ms from the fault; 4145 = 829 x 5). A repeat's STOP branch
// settles link-up + update = 2145 ms after its RUN.
TEST(HCampaign, ComparisonErrorsSettleAfterSearchLinkUpAndUpdate) {
  HCampaignOptions o = reduced(5, 10);
  o.weights = {};
  o.weights[static_cast<int>(HFault::ComparisonError)] = 1;
  const HCampaignResult r = run_h_campaign(o);
  print(r);
  for (const auto& m : r.mismatches) ADD_FAILURE() << m;
  EXPECT_EQ(r.pulses, 0u);
  EXPECT_EQ(r.max_settle, 4145 * bus::kTicksPerMs);
  EXPECT_EQ(r.drawn[static_cast<int>(HFault::ComparisonError)],
            r.injections() - r.comparison_stops);
  // Each cycle: OB 72 ComparisonError; without a repeat also OB 72 MasterSwap on both CPUs.
  const int cycles = r.drawn[static_cast<int>(HFault::ComparisonError)];
  EXPECT_EQ(r.ob72, cycles + 2 * (cycles - r.comparison_stops));
  EXPECT_EQ(r.events_with(0x39C3), cycles);
  EXPECT_EQ(r.events_with(0x38C3), cycles);
}

// Unusable options are refused with a clear error, nothing runs.
TEST(HCampaign, BadOptionsAreRefused) {
  HCampaignOptions o = reduced(1, 10);
  o.weights = {};
  EXPECT_THROW(run_h_campaign(o), std::invalid_argument);
  o = reduced(1, 10);
  o.weights[3] = -1;
  EXPECT_THROW(run_h_campaign(o), std::invalid_argument);
  o = reduced(1, 10);
  o.fault_min = o.fault_max + 1;
  EXPECT_THROW(run_h_campaign(o), std::invalid_argument);
  o = reduced(1, 10);
  o.gsd_dir = "/nonexistent";
  EXPECT_THROW(run_h_campaign(o), std::runtime_error);
  o = reduced(1, 10);
  o.baud = bus::Baud::k12M;  // PBVB0A11 has no 12M_supp
  EXPECT_THROW(run_h_campaign(o), std::runtime_error);
}

// The standby CPU off and on again without telling the observer: its OB 72 and the 39C3 /
// 38C3 of its side are unexpected.
TEST(HCampaign, ObserverCatchesAFaultItWasNotToldAbout) {
  HCampaignOptions o = reduced(11, 6);
  o.tamper.hidden_fault_at = 1;
  const HCampaignResult r = run_h_campaign(o);
  print(r);
  EXPECT_TRUE(has(r, "hidden fault", "unexpected [OB 72 standby CPU lost"));
  EXPECT_TRUE(has(r, "hidden fault", "unexpected [OB 86 39C3"));
  EXPECT_TRUE(has(r, "hidden repair", "unexpected [OB 86 38C3"));
}

// One OB 72 dropped from the event list: missing.
TEST(HCampaign, ObserverCatchesADoctoredEventList) {
  HCampaignOptions o = reduced(11, 6);
  o.tamper.doctor_events = [](std::vector<HSystemEvent>& ev) {
    auto it = std::find_if(ev.begin(), ev.end(), [](const HSystemEvent& e) { return e.ob == 72; });
    if (it != ev.end()) ev.erase(it);
  };
  const HCampaignResult r = run_h_campaign(o);
  print(r);
  EXPECT_TRUE(has(r, "missing [OB 72"));
}

// The program writes 0 once (at 6 s, in Redundant mode): a pulse on both switched stations.
TEST(HCampaign, ObserverCatchesAProgramGlitchWritingZero) {
  HCampaignOptions o = reduced(11, 4);
  o.tamper.zero_output_at = 6000 * bus::kTicksPerMs;
  const HCampaignResult r = run_h_campaign(o);
  print(r);
  EXPECT_GE(r.pulses, 2u);
  ASSERT_FALSE(r.pulse_reports.empty());
  EXPECT_NE(r.pulse_reports[0].find("outputs 0"), std::string::npos);
}

// Both fibres cut while the observer is told one fibre: two masters drive outside F6.
TEST(HCampaign, ObserverCatchesASecondMasterOutsideF6) {
  HCampaignOptions o = reduced(11, 6);
  o.tamper.second_master_at = 1;
  const HCampaignResult r = run_h_campaign(o);
  print(r);
  EXPECT_GT(r.second_master_frames, 0u);
  EXPECT_TRUE(has(r, "two masters drive the switched outputs outside F6"));
  EXPECT_GT(r.stray_dx, 0u);  // the standby's line kept its Data_Exchange
}

}  // namespace
}  // namespace pbvbus::devices
