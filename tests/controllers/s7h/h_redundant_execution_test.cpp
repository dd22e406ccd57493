// Redundant execution of the user program on both CPUs (devices/h_redundant_execution.hpp,
// docs/h-programs.md; seeds-digest.md §5, §7 F16/F18, §11 C3). Times are written out by hand in
// ticks (1 ms = 3 636 000 ticks), expected bytes are literal.
#include "pbvbus/s7h/h_redundant_execution.hpp"

#include <gtest/gtest.h>

#include <array>
#include <cstdint>
#include <random>
#include <stdexcept>
#include <vector>

namespace pbvbus::devices {
namespace {

using bus::Ticks;
constexpr Ticks kMs = 3'636'000;
static_assert(kMs == bus::kTicksPerMs);
using B = std::vector<std::uint8_t>;
B bytes(std::span<const std::uint8_t> s) { return {s.begin(), s.end()}; }
constexpr std::array<bool, 2> kBoth{true, true};

// PII 8, PIQ 8:
//   copy     IB 0..3 → QB 0..3
//   counter  QB 4..5 (width 2), period 100 ms, step 1, pulse Q 6.0 for 20 ms
//   monitor  IB 4 vs IB 5 (mask 0xFF), discrepancy time 10 ms → QB 7
// Memory: counter state 0..15, monitor state 16..32 (header 16..31, last agreed 32).
// Q 6.1..6.7 are written by nobody.
ProgramSpec plant() {
  ProgramSpec s;
  s.scan_time = 10 * kMs;
  s.copies.push_back({0, 0, 4});
  CounterNetwork c;
  c.output = 4;
  c.width = 2;
  c.period = 100 * kMs;
  c.step = 1;
  c.pulse_output = 6;
  c.pulse_bit = 0;
  c.pulse_high = 20 * kMs;
  s.counters.push_back(c);
  DiscrepancyNetwork m;
  m.input_a = 4;
  m.input_b = 5;
  m.length = 1;
  m.mask = 0xFF;
  m.to_output = 7;
  m.discrepancy_time = 10 * kMs;
  s.monitors.push_back(m);
  return s;
}

const B kInputs{0x01, 0x02, 0x03, 0x04, 0x55, 0x55, 0x00, 0x00};

TEST(HRedundantExecution, TheSameInputsGoIntoBothCpus) {
  RedundantExecution x(plant(), 8, 8);
  ASSERT_TRUE(x.set_inputs(kInputs));
  EXPECT_EQ(bytes(x.image(0).pii()), kInputs);
  EXPECT_EQ(bytes(x.image(1).pii()), kInputs);
  const auto r = x.scan(0, kBoth, 0);
  EXPECT_TRUE(r.compared);
  EXPECT_FALSE(r.comparison_error);
  EXPECT_FALSE(r.sync_error);
  ASSERT_TRUE(r.output_rack);
  EXPECT_EQ(*r.output_rack, 0);
  // copy 01 02 03 04, counter 00 00, pulse high (t = 0 ∈ [0, 20 ms)) → 0x01, monitor 0x55
  EXPECT_EQ(bytes(x.image(0).piq()), (B{0x01, 0x02, 0x03, 0x04, 0x00, 0x00, 0x01, 0x55}));
  EXPECT_EQ(x.image(0), x.image(1));
  EXPECT_EQ(x.scans(0), 1u);
  EXPECT_EQ(x.scans(1), 1u);
}

TEST(HRedundantExecution, NoComparisonErrorOverTenThousandRandomScans) {
  RedundantExecution x(plant(), 8, 8);
  std::mt19937 rng(20261125);  // seeded: the stream is the same on every run and platform
  bool disturbed = false;
  int raised = 0, gone = 0;
  for (int i = 0; i < 10'000; ++i) {
    B in(8);
    for (auto& b : in) b = static_cast<std::uint8_t>(rng() & 0xFF);
    if (rng() % 100 < 3) disturbed = !disturbed;  // episodes of ~33 scans on the redundant DI
    in[5] = disturbed ? static_cast<std::uint8_t>(in[4] ^ 0x10) : in[4];
    ASSERT_TRUE(x.set_inputs(in));
    const auto r = x.scan(i * 10 * kMs, kBoth, 0);
    ASSERT_TRUE(r.compared);
    ASSERT_FALSE(r.comparison_error) << "scan " << i;
    ASSERT_FALSE(r.sync_error) << "scan " << i;
    ASSERT_EQ(bytes(x.image(0).piq()), bytes(x.image(1).piq())) << "scan " << i;
    for (const auto& e : r.events) (e.incoming ? raised : gone) += 1;
  }
  // The stream did exercise the monitor (a test that would pass on an idle program proves
  // nothing): 7960 raised and gone, alternating (at most one open episode at the end).
  EXPECT_GT(raised, 10);
  EXPECT_TRUE(raised == gone || raised == gone + 1);
  EXPECT_EQ(x.events().size(), static_cast<std::size_t>(raised + gone));
  // last scan at 9 999 · 10 ms = 99 990 ms: boundaries 100, 200, ..., 99 900 ms → 999 = 0x03E7
  EXPECT_EQ(x.image(0).piq()[4], 0x03);
  EXPECT_EQ(x.image(0).piq()[5], 0xE7);
  EXPECT_EQ(x.scans(0), 10'000u);
  EXPECT_EQ(x.scans(1), 10'000u);
}

// Runs scans at 0, 10, ..., 50 ms on both CPUs with constant inputs, all without error.
void warm_up(RedundantExecution& x) {
  ASSERT_TRUE(x.set_inputs(kInputs));
  for (Ticks ms = 0; ms <= 50; ms += 10) {
    const auto r = x.scan(ms * kMs, kBoth, 0);
    ASSERT_TRUE(r.compared);
    ASSERT_FALSE(r.comparison_error);
  }
}

TEST(HRedundantExecution, InjectedDivergenceIsAComparisonErrorOnEitherRackInEitherArea) {
  struct Case {
    Area area;
    std::uint32_t offset;
    std::uint8_t mask;
    std::uint8_t injected;  // the byte on the injected rack after the next scan
    std::uint8_t clean;     // on the other rack
  };
  const Case cases[] = {
      // Q 6.7: nobody writes it; at 60 ms the pulse Q 6.0 is low (60 ≥ 20 ms) → 0x80 vs 0x00
      {Area::Piq, 6, 0x80, 0x80, 0x00},
      // memory byte 13: a reserved byte of the counter's state (a RAM bit flip)
      {Area::Memory, 13, 0x40, 0x40, 0x00},
  };
  for (const auto& c : cases) {
    for (int rack = 0; rack < 2; ++rack) {
      RedundantExecution x(plant(), 8, 8);
      warm_up(x);
      ASSERT_TRUE(x.inject_divergence(rack, c.area, c.offset, c.mask));
      const auto r = x.scan(60 * kMs, kBoth, 0);
      ASSERT_TRUE(r.comparison_error) << area_name(c.area) << " rack " << rack;
      EXPECT_EQ(r.comparison_error->area, c.area);
      EXPECT_EQ(r.comparison_error->offset, c.offset);
      EXPECT_EQ(r.comparison_error->value[rack], c.injected);
      EXPECT_EQ(r.comparison_error->value[1 - rack], c.clean);
      EXPECT_FALSE(r.sync_error);  // same control flow, different data
      // reported again at every compared scan until the update copies a state over
      EXPECT_TRUE(x.scan(70 * kMs, kBoth, 0).comparison_error);
      ASSERT_TRUE(x.copy_state(1 - rack, rack));
      EXPECT_EQ(x.image(0), x.image(1));
      EXPECT_FALSE(x.scan(80 * kMs, kBoth, 0).comparison_error);
    }
  }
}

TEST(HRedundantExecution, DivergentProgramStateReachesTheOutputImageFirst) {
  RedundantExecution x(plant(), 8, 8);
  warm_up(x);
  // memory 11 = the counter value's low octet (0 at 50 ms); flipped bit 0 on rack 1 → 1
  ASSERT_TRUE(x.inject_divergence(1, Area::Memory, 11, 0x01));
  const auto r = x.scan(100 * kMs, kBoth, 0);  // one boundary: rack 0 → 1, rack 1 → 2
  ASSERT_TRUE(r.comparison_error);
  EXPECT_EQ(r.comparison_error->area, Area::Piq);  // PIQ is compared before memory
  EXPECT_EQ(r.comparison_error->offset, 5u);
  EXPECT_EQ(r.comparison_error->value[0], 0x01);
  EXPECT_EQ(r.comparison_error->value[1], 0x02);
}

TEST(HRedundantExecution, InjectedPiiDivergenceIsOverwrittenAtTheNextSyncPoint) {
  RedundantExecution x(plant(), 8, 8);
  warm_up(x);
  ASSERT_TRUE(x.inject_divergence(0, Area::Pii, 0, 0xFF));
  ASSERT_TRUE(x.set_inputs(kInputs));  // the sync point: both get the I/O's bytes again
  EXPECT_FALSE(x.scan(60 * kMs, kBoth, 0).comparison_error);
  // without a sync point in between, the copy network carries it into QB 0
  ASSERT_TRUE(x.inject_divergence(0, Area::Pii, 0, 0xFF));
  const auto r = x.scan(70 * kMs, kBoth, 0);
  ASSERT_TRUE(r.comparison_error);
  EXPECT_EQ(r.comparison_error->area, Area::Piq);
  EXPECT_EQ(r.comparison_error->offset, 0u);
  EXPECT_EQ(r.comparison_error->value[0], 0xFE);  // 0x01 ^ 0xFF
  EXPECT_EQ(r.comparison_error->value[1], 0x01);
}

TEST(HRedundantExecution, StandbyJoiningMidRunSendsTheSameOutputsAfterCopyState) {
  auto solo_then_join = [](bool update) {
    RedundantExecution x(plant(), 8, 8);
    EXPECT_TRUE(x.set_inputs(kInputs));
    for (Ticks ms = 0; ms <= 1240; ms += 10) x.scan(ms * kMs, {true, false}, 0);  // Solo
    if (update) {
      EXPECT_TRUE(x.copy_state(0, 1));  // the update's output copy
    }
    return x;
  };
  {
    auto x = solo_then_join(true);
    EXPECT_EQ(x.scans(0), 125u);  // 0, 10, ..., 1240 ms
    EXPECT_EQ(x.scans(1), 0u);
    EXPECT_EQ(x.image(0), x.image(1));
    auto r = x.scan(1250 * kMs, kBoth, 0);  // first Redundant scan
    EXPECT_FALSE(r.comparison_error);
    // counter: boundaries 100 .. 1200 ms → 12; pulse low (1250 − 1200 = 50 ms ≥ 20 ms)
    EXPECT_EQ(bytes(x.image(1).piq()), (B{0x01, 0x02, 0x03, 0x04, 0x00, 0x0C, 0x00, 0x55}));
    EXPECT_EQ(bytes(x.image(0).piq()), bytes(x.image(1).piq()));
    // a master swap at any later scan sends identical bytes: no output pulse
    std::mt19937 rng(7);
    B last_sent;
    for (int i = 1; i <= 200; ++i) {
      B in = kInputs;
      in[0] = static_cast<std::uint8_t>(rng());
      ASSERT_TRUE(x.set_inputs(in));
      const int master = i < 100 ? 0 : 1;  // swap at scan 100
      r = x.scan((1250 + 10 * i) * kMs, kBoth, master);
      ASSERT_FALSE(r.comparison_error);
      ASSERT_TRUE(r.output_rack);
      ASSERT_EQ(*r.output_rack, master);
      ASSERT_EQ(bytes(x.image(0).piq()), bytes(x.image(1).piq()));
    }
    // 1250 + 2000 = 3250 ms: 32 boundaries = 0x20; pulse low (50 ms into the period)
    EXPECT_EQ(x.image(1).piq()[5], 0x20);
  }
  {  // the control: without the update the standby starts its own epoch → comparison error
    auto x = solo_then_join(false);
    const auto r = x.scan(1250 * kMs, kBoth, 0);
    ASSERT_TRUE(r.comparison_error);
    EXPECT_EQ(r.comparison_error->area, Area::Piq);
    EXPECT_EQ(r.comparison_error->offset, 5u);
    EXPECT_EQ(r.comparison_error->value[0], 0x0C);
    EXPECT_EQ(r.comparison_error->value[1], 0x00);
  }
}

TEST(HRedundantExecution, EventsAreReportedOnceWithTheMastersRack) {
  RedundantExecution x(plant(), 8, 8);
  B in = kInputs;
  in[5] = 0x54;  // IB 4 0x55 vs IB 5 0x54 from t = 0
  ASSERT_TRUE(x.set_inputs(in));
  EXPECT_TRUE(x.scan(0, kBoth, 1).events.empty());
  const auto r = x.scan(10 * kMs, kBoth, 1);  // 10 ms − 0 ≥ 10 ms: 7960
  const ProgramEvent want{36'360'000, 0x7960, true, 0, 4, 5, 1, 1};  // 10 · 3 636 000, rack 1
  EXPECT_EQ(r.events, (std::vector{want}));
  EXPECT_EQ(x.events(), (std::vector{want}));
  EXPECT_FALSE(r.sync_error);
  ASSERT_TRUE(x.set_inputs(kInputs));
  const auto g = x.scan(20 * kMs, {true, false}, 1);  // master 1 not running: rack 0 reports
  ASSERT_EQ(g.events.size(), 1u);
  EXPECT_FALSE(g.events[0].incoming);
  EXPECT_EQ(g.events[0].rack, 0);
  EXPECT_EQ(g.events[0].time, 72'720'000);  // 20 · 3 636 000
  EXPECT_FALSE(g.output_rack);              // the master did not run: nothing to send
  EXPECT_EQ(x.events().size(), 2u);
}

TEST(HRedundantExecution, DivergingControlFlowIsASyncError) {
  RedundantExecution x(plant(), 8, 8);
  ASSERT_TRUE(x.set_inputs(kInputs));
  x.scan(0, kBoth, 0);
  B in = kInputs;
  in[5] = 0x00;
  ASSERT_TRUE(x.set_inputs(in));
  x.scan(1 * kMs, kBoth, 0);  // since = 1 ms = 3 636 000 = 0x00377B20
  const auto off = static_cast<std::uint32_t>(x.program().monitor_state_offset(0) + 7);  // 23
  EXPECT_EQ(off, 23u);
  EXPECT_EQ(x.image(1).memory()[off], 0x20);
  // F18 stand-in: rack 1's timer start becomes 3 636 001 (one tick later)
  ASSERT_TRUE(x.inject_divergence(1, Area::Memory, off, 0x01));
  const auto r = x.scan(11 * kMs, kBoth, 0);  // rack 0: 10 ms elapsed → 7960; rack 1: 1 tick short
  EXPECT_TRUE(r.sync_error);
  ASSERT_TRUE(r.comparison_error);
  EXPECT_EQ(r.comparison_error->area, Area::Memory);
  EXPECT_EQ(r.comparison_error->offset, 23u);
  EXPECT_EQ(r.comparison_error->value[0], 0x20);
  EXPECT_EQ(r.comparison_error->value[1], 0x21);
  ASSERT_EQ(r.events.size(), 1u);  // the master's run
  EXPECT_EQ(r.events[0].rack, 0);
}

TEST(HRedundantExecution, NextScanIsStartToStart) {
  RedundantExecution x(plant(), 8, 8);
  EXPECT_EQ(x.scan_time(), 36'360'000);  // 10 ms
  EXPECT_EQ(x.next_scan(5), 5);          // nothing ran yet: at once
  x.scan(2 * kMs, kBoth, 0);
  EXPECT_EQ(x.next_scan(3 * kMs), 12 * kMs);   // 2 + 10 ms = 43 632 000
  EXPECT_EQ(x.next_scan(12 * kMs), 12 * kMs);
  EXPECT_EQ(x.next_scan(25 * kMs), 25 * kMs);  // late (after an I/O freeze): at once
  x.scan(13 * kMs, {false, false}, 0);          // no CPU ran: not a scan start
  EXPECT_EQ(x.next_scan(0), 12 * kMs);
}

TEST(HRedundantExecution, SoloScanIsNotCompared) {
  RedundantExecution x(plant(), 8, 8);
  ASSERT_TRUE(x.set_inputs(kInputs));
  const auto r = x.scan(0, {false, true}, 1);
  EXPECT_FALSE(r.compared);
  EXPECT_FALSE(r.comparison_error);
  EXPECT_EQ(r.ran, (std::array<bool, 2>{false, true}));
  ASSERT_TRUE(r.output_rack);
  EXPECT_EQ(*r.output_rack, 1);
  EXPECT_EQ(x.scans(0), 0u);
  EXPECT_EQ(x.scans(1), 1u);
  EXPECT_EQ(bytes(x.image(0).piq()), B(8, 0x00));  // rack 0 did not run
}

TEST(HRedundantExecution, BadArgumentsAreRefusedWithoutChange) {
  RedundantExecution x(plant(), 8, 8);
  EXPECT_FALSE(x.set_inputs(B(7, 0xFF)));
  EXPECT_FALSE(x.set_inputs(B(9, 0xFF)));
  EXPECT_EQ(bytes(x.image(0).pii()), B(8, 0x00));
  EXPECT_FALSE(x.inject_divergence(2, Area::Piq, 0, 1));
  EXPECT_FALSE(x.inject_divergence(-1, Area::Piq, 0, 1));
  EXPECT_FALSE(x.inject_divergence(0, Area::Piq, 8, 1));      // PIQ is QB 0..7
  EXPECT_FALSE(x.inject_divergence(0, Area::Memory, 33, 1));  // memory is 0..32
  EXPECT_TRUE(x.inject_divergence(0, Area::Memory, 32, 0));
  EXPECT_FALSE(x.copy_state(0, 2));
  EXPECT_FALSE(x.copy_state(-1, 0));
  EXPECT_TRUE(x.copy_state(1, 1));
  EXPECT_THROW((void)x.image(2), std::out_of_range);
  EXPECT_EQ(x.scans(7), 0u);
  const auto r = x.scan(-1, kBoth, 0);
  EXPECT_EQ(r.ran, (std::array<bool, 2>{false, false}));
  EXPECT_FALSE(x.scan(0, kBoth, 5).output_rack);  // no such master
  ProgramSpec bad;
  bad.scan_time = 0;
  EXPECT_THROW(RedundantExecution(bad, 8, 8), std::invalid_argument);
}

}  // namespace
}  // namespace pbvbus::devices
