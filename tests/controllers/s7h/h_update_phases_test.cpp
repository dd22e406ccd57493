// HCpuPair's update in phases (devices/h_cpu_pair.hpp; seeds-digest.md §3.1, §4 "Update steps",
// §7 F19–F23, §11 R6–R9; docs/h-system.md "The update in phases").
// Every time is the arithmetic of the defaults unless a test says otherwise:
//   CPU 0 powers on at 0, STARTUP 1 s -> Solo at 1 s; CPU 1 powers on at 5 s -> LINK-UP
//   2 s (the first 1 s of it the load-memory copy) -> t1 = t3 = 7 s.
//   No H parameters: W = 75 ms + 0.7 ms x 100 KB = 145 ms, t4 = t5 = 7.145 s.
//   The manual's example (T_PH 90 ms, 170 KB): W = MAX(75 + 0.7 x 170 = 194, 50 + 90 = 140)
//   = 194 ms, t5 = 7.194 s, t4 = t5 - 90 ms = 7.104 s.
#include <gtest/gtest.h>

#include <algorithm>
#include <stdexcept>
#include <string>
#include <vector>

#include "pbvbus/s7h/h_cpu_pair.hpp"

namespace pbvbus::devices {
namespace {

using bus::Ticks;
constexpr Ticks tms(std::int64_t v) {
  return v * bus::kTicksPerMs;
}
constexpr Ticks sec(std::int64_t v) {
  return v * bus::kTicksPerSecond;
}
constexpr Us us_ms(std::int64_t v) {
  return v * kUsPerMs;
}

constexpr Ticks kT1 = sec(5) + sec(2);  // CPU 1 on at 5 s + LINK-UP 2 s
constexpr Ticks kT3 = kT1;              // the delay stages take no time in the model

/// The manual's example set: cycle extension 1940 ms (10 x 194) > communication delay 776 ms
/// (4 x 194) > T_P15 > T_PH 90 ms, 50 ms + 90 ms <= T_P15.
HParameters manual_set(std::int64_t t_p15_ms) {
  return HParameters{us_ms(1940), us_ms(776), us_ms(t_p15_ms), us_ms(90)};
}

HCpuPairParams manual_params(std::int64_t t_p15_ms) {
  HCpuPairParams prm;
  prm.h_parameters = manual_set(t_p15_ms);
  prm.update_db_kb = 170;
  return prm;
}

/// CPU 0 master in Solo RUN from 1 s, CPU 1 powers on at 5 s and links up at once.
void start(HCpuPair& p) {
  p.power_on(0, 0);
  p.on_time(sec(1));
  p.power_on(1, sec(5));
  ASSERT_EQ(p.state(1), CpuState::LinkUp);
}

bool has_diag(const HCpuPair& p, int r, Ticks at, const std::string& text, std::uint16_t code = 0) {
  return std::any_of(p.diag_buffer(r).begin(), p.diag_buffer(r).end(), [&](const DiagEntry& d) {
    return d.at == at && d.code == code && d.text.find(text) != std::string::npos;
  });
}

bool has_code(const HCpuPair& p, int r, std::uint16_t code) {
  return std::any_of(p.diag_buffer(r).begin(), p.diag_buffer(r).end(),
                     [&](const DiagEntry& d) { return d.code == code; });
}

std::vector<HEvent> ob72(const HCpuPair& p) {
  std::vector<HEvent> v;
  for (const HEvent& e : p.events())
    if (e.kind == HEvent::Kind::Ob && e.ob == 72) v.push_back(e);
  return v;
}

struct Flags {
  bool frozen, held, interrupts;
};
Flags flags_at(HCpuPair& p, Ticks t) {
  p.on_time(t);
  return {p.io_frozen(), p.outputs_held_by_both(), p.interrupts_held()};
}

TEST(HUpdatePhases, NoHParametersWindowIs145msAndNoOutputHold) {
  HCpuPair p;
  EXPECT_EQ(p.update_time(), tms(145));  // 75 ms + 0.7 ms x 100 KB
  start(p);
  EXPECT_FALSE(p.update_window().has_value());
  const Ticks t5 = kT3 + tms(145);  // 7.145 s
  Flags f = flags_at(p, kT3 - 1);
  EXPECT_EQ(p.state(1), CpuState::LinkUp);
  EXPECT_FALSE(f.frozen);
  EXPECT_FALSE(f.interrupts);
  f = flags_at(p, kT3);
  EXPECT_EQ(p.state(1), CpuState::Update);
  EXPECT_TRUE(f.frozen);
  EXPECT_FALSE(f.held);  // T_PH = 0: the hold window [t5, t5) is empty
  EXPECT_TRUE(f.interrupts);
  ASSERT_TRUE(p.update_window().has_value());
  EXPECT_EQ(p.update_window()->t1, kT1);
  EXPECT_EQ(p.update_window()->t3, kT3);
  EXPECT_EQ(p.update_window()->t4, t5);
  EXPECT_EQ(p.update_window()->t5, t5);
  EXPECT_EQ(p.next_deadline(), t5);  // no phase deadline without T_PH
  f = flags_at(p, t5 - 1);
  EXPECT_TRUE(f.frozen);
  EXPECT_FALSE(f.held);
  f = flags_at(p, t5);
  EXPECT_FALSE(f.frozen);
  EXPECT_FALSE(f.held);
  EXPECT_FALSE(f.interrupts);
  EXPECT_EQ(p.system_mode(), SystemMode::Redundant);
  EXPECT_EQ(p.update_window()->t5, t5);
  EXPECT_FALSE(p.update_window()->aborted);
  EXPECT_EQ(p.update_tries(), 1);
}

TEST(HUpdatePhases, ManualExampleWindow194msWithOutputHold90ms) {
  HCpuPair p(manual_params(194));        // configured T_P15 194 ms: the update fits exactly
  EXPECT_EQ(p.update_time(), tms(194));  // MAX(75 + 0.7 x 170 = 194, 50 + 90 = 140)
  start(p);
  const Ticks t5 = kT3 + tms(194);  // 7.194 s
  const Ticks t4 = t5 - tms(90);    // 7.104 s
  Flags f = flags_at(p, kT3 - 1);
  EXPECT_FALSE(f.frozen);
  EXPECT_FALSE(f.held);
  f = flags_at(p, kT3);
  EXPECT_TRUE(f.frozen);
  EXPECT_FALSE(f.held);
  EXPECT_EQ(p.next_deadline(), t4);  // the output hold begins at a deadline of its own
  EXPECT_EQ(p.update_window()->t4, t4);
  EXPECT_EQ(p.update_window()->t5, t5);
  f = flags_at(p, t4 - 1);
  EXPECT_TRUE(f.frozen);
  EXPECT_FALSE(f.held);
  f = flags_at(p, t4);
  EXPECT_TRUE(f.frozen);
  EXPECT_TRUE(f.held);
  EXPECT_TRUE(has_diag(p, 0, t4, "both CPUs drive the outputs"));
  EXPECT_TRUE(has_diag(p, 1, t4, "both CPUs drive the outputs"));
  EXPECT_EQ(p.next_deadline(), t5);
  f = flags_at(p, t5 - 1);
  EXPECT_TRUE(f.frozen);
  EXPECT_TRUE(f.held);
  f = flags_at(p, t5);
  EXPECT_FALSE(f.frozen);
  EXPECT_FALSE(f.held);
  EXPECT_EQ(p.system_mode(), SystemMode::Redundant);
  EXPECT_TRUE(ob72(p).empty());
}

TEST(HUpdatePhases, Tp15Of193msTimesOutAtT3Plus193ms) {
  HCpuPair p(manual_params(193));  // W = 194 ms > T_P15 = 193 ms
  start(p);
  const Ticks abort_at = kT3 + tms(193);  // 7.193 s
  p.on_time(kT3);
  EXPECT_EQ(p.next_deadline(), kT3 + tms(104));  // t4 = 7.194 s - 90 ms comes first
  p.on_time(abort_at - 1);
  EXPECT_EQ(p.state(1), CpuState::Update);
  EXPECT_TRUE(p.outputs_held_by_both());
  p.on_time(abort_at);
  EXPECT_EQ(p.state(1), CpuState::Stop);
  EXPECT_EQ(p.state(0), CpuState::Run);
  EXPECT_EQ(p.master(), 0);
  EXPECT_EQ(p.system_mode(), SystemMode::Solo);
  EXPECT_FALSE(p.io_frozen());
  EXPECT_FALSE(p.outputs_held_by_both());
  const auto o = ob72(p);
  ASSERT_EQ(o.size(), 1u);
  EXPECT_EQ(o[0].at, abort_at);
  EXPECT_EQ(o[0].rack, 0);
  EXPECT_EQ(o[0].role, CpuRole::Master);
  EXPECT_EQ(o[0].reason, HReason::UpdateTimeout);
  EXPECT_EQ(to_string(HReason::UpdateTimeout), "update timeout");
  ASSERT_TRUE(p.update_window().has_value());
  EXPECT_EQ(p.update_window()->t5, abort_at);
  EXPECT_EQ(p.update_window()->t4, kT3 + tms(104));
  EXPECT_TRUE(p.update_window()->aborted);
  EXPECT_TRUE(p.update_window()->timed_out);
  EXPECT_TRUE(has_diag(p, 1, abort_at, "update timeout: T_P15 exceeded"));
  EXPECT_TRUE(has_diag(p, 1, abort_at, "SDBs re-read"));
  EXPECT_TRUE(has_diag(p, 0, abort_at, "update aborted"));
  EXPECT_EQ(p.update_tries(), 1);
  // The retry exactly 60 s after the abort: 7.193 s + 60 s = 67.193 s.
  const Ticks retry = abort_at + sec(60);
  EXPECT_EQ(p.next_deadline(), retry);
  p.on_time(retry - 1);
  EXPECT_EQ(p.state(1), CpuState::Stop);
  p.on_time(retry);
  EXPECT_EQ(p.state(1), CpuState::LinkUp);
  EXPECT_EQ(p.update_tries(), 2);
}

TEST(HUpdatePhases, GivesUpAfter10TriesAndManualStartCountsAgain) {
  HCpuPair p(manual_params(193));
  start(p);
  // Try k starts at L(k) = 5 s + (k - 1) x 62.193 s (LINK-UP 2 s + 193 ms to the abort + 60 s);
  // it aborts at L(k) + 2.193 s. The 10th abort: 5 s + 9 x 62.193 s + 2.193 s = 566.930 s.
  std::vector<Ticks> want;
  for (int k = 0; k < 10; ++k) want.push_back(sec(5) + k * tms(62193) + tms(2193));
  while (p.next_deadline() != bus::kNever) p.on_time(p.next_deadline());
  std::vector<Ticks> got;
  for (const HEvent& e : ob72(p)) {
    EXPECT_EQ(e.reason, HReason::UpdateTimeout);
    got.push_back(e.at);
  }
  EXPECT_EQ(got, want);
  EXPECT_EQ(want.back(), tms(566930));
  EXPECT_EQ(p.update_tries(), kUpdateMaxTries);
  EXPECT_EQ(p.state(1), CpuState::Stop);
  EXPECT_EQ(p.system_mode(), SystemMode::Solo);
  EXPECT_TRUE(has_diag(p, 1, tms(566930), "link-up must be restarted manually"));
  // Smaller DB changes (100 KB: W = MAX(145, 140) = 145 ms <= 193 ms) and a manual restart
  // at 600 s: a new series, Redundant at 600 s + 2 s + 145 ms.
  p.set_changed_db_kb(100, sec(599));
  EXPECT_EQ(p.update_time(), tms(145));
  p.switch_to_run(1, sec(600));
  EXPECT_EQ(p.state(1), CpuState::LinkUp);
  EXPECT_EQ(p.update_tries(), 1);
  p.on_time(sec(602) + tms(145));
  EXPECT_EQ(p.system_mode(), SystemMode::Redundant);
}

TEST(HUpdatePhases, ChangedDbKbSlowsTheNextUpdateNotTheRunningOne) {
  HCpuPair p;
  start(p);
  p.on_time(kT3);
  p.set_changed_db_kb(1000, kT3 + 1);
  EXPECT_EQ(p.update_time(), tms(775));  // 75 ms + 0.7 ms x 1000 KB
  p.on_time(kT3 + tms(145));             // the running update keeps its 145 ms
  EXPECT_EQ(p.system_mode(), SystemMode::Redundant);
  // Next update: standby STOP at 10 s, RUN at 11 s -> t3 = 13 s, t5 = 13.775 s.
  p.switch_to_stop(1, sec(10));
  p.switch_to_run(1, sec(11));
  p.on_time(sec(13));
  EXPECT_EQ(p.update_window()->t5, sec(13) + tms(775));
  p.on_time(sec(13) + tms(775) - 1);
  EXPECT_EQ(p.state(1), CpuState::Update);
  p.on_time(sec(13) + tms(775));
  EXPECT_EQ(p.system_mode(), SystemMode::Redundant);
}

TEST(HUpdatePhases, R7RecordJobsRefusedDuringTheUpdateOnly) {
  HCpuPair p;
  start(p);
  EXPECT_EQ(p.record_job_result(13, kT1 - 1), 0);
  EXPECT_EQ(p.record_job_result(51, kT1 - 1), 0);
  for (int sfc : {13, 55, 56, 57, 58, 59}) EXPECT_EQ(p.record_job_result(sfc, kT1), 0x80C3);
  EXPECT_EQ(p.record_job_result(51, kT1), 0x8085);
  EXPECT_EQ(p.record_job_result(52, kT1), 0);  // not a data-record SFC
  const Ticks t5 = kT3 + tms(145);
  EXPECT_EQ(p.record_job_result(59, t5 - 1), 0x80C3);
  EXPECT_EQ(p.record_job_result(51, t5 - 1), 0x8085);
  EXPECT_EQ(p.record_job_result(59, t5), 0);
  EXPECT_EQ(p.record_job_result(51, t5), 0);
}

TEST(HUpdatePhases, StandbyLostDuringUpdateAbortsTheWindowWithoutTimeout) {
  HCpuPair p;
  start(p);
  p.power_off(1, kT3 + tms(100));  // in UPDATE (7 s .. 7.145 s)
  ASSERT_TRUE(p.update_window().has_value());
  EXPECT_EQ(p.update_window()->t5, kT3 + tms(100));
  EXPECT_EQ(p.update_window()->t4, kT3 + tms(100));  // planned t4 = t5 = 7.145 s, cut
  EXPECT_TRUE(p.update_window()->aborted);
  EXPECT_FALSE(p.update_window()->timed_out);
  EXPECT_FALSE(p.io_frozen());
  EXPECT_FALSE(p.reset_request(1));  // F20 is about LINK-UP only
  EXPECT_EQ(p.system_mode(), SystemMode::Solo);
}

TEST(HUpdatePhases, F20StopDuringLinkUpAfterTheCopySetsResetRequestWithout6523) {
  HCpuPair p;
  start(p);
  // The load-memory copy is the first half of LINK-UP: 5 s .. 6 s. STOP at 6 s: copy done.
  p.switch_to_stop(1, sec(6));
  EXPECT_EQ(p.state(1), CpuState::Stop);
  EXPECT_TRUE(p.reset_request(1));
  EXPECT_TRUE(has_diag(p, 1, sec(6), "reset request: link-up interrupted", 0));
  EXPECT_FALSE(has_code(p, 1, 0x6523));
  p.switch_to_run(1, sec(7));
  EXPECT_EQ(p.state(1), CpuState::Stop);  // refused until MRES
  EXPECT_TRUE(has_diag(p, 1, sec(7), "refused: reset request"));
  EXPECT_TRUE(p.memory_reset(1, sec(8)));
  EXPECT_FALSE(p.reset_request(1));
  EXPECT_EQ(p.state(1), CpuState::Stop);  // MRES does not start the CPU
  p.switch_to_run(1, sec(8));
  EXPECT_EQ(p.state(1), CpuState::LinkUp);
  p.on_time(sec(10) + tms(145));  // 8 s + 2 s + 145 ms
  EXPECT_EQ(p.system_mode(), SystemMode::Redundant);
}

TEST(HUpdatePhases, F20PowerLossDuringLoadMemoryCopyLogs6523) {
  HCpuPair p;
  start(p);
  p.power_off(1, sec(6) - 1);  // last tick of the copy (5 s .. 6 s)
  EXPECT_TRUE(p.reset_request(1));
  EXPECT_TRUE(has_diag(p, 1, sec(6) - 1, "during the load-memory copy", 0x6523));
  EXPECT_FALSE(p.memory_reset(1, sec(7)));  // off: no MRES
  p.power_on(1, sec(10));
  EXPECT_EQ(p.role(1), CpuRole::Standby);
  p.on_time(sec(20));
  EXPECT_EQ(p.state(1), CpuState::Stop);  // no link-up with a reset request
  EXPECT_TRUE(p.memory_reset(1, sec(20)));
  p.switch_to_run(1, sec(20));
  EXPECT_EQ(p.state(1), CpuState::LinkUp);
}

TEST(HUpdatePhases, R8ConnectionsBrokenOnTheStandbyAndNoNewOnesUntilTheUpdateEnds) {
  HCpuPairParams prm;
  prm.switch_run = {true, false};  // the standby waits in STOP
  HCpuPair p(prm);
  p.power_on(0, 0);
  EXPECT_FALSE(p.connect(1, 0));  // CPU 1 off
  p.on_time(sec(1));
  EXPECT_TRUE(p.connect(0, sec(2)));
  EXPECT_TRUE(p.connect(0, sec(2)));
  p.power_on(1, sec(3));
  for (int i = 0; i < 3; ++i) EXPECT_TRUE(p.connect(1, sec(3)));
  EXPECT_EQ(p.connections(1), 3);
  p.switch_to_run(1, sec(5));  // LINK-UP 5 s .. 7 s, UPDATE 7 s .. 7.145 s
  EXPECT_EQ(p.connections(1), 0);
  EXPECT_EQ(p.connections(0), 2);
  EXPECT_TRUE(has_diag(p, 1, sec(5), "3 connection(s) of this CPU broken"));
  EXPECT_FALSE(p.connect(0, sec(5)));
  EXPECT_FALSE(p.connect(1, sec(6)));
  EXPECT_FALSE(p.connect(0, kT3 + tms(145) - 1));
  EXPECT_TRUE(p.connect(0, kT3 + tms(145)));  // Redundant
  EXPECT_TRUE(p.connect(1, kT3 + tms(145)));
  EXPECT_EQ(p.connections(0), 3);
  EXPECT_EQ(p.connections(1), 1);
  ASSERT_TRUE(p.inject_comparison_error(sec(10)));
  EXPECT_EQ(p.state(1), CpuState::ErrorSearch);
  EXPECT_FALSE(p.connect(1, sec(10)));
  EXPECT_TRUE(p.connect(0, sec(10)));
}

TEST(HUpdatePhases, F22StructuralChangeInRedundantStopsBoth) {
  HCpuPair p;
  start(p);
  p.on_time(kT3 + tms(145));
  ASSERT_EQ(p.system_mode(), SystemMode::Redundant);
  EXPECT_EQ(p.load_change(HChange::Allowed, sec(8)), HChangeResult::Loaded);
  EXPECT_EQ(p.system_mode(), SystemMode::Redundant);
  EXPECT_TRUE(has_diag(p, 0, sec(8), "program change loaded: allowed change"));
  EXPECT_TRUE(has_diag(p, 1, sec(8), "program change loaded: allowed change"));
  EXPECT_EQ(p.load_change(HChange::StructuralFbInterface, sec(9)), HChangeResult::BothStopped);
  EXPECT_EQ(p.state(0), CpuState::Stop);
  EXPECT_EQ(p.state(1), CpuState::Stop);
  EXPECT_EQ(p.system_mode(), SystemMode::Stop);
  EXPECT_TRUE(ob72(p).empty());
  EXPECT_TRUE(has_diag(p, 0, sec(9), "structural FB-interface change loaded in Redundant mode"));
}

TEST(HUpdatePhases, F22GlobalDbChangeInSoloIsAllowedAndRefusedDuringLinkUp) {
  HCpuPair p;
  p.power_on(0, 0);
  p.on_time(sec(1));
  EXPECT_EQ(p.load_change(HChange::GlobalDb, sec(2)), HChangeResult::Loaded);
  EXPECT_EQ(p.state(0), CpuState::Run);
  EXPECT_EQ(p.system_mode(), SystemMode::Solo);
  p.power_on(1, sec(5));
  EXPECT_EQ(p.load_change(HChange::GlobalDb, sec(6)), HChangeResult::Refused);
  EXPECT_EQ(p.load_change(HChange::Allowed, kT3), HChangeResult::Refused);  // UPDATE
  EXPECT_EQ(p.state(1), CpuState::Update);
}

TEST(HUpdatePhases, F23SwapAfterForbiddenParameterChangeRefusedWith5966) {
  HCpuPairParams prm;
  prm.switch_run = {true, false};
  HCpuPair p(prm);
  p.power_on(0, 0);
  p.power_on(1, sec(2));
  p.on_time(sec(3));
  p.set_standby_parameter_change(true);
  EXPECT_FALSE(p.request_master_swap(sec(5)));
  EXPECT_EQ(p.state(1), CpuState::Stop);
  EXPECT_EQ(p.master(), 0);
  EXPECT_TRUE(has_diag(p, 0, sec(5), "master swap refused", 0x5966));
  EXPECT_TRUE(has_diag(p, 1, sec(5), "master swap refused", 0x5966));
  p.set_standby_parameter_change(false);
  EXPECT_TRUE(p.request_master_swap(sec(6)));
  p.on_time(sec(8) + tms(145));  // 6 s + 2 s + 145 ms
  EXPECT_EQ(p.master(), 1);
}

TEST(HUpdatePhases, F21MasterInHoldStillRefusesTheLinkUp) {
  HCpuPair p;
  p.power_on(0, 0);
  p.on_time(sec(1));
  ASSERT_TRUE(p.hold(0, sec(2)));
  p.power_on(1, sec(3));
  EXPECT_EQ(p.state(1), CpuState::Stop);
  EXPECT_TRUE(has_diag(p, 1, sec(3), "link-up not possible: master CPU in HOLD"));
  p.release_hold(0, sec(4));
  p.on_time(sec(10));
  EXPECT_EQ(p.state(1), CpuState::Stop);
  EXPECT_FALSE(p.update_window().has_value());
  EXPECT_EQ(p.update_tries(), 0);
}

TEST(HUpdatePhases, BadHParametersThrowTheCheckersMessage) {
  HCpuPairParams prm;
  prm.h_parameters.t_p15 = us_ms(194);  // one of four
  try {
    HCpuPair p(prm);
    FAIL() << "no exception";
  } catch (const std::invalid_argument& e) {
    EXPECT_EQ(std::string(e.what()),
              "configure all four H parameters or none; missing: max scan-cycle extension, max "
              "communication delay, T_PH");
  }
  HCpuPairParams bad_copy;
  bad_copy.load_memory_copy_time = sec(2) + 1;  // longer than LINK-UP (2 s)
  EXPECT_THROW(HCpuPair{bad_copy}, std::invalid_argument);
  HCpuPairParams zero;
  zero.h_parameters = HParameters{0, 0, 0, 0};  // all 0 = none configured: accepted
  HCpuPair ok(zero);
  EXPECT_EQ(ok.update_time(), tms(145));
}

TEST(HUpdatePhases, S7_1500SyncUpHasNoPhases) {
  HCpuPairParams prm;
  prm.profile = HProfile::S7_1500RH;
  prm.h_parameters = manual_set(193);  // would time out in the 400H profile
  prm.update_db_kb = 170;
  HCpuPair p(prm);
  p.power_on(0, 0);
  p.on_time(sec(1));
  p.power_on(1, sec(5));
  EXPECT_EQ(p.state(1), CpuState::SyncUp);
  EXPECT_EQ(p.record_job_result(51, sec(6)), 0);
  EXPECT_FALSE(p.io_frozen());
  EXPECT_FALSE(p.outputs_held_by_both());
  EXPECT_FALSE(p.interrupts_held());
  EXPECT_FALSE(p.update_window().has_value());
  p.on_time(sec(7) + tms(194));  // SYNCUP = LINK-UP 2 s + W 194 ms
  EXPECT_EQ(p.system_mode(), SystemMode::Redundant);
  EXPECT_TRUE(ob72(p).empty());
}

}  // namespace
}  // namespace pbvbus::devices
