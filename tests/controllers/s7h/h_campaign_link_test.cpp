// The H campaign's link-up/update fault kinds (devices/h_campaign.hpp: F2, F18-F23), one cycle
// of each in a small deterministic run (one kind's weight only, keep_log): the event sequence
// of HSystemModel::events() (OBs 72 and the I/O OBs; OB 85 left out) is checked here by hand
// against the injection times of the step log, besides the observer's own comparison (0
// mismatches, 0 pulses). Times: LINK-UP 2 000 ms, STARTUP 1 000 ms, T_P15 194 ms (the manual's
// four H parameters), W = MAX(75 + 0.7 x 100, 50 + 90) = 145 ms, the F19 retry 60 s.
// The last test is the observer's: an update timeout it is not told about is caught.
#include <gtest/gtest.h>

#include <algorithm>
#include <iostream>
#include <string>
#include <vector>

#include "pbvbus/s7h/h_campaign.hpp"

namespace pbvbus::devices {
namespace {

constexpr bus::Ticks kMs = bus::kTicksPerMs;

HCampaignResult run_one(HFault f, int injections, std::uint64_t seed = 3) {
  HCampaignOptions o;
  o.seed = seed;
  o.steps = injections;
  o.gsd_dir = std::string(PBVBUS_SOURCE_DIR) + "/examples/gsd";
  o.weights = {};
  o.weights[static_cast<int>(f)] = 1;
  o.keep_log = true;
  HCampaignResult r = run_h_campaign(o);
  std::cout << r.summary() << "\n";
  for (const auto& s : r.log)
    std::cout << "  step " << static_cast<double>(s.at) / kMs << " ms: " << s.what << "\n";
  for (const auto& m : r.mismatches) ADD_FAILURE() << m;
  for (const auto& p : r.pulse_reports) ADD_FAILURE() << p;
  EXPECT_EQ(r.pulses, 0u);
  EXPECT_EQ(r.drawn[static_cast<int>(f)], 1);
  EXPECT_EQ(r.injections(), injections);
  return r;
}

/// The OB 72/121 and I/O OB events from `from` on (OB 85 and the rest left out).
std::vector<HSystemEvent> obs_from(const HCampaignResult& r, bus::Ticks from) {
  std::vector<HSystemEvent> v;
  for (const auto& e : r.events)
    if (e.time >= from &&
        (e.source == HSystemEvent::Source::Cpu || e.source == HSystemEvent::Source::Io))
      v.push_back(e);
  return v;
}

void expect_ob72(const HSystemEvent& e, bus::Ticks at, int rack, HReason why) {
  EXPECT_EQ(e.source, HSystemEvent::Source::Cpu);
  EXPECT_EQ(e.ob, 72);
  EXPECT_EQ(e.time, at);
  EXPECT_EQ(e.rack, rack);
  EXPECT_EQ(e.role, CpuRole::Master);
  EXPECT_EQ(e.text, "OB 72 " + std::string(to_string(why)));
}

void expect_io(const HSystemEvent& e, bus::Ticks at, std::uint16_t code, int line, int rack) {
  EXPECT_EQ(e.source, HSystemEvent::Source::Io);
  EXPECT_EQ(e.ob, 86);
  EXPECT_EQ(e.code, code);
  EXPECT_EQ(e.time, at);
  EXPECT_EQ(e.line, line);
  EXPECT_EQ(e.station, 0xFF);
  EXPECT_EQ(e.rack, rack);
}

// Rack 0 is master after the start-up; the standby is rack 1 (line B = 1).
TEST(HCampaignLink, SyncErrorStopsTheStandby) {
  const HCampaignResult r = run_one(HFault::SyncError, 2);
  ASSERT_EQ(r.log.size(), 3u);  // start-up, F18, RUN
  const bus::Ticks t0 = r.log[1].at, t1 = r.log[2].at;
  const auto ev = obs_from(r, t0);
  ASSERT_EQ(ev.size(), 3u);
  expect_ob72(ev[0], t0, 0, HReason::StandbyStop);
  expect_io(ev[1], t0, 0x39C3, 1, 0);
  expect_io(ev[2], t1 + 2000 * kMs, 0x38C3, 1, 0);  // RUN + LINK-UP 2 000 ms: UPDATE starts
  EXPECT_EQ(r.diag_checks, 2);                        // "sync error (F18)" on both CPUs
}

TEST(HCampaignLink, MasterHoldRefusesTheLinkUpUntilReleased) {
  // STOP standby, HOLD, RUN (refused), release, RUN: 5 injections.
  const HCampaignResult r = run_one(HFault::MasterHold, 5);
  ASSERT_EQ(r.log.size(), 6u);
  const bus::Ticks t0 = r.log[1].at, t5 = r.log[5].at;
  const auto ev = obs_from(r, t0);
  ASSERT_EQ(ev.size(), 3u);  // nothing while the master is in HOLD, none at the refused RUN
  expect_ob72(ev[0], t0, 0, HReason::StandbyStop);
  expect_io(ev[1], t0, 0x39C3, 1, 0);
  expect_io(ev[2], t5 + 2000 * kMs, 0x38C3, 1, 0);
  EXPECT_GT(r.cleared_samples, 0u);  // HOLD: the master's DP master in Clear, outputs 0
  EXPECT_EQ(r.refusals, 2);          // HOLD in Redundant, RUN while the master is in HOLD
  EXPECT_EQ(r.diag_checks, 1);  // the refusal in the master's buffer
  EXPECT_EQ(r.role_swaps, 0);
}

TEST(HCampaignLink, LoadMemoryErrorNeedsAMemoryReset) {
  // F2, RUN (refused: reset request), MRES + RUN: 3 injections.
  const HCampaignResult r = run_one(HFault::LoadMemoryError, 3);
  ASSERT_EQ(r.log.size(), 4u);
  const bus::Ticks t0 = r.log[1].at, t3 = r.log[3].at;
  const int rack = r.log[1].what.back() - '0';  // "...: rack r"
  ASSERT_TRUE(rack == 0 || rack == 1) << r.log[1].what;
  const int partner = 1 - rack;  // master afterwards (F2 on the master: the standby takes over)
  const auto ev = obs_from(r, t0);
  ASSERT_EQ(ev.size(), 3u);
  expect_ob72(ev[0], t0, partner, rack == 0 ? HReason::MasterStop : HReason::StandbyStop);
  expect_io(ev[1], t0, 0x39C3, rack, partner);
  expect_io(ev[2], t3 + 2000 * kMs, 0x38C3, rack, partner);  // MRES + RUN + LINK-UP
  EXPECT_EQ(r.refusals, 1);
  EXPECT_EQ(r.role_swaps, rack == 0 ? 1 : 0);
}

TEST(HCampaignLink, UpdateTimeoutAbortsAtTp15AndRetriesAfterSixtySeconds) {
  // STOP (1024 KB changed), RUN, KB back: 3 injections; 1 or 2 updates time out (drawn).
  const HCampaignResult r = run_one(HFault::UpdateTimeout, 3);
  ASSERT_EQ(r.log.size(), 4u);
  const bus::Ticks t0 = r.log[1].at, t1 = r.log[2].at;
  const int n = r.update_timeouts;
  ASSERT_TRUE(n == 1 || n == 2) << n;
  const auto ev = obs_from(r, t0);
  ASSERT_EQ(ev.size(), static_cast<std::size_t>(2 + 3 * n + 1));
  expect_ob72(ev[0], t0, 0, HReason::StandbyStop);
  expect_io(ev[1], t0, 0x39C3, 1, 0);
  bus::Ticks link = t1;
  for (int i = 0; i < n; ++i) {
    // UPDATE at link + 2 000 ms; W = 75 + 0.7 x 1024 = 791.8 ms > T_P15 = 194 ms: the abort at
    // t3 + 194 ms = link + 2 194 ms; the retry 60 000 ms after it.
    const bus::Ticks up = link + 2000 * kMs, abort = up + 194 * kMs;
    expect_io(ev[2 + 3 * i], up, 0x38C3, 1, 0);
    expect_ob72(ev[3 + 3 * i], abort, 0, HReason::UpdateTimeout);
    expect_io(ev[4 + 3 * i], abort, 0x39C3, 1, 0);
    link = abort + 60000 * kMs;
  }
  // The KB were reset before the last retry: its update (145 ms) succeeds.
  EXPECT_LT(r.log[3].at, link);
  expect_io(ev[2 + 3 * n], link + 2000 * kMs, 0x38C3, 1, 0);
  // Settled from the retry (LINK-UP + W = 2 145 ms, 2 150 at the 10 ms polling) within the
  // start-up's 3 150 ms (STARTUP 1 000 + LINK-UP 2 000 + W 145, polled): the longest stays it.
  EXPECT_EQ(r.max_settle, 3150 * kMs);
  EXPECT_EQ(r.update_timeouts, n);
}

TEST(HCampaignLink, StandbyLostInTheLoadMemoryCopyGetsAResetRequest) {
  // STOP, RUN (LINK-UP), power off in the copy, power on + MRES + RUN: 4 injections.
  const HCampaignResult r = run_one(HFault::StandbyLostDuringLinkUp, 4);
  ASSERT_EQ(r.log.size(), 5u);
  const bus::Ticks t0 = r.log[1].at, t2 = r.log[2].at, t3 = r.log[3].at, t4 = r.log[4].at;
  EXPECT_GT(t3, t2);
  EXPECT_LT(t3 - t2, 1000 * kMs);  // inside the load-memory copy (half of LINK-UP)
  const auto ev = obs_from(r, t0);
  ASSERT_EQ(ev.size(), 3u);  // no OB 72 and no 39C3 at the power-off (Solo, side never ran)
  expect_ob72(ev[0], t0, 0, HReason::StandbyStop);
  expect_io(ev[1], t0, 0x39C3, 1, 0);
  expect_io(ev[2], t4 + 2000 * kMs, 0x38C3, 1, 0);
  EXPECT_EQ(r.diag_checks, 1);  // W#16#6523
}

TEST(HCampaignLink, StructuralChangeStopsBothAndBothRestart) {
  // The change, RUN both: 2 injections.
  const HCampaignResult r = run_one(HFault::LoadChange, 2);
  ASSERT_EQ(r.log.size(), 3u);
  const bus::Ticks t0 = r.log[1].at, t1 = r.log[2].at;
  EXPECT_EQ(r.log[1].expected, 0);  // no OB 72 (nobody runs), the 39C3 only a diag entry
  EXPECT_GT(r.cleared_samples, 0u);   // both in STOP: the master's DP master Clear, outputs 0
  const auto ev = obs_from(r, t0);
  ASSERT_EQ(ev.size(), 1u);
  // RUN at t1: the master's STARTUP 1 000 ms, then the standby's LINK-UP 2 000 ms.
  expect_io(ev[0], t1 + 3000 * kMs, 0x38C3, 1, 0);
  EXPECT_EQ(r.role_swaps, 0);
}

TEST(HCampaignLink, ParameterChangeRefusesTheSwap) {
  // STOP, the swap request (refused), RUN: 3 injections.
  const HCampaignResult r = run_one(HFault::ParameterChangeSwap, 3);
  ASSERT_EQ(r.log.size(), 4u);
  const bus::Ticks t0 = r.log[1].at, t3 = r.log[3].at;
  const auto ev = obs_from(r, t0);
  ASSERT_EQ(ev.size(), 3u);  // no OB 72 MasterSwap: no role change
  expect_ob72(ev[0], t0, 0, HReason::StandbyStop);
  expect_io(ev[1], t0, 0x39C3, 1, 0);
  expect_io(ev[2], t3 + 2000 * kMs, 0x38C3, 1, 0);
  EXPECT_EQ(r.refusals, 1);
  EXPECT_EQ(r.diag_checks, 2);  // W#16#5966 on both
  EXPECT_EQ(r.role_swaps, 0);
}

// The changed DBs set large without telling the observer: the restart of a standby STOP cycle
// times out: OB 72 UpdateTimeout and the standby's 39C3 are unexpected, Redundant is not
// reached within the settle limit.
TEST(HCampaignLink, ObserverCatchesAnUpdateTimeoutItWasNotToldAbout) {
  HCampaignOptions o;
  o.seed = 3;
  o.steps = 2;
  o.gsd_dir = std::string(PBVBUS_SOURCE_DIR) + "/examples/gsd";
  o.weights = {};
  o.weights[static_cast<int>(HFault::StandbyStop)] = 1;
  o.tamper.hidden_update_timeout_at = 0;
  const HCampaignResult r = run_h_campaign(o);
  std::cout << r.summary() << "\n";
  for (const auto& m : r.mismatches) std::cout << "  mismatch: " << m << "\n";
  auto has = [&](const char* a, const char* b) {
    return std::any_of(r.mismatches.begin(), r.mismatches.end(), [&](const std::string& m) {
      return m.find(a) != std::string::npos && m.find(b) != std::string::npos;
    });
  };
  EXPECT_TRUE(has("RUN rack 1", "unexpected [OB 72 update timeout"));
  EXPECT_TRUE(has("RUN rack 1", "unexpected [OB 86 39C3"));
  EXPECT_TRUE(has("not back in Redundant", "RUN rack 1"));
}

// Unusable H parameters and F19 settings are refused before anything runs.
TEST(HCampaignLink, BadLinkUpOptionsAreRefused) {
  HCampaignOptions o;
  o.gsd_dir = std::string(PBVBUS_SOURCE_DIR) + "/examples/gsd";
  o.h_parameters.t_ph = ms(200);  // T_P15 194 ms > T_PH fails, 50 + T_PH > T_P15 too
  EXPECT_THROW(run_h_campaign(o), std::invalid_argument);
  o = HCampaignOptions{};
  o.h_parameters = {ms(1000), ms(400), ms(100), ms(30)};  // valid, but 145 ms > T_P15 100 ms
  EXPECT_THROW(run_h_campaign(o), std::invalid_argument);
  o = HCampaignOptions{};
  o.update_timeout_kb = 100;  // W = 145 ms fits in T_P15: no timeout to draw
  EXPECT_THROW(run_h_campaign(o), std::invalid_argument);
  o = HCampaignOptions{};
  o.update_timeout_failures_max = 11;
  EXPECT_THROW(run_h_campaign(o), std::invalid_argument);
}

}  // namespace
}  // namespace pbvbus::devices
