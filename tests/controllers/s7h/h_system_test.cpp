// The H-system model (devices/h_system.hpp): an HCpuPair driving one redundant DP master system
// on two bus::Lines at 1.5 Mbit/s — two switched stations (PBVB0A10 at 5, T_SLAVE_UM 30 ms;
// PBVB0A11 at 6, 820 ms) on both lines, one one-sided slave per line (PBVB0A01 at 10 on A, 11
// on B), as in redundant_master_system_test.cpp. The program (OB 1, every 10 ms) is a counter
// written into every output module through the I/O map, so "no pulse" is checkable: sampled
// after every frame on either line, a switched station's backplane outputs never drop to 0 and
// never go back to an older value once they were set.
//
// Pair timing (defaults, docs/h-system.md): STARTUP 1 s, LINK-UP 2 s, UPDATE 75 ms + 0.7 ms x
// 100 KB = 145 ms. power_on_both at t0 = 12 ms: master RUN (Solo) at t0 + 1 s = 1.012 s, standby
// LINK-UP then, UPDATE at 1.012 + 2 = 3.012 s, Redundant at 3.012 + 0.145 = 3.157 s. The scans
// start at 1.012 s and lie on 1.012 + k x 10 ms, so no check time (whole ms ending in 0 or 5)
// falls on a scan whose outputs are not sent yet — until the first update: no OB 1 in its no-I/O
// window [t3, t5), OB 1 restarts at t5 (3.157 s) and lies on 3.157 + k x 10 ms from then on.
#include "h_system_fixture.hpp"

