// The scenario fields of docs/h-scenario-changes.md: planned, refused with FILE:LINE:COLUMN, and
// run through the Simulation (HSystemNode -> HSystemModel -> HCpuPair). Every time below is the
// pair's arithmetic worked by hand: STARTUP 1 s (or as set), LINK-UP as set or T8, UPDATE
// 75 ms + 0.7 ms x 100 KB = 145 ms (digest §3.1).
#include <gtest/gtest.h>

#include <algorithm>
#include <string>
#include <tuple>
#include <vector>

#include "scenario_run_support.hpp"
#include "pbvbus/scenario/scenario.hpp"
#include "pbvbus/simulation/simulation.hpp"

namespace pbvbus::tools {
namespace {

constexpr bus::Ticks kMs = bus::kTicksPerMs;
constexpr bus::Ticks kS = bus::kTicksPerSecond;
using K = PlanFault::Kind;

/// When the pair first reached `mode` (the timeline's system-mode rows of CPU 0).
std::optional<bus::Ticks> first_mode(const HSystemReport& h, devices::SystemMode mode) {
  for (const auto& t : h.cpus[0].timeline)
    if (t.kind == devices::HEvent::Kind::SystemMode && t.mode == mode) return t.at;
  return std::nullopt;
}

std::optional<bus::Ticks> first_state(const HCpuReport& c, devices::CpuState s) {
  for (const auto& t : c.timeline)
    if (t.kind == devices::HEvent::Kind::State && t.state == s) return t.at;
  return std::nullopt;
}

// ---- T8: the link-up time from the memory size (000 §5.3.1 L1364-1374) ----

// (3 MB load + 1 MB work) x 1 s + 1 s base = 5 s; with base "3s" and 2 MB: 2 + 3 = 5 s; 1 MB
// alone: 1 + 1 = 2 s (the pair's default, h_cpu_pair.hpp).
TEST(HScenarioFields, T8LinkUpTimeIsPlannedFromTheMemorySize) {
  const auto a = parse_scenario(R"(h_system { name: "H" cpu { load_memory_mb: 3 work_memory_mb: 1 } })", "h.textproto");
  ASSERT_TRUE(a.ok()) << a.errors[0].str();
  EXPECT_EQ(a.plan->h_systems.at(0).runtime->pair.link_up_time, 5 * kS);
  const auto b = parse_scenario(R"(h_system { name: "H" cpu { load_memory_mb: 2 link_up_base_time: "3s" } })", "h.textproto");
  ASSERT_TRUE(b.ok()) << b.errors[0].str();
  EXPECT_EQ(b.plan->h_systems.at(0).runtime->pair.link_up_time, 5 * kS);
  const auto c = parse_scenario(R"(h_system { name: "H" cpu { load_memory_mb: 1 } })", "h.textproto");
  ASSERT_TRUE(c.ok()) << c.errors[0].str();
  EXPECT_EQ(c.plan->h_systems.at(0).runtime->pair.link_up_time, 2 * kS);
}

// Both CPUs on at 0 s: CPU 0 STARTUP 0 -> 1 s (Solo), CPU 1 LINK-UP 1 -> 6 s (5 s of T8), UPDATE
// 6 -> 6.145 s, Redundant at 6.145 s.
TEST(HScenarioFields, T8RunLinksUpForMemoryTimesOneSecondPlusBase) {
  const test::ScenarioRun run = test::run_scenario(R"(name: "t8"
duration: "6500ms"
h_system { name: "H" cpu { load_memory_mb: 3 work_memory_mb: 1 } }
)");
  ASSERT_TRUE(run.report) << run.error;
  const HSystemReport& h = run.report->h_systems.at(0);
  EXPECT_EQ(first_state(h.cpus[1], devices::CpuState::LinkUp), std::optional<bus::Ticks>(1 * kS));
  ASSERT_EQ(h.updates.size(), 1u);
  EXPECT_EQ(h.updates[0].t1, 6 * kS);  // the link-up lasted 6 - 1 = 5 s
  EXPECT_EQ(h.updates[0].t5, 6145 * kMs);
  EXPECT_EQ(first_mode(h, devices::SystemMode::Redundant), std::optional<bus::Ticks>(6145 * kMs));
}

// ---- battery and RAM test (000 L640, 001 L1149-1153: 8 s per MB after an unbuffered POWER ON) ----

TEST(HScenarioFields, BatteryAndRamArePlanned) {
  const auto r = parse_scenario(R"(h_system { name: "H" cpu { cpu0 { ram_mb: 2 } cpu1 { battery: false } } })", "h.textproto");
  ASSERT_TRUE(r.ok()) << r.errors[0].str();
  const auto& rp = r.plan->h_systems.at(0).runtime->changes.rack_power;
  ASSERT_TRUE(rp.has_value());
  EXPECT_EQ(rp->ram_kb, 2048u);  // given for cpu0, both CPUs have it
  EXPECT_TRUE(rp->battery[0]);
  EXPECT_FALSE(rp->battery[1]);
  const auto d = parse_scenario(R"(h_system { name: "H" cpu { } })", "h.textproto");
  ASSERT_TRUE(d.ok());
  EXPECT_FALSE(d.plan->h_systems.at(0).runtime->changes.rack_power.has_value());
}

// 1 MB: 8 s of RAM test at the first POWER ON of both CPUs (0 s): both STOP at 8 s, CPU 0
// STARTUP 8 -> 9 s, LINK-UP 9 -> 11 s, UPDATE -> 11.145 s. CPU 1 (no battery) fails at 12 s and
// gets power back at 13 s: again 8 s -> 21 s, LINK-UP 21 -> 23 s, Redundant at 23.145 s. No
// DP lines and no program: the long virtual time costs only the pair's events.
TEST(HScenarioFields, RamTestDelaysTheStartUp) {
  const test::ScenarioRun run = test::run_scenario(R"(name: "ram"
duration: "24s"
h_system { name: "H" cpu { cpu0 { ram_mb: 1 } cpu1 { battery: false } } }
fault { at: "12s" repair_at: "13s" cpu_failure { rack: 1 } }
)");
  ASSERT_TRUE(run.report) << run.error;
  const HSystemReport& h = run.report->h_systems.at(0);
  ASSERT_FALSE(h.cpus[0].timeline.empty());
  EXPECT_EQ(h.cpus[0].timeline.front().at, 8 * kS);  // nothing before the test's end
  EXPECT_EQ(first_state(h.cpus[0], devices::CpuState::Startup), std::optional<bus::Ticks>(8 * kS));
  ASSERT_EQ(h.updates.size(), 2u);
  EXPECT_EQ(h.updates[0].t1, 11 * kS);
  EXPECT_EQ(h.updates[1].t1, 23 * kS);
  EXPECT_EQ(h.updates[1].t5, 23145 * kMs);
  ASSERT_FALSE(h.faults.empty());
  EXPECT_EQ(h.faults.front(), (std::pair<bus::Ticks, std::string>{
                                  0, "RAM test at every unbuffered POWER ON: 8000 ms (1 MB x 8 s; 000 L640)"}));
}

// ---- the switch to CPU with modified configuration (000 §5.2.2-5.2.3, §10.4.6-10.4.7) ----

const std::string kLines = R"(line { name: "DP_A" baud: "1.5M" }
line { name: "DP_B" baud: "1.5M" }
dp_master { address: 1 line: "DP_A" watchdog: "100ms" }
dp_master { address: 1 line: "DP_B" watchdog: "100ms" }
redundant_master_system { name: "S" line_a: "DP_A" master_a: 1 line_b: "DP_B" master_b: 1 }
switched_station { system: "S" address: 3 gsd: "gsd/PBVB0A10.gsd" modules: ["16DI DC24V", "16DI DC24V", "16DO DC24V/0.5A"] }
)";
const std::string kFile = PBVBUS_SOURCE_DIR "/examples/test.textproto";

// CPU 1's switch at STOP: CPU 0 RUN at 0.1 s; the switch at 0.2 s: LINK-UP 0.2 -> 0.7 s, UPDATE
// 0.7 -> 0.845 s = the swap (OB 72 master swap on CPU 1, OB1_SCAN_1 B#16#05 at 0.845 s), CPU 0
// STOP; cpu_stop's repair at 1.1 s: LINK-UP 1.1 -> 1.6 s, UPDATE -> 1.745 s Redundant: OB 83
// W#16#3861 on both CPUs for the added module 1 of station 3 (IB 2..3: MDL_ADDR 2; module 0 is
// IB 0..1). DB 1 same stamp: copied; DB 2 changed: the standby's; DB 3 changed with SFB
// instances: reset (000 L1251-1254).
std::string switch_text(const std::string& variant) {
  return R"(name: "switch"
duration: "2s"
)" + kLines + R"(h_system {
  name: "H"
  dp_system { system: "S" t_pto: "1250ms" }
  cpu {
    cpu0 { power_on: "0s" } cpu1 { power_on: "0s" switch: STOP }
    startup_time: "100ms" link_up_time: "500ms"
    s7_memory { db { number: 1 size: 4 } db { number: 2 size: 4 } db { number: 3 size: 4 sfb_instances: true } }
  }
  program { scan_time: "10ms" copy { from_input: 0 to_output: 0 } }
}
fault { at: "200ms" switch_to_cpu { )" + variant +
         R"( added_module { system: "S" address: 3 module_index: 1 } changed_db: [2, 3] } }
fault { at: "1s" repair_at: "1100ms" cpu_stop { rack: 0 } }
)";
}

TEST(HScenarioFields, SwitchToCpuIsPlanned) {
  const auto r = parse_scenario(switch_text("variant: EXPANDED_MEMORY master { work_memory_kb: 1024 } standby { work_memory_kb: 2048 flash: true os_version: 3 }"), kFile);
  ASSERT_TRUE(r.ok()) << r.errors[0].str();
  const PlanFault& f = r.plan->faults.at(0);
  EXPECT_EQ(f.kind, K::HSwitchToCpu);
  EXPECT_TRUE(is_h_fault(K::HSwitchToCpu));
  EXPECT_EQ(f.description, "PG/ES: switch to CPU with expanded memory configuration");
  ASSERT_TRUE(f.cpu_switch.has_value());
  EXPECT_EQ(f.cpu_switch->variant, devices::HSwitchVariant::ExpandedMemory);
  EXPECT_EQ(f.cpu_switch->master.work_memory_kb, 1024u);
  EXPECT_EQ(f.cpu_switch->standby.work_memory_kb, 2048u);
  EXPECT_EQ(f.cpu_switch->standby.load_memory, devices::LoadMemoryType::Flash);
  EXPECT_EQ(f.cpu_switch->standby.os_version, 3u);
  ASSERT_EQ(f.cpu_switch->added.size(), 1u);
  EXPECT_EQ(f.cpu_switch->added[0].system, 0);
  EXPECT_EQ(f.cpu_switch->added[0].station, 3);
  EXPECT_EQ(f.cpu_switch->added[0].module, 1u);
  EXPECT_EQ(f.cpu_switch->changed_db, (std::vector<int>{2, 3}));
  const auto& blocks = r.plan->h_systems.at(0).runtime->changes.db_blocks;
  ASSERT_EQ(blocks.size(), 3u);
  EXPECT_FALSE(blocks[0].comm_sfb_instances);
  EXPECT_TRUE(blocks[2].comm_sfb_instances);
}

TEST(HScenarioFields, SwitchToCpuRunShowsOb1Scan1OutputsAndOb83) {
  const auto loaded = parse_scenario(switch_text("variant: MODIFIED_CONFIGURATION"), kFile);
  ASSERT_TRUE(loaded.ok()) << loaded.errors[0].str();
  Simulation sim(*loaded.plan);
  sim.start();
  devices::HSystemModel& m = sim.h_system(0).model();
  // Contents by hand: the master's DBs 11.., the standby's (new configuration) A2...
  for (std::uint16_t db = 1; db <= 3; ++db) {
    std::ranges::fill(m.s7_db(0, db), std::uint8_t{0x11});
    std::ranges::fill(m.s7_db(1, db), std::uint8_t{0xA2});
  }
  sim.run_until(*sim.duration());
  const Report rep = sim.report(1.0);
  const HSystemReport& h = rep.h_systems.at(0);
  // The swap at 0.845 s: OB 72 master swap on CPU 1.
  bool swap = false;
  for (const auto& t : h.cpus[1].timeline)
    swap |= t.kind == devices::HEvent::Kind::Ob && t.ob == 72 && t.at == 845 * kMs &&
            t.reason == devices::HReason::MasterSwap;
  EXPECT_TRUE(swap);
  // OB1_SCAN_1 = B#16#05 for the new master's first OB 1, in the report's events.
  std::vector<std::pair<bus::Ticks, int>> ob1, ob83;
  for (const HIoEvent& e : h.io_events) {
    if (e.ob == 1) ob1.emplace_back(e.at, e.racks.at(0));
    if (e.ob == 83 && e.code == 0x3861) ob83.emplace_back(e.at, e.mdl_addr.value_or(0xFFFF));
  }
  EXPECT_EQ(ob1, (std::vector<std::pair<bus::Ticks, int>>{{845 * kMs, 1}}));
  EXPECT_EQ(ob83, (std::vector<std::pair<bus::Ticks, int>>{{1745 * kMs, 2}}));
  EXPECT_EQ(h.mode, devices::SystemMode::Redundant);
  EXPECT_EQ(h.cpus[1].role, devices::CpuRole::Master);
  // 5.2.3 on the new master (CPU 1): DB 1 the master's, DB 2 its own, DB 3 reset.
  ASSERT_TRUE(m.db_copy_plan().has_value());
  EXPECT_EQ(m.db_copy_plan()->copied, (std::vector<int>{1}));
  EXPECT_EQ(m.db_copy_plan()->sfb_reset, (std::vector<int>{3}));
  const auto bytes = [&](std::uint16_t db) {
    const auto s = m.s7_db(1, db);
    return std::vector<std::uint8_t>(s.begin(), s.end());
  };
  // Read after the return to Redundant: the second update copied CPU 1's DBs to CPU 0 again.
  EXPECT_EQ(bytes(1), (std::vector<std::uint8_t>{0x11, 0x11, 0x11, 0x11}));
  EXPECT_EQ(bytes(2), (std::vector<std::uint8_t>{0xA2, 0xA2, 0xA2, 0xA2}));
  EXPECT_EQ(bytes(3), (std::vector<std::uint8_t>{0, 0, 0, 0}));
  EXPECT_EQ(h.faults.at(0).second,
            "PG/ES: switch to CPU with modified configuration (added modules at 2) (changed DBs 2, 3)");
}

// After the switch both CPUs run the new configuration: a later master_swap (the switch with
// nothing changed, 000 L1120) copies every DB. The run above, then CPU 0 (standby) to STOP at 2 s
// (Solo) and the swap at 2.1 s: LINK-UP 2.1 -> 2.6 s, UPDATE -> 2.745 s, CPU 0 master again.
TEST(HScenarioFields, MasterSwapAfterTheSwitchCopiesEveryDb) {
  std::string text = switch_text("variant: MODIFIED_CONFIGURATION");
  text.replace(text.find("duration: \"2s\""), 15, "duration: \"3s\"");
  text += "fault { at: \"2s\" cpu_stop { rack: 0 } }\nfault { at: \"2100ms\" master_swap { } }\n";
  const auto loaded = parse_scenario(text, kFile);
  ASSERT_TRUE(loaded.ok()) << loaded.errors[0].str();
  Simulation sim(*loaded.plan);
  sim.start();
  sim.run_until(*sim.duration());
  const devices::HSystemModel& m = sim.h_system(0).model();
  ASSERT_TRUE(m.db_copy_plan().has_value());
  EXPECT_EQ(m.db_copy_plan()->copied, (std::vector<int>{1, 2, 3}));
  EXPECT_TRUE(m.db_copy_plan()->sfb_reset.empty());
  const Report rep = sim.report(1.0);
  bool swap_back = false;
  for (const auto& t : rep.h_systems.at(0).cpus[0].timeline)
    swap_back |= t.kind == devices::HEvent::Kind::Ob && t.ob == 72 && t.at == 2745 * kMs &&
                 t.reason == devices::HReason::MasterSwap;
  EXPECT_TRUE(swap_back);
}

// Expanded memory without a larger memory is refused at the request (000 L1134-1138): the
// standby stays in STOP, no swap.
TEST(HScenarioFields, SwitchToCpuRefusedVariantKeepsTheMaster) {
  const test::ScenarioRun run = test::run_scenario(
      switch_text("variant: EXPANDED_MEMORY master { work_memory_kb: 1024 } standby { work_memory_kb: 1024 }"),
      kFile);
  ASSERT_TRUE(run.report) << run.error;
  const HSystemReport& h = run.report->h_systems.at(0);
  EXPECT_EQ(h.faults.at(0).second,
            "PG/ES: switch to CPU with expanded memory configuration (added modules at 2) (changed DBs 2, "
            "3): refused (the reason is in the diagnostic buffers)");
  EXPECT_EQ(h.cpus[0].role, devices::CpuRole::Master);
  EXPECT_FALSE(first_state(h.cpus[1], devices::CpuState::LinkUp).has_value());
}

// ---- watchdog OBs, OB 72 with SFC 27, partitions ----

// OB 35 every 100 ms, phase 30 ms: requests at 0.130, 0.230 ... s. The program runs from CPU 0's
// RUN at 1 s: runs at 1.030 .. 2.930 s (20). The update 3 -> 3.145 s holds the requests at 3.030
// and 3.130 s: one run at 3.145 s (000 L1179), then 3.245, 3.345, 3.445 s: 24 runs, counted in
// DB 1 DBW 0 of CPU 0 = 0x0018. OB 72 at Redundant (3.145 s) calls SFC 27 for partition 1: rack
// 3's module (partition 1) gets the PIQ then; without ob72_updat_po it is never written (0).
std::string wd_text(const std::string& ob72) {
  return R"(name: "wd"
duration: "3500ms"
h_system {
  name: "H"
  cpu { s7_memory { db { number: 1 size: 4 } } }
  expansion_rack { number: 3 side: 0 module { name: "DO8" out_len: 1 partition: 1 } }
  program {
    scan_time: "10ms"
    counter { output: 0 width: 1 period: "10ms" }
    watchdog_ob { ob: 35 cycle: "100ms" phase: "30ms" db: 1 offset: 0 width: 2 }
    )" + ob72 + R"(
  }
}
)";
}

