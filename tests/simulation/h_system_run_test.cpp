// The built-in default scenario (examples/h-system.textproto) run through the Simulation: the
// seeds' story of docs/h-system.md, asserted from the run's report (the H-system part and
// the redundancy part) with the times worked out from the scenario:
//   pair defaults in the file: startup 1 s, link-up 2 s (the first 1 s copying the load memory),
//   update W = MAX(75 ms + 0.7 ms x 100 KB, 50 ms + T_PH 30 ms) = MAX(145, 80) = 145 ms,
//   t4 = t5 - T_PH = t5 - 30 ms; program scan 10 ms.
//   0 s power on together (rack 0 master) -> CPU 0 STARTUP; 1 s CPU 0 RUN (Solo), CPU 1 LINK-UP;
//   3 s UPDATE; 3.145 s Redundant. 5 s upper fibre cut (F5): CPU 1 STOP, OB 72 on CPU 0, one
//   W#16#39C3 for line DP_B (CPU 1's DP master stops); 6 s spliced; 6.5 s CPU 1 switch STOP
//   (already in STOP), 7 s RUN: link-up 7 s -> 9 s, update -> 9.145 s; W#16#38C3 for DP_B at
//   9 s (CPU 1's DP master runs again from its UPDATE). 10 s station 3's DP_A interface fails
//   (F10): OB 70 W#16#73A3 on both CPUs (Redundant) after the DP error recognition; 11 s
//   repaired: W#16#72A3 when the channel is back in data exchange. 12 s CPU 0 (master) fails
//   (F1): CPU 1 master with OB 72, one W#16#39C3 for DP_A, station 4 (still on DP_A) switches
//   to DP_B within the planner's whole-line bound. 14 s CPU 0's power returns: standby,
//   LINK-UP 14 -> 16 s, UPDATE -> 16.145 s Redundant, W#16#38C3 for DP_A at 16 s.
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "pbvbus/scenario/scenario.hpp"
#include "pbvbus/simulation/simulation.hpp"

