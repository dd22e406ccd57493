// The seeded random fault campaign for switched I/O (devices/switchover_campaign.hpp), reduced
// for CI: a fixed seed, ~150 faults and repairs over every fault kind, on two lines at
// 1.5 Mbit/s with 4 switched stations (one PBVB0A11) and one one-sided slave per line. It must
// see 0 output pulses and 0 mismatches between the events the observer derives and the ones the
// MasterSystem raised. The observer's own tests: a fault it is not told about, a doctored event
// list and a program that writes 0 once must each be caught. The full campaign (>= 1000) is
// bench/switchover_campaign_bench.cpp.
#include "pbvbus/switched_io/switchover_campaign.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <iostream>
#include <string>

#include "pbvbus/bus/line.hpp"
#include "pbvbus/bus/scheduler.hpp"
#include "pbvbus/gsd/gsd.hpp"
#include "pbvbus/switched_io/redundant_master_system.hpp"
#include "pbvbus/slaves/slave_model.hpp"
#include "pbvbus/switched_io/switched_station.hpp"

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
  for (const auto& m : r.mismatches) ADD_FAILURE() << m;
  for (int k = 0; k < kCampaignFaultKinds; ++k)
    EXPECT_GE(r.drawn[k], 3) << to_string(static_cast<CampaignFault>(k));
  EXPECT_GT(r.output_samples, 100000u);
  // Some F11/F24 outages outlast Output_Hold_Time: the safe state was seen, and allowed.
  EXPECT_GT(r.safe_state_samples, 0u);
  EXPECT_GT(r.switchovers, 0u);
  EXPECT_GT(r.station_switches, 0u);
  // Every code occurred, and every event was one the observer expected.
  for (int c : {0x73A3, 0x72A3, 0x39C4, 0x38C4, 0x39C3, 0x38C3})
    EXPECT_GT(r.events_with(static_cast<std::uint16_t>(c)), 0) << std::hex << c;
  int total = 0;
  for (const auto& [c, n] : r.events) total += n;
  EXPECT_EQ(total, r.expected_events);
  // S8: every alarm delivered to the program exactly once, none lost, none twice.
  ASSERT_TRUE(r.alarms_supported);
  EXPECT_GE(r.alarms_raised, 30);
  EXPECT_EQ(r.alarms_lost, 0);
  EXPECT_EQ(r.alarms_duplicated, 0);
  EXPECT_EQ(r.alarms_delivered, r.alarms_raised);
}