TEST(HScenarioFields, WatchdogObsAndOb72ArePlanned) {
  const auto r = parse_scenario(wd_text("ob72_updat_po: [1]"), "h.textproto");
  ASSERT_TRUE(r.ok()) << r.errors[0].str();
  const HRuntimePlan& rt = *r.plan->h_systems.at(0).runtime;
  ASSERT_EQ(rt.changes.watchdogs.size(), 1u);
  EXPECT_EQ(rt.changes.watchdogs[0].ob, 35);
  EXPECT_EQ(rt.changes.watchdogs[0].cycle, 100 * kMs);
  EXPECT_EQ(rt.changes.watchdogs[0].phase, 30 * kMs);
  EXPECT_EQ(rt.changes.watchdogs[0].db, 1);
  EXPECT_EQ(rt.changes.ob72_updat_po, (std::vector<int>{1}));
  ASSERT_EQ(rt.racks.size(), 1u);
  EXPECT_EQ(rt.racks[0].modules.at(0).partition, 1);
}

TEST(HScenarioFields, WatchdogObRunsAndOb72RefreshesItsPartition) {
  for (const bool with_ob72 : {true, false}) {
    const auto loaded = parse_scenario(wd_text(with_ob72 ? "ob72_updat_po: [1]" : ""), "h.textproto");
    ASSERT_TRUE(loaded.ok()) << loaded.errors[0].str();
    Simulation sim(*loaded.plan);
    sim.start();
    sim.run_until(*sim.duration());
    const devices::HSystemModel& m = sim.h_system(0).model();
    const auto& runs = m.watchdog_runs();
    ASSERT_EQ(runs.size(), 24u);
    EXPECT_EQ(runs.front().at, 1030 * kMs);
    EXPECT_EQ(runs[19].at, 2930 * kMs);
    EXPECT_EQ(runs[20].at, 3145 * kMs);
    EXPECT_TRUE(runs[20].after_update);
    EXPECT_EQ(runs.back().at, 3445 * kMs);
    const auto db = sim.h_system(0).model().redundancy_returns();
    EXPECT_EQ(db, (std::vector<bus::Ticks>{3145 * kMs}));
    auto& mm = sim.h_system(0).model();
    const auto d1 = mm.s7_db(0, 1);
    EXPECT_EQ(d1[0], 0x00);
    EXPECT_EQ(d1[1], 0x18);
    const Report rep = sim.report(1.0);
    const HSystemReport& h = rep.h_systems.at(0);
    const auto out = h.racks.at(0).modules.at(0).outputs;
    ASSERT_EQ(out.size(), 1u);
    bool ob72_row = false;
    for (const HIoEvent& e : h.io_events)
      ob72_row |= e.ob == 72 && e.at == 3145 * kMs &&
                  e.text == "OB 72 redundancy restored: SFC 27 UPDAT_PO partitions 1 (000 L1752)";
    if (with_ob72) {
      EXPECT_NE(out[0], 0);  // the counter's PIQ value at 3.145 s
      EXPECT_TRUE(ob72_row);
    } else {
      EXPECT_EQ(out[0], 0);
      EXPECT_FALSE(ob72_row);
    }
  }
}

}  // namespace
}  // namespace pbvbus::tools

