// The H-system model with SFC 90 from the user program (h_system_sfc90.cpp, docs/h-sfc90.md):
// the manual's cam example (T6, T7), the watchdog OBs across an update (R7) and the S7 jobs
// held by the update. No DP line: the cam switch is a central input module in expansion rack 1
// of CPU 0 (read at every OB 1, no bus: t_IO = 0), so every time is the pair's arithmetic:
//   power_on_both() at 0 → STARTUP 1 s → Solo at 1.000 s (first OB 1; OB 1 every 10 ms);
//   the standby links up 1.000 s .. 3.000 s → UPDATE t1 = t3 = 3.000 s,
//   W = T_P15_AWP = 75 ms + 0.7 ms x 100 KB = 145 ms → t5 = 3.145 s, Redundant.
//
// The cam (001 L4741-4745, 000 §5.2.4 L1289-1298): a carriage with a 50 mm cam at
// v = 10 km/h = 2.78 mm/ms closes the switch for Δt = 50 / 2.78 = 18 ms. Here it passes every
// 500 ms: the switch is closed in [k·500 + 103, k·500 + 121) ms (103 so that no edge falls on
// an OB 1 start, which are at whole 10 ms before the update).
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "hex.hpp"
#include "pbvbus/bus/scheduler.hpp"
#include "pbvbus/s7h/h_system.hpp"

namespace pbvbus::devices {
namespace {

using bus::Ticks;
constexpr Ticks ms(std::int64_t v) { return v * bus::kTicksPerMs; }
constexpr Ticks kScan = ms(10);
constexpr Ticks kT1 = ms(3000);
constexpr Ticks kW = ms(75) + 100 * (ms(7) / 10);  // T_P15_AWP(100 KB) = 145 ms
static_assert(kW == ms(145));
constexpr Ticks kT5 = kT1 + kW;  // 3.145 s
constexpr Ticks kCamPeriod = ms(500);
constexpr Ticks kCamOn = ms(103);
constexpr Ticks kCamPulse = ms(18);  // 50 mm / 2.78 mm/ms

std::vector<HExpansionRack> cam_rack() {
  HRackModule cam;
  cam.name = "cam switch DI";
  cam.in_len = 1;
  cam.out_len = 1;
  cam.inputs = IoBehaviour::table({{0, 0}, {kCamOn, 1}, {kCamOn + kCamPulse, 0}}, true,
                                  kCamPeriod);
  HExpansionRack r;
  r.number = 1;
  r.side = 0;
  r.modules.push_back(cam);
  return {r};
}

// The program: OB 1 counts the switch's rising edges (the first OB 1 that sees it closed).
struct Cam {
  bus::Scheduler sched;
  std::unique_ptr<HSystemModel> h;
  bool last = false;
  std::vector<Ticks> seen;  // OB 1 times that saw a new pulse
  std::function<void(Ticks)> extra;  // more of OB 1 (SFC 90 calls)

