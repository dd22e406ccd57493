// HSystemModel::ps_failure / ps_repair (F1 with a PS 407 10A R pair), checksum_error
// (001 Table 5-6) and the switch to CPU with modified configuration (HSystemSwap) on the DP
// master systems (docs/h-changes.md); fixture h_system_fixture.hpp:
// Redundant at kRedundant = 3.157 s, CPU 0 master.
#include "h_system_fixture.hpp"
#include "pbvbus/s7h/h_dp_startup.hpp"
#include "pbvbus/s7h/h_rack_power.hpp"

namespace pbvbus::devices {
namespace {

int count_code(const std::vector<DiagEntry>& d, std::uint16_t code) {
  return static_cast<int>(std::count_if(d.begin(), d.end(), [&](const DiagEntry& e) { return e.code == code; }));
}

TEST(HSystemPower, F1HalfPsNoEffectBothHalvesMasterSystemFailure) {
  HSys s;
  Sampler smp(s);
  s.bring_up();
  const bus::Ticks t1 = 4000 * kMs;
  s.at(t1);
  EXPECT_FALSE(s.h->ps_failure(0, 1));
  EXPECT_TRUE(s.h->events().empty());  // no OB 72, no 39C3
  EXPECT_EQ(s.h->pair().system_mode(), SystemMode::Redundant);
  EXPECT_EQ(count_code(s.h->diag_buffer(0), 0x3923), 1);
  EXPECT_EQ(count_code(s.h->diag_buffer(1), 0x3923), 0);
  EXPECT_FALSE(s.h->ps_failure(0, 1));  // already failed
  const bus::Ticks t2 = 5000 * kMs;
  s.at(t2);
  EXPECT_TRUE(s.h->ps_failure(0, 0));  // the second half: as cpu_failure (F1)
  EXPECT_EQ(s.h->pair().state(0), CpuState::Off);
  EXPECT_EQ(s.h->pair().master(), 1);
  auto ev = s.h->events();
  ASSERT_EQ(ev.size(), 2u);
  EXPECT_EQ(ev[0].ob, 72);
  EXPECT_EQ(ev[0].time, t2);
  EXPECT_EQ(ev[1].code, 0x39C3);
  // One half back: power returns, CPU 0 links up as standby (2 s + 145 ms), Redundant.
  const bus::Ticks t3 = 6000 * kMs;
  s.at(t3);
  EXPECT_TRUE(s.h->ps_repair(0, 0));
  s.run_until(t3 + 2145 * kMs);
  EXPECT_EQ(s.h->pair().system_mode(), SystemMode::Redundant);
  EXPECT_EQ(s.h->pair().master(), 1);
  EXPECT_TRUE(s.h->ps_repair(0, 1));  // the other half replaced: the outgoing entry
  EXPECT_EQ(count_code(s.h->diag_buffer(0), 0x3823), 1);
  EXPECT_FALSE(s.h->ps_repair(0, 1));
  smp.expect_no_pulse(t1);
}

TEST(HSystemPower, ChecksumErrorInRedundantStandbyToErrorSearch) {
  HSys s;
  s.bring_up();
  const bus::Ticks t = 4000 * kMs;
  s.at(t);
  EXPECT_TRUE(s.h->checksum_error(1));
  EXPECT_EQ(s.h->pair().state(1), CpuState::ErrorSearch);
  EXPECT_EQ(s.h->pair().system_mode(), SystemMode::Solo);
  const auto& ev = s.h->events();
  ASSERT_FALSE(ev.empty());
  EXPECT_EQ(ev[0].ob, 72);
  EXPECT_EQ(ev[0].rack, 0);
  EXPECT_EQ(ev[0].time, t);
  EXPECT_EQ(s.h->side_mode(0, 1), Mode::Stop);  // ERROR-SEARCH: its DP master stops
  EXPECT_FALSE(s.h->checksum_error(2));
}

// 001 L8094-8113: the master's DP master system starts with the CPU (kT0, STARTUP 1 s); the
// one-sided station 10 on line A is switched off, so it cannot be parameterised: with a
// monitoring time of 10 x 100 ms = 1 s the CPU enters W#16#6547 at kT0 + 1 s naming it;
// stations 5 and 6 reach data exchange in time. The start-up goes on (RUN at kT0 + 1 s).
TEST(HSystemPower, ParamTransferMonitoringW6547OnTheMastersStartUp) {
  HSys s;
  s.line[0].set_power(s.one_att[0], false);
  HDpStartupMonitor mon(
      [&](int r, bus::Ticks, std::string t, std::uint16_t c) { s.h->log_entry(r, std::move(t), c); },
      10, {kFast, kSlow, kOneA});
  s.at(kT0);
  s.h->power_on_both();
  mon.start(0, kT0);
  const bus::Ticks end = kT0 + 1000 * kMs;
  ASSERT_EQ(mon.next_deadline(), end);
  for (bus::Ticks t = kT0 + kMs; t < end; t += kMs) {  // 1 ms steps, virtual time
    s.run_until(t);
    for (std::uint8_t a : {kFast, kSlow, kOneA})
      if (s.sys->master(0).slave_state(a) == dp::SlaveStatusState::DataExchange)
        mon.data_exchange(a, t);
  }
  s.run_until(end);
  mon.on_time(end);
  EXPECT_EQ(mon.late(), (std::vector<std::uint8_t>{kOneA}));
  int n = 0;
  for (const auto& d : s.h->diag_buffer(0))
    if (d.code == 0x6547) {
      ++n;
      EXPECT_EQ(d.at, end);
      EXPECT_EQ(d.text, "transfer of parameters to modules: monitoring time exceeded, stations 10");
    }
  EXPECT_EQ(n, 1);
  EXPECT_EQ(s.h->pair().state(0), CpuState::Run);
}

// The same started by the model (set_param_transfer_time, h_system_dp_startup.cpp): CPU 0
// enters STARTUP at kT0, monitoring 10 x 100 ms = 1 s -> W#16#6547 at kT0 + 1 s naming station
// 10 (switched off); CPU 1's own monitoring starts at its UPDATE (kUpdate) and ends at
// kUpdate + 1 s with every station of line B in data exchange: no entry there.
TEST(HSystemPower, ModelStartsParamTransferMonitoringW6547) {
  HSys s;
  s.line[0].set_power(s.one_att[0], false);
  s.h->set_param_transfer_time(10);
  EXPECT_EQ(s.h->param_transfer_time_100ms(), 10u);
  s.at(kT0);
  s.h->power_on_both();
  const bus::Ticks end = kT0 + 1000 * kMs;
  s.run_until(end - kMs);
  EXPECT_EQ(count_code(s.h->diag_buffer(0), 0x6547), 0);
  s.run_until(end);
  int n = 0;
  for (const auto& d : s.h->diag_buffer(0))
    if (d.code == 0x6547) {
      ++n;
      EXPECT_EQ(d.at, end);
      EXPECT_EQ(d.text, "transfer of parameters to modules: monitoring time exceeded, stations 10");
    }
  EXPECT_EQ(n, 1);
  EXPECT_EQ(s.h->param_transfer_late(0), (std::vector<std::uint8_t>{kOneA}));
  s.run_until(kUpdate + 1100 * kMs);
  EXPECT_EQ(count_code(s.h->diag_buffer(1), 0x6547), 0);
  EXPECT_TRUE(s.h->param_transfer_late(1).empty());
  EXPECT_EQ(count_code(s.h->diag_buffer(0), 0x6547), 1);
}

// ---- the switch to CPU with modified configuration on the model (docs/h-changes.md "In the
// H-system model"; 000 §10.4.6 L3364-3388, §10.4.7 L3400-3416) ----

const std::string kNote =
    "PG/ES: switch to CPU with modified configuration: no blocks copied; data blocks as 5.2.3";

bool has_entry(const std::vector<DiagEntry>& d, bus::Ticks at, const std::string& text) {
  return std::any_of(d.begin(), d.end(),
                     [&](const DiagEntry& e) { return e.at == at && e.text == text; });
}

// Fixture times (STARTUP 1 s, LINK-UP 2 s, UPDATE 75 ms + 0.7 ms x 100 KB = 145 ms, OB 1 every
// 10 ms), expansion rack 3 on CPU 0, rack 9 on CPU 1, one DO16 each (2 octets of the counter):
//   3.157 s  Redundant, CPU 0 master: both racks take the counter at every OB 1
//   4 s      CPU 1's mode switch to STOP: Solo; rack 9 is no longer addressed (holds its value)
//   4.5 s    "switch to CPU with modified configuration", switched module 512 added:
//            LINK-UP 4.5 -> 6.5 s, UPDATE 6.5 -> 6.645 s = t5: CPU 1 master, CPU 0 STOP
//   6.645 s  OB 1 restarts at t5: OB1_SCAN_1 = B#16#05; rack 9 reset to 0 and not written
//   6.655 s  the next OB 1 (B#16#03) writes rack 9: 0 for one cycle [6.645, 6.655)
//   9 s      CPU 0 to RUN: LINK-UP 9 -> 11 s, UPDATE 11 -> 11.145 s: Redundant, OB 83
//            W#16#3861 for module 512 on both CPUs; CPU 0's substitute values end there
TEST(HSystemSwap, ModifiedConfigurationSequenceOnTheModel) {
  HSys s;
  const HRackModule dq{"DO16", 0, 2, {}, 0};
  s.h->set_expansion_racks({HExpansionRack{3, 0, {dq}}, HExpansionRack{9, 1, {dq}}});
  std::vector<std::pair<bus::Ticks, std::uint8_t>> scans;  // (OB 1 start, OB1_SCAN_1)
  s.h->set_program(
      [&](std::span<const std::uint8_t>, std::span<std::uint8_t> piq, bus::Ticks now) {
        ++s.counter;
        scans.emplace_back(now, s.h->ob1_scan_1());
        for (std::size_t i = 0; i + 1 < piq.size(); i += 2) {
          piq[i] = static_cast<std::uint8_t>(s.counter >> 8);
          piq[i + 1] = static_cast<std::uint8_t>(s.counter);
        }
      },
      kScan);
  Sampler smp(s);  // S9: the switched stations' outputs never drop across the swaps
  auto rack = [&](int n) {
    const auto o = s.h->rack_outputs(n, 0);
    return static_cast<std::uint16_t>((o[0] << 8) | o[1]);
  };
  s.bring_up();
  EXPECT_EQ(rack(3), s.counter);
  EXPECT_EQ(rack(9), s.counter);
  s.at(4000 * kMs);
  s.h->switch_to_stop(1);
  EXPECT_EQ(s.h->pair().system_mode(), SystemMode::Solo);
  const std::uint16_t held9 = rack(9);
  EXPECT_NE(held9, 0);
  const bus::Ticks req = 4500 * kMs, swap = 6645 * kMs;
  s.at(req);
  const HCpuConfig cfg{2048, 1024, LoadMemoryType::Ram, 0x040500};
  ASSERT_TRUE(s.h->switch_to_cpu(HSwitchVariant::ModifiedConfiguration, cfg, cfg, {512}));
  EXPECT_TRUE(has_entry(s.h->diag_buffer(0), req, kNote));
  EXPECT_EQ(s.h->pair().state(1), CpuState::LinkUp);
  s.run_until(swap - kMs);
  EXPECT_EQ(s.h->pair().master(), 0);
  EXPECT_EQ(rack(9), held9);
  const std::uint16_t held3 = rack(3);
  s.run_until(swap);
  ASSERT_EQ(s.h->pair().master(), 1);
  EXPECT_EQ(s.h->pair().state(0), CpuState::Stop);
  const HConfigChange* cc = s.h->config_change();
  ASSERT_NE(cc, nullptr);
  ASSERT_TRUE(cc->swap_time().has_value());
  EXPECT_EQ(*cc->swap_time(), swap);
  EXPECT_EQ(s.h->first_ob1_after_swap(), (std::vector<bus::Ticks>{swap}));
  ASSERT_FALSE(scans.empty());
  EXPECT_EQ(scans.back(), (std::pair<bus::Ticks, std::uint8_t>{swap, 0x05}));
  EXPECT_EQ(rack(9), 0);  // reset, and the first OB 1 did not write it
  EXPECT_TRUE(cc->central_outputs_zero(1, swap));
  EXPECT_EQ(rack(3), held3);  // the old master's central module is no longer addressed
  s.run_until(swap + kScan);
  EXPECT_EQ(scans.back(), (std::pair<bus::Ticks, std::uint8_t>{swap + kScan, 0x03}));
  EXPECT_EQ(rack(9), s.counter);
  EXPECT_FALSE(cc->central_outputs_zero(1, swap + kScan));
  const auto after_swap = [](const auto& x) { return x.second == 0x05; };
  EXPECT_EQ(std::count_if(scans.begin(), scans.end(), after_swap), 1);
  // The old master's one-sided DP station 10: its DP master stopped, fail-safe (substitute).
  s.run_until(swap + 2000 * kMs);
  EXPECT_TRUE(s.one[0]->application().outputs_safe());
  EXPECT_TRUE(cc->one_sided_substitute(0, s.sched.now()));
  EXPECT_EQ(rack(3), held3);
  auto ob83 = [&] {
    std::vector<HSystemEvent> v;
    for (const auto& e : s.h->events())
      if (e.ob == 83) v.push_back(e);
    return v;
  };
  EXPECT_TRUE(ob83().empty());
  s.at(9000 * kMs);
  s.h->switch_to_run(0);
  const bus::Ticks red = 11145 * kMs;
  s.run_until(red - kMs);
  EXPECT_NE(s.h->pair().system_mode(), SystemMode::Redundant);
  s.run_until(red);
  ASSERT_EQ(s.h->pair().system_mode(), SystemMode::Redundant);
  EXPECT_EQ(s.h->pair().master(), 1);  // no swap back (000 L3400-3416)
  const auto e83 = ob83();
  ASSERT_EQ(e83.size(), 1u);
  EXPECT_EQ(e83[0].time, red);
  EXPECT_EQ(e83[0].rack, -1);
  EXPECT_EQ(e83[0].code, 0x3861);
  EXPECT_EQ(e83[0].mdl_addr, 512);
  EXPECT_EQ(e83[0].source, Src::Alarm);
  const std::string t83 =
      "OB 83: module inserted (switched, address 512): new configuration, ignore (000 L3412)";
  EXPECT_TRUE(has_entry(s.h->diag_buffer(0), red, t83));
  EXPECT_TRUE(has_entry(s.h->diag_buffer(1), red, t83));
  EXPECT_TRUE(cc->one_sided_substitute(0, red - kMs));
  EXPECT_FALSE(cc->one_sided_substitute(0, red));
  s.run_until(red + 1000 * kMs);
  EXPECT_FALSE(s.one[0]->application().outputs_safe());  // CPU 0's DP master drives it again
  EXPECT_EQ(rack(3), s.counter);                         // and its central module
  smp.expect_no_pulse(0);
}

// The operator's swap (request_master_swap, the scenario's master_swap) is that switch with
// nothing changed (000 L1120). CPU 1's switch at STOP: request at 1.5 s, LINK-UP 1.5 -> 3.5 s,
// UPDATE 3.5 -> 3.645 s: the new master's first OB 1 at 3.645 s has B#16#05.
TEST(HSystemSwap, OperatorSwapIsTheSwitchWithNothingChanged) {
  HCpuPairParams p;
  p.switch_run = {true, false};
  HSys s(p);
  s.at(kT0);
  s.h->power_on_both();
  s.run_until(1500 * kMs);
  EXPECT_EQ(s.h->config_change(), nullptr);
  EXPECT_EQ(s.h->ob1_scan_1(), 0x03);
  ASSERT_TRUE(s.h->request_master_swap());
  ASSERT_NE(s.h->config_change(), nullptr);
  EXPECT_TRUE(has_entry(s.h->diag_buffer(0), 1500 * kMs, kNote));
  const bus::Ticks swap = 3645 * kMs;
  s.run_until(swap);
  ASSERT_TRUE(s.h->config_change()->swap_time().has_value());
  EXPECT_EQ(*s.h->config_change()->swap_time(), swap);
  EXPECT_EQ(s.h->first_ob1_after_swap(), (std::vector<bus::Ticks>{swap}));
  EXPECT_EQ(s.h->ob1_scan_1(), 0x05);
  s.run_until(swap + kScan);
  EXPECT_EQ(s.h->ob1_scan_1(), 0x03);
  EXPECT_TRUE(s.h->config_change()->ob83_modules().empty());
}

// 000 L1134-1138: a refused variant (expanded memory without an enlargement): the standby stays
// in STOP, the master in RUN, the same entry on both CPUs at the request; no swap later.
TEST(HSystemSwap, RefusedVariantStandbyStaysInStop) {
  HCpuPairParams p;
  p.switch_run = {true, false};
  HSys s(p);
  s.at(kT0);
  s.h->power_on_both();
  s.run_until(1500 * kMs);
  const HCpuConfig cfg{2048, 1024, LoadMemoryType::Ram, 0x040500};
  EXPECT_FALSE(s.h->switch_to_cpu(HSwitchVariant::ExpandedMemory, cfg, cfg));
  const std::string t =
      "PG/ES: switch to CPU with expanded memory configuration refused: standby CPU stays in "
      "STOP: memory not enlarged";
  EXPECT_TRUE(has_entry(s.h->diag_buffer(0), 1500 * kMs, t));
  EXPECT_TRUE(has_entry(s.h->diag_buffer(1), 1500 * kMs, t));
  s.run_until(3700 * kMs);
  EXPECT_EQ(s.h->pair().state(1), CpuState::Stop);
  EXPECT_EQ(s.h->pair().master(), 0);
  EXPECT_TRUE(s.h->first_ob1_after_swap().empty());
}

// 000 L640, 001 L1149-1153 on the model (set_rack_power): RAM test 8 s per MB after an
// unbuffered POWER ON; ram_kb = 256 -> 256 x 8 s / 1024 = 2 s.
//   12 ms     both racks switched on, the first power-on (unbuffered): RAM tests to 2.012 s
//   2.012 s   the pair's POWER ON of both (rack 0 first): STARTUP 1 s -> CPU 0 RUN at 3.012 s,
//             CPU 1 LINK-UP 3.012 -> 5.012 s, UPDATE -> 5.157 s Redundant
//   6 s / 6.5 s  rack 1 (no battery) off and on again: RAM test to 8.5 s, then LINK-UP
//             8.5 -> 10.5 s; rack 0 has its battery: off at 11 s, on at 11.5 s: at once
TEST(HSystemPower, RamTestLengthensThePowerOnOfTheModel) {
  HSys s;
  HRackPowerParams rp;
  rp.ram_kb = 256;
  rp.battery = {true, false};
  s.h->set_rack_power(rp);
  ASSERT_NE(s.h->rack_power(), nullptr);
  s.at(kT0);
  s.h->power_on_both();
  EXPECT_TRUE(s.h->rack_power()->self_testing(0));
  EXPECT_TRUE(s.h->rack_power()->self_testing(1));
  const bus::Ticks on = kT0 + 2000 * kMs;
  s.run_until(on - kMs);
  EXPECT_EQ(s.h->pair().state(0), CpuState::Off);
  EXPECT_EQ(s.h->pair().state(1), CpuState::Off);
  EXPECT_EQ(s.h->side_mode(0, 0), Mode::Unpowered);
  s.run_until(on);
  EXPECT_FALSE(s.h->rack_power()->self_testing(0));
  EXPECT_NE(s.h->pair().state(0), CpuState::Off);
  EXPECT_NE(s.h->pair().state(1), CpuState::Off);
  s.run_until(on + 1000 * kMs);
  EXPECT_EQ(s.h->pair().state(0), CpuState::Run);
  s.run_until(on + 3145 * kMs);
  EXPECT_EQ(s.h->pair().system_mode(), SystemMode::Redundant);
  s.at(6000 * kMs);
  s.h->power_off(1);
  EXPECT_EQ(s.h->pair().state(1), CpuState::Off);
  s.at(6500 * kMs);
  s.h->power_on(1);
  EXPECT_TRUE(s.h->rack_power()->self_testing(1));
  s.run_until(8500 * kMs - kMs);
  EXPECT_EQ(s.h->pair().state(1), CpuState::Off);
  s.run_until(8500 * kMs);
  EXPECT_NE(s.h->pair().state(1), CpuState::Off);
  s.at(11000 * kMs);
  EXPECT_EQ(s.h->pair().system_mode(), SystemMode::Redundant);
  s.h->power_off(0);
  s.at(11500 * kMs);
  s.h->power_on(0);
  EXPECT_FALSE(s.h->rack_power()->self_testing(0));
  EXPECT_NE(s.h->pair().state(0), CpuState::Off);
}


// 000 §5.2.3 (L1251, L1265) on the model's DBs: DB 1 keeps its interface time stamp (copied: the
// old master's content), DB 2 is modified (the new configuration's own start values stay), DB 3
// is modified and holds S7-communication SFB instances (reset: 0). Same times as above:
// request at 1.5 s, swap at 3.645 s; the standby CPU 1 in STOP holds its own values.
TEST(HSystemSwap, ModifiedConfigurationCopiesOnlyUnchangedDbs) {
  HCpuPairParams p;
  p.switch_run = {true, false};
  HSys s(p);
  HS7MemoryConfig m;
  m.dbs = {HS7Db{1, 4}, HS7Db{2, 4}, HS7Db{3, 4}};
  s.h->set_s7_memory(m);
  s.h->set_db_blocks(0, {HDbBlock{1, 100}, HDbBlock{2, 200}, HDbBlock{3, 300, false, false, false, true}});
  s.h->set_db_blocks(1, {HDbBlock{1, 100}, HDbBlock{2, 201}, HDbBlock{3, 301, false, false, false, true}});
  s.at(kT0);
  s.h->power_on_both();
  s.run_until(1500 * kMs);
  for (std::uint16_t n = 1; n <= 3; ++n) {
    ASSERT_EQ(s.h->s7_db(0, n).size(), 4u);
    std::ranges::fill(s.h->s7_db(0, n), static_cast<std::uint8_t>(0x10 * n + 1));  // 11 21 31
    std::ranges::fill(s.h->s7_db(1, n), static_cast<std::uint8_t>(0xA0 + n));      // A1 A2 A3
  }
  const HCpuConfig cfg{2048, 1024, LoadMemoryType::Ram, 0x040500};
  ASSERT_TRUE(s.h->switch_to_cpu(HSwitchVariant::ModifiedConfiguration, cfg, cfg));
  ASSERT_TRUE(s.h->db_copy_plan().has_value());
  EXPECT_EQ(s.h->db_copy_plan()->copied, (std::vector<int>{1}));
  EXPECT_EQ(s.h->db_copy_plan()->sfb_reset, (std::vector<int>{3}));
  s.run_until(3645 * kMs);
  ASSERT_EQ(s.h->pair().master(), 1);
  const std::vector<std::uint8_t> db1(4, 0x11), db2(4, 0xA2), db3(4, 0x00);
  const auto r1 = s.h->s7_db(1, 1), r2 = s.h->s7_db(1, 2), r3 = s.h->s7_db(1, 3);
  EXPECT_EQ(std::vector<std::uint8_t>(r1.begin(), r1.end()), db1);
  EXPECT_EQ(std::vector<std::uint8_t>(r2.begin(), r2.end()), db2);
  EXPECT_EQ(std::vector<std::uint8_t>(r3.begin(), r3.end()), db3);
  EXPECT_TRUE(s.h->s7_db(1, 9).empty());
}

// 000 L1256: an SFC-generated DB 4 of the master also in the standby's load memory: the link-up
// is interrupted with an entry; the model refuses at the request (both buffers, standby STOP).
TEST(HSystemSwap, ModifiedConfigurationSfcDbInStandbyLoadMemoryIsRefused) {
  HCpuPairParams p;
  p.switch_run = {true, false};
  HSys s(p);
  s.h->set_db_blocks(0, {HDbBlock{4, 1, false, false, true}});
  s.h->set_db_blocks(1, {HDbBlock{4, 1}});
  s.at(kT0);
  s.h->power_on_both();
  s.run_until(1500 * kMs);
  const HCpuConfig cfg{2048, 1024, LoadMemoryType::Ram, 0x040500};
  EXPECT_FALSE(s.h->switch_to_cpu(HSwitchVariant::ModifiedConfiguration, cfg, cfg));
  const std::string t =
      "PG/ES: switch to CPU with modified configuration refused: standby CPU stays in STOP: "
      "link-up aborted: DB 4 generated by SFC in the master is in the standby's load memory "
      "(000 L1256, L1263)";
  EXPECT_TRUE(has_entry(s.h->diag_buffer(0), 1500 * kMs, t));
  EXPECT_TRUE(has_entry(s.h->diag_buffer(1), 1500 * kMs, t));
  s.run_until(3700 * kMs);
  EXPECT_EQ(s.h->pair().state(1), CpuState::Stop);
  EXPECT_EQ(s.h->pair().master(), 0);
}

}  // namespace
}  // namespace pbvbus::devices