namespace pbvbus::tools {
namespace {

// examples/h-changes.textproto: its header's story (startup 1 s, T8 link-up 2 s, update 145 ms).
TEST(HScenarioFields, TheExampleRuns) {
  const auto loaded = load_scenario_file(PBVBUS_SOURCE_DIR "/examples/h-changes.textproto");
  ASSERT_TRUE(loaded.ok()) << loaded.errors[0].str();
  EXPECT_EQ(loaded.plan->h_systems.at(0).runtime->pair.link_up_time, 2 * kS);
  Simulation sim(*loaded.plan);
  sim.start();
  sim.run_until(*sim.duration());
  const Report rep = sim.report(1.0);
  const HSystemReport& h = rep.h_systems.at(0);
  std::vector<std::tuple<bus::Ticks, int, std::uint16_t>> rows;
  for (const HIoEvent& e : h.io_events)
    if (e.ob == 1 || e.ob == 72 || e.ob == 83) rows.emplace_back(e.at, e.ob, e.mdl_addr.value_or(0));
  EXPECT_EQ(rows, (std::vector<std::tuple<bus::Ticks, int, std::uint16_t>>{
                      {3645 * kMs, 1, 0}, {6645 * kMs, 83, 2}, {6645 * kMs, 72, 0}}));
  EXPECT_EQ(h.mode, devices::SystemMode::Redundant);
  EXPECT_EQ(h.cpus[1].role, devices::CpuRole::Master);
  const devices::HSystemModel& m = sim.h_system(0).model();
  ASSERT_TRUE(m.db_copy_plan().has_value());
  EXPECT_EQ(m.db_copy_plan()->copied, (std::vector<int>{1}));
  EXPECT_EQ(m.db_copy_plan()->sfb_reset, (std::vector<int>{3}));
}

}  // namespace
}  // namespace pbvbus::tools
