// Switched I/O in scenario files (redundant_master_system, switched_station, the faults
// interface_failure, station_power_loss, master_failure, master_stop): the shipped example
// examples/switched-io.textproto run to its end, every S7 event of its fault script asserted
// (code, line, station, time window), and every measured switchover checked against the
// planner's bound, which the test works out by hand from the bus parameters and the GSDs.
// Then the loader's errors for broken redundancy entries, at FILE:LINE:COLUMN.
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "pbvbus/scenario/scenario.hpp"
#include "pbvbus/simulation/simulation.hpp"

namespace pbvbus::tools {
namespace {

constexpr bus::Ticks kMs = bus::kTicksPerMs;
constexpr bus::Ticks kBit = 2424;  // ticks per bit at 1.5 Mbit/s: 3 636 000 000 / 1 500 000

std::string example() { return PBVBUS_SOURCE_DIR "/examples/switched-io.textproto"; }

struct Expected {
  int ob;
  std::uint16_t code;
  const char* line;
  int station;  // -1 = the master system
  bus::Ticks from, to;  // the event's time window
};

// The bounds by hand. Both lines: TSL 315, min TSDR 11, max TSDR 300 (PBVB0A11's MaxTsdr_1.5M),
// TSET 1, TQUI 0, retry 1 (as the loader derives them; asserted below). TID1 = max(TSYN 33 +
// 2 + 2·TSET + TQUI, min TSDR) = 37, TID2 = max(37, max TSDR) = 300.
// Each line polls 4 switched stations (3, 4, 5: PBVB0A10, MaxTsdr 150, Max_Diag_Data_Len 64;
// 6: PBVB0A11, MaxTsdr 300, 64) and one one-sided PBVB0A01 (MaxTsdr 150), all 2 in / 2 out:
//   DX = 11·11 (SD2, 2 octets) + TSDR + 11·11 + TID1 = 279 + TSDR: 429 ×4 + 579 = 2295
//   Global_Control 11·13 + TID2 = 443; token 11·3 + TID1 = 70
//   GAP: answered 11·6 + 300 + 11·6 + 37 = 469 > unanswered 11·6 + 315 = 381 → 469
//   Slave_Diag reserve: 11·11 + 300 + 11·(9 + 2 + 64) + 37 = 1283 (PBVB0A11)
//   retry reserve: 11·11 + TSL = 436
//   T_TR = 2295 + 443 + 70 + 469 + 1283 + 436 = 4996 bits
//   recognition = T_TR + (1 + retry)·(121 + 315) = 5868 bits
//   PrmCmd cycle = 11·(9 + 2 + 18) + TSDR + 11 (SC) + 37 = 517 (TSDR 150) / 667 (TSDR 300)
//   T_DP_UM = 2·T_TR + PrmCmd = 10509 (fast) / 10659 (slow)
//   station bound = recognition + T_DP_UM + T_SLAVE_UM (30 ms / 820 ms from the GSDs)
//   system: T_DP_UM = 2·T_TR + 3·517 + 667 = 12210 bits, + the slowest T_SLAVE_UM (820 ms);
//   a short is recognised within T_TR (4996 bits) of the shorted line; a master stop or
//   failure at once.
constexpr bus::Ticks kBoundFast = (5868 + 10509) * kBit + 30 * kMs;
constexpr bus::Ticks kBoundSlow = (5868 + 10659) * kBit + 820 * kMs;
constexpr bus::Ticks kBoundShort = (4996 + 12210) * kBit + 820 * kMs;
constexpr bus::Ticks kBoundMaster = 12210 * kBit + 820 * kMs;

TEST(SwitchedIoScenario, ExampleLoadsWithTheDerivedBusParameters) {
  const auto r = load_scenario_file(example());
  ASSERT_TRUE(r.ok()) << r.errors.front().str();
  const ScenarioPlan& p = *r.plan;
  ASSERT_EQ(p.redundant_systems.size(), 1u);
  ASSERT_EQ(p.switched.size(), 4u);
  EXPECT_EQ(p.redundant_systems[0].name, "H-DP 1");
  EXPECT_EQ(p.redundant_systems[0].output_hold_10ms, 100);
  for (const auto& l : p.lines) {
    EXPECT_EQ(l.params.tsl, 315u) << l.name;
    EXPECT_EQ(l.params.max_tsdr, 300u);
    EXPECT_EQ(l.params.min_tsdr, 11u);
    EXPECT_EQ(l.params.tset, 1u);
    EXPECT_EQ(l.params.tqui, 0u);
    EXPECT_EQ(l.params.max_retry, 1);
    EXPECT_EQ(l.params.tid1(), 37u);
    EXPECT_EQ(l.params.tid2(), 300u);
    // Each line: master, the four switched stations, its one-sided slave.
    EXPECT_EQ(l.stations.size(), 6u);
  }
  // T_SLAVE_UM from the GSDs: Slave_Max_Switch_Over_Time 3 and 82 (× 10 ms).
  EXPECT_EQ(*p.switched[0].t_slave_um, 30 * kMs);
  EXPECT_TRUE(p.switched[0].t_slave_um_from_gsd);
  EXPECT_EQ(*p.switched[3].t_slave_um, 820 * kMs);
  // Each switched station is one dp_slave plan per line, with a PrmCmd block in its Set_Prm.
  for (const auto& w : p.switched)
    for (int side = 0; side < 2; ++side)
      EXPECT_EQ(p.dp_slaves.at(static_cast<std::size_t>(w.slave[side])).params.prm_cmd.size(), 8u);
}

TEST(SwitchedIoScenario, FaultScriptGivesTheS7EventsAndEverySwitchoverStaysInItsBound) {
  const auto r = load_scenario_file(example());
  ASSERT_TRUE(r.ok()) << r.errors.front().str();
  Simulation sim(*r.plan);
  sim.run_until(10'000 * kMs);
  const Report rep = sim.report(1.0);
  ASSERT_EQ(rep.redundancy.size(), 1u);
  const RedundancyReport& red = rep.redundancy[0];

  // The planner agrees with the hand computation.
  EXPECT_EQ(red.t_tr[0], 4996 * kBit);
  EXPECT_EQ(red.recognition[0], 5868 * kBit);
  EXPECT_EQ(red.system_bound[1], kBoundShort);
  ASSERT_EQ(red.stations.size(), 4u);
  EXPECT_EQ(red.stations[0].bound[0], kBoundFast);
  EXPECT_EQ(red.stations[3].bound[0], kBoundSlow);

  // Incoming events come within the recognition time of the fault (a master stop, a master
  // failure and a short: at once, or at the master's next transmission); returns within a
  // re-start-up (a few DP cycles; 20 ms).
  const bus::Ticks rec = 5868 * kBit;
  const bus::Ticks back = 20 * kMs;
  auto at = [](int ms) { return static_cast<bus::Ticks>(ms) * kMs; };
  const std::vector<Expected> want = {
      {70, 0x73A3, "DP_A", 3, at(1000), at(1000) + rec},    // F10
      {70, 0x72A3, "DP_A", 3, at(1500), at(1500) + back},   // repair: no switch back
      {70, 0x73A3, "DP_A", 4, at(2000), at(2000) + rec},    // F11: first interface
      {86, 0x39C4, "DP_B", 4, at(2300), at(2300) + rec},    //      second interface
      {86, 0x38C4, "DP_B", 4, at(2600), at(2600) + back},   // repairs
      {70, 0x72A3, "DP_A", 4, at(2800), at(2800) + back},
      {86, 0x39C4, "DP_A", 10, at(3500), at(3500) + rec},   // F13: one-sided behind the cut
      {70, 0x73A3, "DP_A", 6, at(3500), at(3500) + rec},    //      switched behind the cut
      {70, 0x72A3, "DP_A", 6, at(4000), at(4000) + back},
      {86, 0x38C4, "DP_A", 10, at(4000), at(4000) + back},
      {86, 0x39C3, "DP_B", -1, at(5000), at(5000) + 4996 * kBit},  // F14 short: one event
      {86, 0x38C3, "DP_B", -1, at(5500), at(5500) + 4996 * kBit},
      {70, 0x73A3, "DP_A", 3, at(6500), at(6500)},          // F9: per station, at once
      {70, 0x73A3, "DP_A", 4, at(6500), at(6500)},
      {70, 0x73A3, "DP_A", 5, at(6500), at(6500)},
      {70, 0x73A3, "DP_A", 6, at(6500), at(6500)},
      {86, 0x39C4, "DP_A", 10, at(6500), at(6500)},
      {86, 0x38C4, "DP_A", 10, at(7000), at(7000) + back},  // the master starts up again
      {70, 0x72A3, "DP_A", 3, at(7000), at(7000) + back},
      {70, 0x72A3, "DP_A", 4, at(7000), at(7000) + back},
      {70, 0x72A3, "DP_A", 5, at(7000), at(7000) + back},
      {70, 0x72A3, "DP_A", 6, at(7000), at(7000) + back},
      {86, 0x39C3, "DP_B", -1, at(8500), at(8500)},         // F14 master stop: one event
      {86, 0x38C3, "DP_B", -1, at(9000), at(9000)},
  };
  std::vector<RedEventReport> got;
  for (const auto& e : red.events)
    if (e.ob != 0) got.push_back(e);
  ASSERT_EQ(got.size(), want.size());
  for (std::size_t i = 0; i < want.size(); ++i) {
    SCOPED_TRACE("event " + std::to_string(i) + ": " + got[i].kind + " at " +
                 bus::format_duration(got[i].time));
    EXPECT_EQ(got[i].ob, want[i].ob);
    EXPECT_EQ(got[i].code, want[i].code);
    EXPECT_EQ(got[i].line, want[i].line);
    EXPECT_EQ(got[i].station, want[i].station);
    EXPECT_GE(got[i].time, want[i].from);
    EXPECT_LE(got[i].time, want[i].to);
  }

  // Every switchover a fault caused: measured (fault → first fresh outputs on the new channel)
  // and within the hand-computed bound.
  struct Sw {
    int station;
    const char* to;
    bus::Ticks bound;
  };
  const std::vector<Sw> want_sw = {
      {3, "DP_B", kBoundFast},   {4, "DP_B", kBoundFast},   {6, "DP_B", kBoundSlow},
      {3, "DP_A", kBoundShort},  {4, "DP_A", kBoundShort},  {6, "DP_A", kBoundShort},
      {3, "DP_B", kBoundMaster}, {4, "DP_B", kBoundMaster}, {5, "DP_B", kBoundMaster},
      {6, "DP_B", kBoundMaster}, {3, "DP_A", kBoundMaster}, {4, "DP_A", kBoundMaster},
      {5, "DP_A", kBoundMaster}, {6, "DP_A", kBoundMaster}};
  ASSERT_EQ(red.switchovers.size(), want_sw.size());
  for (std::size_t i = 0; i < want_sw.size(); ++i) {
    const auto& s = red.switchovers[i];
    SCOPED_TRACE("switchover " + std::to_string(i) + " of station " + std::to_string(s.station));
    EXPECT_EQ(s.station, want_sw[i].station);
    EXPECT_EQ(s.to, want_sw[i].to);
    EXPECT_EQ(s.bound, want_sw[i].bound);
    ASSERT_TRUE(s.measured.has_value());
    EXPECT_GT(*s.measured, 0);
    EXPECT_LE(*s.measured, want_sw[i].bound);
    EXPECT_FALSE(s.exceeded);
    // S5: the IM's own time, drawn in [T_SLAVE_UM / 2, T_SLAVE_UM] (30 ms; station 6 820 ms),
    // is part of every measured switchover.
    const bus::Ticks t_slave_um = (s.station == 6 ? 820 : 30) * kMs;
    ASSERT_TRUE(s.im_time.has_value());
    EXPECT_GE(*s.im_time, t_slave_um / 2);
    EXPECT_LE(*s.im_time, t_slave_um);
    EXPECT_GE(*s.measured, *s.im_time);
  }
  EXPECT_EQ(red.exceeded, 0u);
  // The whole-line switchovers (F14 short at 5 s, F9 master failure at 6.5 s, F14 master stop
  // at 8.5 s) end with the slow station 6: at least 410 ms, its IM dominates.
  for (std::size_t first : {3u, 6u, 10u}) {
    const std::size_t n = first == 3u ? 3u : 4u;
    bus::Ticks longest = 0;
    int who = 0;
    for (std::size_t k = first; k < first + n; ++k)
      if (*red.switchovers[k].measured > longest) {
        longest = *red.switchovers[k].measured;
        who = red.switchovers[k].station;
      }
    EXPECT_EQ(who, 6) << first;
    EXPECT_GE(longest, 410 * kMs) << first;
  }
  // The end: after the master stop on DP_B everything runs on DP_A again, redundantly.
  for (const auto& s : red.stations) {
    EXPECT_EQ(s.active, "DP_A") << int(s.address);
    EXPECT_FALSE(s.failed);
    EXPECT_FALSE(s.redundancy_lost);
    EXPECT_EQ(s.roles[0], "PRIMARY");
    EXPECT_EQ(s.roles[1], "BACKUP");
  }
}

// --- loader errors -------------------------------------------------------------------------

const std::string kFile = PBVBUS_SOURCE_DIR "/examples/test.textproto";

std::string lines_and_masters() {
  return "name: \"t\"\nduration: \"1s\"\n"
         "line { name: \"A\" baud: \"1.5M\" }\n"
         "line { name: \"B\" baud: \"1.5M\" }\n"
         "dp_master { address: 1 line: \"A\" }\n"
         "dp_master { address: 1 line: \"B\" }\n";
}

std::vector<std::string> errors_of(const std::string& text) {
  const auto r = parse_scenario(text, kFile);
  std::vector<std::string> out;
  for (const auto& e : r.errors) out.push_back(e.str());
  return out;
}

TEST(SwitchedIoScenario, RefusesBrokenSystemsAndStationsWithPositions) {
  const std::string base = lines_and_masters();
  // Line 7: the system.
  auto e = errors_of(base + "redundant_master_system { name: \"S\" line_a: \"A\" master_a: 2 "
                            "line_b: \"C\" master_b: 1 }\n");
  ASSERT_EQ(e.size(), 2u);
  EXPECT_NE(e[0].find("test.textproto:7:"), std::string::npos) << e[0];
  EXPECT_NE(e[0].find("no dp_master 2 on line \"A\""), std::string::npos) << e[0];
  EXPECT_NE(e[1].find("unknown line \"C\""), std::string::npos) << e[1];

  e = errors_of(base + "redundant_master_system { name: \"S\" line_a: \"A\" master_a: 1 "
                       "line_b: \"A\" master_b: 1 }\n");
  ASSERT_EQ(e.size(), 1u);
  EXPECT_NE(e[0].find("two different lines"), std::string::npos) << e[0];

  e = errors_of(base + "redundant_master_system { name: \"S\" line_a: \"A\" master_a: 1 "
                       "line_b: \"B\" master_b: 1 output_hold_time: \"15ms\" }\n");
  ASSERT_EQ(e.size(), 1u);
  EXPECT_NE(e[0].find("multiple of 10 ms"), std::string::npos) << e[0];

  const std::string sys = base +
                          "redundant_master_system { name: \"S\" line_a: \"A\" master_a: 1 "
                          "line_b: \"B\" master_b: 1 }\n";
  // An unknown system; a GSD without System Redundancy; a station address out of range.
  e = errors_of(sys + "switched_station { system: \"T\" address: 3 gsd: \"gsd/PBVB0A10.gsd\" }\n");
  ASSERT_EQ(e.size(), 1u);
  EXPECT_NE(e[0].find("test.textproto:8:"), std::string::npos) << e[0];
  EXPECT_NE(e[0].find("no redundant_master_system \"T\""), std::string::npos) << e[0];
  e = errors_of(sys + "switched_station { system: \"S\" address: 3 gsd: \"gsd/PBVB0A01.gsd\" }\n");
  ASSERT_EQ(e.size(), 1u);
  EXPECT_NE(e[0].find("does not declare System Redundancy"), std::string::npos) << e[0];
  e = errors_of(sys + "switched_station { system: \"S\" address: 126 gsd: \"gsd/PBVB0A10.gsd\" "
                      "modules: [\"16DI DC24V\"] }\n");
  ASSERT_FALSE(e.empty());
  EXPECT_NE(e[0].find("out of range 0..125"), std::string::npos) << e[0];
  // The same address as a one-sided slave on line B.
  e = errors_of(sys +
                "switched_station { system: \"S\" address: 3 gsd: \"gsd/PBVB0A10.gsd\" "
                "modules: [\"16DI DC24V\"] }\n"
                "dp_slave { address: 3 line: \"B\" gsd: \"gsd/PBVB0A01.gsd\" master: 1 }\n");
  ASSERT_FALSE(e.empty());
  bool twice = false;
  for (const auto& x : e) twice = twice || x.find("already used on line \"B\"") != std::string::npos;
  EXPECT_TRUE(twice) << e[0];
  // Faults: an interface of a station that does not exist; a master that does not exist.
  const std::string st = sys +
                         "switched_station { system: \"S\" address: 3 gsd: \"gsd/PBVB0A10.gsd\" "
                         "modules: [\"16DI DC24V\"] }\n";
  e = errors_of(st + "fault { at: \"100ms\" interface_failure { address: 4 line: \"A\" } }\n");
  ASSERT_EQ(e.size(), 1u);
  EXPECT_NE(e[0].find("no switched_station 4 on line \"A\""), std::string::npos) << e[0];
  e = errors_of(st + "fault { at: \"100ms\" master_stop { address: 2 line: \"B\" } }\n");
  ASSERT_EQ(e.size(), 1u);
  EXPECT_NE(e[0].find("no dp_master 2 on line \"B\""), std::string::npos) << e[0];
  EXPECT_TRUE(errors_of(st + "fault { at: \"100ms\" station_power_loss { address: 3 } }\n").empty());
}

// Station power loss from a scenario: both masters lose the station (one 39C4 after the
// second channel), and it returns on its own after power-on.
TEST(SwitchedIoScenario, StationPowerLossIsAStationFailure) {
  const std::string text = lines_and_masters() +
                           "redundant_master_system { name: \"S\" line_a: \"A\" master_a: 1 "
                           "line_b: \"B\" master_b: 1 }\n"
                           "switched_station { system: \"S\" address: 3 gsd: \"gsd/PBVB0A10.gsd\" "
                           "modules: [\"16DI DC24V\", \"16DO DC24V/0.5A\"] }\n"
                           "fault { at: \"300ms\" repair_at: \"600ms\" station_power_loss { address: 3 } }\n";
  const auto r = parse_scenario(text, kFile);
  ASSERT_TRUE(r.ok()) << r.errors.front().str();
  Simulation sim(*r.plan);
  sim.run_until(1000 * kMs);
  const auto red = sim.report(1.0).redundancy.at(0);
  std::vector<std::uint16_t> codes;
  for (const auto& e : red.events)
    if (e.ob != 0) codes.push_back(e.code);
  // The first channel lost is a redundancy loss, the second the station failure; the first
  // back is the station's return, the second restores redundancy.
  EXPECT_EQ(codes, (std::vector<std::uint16_t>{0x73A3, 0x39C4, 0x38C4, 0x72A3}));
  // After the cold start the first channel back in data exchange is made active (the system
  // sends it Primary_Request), whichever line it is on.
  EXPECT_FALSE(red.stations.at(0).active.empty());
  EXPECT_FALSE(red.stations.at(0).failed);
}

}  // namespace
}  // namespace pbvbus::tools