// S5: the same campaign with the stations taking their IM's own switchover time (30 ms / 820 ms
// GSD bounds, drawn per switchover): still no pulse, no mismatch, every alarm once.
TEST(SwitchoverCampaign, ReducedCampaignWithTheImsOwnTime) {
  CampaignOptions o = reduced(7, 80);
  o.im_time = true;
  const CampaignResult r = run_campaign(o);
  print(r);
  EXPECT_GE(r.injections(), 80);
  EXPECT_EQ(r.pulses, 0u);
  for (const auto& m : r.mismatches) ADD_FAILURE() << m;
  EXPECT_GT(r.switchovers, 0u);
  EXPECT_EQ(r.alarms_lost, 0);
  EXPECT_EQ(r.alarms_duplicated, 0);
  // Every IM switchover within its bound (a later one is a mismatch, above); the slow station
  // (PBVB0A11, 820 ms) switched at least once, so the longest is in [410 ms, 820 ms].
  EXPECT_GT(r.im_switchovers, 0u);
  EXPECT_GE(r.max_im_switchover, 410 * bus::kTicksPerMs);
  EXPECT_LE(r.max_im_switchover, 820 * bus::kTicksPerMs);
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

// Minimal reproduction of the campaign's first finding (seed 7, 150 injections: "alarm 48 of
// station 20 delivered 2 times (line 1 at +1.2 ms, line 0 at +14.2 ms)", the active interface
// failing 41 us after master B had read the alarm): one switched station on two lines; an
// alarm is raised; master A reads it (MasterEvent::Alarm, its Alarm_Ack queued) and the active
// interface A fails before the Alarm_Ack reaches the station. The station repeats the
// unacknowledged alarm on the new PRIMARY (B), and master B reports it again: the program of
// the redundant pair sees one alarm twice (S8 asks for none lost; the campaign counts by
// (station, slot, type, payload) and expects exactly one delivery). Not fixed here (library
// code: MasterSystem would have to recognise the repeat of an alarm already delivered through
// the old active line, and acknowledge it without reporting it). Enable when fixed.
// S8 at its sharpest: master A has read the alarm, its Alarm_Ack has not reached the station
// when interface A fails; the station raises the alarm again on B, master B reads it, and the
// system recognises the repeat: the program gets it once (the masters each report it).
TEST(SwitchoverCampaign, AlarmReadJustBeforeTheActiveInterfaceFailsIsDeliveredOnce) {
  constexpr bus::Baud kBaud = bus::Baud::k1_5M;
  constexpr std::uint8_t kAddr = 5;
  bus::Scheduler sched;
  bus::Line line[2] = {bus::Line{sched, "A", kBaud}, bus::Line{sched, "B", kBaud}};
  fdl::BusParams bp = fdl::BusParams::defaults(kBaud);
  bp.hsa = 12;
  auto g = load_gsd(std::string(PBVBUS_SOURCE_DIR) + "/examples/gsd/PBVB0A10.gsd");
  ASSERT_TRUE(g.ok());
  const std::vector<ModuleChoice> mods{ModuleChoice::named("16DI DC24V"),
                                       ModuleChoice::named("16DO DC24V/0.5A")};
  auto sp = master_slave_params(*g.file, mods, kAddr);
  ASSERT_TRUE(sp.ok());
  dp::SlaveParams p = *sp.value;
  p.prm_cmd.assign(8, 0);
  RedundantMasterSystemOptions o;
  o.bus_params = bp;
  RedundantMasterSystemModel sys(o, {p}, {p}, {{kAddr, 30 * bus::kTicksPerMs, false}});
  std::vector<std::pair<int, bus::Ticks>> alarms;  // what the program gets
  int master_reports = 0;                          // what the masters saw
  sys.system().on_alarm([&](const redundancy::SystemAlarm& a) {
    if (a.station == kAddr) alarms.emplace_back(a.line, a.time);
  });
  sys.set_master_event_handler([&](int, const dp::MasterEvent& e) {
    if (e.kind == dp::MasterEvent::Kind::Alarm && e.slave == kAddr) ++master_reports;
  });
  for (int l = 0; l < 2; ++l) sys.attach(l, line[l], "master");
  SwitchedStationOptions so;
  so.address = kAddr;
  so.bus_params = bp;
  auto b = SwitchedStationModel::build(*g.file, mods, so);
  ASSERT_TRUE(b.ok());
  for (int l = 0; l < 2; ++l) b.model->attach(l, line[l]);
  line[0].start();
  line[1].start();
  sched.run_until(150 * bus::kTicksPerMs);
  ASSERT_EQ(b.model->primary(), 0);
  const std::vector<std::uint8_t> data{0xAB, 0xCD};
  ASSERT_EQ(b.model->raise_alarm(1, 2, dp::AlarmSpec::Appears, false, data), dp::AlarmResult::Ok);
  while (alarms.empty() && sched.now() < 200 * bus::kTicksPerMs)
    sched.run_until(sched.now() + 10 * bus::kTicksPerUs);
  ASSERT_EQ(alarms.size(), 1u);
  EXPECT_EQ(alarms[0].first, 0);
  b.model->fail_interface(0);  // before master A's Alarm_Ack reaches the station
  sched.run_until(700 * bus::kTicksPerMs);
  EXPECT_EQ(b.model->primary(), 1);
  EXPECT_EQ(alarms.size(), 1u) << "read on line 0 at " << alarms.front().second / bus::kTicksPerUs
                               << " us, delivered again on line " << alarms.back().first << " at "
                               << alarms.back().second / bus::kTicksPerUs << " us";
  // The repeat did come (master B read it and acknowledged it): recognised, not delivered.
  EXPECT_EQ(master_reports, 2);
  EXPECT_EQ(sys.system().alarm_repeats(), 1u);
}

}  // namespace
}  // namespace pbvbus::devices
