// HSystemModel::ps_failure / ps_repair (F1 with a PS 407 10A R pair) and checksum_error
// (001 Table 5-6) on the DP master systems (docs/h-changes.md); fixture h_system_fixture.hpp:
// Redundant at kRedundant = 3.157 s, CPU 0 master.
#include "h_system_fixture.hpp"

namespace pbvbus::devices {
namespace {

int count_code(const std::vector<DiagEntry>& d, std::uint16_t code) {
  return static_cast<int>(std::count_if(d.begin(), d.end(), [&](const DiagEntry& e) { return e.code == code; }));
}

TEST(HSystemPower, F1HalfPsNoEffectBothHalvesMasterSystemFailure) {
  HSys s;
  Sampler smp(s);
  s.bring_up();
  const bus::Ticks t1 = 4000 * kMs;
  s.at(t1);
  EXPECT_FALSE(s.h->ps_failure(0, 1));
  EXPECT_TRUE(s.h->events().empty());  // no OB 72, no 39C3
  EXPECT_EQ(s.h->pair().system_mode(), SystemMode::Redundant);
  EXPECT_EQ(count_code(s.h->diag_buffer(0), 0x3923), 1);
  EXPECT_EQ(count_code(s.h->diag_buffer(1), 0x3923), 0);
  EXPECT_FALSE(s.h->ps_failure(0, 1));  // already failed
  const bus::Ticks t2 = 5000 * kMs;
  s.at(t2);
  EXPECT_TRUE(s.h->ps_failure(0, 0));  // the second half: as cpu_failure (F1)
  EXPECT_EQ(s.h->pair().state(0), CpuState::Off);
  EXPECT_EQ(s.h->pair().master(), 1);
  auto ev = s.h->events();
  ASSERT_EQ(ev.size(), 2u);
  EXPECT_EQ(ev[0].ob, 72);
  EXPECT_EQ(ev[0].time, t2);
  EXPECT_EQ(ev[1].code, 0x39C3);
  // One half back: power returns, CPU 0 links up as standby (2 s + 145 ms), Redundant.
  const bus::Ticks t3 = 6000 * kMs;
  s.at(t3);
  EXPECT_TRUE(s.h->ps_repair(0, 0));
  s.run_until(t3 + 2145 * kMs);
  EXPECT_EQ(s.h->pair().system_mode(), SystemMode::Redundant);
  EXPECT_EQ(s.h->pair().master(), 1);
  EXPECT_TRUE(s.h->ps_repair(0, 1));  // the other half replaced: the outgoing entry
  EXPECT_EQ(count_code(s.h->diag_buffer(0), 0x3823), 1);
  EXPECT_FALSE(s.h->ps_repair(0, 1));
  smp.expect_no_pulse(t1);
}

TEST(HSystemPower, ChecksumErrorInRedundantStandbyToErrorSearch) {
  HSys s;
  s.bring_up();
  const bus::Ticks t = 4000 * kMs;
  s.at(t);
  EXPECT_TRUE(s.h->checksum_error(1));
  EXPECT_EQ(s.h->pair().state(1), CpuState::ErrorSearch);
  EXPECT_EQ(s.h->pair().system_mode(), SystemMode::Solo);
  const auto& ev = s.h->events();
  ASSERT_FALSE(ev.empty());
  EXPECT_EQ(ev[0].ob, 72);
  EXPECT_EQ(ev[0].rack, 0);
  EXPECT_EQ(ev[0].time, t);
  EXPECT_EQ(s.h->side_mode(0, 1), Mode::Stop);  // ERROR-SEARCH: its DP master stops
  EXPECT_FALSE(s.h->checksum_error(2));
}

}  // namespace
}  // namespace pbvbus::devices
