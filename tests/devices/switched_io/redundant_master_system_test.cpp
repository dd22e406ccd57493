// The redundant DP master system (devices/redundant_master_system.hpp, redundancy::MasterSystem)
// on two bus::Lines at 1.5 Mbit/s: two switched stations (PBVB0A10, T_SLAVE_UM 30 ms, at 5;
// PBVB0A11, 820 ms, at 6) on both lines, one one-sided slave per line (PBVB0A01 at 10 on A, at
// 11 on B). The program writes one 16-bit counter into every output module through the system
// (both lines alike), so "no pulse" is checkable: sampled after every frame on either line, a
// station's backplane outputs never drop to 0 and never go back to an older (smaller) value.
// Events are asserted with their S7 codes, lines, stations and times (seeds-digest.md §2, §7,
// §11 S1–S4, F9–F11, F13, F14, F24).
#include <gtest/gtest.h>

#include <algorithm>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "pbvbus/bus/line.hpp"
#include "pbvbus/bus/scheduler.hpp"
#include "pbvbus/gsd/gsd.hpp"
#include "pbvbus/switched_io/redundant_master_system.hpp"
#include "pbvbus/slaves/slave_model.hpp"
#include "pbvbus/switched_io/switched_station.hpp"
#include "pbvbus/redundancy/switchover_timing.hpp"

namespace pbvbus::devices {
namespace {

using Bytes = std::vector<std::uint8_t>;
using redundancy::SystemEvent;
using K = SystemEvent::Kind;

constexpr bus::Baud kBaud = bus::Baud::k1_5M;
constexpr bus::Ticks kMs = bus::kTicksPerMs;
constexpr std::uint8_t kFast = 5;  // PBVB0A10, switchover time 30 ms
constexpr std::uint8_t kSlow = 6;  // PBVB0A11, 820 ms
constexpr std::uint8_t kOneA = 10;
constexpr std::uint8_t kOneB = 11;

GsdFile load(const char* name) {
  auto r = load_gsd(std::string(PBVBUS_SOURCE_DIR) + "/examples/gsd/" + name);
  EXPECT_TRUE(r.ok()) << name;
  return *r.file;
}

std::vector<ModuleChoice> switched_modules() {
  return {ModuleChoice::named("16DI DC24V"), ModuleChoice::named("16DO DC24V/0.5A")};
}
std::vector<ModuleChoice> plain_modules() { return {ModuleChoice::named("16DI/16DO DC24V")}; }

struct System {
  bus::Scheduler sched;
  bus::Line line[2] = {bus::Line{sched, "A", kBaud}, bus::Line{sched, "B", kBaud}};
  fdl::BusParams bp = fdl::BusParams::defaults(kBaud);
  std::unique_ptr<RedundantMasterSystemModel> sys;
  std::unique_ptr<SwitchedStationModel> st[2];  // kFast, kSlow
  std::unique_ptr<SlaveModel> one[2];           // kOneA on A, kOneB on B
  bus::AttachmentId one_att[2] = {-1, -1};
  std::uint16_t counter = 0;
  std::vector<std::pair<int, dp::MasterEvent>> master_events;

