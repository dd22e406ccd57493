// The update phases of the CPU pair acting on the H-system's I/O (HSystemModel; fixture in
// h_system_fixture.hpp). The manual's H parameters: max cycle extension 1940 ms, max
// communication delay 776 ms, T_P15 194 ms, T_PH 90 ms, 170 KB of changed DBs:
//   W = MAX(T_P15_AWP = 75 ms + 0.7 ms x 170 = 194 ms, 50 ms + T_PH = 140 ms) = 194 ms;
//   no update timeout (T_P15 = 194 ms is not < W).
// power_on_both at 12 ms: Solo at 1.012 s, LINK-UP 2 s, so t1 = t3 = 3.012 s,
// t5 = 3.012 + 0.194 = 3.206 s, t4 = t5 - T_PH = 3.116 s. OB 1 every 10 ms from 1.012 s: the
// last scan before t3 is 3.002 s (the one at 3.012 s is in the window); OB 1 restarts at t5.
#include <gmock/gmock.h>

#include "h_system_fixture.hpp"
#include "pbvbus/s7h/h_update_timing.hpp"

namespace pbvbus::devices {
namespace {

using ::testing::HasSubstr;

constexpr bus::Ticks kT1 = 3012 * kMs;
constexpr bus::Ticks kT4 = 3116 * kMs;
constexpr bus::Ticks kT5 = 3206 * kMs;

HCpuPairParams manual_params() {
  HCpuPairParams p;
  p.h_parameters = {1'940'000, 776'000, 194'000, 90'000};  // µs: ext, comm delay, T_P15, T_PH
  p.update_db_kb = 170;
  return p;
}

ProgramSpec counters_spec() {
  ProgramSpec p;
  p.scan_time = kScan;
  p.counters.push_back({0, 2, 10 * kMs, 1, 0, 0, 0});  // QB 0..1: station 5
  p.counters.push_back({2, 2, 10 * kMs, 1, 0, 0, 0});  // QB 2..3: station 6
  return p;
}

void start(HSys& s) {
  s.at(kT0);
  s.h->power_on_both();
}

TEST(HSystemUpdate, ManualParametersWindowAndOutputHold) {
  HSys s(manual_params());
  Sampler smp(s);
  s.h->set_program(counters_spec());
  start(s);
  s.run_until(kT1 - 1);
  EXPECT_EQ(s.h->scans(), 200u);  // 1.012 + k x 10 ms, k = 0..199 (3.002 s)
  EXPECT_EQ(s.h->side_mode(0, 1), Mode::Stop);
  s.run_until(kT1);
  EXPECT_TRUE(s.h->pair().io_frozen());
  EXPECT_EQ(s.h->side_mode(0, 1), Mode::Clear);  // UPDATE: standby's side Clear until t4
  s.run_until(kT4 - 1);
  EXPECT_EQ(s.h->side_mode(0, 1), Mode::Clear);
  EXPECT_EQ(s.h->scans(), 200u);
  s.run_until(kT4);
  EXPECT_TRUE(s.h->pair().outputs_held_by_both());
  EXPECT_EQ(s.h->side_mode(0, 1), Mode::Operate);  // the output copy: both drive during T_PH
  EXPECT_EQ(s.h->execution()->image(0), s.h->execution()->image(1));  // copy_state at t4
  s.run_until(kT5 - 1);
  EXPECT_EQ(s.h->scans(), 200u);  // no OB 1 in [t3, t5)
  s.run_until(kT5);
  EXPECT_EQ(s.h->pair().system_mode(), SystemMode::Redundant);
  EXPECT_EQ(s.h->scans(), 201u);  // OB 1 at t5 itself
  s.run_until(kT5 + 500 * kMs);
  ASSERT_EQ(s.h->update_measures().size(), 1u);
  const UpdateMeasure& m = s.h->update_measures()[0];
  EXPECT_EQ(m.t1, kT1);
  EXPECT_EQ(m.t3, kT1);
  EXPECT_EQ(m.t4, kT4);
  EXPECT_EQ(m.t5, kT5);
  EXPECT_EQ(m.standby, 1);
  EXPECT_FALSE(m.aborted);
  EXPECT_EQ(m.last_scan_before, 3002 * kMs);
  EXPECT_EQ(m.first_scan_after, kT5);
  EXPECT_EQ(m.standby_operate_from, kT4);
  // 3.206 - 3.002 = 204 ms <= W + scan time = 194 + 10 = 204 ms.
  EXPECT_EQ(m.no_io_window(), 204 * kMs);
  EXPECT_LE(m.no_io_window(), 194 * kMs + kScan);
  EXPECT_EQ(m.output_hold_window(), 90 * kMs);  // T_PH
  EXPECT_TRUE(s.events(Src::Cpu).empty());      // no comparison error after the copy
  smp.expect_no_pulse(0);
}

// Samples station 5's output byte 0 after every frame on either line.
struct OutSampler final : bus::Tap {
  explicit OutSampler(HSys& s) : sys(s) {
    s.line[0].add_tap(*this);
    s.line[1].add_tap(*this);
  }
  void on_frame(const bus::TapFrame&) override {
    seen = seen || sys.station(kFast).outputs()[0] == 0x01;
  }
  HSys& sys;
  bool seen = false;
};

// The minimum input-signal duration across this update (T7): t_io = 10 ms (a bound on the DP
// cycle of these lines: 3 stations at 1.5 Mbit/s take a few ms), t_call = 10 ms (OB 1),
// t_run = 0, 170 KB: 2 x 10 + 10 + 0 + (75 + 0.7 x 170 = 194) = 224 ms. A pulse at slave 10's
// inputs (one-sided, line A) from 3.020 s (inside the window) copied by OB 1 (IB 4 -> QB 0 =
// station 5's outputs): 180 ms (< 224, ends at 3.200 < t5) is never seen; 230 ms (> 224, ends
// at 3.250) is seen by the OB 1 at t5 = 3.206 s.
TEST(HSystemUpdate, InputPulseAcrossTheUpdate) {
  const SignalDuration bound = min_signal_duration({ms(10), ms(10), 0, 170, 0});
  ASSERT_EQ(bound.total, 224'000);
  for (const Us pulse : {ms(180), ms(230)}) {
    HSys s(manual_params());
    OutSampler out(s);
    ProgramSpec p;
    p.scan_time = kScan;
    p.copies.push_back({4, 0, 1});
    s.h->set_program(p);
    start(s);
    s.run_until(3020 * kMs);
    ASSERT_TRUE(s.one[0]->application().write_inputs(0, Bytes{0x01, 0x00}));
    s.run_until(3020 * kMs + to_ticks(pulse));
    ASSERT_TRUE(s.one[0]->application().write_inputs(0, Bytes{0x00, 0x00}));
    s.run_until(3600 * kMs);
    EXPECT_EQ(out.seen, pulse_seen_across_update(pulse, bound)) << pulse;
    EXPECT_EQ(out.seen, pulse == ms(230)) << pulse;
  }
}

// The standby loses power at 3.100 s, inside the window: the abort ends the freeze, OB 1 runs
// at the abort time (201st scan), the measure is aborted with t5 = 3.100 s.
TEST(HSystemUpdate, StandbyPowerLossAbortEndsTheFreeze) {
  HSys s(manual_params());
  s.h->set_program(counters_spec());
  start(s);
  s.at(3100 * kMs);
  EXPECT_TRUE(s.h->pair().io_frozen());
  EXPECT_EQ(s.h->scans(), 200u);
  s.h->power_off(1);
  EXPECT_FALSE(s.h->pair().io_frozen());
  s.run_until(3100 * kMs);  // the OB 1 armed at the abort instant
  EXPECT_EQ(s.h->scans(), 201u);
  ASSERT_EQ(s.h->update_measures().size(), 1u);
  const UpdateMeasure& m = s.h->update_measures()[0];
  EXPECT_TRUE(m.aborted);
  EXPECT_EQ(m.t5, 3100 * kMs);
  EXPECT_EQ(m.first_scan_after, 3100 * kMs);
  EXPECT_EQ(m.standby_operate_from, bus::kNever);  // before t4
  EXPECT_EQ(m.no_io_window(), 98 * kMs);            // 3.100 - 3.002
  EXPECT_EQ(s.h->side_mode(0, 1), Mode::Unpowered);
  EXPECT_EQ(s.h->pair().system_mode(), SystemMode::Solo);
}

// R7: data-record jobs and SFC 51 around the update. Station 5 answers index 7 of slot 1 with
// 2 octets 12 34 (both interfaces).
TEST(HSystemUpdate, RecordJobsAndSfc51) {
  HSys s(manual_params());
  for (int i = 0; i < 2; ++i)
    s.station(kFast).redundant_slave().engine(i).application().on_read(
        1, 7, [](const dp::RecordCall&, std::span<std::uint8_t> out) {
          out[0] = 0x12;
          out[1] = 0x34;
          return dp::RecordResult::ok(2);
        });
  s.h->set_program(counters_spec());
  start(s);
  std::vector<RecordJobResult> got;
  auto cb = [&](const RecordJobResult& r) { got.push_back(r); };
  s.run_until(2000 * kMs);  // Solo
  EXPECT_EQ(s.h->read_record(0, kFast, 1, 7, 2, cb), 0);
  s.run_until(2100 * kMs);
  ASSERT_EQ(got.size(), 1u);
  EXPECT_EQ(got[0].ret_val, 0);
  EXPECT_EQ(got[0].result.data, (Bytes{0x12, 0x34}));
  const HSystemState before = s.h->read_system_state(s.sched.now());
  EXPECT_EQ(before.ret_val, 0);
  EXPECT_EQ(before.master_rack, 0);
  EXPECT_EQ(before.mode, SystemMode::LinkUp);  // the standby links up from 1.012 s
  EXPECT_EQ(before.state[1], CpuState::LinkUp);
  // A job started 1 tick before t1 is still running at t1: its result is 80C3, after t5.
  s.run_until(kT1 - 1);
  EXPECT_EQ(s.h->read_record(0, kFast, 1, 7, 2, cb), 0);
  s.run_until(kT1 + 50 * kMs);
  EXPECT_EQ(got.size(), 1u);  // BUSY during the update
  EXPECT_EQ(s.h->read_record(0, kFast, 1, 7, 2, cb), 0x80C3);  // new job: refused at once
  EXPECT_EQ(s.h->write_record(0, kFast, 1, 7, Bytes{1}, cb), 0x80C3);
  EXPECT_EQ(s.h->read_system_state(s.sched.now()).ret_val, 0x8085);
  s.run_until(kT5);
  ASSERT_EQ(got.size(), 2u);
  EXPECT_EQ(got[1].ret_val, 0x80C3);
  EXPECT_EQ(got[1].completed, kT5);
  s.run_until(kT5 + 100 * kMs);
  EXPECT_EQ(s.h->read_record(0, kFast, 1, 7, 2, cb), 0);
  s.run_until(kT5 + 200 * kMs);
  ASSERT_EQ(got.size(), 3u);
  EXPECT_EQ(got[2].ret_val, 0);
  const HSystemState after = s.h->read_system_state(s.sched.now());
  EXPECT_EQ(after.ret_val, 0);
  EXPECT_EQ(after.mode, SystemMode::Redundant);
  EXPECT_EQ(after.state[1], CpuState::Run);
  EXPECT_EQ(after.role[1], CpuRole::Standby);
  EXPECT_EQ(s.h->read_record(5, kFast, 1, 7, 2, cb), 0x8090);  // no such master system
}

// A diagnostic alarm of station 5 (type 1, slot 2: enabled by the GSD's DPV1_Status_2 = 20)
// raised at 3.050 s (inside the update) reaches the master system then and is held: delivered at
// t5 exactly once, as OB 82 on both CPUs, with its original time.
TEST(HSystemUpdate, AlarmDuringTheUpdateDeliveredAfterT5Once) {
  HSys s(manual_params());
  s.h->set_program(counters_spec());
  start(s);
  s.run_until(3050 * kMs);
  const Bytes data{0xAB, 0xCD};
  s.station(kFast).raise_alarm(1, 2, dp::AlarmSpec::Appears, false, data);
  s.run_until(kT5 - 1);
  ASSERT_EQ(s.ms().alarms().size(), 1u);
  const bus::Ticks received = s.ms().alarms()[0].time;
  EXPECT_GT(received, 3050 * kMs);
  EXPECT_LT(received, kT5);
  EXPECT_TRUE(s.events(Src::Alarm).empty());
  s.run_until(kT5 + 1000 * kMs);
  const auto al = s.events(Src::Alarm);
  ASSERT_EQ(al.size(), 1u);
  EXPECT_EQ(al[0].ob, 82);
  EXPECT_EQ(al[0].time, kT5);
  EXPECT_EQ(al[0].original_time, received);
  EXPECT_EQ(al[0].rack, -1);
  EXPECT_EQ(al[0].station, kFast);
  EXPECT_THAT(al[0].text, HasSubstr("OB 82 diagnostic alarm, DP master system 1, station 5, slot 2"));
}

}  // namespace
}  // namespace pbvbus::devices
