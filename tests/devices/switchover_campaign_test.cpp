// The seeded random fault campaign for switched I/O (devices/switchover_campaign.hpp), reduced
// for CI: a fixed seed, ~150 faults and repairs over every fault kind, on two lines at
// 1.5 Mbit/s with 4 switched stations (one PBVB0A11) and one one-sided slave per line. It must
// see 0 output pulses and 0 mismatches between the events the observer derives and the ones the
// MasterSystem raised. The observer's own tests: a fault it is not told about, a doctored event
// list and a program that writes 0 once must each be caught. The full campaign (>= 1000) is
// bench/switchover_campaign_bench.cpp.
#include <gtest/gtest.h>

#include <algorithm>
#include <iostream>
#include <string>

#include "pbvbus/devices/switchover_campaign.hpp"

namespace pbvbus::devices {
namespace {

CampaignOptions reduced(std::uint64_t seed, int faults) {
  CampaignOptions o;
  o.seed = seed;
  o.faults = faults;
  o.gsd_dir = std::string(PBVBUS_SOURCE_DIR) + "/examples/gsd";
  return o;
}

void print(const CampaignResult& r) {
  std::cout << r.summary() << "\n";
  for (std::size_t i = 0; i < r.mismatches.size() && i < 10; ++i)
    std::cout << "  mismatch: " << r.mismatches[i] << "\n";
  for (const auto& p : r.pulse_reports) std::cout << "  pulse: " << p << "\n";
}

TEST(SwitchoverCampaign, ReducedCampaignHasNoPulseAndNoMismatch) {
  const CampaignResult r = run_campaign(reduced(7, 150));
  print(r);
  EXPECT_GE(r.injections(), 150);
  EXPECT_EQ(r.pulses, 0u);
  EXPECT_TRUE(r.mismatches.empty()) << r.mismatches.front();
  for (int k = 0; k < kCampaignFaultKinds; ++k)
    EXPECT_GE(r.drawn[k], 3) << to_string(static_cast<CampaignFault>(k));
  EXPECT_GT(r.output_samples, 100000u);
  EXPECT_GT(r.switchovers, 0u);
  EXPECT_GT(r.station_switches, 0u);
  // Every code occurred, and every event was one the observer expected.
  for (int c : {0x73A3, 0x72A3, 0x39C4, 0x38C4, 0x39C3, 0x38C3})
    EXPECT_GT(r.events_with(static_cast<std::uint16_t>(c)), 0) << std::hex << c;
  int total = 0;
  for (const auto& [c, n] : r.events) total += n;
  EXPECT_EQ(total, r.expected_events);
  if (r.alarms_supported) {
    EXPECT_GT(r.alarms_raised, 0);
    EXPECT_EQ(r.alarms_delivered, r.alarms_raised);
    EXPECT_EQ(r.alarms_lost, 0);
    EXPECT_EQ(r.alarms_duplicated, 0);
  }
}

// The observer is not told about one fault (a passive interface failure and its repair): the
// 73A3 and 72A3 it causes are unexpected events.
TEST(SwitchoverCampaign, ObserverCatchesAFaultItWasNotToldAbout) {
  CampaignOptions o = reduced(11, 12);
  o.tamper.hidden_fault_at = 1;
  const CampaignResult r = run_campaign(o);
  print(r);
  ASSERT_GE(r.mismatches.size(), 2u);
  const auto has = [&](const char* a, const char* b) {
    return std::any_of(r.mismatches.begin(), r.mismatches.end(), [&](const std::string& m) {
      return m.find(a) != std::string::npos && m.find(b) != std::string::npos;
    });
  };
  EXPECT_TRUE(has("hidden fault", "73A3"));
  EXPECT_TRUE(has("hidden repair", "72A3"));
  EXPECT_EQ(r.pulses, 0u);
}

// A doctored event list: the first 39C3 dropped, one 72A3 turned into 38C4, one 73A3 moved to
// the wrong line. Each must be reported.
TEST(SwitchoverCampaign, ObserverCatchesDoctoredEvents) {
  CampaignOptions o = reduced(7, 60);
  o.weights = {2, 2, 1, 1, 3, 2, 1, 1};
  int dropped = 0, changed = 0, moved = 0;
  o.tamper.doctor_events = [&](std::vector<redundancy::SystemEvent>& ev) {
    using K = redundancy::SystemEvent::Kind;
    for (auto it = ev.begin(); it != ev.end(); ++it)
      if (it->kind == K::MasterSystemFailure) {
        ev.erase(it);
        ++dropped;
        break;
      }
    for (auto& e : ev)
      if (e.kind == K::RedundancyReturn) {
        e.kind = K::StationReturn;
        ++changed;
        break;
      }
    for (auto& e : ev)
      if (e.kind == K::RedundancyLoss) {
        e.line = 1 - e.line;
        ++moved;
        break;
      }
  };
  const CampaignResult r = run_campaign(o);
  print(r);
  ASSERT_EQ(dropped, 1);
  ASSERT_EQ(changed, 1);
  ASSERT_EQ(moved, 1);
  EXPECT_GE(r.mismatches.size(), 3u);
  const auto count = [&](const char* s) {
    return std::count_if(r.mismatches.begin(), r.mismatches.end(),
                         [&](const std::string& m) { return m.find(s) != std::string::npos; });
  };
  EXPECT_GE(count("missing"), 3);
}

// The program writes 0 once (20 ms): the sampler must see it on the backplane as a pulse.
TEST(SwitchoverCampaign, SamplerCatchesAnOutputPulse) {
  CampaignOptions o = reduced(3, 4);
  o.tamper.zero_output_at = 200 * bus::kTicksPerMs + 7;  // after start-up, before the 1st fault
  const CampaignResult r = run_campaign(o);
  print(r);
  EXPECT_GT(r.pulses, 0u);
  ASSERT_FALSE(r.pulse_reports.empty());
  EXPECT_NE(r.pulse_reports[0].find("outputs 0"), std::string::npos);
}

}  // namespace
}  // namespace pbvbus::devices