  /// im_time: the stations take their IM's own switchover time (T_SLAVE_UM 30 ms / 820 ms,
  /// drawn in [T/2, T] with the seed `seed` ^ address).
  explicit System(bool im_time = false, std::uint64_t seed = 0) {
    bp.hsa = 12;
    const GsdFile fast = load("PBVB0A10.gsd");
    const GsdFile slow = load("PBVB0A11.gsd");
    const GsdFile plain = load("PBVB0A01.gsd");
    std::vector<dp::SlaveParams> cfg[2];
    for (int l = 0; l < 2; ++l) {
      for (auto [gsd, a] : {std::pair{&fast, kFast}, std::pair{&slow, kSlow}}) {
        auto sp = master_slave_params(*gsd, switched_modules(), a);
        EXPECT_TRUE(sp.ok());
        dp::SlaveParams p = *sp.value;
        p.prm_cmd.assign(8, 0);  // the MasterSystem writes the block
        cfg[l].push_back(p);
      }
      auto sp = master_slave_params(plain, plain_modules(), l == 0 ? kOneA : kOneB);
      EXPECT_TRUE(sp.ok());
      cfg[l].push_back(*sp.value);
    }
    RedundantMasterSystemOptions o;
    o.bus_params = bp;
    std::vector<redundancy::SwitchedStationRef> refs{{kFast, 30 * kMs, false},
                                                      {kSlow, 820 * kMs, false}};
    sys = std::make_unique<RedundantMasterSystemModel>(o, cfg[0], cfg[1], refs);
    sys->set_master_event_handler(
        [this](int l, const dp::MasterEvent& e) { master_events.emplace_back(l, e); });
    // The program: one counter, written into every output module of every slave, both lines.
    sys->set_cycle_hook([this](RedundantMasterSystemModel& m, int, bus::Ticks) {
      ++counter;
      const Bytes v{static_cast<std::uint8_t>(counter >> 8), static_cast<std::uint8_t>(counter)};
      m.system().write_outputs(kFast, 1, v);
      m.system().write_outputs(kSlow, 1, v);
      m.system().write_outputs(kOneA, 0, v);
      m.system().write_outputs(kOneB, 0, v);
    });
    // Line order: master, switched 5, switched 6, one-sided (cable positions for the cut test).
    for (int l = 0; l < 2; ++l) sys->attach(l, line[l], "master 1");
    int k = 0;
    for (auto [gsd, a] : {std::pair{&fast, kFast}, std::pair{&slow, kSlow}}) {
      SwitchedStationOptions so;
      so.address = a;
      so.bus_params = bp;
      if (im_time) {
        so.redundancy.im_switchover_bound = (a == kFast ? 30 : 820) * kMs;
        so.redundancy.im_seed = seed ^ a;
      }
      auto b = SwitchedStationModel::build(*gsd, switched_modules(), so);
      EXPECT_TRUE(b.ok()) << (b.errors.empty() ? "" : b.errors[0]);
      st[k] = std::move(b.model);
      for (int l = 0; l < 2; ++l) st[k]->attach(l, line[l]);
      ++k;
    }
    for (int l = 0; l < 2; ++l) {
      SlaveModelOptions so;
      so.address = l == 0 ? kOneA : kOneB;
      so.bus_params = bp;
      auto b = SlaveModel::build(plain, plain_modules(), so);
      EXPECT_TRUE(b.ok());
      one[l] = std::move(b.model);
      one_att[l] = line[l].attach(*one[l], "one-sided");
    }
  }
  void start() {
    line[0].start();
    line[1].start();
  }
  void run_until(bus::Ticks t) { sched.run_until(t); }
  redundancy::MasterSystem& ms() { return sys->system(); }
  SwitchedStationModel& station(std::uint8_t a) { return *st[a == kFast ? 0 : 1]; }

  /// The S7 events (Switchover records left out), in order.
  std::vector<SystemEvent> s7() const {
    std::vector<SystemEvent> out;
    for (const auto& e : sys->system().events())
      if (e.s7()) out.push_back(e);
    return out;
  }
  std::vector<SystemEvent> s7_since(bus::Ticks t) const {
    auto v = s7();
    v.erase(std::remove_if(v.begin(), v.end(), [t](const SystemEvent& e) { return e.time < t; }),
            v.end());
    return v;
  }
  /// When line l's master reported `kind` for `slave` first at or after `t`.
  bus::Ticks master_event_at(int l, dp::MasterEvent::Kind kind, std::uint8_t slave,
                             bus::Ticks t) const {
    for (const auto& [ln, e] : master_events)
      if (ln == l && e.kind == kind && e.slave == slave && e.time >= t) return e.time;
    return bus::kNever;
  }
};

/// The backplane of both switched stations after every frame on either line.
struct Sampler final : bus::Tap {
  explicit Sampler(System& s) : sys(s) {}
  void on_frame(const bus::TapFrame& f) override {
    for (int k = 0; k < 2; ++k) {
      const auto o = sys.st[k]->outputs();
      samples[k].push_back({f.end, static_cast<std::uint16_t>((o[0] << 8) | o[1])});
    }
  }
  struct Sample {
    bus::Ticks at;
    std::uint16_t value;
  };
  System& sys;
  std::vector<Sample> samples[2];