namespace pbvbus::devices {
namespace {

// The I/O map: system 0, slaves by address (5, 6, 10, 11), modules in slot order. Station 5/6:
// module 0 16DI (2 in), module 1 16DO (2 out); 10/11: one 16DI/16DO module (2 in, 2 out).
TEST(HSystem, IoMapIsConsecutiveBySystemAddressAndSlot) {
  HSys s;
  const std::vector<HIoEntry> want{
      {0, kFast, 0, 0, 2, 0, 0}, {0, kFast, 1, 2, 0, 0, 2},  // 5: PII 0..1, PIQ 0..1
      {0, kSlow, 0, 2, 2, 2, 0}, {0, kSlow, 1, 4, 0, 2, 2},  // 6: PII 2..3, PIQ 2..3
      {0, kOneA, 0, 4, 2, 4, 2},                             // 10: PII 4..5, PIQ 4..5
      {0, kOneB, 0, 6, 2, 6, 2},                             // 11: PII 6..7, PIQ 6..7
  };
  EXPECT_EQ(s.h->io_map().entries(), want);
  EXPECT_EQ(s.h->io_map().pii_size(), 8u);
  EXPECT_EQ(s.h->io_map().piq_size(), 8u);
  ASSERT_NE(s.h->io_map().find(0, kOneB, 0), nullptr);
  EXPECT_EQ(s.h->io_map().find(0, kOneB, 1), nullptr);
  // Nothing runs before a CPU is powered: both masters dark, no scans.
  s.run_until(500 * kMs);
  EXPECT_FALSE(s.sys->attachment_powered(0));
  EXPECT_FALSE(s.sys->attachment_powered(1));
  EXPECT_EQ(s.h->scans(), 0u);
  EXPECT_EQ(s.sys->master(0).slave_stats(kFast).data_exchanges, 0u);
}

// R1/S11: STOP -> STARTUP -> Solo: only the master's line exchanges data; the standby's line
// carries no Data_Exchange until its UPDATE; then both; no 39C3/73A3 for the unstarted side.
TEST(HSystem, StartUpSoloThenRedundantBothLines) {
  HSys s;
  Sampler smp(s);
  s.at(kT0);
  s.h->power_on_both();
  EXPECT_EQ(s.h->side_mode(0, 0), Mode::Clear);  // master in STOP/STARTUP: outputs disabled
  EXPECT_EQ(s.h->side_mode(0, 1), Mode::Stop);   // standby, never ran: idle
  EXPECT_TRUE(s.ms().line_idle(1));
  s.run_until(kSolo - 1);
  EXPECT_EQ(s.h->scans(), 0u);
  EXPECT_EQ(s.station(kFast).outputs()[1], 0);  // Clear
  s.run_until(kSolo);
  EXPECT_EQ(s.h->side_mode(0, 0), Mode::Operate);
  EXPECT_EQ(s.h->pair().state(1), CpuState::LinkUp);
  s.run_until(kUpdate - 1);
  EXPECT_EQ(s.h->side_mode(0, 1), Mode::Stop);
  for (std::uint8_t a : {kFast, kSlow, kOneB}) {
    EXPECT_EQ(s.sys->master(1).slave_stats(a).data_exchanges, 0u) << int(a);
    EXPECT_GT(s.sys->master(0).slave_stats(a == kOneB ? kOneA : a).data_exchanges, 0u);
  }
  // Scans every 10 ms from 1.012 s: at 1.012, 1.022, ..., 3.002 s = 200 scans before 3.012 s.
  EXPECT_EQ(s.h->scans(), 200u);
  s.run_until(kUpdate);
  // The standby's master runs from UPDATE on, in Clear until t4 (= t5 here: T_PH = 0, no H
  // parameters), Operate from then.
  EXPECT_EQ(s.h->side_mode(0, 1), Mode::Clear);
  EXPECT_FALSE(s.ms().line_idle(1));
  s.run_until(kRedundant);
  EXPECT_EQ(s.h->side_mode(0, 1), Mode::Operate);
  EXPECT_EQ(s.h->pair().system_mode(), SystemMode::Redundant);
  s.run_until(kRedundant + 500 * kMs);
  for (std::uint8_t a : {kFast, kSlow}) {
    EXPECT_EQ(s.sys->master(1).slave_state(a), dp::SlaveStatusState::DataExchange) << int(a);
    EXPECT_EQ(s.sys->master(0).slave_state(a), dp::SlaveStatusState::DataExchange) << int(a);
    EXPECT_EQ(s.ms().active(a), 0) << int(a);
  }
  EXPECT_EQ(s.sys->master(1).slave_state(kOneB), dp::SlaveStatusState::DataExchange);
  EXPECT_TRUE(s.s7().empty());
  EXPECT_TRUE(s.h->events().empty());
  smp.expect_no_pulse(0);
  s.run_until(s.sched.now() + 3 * kMs);  // past the scan at 3.657 s (grid 3.157 + k x 10 ms)
  EXPECT_EQ(s.one_outputs(1), s.counter);  // B's one-sided slave follows the program too
}

// F1: the master CPU powers off in Redundant mode.
TEST(HSystem, F1MasterPowerOffOneMasterSystemFailureNoPulse) {
  HSys s;
  Sampler smp(s);
  s.bring_up();
  const bus::Ticks tf = 4000 * kMs;
  std::vector<int> handled;
  s.h->set_event_handler([&](const HSystemEvent& e) { handled.push_back(e.ob); });
  s.at(tf);
  s.h->power_off(0);
  EXPECT_EQ(handled, (std::vector<int>{72, 86}));
  EXPECT_EQ(s.h->model(0), s.sys.get());
  EXPECT_EQ(s.h->model(1), nullptr);
  EXPECT_EQ(s.h->pair().master(), 1);
  EXPECT_EQ(s.h->side_mode(0, 0), Mode::Unpowered);
  EXPECT_FALSE(s.sys->attachment_powered(0));
  auto ev = s.h->events();
  ASSERT_EQ(ev.size(), 2u);
  EXPECT_EQ(ev[0].source, Src::Cpu);
  EXPECT_EQ(ev[0].ob, 72);
  EXPECT_EQ(ev[0].rack, 1);
  EXPECT_EQ(ev[0].role, CpuRole::Master);
  EXPECT_EQ(ev[0].time, tf);
  EXPECT_EQ(ev[1].source, Src::Io);
  EXPECT_EQ(ev[1].ob, 86);
  EXPECT_EQ(ev[1].code, 0x39C3);
  EXPECT_EQ(ev[1].rack, 1);  // Solo: the OB runs on the new master only
  EXPECT_EQ(ev[1].system, 0);
  EXPECT_EQ(ev[1].line, 0);
  EXPECT_EQ(ev[1].time, tf);
  s.run_until(tf + 2000 * kMs);
  auto io = s.s7();
  ASSERT_EQ(io.size(), 1u);  // exactly one 39C3, no 73A3
  EXPECT_EQ(*s.ms().line_loss(0), redundancy::LineLoss::CpuFailure);
  for (std::uint8_t a : {kFast, kSlow}) {
    EXPECT_EQ(s.ms().active(a), 1) << int(a);
    EXPECT_EQ(s.station(a).primary(), 1) << int(a);
  }
  smp.expect_no_pulse(0);
  // The one-sided slave of A: no master any more, its watchdog dropped its outputs.
  EXPECT_TRUE(s.one[0]->application().outputs_safe());
  EXPECT_EQ(s.one_outputs(0), 0);
  EXPECT_EQ(s.one_outputs(1), s.counter);

  // Return: power-on 7 s -> standby, LINK-UP at once (master in Solo RUN), UPDATE at 9 s (38C3
  // then: its DP master runs), Redundant at 9.145 s.
  const bus::Ticks tb = 7000 * kMs;
  s.at(tb);
  s.h->power_on(0);
  EXPECT_EQ(s.h->pair().role(0), CpuRole::Standby);
  EXPECT_EQ(s.h->side_mode(0, 0), Mode::Stop);
  EXPECT_TRUE(s.sys->attachment_powered(0));
  s.run_until(tb + 2000 * kMs);
  EXPECT_EQ(s.h->side_mode(0, 0), Mode::Clear);  // UPDATE: Clear until t4 (= t5, T_PH = 0)
  s.run_until(tb + 2145 * kMs);
  EXPECT_EQ(s.h->side_mode(0, 0), Mode::Operate);
  io = s.s7();
  ASSERT_EQ(io.size(), 2u);
  EXPECT_EQ(io[1].code(), 0x38C3);
  EXPECT_EQ(io[1].line, 0);
  EXPECT_EQ(io[1].time, tb + 2000 * kMs);
  s.run_until(tb + 3000 * kMs);
  EXPECT_EQ(s.h->pair().system_mode(), SystemMode::Redundant);
  EXPECT_EQ(s.h->pair().role(0), CpuRole::Standby);
  for (std::uint8_t a : {kFast, kSlow}) {
    EXPECT_TRUE(s.ms().channel_up(a, 0)) << int(a);
    EXPECT_EQ(s.ms().active(a), 1) << int(a);  // no switch back
  }
  EXPECT_EQ(s.s7().size(), 2u);  // the channels came back silently
  EXPECT_EQ(s.one_outputs(0), s.counter);
  smp.expect_no_pulse(0);
}

// F5: one fibre cut -> the standby STOPs: one 39C3 for its side; the stations stay on A.
TEST(HSystem, F5OneFibreStandbyStopsOneMasterSystemFailure) {
  HSys s;
  Sampler smp(s);
  s.bring_up();
  const bus::Ticks tf = 4000 * kMs;
  s.at(tf);
  s.h->cut_fibre(0);
  EXPECT_EQ(s.h->pair().state(1), CpuState::Stop);
  EXPECT_EQ(s.h->side_mode(0, 1), Mode::Stop);
  EXPECT_EQ(s.h->side_mode(0, 0), Mode::Operate);
  s.run_until(tf + 1500 * kMs);
  const auto io = s.s7();
  ASSERT_EQ(io.size(), 1u);
  EXPECT_EQ(io[0].kind, K::MasterSystemFailure);
  EXPECT_EQ(io[0].line, 1);
  EXPECT_EQ(io[0].time, tf);
  const auto ev = s.events(Src::Io);
  ASSERT_EQ(ev.size(), 1u);
  EXPECT_EQ(ev[0].rack, 0);
  for (std::uint8_t a : {kFast, kSlow}) EXPECT_EQ(s.ms().active(a), 0) << int(a);
  EXPECT_EQ(s.ms().switchovers(), 0u);
  smp.expect_no_pulse(0);
  EXPECT_TRUE(s.one[1]->application().outputs_safe());
}

// F6: both fibres at once -> two masters in RUN, each side follows its own CPU: both Operate,
// no I/O event, both lines keep exchanging data.
TEST(HSystem, F6BothFibresTwoMastersBothSidesOperate) {
  HSys s;
  Sampler smp(s);
  s.bring_up();
  const bus::Ticks tf = 4000 * kMs;
  s.at(tf);
  const auto dx = s.sys->master(1).slave_stats(kFast).data_exchanges;
  s.h->cut_both_fibres();
  EXPECT_EQ(s.h->pair().master_count(), 2);
  EXPECT_EQ(s.h->side_mode(0, 0), Mode::Operate);
  EXPECT_EQ(s.h->side_mode(0, 1), Mode::Operate);
  s.run_until(tf + 1000 * kMs);
  EXPECT_TRUE(s.s7().empty());
  EXPECT_EQ(s.events(Src::Cpu).size(), 2u);  // OB 72 on both
  EXPECT_GT(s.sys->master(1).slave_stats(kFast).data_exchanges, dx);
  smp.expect_no_pulse(0);
}

// F9 under the model: the DP master module of A fails on its own -> per-station events as
// before (73A3 x 2, 39C4 for 10), on both CPUs (Redundant: rack -1); the CPU stays in RUN and a
// reconciliation does not power the failed module again; the repair does.
TEST(HSystem, F9MasterModuleFailureUnchanged) {
  HSys s;
  Sampler smp(s);
  s.bring_up();
  const bus::Ticks tf = 4000 * kMs;
  s.at(tf);
  s.sys->fail_master(0);
  s.h->reconcile();
  EXPECT_FALSE(s.sys->attachment_powered(0));
  s.run_until(tf + 1000 * kMs);
  const auto ev = s.events(Src::Io);
  ASSERT_EQ(ev.size(), 3u);
  int r73 = 0, r39 = 0;
  for (const auto& e : ev) {
    EXPECT_EQ(e.rack, -1);
    EXPECT_EQ(e.time, tf);
    if (e.code == 0x73A3) ++r73;
    if (e.code == 0x39C4 && e.station == kOneA) ++r39;
  }
  EXPECT_EQ(r73, 2);
  EXPECT_EQ(r39, 1);
  EXPECT_EQ(s.h->leds(0).busf[0], BusLed::On);  // interface fault
  EXPECT_EQ(s.h->pair().system_mode(), SystemMode::Redundant);
  smp.expect_no_pulse(0);
  s.sys->repair_master(0);
  EXPECT_TRUE(s.sys->attachment_powered(0));
}

// Operator master swap: the standby (switch at STOP) links up on request; after the update it is
// master (Solo) and the old master STOPs -> one 39C3 for line A, every station to B, no pulse;
// the one-sided outputs of A drop.
TEST(HSystem, OperatorMasterSwapMovesStationsWithoutPulse) {
  HCpuPairParams p;
  p.switch_run = {true, false};
  HSys s(p);
  Sampler smp(s);
  s.at(kT0);
  s.h->power_on_both();
  s.run_until(1500 * kMs);
  ASSERT_EQ(s.h->pair().system_mode(), SystemMode::Solo);
  EXPECT_EQ(s.h->side_mode(0, 1), Mode::Stop);
  EXPECT_TRUE(s.h->request_master_swap());
  // LINK-UP 1.5 s -> 3.5 s, UPDATE 3.5 s -> 3.645 s, then the swap.
  const bus::Ticks up = 3500 * kMs, swap = up + 145 * kMs;
  s.run_until(up);
  EXPECT_EQ(s.h->side_mode(0, 1), Mode::Clear);  // UPDATE: Clear until t4 (= t5, T_PH = 0)
  s.run_until(swap);
  EXPECT_EQ(s.h->side_mode(0, 1), Mode::Operate);
  EXPECT_EQ(s.h->pair().master(), 1);
  EXPECT_EQ(s.h->side_mode(0, 0), Mode::Stop);
  s.run_until(swap + 2000 * kMs);
  const auto io = s.s7();
  ASSERT_EQ(io.size(), 1u);
  EXPECT_EQ(io[0].kind, K::MasterSystemFailure);
  EXPECT_EQ(io[0].line, 0);
  EXPECT_EQ(io[0].time, swap);
  for (std::uint8_t a : {kFast, kSlow}) {
    EXPECT_EQ(s.ms().active(a), 1) << int(a);
    EXPECT_EQ(s.station(a).primary(), 1) << int(a);
  }
  smp.expect_no_pulse(0);
  EXPECT_TRUE(s.one[0]->application().outputs_safe());
  s.run_until(s.sched.now() + 3 * kMs);  // OB 1 restarts at t5 of each update: off the grid
  EXPECT_EQ(s.one_outputs(1), s.counter);
  const auto cpu = s.events(Src::Cpu);
  ASSERT_EQ(cpu.size(), 1u);
  EXPECT_EQ(cpu[0].ob, 72);
  EXPECT_EQ(cpu[0].rack, 1);
  EXPECT_EQ(cpu[0].time, swap);
}

// The automatic swap after ERROR-SEARCH (self-test 1 s here): the standby's line is lost while
// it searches (39C3 on B) and back at its UPDATE (38C3); at the end of the update the roles swap
// with both CPUs in RUN: nothing stopped, so the active channels stay on A; no pulse.
TEST(HSystem, AutomaticSwapAfterErrorSearchKeepsChannels) {
  HCpuPairParams p;
  p.self_test_time = 1000 * kMs;
  HSys s(p);
  Sampler smp(s);
  s.bring_up();
  const bus::Ticks te = 4000 * kMs;
  s.at(te);
  EXPECT_TRUE(s.h->inject_comparison_error());
  EXPECT_EQ(s.h->pair().state(1), CpuState::ErrorSearch);
  EXPECT_EQ(s.h->side_mode(0, 1), Mode::Stop);
  // Self-test 4 -> 5 s, LINK-UP 5 -> 7 s, UPDATE 7 -> 7.145 s, swap.
  const bus::Ticks up = te + 3000 * kMs, swap = up + 145 * kMs;
  s.run_until(te + 1500 * kMs);
  EXPECT_TRUE(s.one[1]->application().outputs_safe());  // B's master stopped: 11 dropped
  EXPECT_EQ(s.one_outputs(0), s.counter);
  s.run_until(swap + 1003 * kMs);  // OB 1 restarted at the swap (t5): 8.145 s is a scan
  EXPECT_EQ(s.one_outputs(1), s.counter);  // back with B's master
  EXPECT_EQ(s.h->pair().master(), 1);
  EXPECT_EQ(s.h->pair().system_mode(), SystemMode::Redundant);
  const auto io = s.s7();
  ASSERT_EQ(io.size(), 2u);
  EXPECT_EQ(io[0].code(), 0x39C3);
  EXPECT_EQ(io[0].line, 1);
  EXPECT_EQ(io[0].time, te);
  EXPECT_EQ(io[1].code(), 0x38C3);
  EXPECT_EQ(io[1].line, 1);
  EXPECT_EQ(io[1].time, up);
  for (std::uint8_t a : {kFast, kSlow}) EXPECT_EQ(s.ms().active(a), 0) << int(a);
  EXPECT_EQ(s.h->side_mode(0, 0), Mode::Operate);
  EXPECT_EQ(s.h->side_mode(0, 1), Mode::Operate);
  smp.expect_no_pulse(0);
}

// System STOP: the master (alone, the standby's switch at STOP) is switched to STOP: it still
// accesses the switched I/O but in Clear: the outputs go to 0; the scans stop.
TEST(HSystem, SystemStopClearsOutputs) {
  HCpuPairParams p;
  p.switch_run = {true, false};
  HSys s(p);
  s.at(kT0);
  s.h->power_on_both();
  s.run_until(2000 * kMs);
  ASSERT_NE(s.station(kFast).outputs()[1] | s.station(kFast).outputs()[0], 0);
  s.h->switch_to_stop(0);
  EXPECT_EQ(s.h->pair().state(0), CpuState::Stop);
  EXPECT_EQ(s.h->side_mode(0, 0), Mode::Clear);
  const auto scans = s.h->scans();
  s.run_until(2200 * kMs);
  EXPECT_EQ(s.h->scans(), scans);
  for (std::uint8_t a : {kFast, kSlow}) {
    EXPECT_EQ(s.station(a).outputs()[0], 0) << int(a);
    EXPECT_EQ(s.station(a).outputs()[1], 0) << int(a);
  }
  EXPECT_EQ(s.one_outputs(0), 0);
  EXPECT_TRUE(s.s7().empty());
}

// BUSxF: a short circuit on line A -> BUS1F on for CPU 0 (line A), off for CPU 1; a one-sided
// station on B fails -> BUS1F flashing for CPU 1; a CPU off -> dark.
TEST(HSystem, BusFaultLeds) {
  HSys s;
  s.bring_up();
  EXPECT_EQ(s.h->leds(0).busf, std::vector<BusLed>{BusLed::Off});
  s.at(4000 * kMs);
  s.line[0].set_short_circuit(true);
  s.run_until(4500 * kMs);
  EXPECT_EQ(s.h->leds(0).busf[0], BusLed::On);
  EXPECT_EQ(s.h->leds(1).busf[0], BusLed::Off);
  s.line[0].set_short_circuit(false);
  s.run_until(6000 * kMs);
  EXPECT_EQ(s.h->leds(0).busf[0], BusLed::Off);
  s.line[1].set_power(s.one_att[1], false);
  s.run_until(6500 * kMs);
  EXPECT_EQ(s.h->leds(1).busf[0], BusLed::Flashing);
  EXPECT_EQ(s.h->leds(0).busf[0], BusLed::Off);
  s.h->power_off(1);
  EXPECT_EQ(s.h->leds(1).busf[0], BusLed::Off);
  EXPECT_FALSE(s.h->leds(1).cpu.rack1);
}

// The diagnostic buffer: the pair's entries and the I/O events merged by time, the CPU's first at
// one instant; each powered CPU logs the I/O event with its own role.
TEST(HSystem, DiagBufferMergesCpuAndIoEntries) {
  HSys s;
  s.bring_up();
  const bus::Ticks tf = 4000 * kMs;
  s.at(tf);
  s.h->cut_fibre(0);
  const std::string text = "OB 86 W#16#39C3 master system failure, DP master system 1, line B";
  for (int r = 0; r < 2; ++r) {
    const auto d = s.h->diag_buffer(r);
    ASSERT_FALSE(d.empty());
    for (std::size_t i = 1; i < d.size(); ++i) EXPECT_LE(d[i - 1].at, d[i].at) << r;
    auto it = std::find_if(d.begin(), d.end(), [&](const DiagEntry& e) { return e.text == text; });
    ASSERT_NE(it, d.end()) << r;
    EXPECT_EQ(it->at, tf);
    EXPECT_EQ(it->code, 0x39C3);
    EXPECT_EQ(it->role, r == 0 ? CpuRole::Master : CpuRole::Standby);
    // Every CPU entry at tf comes before it, and it is the last entry.
    EXPECT_EQ(it + 1, d.end()) << r;
    const auto& cpu = s.h->pair().diag_buffer(r);
    EXPECT_EQ(d.size(), cpu.size() + 1) << r;
    EXPECT_EQ(cpu.back().at, tf) << r;  // the pair logged the cut at the same instant
  }
}

// The program's inputs come through the I/O map (the one-sided slave 10's module at PII 4..5);
// the I/O gate skips whole scans: the hook does not run and the outputs stay as they were.
// Solo from 1.012 s, scans at 1.012 + k x 10 ms; the gate is shut for [2.000 s, 2.100 s):
// the scans at 2.002, 2.012, ..., 2.092 s (10) are skipped. Until 2.5 s: k = 0..148 = 149
// scan times, 149 - 10 = 139 scans run.
TEST(HSystem, InputsThroughTheMapAndTheIoGate) {
  HCpuPairParams p;
  p.switch_run = {true, false};
  HSys s(p);
  const Bytes in{0x12, 0x34};
  ASSERT_TRUE(s.one[0]->application().write_inputs(0, in));
  s.h->set_io_gate([](bus::Ticks now) { return now < 2000 * kMs || now >= 2100 * kMs; });
  s.at(kT0);
  s.h->power_on_both();
  s.run_until(1995 * kMs);
  EXPECT_EQ(s.h->pii()[4], 0x12);
  EXPECT_EQ(s.h->pii()[5], 0x34);
  EXPECT_EQ(s.h->pii()[6], 0x00);  // 11 on B: no active channel (B never ran), last value 0
  s.run_until(2000 * kMs);
  const int frozen = s.station(kFast).outputs()[1] | (s.station(kFast).outputs()[0] << 8);
  EXPECT_NE(frozen, 0);
  s.run_until(2095 * kMs);
  EXPECT_EQ(s.station(kFast).outputs()[1] | (s.station(kFast).outputs()[0] << 8), frozen);
  s.run_until(2500 * kMs);
  EXPECT_EQ(s.h->scans(), 139u);
  EXPECT_EQ(s.counter, 139);
}

// A CPU never powered is no lost line: the master alone runs Solo, its partner's side stays
// dark and idle, no I/O event at all; the master's power-off then loses line A only (one 39C3,
// no OB: no CPU runs a program, and no CPU is powered to log it).
TEST(HSystem, NeverPoweredPartnerIsNoLineLoss) {
  HSys s;
  s.at(kT0);
  s.h->power_on(0);
  s.run_until(3000 * kMs);
  EXPECT_EQ(s.h->pair().system_mode(), SystemMode::Solo);
  EXPECT_EQ(s.h->side_mode(0, 1), Mode::Unpowered);
  EXPECT_FALSE(s.sys->attachment_powered(1));
  EXPECT_TRUE(s.ms().line_idle(1));
  EXPECT_TRUE(s.s7().empty());
  for (std::uint8_t a : {kFast, kSlow}) EXPECT_EQ(s.ms().active(a), 0) << int(a);
  s.h->power_off(0);
  const auto io = s.s7();
  ASSERT_EQ(io.size(), 1u);
  EXPECT_EQ(io[0].code(), 0x39C3);
  EXPECT_EQ(io[0].line, 0);
  EXPECT_EQ(io[0].time, 3000 * kMs);
  EXPECT_TRUE(s.h->events().empty());
  EXPECT_EQ(s.h->diag_buffer(0).size(), s.h->pair().diag_buffer(0).size());
}

// Two master systems: the second system's modules follow the first's in both images (PII/PIQ
// 8..9 for its slave at 3); a null system is dropped.
TEST(HSystem, IoMapSecondSystemFollowsTheFirst) {
  HSys s;
  const GsdFile plain = load("PBVB0A01.gsd");
  auto sp = master_slave_params(plain, plain_modules(), 3);
  ASSERT_TRUE(sp.ok());
  RedundantMasterSystemOptions o;
  o.bus_params = s.bp;
  RedundantMasterSystemModel second(o, {*sp.value}, {}, {});
  const std::vector<RedundantMasterSystemModel*> both{s.sys.get(), &second};
  const HIoMap map(both);
  ASSERT_EQ(map.entries().size(), 7u);
  EXPECT_EQ(map.entries()[6], (HIoEntry{1, 3, 0, 8, 2, 8, 2}));
  EXPECT_EQ(map.pii_size(), 10u);
  EXPECT_EQ(map.piq_size(), 10u);
  bus::Scheduler other;
  HSystemModel h(other, {}, {nullptr, &second});
  EXPECT_EQ(h.master_systems().size(), 1u);
  EXPECT_EQ(h.io_map().entries(), (std::vector<HIoEntry>{{0, 3, 0, 0, 2, 0, 2}}));
  EXPECT_EQ(h.leds(0).busf.size(), 1u);
  EXPECT_EQ(h.leds(2).busf.size(), 0u);  // bad rack: empty, no crash
}

}  // namespace
}  // namespace pbvbus::devices
