// The user program of an H-CPU (devices/h_program.hpp, docs/h-programs.md): copies, counters and
// pulses on virtual time, the discrepancy monitor (error 7960), validation. Every time is
// written out by hand in ticks (1 ms = 3 636 000 ticks, 1 µs = 3 636 ticks, bus/time.hpp) with
// the arithmetic in a comment; every expected byte is literal.
#include "pbvbus/s7h/h_program.hpp"
#include "pbvbus/s7h/h_dp_sfc.hpp"

#include <gtest/gtest.h>

#include <cstdint>
#include <stdexcept>
#include <string>
#include <vector>

namespace pbvbus::devices {
namespace {

using bus::Ticks;
constexpr Ticks kMs = 3'636'000;  // bus::kTicksPerMs, written out
static_assert(kMs == bus::kTicksPerMs);

std::vector<std::uint8_t> bytes(std::span<const std::uint8_t> s) { return {s.begin(), s.end()}; }
using B = std::vector<std::uint8_t>;

ProgramSpec counter_spec(std::uint32_t width, std::uint32_t step) {
  ProgramSpec s;
  CounterNetwork c;
  c.output = 0;
  c.width = width;
  c.period = 100 * kMs;  // 363 600 000 ticks
  c.step = step;
  s.counters.push_back(c);
  return s;
}

// ---- counters --------------------------------------------------------------------------------

TEST(HProgram, CounterValueAtVirtualTimes) {
  const Program p(counter_spec(2, 1), 0, 4);
  auto img = p.make_image();
  // epoch = the first scan at t = 0; boundaries at k·100 ms.
  p.scan(img, 0);
  EXPECT_EQ(bytes(img.piq()), (B{0x00, 0x00, 0x00, 0x00}));
  p.scan(img, 363'596'364);  // 99.999 ms = 99 999 µs · 3 636 = 363 596 364 ticks
  EXPECT_EQ(bytes(img.piq()), (B{0x00, 0x00, 0x00, 0x00}));
  p.scan(img, 363'600'000);  // 100 ms = 100 · 3 636 000
  EXPECT_EQ(bytes(img.piq()), (B{0x00, 0x01, 0x00, 0x00}));
  p.scan(img, 3'636'000'000);  // 1 s: 10 boundaries (100 ms .. 1 s) → 10 = 0x000A
  EXPECT_EQ(bytes(img.piq()), (B{0x00, 0x0A, 0x00, 0x00}));
}

TEST(HProgram, CounterDependsOnTimeNotOnScanCount) {
  const Program p(counter_spec(2, 3), 0, 2);
  auto every_ms = p.make_image();
  auto twice = p.make_image();
  for (Ticks t = 0; t <= 1000 * kMs; t += kMs) p.scan(every_ms, t);  // 1001 scans
  p.scan(twice, 0);
  p.scan(twice, 1000 * kMs);
  // 10 boundaries · step 3 = 30 = 0x001E in both, whatever the scan count.
  EXPECT_EQ(bytes(every_ms.piq()), (B{0x00, 0x1E}));
  EXPECT_EQ(bytes(twice.piq()), (B{0x00, 0x1E}));
  EXPECT_EQ(every_ms.memory()[15], 0);  // (reserved byte, still zero)
  EXPECT_EQ(bytes(every_ms.memory()), bytes(twice.memory()));
}

TEST(HProgram, CounterEpochIsTheFirstScan) {
  const Program p(counter_spec(1, 1), 0, 1);
  auto img = p.make_image();
  p.scan(img, 250 * kMs);  // epoch 250 ms, boundaries 350, 450, ... ms
  p.scan(img, 349 * kMs);
  EXPECT_EQ(img.piq()[0], 0x00);
  p.scan(img, 350 * kMs);
  EXPECT_EQ(img.piq()[0], 0x01);
  // memory: the next boundary, 450 ms, big-endian in bytes 0..7, then the value and the flags
  const auto m = img.memory();
  std::int64_t next = 0;
  for (int i = 0; i < 8; ++i) next = (next << 8) | m[static_cast<std::size_t>(i)];
  EXPECT_EQ(next, 1'636'200'000);  // 450 · 3 636 000
  EXPECT_EQ(bytes(m.subspan(8, 5)), (B{0x00, 0x00, 0x00, 0x01, 0x01}));  // value 1, started
}

TEST(HProgram, CounterWrapsAtItsWidth) {
  {  // width 2: 65 535 boundaries → 0xFFFF, 65 536 → 0x0000
    const Program p(counter_spec(2, 1), 0, 2);
    auto img = p.make_image();
    p.scan(img, 0);
    p.scan(img, 23'828'526'000'000);  // 65 535 · 363 600 000
    EXPECT_EQ(bytes(img.piq()), (B{0xFF, 0xFF}));
    p.scan(img, 23'828'889'600'000);  // 65 536 · 363 600 000
    EXPECT_EQ(bytes(img.piq()), (B{0x00, 0x00}));
  }
  {  // width 1, step 16: 15 boundaries → 240 = 0xF0, 16 → 256 → 0x00, 17 → 0x10
    const Program p(counter_spec(1, 16), 0, 1);
    auto img = p.make_image();
    p.scan(img, 0);
    p.scan(img, 15 * 100 * kMs);
    EXPECT_EQ(img.piq()[0], 0xF0);
    p.scan(img, 16 * 100 * kMs);
    EXPECT_EQ(img.piq()[0], 0x00);
    p.scan(img, 17 * 100 * kMs);
    EXPECT_EQ(img.piq()[0], 0x10);
  }
  {  // width 4, big-endian: step 0x01020304 after one period; 0xFFFFFFFF + 1 wraps to 0
    const Program p(counter_spec(4, 0x01020304), 0, 4);
    auto img = p.make_image();
    p.scan(img, 0);
    p.scan(img, 100 * kMs);
    EXPECT_EQ(bytes(img.piq()), (B{0x01, 0x02, 0x03, 0x04}));
    const Program q(counter_spec(4, 0xFFFFFFFF), 0, 4);
    auto w = q.make_image();
    q.scan(w, 0);
    q.scan(w, 100 * kMs);
    EXPECT_EQ(bytes(w.piq()), (B{0xFF, 0xFF, 0xFF, 0xFF}));
    q.scan(w, 200 * kMs);  // 0xFFFFFFFF · 2 mod 2^32 = 0xFFFFFFFE
    EXPECT_EQ(bytes(w.piq()), (B{0xFF, 0xFF, 0xFF, 0xFE}));
  }
}

TEST(HProgram, PulseHighExactlyInItsWindow) {
  ProgramSpec s = counter_spec(1, 1);
  s.counters[0].pulse_output = 3;
  s.counters[0].pulse_bit = 5;             // Q 3.5 = 0x20
  s.counters[0].pulse_high = 20 * kMs;     // 72 720 000 ticks
  const Program p(s, 0, 4);
  auto img = p.make_image();
  img.piq()[3] = 0x81;  // other bits of QB 3 are not the counter's: they stay
  struct Probe {
    Ticks t;
    std::uint8_t qb3;
  };
  // window [k·100 ms, k·100 ms + 20 ms)
  const Probe probes[] = {
      {0, 0xA1},                    // k = 0 start: high
      {20 * kMs - 1, 0xA1},         // 72 719 999: last tick of the window
      {20 * kMs, 0x81},             // 72 720 000: low
      {100 * kMs - 1, 0x81},        // 363 599 999
      {100 * kMs, 0xA1},            // k = 1
      {700 * kMs + 20 * kMs - 1, 0xA1},  // k = 7: 2 617 919 999
      {720 * kMs, 0x81},            // 2 617 920 000
      {3'000 * kMs + 5 * kMs, 0xA1},     // k = 30 after a long gap without scans
  };
  for (const auto& pr : probes) {
    p.scan(img, pr.t);
    EXPECT_EQ(img.piq()[3], pr.qb3) << "t = " << pr.t;
  }
}

TEST(HProgram, PulseAsLongAsThePeriodIsAlwaysHigh) {
  ProgramSpec s = counter_spec(1, 1);
  s.counters[0].pulse_output = 1;
  s.counters[0].pulse_bit = 0;
  s.counters[0].pulse_high = 100 * kMs;
  const Program p(s, 0, 2);
  auto img = p.make_image();
  for (Ticks t : {Ticks{0}, 100 * kMs - 1, 100 * kMs, 250 * kMs}) {
    p.scan(img, t);
    EXPECT_EQ(img.piq()[1], 0x01) << t;
  }
}

// ---- copies and order ------------------------------------------------------------------------

TEST(HProgram, CopyBytes) {
  ProgramSpec s;
  s.copies.push_back({2, 5, 3});  // IB 2..4 → QB 5..7
  s.copies.push_back({0, 0, 1});  // IB 0 → QB 0
  const Program p(s, 8, 8);
  auto img = p.make_image();
  const B in{0x11, 0x22, 0x33, 0x44, 0x55, 0x66, 0x77, 0x88};
  std::copy(in.begin(), in.end(), img.pii().begin());
  p.scan(img, 0);
  EXPECT_EQ(bytes(img.piq()), (B{0x11, 0x00, 0x00, 0x00, 0x00, 0x33, 0x44, 0x55}));
}

TEST(HProgram, CounterOverwritesACopyOnPurpose) {
  ProgramSpec s = counter_spec(1, 1);  // QB 0
  s.copies.push_back({0, 0, 2});       // IB 0..1 → QB 0..1, then the counter writes QB 0
  const Program p(s, 2, 2);
  auto img = p.make_image();
  img.pii()[0] = 0xAA;
  img.pii()[1] = 0xBB;
  p.scan(img, 0);
  p.scan(img, 200 * kMs);  // value 2
  EXPECT_EQ(bytes(img.piq()), (B{0x02, 0xBB}));
}

// ---- discrepancy monitor ---------------------------------------------------------------------

ProgramSpec monitor_spec(Ticks discrepancy_time) {
  ProgramSpec s;
  DiscrepancyNetwork m;
  m.input_a = 0;
  m.input_b = 1;
  m.length = 1;
  m.mask = 0x0F;
  m.to_output = 0;
  m.discrepancy_time = discrepancy_time;
  s.monitors.push_back(m);
  return s;
}

ProgramEvent ev(Ticks t, bool incoming) {
  return ProgramEvent{t, 0x7960, incoming, 0, 0, 1, 1, -1};
}

TEST(HProgram, DiscrepancyErrorExactlyAtTheBoundaryThenGone) {
  const Program p(monitor_spec(10 * kMs), 2, 1);
  auto img = p.make_image();
  auto in = [&](std::uint8_t a, std::uint8_t b) {
    img.pii()[0] = a;
    img.pii()[1] = b;
  };
  in(0x05, 0x05);
  EXPECT_TRUE(p.scan(img, 0).empty());
  EXPECT_EQ(img.piq()[0], 0x05);
  in(0x34, 0x05);  // mask bits: 0x4 vs 0x5, bit 0 differs; since = 1 ms
  EXPECT_TRUE(p.scan(img, 1 * kMs).empty());
  // bit 0 keeps the last agreed 1; bits 1..3 agree (0x4); bits 4..7 from A (0x30) → 0x35
  EXPECT_EQ(img.piq()[0], 0x35);
  EXPECT_TRUE(p.scan(img, 11 * kMs - 1).empty());  // lasted 10 ms − 1 tick: not expired
  EXPECT_EQ(p.scan(img, 11 * kMs), (std::vector{ev(39'996'000, true)}));  // 11 · 3 636 000
  EXPECT_TRUE(p.scan(img, 12 * kMs).empty());  // once per episode
  EXPECT_TRUE(p.scan(img, 500 * kMs).empty());
  in(0x04, 0x04);  // agree again → gone
  EXPECT_EQ(p.scan(img, 520 * kMs), (std::vector{ev(1'890'720'000, false)}));  // 520 · 3 636 000
  EXPECT_EQ(img.piq()[0], 0x04);
  EXPECT_TRUE(p.scan(img, 530 * kMs).empty());
}

TEST(HProgram, DiscrepancyShorterThanTheTimeRaisesNothing) {
  const Program p(monitor_spec(10 * kMs), 2, 1);
  auto img = p.make_image();
  img.pii()[0] = 0x01;  // differs from IB 1 = 0 at the first scan: since = 0
  EXPECT_TRUE(p.scan(img, 0).empty());
  EXPECT_TRUE(p.scan(img, 10 * kMs - 1).empty());  // 36 359 999: one tick short
  img.pii()[1] = 0x01;
  EXPECT_TRUE(p.scan(img, 10 * kMs).empty());  // agreed at the boundary: no 7960, no "gone"
  img.pii()[1] = 0x00;                          // a new episode from 20 ms
  EXPECT_TRUE(p.scan(img, 20 * kMs).empty());
  EXPECT_TRUE(p.scan(img, 29 * kMs).empty());
  EXPECT_EQ(p.scan(img, 30 * kMs), (std::vector{ev(109'080'000, true)}));  // 30 · 3 636 000
}

TEST(HProgram, DiscrepancyOncePerEpisodeOverTwoEpisodes) {
  const Program p(monitor_spec(5 * kMs), 2, 1);
  auto img = p.make_image();
  std::vector<ProgramEvent> all;
  // IB 0 bit 2 differs during [10, 40) ms and [60, 100) ms; scans every ms until 120 ms.
  for (Ticks ms = 0; ms <= 120; ++ms) {
    const bool differ = (ms >= 10 && ms < 40) || (ms >= 60 && ms < 100);
    img.pii()[0] = differ ? 0x04 : 0x00;
    p.scan(img, ms * kMs, all);
  }
  // raised at 10 + 5 = 15 ms and 60 + 5 = 65 ms; gone at 40 and 100 ms
  EXPECT_EQ(all, (std::vector{ev(54'540'000, true), ev(145'440'000, false),
                              ev(236'340'000, true), ev(363'600'000, false)}));
}

TEST(HProgram, DiscrepancyMaskIgnoresOtherBitsAndZeroTimeRaisesAtOnce) {
  const Program p(monitor_spec(0), 2, 1);
  auto img = p.make_image();
  img.pii()[0] = 0xF0;  // outside the mask 0x0F: no discrepancy
  EXPECT_TRUE(p.scan(img, 0).empty());
  EXPECT_EQ(img.piq()[0], 0xF0);
  img.pii()[1] = 0x08;  // bit 3 differs; discrepancy_time 0 → raised at the first scan
  EXPECT_EQ(p.scan(img, 7 * kMs), (std::vector{ev(25'452'000, true)}));  // 7 · 3 636 000
}

// ---- image, state, bad input -----------------------------------------------------------------

TEST(HProgram, AllStateIsInTheImage) {
  ProgramSpec s = counter_spec(2, 1);
  s.monitors = monitor_spec(10 * kMs).monitors;
  s.monitors[0].input_a = 0;
  s.monitors[0].input_b = 1;
  s.monitors[0].to_output = 2;
  const Program p(s, 2, 3);
  EXPECT_EQ(p.memory_size(), 16u + 16u + 1u);
  EXPECT_EQ(p.monitor_state_offset(0), 16u);
  auto a = p.make_image();
  a.pii()[0] = 0x01;
  for (Ticks ms = 0; ms <= 250; ms += 10) p.scan(a, ms * kMs);
  ProcessImage b = a;  // the update copies the image; the program object has no state
  const auto ea = p.scan(a, 360 * kMs);
  const auto eb = p.scan(b, 360 * kMs);
  EXPECT_EQ(a, b);
  EXPECT_EQ(ea, eb);
  EXPECT_EQ(bytes(a.piq()), (B{0x00, 0x03, 0x00}));  // 3 boundaries; bit 0 last agreed = 0
}

TEST(HProgram, ScanRefusesForeignImagesAndNegativeTime) {
  const Program p(counter_spec(1, 1), 0, 2);
  ProcessImage wrong(0, 3, p.memory_size());
  std::vector<ProgramEvent> e;
  EXPECT_FALSE(p.scan(wrong, 0, e));
  EXPECT_EQ(bytes(wrong.piq()), (B{0, 0, 0}));
  auto img = p.make_image();
  EXPECT_FALSE(p.scan(img, -1, e));
  EXPECT_EQ(img.memory()[12], 0x00);  // not started
  EXPECT_TRUE(p.scan(img, 0, e));
  EXPECT_EQ(img.memory()[12], 0x01);
}

TEST(HProgram, ImageSizesAreLimited) {
  EXPECT_NO_THROW(ProcessImage(16384, 16384, 10));
  EXPECT_NO_THROW(ProcessImage(0, 0));
  try {
    ProcessImage img(16385, 1);
    ADD_FAILURE() << "no exception";
  } catch (const std::invalid_argument& e) {
    EXPECT_EQ(std::string(e.what()), "PII size 16385 bytes exceeds the maximum 16384");
  }
  EXPECT_EQ(validate(ProgramSpec{}, 1, 20000),
            (std::vector<std::string>{"PIQ size 20000 bytes exceeds the maximum 16384"}));
}

TEST(HProgram, ValidationMessagesNameNetworkAndAddress) {
  ProgramSpec s;
  s.scan_time = 0;
  s.copies.push_back({7, 0, 2});  // IB 7..8 in an 8-byte PII
  s.copies.push_back({0, 2, 3});  // QB 2..4: overlaps copy 2 below
  s.copies.push_back({0, 4, 1});
  CounterNetwork c3;
  c3.output = 1;
  c3.width = 3;
  s.counters.push_back(c3);
  CounterNetwork c0;
  c0.output = 6;
  c0.period = 0;
  c0.pulse_output = 6;
  c0.pulse_bit = 1;
  c0.pulse_high = kMs;
  s.counters.push_back(c0);
  DiscrepancyNetwork m;
  m.input_a = 2;
  m.input_b = 3;
  m.length = 2;  // IB 2..3 and IB 3..4 overlap
  m.to_output = 7;  // QB 7..8 in an 8-byte PIQ
  m.mask = 0;
  s.monitors.push_back(m);
  const std::vector<std::string> want{
      "program: scan_time 0 ticks must be > 0",
      "copy 0: from_input IB 7 (2 octets) lies outside the PII (8 bytes, IB 0..IB 7)",
      "copy 2: to_output QB 4 (1 octet) overlaps the output of copy 1",
      "counter 0: width 3 at QB 1 (must be 1, 2 or 4 octets)",
      "counter 1: period 0 ticks at QB 6 must be > 0",
      "counter 1: pulse Q 6.1 lies inside its own value QB 6 (1 octet)",
      "monitor 0: mask 0 at IB 2 monitors no bit",
      "monitor 0: to_output QB 7 (2 octets) lies outside the PIQ (8 bytes, QB 0..QB 7)",
      "monitor 0: input_a IB 2 (2 octets) overlaps input_b IB 3 (2 octets) (two modules cannot "
      "share an address)",
  };
  EXPECT_EQ(validate(s, 8, 8), want);
  try {
    Program p(s, 8, 8);
    ADD_FAILURE() << "no exception";
  } catch (const std::invalid_argument& e) {
    EXPECT_EQ(std::string(e.what()), want.front());
  }
}

TEST(HProgram, ValidationOfCountersAgainstEachOtherAndHugeAddresses) {
  ProgramSpec s;
  CounterNetwork a;  // QB 0..1, pulse Q 4.0
  a.output = 0;
  a.width = 2;
  a.pulse_output = 4;
  a.pulse_high = kMs;
  CounterNetwork b = a;  // QB 1 (overlaps a's value), pulse Q 4.0 again
  b.output = 1;
  b.width = 1;
  CounterNetwork c = a;  // value QB 4 = a's pulse byte; pulse_high > period; bit 8
  c.output = 4;
  c.width = 1;
  c.pulse_output = 3;
  c.pulse_bit = 8;
  c.pulse_high = 200 * kMs;
  s.counters = {a, b, c};
  s.copies.push_back({0xFFFFFFFF, 0, 2});  // must not wrap into range
  const std::vector<std::string> want{
      "copy 0: from_input IB 4294967295 (2 octets) lies outside the PII (4 bytes, IB 0..IB 3)",
      "counter 1: output QB 1 (1 octet) overlaps the value of counter 0",
      "counter 1: pulse Q 4.0 is also the pulse of counter 0",
      "counter 2: pulse_high 727200000 ticks is longer than the period 363600000",
      "counter 2: pulse_bit 8 at QB 3 (must be 0..7)",
      "counter 2: output QB 4 (1 octet) overlaps the pulse byte of counter 0",
      "counter 2: output QB 4 (1 octet) overlaps the pulse byte of counter 1",
  };
  EXPECT_EQ(validate(s, 4, 8), want);
  ProgramSpec ok;
  ok.counters = {a};
  CounterNetwork d = a;  // same pulse byte, another bit: allowed
  d.output = 2;
  d.pulse_bit = 1;
  ok.counters.push_back(d);
  ok.copies.push_back({0, 0, 4});  // copy over a counter's output: allowed on purpose
  EXPECT_TRUE(validate(ok, 4, 8).empty());
}

TEST(HProgram, ValidationOfLengthsSignsAndMonitorOutputs) {
  ProgramSpec s;
  s.copies.push_back({0, 0, 0});
  CounterNetwork c;
  c.output = 2;
  c.pulse_output = 3;
  c.pulse_high = -5;
  s.counters.push_back(c);
  DiscrepancyNetwork m0;
  m0.length = 0;
  DiscrepancyNetwork m1;  // IB 0 vs IB 1 → QB 0
  m1.input_b = 1;
  m1.discrepancy_time = -1;
  DiscrepancyNetwork m2 = m1;  // IB 2 vs IB 3 → QB 0 again
  m2.input_a = 2;
  m2.input_b = 3;
  m2.discrepancy_time = 0;
  s.monitors = {m0, m1, m2};
  EXPECT_EQ(validate(s, 4, 4), (std::vector<std::string>{
                                   "copy 0: length 0 (at least 1 octet)",
                                   "counter 0: pulse_high -5 ticks must be ≥ 0",
                                   "monitor 0: length 0 (at least 1 octet)",
                                   "monitor 1: discrepancy_time -1 ticks must be ≥ 0",
                                   "monitor 2: to_output QB 0 (1 octet) overlaps the output of "
                                   "monitor 1",
                               }));
}


// ---- SFC 14 DPRD_DAT / SFC 15 DPWR_DAT (h_dp_sfc.hpp, docs/h-dp-sfc.md) ----------------------
// Modules: a DP module 4 in at IB 2..5 and 2 out at QB 0..1; a central module 1 in at IB 6.
// RECORD in MB 10.., RET_VAL in MW 0. Expected RET_VALs: 0000; 8090 no module at LADDR; 8093
// not a DP module; 80B1 RECORD's length is not the module's (001 L3352-3354, L3365); 8323 RECORD
// (SFC 14's parameter 3) outside M when writing; 8222 RECORD (SFC 15's parameter 2) outside M
// when reading.
struct DpSfcCase {
  ProgramSpec spec;
  ProcessImage img{8, 4, 16};
  DpSfcCase() {
    spec.io_modules = {{2, 4, 0, 2, true}, {6, 1, 0, 0, false}};
    const B in = {0x00, 0x00, 0x11, 0x22, 0x33, 0x44, 0x55, 0x00};
    std::copy(in.begin(), in.end(), img.pii().begin());
  }
  std::uint16_t ret_val() const {
    return static_cast<std::uint16_t>((img.memory()[0] << 8) | img.memory()[1]);
  }
  std::uint16_t read(std::uint32_t laddr, std::uint32_t record, std::uint32_t length) {
    ProgramSpec s = spec;
    s.dprd_dat.push_back({0, laddr, record, length, 0u});
    const Program p(s, 8, 4);
    EXPECT_TRUE(p.scan(img, 0).empty());
    return ret_val();
  }
  std::uint16_t write(std::uint32_t laddr, std::uint32_t record, std::uint32_t length) {
    ProgramSpec s = spec;
    s.dpwr_dat.push_back({0, laddr, record, length, 0u});
    const Program p(s, 8, 4);
    EXPECT_TRUE(p.scan(img, 0).empty());
    return ret_val();
  }
};

TEST(HProgramDpSfc, Sfc14ReadsTheWholeModuleOrAnswersItsRetVal) {
  DpSfcCase c;
  EXPECT_EQ(c.read(2, 10, 4), 0x0000);
  EXPECT_EQ(bytes(c.img.memory().subspan(10, 4)), (B{0x11, 0x22, 0x33, 0x44}));
  DpSfcCase w;  // a fresh M each: a refused call writes no RECORD
  EXPECT_EQ(w.read(2, 10, 2), 0x80B1);  // 2 octets of a 4-octet module
  EXPECT_EQ(w.read(2, 10, 5), 0x80B1);
  EXPECT_EQ(w.read(3, 10, 4), 0x8090);  // IB 3 is inside the module, not its start
  EXPECT_EQ(w.read(0, 10, 2), 0x8090);  // QB 0 is an output address; IB 0 has no module
  EXPECT_EQ(w.read(6, 10, 1), 0x8093);  // a central module
  EXPECT_EQ(w.read(2, 13, 4), 0x8323);  // MB 13..16 of a 16-octet M
  EXPECT_EQ(bytes(w.img.memory().subspan(2, 14)), B(14, 0));
}

TEST(HProgramDpSfc, Sfc15WritesTheWholeModuleOrAnswersItsRetVal) {
  DpSfcCase c;
  c.img.memory()[10] = 0xBE;
  c.img.memory()[11] = 0xEF;
  EXPECT_EQ(c.write(0, 10, 2), 0x0000);
  EXPECT_EQ(bytes(c.img.piq()), (B{0xBE, 0xEF, 0x00, 0x00}));
  DpSfcCase w;
  w.img.memory()[10] = 0xBE;
  EXPECT_EQ(w.write(0, 10, 1), 0x80B1);
  EXPECT_EQ(w.write(0, 10, 4), 0x80B1);
  EXPECT_EQ(w.write(2, 10, 2), 0x8090);  // no module's outputs start at QB 2
  EXPECT_EQ(w.write(0, 15, 2), 0x8222);  // MB 15..16 of a 16-octet M
  EXPECT_EQ(bytes(w.img.piq()), B(4, 0));
}

TEST(HProgramDpSfc, CallsRunFromTheirTimeAndInSpecOrder) {
  DpSfcCase c;
  // SFC 14 from 20 ms: IB 2..5 -> MB 10..13; SFC 15: MB 10..11 -> QB 0..1, every scan.
  c.spec.dprd_dat.push_back({20 * kMs, 2, 10, 4, 0u});
  c.spec.dpwr_dat.push_back({0, 0, 10, 2, std::nullopt});
  const Program p(c.spec, 8, 4);
  EXPECT_TRUE(p.scan(c.img, 10 * kMs).empty());  // SFC 14 not due: MB 10..11 are 0
  EXPECT_EQ(bytes(c.img.piq()), B(4, 0));
  EXPECT_EQ(c.ret_val(), 0x0000);
  EXPECT_TRUE(p.scan(c.img, 20 * kMs).empty());  // 14 then 15 in the same OB 1
  EXPECT_EQ(bytes(c.img.piq()), (B{0x11, 0x22, 0x00, 0x00}));
  EXPECT_EQ(bytes(c.img.memory().subspan(0, 2)), (B{0x00, 0x00}));  // RET_VAL 0000 stored
}

TEST(HProgramDpSfc, Sfc11ParameterCheck) {
  EXPECT_EQ(check_dpsyc_fr(0x01, 0x20), 0);       // SYNC to group 1
  EXPECT_EQ(check_dpsyc_fr(0x81, 0x0C), 0);       // FREEZE + UNFREEZE, groups 1 and 8
  EXPECT_EQ(check_dpsyc_fr(0x00, 0x20), 0x8094);  // no group
  EXPECT_EQ(check_dpsyc_fr(0x01, 0x00), 0x8095);  // no command
  EXPECT_EQ(check_dpsyc_fr(0x01, 0x22), 0x8095);  // Clear_Data is no SFC 11 command
}

}  // namespace
}  // namespace pbvbus::devices