  /// No pulse from `from` on, once the first outputs arrived (before them the modules are in
  /// their safe state, 0): never 0, never smaller than before (the counter only grows).
  void expect_no_pulse(int k, bus::Ticks from) const {
    std::uint16_t last = 0;
    bool started = false;
    for (const auto& s : samples[k]) {
      started = started || s.value != 0;
      if (s.at < from || !started) {
        last = s.value;
        continue;
      }
      ASSERT_NE(s.value, 0) << "station " << k << " outputs 0 at " << s.at;
      ASSERT_GE(s.value, last) << "station " << k << " older value at " << s.at;
      last = s.value;
    }
  }
};

void expect_event(const SystemEvent& e, K kind, int line, std::uint8_t station, bus::Ticks at) {
  EXPECT_EQ(e.kind, kind) << to_string(e.kind);
  EXPECT_EQ(e.line, line);
  EXPECT_EQ(e.station, station);
  EXPECT_EQ(e.time, at);
}

TEST(RedundantMasterSystem, EventCodesAreTheS7Ones) {
  SystemEvent e;
  const std::pair<K, std::uint16_t> codes[] = {
      {K::RedundancyLoss, 0x73A3},      {K::RedundancyReturn, 0x72A3},
      {K::StationFailure, 0x39C4},      {K::StationReturn, 0x38C4},
      {K::MasterSystemFailure, 0x39C3}, {K::MasterSystemReturn, 0x38C3}};
  for (auto [k, c] : codes) {
    e.kind = k;
    EXPECT_EQ(e.code(), c);
    EXPECT_EQ(e.ob(), k == K::RedundancyLoss || k == K::RedundancyReturn ? 70 : 86);
  }
  e.kind = K::Switchover;
  EXPECT_EQ(e.code(), 0);
  EXPECT_FALSE(e.s7());
}

TEST(RedundantMasterSystem, RefusesAnInconsistentConfiguration) {
  const GsdFile fast = load("PBVB0A10.gsd");
  auto sp = master_slave_params(fast, switched_modules(), kFast);
  ASSERT_TRUE(sp.ok());
  dp::SlaveParams with = *sp.value;
  with.prm_cmd.assign(8, 0);
  RedundantMasterSystemOptions o;
  // Only on line A.
  EXPECT_THROW(RedundantMasterSystemModel(o, {with}, {}, {{kFast, 0, false}}),
               std::invalid_argument);
  // Without a PrmCmd block.
  EXPECT_THROW(RedundantMasterSystemModel(o, {*sp.value}, {*sp.value}, {{kFast, 0, false}}),
               std::invalid_argument);
  // A "one-sided" slave on both lines.
  EXPECT_THROW(RedundantMasterSystemModel(o, {with}, {with}, {}), std::invalid_argument);
  EXPECT_NO_THROW(RedundantMasterSystemModel(o, {with}, {with}, {{kFast, 0, false}}));
}

// S6 and the start-up: both lines in data exchange with every station, line A active for the
// switched stations, no S7 event; the PrmCmd with Primary_Request went out on A only.
TEST(RedundantMasterSystem, StartUpMakesLineAActiveOnEveryStation) {
  System s;
  Sampler smp(s);
  s.line[0].add_tap(smp);
  s.line[1].add_tap(smp);
  s.start();
  s.run_until(150 * kMs);
  for (std::uint8_t a : {kFast, kSlow}) {
    EXPECT_EQ(s.ms().active(a), 0) << int(a);
    EXPECT_TRUE(s.ms().channel_up(a, 0));
    EXPECT_TRUE(s.ms().channel_up(a, 1));
    EXPECT_EQ(s.station(a).primary(), 0);
    EXPECT_EQ(s.sys->master(0).slave_state(a), dp::SlaveStatusState::DataExchange);
    EXPECT_EQ(s.sys->master(1).slave_state(a), dp::SlaveStatusState::DataExchange);
    // Set_Prm block on A: 08 02 00, Seq_Nr 1 (0x08), Primary_Request (0x02), Address_Change
    // (0x04), Output_Hold_Time 100 x 10 ms = 00 64; on B the same without Primary_Request.
    EXPECT_EQ(s.sys->master(0).slave_params(a).prm_cmd,
              (Bytes{0x08, 0x02, 0x00, 0x08, 0x02, 0x04, 0x00, 0x64}));
    EXPECT_EQ(s.sys->master(1).slave_params(a).prm_cmd,
              (Bytes{0x08, 0x02, 0x00, 0x08, 0x00, 0x04, 0x00, 0x64}));
  }
  EXPECT_EQ(s.ms().active(kOneA), 0);
  EXPECT_EQ(s.ms().active(kOneB), 1);
  EXPECT_TRUE(s.s7().empty());
  EXPECT_EQ(s.ms().switchovers(), 0u);
  // One start-up record per switched station: line A, from no channel, when master A read the
  // station's Red_Status showing Primary (its first diagnosis in data exchange).
  int records = 0;
  for (const auto& e : s.ms().events()) {
    ASSERT_EQ(e.kind, K::Switchover);
    EXPECT_EQ(e.cause, SystemEvent::Cause::StartUp);
    EXPECT_EQ(e.line, 0);
    EXPECT_EQ(e.from, -1);
    EXPECT_LT(e.time, 20 * kMs);
    ++records;
  }
  EXPECT_EQ(records, 2);
  // The program's outputs reach the modules: the backplane follows the counter.
  EXPECT_GT(s.station(kFast).outputs()[1] | (s.station(kFast).outputs()[0] << 8), 0);
  smp.expect_no_pulse(0, 0);
  smp.expect_no_pulse(1, 0);
  // Inputs come from the active channel's image.
  ASSERT_NE(s.ms().active_image(kFast), nullptr);
  EXPECT_EQ(s.ms().active_image(kFast), &s.sys->master(0).image(kFast));
}

// S1/F10: the active interface of one station fails → that station only switches to B:
// OB 70 W#16#73A3 on line A at the moment master A reports the failure, no OB 86, outputs
// held without pulse; the other station stays on A. S2: the repair → W#16#72A3, no switch back.
TEST(RedundantMasterSystem, ActiveInterfaceFailureSwitchesThatStationOnly) {
  System s;
  Sampler smp(s);
  s.line[0].add_tap(smp);
  s.line[1].add_tap(smp);
  s.start();
  s.run_until(150 * kMs);
  const bus::Ticks fault = s.sched.now();
  s.station(kFast).fail_interface(0);
  s.run_until(400 * kMs);

  const bus::Ticks seen = s.master_event_at(0, dp::MasterEvent::Kind::StationFailure, kFast, fault);
  ASSERT_NE(seen, bus::kNever);
  auto ev = s.s7();
  ASSERT_EQ(ev.size(), 1u);
  expect_event(ev[0], K::RedundancyLoss, 0, kFast, seen);
  EXPECT_EQ(s.ms().active(kFast), 1);
  EXPECT_EQ(s.station(kFast).primary(), 1);
  EXPECT_EQ(s.ms().active(kSlow), 0);
  EXPECT_EQ(s.station(kSlow).primary(), 0);
  EXPECT_TRUE(s.ms().redundancy_lost(kFast));
  smp.expect_no_pulse(0, 0);
  smp.expect_no_pulse(1, 0);
  // The old line's stored Set_Prm no longer asks for the primary role (no switch back at a
  // later re-start-up); the new line's does, with Seq_Nr 2.
  EXPECT_EQ(s.sys->master(0).slave_params(kFast).prm_cmd[4], 0x00);
  EXPECT_EQ(s.sys->master(1).slave_params(kFast).prm_cmd[4], 0x02);
  EXPECT_EQ(s.sys->master(1).slave_params(kFast).prm_cmd[3], 2 << 3);
  EXPECT_EQ(s.sys->master(1).slave_stats(kFast).prm_cmds, 1u);

  // S2: repair.
  const bus::Ticks repair = s.sched.now();
  s.station(kFast).repair_interface(0);
  s.run_until(700 * kMs);
  const bus::Ticks back =
      s.master_event_at(0, dp::MasterEvent::Kind::DataExchangeEntered, kFast, repair);
  ASSERT_NE(back, bus::kNever);
  ev = s.s7();
  ASSERT_EQ(ev.size(), 2u);
  expect_event(ev[1], K::RedundancyReturn, 0, kFast, back);
  EXPECT_EQ(s.ms().active(kFast), 1);  // no switch back
  EXPECT_EQ(s.station(kFast).primary(), 1);
  EXPECT_FALSE(s.ms().redundancy_lost(kFast));
  smp.expect_no_pulse(0, 0);
}

// S3/F11: after S1 the second interface fails too → OB 86 W#16#39C4 on line B.
TEST(RedundantMasterSystem, SecondInterfaceFailureIsAStationFailure) {
  System s;
  s.start();
  s.run_until(150 * kMs);
  s.station(kFast).fail_interface(0);
  s.run_until(300 * kMs);
  const bus::Ticks fault2 = s.sched.now();
  s.station(kFast).fail_interface(1);
  s.run_until(500 * kMs);
  const bus::Ticks seen = s.master_event_at(1, dp::MasterEvent::Kind::StationFailure, kFast, fault2);
  ASSERT_NE(seen, bus::kNever);
  const auto ev = s.s7();
  ASSERT_EQ(ev.size(), 2u);
  EXPECT_EQ(ev[0].kind, K::RedundancyLoss);
  expect_event(ev[1], K::StationFailure, 1, kFast, seen);
  EXPECT_EQ(s.ms().active(kFast), -1);
  EXPECT_TRUE(s.ms().station_failed(kFast));
  // The first channel back is a station return (38C4), the second restores redundancy (72A3).
  s.station(kFast).repair_interface(1);
  s.run_until(800 * kMs);
  s.station(kFast).repair_interface(0);
  s.run_until(1100 * kMs);
  const auto after = s.s7_since(fault2 + 1);
  ASSERT_EQ(after.size(), 3u);
  EXPECT_EQ(after[1].kind, K::StationReturn);
  EXPECT_EQ(after[1].line, 1);
  EXPECT_EQ(after[2].kind, K::RedundancyReturn);
  EXPECT_EQ(after[2].line, 0);
  EXPECT_EQ(s.ms().active(kFast), 1);
}

// F24: the new channel fails while the switchover to it is under way → the station is lost:
// exactly one 73A3 then one 39C4, both caught.
TEST(RedundantMasterSystem, TotalLossDuringASwitchoverIsCaught) {
  System s;
  s.start();
  s.run_until(150 * kMs);
  s.station(kFast).fail_interface(0);
  // Master A needs its retries before it reports; fail B before the switchover can finish.
  s.run_until(150 * kMs + 200 * bus::kTicksPerUs);
  s.station(kFast).fail_interface(1);
  s.run_until(600 * kMs);
  const auto ev = s.s7();
  ASSERT_EQ(ev.size(), 2u);
  EXPECT_EQ(ev[0].kind, K::RedundancyLoss);
  EXPECT_EQ(ev[0].station, kFast);
  EXPECT_EQ(ev[1].kind, K::StationFailure);
  EXPECT_EQ(ev[1].station, kFast);
  EXPECT_EQ(ev[1].code(), 0x39C4);
  EXPECT_EQ(s.ms().active(kFast), -1);
  EXPECT_EQ(s.ms().switching_to(kFast), -1);
  EXPECT_EQ(s.ms().active(kSlow), 0);
}

// S4/F14: a short circuit on line A → exactly one W#16#39C3 (line A, at the first master A
// activity after the short), no per-station event; every switched station switches to B
// without pulse; the one-sided slave on A is lost silently. The repair → one W#16#38C3, the
// channels come back silently, the active channel stays B.
TEST(RedundantMasterSystem, ShortCircuitIsOneMasterSystemFailure) {
  System s;
  Sampler smp(s);
  s.line[0].add_tap(smp);
  s.line[1].add_tap(smp);
  s.start();
  s.run_until(150 * kMs);
  const bus::Ticks fault = s.sched.now();
  s.line[0].set_short_circuit(true);
  s.run_until(1500 * kMs);
  auto ev = s.s7();
  ASSERT_EQ(ev.size(), 1u);
  EXPECT_EQ(ev[0].kind, K::MasterSystemFailure);
  EXPECT_EQ(ev[0].code(), 0x39C3);
  EXPECT_EQ(ev[0].line, 0);
  EXPECT_EQ(ev[0].station, 0xFF);
  EXPECT_GE(ev[0].time, fault);
  EXPECT_LE(ev[0].time, fault + 5 * kMs);  // master A's next transmission: within a rotation
  for (std::uint8_t a : {kFast, kSlow}) {
    EXPECT_EQ(s.ms().active(a), 1) << int(a);
    EXPECT_EQ(s.station(a).primary(), 1) << int(a);
  }
  EXPECT_EQ(s.ms().active(kOneA), -1);
  EXPECT_EQ(s.ms().active(kOneB), 1);
  smp.expect_no_pulse(0, 0);
  smp.expect_no_pulse(1, 0);
  // Both switchovers were commanded at the line loss, in the same instant.
  int sw = 0;
  for (const auto& e : s.ms().events())
    if (e.kind == K::Switchover && e.cause != SystemEvent::Cause::StartUp) {
      EXPECT_EQ(e.time, ev[0].time);
      EXPECT_EQ(e.line, 1);
      ++sw;
    }
  EXPECT_EQ(sw, 2);

  s.line[0].set_short_circuit(false);
  s.run_until(3000 * kMs);
  ev = s.s7();
  ASSERT_EQ(ev.size(), 2u);
  EXPECT_EQ(ev[1].kind, K::MasterSystemReturn);
  EXPECT_EQ(ev[1].code(), 0x38C3);
  for (std::uint8_t a : {kFast, kSlow}) {
    EXPECT_TRUE(s.ms().channel_up(a, 0)) << int(a);
    EXPECT_EQ(s.ms().active(a), 1) << int(a);
  }
  EXPECT_EQ(s.ms().active(kOneA), 0);
  smp.expect_no_pulse(0, 0);
  smp.expect_no_pulse(1, 0);
}

// F14: the master of line A stops (CP RUN → STOP) → one 39C3, all stations to B at once.
TEST(RedundantMasterSystem, MasterStopIsOneMasterSystemFailure) {
  System s;
  Sampler smp(s);
  s.line[0].add_tap(smp);
  s.line[1].add_tap(smp);
  s.start();
  s.run_until(150 * kMs);
  const bus::Ticks fault = s.sched.now();
  s.sys->stop_master(0);
  s.run_until(1500 * kMs);
  auto ev = s.s7();
  ASSERT_EQ(ev.size(), 1u);
  expect_event(ev[0], K::MasterSystemFailure, 0, 0xFF, fault);
  for (std::uint8_t a : {kFast, kSlow}) EXPECT_EQ(s.station(a).primary(), 1) << int(a);
  smp.expect_no_pulse(0, 0);
  smp.expect_no_pulse(1, 0);
  s.sys->start_master(0);
  s.run_until(2500 * kMs);
  ev = s.s7();
  ASSERT_EQ(ev.size(), 2u);
  EXPECT_EQ(ev[1].kind, K::MasterSystemReturn);
  for (std::uint8_t a : {kFast, kSlow}) {
    EXPECT_TRUE(s.ms().channel_up(a, 0));
    EXPECT_EQ(s.station(a).primary(), 1);
  }
}

// F9: the DP master module of line A fails → one-sided slaves of A lost (OB 86 39C4), every
// switched station served by B (OB 70 73A3 each), all at the moment of the failure.
TEST(RedundantMasterSystem, MasterFailureReportsPerStation) {
  System s;
  Sampler smp(s);
  s.line[0].add_tap(smp);
  s.line[1].add_tap(smp);
  s.start();
  s.run_until(150 * kMs);
  const bus::Ticks fault = s.sched.now();
  s.sys->fail_master(0);
  s.run_until(1500 * kMs);
  const auto ev = s.s7();
  ASSERT_EQ(ev.size(), 3u);
  std::map<std::uint8_t, SystemEvent> by;
  for (const auto& e : ev) by[e.station] = e;
  expect_event(by[kFast], K::RedundancyLoss, 0, kFast, fault);
  expect_event(by[kSlow], K::RedundancyLoss, 0, kSlow, fault);
  expect_event(by[kOneA], K::StationFailure, 0, kOneA, fault);
  for (std::uint8_t a : {kFast, kSlow}) EXPECT_EQ(s.station(a).primary(), 1) << int(a);
  smp.expect_no_pulse(0, 0);
  smp.expect_no_pulse(1, 0);
  // The repair: the master starts up again; 72A3 per switched station, 38C4 for the one-sided.
  s.sys->repair_master(0);
  s.run_until(3000 * kMs);
  const auto after = s.s7_since(fault + 1);
  int r72 = 0, r38 = 0;
  for (const auto& e : after) {
    if (e.kind == K::RedundancyReturn) ++r72;
    if (e.kind == K::StationReturn && e.station == kOneA) ++r38;
  }
  EXPECT_EQ(r72, 2);
  EXPECT_EQ(r38, 1);
  for (std::uint8_t a : {kFast, kSlow}) EXPECT_EQ(s.station(a).primary(), 1) << int(a);
}

// F13: a cable cut on line A behind station 5: station 6 and the one-sided slave are cut off
// from master A: 73A3 for 6 (it switches to B), 39C4 for 10; station 5 stays on A, untouched.
TEST(RedundantMasterSystem, CableCutSwitchesTheStationsBehindIt) {
  System s;
  Sampler smp(s);
  s.line[0].add_tap(smp);
  s.line[1].add_tap(smp);
  s.start();
  s.run_until(150 * kMs);
  // Attachments on A: 0 master, 1 station 5, 2 station 6, 3 one-sided.
  s.line[0].set_cut_after(1, true);
  s.run_until(600 * kMs);
  auto ev = s.s7();
  ASSERT_EQ(ev.size(), 2u);
  std::map<std::uint8_t, SystemEvent> by;
  for (const auto& e : ev) by[e.station] = e;
  EXPECT_EQ(by[kSlow].kind, K::RedundancyLoss);
  EXPECT_EQ(by[kSlow].line, 0);
  EXPECT_EQ(by[kOneA].kind, K::StationFailure);
  EXPECT_EQ(s.station(kFast).primary(), 0);
  EXPECT_EQ(s.station(kSlow).primary(), 1);
  smp.expect_no_pulse(0, 0);
  smp.expect_no_pulse(1, 0);
  s.line[0].set_cut_after(1, false);
  s.run_until(1500 * kMs);
  ev = s.s7();
  ASSERT_EQ(ev.size(), 4u);
  int r72 = 0, r38 = 0;
  for (std::size_t i = 2; i < ev.size(); ++i) {
    if (ev[i].kind == K::RedundancyReturn && ev[i].station == kSlow) ++r72;
    if (ev[i].kind == K::StationReturn && ev[i].station == kOneA) ++r38;
  }
  EXPECT_EQ(r72, 1);
  EXPECT_EQ(r38, 1);
  EXPECT_EQ(s.station(kSlow).primary(), 1);  // no switch back
}

// The passive channel failing: 73A3, no switchover.
TEST(RedundantMasterSystem, PassiveChannelFailureLosesRedundancyWithoutSwitching) {
  System s;
  s.start();
  s.run_until(150 * kMs);
  s.station(kSlow).fail_interface(1);
  s.run_until(400 * kMs);
  const auto ev = s.s7();
  ASSERT_EQ(ev.size(), 1u);
  EXPECT_EQ(ev[0].kind, K::RedundancyLoss);
  EXPECT_EQ(ev[0].line, 1);
  EXPECT_EQ(ev[0].station, kSlow);
  EXPECT_EQ(s.ms().switchovers(), 0u);
  EXPECT_EQ(s.station(kSlow).primary(), 0);
}

// Start-up with line A's master failed from the beginning: B's channels get Primary_Request
// as they reach data exchange, and each switched station reports its missing A channel (73A3)
// once; the one-sided slave of A is lost (39C4).
TEST(RedundantMasterSystem, StartUpWithoutLineAUsesB) {
  System s;
  s.start();  // powers every attachment: the failure comes right after, at 0
  s.sys->fail_master(0);
  s.run_until(1500 * kMs);
  for (std::uint8_t a : {kFast, kSlow}) {
    EXPECT_EQ(s.ms().active(a), 1) << int(a);
    EXPECT_EQ(s.station(a).primary(), 1) << int(a);
  }
  int r73 = 0;
  for (const auto& e : s.s7())
    if (e.kind == K::RedundancyLoss) ++r73;
  EXPECT_EQ(r73, 2);
}

}  // namespace
}  // namespace pbvbus::devices

