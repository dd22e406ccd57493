// Probe taps (line.hpp "Taps come in two kinds"): what an analyzer clipped onto the cable next to
// one station sees. Cuts hide the far side, a cut during a frame leaves a partial frame at the
// probes it separates, a short hides everything, collisions show only on their own segment, and
// the probe hears the cable whatever the station next to it is doing.
// Frames are golden octets written by hand (protocol-facts.md §B); times are worked out in bit
// times at 1.5 Mbit/s (11 bit times per octet).

#include <gtest/gtest.h>

#include <memory>
#include <vector>

#include "hex.hpp"
#include "pbvbus/bus/line.hpp"
#include "probe.hpp"

namespace pbvbus::test {
namespace {

using bus::Baud;
using bus::LineEventKind;
using bus::ProbePoint;
using bus::Ticks;

constexpr const char* kSd1 = "10 03 01 49 4D 16";                 // 6 octets = 66 bit times
constexpr const char* kSd2 = "68 05 05 68 8A 81 6D 3C 3E F2 16";  // 11 octets = 121 bit times
constexpr const char* kSc = "E5";                                  // 11 bit times
constexpr const char* kToken = "DC 05 01";                         // 33 bit times

/// Records what one tap sees, with the probe position and what the line still had on the wire.
class ProbeRecorder final : public bus::Tap {
 public:
  struct Frame {
    std::string hex;
    Ticks start, end;
    std::uint16_t flags, sender;
    std::int16_t probe;
    std::uint32_t sent_len;
    Ticks earliest_in_flight;  ///< Line::earliest_start_in_flight() when it arrived
    std::vector<std::uint8_t> bytes;
  };
  void on_frame(const bus::TapFrame& f) override {
    frames.push_back({to_hex(f.bytes), f.start, f.end, f.flags, f.sender, f.probe, f.sent_len,
                      f.line->earliest_start_in_flight(), {f.bytes.begin(), f.bytes.end()}});
  }
  void on_line_event(const bus::LineEvent& e) override { events.push_back(e.kind); }
  std::vector<std::string> hex_all() const {
    std::vector<std::string> v;
    for (const auto& f : frames) v.push_back(f.hex);
    return v;
  }
  std::vector<Frame> frames;
  std::vector<LineEventKind> events;
};

class LineProbeTest : public ::testing::Test {
 protected:
  static constexpr Ticks kBit = 2424;  // 1.5 Mbit/s
  static constexpr Ticks B(std::int64_t bits) { return bits * kBit; }

  void make(int n) {
    for (int i = 0; i < n; ++i) {
      probes.push_back(std::make_unique<Probe>());
      line.attach(*probes.back(), "p" + std::to_string(i));
    }
  }
  Probe& p(int i) { return *probes.at(static_cast<std::size_t>(i)); }
  void at(Ticks t, std::function<void()> fn) { sched.schedule(t, std::move(fn)); }