  Cam() {
    h = std::make_unique<HSystemModel>(sched, HCpuPairParams{},
                                       std::vector<RedundantMasterSystemModel*>{}, cam_rack());
    h->set_program(
        [this](std::span<const std::uint8_t> pii, std::span<std::uint8_t>, Ticks now) {
          const bool on = (pii[0] & 1) != 0;
          if (on && !last) seen.push_back(now);
          last = on;
          if (extra) extra(now);
        },
        kScan);
  }
  void run(Ticks t) { sched.run_until(t); }
};

// The pulses that start in [from, to).
std::vector<Ticks> pulses(Ticks from, Ticks to) {
  std::vector<Ticks> v;
  for (Ticks t = kCamOn; t < to; t += kCamPeriod)
    if (t >= from) v.push_back(t);
  return v;
}

TEST(HSfc90Cam, T6EighteenMsIsBelowAnySettableTp15) {
  // STEP 7 allows T_P15 = 0 or 100..60000 ms (digest §3.1, 001 L4747-4752): the blocking time
  // for classes > 15 "must be noticeably less than 18 ms", and no settable value is.
  EXPECT_FALSE(t_p15_settable(18 * kUsPerMs));
  EXPECT_FALSE(t_p15_settable(99 * kUsPerMs));
  EXPECT_TRUE(t_p15_settable(100 * kUsPerMs));  // the smallest non-zero value
  EXPECT_GT(100 * kUsPerMs, 18 * kUsPerMs);
}

TEST(HSfc90Cam, T7WithoutSfc90ThePulseInsideTheUpdateIsNotSeen) {
  // T7 (000 L1066-1079, 001 L4404-4440): minimum signal duration
  //   > 2·t_IO (0: central I/O, "for DP only") + call interval of OB 1 (10 ms)
  //     + its run time (0 in the model) + update (75 + 0.7·100 = 145 ms) + higher classes (0)
  //   = 155 ms > 18 ms: a cam pulse can be lost.
  constexpr Ticks kMinDuration = 2 * 0 + kScan + 0 + kW + 0;
  static_assert(kMinDuration == ms(155));
  static_assert(kCamPulse < kMinDuration);
  Cam c;
  c.h->power_on_both();
  c.run(ms(4000));
  ASSERT_EQ(c.h->pair().system_mode(), SystemMode::Redundant);
  ASSERT_EQ(c.h->pair().update_window()->t1, kT1);
  ASSERT_EQ(c.h->pair().update_window()->t5, kT5);
  // Pulses 1.103, 1.603, 2.103, 2.603, 3.103, 3.603 s; the one at 3.103 .. 3.121 s lies in
  // [t1, t5) = [3.000, 3.145) s: no OB 1 sees it. OB 1 restarts at t5 = 3.145 s (phase 5 ms),
  // so the 3.603 s pulse is seen at 3.145 + 46 x 10 ms = 3.605 s.
  EXPECT_EQ(pulses(ms(1000), ms(4000)).size(), 6u);
  const std::vector<Ticks> want{ms(1110), ms(1610), ms(2110), ms(2610), ms(3605)};
  EXPECT_EQ(c.seen, want);
}

TEST(HSfc90Cam, Sfc90BlocksTheUpdateWhileTheCamMayPulseEveryPulseSeen) {
  // The manual's remedy (001 L4755-4760): move the update to a time when the process is not
  // critical. OB 1 disables the update at its first scan (MODE 3) and re-enables it (MODE 4)
  // when the cam has passed: at a cycle phase in [150, 300) ms the 145 ms update ends before
  // the next pulse at phase 103 ms of the next 500 ms.
  Cam c;
  std::vector<std::uint16_t> rv;
  c.extra = [&](Ticks now) {
    if (c.h->scans() == 1) rv.push_back(c.h->h_ctrl(3, 0));
    const Ticks phase = now % kCamPeriod;
    if (c.h->pair().update_waiting() && phase >= ms(150) && phase < ms(300))
      rv.push_back(c.h->h_ctrl(4, 0));
  };
  c.h->power_on_both();
  c.run(ms(4000));
  EXPECT_EQ(rv, (std::vector<std::uint16_t>{0x0000, 0x0000}));
  // The link-up is done at 3.000 s and waits; the OB 1 at 3.150 s (phase 150 ms) re-enables:
  // t1 = 3.150 s (after that OB 1), t5 = 3.150 + 0.145 = 3.295 s.
  const auto w = c.h->pair().update_window();
  ASSERT_TRUE(w.has_value());
  EXPECT_EQ(w->t1, ms(3150));
  EXPECT_EQ(w->t5, ms(3295));
  EXPECT_EQ(c.h->pair().system_mode(), SystemMode::Redundant);
  // Every pulse seen: the 3.103 s one at 3.110 s (still Link-up, OB 1 runs); after t5 OB 1
  // runs at 3.295 + 10·n ms, so the 3.603 s pulse is seen at 3.605 s.
  const std::vector<Ticks> want{ms(1110), ms(1610), ms(2110), ms(2610), ms(3110), ms(3605)};
  EXPECT_EQ(c.seen, want);
  ASSERT_EQ(c.h->h_ctrl_calls().size(), 2u);
  EXPECT_EQ(c.h->h_ctrl_calls()[0].at, ms(1000));
  EXPECT_EQ(c.h->h_ctrl_calls()[1].at, ms(3150));
}

TEST(HSfc90Cam, ProgramSpecCallsSfc90AtItsTime) {
  // The same through a ProgramSpec: MODE 3 at the first OB 1, MODE 4 at the first OB 1 at or
  // after 3.150 s (the OB 1 at 3.150 s): t1 = 3.150 s.
  Cam c;
  ProgramSpec p;
  p.scan_time = kScan;
  p.copies.push_back({0, 0, 1, false});  // the cam switch to its output, as a lamp
  p.h_ctrl_calls.push_back({0, 3, 0});
  p.h_ctrl_calls.push_back({ms(3150), 4, 0});
  c.h->set_program(p);
  c.h->power_on_both();
  c.run(ms(3100));
  EXPECT_EQ(c.h->pair().state(1), CpuState::LinkUp);
  EXPECT_TRUE(c.h->pair().update_waiting());
  c.run(ms(3400));
  ASSERT_TRUE(c.h->pair().update_window().has_value());
  EXPECT_EQ(c.h->pair().update_window()->t1, ms(3150));
  EXPECT_EQ(c.h->pair().system_mode(), SystemMode::Redundant);
  ASSERT_EQ(c.h->h_ctrl_calls().size(), 2u);
  EXPECT_EQ(c.h->h_ctrl_calls()[0].at, ms(1000));
  EXPECT_EQ(c.h->h_ctrl_calls()[0].ret_val, 0x0000);
  EXPECT_EQ(c.h->h_ctrl_calls()[1].at, ms(3150));
}

// ---- R7: watchdog OBs run at most once at the end of the update, their phase restarts ----

TEST(HSfc90Cam, R7WatchdogObRunsOnceAtTheEndOfTheUpdateAndLosesItsPhase) {
  Cam c;
  c.h->power_on_both();
  c.run(ms(1505));  // Solo since 1.000 s
  int body = 0;
  c.h->set_watchdog_ob(35, ms(100), [&](Ticks) { ++body; });
  c.h->set_watchdog_ob(32, ms(1000));
  c.run(ms(3500));
  // OB 35: requests every 100 ms from 1.505 s: 1.605 .. 2.905 s run (14 of them); 3.005 and
  // 3.105 s fall in [t1, t5) = [3.000, 3.145) s: no request; one run at t5 = 3.145 s, then
  // every 100 ms from there: 3.245, 3.345, 3.445 s (the old phase .x05 is lost).
  // OB 32: 2.505 s; 3.505 s lies after t5 and lost nothing: it keeps its phase (3.505 s, after
  // the end of this run).
  std::vector<Ticks> ob35, ob35_after;
  std::vector<Ticks> ob32;
  for (const auto& r : c.h->watchdog_runs()) {
    if (r.ob == 35) (r.after_update ? ob35_after : ob35).push_back(r.at);
    if (r.ob == 32) ob32.push_back(r.at);
  }
  std::vector<Ticks> want35;
  for (Ticks t = ms(1605); t <= ms(2905); t += ms(100)) want35.push_back(t);
  ASSERT_EQ(want35.size(), 14u);
  for (const Ticks t : {ms(3245), ms(3345), ms(3445)}) want35.push_back(t);
  EXPECT_EQ(ob35, want35);
  EXPECT_EQ(ob35_after, std::vector<Ticks>{kT5});
  EXPECT_EQ(body, 18);
  EXPECT_EQ(ob32, std::vector<Ticks>{ms(2505)});
  c.run(ms(3600));
  ob32.clear();
  for (const auto& r : c.h->watchdog_runs())
    if (r.ob == 32) ob32.push_back(r.at);
  EXPECT_EQ(ob32, (std::vector<Ticks>{ms(2505), ms(3505)}));
  EXPECT_THROW(c.h->set_watchdog_ob(39, ms(100)), std::invalid_argument);
  EXPECT_THROW(c.h->set_watchdog_ob(30, 0), std::invalid_argument);
}

TEST(HSfc90Cam, R7NoWatchdogRequestsWhileTheUpdateIsDisabledWaiting) {
  // While the update waits (SFC 90 MODE 3) the system is in Link-up: every OB runs (digest
  // §4 "Link-up vs update"), so the watchdog keeps its phase until the update really runs.
  Cam c;
  c.h->power_on_both();
  c.run(ms(1005));
  c.h->h_ctrl(3, 0);
  c.h->set_watchdog_ob(35, ms(100));
  c.run(ms(3500));
  std::size_t n = 0;
  for (const auto& r : c.h->watchdog_runs()) n += (r.ob == 35 && !r.after_update) ? 1 : 0;
  // 1.105 .. 3.405 s: 24 runs, none lost.
  EXPECT_EQ(n, 24u);
  EXPECT_EQ(c.h->pair().state(1), CpuState::LinkUp);
}

// ---- S7 jobs held during the update (000 L1673-1680) ----

std::vector<std::uint8_t> hex(std::string_view s) {
  std::string clean;
  for (const char ch : s)
    if (ch != '|') clean.push_back(ch);
  return test::bytes_from_hex(clean);
}
// Setup Communication and its answer (the S7 door tests' frames, h_s7_test.cpp).
const std::vector<std::uint8_t> kSetup = hex("32 01 00 00 00 00 00 08 00 00 | F0 00 00 01 00 01 01 E0");
const std::vector<std::uint8_t> kSetupAnswer =
    hex("32 03 00 00 00 00 00 08 00 00 00 00 | F0 00 00 01 00 01 00 F0");
// Read SZL W#16#0424 index 0: the CPU's state octet (bzu_id) at answer[37].
const std::vector<std::uint8_t> kSzl0424 =
    hex("32 07 00 00 00 14 00 08 00 08 | 00 01 12 04 11 44 01 00 | FF 09 00 04 04 24 00 00");

TEST(HSfc90Cam, S7JobsArrivingDuringTheUpdateAreAnsweredAfterIt) {
  Cam c;
  c.h->power_on_both();
  c.run(ms(500));  // STARTUP: connections accepted (R8 refuses them from the link-up at 1 s)
  HS7Session s = c.h->open_s7_adhoc(0);
  ASSERT_TRUE(s.alive());
  ASSERT_EQ(s.handle(kSetup), kSetupAnswer);  // answered at once outside the update
  std::vector<std::pair<Ticks, std::vector<std::uint8_t>>> late;
  s.on_late_answer([&](std::vector<std::uint8_t> a) { late.emplace_back(c.sched.now(), a); });
  c.run(ms(3050));  // inside [t1, t5) = [3.000, 3.145) s
  ASSERT_TRUE(c.h->pair().interrupts_held());
  EXPECT_TRUE(s.handle(kSzl0424).empty());  // stored, no answer now
  EXPECT_TRUE(s.handle(kSetup).empty());
  EXPECT_EQ(c.h->held_s7_jobs(), 2u);
  c.run(kT5 - 1);
  EXPECT_TRUE(late.empty());
  c.run(kT5);
  // Both answered at t5 in arrival order; the SZL answer shows RUN-R (09): it was run after the
  // update, in Redundant mode.
  ASSERT_EQ(late.size(), 2u);
  EXPECT_EQ(late[0].first, kT5);
  ASSERT_GT(late[0].second.size(), 37u);
  EXPECT_EQ(late[0].second[37], 0x09);
  EXPECT_EQ(late[1].second, kSetupAnswer);
  EXPECT_EQ(c.h->held_s7_jobs(), 0u);
  EXPECT_EQ(s.handle(kSetup), kSetupAnswer);  // at once again
}

TEST(HSfc90Cam, S7SessionWithoutSinkIsStillAnsweredAtOnce) {
  Cam c;
  c.h->power_on_both();
  c.run(ms(500));
  HS7Session s = c.h->open_s7_adhoc(0);
  ASSERT_TRUE(s.alive());
  c.run(ms(3050));
  EXPECT_EQ(s.handle(kSetup), kSetupAnswer);
  EXPECT_EQ(c.h->held_s7_jobs(), 0u);
}

TEST(HSfc90Cam, HeldJobOfAClosedSessionIsDropped) {
  Cam c;
  c.h->power_on_both();
  c.run(ms(500));
  int answers = 0;
  {
    HS7Session s = c.h->open_s7_adhoc(0);
    s.on_late_answer([&](std::vector<std::uint8_t>) { ++answers; });
    c.run(ms(3050));
    EXPECT_TRUE(s.handle(kSetup).empty());
  }  // released during the update
  c.run(ms(3300));
  EXPECT_EQ(answers, 0);
  EXPECT_EQ(c.h->held_s7_jobs(), 0u);
}

// ---- OB 72 on the return to Redundant, SFC 27 UPDAT_PO (000 L1752, L1886; 001 L5526) ----
//
// Rack 2 hangs on CPU 1 (the standby): one-sided outputs of the standby. Module 0 "DO part 1" is
// in process-image partition 1 (written only by SFC 27), module 1 "DO OB 1" in the OB 1 image.
// OB 1 writes 0x11 into both until 5 s, then 0x22, and calls SFC 27 for partition 1 only when
// the value changes (event-driven). Times: Redundant at 3.145 s; the standby STOPs at 4 s;
// the value changes at 5 s (rack 2 unreachable: its CPU does not run); STOP -> RUN at 6 s:
// LINK-UP 6 .. 8 s, UPDATE 8 .. 8.145 s, Redundant at 8.145 s.
struct OneSided {
  bus::Scheduler sched;
  std::unique_ptr<HSystemModel> h;
  std::uint8_t written = 0;
  explicit OneSided(bool sfc27_in_ob72) {
    HRackModule part;
    part.name = "DO part 1";
    part.out_len = 1;
    part.partition = 1;
    HRackModule ob1;
    ob1.name = "DO OB 1";
    ob1.out_len = 1;
    HExpansionRack r;
    r.number = 2;
    r.side = 1;
    r.modules = {part, ob1};
    h = std::make_unique<HSystemModel>(sched, HCpuPairParams{},
                                       std::vector<RedundantMasterSystemModel*>{},
                                       std::vector<HExpansionRack>{r});
    h->set_program(
        [this](std::span<const std::uint8_t>, std::span<std::uint8_t> piq, Ticks now) {
          const std::uint8_t v = now < ms(5000) ? 0x11 : 0x22;
          piq[0] = v;
          piq[1] = v;
          if (v != written) {
            written = v;
            h->updat_po(1);
          }
        },
        kScan);
    if (sfc27_in_ob72) h->set_ob72_return([this](Ticks) { h->updat_po(1); });
  }
  std::uint8_t part() const { return h->rack_outputs(2, 0)[0]; }
  std::uint8_t ob1() const { return h->rack_outputs(2, 1)[0]; }
  void run() {
    h->power_on_both();
    sched.run_until(ms(3200));
  }
};

TEST(HSfc90Cam, Ob72WithoutSfc27TheStandbysPartitionOutputsKeepStaleValues) {
  OneSided o(false);
  o.run();
  EXPECT_EQ(o.h->redundancy_returns(), std::vector<Ticks>{kT5});
  EXPECT_EQ(o.ob1(), 0x11);   // the OB 1 image reaches the standby's modules
  EXPECT_EQ(o.part(), 0x00);  // SFC 27 ran at 1.000 s, when rack 2 was not reachable
  o.sched.run_until(ms(4000));
  o.h->switch_to_stop(1);  // Solo from 4 s
  o.sched.run_until(ms(6000));
  o.h->switch_to_run(1);
  o.sched.run_until(ms(8200));
  EXPECT_EQ(o.ob1(), 0x22);
  EXPECT_EQ(o.part(), 0x00);  // stale: the change at 5 s was sent while rack 2 was unreachable
  EXPECT_EQ(o.h->updat_po(0), 0x8090);
  EXPECT_EQ(o.h->updat_po(16), 0x8090);
}

TEST(HSfc90Cam, Ob72WithSfc27RefreshesTheStandbysPartitionOutputs) {
  OneSided o(true);
  o.run();
  EXPECT_EQ(o.part(), 0x11);  // OB 72 at 3.145 s called SFC 27
  o.sched.run_until(ms(4000));
  o.h->switch_to_stop(1);  // Solo from 4 s; 0x22 from 5 s is not sent to rack 2
  o.sched.run_until(ms(6000));
  EXPECT_EQ(o.part(), 0x11);
  o.h->switch_to_run(1);
  o.sched.run_until(ms(8145) - 1);
  EXPECT_EQ(o.part(), 0x11);
  o.sched.run_until(ms(8145));
  EXPECT_EQ(o.part(), 0x22);  // at the return to Redundant, 8.145 s
  EXPECT_EQ(o.h->redundancy_returns(), (std::vector<Ticks>{kT5, ms(8145)}));
}

}  // namespace
}  // namespace pbvbus::devices