namespace pbvbus::devices {
namespace {

// S6/S8 for data records: a Read goes over the active channel only; when the active interface
// fails while the job is under way, the system repeats it over the new active channel and the
// caller gets one result, from line B.
TEST(RedundantMasterSystem, DataRecordGoesOverTheActiveChannelAndSurvivesASwitchover) {
  System s;
  s.start();
  s.run_until(150 * kMs);
  // Steady state: the record job runs on line A only.
  std::vector<dp::AcyclicResult> got;
  ASSERT_NE(s.ms().read(kFast, 0, 1, 8, [&](const dp::AcyclicResult& r) { got.push_back(r); },
                        s.sched.now()),
            0u);
  s.run_until(200 * kMs);
  ASSERT_EQ(got.size(), 1u);
  EXPECT_TRUE(got[0].status == dp::AcyclicStatus::Ok || got[0].status == dp::AcyclicStatus::Negative)
      << dp::to_string(got[0].status);
  EXPECT_EQ(s.ms().record_repeats(), 0u);

  // A job interrupted by the failure of the active interface: repeated on B, one result.
  got.clear();
  const auto id = s.ms().read(kFast, 0, 1, 8, [&](const dp::AcyclicResult& r) { got.push_back(r); },
                              s.sched.now());
  ASSERT_NE(id, 0u);
  s.station(kFast).fail_interface(0);
  s.run_until(600 * kMs);
  ASSERT_EQ(got.size(), 1u);
  EXPECT_EQ(got[0].id, id);
  EXPECT_TRUE(got[0].status == dp::AcyclicStatus::Ok || got[0].status == dp::AcyclicStatus::Negative)
      << dp::to_string(got[0].status);
  EXPECT_EQ(s.ms().record_repeats(), 1u);
  EXPECT_EQ(s.ms().active(kFast), 1);
  // With no active channel at all the system refuses at once.
  s.station(kFast).fail_interface(1);
  s.run_until(800 * kMs);
  EXPECT_EQ(s.ms().read(kFast, 0, 1, 8, [](const dp::AcyclicResult&) {}, s.sched.now()), 0u);
}

}  // namespace
}  // namespace pbvbus::devices

