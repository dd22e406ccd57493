// HSystemModel running the real program (set_program(ProgramSpec), RedundantExecution): the
// fixture of h_system_fixture.hpp (h_system_test.cpp has its layout and timing). Timing used
// here: power_on_both at 12 ms, Solo at 1.012 s, UPDATE at 3.012 s, Redundant at t5 = 3.157 s
// (W = 75 ms + 0.7 ms x 100 KB = 145 ms). OB 1 every 10 ms from 1.012 s; the scan at 3.012 s
// falls into the no-I/O window [3.012, 3.157) and is not run; OB 1 restarts at t5 = 3.157 s and
// lies on 3.157 + k x 10 ms after it.
#include <gmock/gmock.h>

#include "h_system_fixture.hpp"

namespace pbvbus::devices {
namespace {

using ::testing::HasSubstr;

// Two counters into the switched stations' outputs (QB 0..1 station 5, QB 2..3 station 6),
// +1 every 10 ms: the Sampler's "never 0, never older" holds for them.
ProgramSpec counters_spec() {
  ProgramSpec p;
  p.scan_time = kScan;
  p.counters.push_back({0, 2, 10 * kMs, 1, 0, 0, 0});
  p.counters.push_back({2, 2, 10 * kMs, 1, 0, 0, 0});
  return p;
}

TEST(HSystemProgram, BadSpecThrowsWithPrefixAndNoExecution) {
  HSys s;
  ProgramSpec p;
  p.copies.push_back({0, 0, 9});  // PII is 8 octets
  try {
    s.h->set_program(p);
    FAIL() << "no throw";
  } catch (const std::invalid_argument& e) {
    EXPECT_EQ(std::string(e.what()).rfind("program: copy 0", 0), 0u) << e.what();
  }
  EXPECT_EQ(s.h->execution(), nullptr);
  EXPECT_FALSE(s.h->inject_divergence(0, Area::Piq, 0, 1));
}

// A copy network from IB 4..5 (one-sided slave 10 on line A) to QB 0..1 (station 5).
TEST(HSystemProgram, CopyThroughTheMapBothCpusRunInRedundant) {
  HSys s;
  ProgramSpec p;
  p.scan_time = kScan;
  p.copies.push_back({4, 0, 2});
  s.h->set_program(p);
  ASSERT_NE(s.h->execution(), nullptr);
  ASSERT_TRUE(s.one[0]->application().write_inputs(0, Bytes{0xA5, 0x3C}));
  s.bring_up();  // until 3.457 s
  EXPECT_EQ(s.station(kFast).outputs()[0], 0xA5);
  EXPECT_EQ(s.station(kFast).outputs()[1], 0x3C);
  // Rack 0 alone from 1.012 s: scans at 1.012 + k x 10 ms up to 3.002 s = 200 scans; both from
  // 3.157 s: 3.157 .. 3.457 s inclusive = 31 scans on each CPU.
  EXPECT_EQ(s.h->execution()->scans(0), 231u);
  EXPECT_EQ(s.h->execution()->scans(1), 31u);
  EXPECT_EQ(s.h->scans(), 231u);
  EXPECT_EQ(s.h->execution()->image(0), s.h->execution()->image(1));
}

// F6 with the real program: both fibres cut at 4.0 s -> two masters, each CPU runs alone and
// drives its own side. Counter 0 -> QB 4..5 (one-sided slave 10, line A), counter 1 -> QB 6..7
// (slave 11, line B). At 4.5 s a bit of rack 1's counter 1 is flipped (memory offset 16 + 10 =
// 26, the high octet of the low word of its 32-bit value: +/- 0x8000); no comparison runs any
// more, so the two CPUs' counters 1 differ by 0x8000 from then on. Line B's slave shows rack 1's
// value, line A's slave rack 0's: each CPU's PIQ goes to its own line only.
TEST(HSystemProgram, TwoMastersEachDrivesItsOwnLine) {
  HSys s;
  ProgramSpec p;
  p.scan_time = kScan;
  p.counters.push_back({4, 2, 10 * kMs, 1, 0, 0, 0});
  p.counters.push_back({6, 2, 10 * kMs, 1, 0, 0, 0});
  s.h->set_program(p);
  s.bring_up();
  s.at(4000 * kMs);
  s.h->cut_both_fibres();
  ASSERT_EQ(s.h->pair().master_count(), 2);
  s.at(4500 * kMs);
  ASSERT_TRUE(s.h->inject_divergence(1, Area::Memory, 26, 0x80));
  // Scans lie on 3.157 + k x 10 ms: the last before 5.005 s is at 4.997 s; one DP cycle of
  // these lines (four slaves at 1.5 Mbit/s) is well below the 8 ms left until 5.005 s.
  s.at(5005 * kMs);
  auto word = [](std::span<const std::uint8_t> b, std::size_t at) {
    return static_cast<std::uint16_t>((b[at] << 8) | b[at + 1]);
  };
  const auto q0 = s.h->execution()->image(0).piq();
  const auto q1 = s.h->execution()->image(1).piq();
  EXPECT_EQ(word(q0, 6) ^ word(q1, 6), 0x8000);  // the CPUs diverged (no comparison)
  EXPECT_EQ(word(q0, 4), word(q1, 4));            // counter 0 untouched
  EXPECT_EQ(s.one_outputs(0), word(q0, 4));       // line A: rack 0's outputs
  EXPECT_EQ(s.one_outputs(1), word(q1, 6));       // line B: rack 1's outputs, not rack 0's
  EXPECT_NE(s.one_outputs(1), word(q0, 6));
}

// F16 found by the comparison: a bit of the standby's memory flipped at 3.460 s (counter 0's
// flags byte, memory offset 12: 01 -> 03, it never reaches the PIQ) is found by the comparison
// after the next Redundant scan at 3.467 s: standby ERROR-SEARCH, OB 72 on the master, Solo.
TEST(HSystemProgram, F16DivergenceFoundByTheComparison) {
  HSys s;
  Sampler smp(s);
  s.h->set_program(counters_spec());
  s.bring_up();
  s.run_until(kRedundant + 303 * kMs);  // 3.460 s
  ASSERT_TRUE(s.h->inject_divergence(1, Area::Memory, 12, 0x02));
  s.run_until(kRedundant + 309 * kMs);  // 3.466 s: no scan yet
  EXPECT_EQ(s.h->pair().state(1), CpuState::Run);
  s.run_until(kRedundant + 310 * kMs);  // 3.467 s
  EXPECT_EQ(s.h->pair().state(1), CpuState::ErrorSearch);
  EXPECT_EQ(s.h->pair().system_mode(), SystemMode::Solo);
  const auto cpu = s.events(Src::Cpu);
  ASSERT_EQ(cpu.size(), 1u);
  EXPECT_EQ(cpu[0].ob, 72);
  EXPECT_EQ(cpu[0].rack, 0);
  EXPECT_EQ(cpu[0].time, kRedundant + 310 * kMs);
  EXPECT_THAT(cpu[0].text, HasSubstr("memory offset 12: 01 (rack 0) / 03 (rack 1)"));
  s.run_until(kRedundant + 1000 * kMs);
  smp.expect_no_pulse(0);
}

// A discrepancy monitor over IB 4 (slave 10, line A) and IB 0 (station 5): IB 4 set to 01 at
// 3.460 s reaches the PII by the scan at 3.467 s (the DP cycle of line A is a few ms), the
// episode starts there; 100 ms later, at the scan at 3.567 s, error 7960 incoming on both CPUs
// (rack -1); IB 4 back to 00 at 3.600 s -> outgoing at the scan at 3.607 s.
TEST(HSystemProgram, DiscrepancyMonitor7960IncomingOutgoing) {
  HSys s;
  ProgramSpec p = counters_spec();
  p.monitors.push_back({4, 0, 1, 0xFF, 4, 100 * kMs});
  s.h->set_program(p);
  s.bring_up();
  s.run_until(kRedundant + 303 * kMs);
  ASSERT_TRUE(s.one[0]->application().write_inputs(0, Bytes{0x01, 0x00}));
  s.run_until(kRedundant + 443 * kMs);  // 3.600 s
  ASSERT_TRUE(s.one[0]->application().write_inputs(0, Bytes{0x00, 0x00}));
  s.run_until(kRedundant + 600 * kMs);
  const auto ev = s.events(Src::Program);
  ASSERT_EQ(ev.size(), 2u);
  EXPECT_EQ(ev[0].code, 0x7960);
  EXPECT_TRUE(ev[0].incoming);
  EXPECT_EQ(ev[0].time, kRedundant + 410 * kMs);  // 3.567 = 3.467 + 0.100
  EXPECT_EQ(ev[0].rack, -1);
  EXPECT_EQ(ev[1].code, 0x7960);
  EXPECT_FALSE(ev[1].incoming);
  EXPECT_EQ(ev[1].time, kRedundant + 450 * kMs);  // 3.607
  EXPECT_EQ(s.h->pair().system_mode(), SystemMode::Redundant);
}

// F18: the same monitor (discrepancy time 1 s), IB 4 set at 3.360 s: the episode starts at the
// scan at 3.367 s on both CPUs. At 3.460 s the standby's "difference first seen" time loses bit
// 33 (2^33 ticks = 2.362 s earlier), so at the next scan (3.467 s) the standby finds the discrepancy time expired and raises 7960, the master does not: the CPUs
// took different paths -> sync error: standby STOP, Solo, OB 72 on the master, "sync error" in
// both diagnostic buffers. No 7960 reported (the master's run raised none).
TEST(HSystemProgram, F18SyncErrorStandbyStop) {
  HSys s;
  Sampler smp(s);
  ProgramSpec p = counters_spec();
  p.monitors.push_back({4, 0, 1, 0xFF, 4, 1000 * kMs});
  s.h->set_program(p);
  s.at(kT0);
  s.h->power_on_both();
  s.run_until(kRedundant + 203 * kMs);  // 3.360 s
  ASSERT_TRUE(s.one[0]->application().write_inputs(0, Bytes{0x01, 0x00}));
  s.run_until(kRedundant + 303 * kMs);  // 3.460 s: episode running since 3.367 s
  const std::size_t mon = s.h->execution()->program().monitor_state_offset(0);
  // since = 3.367 s = 12 242 412 000 ticks = 0x2_D9B4_6860: bit 33 (byte 3, bit 1) set.
  ASSERT_EQ(s.h->execution()->image(1).memory()[mon + 3] & 0x02, 0x02);
  ASSERT_TRUE(s.h->inject_divergence(1, Area::Memory, static_cast<std::uint32_t>(mon + 3), 0x02));
  s.run_until(kRedundant + 310 * kMs);  // 3.467 s
  EXPECT_EQ(s.h->pair().state(1), CpuState::Stop);
  EXPECT_EQ(s.h->pair().state(0), CpuState::Run);
  EXPECT_EQ(s.h->pair().system_mode(), SystemMode::Solo);
  const auto cpu = s.events(Src::Cpu);
  ASSERT_EQ(cpu.size(), 1u);
  EXPECT_EQ(cpu[0].ob, 72);
  EXPECT_EQ(cpu[0].time, kRedundant + 310 * kMs);
  EXPECT_TRUE(s.events(Src::Program).empty());
  for (int r = 0; r < 2; ++r) {
    const auto d = s.h->diag_buffer(r);
    EXPECT_TRUE(std::any_of(d.begin(), d.end(), [](const DiagEntry& e) {
      return e.text.rfind("sync error", 0) == 0;
    })) << r;
  }
  s.run_until(kRedundant + 1000 * kMs);
  smp.expect_no_pulse(0);
}

// OB 85: slave 10 (one-sided, line A) loses power at 4 s in Redundant mode; the master system
// reports its failure (OB 86 W#16#39C4) at some frame time E; the first OB 1 at or after E
// (OB 1 on 3.157 + k x 10 ms) finds no active image: OB 85 W#16#39B1 incoming on both CPUs,
// once; power back at 5 s: at the first OB 1 after the return (38C4) OB 85 W#16#38B1 outgoing.
TEST(HSystemProgram, Ob85OncePerEpisode) {
  HSys s;
  s.h->set_program(counters_spec());
  s.bring_up();
  s.at(4000 * kMs);
  s.line[0].set_power(s.one_att[0], false);
  s.run_until(5000 * kMs);
  s.line[0].set_power(s.one_att[0], true);
  s.run_until(7000 * kMs);
  std::vector<bus::Ticks> fail, back;
  for (const auto& e : s.s7()) {
    if (e.station != kOneA) continue;
    (e.code() == 0x39C4 ? fail : back).push_back(e.time);
  }
  ASSERT_EQ(fail.size(), 1u);
  ASSERT_EQ(back.size(), 1u);
  auto next_scan = [](bus::Ticks t) {  // first 3.157 s + k x 10 ms at or after t
    const bus::Ticks k = (t - kRedundant + kScan - 1) / kScan;
    return kRedundant + k * kScan;
  };
  const auto ob85 = s.events(Src::Image);
  ASSERT_EQ(ob85.size(), 2u);
  EXPECT_EQ(ob85[0].ob, 85);
  EXPECT_EQ(ob85[0].code, 0x39B1);
  EXPECT_TRUE(ob85[0].incoming);
  EXPECT_EQ(ob85[0].station, kOneA);
  EXPECT_EQ(ob85[0].rack, -1);
  EXPECT_EQ(ob85[0].time, next_scan(fail[0]));
  EXPECT_EQ(ob85[1].code, 0x38B1);
  EXPECT_FALSE(ob85[1].incoming);
  EXPECT_EQ(ob85[1].time, next_scan(back[0]));
}


// C1 (001 §4.10.4 L3344-3365): SFC 14/15 in the H-system's program over the redundant master
// system's modules (h_dp_sfc.hpp). Slave 10 (line A, 16DI/16DO) has its inputs at IB 4..5,
// station 5's 16DO lies at QB 0..1 (the fixture's map). SFC 14 reads IB 4..5 into MB 100..101
// (RET_VAL MW 98), SFC 15 writes MB 100..101 to QB 0..1 (RET_VAL MW 96): the station shows the
// slave's two input octets, in one piece. A RECORD of 1 octet for the 2-octet modules: W#16#80B1
// for both, nothing moves; an LADDR inside a module (IB 5): W#16#8090.
TEST(HSystemProgram, C1_Sfc14And15MoveTheModulesDataWithTheConfiguredLength) {
  auto word = [](std::span<const std::uint8_t> b, std::size_t at) {
    return static_cast<std::uint16_t>((b[at] << 8) | b[at + 1]);
  };
  {
    HSys s;
    ProgramSpec p;
    p.scan_time = kScan;
    p.dprd_dat.push_back({0, 4, 100, 2, 98u});
    p.dpwr_dat.push_back({0, 0, 100, 2, 96u});
    s.h->set_s7_memory(HS7MemoryConfig{});  // M: 256 octets, as a scenario's cpu part has
    s.h->set_program(p);
    ASSERT_TRUE(s.one[0]->application().write_inputs(0, Bytes{0xA5, 0x3C}));
    s.bring_up();
    ASSERT_NE(s.h->execution(), nullptr);
    const auto m0 = s.h->execution()->image(0).memory();
    ASSERT_GE(m0.size(), 256u);  // M: 256 octets (HS7MemoryConfig)
    EXPECT_EQ(word(m0, 98), 0x0000);
    EXPECT_EQ(word(m0, 96), 0x0000);
    EXPECT_EQ(word(m0, 100), 0xA53C);
    EXPECT_EQ(s.station(kFast).outputs()[0], 0xA5);
    EXPECT_EQ(s.station(kFast).outputs()[1], 0x3C);
    EXPECT_EQ(s.h->execution()->image(0), s.h->execution()->image(1));  // both CPUs alike
    EXPECT_EQ(s.h->pair().system_mode(), SystemMode::Redundant);
  }
  {
    HSys s;
    ProgramSpec p;
    p.scan_time = kScan;
    p.dprd_dat.push_back({0, 4, 100, 1, 98u});
    p.dpwr_dat.push_back({0, 0, 100, 1, 96u});
    p.dprd_dat.push_back({0, 5, 110, 1, 94u});
    s.h->set_s7_memory(HS7MemoryConfig{});  // M: 256 octets, as a scenario's cpu part has
    s.h->set_program(p);
    ASSERT_TRUE(s.one[0]->application().write_inputs(0, Bytes{0xA5, 0x3C}));
    s.bring_up();
    ASSERT_NE(s.h->execution(), nullptr);
    const auto m0 = s.h->execution()->image(0).memory();
    ASSERT_GE(m0.size(), 256u);  // M: 256 octets (HS7MemoryConfig)
    EXPECT_EQ(word(m0, 98), 0x80B1);
    EXPECT_EQ(word(m0, 96), 0x80B1);
    EXPECT_EQ(word(m0, 94), 0x8090);
    EXPECT_EQ(word(m0, 100), 0x0000);
    EXPECT_EQ(s.station(kFast).outputs()[0], 0x00);
    EXPECT_EQ(s.station(kFast).outputs()[1], 0x00);
  }
}

}  // namespace
}  // namespace pbvbus::devices