namespace pbvbus::tools {
namespace {

constexpr bus::Ticks kMs = bus::kTicksPerMs;


const Report& default_run() {
  static const Report r = [] {
    auto loaded = parse_scenario(default_scenario_text(), "<default>");
    EXPECT_TRUE(loaded.ok()) << (loaded.errors.empty() ? "" : loaded.errors[0].str());
    Simulation sim(*loaded.plan);
    sim.start();
    sim.run_until(*sim.duration());
    return sim.report(1.0);
  }();
  return r;
}

bool has_row(const HCpuReport& c, bus::Ticks at, const std::string& change) {
  for (const auto& t : c.timeline)
    if (t.at == at && t.change == change) return true;
  return false;
}

TEST(HSystemRun, DefaultScenarioTellsTheSeedsStory) {
  const Report& r = default_run();
  ASSERT_EQ(r.h_systems.size(), 1u);
  const HSystemReport& h = r.h_systems[0];
  EXPECT_EQ(h.name, "H-CPU");
  const HCpuReport& c0 = h.cpus[0];
  const HCpuReport& c1 = h.cpus[1];
  // R1: power-up to Redundant.
  EXPECT_TRUE(has_row(c0, 0, "CPU 0: STOP -> STARTUP"));
  EXPECT_TRUE(has_row(c0, 1000 * kMs, "CPU 0: STARTUP -> RUN"));
  EXPECT_TRUE(has_row(c1, 1000 * kMs, "CPU 1: STOP -> LINK-UP"));
  EXPECT_TRUE(has_row(c1, 3000 * kMs, "CPU 1: LINK-UP -> UPDATE"));
  EXPECT_TRUE(has_row(c1, 3145 * kMs, "CPU 1: UPDATE -> RUN"));
  EXPECT_TRUE(has_row(c1, 3145 * kMs, "system mode Update -> Redundant"));
  // F5.
  EXPECT_TRUE(has_row(c0, 5000 * kMs, "CPU 0: OB 72 (redundant link lost)"));
  EXPECT_TRUE(has_row(c1, 5000 * kMs, "CPU 1: RUN -> STOP"));
  EXPECT_TRUE(has_row(c1, 7000 * kMs, "CPU 1: STOP -> LINK-UP"));
  EXPECT_TRUE(has_row(c1, 9145 * kMs, "CPU 1: UPDATE -> RUN"));
  // F1 and the return as standby.
  EXPECT_TRUE(has_row(c0, 12000 * kMs, "CPU 0: RUN -> OFF"));
  EXPECT_TRUE(has_row(c1, 12000 * kMs, "CPU 1: role standby -> master"));
  EXPECT_TRUE(has_row(c1, 12000 * kMs, "CPU 1: OB 72 (master CPU lost)"));
  EXPECT_TRUE(has_row(c0, 14000 * kMs, "CPU 0: role none -> standby"));
  EXPECT_TRUE(has_row(c0, 14000 * kMs, "CPU 0: STOP -> LINK-UP"));
  EXPECT_TRUE(has_row(c0, 16000 * kMs, "CPU 0: LINK-UP -> UPDATE"));
  EXPECT_TRUE(has_row(c0, 16145 * kMs, "CPU 0: UPDATE -> RUN"));
  // The end: Redundant with CPU 1 master, LEDs as the manual has them.
  EXPECT_EQ(h.mode, devices::SystemMode::Redundant);
  EXPECT_EQ(c1.role, devices::CpuRole::Master);
  EXPECT_EQ(c0.role, devices::CpuRole::Standby);
  EXPECT_TRUE(c1.leds.mstr);
  EXPECT_FALSE(c0.leds.mstr);
  EXPECT_EQ(c0.leds.redf, devices::Redf::Off);
  // The scenario's H faults as applied.
  ASSERT_EQ(h.faults.size(), 6u);
  EXPECT_EQ(h.faults[0].first, 5000 * kMs);
  EXPECT_EQ(h.faults[4].first, 12000 * kMs);
  EXPECT_EQ(h.faults[4].second, "CPU 0 (rack 0) fails");
}

TEST(HSystemRun, IoEventsWithCodesRacksAndTimes) {
  const Report& r = default_run();
  const HSystemReport& h = r.h_systems.at(0);
  ASSERT_EQ(r.redundancy.size(), 1u);
  const RedundancyReport& red = r.redundancy[0];
  // Station 3's channel on DP_A fails at 10 s; the master notices within its error
  // recognition (the planner's figure for DP_A).
  const bus::Ticks rec_a = red.recognition[0];
  struct Want {
    bus::Ticks from, to;
    std::vector<int> racks;
    int ob;
    std::uint16_t code;
    std::string text;
  };
  const std::vector<Want> want = {
      {5000 * kMs, 5000 * kMs, {0}, 86, 0x39C3, "master system failure: DP master system \"H-DP 1\", line DP_B"},
      // OB 85 at the first OB 1 that finds the one-sided slave 11 (on DP_B) gone: the scans
      // restarted at the end of the update (3.145 s) every 10 ms, so 5.005 s.
      {5005 * kMs, 5005 * kMs, {0}, 85, 0x39B1,
       "process-image transfer error incoming: DP master system \"H-DP 1\", station 11"},
      {9000 * kMs, 9000 * kMs, {0}, 86, 0x38C3, "master system return: DP master system \"H-DP 1\", line DP_B"},
      // Outgoing at the first OB 1 after the update (t5 = 9.145 s), on both CPUs (Redundant).
      {9145 * kMs, 9145 * kMs, {0, 1}, 85, 0x38B1,
       "process-image transfer error outgoing: DP master system \"H-DP 1\", station 11"},
      {10000 * kMs, 10000 * kMs + rec_a, {0, 1}, 70, 0x73A3,
       "redundancy loss: DP master system \"H-DP 1\", line DP_A, station 3"},
      // Back in data exchange after the repair: a start-up (Slave_Diag, Set_Prm, Chk_Cfg,
      // Slave_Diag) well within 100 ms at 1.5 Mbit/s.
      {11000 * kMs, 11100 * kMs, {0, 1}, 70, 0x72A3,
       "redundancy restored: DP master system \"H-DP 1\", line DP_A, station 3"},
      {12000 * kMs, 12000 * kMs, {1}, 86, 0x39C3, "master system failure: DP master system \"H-DP 1\", line DP_A"},
      // Scan grid from 9.145 s: 12.005 s finds the one-sided slave 10 (on DP_A) gone.
      {12005 * kMs, 12005 * kMs, {1}, 85, 0x39B1,
       "process-image transfer error incoming: DP master system \"H-DP 1\", station 10"},
      {16000 * kMs, 16000 * kMs, {1}, 86, 0x38C3, "master system return: DP master system \"H-DP 1\", line DP_A"},
      {16145 * kMs, 16145 * kMs, {0, 1}, 85, 0x38B1,
       "process-image transfer error outgoing: DP master system \"H-DP 1\", station 10"},
  };
  ASSERT_EQ(h.io_events.size(), want.size());
  for (std::size_t k = 0; k < want.size(); ++k) {
    const HIoEvent& e = h.io_events[k];
    EXPECT_GE(e.at, want[k].from) << k;
    EXPECT_LE(e.at, want[k].to) << k;
    EXPECT_EQ(e.racks, want[k].racks) << k;
    EXPECT_EQ(e.ob, want[k].ob) << k;
    EXPECT_EQ(e.code, want[k].code) << k;
    EXPECT_EQ(e.text, want[k].text) << k;
  }
  // Every switchover within the planner's bound; the F1 one is system-level from the CPU's
  // line loss at 12 s.
  EXPECT_EQ(red.exceeded, 0u);
  bool f1 = false;
  for (const auto& s : red.switchovers) {
    ASSERT_TRUE(s.measured.has_value()) << s.station;
    EXPECT_LE(*s.measured, s.bound) << s.station;
    if (s.system_level && s.fault_at == 12000 * kMs) {
      f1 = true;
      EXPECT_EQ(s.station, 4);
      EXPECT_EQ(s.to, "DP_B");
      EXPECT_EQ(s.fault, "line DP_A's DP master loses power with its CPU");
    }
  }
  EXPECT_TRUE(f1);
}

TEST(HSystemRun, UpdatesStayWithinTheirWindows) {
  const HSystemReport& h = default_run().h_systems.at(0);
  ASSERT_TRUE(h.planned_t_p15.has_value());
  ASSERT_TRUE(h.planned_t_ph.has_value());
  EXPECT_EQ(*h.planned_t_p15, 145 * kMs);  // MAX(145, 50 + 30)
  EXPECT_EQ(*h.planned_t_ph, 30 * kMs);    // MAX(30 ms, 3 x T_TR 2.38 ms)
  ASSERT_EQ(h.updates.size(), 3u);
  const bus::Ticks t1[] = {3000 * kMs, 9000 * kMs, 16000 * kMs};
  for (std::size_t k = 0; k < 3; ++k) {
    const HUpdateWindow& w = h.updates[k];
    EXPECT_EQ(w.rack, k < 2 ? 1 : 0);
    EXPECT_EQ(w.t1, t1[k]);
    ASSERT_TRUE(w.t3 && w.t4) << k;
    EXPECT_EQ(*w.t3, t1[k]);
    EXPECT_EQ(w.t5, t1[k] + 145 * kMs);
    EXPECT_EQ(*w.t4, w.t5 - 30 * kMs);  // both CPUs drive the outputs for T_PH
    ASSERT_TRUE(w.last_io_before && w.first_io_after) << k;
    // No OB 1 (no I/O update) inside [t3, t5); the first one runs at t5 itself; the last one
    // before started at most one scan (10 ms) before t3 (a scan due at t3 itself is dropped).
    EXPECT_LT(*w.last_io_before, *w.t3);
    EXPECT_GE(*w.last_io_before, *w.t3 - 10 * kMs);
    EXPECT_EQ(*w.first_io_after, w.t5);
    EXPECT_LE(*w.first_io_after - *w.last_io_before, *h.planned_t_p15 + 10 * kMs);
  }
}


// SFC 14/15 alone make a program (docs/h-dp-sfc.md): the map puts switched station 3 at IB 0..1 /
// QB 0..1, slave 10 (DP_A, counting inputs) at IB 2..3 / QB 2..3, slave 11 (DP_B) at IB 4..5 /
// QB 4..5. SFC 14 reads IB 2..3 into MB 100..101, SFC 15 writes them to QB 0..1 (RET_VALs MW 98,
// MW 96); a 4-octet RECORD for slave 11's 2-octet outputs: W#16#80B1 in MW 94, QB 4..5 stay 0.
// At 1.5 s CPU 0 runs Solo (RUN at 1 s).
TEST(HSystemRun, Sfc14And15AloneAreAProgram) {
  auto loaded = parse_scenario(R"(name: "sfc" duration: "1500ms"
line { name: "DP_A" baud: "1.5M" }
line { name: "DP_B" baud: "1.5M" }
dp_master { address: 1 line: "DP_A" }
dp_master { address: 1 line: "DP_B" }
redundant_master_system { name: "H-DP 1" line_a: "DP_A" master_a: 1 line_b: "DP_B" master_b: 1 }
switched_station { system: "H-DP 1" address: 3 gsd: "gsd/PBVB0A10.gsd" modules: ["16DI DC24V", "16DO DC24V/0.5A"] }
dp_slave { address: 10 line: "DP_A" gsd: "gsd/PBVB0A01.gsd" master: 1 inputs: COUNTER }
dp_slave { address: 11 line: "DP_B" gsd: "gsd/PBVB0A01.gsd" master: 1 }
h_system { name: "H" dp_system { system: "H-DP 1" t_pto: "2s" } cpu { } program {
  dprd_dat { laddr: 2 record: 100 length: 2 ret_val: 98 }
  dpwr_dat { laddr: 0 record: 100 length: 2 ret_val: 96 }
  dpwr_dat { laddr: 4 record: 100 length: 4 ret_val: 94 }
} }
)", std::string(PBVBUS_SOURCE_DIR) + "/examples/h.textproto");
  ASSERT_TRUE(loaded.ok()) << loaded.errors[0].str();
  Simulation sim(*loaded.plan);
  sim.start();
  sim.run_until(*sim.duration());
  const auto* exec = sim.h_system(0).model().execution();
  ASSERT_NE(exec, nullptr);
  const auto& img = exec->image(0);
  const auto m = img.memory();
  auto word = [](std::span<const std::uint8_t> b, std::size_t at) {
    return static_cast<std::uint16_t>((b[at] << 8) | b[at + 1]);
  };
  EXPECT_EQ(word(m, 98), 0x0000);
  EXPECT_EQ(word(m, 96), 0x0000);
  EXPECT_EQ(word(m, 94), 0x80B1);
  EXPECT_NE(word(img.pii(), 2), 0);  // slave 10 counts
  EXPECT_EQ(word(m, 100), word(img.pii(), 2));
  EXPECT_EQ(word(img.piq(), 0), word(img.pii(), 2));
  EXPECT_EQ(word(img.piq(), 4), 0);
}

}  // namespace
}  // namespace pbvbus::tools
