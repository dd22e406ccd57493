// F8 expansion racks of HSystemModel (h_expansion_rack.hpp; h_system.hpp block "F8 expansion
// racks, OB 80"; seeds-digest.md §7 F8 "IM 460/461: expansion rack off; OB 86 on both", §2
// one-sided I/O).
//
// Most tests use a model without DP master systems (only the pair and its racks), so every
// instant is the pair's: power_on_both at 0 -> STARTUP 1 s -> master (rack 0) RUN Solo at
// 1000 ms; standby LINK-UP 1000..3000 ms, UPDATE (W = 75 ms + 0.7 ms x 100 KB = 145 ms)
// 3000..3145 ms -> Redundant at 3145 ms. OB 1 every 10 ms from the first at 1000 ms: 1000,
// 1010, ..., 2990 (200 scans); the one due at 3000 (= t3) is dropped; OB 1 again at t5 = 3145,
// then 3155, 3165, ...
#include <gtest/gtest.h>

#include <stdexcept>
#include <string>
#include <vector>

#include "h_system_fixture.hpp"
#include "pbvbus/bus/scheduler.hpp"
#include "pbvbus/s7h/h_system.hpp"

namespace pbvbus::devices {
namespace {

using bus::Ticks;
constexpr Ticks ms(std::int64_t v) { return v * bus::kTicksPerMs; }

HRackModule module(std::string name, std::size_t in, std::size_t out,
                   IoBehaviour b = IoBehaviour::constant_value({})) {
  HRackModule m;
  m.name = std::move(name);
  m.in_len = in;
  m.out_len = out;
  m.inputs = std::move(b);
  return m;
}

/// Rack 3 on CPU 0: "DI16" (2 input octets, a counter of the rack's reads) and "DO16" (2
/// output octets). Rack 9 on CPU 1: "DIO8" (1 in = constant A5, 1 out).
/// Map: PII 0..1 = rack 3 DI16, PII 2 = rack 9 DIO8; PIQ 0..1 = rack 3 DO16, PIQ 2 = rack 9.
std::vector<HExpansionRack> two_racks() {
  HExpansionRack r3;
  r3.number = 3;
  r3.side = 0;
  r3.modules = {module("DI16", 2, 0, IoBehaviour::counter_per_cycle()), module("DO16", 0, 2)};
  HExpansionRack r9;
  r9.number = 9;
  r9.side = 1;
  r9.modules = {module("DIO8", 1, 1, IoBehaviour::constant_value({0xA5}))};
  return {r3, r9};
}

struct Pair {
  bus::Scheduler sched;
  std::unique_ptr<HSystemModel> h;
  std::uint16_t n = 0;  // OB 1 calls
  explicit Pair(std::vector<HExpansionRack> racks) {
    h = std::make_unique<HSystemModel>(sched, HCpuPairParams{},
                                       std::vector<RedundantMasterSystemModel*>{}, std::move(racks));
    // OB 1: the call count into PIQ 0..1 (rack 3's DO16), the inverted rack 9 input into PIQ 2.
    h->set_program(
        [this](std::span<const std::uint8_t> pii, std::span<std::uint8_t> piq, bus::Ticks) {
          ++n;
          piq[0] = static_cast<std::uint8_t>(n >> 8);
          piq[1] = static_cast<std::uint8_t>(n);
          piq[2] = static_cast<std::uint8_t>(pii[2] ^ 0xFF);
        },
        ms(10));
    h->power_on_both();
  }
  std::vector<HSystemEvent> events(HSystemEvent::Source s) const {
    std::vector<HSystemEvent> out;
    for (const auto& e : h->events())
      if (e.source == s) out.push_back(e);
    return out;
  }
  Bytes pii() const { return {h->pii().begin(), h->pii().end()}; }
};

Bytes bytes(std::span<const std::uint8_t> s) { return {s.begin(), s.end()}; }

TEST(HExpansionRack, BadConfigurationsThrowWithTheFirstProblem) {
  auto expect_throw = [](std::vector<HExpansionRack> racks, const std::string& msg) {
    bus::Scheduler sched;
    try {
      HSystemModel h(sched, HCpuPairParams{}, {}, std::move(racks));
      ADD_FAILURE() << "no throw, expected: " << msg;
    } catch (const std::invalid_argument& e) {
      EXPECT_EQ(std::string(e.what()), msg);
    }
    EXPECT_TRUE(sched.empty());  // thrown before anything was scheduled
  };
  auto racks = two_racks();
  racks[1].number = 22;
  expect_throw(racks, "expansion racks: expansion rack 22: number is not 1..21");
  racks = two_racks();
  racks[1].number = 3;
  expect_throw(racks, "expansion racks: expansion rack 3: number used twice");
  racks = two_racks();
  racks[0].side = 2;
  expect_throw(racks,
               "expansion racks: expansion rack 3: side 2 is not 0 or 1 (the central rack it hangs on)");
  racks = two_racks();
  racks[1].modules.clear();
  expect_throw(racks, "expansion racks: expansion rack 9: no modules");
  racks = two_racks();
  racks[0].modules[1].out_len = 0;
  expect_throw(racks, "expansion racks: expansion rack 3: module 1 \"DO16\": no inputs and no outputs");
  racks = two_racks();
  racks[0].modules[0].inputs = IoBehaviour::echo();  // DI16 has no outputs to echo
  expect_throw(racks,
               "expansion racks: expansion rack 3: module 0 \"DI16\": echo source module 0 has no outputs");
  racks = two_racks();
  racks[0].modules[0].inputs = IoBehaviour::echo(std::size_t{5});
  expect_throw(racks,
               "expansion racks: expansion rack 3: module 0 \"DI16\": echo source module 5 does not exist (2 modules)");

  // After the program spec: refused, the model unchanged.
  bus::Scheduler sched;
  HSystemModel h(sched, HCpuPairParams{}, {});
  ProgramSpec spec;
  spec.scan_time = ms(10);
  h.set_program(spec);
  EXPECT_THROW(h.set_expansion_racks(two_racks()), std::invalid_argument);
  EXPECT_TRUE(h.expansion_racks().empty());
  EXPECT_EQ(h.io_map().pii_size(), 0U);
}

TEST(HExpansionRack, MapAppendsCentralEntriesAfterTheDpModules) {
  HSys s;  // one redundant DP master system (h_system_fixture.hpp)
  const std::vector<HIoEntry> dp = s.h->io_map().entries();
  const std::size_t pii = s.h->io_map().pii_size(), piq = s.h->io_map().piq_size();
  ASSERT_FALSE(dp.empty());
  s.h->set_expansion_racks(two_racks());
  const auto& e = s.h->io_map().entries();
  ASSERT_EQ(e.size(), dp.size() + 3);
  for (std::size_t k = 0; k < dp.size(); ++k) EXPECT_EQ(e[k], dp[k]) << k;  // unchanged
  // Rack 3 module 0: PII pii..pii+1; module 1: PIQ piq..piq+1; rack 9: PII pii+2, PIQ piq+2.
  const HIoEntry* a = s.h->io_map().find_central(3, 0);
  const HIoEntry* b = s.h->io_map().find_central(3, 1);
  const HIoEntry* c = s.h->io_map().find_central(9, 0);
  ASSERT_TRUE(a && b && c);
  EXPECT_TRUE(a->central && b->central && c->central);
  EXPECT_EQ(a->system, -1);
  EXPECT_EQ(a->rack, 3);
  EXPECT_EQ(c->rack, 9);
  EXPECT_EQ(a->in_addr, pii);
  EXPECT_EQ(a->in_len, 2U);
  EXPECT_EQ(b->out_addr, piq);
  EXPECT_EQ(b->out_len, 2U);
  EXPECT_EQ(c->in_addr, pii + 2);
  EXPECT_EQ(c->out_addr, piq + 2);
  EXPECT_EQ(s.h->io_map().pii_size(), pii + 3);
  EXPECT_EQ(s.h->io_map().piq_size(), piq + 3);
  EXPECT_EQ(s.h->pii().size(), pii + 3);
  EXPECT_EQ(s.h->piq().size(), piq + 3);
  // A DP find() does not return a central entry.
  EXPECT_EQ(s.h->io_map().find(-1, 0, 0), nullptr);
  // Once an OB 1 ran the images are fixed.
  s.bring_up();
  EXPECT_THROW(s.h->set_expansion_racks({}), std::invalid_argument);
}

TEST(HExpansionRack, InputsOutputsOb86Ob85AndTheStandbysRack) {
  Pair p(two_racks());

  // Solo: rack 9's CPU has not run the program yet (idle: no OB 85, input 0).
  p.sched.run_until(ms(2995));
  EXPECT_TRUE(p.events(Src::Image).empty());
  EXPECT_FALSE(p.h->expansion_rack_reachable(9));
  EXPECT_TRUE(p.h->expansion_rack_reachable(3));
  // 200 reads (1000..2990 ms): the counter showed 0..199; the last = 199 = 0x00C7.
  EXPECT_EQ(p.pii(), (Bytes{0x00, 0xC7, 0x00}));
  EXPECT_EQ(bytes(p.h->rack_outputs(3, 1)), (Bytes{0x00, 0xC8}));  // n = 200
  EXPECT_EQ(bytes(p.h->rack_outputs(9, 0)), (Bytes{0x00}));        // never reached

  // Redundant from 3145: rack 9 read (A5; shared PII: the partner's one-sided input).
  p.sched.run_until(ms(3150));
  ASSERT_EQ(p.h->pair().system_mode(), SystemMode::Redundant);
  EXPECT_EQ(p.pii(), (Bytes{0x00, 0xC8, 0xA5}));  // read 201 shows 200
  EXPECT_EQ(bytes(p.h->rack_inputs(9, 0)), (Bytes{0xA5}));
  EXPECT_EQ(bytes(p.h->rack_outputs(9, 0)), (Bytes{0x5A}));
  EXPECT_EQ(bytes(p.h->rack_outputs(3, 1)), (Bytes{0x00, 0xC9}));  // n = 201

  // F8: rack 3 off at 3203 ms (after the OB 1 at 3195: reads 3145..3195 = 6 more, last = 205).
  p.sched.run_until(ms(3203));
  EXPECT_TRUE(p.h->expansion_rack_off(3));
  EXPECT_FALSE(p.h->expansion_rack_off(3));  // off already
  EXPECT_FALSE(p.h->expansion_rack_off(4));  // no such rack
  {
    const auto io = p.events(Src::Io);
    ASSERT_EQ(io.size(), 1U);
    EXPECT_EQ(io[0].time, ms(3203));
    EXPECT_EQ(io[0].ob, 86);
    EXPECT_EQ(io[0].code, 0x39C1);
    EXPECT_EQ(io[0].rack, -1);  // Redundant: OB 86 on both
    EXPECT_EQ(io[0].station, 3);
    EXPECT_EQ(io[0].line, 0);
    EXPECT_TRUE(io[0].incoming);
    for (int r = 0; r < 2; ++r) {
      const auto d = p.h->diag_buffer(r);
      ASSERT_FALSE(d.empty());
      EXPECT_EQ(d.back().at, ms(3203));
      EXPECT_EQ(d.back().code, 0x39C1);
      EXPECT_EQ(d.back().text, "OB 86 W#16#39C1 expansion rack failure, expansion rack 3 (IM 460 of CPU 0)");
    }
  }
  // Next OB 1 at 3205: OB 85 incoming; rack 3's input frozen at 205 = 0x00CD, its outputs at
  // n = 206 (the OB 1 at 3195) although OB 1 goes on (n = 207 .. 216 at 3205 .. 3295).
  p.sched.run_until(ms(3300));
  EXPECT_EQ(p.pii(), (Bytes{0x00, 0xCD, 0xA5}));
  EXPECT_EQ(bytes(p.h->rack_outputs(3, 1)), (Bytes{0x00, 0xCE}));
  EXPECT_EQ(p.n, 216);
  EXPECT_TRUE(p.h->expansion_rack_ob85(3));
  EXPECT_EQ(p.h->pair().state(0), CpuState::Run);  // no CPU changes state
  EXPECT_EQ(p.h->pair().state(1), CpuState::Run);
  EXPECT_EQ(p.h->pair().system_mode(), SystemMode::Redundant);

  // Repair at 3302: OB 86 38C1 on both; OB 1 at 3305: OB 85 outgoing, read 207 shows 206.
  p.sched.run_until(ms(3302));
  EXPECT_TRUE(p.h->expansion_rack_on(3));
  EXPECT_FALSE(p.h->expansion_rack_on(3));
  p.sched.run_until(ms(3306));
  EXPECT_EQ(p.pii(), (Bytes{0x00, 0xCE, 0xA5}));
  EXPECT_EQ(bytes(p.h->rack_outputs(3, 1)), (Bytes{0x00, 0xD9}));  // n = 217
  EXPECT_FALSE(p.h->expansion_rack_ob85(3));

  // CPU 1 (rack 9's) fails at 3402: Solo; OB 1 at 3405 on CPU 0 alone: OB 85 for rack 9, whose
  // input keeps A5. Rack 9 off while its CPU is off: nobody sees it (no event, no entry).
  p.sched.run_until(ms(3402));
  p.h->power_off(1);
  p.sched.run_until(ms(3406));
  EXPECT_EQ(p.pii()[2], 0xA5);
  const std::size_t diag0 = p.h->diag_buffer(0).size();
  p.sched.run_until(ms(3452));
  EXPECT_TRUE(p.h->expansion_rack_off(9));
  EXPECT_FALSE(p.h->expansion_rack_is_on(9));
  EXPECT_EQ(p.h->diag_buffer(0).size(), diag0);

  const auto io = p.events(Src::Io);
  ASSERT_EQ(io.size(), 2U);
  EXPECT_EQ(io[1].time, ms(3302));
  EXPECT_EQ(io[1].code, 0x38C1);
  EXPECT_EQ(io[1].rack, -1);
  EXPECT_FALSE(io[1].incoming);
  const auto img = p.events(Src::Image);
  ASSERT_EQ(img.size(), 3U);
  EXPECT_EQ(img[0].time, ms(3205));
  EXPECT_EQ(img[0].ob, 85);
  EXPECT_EQ(img[0].code, 0x39B1);
  EXPECT_EQ(img[0].rack, -1);
  EXPECT_EQ(img[0].station, 3);
  EXPECT_EQ(img[0].text, "OB 85 W#16#39B1 process-image transfer error incoming, expansion rack 3");
  EXPECT_EQ(img[1].time, ms(3305));
  EXPECT_EQ(img[1].code, 0x38B1);
  EXPECT_EQ(img[1].rack, -1);
  EXPECT_EQ(img[2].time, ms(3405));
  EXPECT_EQ(img[2].code, 0x39B1);
  EXPECT_EQ(img[2].rack, 0);  // Solo: the master alone
  EXPECT_EQ(img[2].station, 9);
}

TEST(HExpansionRack, SoloRackFailureOnTheMasterAndEchoInputs) {
  // Rack 5 on CPU 0: "DIO8" echoes its own outputs (the PIQ of the OB 1 before).
  HExpansionRack r5;
  r5.number = 5;
  r5.side = 0;
  r5.modules = {module("DIO8", 1, 1, IoBehaviour::echo())};
  bus::Scheduler sched;
  HSystemModel h(sched, HCpuPairParams{}, {}, {r5});
  // OB 1: PIQ 0 = PII 0 + 1: each OB 1 sees the last one's output (echo), so OB 1 number k
  // (k = 1 at 1000 ms) writes k.
  h.set_program([](std::span<const std::uint8_t> pii, std::span<std::uint8_t> piq,
                   bus::Ticks) { piq[0] = static_cast<std::uint8_t>(pii[0] + 1); },
                ms(10));
  h.power_on(0);  // rack 1 stays off: Solo from 1000 ms
  sched.run_until(ms(1045));  // OB 1 at 1000, 1010, 1020, 1030, 1040: k = 5
  EXPECT_EQ(bytes(h.rack_outputs(5, 0)), (Bytes{5}));
  EXPECT_EQ(bytes(h.rack_inputs(5, 0)), (Bytes{4}));
  EXPECT_TRUE(h.expansion_rack_off(5));
  sched.run_until(ms(1100));
  const auto& ev = h.events();
  ASSERT_EQ(ev.size(), 2U);
  EXPECT_EQ(ev[0].time, ms(1045));
  EXPECT_EQ(ev[0].ob, 86);
  EXPECT_EQ(ev[0].code, 0x39C1);
  EXPECT_EQ(ev[0].rack, 0);  // Solo: on the master
  EXPECT_EQ(ev[0].role, CpuRole::Master);
  EXPECT_EQ(ev[1].time, ms(1050));
  EXPECT_EQ(ev[1].code, 0x39B1);
  // Frozen: the input stays 4 (the OB 1s from 1050 on write 5 again and again), the module's
  // output stays 5.
  EXPECT_EQ(h.pii()[0], 4);
  EXPECT_EQ(bytes(h.rack_outputs(5, 0)), (Bytes{5}));
  EXPECT_EQ(h.piq()[0], 5);
  EXPECT_EQ(h.diag_buffer(1).size(), 0U);  // CPU 1 off: no entry there
}

}  // namespace
}  // namespace pbvbus::devices

