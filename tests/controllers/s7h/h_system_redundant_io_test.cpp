// Redundant two-channel I/O in the H-system model (HSystemModel::set_redundant_io; docs/
// h-redundant-io.md "In the H-system model"): the fixture of h_system_fixture.hpp (layout and
// timing in h_system_test.cpp). PII: station 5 IB 0..1, station 6 IB 2..3, one-sided slave 10
// (line A, CPU 0's side) IB 4..5, one-sided slave 11 (line B, CPU 1's side) IB 6..7. The pair
// here is the manual's one-sided layout (000 §6.4 L1860-1862: one module in each subsystem):
// module_L = slave 10 (IB 4, the lower address), module_H = slave 11 (IB 6). OB 1 every 10 ms;
// Redundant from t5 = 3.157 s, bring_up() runs to 3.457 s.
#include <gmock/gmock.h>

#include "h_system_fixture.hpp"

namespace pbvbus::devices {
namespace {

std::vector<HSystemModel::RedIoPair> di_pair_10_11() {
  HSystemModel::RedIoPair p;
  p.spec.kind = RedIoKind::DI;
  p.spec.discrepancy_time = 100 * kMs;
  p.a = {0, kOneB, 0};  // given in either order: module_L is the lower address (IB 4)
  p.b = {0, kOneA, 0};
  return {p};
}

std::vector<HSystemEvent> red_io_events(const HSys& s) {
  std::vector<HSystemEvent> out;
  for (const auto& e : s.h->events())
    if (e.source == Src::Program && (e.code & 0xFFF0) == 0x7960) out.push_back(e);
  return out;
}

TEST(HSystemRedundantIo, BadPairsAreRejectedWithPrefix) {
  HSys s;
  auto p = di_pair_10_11();
  p[0].b.module = 3;  // slave 10 has one module
  try {
    s.h->set_redundant_io(p);
    FAIL() << "no throw";
  } catch (const std::invalid_argument& e) {
    EXPECT_EQ(std::string(e.what()).rfind("redundant I/O: pair 0: no module 3", 0), 0u)
        << e.what();
  }
  p = di_pair_10_11();
  p[0].b = {0, kFast, 1};  // the 16DO module: no inputs
  EXPECT_THROW(s.h->set_redundant_io(p), std::invalid_argument);
  EXPECT_EQ(s.h->redundant_io(), nullptr);
  EXPECT_FALSE(s.h->red_depa());
}

// Slave 11 (module_H) stuck at 0 while slave 10 sets I 5.0 at 3.457 s: 7960 after the 100 ms
// discrepancy time, nobody passivated; slave 10 changes back at 3.7 s → module_H passivated
// (7961), both CPUs log it; from then the PII shows slave 10's inputs. FC 451 takes module_H
// back (7963) at the next OB 1.
TEST(HSystemRedundantIo, StuckOneSidedModuleIsPassivatedAndFc451TakesItBack) {
  HSys s;
  s.h->set_redundant_io(di_pair_10_11());
  ASSERT_NE(s.h->redundant_io(), nullptr);
  EXPECT_EQ(s.h->redundant_io()->spec(0).address_low, 4u);
  EXPECT_EQ(s.h->redundant_io()->spec(0).address_high, 6u);
  EXPECT_EQ(s.h->redundant_io()->spec(0).length, 2u);
  s.bring_up();
  EXPECT_TRUE(red_io_events(s).empty());
  const bus::Ticks t1 = s.sched.now();
  ASSERT_TRUE(s.one[0]->application().write_inputs(0, Bytes{0x00, 0x01}));
  s.run_until(t1 + 90 * kMs);
  EXPECT_EQ(s.h->pii()[5], 0x00);  // the last agreeing value during the discrepancy time
  EXPECT_TRUE(red_io_events(s).empty());
  s.run_until(t1 + 200 * kMs);
  auto ev = red_io_events(s);
  ASSERT_EQ(ev.size(), 1u);
  EXPECT_EQ(ev[0].code, 0x7960);
  // The difference reaches the PII within one DP cycle and one scan (< 30 ms) of t1; 7960 comes
  // 100 ms after the first OB 1 that saw it.
  EXPECT_GE(ev[0].time, t1 + 100 * kMs);
  EXPECT_LE(ev[0].time, t1 + 130 * kMs);
  EXPECT_EQ(ev[0].rack, -1);  // Redundant: the block runs on both CPUs
  EXPECT_FALSE(s.h->redundant_io()->passivated(0, RedModule::H));

  ASSERT_TRUE(s.one[0]->application().write_inputs(0, Bytes{0x00, 0x00}));
  s.run_until(t1 + 300 * kMs);
  ev = red_io_events(s);
  ASSERT_EQ(ev.size(), 2u);
  EXPECT_EQ(ev[1].code, 0x7961);
  EXPECT_EQ(ev[1].station, kOneB);
  EXPECT_EQ(ev[1].mdl_addr, 6u);
  EXPECT_THAT(ev[1].text, ::testing::HasSubstr("module_H (IB 6) passivated"));
  EXPECT_TRUE(s.h->redundant_io()->passivated(0, RedModule::H));
  for (int r = 0; r < 2; ++r) {
    const auto d = s.h->diag_buffer(r);
    EXPECT_TRUE(std::any_of(d.begin(), d.end(), [](const DiagEntry& x) { return x.code == 0x7961; }))
        << "rack " << r;
  }
  ASSERT_TRUE(s.one[0]->application().write_inputs(0, Bytes{0x12, 0x34}));
  s.run_until(t1 + 350 * kMs);
  EXPECT_EQ(s.h->pii()[4], 0x12);
  EXPECT_EQ(s.h->pii()[5], 0x34);

  ASSERT_TRUE(s.one[1]->application().write_inputs(0, Bytes{0x12, 0x34}));  // repaired
  s.run_until(t1 + 400 * kMs);
  ASSERT_TRUE(s.h->red_depa());
  s.run_until(t1 + 420 * kMs);
  ev = red_io_events(s);
  ASSERT_EQ(ev.size(), 3u);
  EXPECT_EQ(ev[2].code, 0x7963);
  EXPECT_FALSE(s.h->redundant_io()->passivated(0, RedModule::H));
  EXPECT_FALSE(s.h->red_depa());  // nothing passivated any more
}

// The standby STOPs: its one-sided slave 11 is no longer reached → OB 85 at the next OB 1 →
// RED_DIAG passivates module_H (7965). The standby back to RUN: link-up, update, Redundant; the
// OB 85 goes (38B1) and the depassivation requested on entering Redundant takes module_H back
// at the first OB 1 in Redundant (7963).
TEST(HSystemRedundantIo, StandbyStopPassivatesItsSideAndRedundantDepassivates) {
  HSys s;
  s.h->set_redundant_io(di_pair_10_11());
  s.bring_up();
  const int standby = 1 - s.h->pair().master();
  ASSERT_EQ(standby, 1);  // rack 1 (line B, slave 11) is the standby
  s.h->switch_to_stop(standby);
  s.run_until(s.sched.now() + 50 * kMs);
  auto ev = red_io_events(s);
  ASSERT_EQ(ev.size(), 1u);
  EXPECT_EQ(ev[0].code, 0x7965);
  EXPECT_EQ(ev[0].station, kOneB);
  EXPECT_TRUE(s.h->redundant_io()->passivated(0, RedModule::H));
  EXPECT_EQ(s.h->redundant_io()->pair(0).cause[1], RedIoCause::Ob85);
  s.h->switch_to_run(standby);
  s.run_until(s.sched.now() + 3000 * kMs);
  ASSERT_EQ(s.h->pair().system_mode(), SystemMode::Redundant);
  ev = red_io_events(s);
  ASSERT_EQ(ev.size(), 2u);
  EXPECT_EQ(ev[1].code, 0x7963);
  EXPECT_FALSE(s.h->redundant_io()->passivated(0, RedModule::H));
}

// A DO pair (the 16DO modules of stations 5 and 6, QB 0..1 and QB 2..3): RED_OUT drives both
// alike with what the program wrote at the lower address; what it wrote at QB 2..3 has no
// meaning (001 L5819-5822) and the PIQ keeps it.
TEST(HSystemRedundantIo, DoPairDrivenAlike) {
  HSys s;
  s.h->set_program(
      [](std::span<const std::uint8_t>, std::span<std::uint8_t> piq, bus::Ticks) {
        piq[0] = 0xA5;
        piq[1] = 0x5A;
        piq[2] = 0x11;
        piq[3] = 0x22;
      },
      kScan);
  HSystemModel::RedIoPair p;
  p.spec.kind = RedIoKind::DO;
  p.a = {0, kFast, 1};
  p.b = {0, kSlow, 1};
  s.h->set_redundant_io({p});
  s.bring_up();
  EXPECT_EQ(s.station(kFast).outputs()[0], 0xA5);
  EXPECT_EQ(s.station(kFast).outputs()[1], 0x5A);
  EXPECT_EQ(s.station(kSlow).outputs()[0], 0xA5);
  EXPECT_EQ(s.station(kSlow).outputs()[1], 0x5A);
  EXPECT_EQ(s.h->piq()[2], 0x11);
}

}  // namespace
}  // namespace pbvbus::devices