namespace pbvbus::devices {
namespace {

// S11 at the master-system level: one side's master out (the other CPU in Solo): the remaining
// master reaches every switched station (all active on its line) and its one-sided slave; the
// failed side reaches none. No switchover is needed when the failed side was the passive one.
TEST(RedundantMasterSystem, SoloSideReachesEverySwitchedStation) {
  System s;
  s.start();
  s.run_until(150 * kMs);
  s.sys->fail_master(1);
  s.run_until(1500 * kMs);
  EXPECT_EQ(s.ms().switchovers(), 0u);
  for (std::uint8_t a : {kFast, kSlow}) {
    EXPECT_EQ(s.ms().active(a), 0) << int(a);
    EXPECT_EQ(s.station(a).primary(), 0) << int(a);
    EXPECT_EQ(s.sys->master(0).slave_state(a), dp::SlaveStatusState::DataExchange);
    EXPECT_FALSE(s.ms().channel_up(a, 1));
    // The passive interface lost its master: its watchdog took it out of data exchange.
    EXPECT_NE(s.station(a).redundant_slave().engine(1).state(), dp::SlaveState::DataExch);
  }
  EXPECT_EQ(s.sys->master(0).slave_state(kOneA), dp::SlaveStatusState::DataExchange);
  EXPECT_EQ(s.ms().active(kOneB), -1);
  // F9 on the passive side: 73A3 per switched station, 39C4 for its one-sided slave.
  int r73 = 0, r39 = 0;
  for (const auto& e : s.s7()) {
    if (e.kind == K::RedundancyLoss && e.line == 1) ++r73;
    if (e.kind == K::StationFailure && e.station == kOneB) ++r39;
  }
  EXPECT_EQ(r73, 2);
  EXPECT_EQ(r39, 1);
}

// --- S5: the IM's own switchover time -------------------------------------------------------------
// seeds-digest §2 (L105) / 000 L1832: switchover time = DP error recognition + DP switchover time
// + the DP slave interface's (IM's) own time; a whole line's switchover is dominated by the
// slowest IM. The stations here draw their IM time in [T_SLAVE_UM / 2, T_SLAVE_UM].

/// The first FreshOutputs of station `a` on interface `iface` at or after `t`.
bus::Ticks fresh_at(System& s, std::uint8_t a, int iface, bus::Ticks t) {
  for (const auto& e : s.station(a).events())
    if (e.kind == redundancy::RedEvent::Kind::FreshOutputs && e.iface == iface && e.at >= t)
      return e.at;
  return bus::kNever;
}

/// The planner's bounds for this system (redundancy::plan_switchover; its own golden test is
/// tests/stacks/redundancy/switchover_timing_test.cpp): here only the consistency check that
/// every measured switchover stays inside them.
redundancy::SwitchoverPlan plan_of(System& s) {
  std::vector<redundancy::PlannedSlave> ps;
  for (std::uint8_t a : {kFast, kSlow}) {
    redundancy::PlannedSlave p;
    p.address = a;
    p.in_len = p.out_len = 2;
    p.max_diag_len = 32;
    p.switched = true;
    p.t_slave_um = (a == kFast ? 30 : 820) * kMs;
    ps.push_back(p);
  }
  for (int l = 0; l < 2; ++l) {
    redundancy::PlannedSlave p;
    p.address = l == 0 ? kOneA : kOneB;
    p.in_len = p.out_len = 2;
    p.line = l;
    ps.push_back(p);
  }
  return redundancy::plan_switchover(s.bp, ps);
}

TEST(RedundantMasterSystemImTime, AStationSwitchoverTakesItsImTimeWithinTheBound) {
  System s(true, 5);
  Sampler smp(s);
  s.line[0].add_tap(smp);
  s.line[1].add_tap(smp);
  s.start();
  s.run_until(150 * kMs);
  const bus::Ticks fault = s.sched.now();
  s.station(kFast).fail_interface(0);
  s.run_until(400 * kMs);
  const auto& im = s.station(kFast).redundant_slave().im_switchovers();
  ASSERT_EQ(im.size(), 1u);
  EXPECT_EQ(im[0].iface, 1);
  ASSERT_GE(im[0].drawn, 15 * kMs);  // [30 ms / 2, 30 ms]
  ASSERT_LE(im[0].drawn, 30 * kMs);
  const bus::Ticks fresh = fresh_at(s, kFast, 1, fault);
  ASSERT_NE(fresh, bus::kNever);
  const bus::Ticks measured = fresh - fault;
  // At least the IM's time; at most T_SLAVE_UM + the DP parts (recognition ≈ 2.6 ms and
  // T_DP_UM ≈ 4.3 ms at 1.5 Mbit/s with three slaves a line, docs/switchover-timing.md's worked
  // example: together < 10 ms), and within the planner's station bound.
  EXPECT_GE(measured, im[0].drawn);
  EXPECT_LE(measured, 30 * kMs + 10 * kMs);
  EXPECT_LE(measured, plan_of(s).stations[0].bound[0]);
  // The command reached the IM after the recognition: the IM's time starts there.
  EXPECT_GT(im[0].trigger, fault);
  EXPECT_GE(fresh, im[0].primary_at);
  smp.expect_no_pulse(0, 0);
  smp.expect_no_pulse(1, 0);
  EXPECT_EQ(s.station(kSlow).primary(), 0);  // untouched
  EXPECT_TRUE(s.station(kSlow).redundant_slave().im_switchovers().empty());
}

TEST(RedundantMasterSystemImTime, AWholeLineSwitchoverIsDominatedByTheSlowestIm) {
  System s(true, 9);
  Sampler smp(s);
  s.line[0].add_tap(smp);
  s.line[1].add_tap(smp);
  s.start();
  s.run_until(150 * kMs);
  const bus::Ticks fault = s.sched.now();
  s.sys->stop_master(0);  // master stop on line A: known at once
  s.run_until(1200 * kMs);
  const auto plan = plan_of(s);
  bus::Ticks fresh[2] = {0, 0};
  bus::Ticks drawn[2] = {0, 0};
  int k = 0;
  for (std::uint8_t a : {kFast, kSlow}) {
    const auto& im = s.station(a).redundant_slave().im_switchovers();
    ASSERT_EQ(im.size(), 1u) << int(a);
    drawn[k] = im[0].drawn;
    fresh[k] = fresh_at(s, a, 1, fault);
    ASSERT_NE(fresh[k], bus::kNever) << int(a);
    EXPECT_GE(fresh[k] - fault, drawn[k]) << int(a);
    ++k;
  }
  ASSERT_GE(drawn[0], 15 * kMs);
  ASSERT_LE(drawn[0], 30 * kMs);
  ASSERT_GE(drawn[1], 410 * kMs);  // [820 ms / 2, 820 ms]
  ASSERT_LE(drawn[1], 820 * kMs);
  // The whole line is switched when the slow station has its fresh outputs: at least its IM's
  // time (≥ 410 ms), at most 820 ms + T_DP_UM_system (< 10 ms here) and the planner's bound.
  const bus::Ticks whole = std::max(fresh[0], fresh[1]) - fault;
  EXPECT_EQ(whole, fresh[1] - fault);  // the slow IM dominates
  EXPECT_GE(whole, 410 * kMs);
  EXPECT_LE(whole, 820 * kMs + 10 * kMs);
  EXPECT_LE(whole, plan.system_bound_master_stop[0]);
  EXPECT_LE(fresh[0] - fault, 30 * kMs + 10 * kMs);
  smp.expect_no_pulse(0, 0);  // outputs frozen (Output_Hold_Time 1 s > 820 ms)
  smp.expect_no_pulse(1, 0);
}

}  // namespace
}  // namespace pbvbus::devices