  bus::Scheduler sched;
  bus::Line line{sched, "A", Baud::k1_5M, 7};
  std::vector<std::unique_ptr<Probe>> probes;
};

TEST_F(LineProbeTest, ProbesOnBothSidesOfACutSeeOnlyTheirSide) {
  make(4);  // p0 p1 | p2 p3
  ProbeRecorder left, edge, right;
  line.add_tap(left, ProbePoint{0});
  line.add_tap(edge, ProbePoint{1});  // right next to the cut, still on the left
  line.add_tap(right, ProbePoint{3});
  line.start();
  at(B(0), [&] { line.set_cut_after(1, true); });
  p(0).send(B(10), kSd1);  // [10, 76) on the left
  p(3).send(B(10), kSd2);  // [10, 131) on the right: no collision with the SD1
  at(B(500), [&] { line.set_cut_after(1, false); });
  p(3).send(B(600), kToken);  // [600, 633) on the whole line again
  sched.run_until(B(1000));

  for (ProbeRecorder* r : {&left, &edge}) {
    ASSERT_EQ(r->frames.size(), 2u);
    EXPECT_EQ(r->frames[0].hex, kSd1);
    EXPECT_EQ(r->frames[0].start, B(10));
    EXPECT_EQ(r->frames[0].end, B(76));
    EXPECT_EQ(r->frames[0].sender, 0);
    EXPECT_EQ(r->frames[0].flags, 0);
    EXPECT_EQ(r->frames[1].hex, kToken);
    EXPECT_EQ(r->frames[1].start, B(600));
    EXPECT_EQ(r->frames[1].sender, 3);
  }
  EXPECT_EQ(left.frames[0].probe, 0);
  EXPECT_EQ(edge.frames[0].probe, 1);
  ASSERT_EQ(right.frames.size(), 2u);
  EXPECT_EQ(right.frames[0].hex, kSd2);
  EXPECT_EQ(right.frames[0].start, B(10));
  EXPECT_EQ(right.frames[0].end, B(131));
  EXPECT_EQ(right.frames[0].flags, 0);
  EXPECT_EQ(right.frames[0].probe, 3);
  EXPECT_EQ(right.frames[1].hex, kToken);
  EXPECT_EQ(right.frames[1].end, B(633));
  // Faults reach every probe: 4 power-on, the cut, the repair.
  for (ProbeRecorder* r : {&left, &edge, &right}) {
    ASSERT_EQ(r->events.size(), 6u);
    EXPECT_EQ(r->events[4], LineEventKind::CableCut);
    EXPECT_EQ(r->events[5], LineEventKind::CableRepaired);
  }
}

TEST_F(LineProbeTest, AFrameCutMidwayIsPartialOnlyAtProbesBeyondTheCut) {
  make(4);
  ProbeRecorder r[4];
  for (int i = 0; i < 4; ++i) line.add_tap(r[i], ProbePoint{i});
  line.start();
  p(0).send(0, kSd2);  // [0, 121)
  at(B(50), [&] { line.set_cut_after(1, true); });  // 4 whole characters [0, 44) are out
  p(3).send(B(60), kSd1);  // [60, 126) on the far side
  sched.run_until(B(1000));

  for (int i : {0, 1}) {
    ASSERT_EQ(r[i].frames.size(), 1u) << i;
    EXPECT_EQ(r[i].frames[0].hex, kSd2);
    EXPECT_EQ(r[i].frames[0].end, B(121));
    EXPECT_EQ(r[i].frames[0].flags, 0);
  }
  for (int i : {2, 3}) {
    ASSERT_EQ(r[i].frames.size(), 2u) << i;
    EXPECT_EQ(r[i].frames[0].hex, "68 05 05 68");
    EXPECT_EQ(r[i].frames[0].start, 0);
    EXPECT_EQ(r[i].frames[0].end, B(50));
    EXPECT_EQ(r[i].frames[0].flags, bus::kRxPartial);
    EXPECT_EQ(r[i].frames[0].sent_len, 11u);
    EXPECT_EQ(r[i].frames[0].sender, 0);
    EXPECT_EQ(r[i].frames[0].probe, i);
    EXPECT_EQ(r[i].frames[1].hex, kSd1);
    EXPECT_EQ(r[i].frames[1].start, B(60));
    EXPECT_EQ(r[i].frames[1].flags, 0);
  }
}

TEST_F(LineProbeTest, AShortCircuitHidesEverythingAtEveryProbe) {
  make(3);
  ProbeRecorder first, last;
  line.add_tap(first, ProbePoint{0});
  line.add_tap(last, ProbePoint{2});
  line.start();
  p(0).send(0, kSd2);  // [0, 121), cut short at 50 at its source
  at(B(50), [&] { line.set_short_circuit(true); });
  p(1).send(B(100), kSd1);  // during the short: never on the cable
  p(2).send(B(200), kSc);   // the probe's own station: nothing either
  at(B(300), [&] { line.set_short_circuit(false); });
  p(1).send(B(400), kSd1);  // [400, 466)
  sched.run_until(B(1000));

  for (ProbeRecorder* r : {&first, &last}) {
    ASSERT_EQ(r->frames.size(), 2u);
    EXPECT_EQ(r->frames[0].hex, "68 05 05 68");
    EXPECT_EQ(r->frames[0].flags, bus::kRxPartial);
    EXPECT_EQ(r->frames[0].end, B(50));
    EXPECT_EQ(r->frames[1].hex, kSd1);
    EXPECT_EQ(r->frames[1].start, B(400));
    EXPECT_EQ(r->frames[1].end, B(466));
    EXPECT_EQ(r->frames[1].flags, 0);
    ASSERT_EQ(r->events.size(), 5u);  // 3 power-on, short, repair
    EXPECT_EQ(r->events[3], LineEventKind::ShortCircuit);
    EXPECT_EQ(r->events[4], LineEventKind::ShortRepaired);
  }
}

TEST_F(LineProbeTest, ACollisionIsFlaggedOnItsSegmentAndInvisibleBeyondTheCut) {
  make(4);  // p0 p1 | p2 p3
  ProbeRecorder left, right;
  line.add_tap(left, ProbePoint{0});
  line.add_tap(right, ProbePoint{3});
  line.start();
  line.set_cut_after(1, true);
  p(2).send(B(10), kSd1);  // [10, 76)
  p(3).send(B(43), kSd2);  // [43, 164): overlaps SD1 characters 3..5 ([43, 76))
  p(0).send(B(20), kSd1);  // [20, 86) on the left, alone
  sched.run_until(B(1000));

  ASSERT_EQ(left.frames.size(), 1u);
  EXPECT_EQ(left.frames[0].hex, kSd1);
  EXPECT_EQ(left.frames[0].sender, 0);
  EXPECT_EQ(left.frames[0].flags, 0);

  ASSERT_EQ(right.frames.size(), 2u);
  const auto sd1 = bytes_from_hex(kSd1);
  const auto sd2 = bytes_from_hex(kSd2);
  const auto& a = right.frames[0];  // SD1, ends first
  const auto& b = right.frames[1];
  EXPECT_EQ(a.sender, 2);
  EXPECT_EQ(a.start, B(10));
  EXPECT_EQ(a.flags, bus::kRxCollision);
  ASSERT_EQ(a.bytes.size(), 6u);
  for (std::size_t i = 0; i < 6; ++i) {
    if (i < 3) EXPECT_EQ(a.bytes[i], sd1[i]) << i;
    else EXPECT_NE(a.bytes[i], sd1[i]) << i;
  }
  EXPECT_EQ(b.sender, 3);
  EXPECT_EQ(b.start, B(43));
  EXPECT_EQ(b.flags, bus::kRxCollision);
  ASSERT_EQ(b.bytes.size(), 11u);
  for (std::size_t i = 0; i < 11; ++i) {
    if (i < 3) EXPECT_NE(b.bytes[i], sd2[i]) << i;
    else EXPECT_EQ(b.bytes[i], sd2[i]) << i;
  }
  // Exactly what the stations on that segment received.
  ASSERT_EQ(p(3).rx.size(), 1u);
  EXPECT_EQ(p(3).rx[0].bytes, a.bytes);
  ASSERT_EQ(p(2).rx.size(), 1u);
  EXPECT_EQ(p(2).rx[0].bytes, b.bytes);
}

TEST_F(LineProbeTest, AProbeHearsTheCableWhateverItsStationIsDoing) {
  make(3);
  ProbeRecorder r;
  line.add_tap(r, ProbePoint{1});
  line.start();
  at(B(5), [&] { line.set_power(1, false); });
  p(0).send(B(10), kSd1);  // [10, 76): p1 is off, the probe next to it hears it
  at(B(100), [&] {
    line.set_power(1, true);
    line.set_transceiver_ok(1, false);
  });
  p(2).send(B(200), kSc);  // [200, 211): p1's transceiver is dead, the probe is not
  at(B(250), [&] { p(1).send(B(300), kToken); });  // never reaches the cable
  sched.run_until(B(1000));

  EXPECT_TRUE(p(1).rx.empty());
  ASSERT_EQ(r.frames.size(), 2u);
  EXPECT_EQ(r.frames[0].hex, kSd1);
  EXPECT_EQ(r.frames[0].start, B(10));
  EXPECT_EQ(r.frames[1].hex, kSc);
  EXPECT_EQ(r.frames[1].start, B(200));
  EXPECT_EQ(r.frames[1].sender, 2);
  EXPECT_EQ(line.stats().lost, 1u);
}

TEST_F(LineProbeTest, OverlappingFramesArriveByEndAndTheLineSaysWhatIsStillOnTheWire) {
  make(3);
  ProbeRecorder r;
  line.add_tap(r, ProbePoint{2});
  line.start();
  EXPECT_EQ(line.earliest_start_in_flight(), bus::kNever);
  p(0).send(0, kSd2);      // [0, 121)
  p(1).send(B(50), kSc);   // [50, 61): inside the SD2
  sched.run_until(B(1000));
  ASSERT_EQ(r.frames.size(), 2u);
  EXPECT_EQ(r.frames[0].start, B(50));  // the SC ends first ...
  EXPECT_EQ(r.frames[0].end, B(61));
  EXPECT_EQ(r.frames[0].earliest_in_flight, 0);  // ... while the SD2 from 0 is still going
  EXPECT_EQ(r.frames[0].flags, bus::kRxCollision);
  EXPECT_EQ(r.frames[1].start, 0);
  EXPECT_EQ(r.frames[1].end, B(121));
  // While the taps are told about a frame it still counts as on the wire: a tap that sits at
  // several points must not take it for gone before its other probes have it.
  EXPECT_EQ(r.frames[1].earliest_in_flight, 0);
  EXPECT_EQ(line.earliest_start_in_flight(), bus::kNever);
}

TEST_F(LineProbeTest, OneTapAtSeveralPointsGetsEachEventOnceAndRemoveTakesAll) {
  make(3);
  ProbeRecorder r, other;
  EXPECT_THROW(line.add_tap(r, ProbePoint{3}), std::out_of_range);
  line.add_tap(r);  // whole line
  line.add_tap(r, ProbePoint{0});
  line.add_tap(other, ProbePoint{1});
  line.add_tap(r, ProbePoint{2});
  EXPECT_EQ(line.probe_count(), 3);
  line.start();
  p(0).send(0, kSd1);       // [0, 66)
  p(1).send(B(100), kSd2);  // [100, 221): r is removed in the middle of it
  at(B(150), [&] { line.remove_tap(r); });
  at(B(160), [&] { line.set_noise(0); });
  sched.run_until(B(1000));

  // The SD1 three times: whole-line, then the probes at 0 and 2.
  ASSERT_EQ(r.frames.size(), 3u);
  EXPECT_EQ(r.frames[0].probe, -1);
  EXPECT_EQ(r.frames[1].probe, 0);
  EXPECT_EQ(r.frames[2].probe, 2);
  EXPECT_EQ(r.hex_all(), (std::vector<std::string>{kSd1, kSd1, kSd1}));
  EXPECT_EQ(r.events.size(), 3u);  // the power-ons, once each
  EXPECT_EQ(line.probe_count(), 1);
  // The other tap keeps its probe (its index moved down) and hears the SD2 to its end.
  ASSERT_EQ(other.frames.size(), 2u);
  EXPECT_EQ(other.frames[1].hex, kSd2);
  EXPECT_EQ(other.frames[1].probe, 1);
  EXPECT_EQ(other.frames[1].end, B(221));
  EXPECT_EQ(other.events.size(), 4u);
}

}  // namespace
}  // namespace pbvbus::test