namespace pbvbus::devices {
namespace {

// OB 122 for a direct access to a central module (digest D1 applied to an expansion rack): a
// copy network with `direct` from PIB 2 (rack 9's DIO8, CPU 1's side) to PQB 0 (rack 3's DO16).
// In Solo (1000 .. 2990 ms, CPU 1 in LINK-UP) rack 9 is not reachable: every OB 1 raises one
// OB 122 W#16#2942 (read) on CPU 0 alone and copies 0; the write goes to rack 3, which is there
// (no 2943). From Redundant (3145 ms) rack 9 answers: A5 lands in rack 3's DO16, no OB 122.
TEST(HExpansionRack, DirectAccessToAnUnreachableRackIsOb122) {
  Pair p(two_racks());
  ProgramSpec spec;
  spec.copies.push_back(CopyNetwork{2, 0, 1, true});
  p.h->set_program(spec);
  p.sched.run_until(ms(2995));
  auto ob122 = [&] {
    std::vector<HSystemEvent> out;
    for (const auto& e : p.h->events())
      if (e.ob == 122) out.push_back(e);
    return out;
  };
  const auto solo = ob122();
  ASSERT_EQ(solo.size(), 200U);  // OB 1 at 1000, 1010, ..., 2990 ms
  EXPECT_EQ(solo[0].time, ms(1000));
  EXPECT_EQ(solo[199].time, ms(2990));
  EXPECT_EQ(solo[0].code, 0x2942);
  EXPECT_EQ(solo[0].rack, 0);
  EXPECT_EQ(solo[0].system, -1);
  EXPECT_EQ(solo[0].station, 9);
  EXPECT_EQ(solo[0].mdl_addr, 2);
  EXPECT_EQ(solo[0].text,
            "OB 122 W#16#2942 I/O access error reading, copy 0, PIB 2, expansion rack 9, module 0");
  EXPECT_EQ(bytes(p.h->rack_outputs(3, 1)), (Bytes{0x00, 0x00}));
  p.sched.run_until(ms(3300));
  EXPECT_EQ(ob122().size(), 200U);
  EXPECT_EQ(bytes(p.h->rack_outputs(3, 1)), (Bytes{0xA5, 0x00}));
  EXPECT_EQ(p.h->access_errors(), 200U);
}

}  // namespace
}  // namespace pbvbus::devices
