// The seeded H-system fault campaign (devices/h_campaign.hpp), reduced for CI: seed 7, 150
// injections over every fault kind (CPU power/STOP of master and standby, one fibre, both
// fibres, active/passive IM, short circuit, DP master module, comparison error, one-sided
// OB 121, operator master swap) on two lines at 1.5 Mbit/s with the CPU pair, two switched
// stations and one one-sided slave per line. It must see 0 output pulses, 0 mismatches between
// the events the observer derives and HSystemModel::events(), never two masters driving the
// switched outputs outside F6. The observer's own tests: a fault it is not told about, a
// doctored event list, a program writing 0 once and a second master outside F6 must each be
// caught. The full campaign (>= 1000 injections) is bench/h_campaign_bench.cpp.
#include "pbvbus/devices/h_campaign.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <iostream>
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
  for (int k = 0; k < kHFaultKinds; ++k)
    EXPECT_GE(r.drawn[k], 1) << to_string(static_cast<HFault>(k));
  EXPECT_EQ(r.second_master_frames, 0u);
  EXPECT_EQ(r.stray_dx, 0u);
  EXPECT_GT(r.split_frames, 0u);  // F6 was seen on the wire's time line, and allowed
  EXPECT_GT(r.dx_requests, 10000u);
  EXPECT_GT(r.output_samples, 100000u);
  EXPECT_GT(r.role_swaps, 0);
  EXPECT_GT(r.defective, 0);         // F17 repeated within 7 days
  EXPECT_GT(r.comparison_stops, 0);  // F16 within the first self-test cycle after a search
  // Every event was one the observer expected (the multiset matched, so the counts agree).
  EXPECT_EQ(r.observed_events, r.expected_events);
  for (int c : {0x73A3, 0x72A3, 0x39C4, 0x38C4, 0x39C3, 0x38C3})
    EXPECT_GT(r.events_with(static_cast<std::uint16_t>(c)), 0) << std::hex << c;
  EXPECT_GT(r.ob72, 0);
  EXPECT_GT(r.ob121, 0);
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
