// Changes in operation, the racks' power, checksum errors and W#16#6547 (docs/h-changes.md):
// h_config_change.hpp, h_rack_power.hpp, h_dp_startup.hpp, HCpuPair::checksum_error.
// Every time is the arithmetic of the pair's defaults: STARTUP 1 s, LINK-UP 2 s, UPDATE
// 75 ms + 0.7 ms x 100 KB = 145 ms, self-test 90 s, 7-day window.
#include <gtest/gtest.h>

#include <stdexcept>
#include <string>
#include <vector>

#include "pbvbus/s7h/h_config_change.hpp"
#include "pbvbus/s7h/h_cpu_pair.hpp"
#include "pbvbus/s7h/h_dp_startup.hpp"
#include "pbvbus/s7h/h_rack_power.hpp"

namespace pbvbus::devices {
namespace {

using bus::Ticks;
constexpr Ticks ms(std::int64_t v) { return v * bus::kTicksPerMs; }
constexpr Ticks sec(std::int64_t v) { return v * bus::kTicksPerSecond; }
constexpr Ticks kStartup = sec(1);
constexpr Ticks kLinkUp = sec(2);
constexpr Ticks kUpdate = ms(145);  // 75 ms + 0.7 ms x 100 KB
constexpr Ticks kSelfTest = sec(90);
constexpr Ticks kDay = sec(24 * 3600);

std::vector<HEvent> obs(const HCpuPair& p, int nr) {
  std::vector<HEvent> v;
  for (const HEvent& e : p.events())
    if (e.kind == HEvent::Kind::Ob && e.ob == nr) v.push_back(e);
  return v;
}

// The buffer entries of `rack` containing `part`, oldest first.
std::vector<DiagEntry> entries(const HCpuPair& p, int rack, const std::string& part) {
  std::vector<DiagEntry> v;
  for (const auto& d : p.diag_buffer(rack))
    if (d.text.find(part) != std::string::npos) v.push_back(d);
  return v;
}

// Solo: CPU 0 master in RUN from 1 s, CPU 1 standby in STOP (switch at STOP), linked.
HCpuPair solo_pair() {
  HCpuPairParams prm;
  prm.switch_run = {true, false};
  HCpuPair p(prm);
  p.power_on_both(0);
  p.on_time(kStartup);
  return p;
}

// Redundant at 5 s + 2 s + 145 ms = 7.145 s (CPU 0 master).
constexpr Ticks kRedundantAt = sec(5) + kLinkUp + kUpdate;
void bring_up(HCpuPair& p) {
  p.power_on(0, 0);
  p.on_time(kStartup);
  p.power_on(1, sec(5));
  p.on_time(kRedundantAt);
  ASSERT_EQ(p.system_mode(), SystemMode::Redundant);
}

HCpuConfig cfg(std::uint32_t work, std::uint32_t load, LoadMemoryType t, std::uint32_t os) {
  HCpuConfig c;
  c.work_memory_kb = work;
  c.load_memory_kb = load;
  c.load_memory = t;
  c.os_version = os;
  return c;
}
const HCpuConfig kMasterCfg = cfg(2048, 1024, LoadMemoryType::Ram, 0x030100);

// ---------------------------------------------------------------- switch to CPU with ...

// 000 §10.4.6 (L3364-3388) and §5.2.2 (L1200-1209): the standby links up, is updated and
// becomes master; the old master STOPs; Solo with the new configuration; the first OB 1 of the
// new master has its own start identifier; its central outputs are briefly 0, the old master's
// one-sided outputs go to their substitute values; step 7 (L3400-3412): the old master is
// restarted, links up, Redundant, OB 83 for the added switched modules.
TEST(HConfigChange, ModifiedConfigurationSequence) {
  HCpuPair p = solo_pair();
  HConfigChange cc(p);
  const Ticks req = sec(10);
  ASSERT_TRUE(cc.request(HSwitchVariant::ModifiedConfiguration, kMasterCfg, kMasterCfg, req,
                         {512}));
  EXPECT_EQ(p.state(1), CpuState::LinkUp);
  EXPECT_EQ(p.state(0), CpuState::Run);
  // The master's buffer: the pair's request entry, then (after the link-up entries of the
  // same instant) the variant's note, both at 10 s.
  const auto& d0 = p.diag_buffer(0);
  std::size_t i_req = d0.size(), i_note = d0.size();
  for (std::size_t i = 0; i < d0.size(); ++i) {
    if (d0[i].text == "PG/ES: switch to CPU with modified configuration") i_req = i;
    if (d0[i].text ==
        "PG/ES: switch to CPU with modified configuration: no blocks copied; data blocks as 5.2.3")
      i_note = i;
  }
  ASSERT_LT(i_req, d0.size());
  ASSERT_LT(i_note, d0.size());
  EXPECT_LT(i_req, i_note);
  EXPECT_EQ(d0[i_req].at, req);
  EXPECT_EQ(d0[i_note].at, req);
  // t5 = 10 s + 2 s link-up + 145 ms update = 12.145 s.
  const Ticks t5 = req + kLinkUp + kUpdate;
  p.on_time(t5 - 1);
  cc.observe();
  EXPECT_FALSE(cc.swap_time().has_value());
  EXPECT_EQ(cc.ob1_scan_1(1, t5 - 1), kOb1ScanFreeCycle);
  p.on_time(t5);
  cc.observe();
  ASSERT_TRUE(cc.swap_time().has_value());
  EXPECT_EQ(*cc.swap_time(), t5);
  EXPECT_EQ(cc.new_master(), 1);
  EXPECT_EQ(p.master(), 1);
  EXPECT_EQ(p.state(0), CpuState::Stop);
  EXPECT_EQ(p.system_mode(), SystemMode::Solo);
  const auto o72 = obs(p, 72);
  ASSERT_EQ(o72.size(), 1u);
  EXPECT_EQ(o72[0].rack, 1);
  EXPECT_EQ(o72[0].at, t5);
  EXPECT_EQ(o72[0].reason, HReason::MasterSwap);
  // OB1_SCAN_1: B#16#05 for the new master's first OB 1, B#16#03 after; the old master none.
  EXPECT_EQ(cc.ob1_scan_1(0, t5), kOb1ScanFreeCycle);
  EXPECT_EQ(cc.ob1_scan_1(1, t5), 0x05);
  EXPECT_EQ(cc.ob1_scan_1(1, t5 + ms(10)), 0x03);
  // Central outputs of the new master 0 for one OB 1 cycle (10 ms default): [t5, t5 + 10 ms).
  EXPECT_FALSE(cc.central_outputs_zero(1, t5 - 1));
  EXPECT_TRUE(cc.central_outputs_zero(1, t5));
  EXPECT_TRUE(cc.central_outputs_zero(1, t5 + ms(10) - 1));
  EXPECT_FALSE(cc.central_outputs_zero(1, t5 + ms(10)));
  EXPECT_FALSE(cc.central_outputs_zero(0, t5));
  // The old master's one-sided outputs: substitute values from t5.
  EXPECT_FALSE(cc.one_sided_substitute(0, t5 - 1));
  EXPECT_TRUE(cc.one_sided_substitute(0, t5));
  EXPECT_FALSE(cc.one_sided_substitute(1, t5));
  // Step 7: restart the old master at 20 s: link-up + update, Redundant at 22.145 s.
  p.switch_to_run(0, sec(20));
  EXPECT_EQ(p.state(0), CpuState::LinkUp);
  const Ticks red = sec(20) + kLinkUp + kUpdate;
  p.on_time(red);
  cc.observe();
  EXPECT_EQ(p.system_mode(), SystemMode::Redundant);
  EXPECT_EQ(p.master(), 1);  // no swap back
  EXPECT_EQ(cc.ob83_time(), red);
  for (int r = 0; r < 2; ++r) {
    const auto e = entries(p, r, "OB 83: module inserted (switched, address 512)");
    ASSERT_EQ(e.size(), 1u) << r;
    EXPECT_EQ(e[0].at, red);
  }
  EXPECT_TRUE(cc.one_sided_substitute(0, red - 1));
  EXPECT_FALSE(cc.one_sided_substitute(0, red));
}

TEST(HConfigChange, NotInSoloOrStandbyRunningIsRefusedWithoutEntries) {
  HCpuPair p;
  bring_up(p);
  HConfigChange cc(p);
  const auto n0 = p.diag_buffer(0).size();
  EXPECT_FALSE(cc.request(HSwitchVariant::ModifiedConfiguration, kMasterCfg, kMasterCfg,
                          sec(10)));
  EXPECT_EQ(p.diag_buffer(0).size(), n0);
  EXPECT_EQ(p.system_mode(), SystemMode::Redundant);
}

// 000 L1124-1160 / 001 L4494-4530: what each variant allows.
TEST(HConfigChange, VariantChecks) {
  using V = HSwitchVariant;
  const auto M = kMasterCfg;
  // Modified configuration: any load-memory type/size; the swap also without a change.
  EXPECT_TRUE(check_switch(V::ModifiedConfiguration, M, M).allowed);
  auto flash = cfg(2048, 512, LoadMemoryType::Flash, 0x030100);
  EXPECT_TRUE(check_switch(V::ModifiedConfiguration, M, flash).allowed);
  EXPECT_FALSE(check_switch(V::ModifiedConfiguration, M, M).copy_user_program);
  // Expanded memory: only enlargements of the same type; blocks copied (FLASH: work memory).
  const auto big = cfg(4096, 1024, LoadMemoryType::Ram, 0x030100);
  auto c = check_switch(V::ExpandedMemory, M, big);
  EXPECT_TRUE(c.allowed);
  EXPECT_TRUE(c.copy_user_program);
  EXPECT_TRUE(c.copy_load_memory);
  const auto mflash = cfg(2048, 512, LoadMemoryType::Flash, 0x030100);
  c = check_switch(V::ExpandedMemory, mflash, cfg(2048, 1024, LoadMemoryType::Flash, 0x030100));
  EXPECT_TRUE(c.allowed);
  EXPECT_FALSE(c.copy_load_memory);
  EXPECT_FALSE(check_switch(V::ExpandedMemory, M, M).allowed);  // nothing enlarged
  EXPECT_EQ(check_switch(V::ExpandedMemory, M, M).text,
            "standby CPU stays in STOP: memory not enlarged");
  EXPECT_FALSE(check_switch(V::ExpandedMemory, M, cfg(4096, 1024, LoadMemoryType::Flash,
                                                      0x030100)).allowed);  // type changed
  EXPECT_FALSE(check_switch(V::ExpandedMemory, M, cfg(4096, 1024, LoadMemoryType::Ram,
                                                      0x030200)).allowed);  // OS changed
  // Modified OS: a newer OS, nothing else (digest §10 item 8: 000 allowed, 001 unusable).
  const auto newer = cfg(2048, 1024, LoadMemoryType::Ram, 0x030200);
  EXPECT_TRUE(check_switch(V::ModifiedOs, M, newer).allowed);
  EXPECT_FALSE(check_switch(V::ModifiedOs, M, newer, false).allowed);
  EXPECT_FALSE(check_switch(V::ModifiedOs, M, M).allowed);  // OS not changed
  EXPECT_FALSE(check_switch(V::ModifiedOs, M, cfg(4096, 1024, LoadMemoryType::Ram, 0x030200))
                   .allowed);  // memory enlarged too
}

// A refused variant: "will not switch to RUN but relapse into STOP with a diagnostics buffer
// entry ... the master remains in RUN" (000 L1134-1138): decided at the request, like F23.
TEST(HConfigChange, RefusedVariantStandbyStaysInStop) {
  HCpuPair p = solo_pair();
  HConfigChange cc(p);
  const auto ev = p.events().size();
  EXPECT_FALSE(cc.request(HSwitchVariant::ExpandedMemory, kMasterCfg, kMasterCfg, sec(10)));
  EXPECT_EQ(p.events().size(), ev);  // no state, role or OB event
  EXPECT_EQ(p.state(0), CpuState::Run);
  EXPECT_EQ(p.state(1), CpuState::Stop);
  const std::string t =
      "PG/ES: switch to CPU with expanded memory configuration refused: standby CPU stays in "
      "STOP: memory not enlarged";
  for (int r = 0; r < 2; ++r) {
    ASSERT_FALSE(p.diag_buffer(r).empty());
    EXPECT_EQ(p.diag_buffer(r).back().text, t);
    EXPECT_EQ(p.diag_buffer(r).back().at, sec(10));
  }
  p.on_time(sec(20));
  cc.observe();
  EXPECT_FALSE(cc.swap_time().has_value());
  EXPECT_EQ(cc.ob1_scan_1(1, sec(20)), kOb1ScanFreeCycle);
}

// 000 §5.2.3 (L1239-1269) / 001 §6.2.3 (L4673-4720).
TEST(HConfigChange, ModifiedConfigurationCopyPlan) {
  std::vector<HDbBlock> m, s;
  m.push_back({1, 7, false, false, false, false, 2});    // same stamp: copied
  m.push_back({2, 3, true, false, false, false, 1});     // read-only: not copied
  m.push_back({3, 5, false, false, false, true, 1});     // modified, S7-comm SFB instances
  m.push_back({4, 9, false, true, false, false, 1});     // unlinked: not copied
  m.push_back({5, 4, false, false, false, false, 1});    // not in the new configuration
  m.push_back({100, 0, false, false, true, false, 4});   // generated by SFC: transferred
  s.push_back({1, 7, false, false, false, false, 2});
  s.push_back({2, 3, true, false, false, false, 1});
  s.push_back({3, 6, false, false, false, true, 1});
  s.push_back({4, 9, false, true, false, false, 1});
  s.push_back({200, 0, false, false, true, false, 2});  // the standby's SFC DB: reset
  auto r = plan_modified_configuration_copy(m, s, 4, 150, 120);
  ASSERT_FALSE(r.aborted) << r.abort_text;
  EXPECT_EQ(r.copied, (std::vector<int>{1}));
  EXPECT_EQ(r.created, (std::vector<int>{100}));
  EXPECT_EQ(r.deleted, (std::vector<int>{200}));
  EXPECT_EQ(r.sfb_reset, (std::vector<int>{3}));
  EXPECT_EQ(r.diag_entries, 120u);  // the standby's smaller buffer: the 120 newest
  EXPECT_EQ(plan_modified_configuration_copy(m, s, 4, 80, 120).diag_entries, 80u);
  // 4 KB of SFC DBs into 3 KB: "insufficient memory" aborts the link-up.
  r = plan_modified_configuration_copy(m, s, 3, 150, 120);
  EXPECT_TRUE(r.aborted);
  EXPECT_EQ(r.abort_text, "link-up aborted: insufficient memory in the standby CPU");
  EXPECT_TRUE(r.copied.empty());
  // The standby's load memory holds a DB 100: aborted.
  s.push_back({100, 1, false, false, false, false, 1});
  r = plan_modified_configuration_copy(m, s, 4, 150, 120);
  EXPECT_TRUE(r.aborted);
  EXPECT_EQ(r.abort_text,
            "link-up aborted: DB 100 generated by SFC in the master is in the standby's load "
            "memory");
}

// 000 L3382-3388 (step 6, the swap) and L3410-3416 (step 7, back to Redundant).
TEST(HConfigChange, IoReactionTables) {
  using O = HIoOwner;
  using P = HIoPresence;
  EXPECT_EQ(output_at_switch(O::OldMaster, P::Added, false), HOutput::NotAddressed);
  EXPECT_EQ(output_at_switch(O::OldMaster, P::Kept, true), HOutput::SubstituteValues);
  EXPECT_EQ(output_at_switch(O::OldMaster, P::Kept, false), HOutput::SubstituteValues);
  EXPECT_EQ(output_at_switch(O::OldMaster, P::AddedStation, false), HOutput::NotAddressed);
  EXPECT_EQ(output_at_switch(O::NewMaster, P::Added, true), HOutput::SubstituteThenUpdated);
  EXPECT_EQ(output_at_switch(O::NewMaster, P::Kept, true), HOutput::ZeroThenUpdated);
  EXPECT_EQ(output_at_switch(O::NewMaster, P::Kept, false), HOutput::Updated);
  EXPECT_EQ(output_at_switch(O::NewMaster, P::AddedStation, false),
            HOutput::SubstituteThenUpdated);
  EXPECT_EQ(output_at_switch(O::Switched, P::Kept, false), HOutput::Uninterrupted);
  EXPECT_EQ(output_at_redundant(O::OldMaster, P::Added, false), HOutput::SubstituteThenUpdated);
  EXPECT_EQ(output_at_redundant(O::OldMaster, P::Kept, true), HOutput::ZeroThenUpdated);
  EXPECT_EQ(output_at_redundant(O::NewMaster, P::Kept, true), HOutput::Uninterrupted);
  EXPECT_EQ(output_at_redundant(O::NewMaster, P::Added, false), HOutput::Updated);
  EXPECT_EQ(output_at_redundant(O::Switched, P::Added, false), HOutput::Updated);
  EXPECT_EQ(to_string(HOutput::ZeroThenUpdated), "briefly 0, then updated");
}

// 001 L2745-2757: CiR in RUN (also Solo), processing held at most 2.5 s (configurable),
// outputs keep their values, distributed I/O only.
TEST(HConfigChange, CirHoldAtMost2500ms) {
  EXPECT_EQ(kCirMaxHold, ms(2500));
  HCpuPair p = solo_pair();
  HConfigChange cc(p);
  auto r = cc.cir_change(sec(10));
  ASSERT_TRUE(r.accepted) << r.text;
  EXPECT_EQ(r.hold_from, sec(10));
  EXPECT_EQ(r.hold_until, sec(10) + ms(2500));
  EXPECT_EQ(p.diag_buffer(0).back().text,
            "CiR: configuration changed in RUN, processing held 2500 ms, outputs kept");
  EXPECT_FALSE(cc.cir_change(sec(11), true).accepted);  // central I/O
  HCpuPair q;
  bring_up(q);
  HConfigChangeParams prm;
  prm.cir_hold_time = ms(1000);
  HConfigChange c2(q, prm);
  r = c2.cir_change(sec(10));
  ASSERT_TRUE(r.accepted);
  EXPECT_EQ(r.hold_until - r.hold_from, ms(1000));
  EXPECT_EQ(q.diag_buffer(1).back().at, sec(10));  // both CPUs in RUN log it
  prm.cir_hold_time = ms(2500) + 1;
  EXPECT_THROW(HConfigChange(q, prm), std::invalid_argument);
  prm.cir_hold_time = 0;
  EXPECT_THROW(HConfigChange(q, prm), std::invalid_argument);
  HCpuPair off;
  HConfigChange c3(off);
  EXPECT_FALSE(c3.cir_change(0).accepted);
}

// ---------------------------------------------------------------- F1: PS 407 10A R halves

TEST(HRackPower, F1HalfOfRedundantPsNoEffectBothHalvesCpuFails) {
  HCpuPair p;
  HRackPower pw(p);
  pw.switch_on(0, 0);
  p.on_time(kStartup);
  pw.switch_on(1, sec(5));
  p.on_time(kRedundantAt);
  ASSERT_EQ(p.system_mode(), SystemMode::Redundant);
  const auto ev = p.events().size();
  EXPECT_FALSE(pw.fail_half(0, 1, sec(10)));
  EXPECT_EQ(p.events().size(), ev);  // no state, role or OB event
  EXPECT_EQ(p.system_mode(), SystemMode::Redundant);
  ASSERT_FALSE(p.diag_buffer(0).empty());
  EXPECT_EQ(p.diag_buffer(0).back().code, 0x3923);
  EXPECT_EQ(p.diag_buffer(0).back().at, sec(10));
  EXPECT_FALSE(pw.fail_half(0, 1, sec(11)));  // already failed: nothing
  // The second half: F1, the master is lost, CPU 1 master in Solo with OB 72.
  EXPECT_TRUE(pw.fail_half(0, 0, sec(12)));
  EXPECT_EQ(p.state(0), CpuState::Off);
  EXPECT_EQ(p.master(), 1);
  EXPECT_EQ(p.system_mode(), SystemMode::Solo);
  const auto o = obs(p, 72);
  ASSERT_EQ(o.size(), 1u);
  EXPECT_EQ(o[0].reason, HReason::MasterLost);
  EXPECT_EQ(o[0].at, sec(12));
  // One half replaced at 20 s: power returns (battery: no RAM test), the CPU links up as
  // standby: Redundant at 20 s + 2 s + 145 ms.
  pw.repair_half(0, 0, sec(20));
  EXPECT_EQ(p.state(0), CpuState::LinkUp);
  p.on_time(sec(20) + kLinkUp + kUpdate);
  EXPECT_EQ(p.system_mode(), SystemMode::Redundant);
  EXPECT_EQ(p.master(), 1);
  // The other half replaced: the outgoing entry.
  pw.repair_half(0, 1, sec(30));
  EXPECT_EQ(p.diag_buffer(0).back().code, 0x3823);
}

TEST(HRackPower, F1SinglePsFailureIsCpuFailure) {
  HCpuPair p;
  HRackPowerParams prm;
  prm.redundant_ps = false;
  HRackPower pw(p, prm);
  pw.switch_on(0, 0);
  p.on_time(kStartup);
  pw.switch_on(1, sec(5));
  p.on_time(kRedundantAt);
  EXPECT_TRUE(pw.fail_half(1, 0, sec(10)));
  EXPECT_EQ(p.state(1), CpuState::Off);
  ASSERT_EQ(obs(p, 72).size(), 1u);
  EXPECT_EQ(obs(p, 72)[0].reason, HReason::StandbyLost);
}

// 000 L640 / 001 L1149: ~8 s per MB after an unbuffered POWER ON; with a battery not again.
TEST(HRackPower, RamTestEightSecondsPerMegabyte) {
  EXPECT_EQ(ram_test_time(1024), sec(8));
  EXPECT_EQ(ram_test_time(512), sec(4));
  HCpuPair p;
  HRackPowerParams prm;
  prm.ram_kb = 2048;                // 2 MB -> 16 s
  prm.battery = {true, false};      // rack 1 without a backup battery
  HRackPower pw(p, prm);
  pw.switch_on(0, 0);
  EXPECT_TRUE(pw.self_testing(0));
  EXPECT_EQ(p.state(0), CpuState::Off);
  EXPECT_EQ(pw.next_deadline(), sec(16));
  pw.on_time(sec(16) - 1);
  EXPECT_EQ(p.state(0), CpuState::Off);
  pw.on_time(sec(16));
  EXPECT_FALSE(pw.self_testing(0));
  EXPECT_EQ(p.state(0), CpuState::Startup);
  p.on_time(sec(16) + kStartup);
  EXPECT_EQ(p.state(0), CpuState::Run);
  // Power cycle with the battery: no test, STARTUP at once.
  pw.switch_off(0, sec(30));
  pw.switch_on(0, sec(40));
  EXPECT_FALSE(pw.self_testing(0));
  EXPECT_NE(p.state(0), CpuState::Off);
  // Rack 1 without a battery: the test at every power-on.
  pw.switch_on(1, sec(50));
  pw.on_time(sec(66));
  EXPECT_NE(p.state(1), CpuState::Off);
  pw.switch_off(1, sec(100));
  pw.switch_on(1, sec(110));
  EXPECT_TRUE(pw.self_testing(1));
  EXPECT_EQ(pw.next_deadline(), sec(126));
}

// 001 Table 5-6: a checksum error in the test at start-up after power-on -> DEFECTIVE.
TEST(HRackPower, ChecksumErrorInPowerOnTestDefective) {
  HCpuPair p;
  HRackPowerParams prm;
  prm.ram_kb = 1024;
  HRackPower pw(p, prm);
  pw.switch_on(0, 0);
  EXPECT_TRUE(pw.checksum_in_power_on_test(0, sec(3)));
  pw.on_time(sec(8));
  EXPECT_EQ(p.state(0), CpuState::Defective);
  EXPECT_FALSE(entries(p, 0, "checksum error in the power-on self-test").empty());
  EXPECT_FALSE(pw.checksum_in_power_on_test(0, sec(9)));  // no test running
}

// ---------------------------------------------------------------- checksum errors (Table 5-6)

TEST(HChecksum, CyclicInSoloCorrected) {
  HCpuPair p = solo_pair();
  const auto ev = p.events().size();
  EXPECT_TRUE(p.checksum_error(0, HChecksumContext::Cyclic, sec(10)));
  EXPECT_EQ(p.events().size(), ev);
  EXPECT_EQ(p.state(0), CpuState::Run);
  EXPECT_EQ(p.diag_buffer(0).back().text, "checksum error in the cyclic self-test: corrected");
  // In STOP too (the standby).
  EXPECT_TRUE(p.checksum_error(1, HChecksumContext::Cyclic, sec(11)));
  EXPECT_EQ(p.state(1), CpuState::Stop);
}

TEST(HChecksum, CyclicInRedundantErrorSearchThenRelinkAndSwap) {
  HCpuPair p;
  bring_up(p);
  const Ticks t = sec(10);
  // On the master: it goes ERROR-SEARCH, CPU 1 master in Solo, OB 72 on CPU 1.
  ASSERT_TRUE(p.checksum_error(0, HChecksumContext::Cyclic, t));
  EXPECT_EQ(p.state(0), CpuState::ErrorSearch);
  EXPECT_EQ(p.master(), 1);
  EXPECT_EQ(p.system_mode(), SystemMode::Solo);
  auto o = obs(p, 72);
  ASSERT_EQ(o.size(), 1u);
  EXPECT_EQ(o[0].rack, 1);
  EXPECT_EQ(o[0].reason, HReason::ChecksumError);
  EXPECT_EQ(to_string(HReason::ChecksumError), "checksum error");
  // "No data exchange in ERROR-SEARCH" (001 L3932): no S7 connection to CPU 0.
  EXPECT_FALSE(p.accepts_connections(0));
  EXPECT_FALSE(p.connect(0, t + sec(1)));
  EXPECT_TRUE(p.connect(1, t + sec(1)));
  // Nothing found after 90 s: re-link (2 s + 145 ms), Redundant, CPU 0 master again.
  p.on_time(t + kSelfTest + kLinkUp + kUpdate);
  EXPECT_EQ(p.system_mode(), SystemMode::Redundant);
  EXPECT_EQ(p.master(), 0);
}

TEST(HChecksum, InErrorSearchAndRepeatedWithin7DaysDefective) {
  HCpuPair p;
  bring_up(p);
  ASSERT_TRUE(p.checksum_error(1, HChecksumContext::Cyclic, sec(10)));
  EXPECT_EQ(p.state(1), CpuState::ErrorSearch);
  // Found again by the full self-test of ERROR-SEARCH: DEFECTIVE.
  ASSERT_TRUE(p.checksum_error(1, HChecksumContext::Cyclic, sec(20)));
  EXPECT_EQ(p.state(1), CpuState::Defective);
  EXPECT_EQ(p.master(), 0);
  EXPECT_FALSE(p.checksum_error(1, HChecksumContext::Cyclic, sec(21)));  // DEFECTIVE: nothing
  // Within 7 days (inclusive) in Solo: DEFECTIVE instead of "corrected".
  HCpuPair q = solo_pair();
  ASSERT_TRUE(q.checksum_error(0, HChecksumContext::Cyclic, sec(10)));
  EXPECT_EQ(q.state(0), CpuState::Run);
  ASSERT_TRUE(q.checksum_error(0, HChecksumContext::Cyclic, sec(10) + 7 * kDay));
  EXPECT_EQ(q.state(0), CpuState::Defective);
  ASSERT_EQ(entries(q, 0, "checksum error repeated within 7 days").size(), 2u);  // + state
  EXPECT_EQ(entries(q, 0, "checksum error repeated within 7 days")[0].at, sec(10) + 7 * kDay);
  // 7 days + 1 tick later: corrected again.
  HCpuPair r = solo_pair();
  ASSERT_TRUE(r.checksum_error(0, HChecksumContext::Cyclic, sec(10)));
  ASSERT_TRUE(r.checksum_error(0, HChecksumContext::Cyclic, sec(10) + 7 * kDay + 1));
  EXPECT_EQ(r.state(0), CpuState::Run);
}

// ---------------------------------------------------------------- W#16#6547

// 001 L8094-8113: the monitoring time in 100 ms units (600 = 60 s); too short -> W#16#6547.
TEST(HDpStartup, ParamTransferMonitoringW6547) {
  EXPECT_EQ(param_transfer_time(600), sec(60));
  // 1 s monitoring from 1 s: station 5 at 1.5 s in time, 6 exactly at 2 s in time, 7 late.
  EXPECT_EQ(late_stations(sec(1), 10, {{5, ms(1500)}, {6, sec(2)}, {7, sec(2) + 1}}),
            (std::vector<std::uint8_t>{7}));
  EXPECT_EQ(late_stations(sec(1), 10, {{5, std::nullopt}}), (std::vector<std::uint8_t>{5}));
  HCpuPair p;
  p.power_on(0, 0);
  HDpStartupMonitor mon(p, 10, {5, 6});
  mon.start(0, 0);
  EXPECT_EQ(mon.next_deadline(), sec(1));
  mon.data_exchange(5, ms(400));
  p.on_time(sec(1));
  mon.on_time(sec(1));
  EXPECT_EQ(mon.late(), (std::vector<std::uint8_t>{6}));
  ASSERT_FALSE(p.diag_buffer(0).empty());
  EXPECT_EQ(p.diag_buffer(0).back().code, 0x6547);
  EXPECT_EQ(p.diag_buffer(0).back().at, sec(1));
  EXPECT_EQ(p.diag_buffer(0).back().text,
            "transfer of parameters to modules: monitoring time exceeded, stations 6");
  // The start-up continues (decision): RUN at 1 s as without the monitoring.
  EXPECT_EQ(p.state(0), CpuState::Run);
  // Long enough (600 = 60 s): no entry.
  HCpuPair q;
  q.power_on(0, 0);
  HDpStartupMonitor ok(q, 600, {5, 6});
  ok.start(0, 0);
  ok.data_exchange(5, ms(400));
  ok.data_exchange(6, sec(3));
  q.on_time(sec(60));
  ok.on_time(sec(60));
  EXPECT_FALSE(ok.exceeded());
  for (const auto& d : q.diag_buffer(0)) EXPECT_NE(d.code, 0x6547);
}

}  // namespace
}  // namespace pbvbus::devices
