// HSystemModel::ps_failure / ps_repair (F1 with a PS 407 10A R pair) and checksum_error
// (001 Table 5-6) on the DP master systems (docs/h-changes.md); fixture h_system_fixture.hpp:
// Redundant at kRedundant = 3.157 s, CPU 0 master.
#include "h_system_fixture.hpp"
#include "pbvbus/s7h/h_dp_startup.hpp"

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

// 001 L8094-8113: the master's DP master system starts with the CPU (kT0, STARTUP 1 s); the
// one-sided station 10 on line A is switched off, so it cannot be parameterised: with a
// monitoring time of 10 x 100 ms = 1 s the CPU enters W#16#6547 at kT0 + 1 s naming it;
// stations 5 and 6 reach data exchange in time. The start-up goes on (RUN at kT0 + 1 s).
TEST(HSystemPower, ParamTransferMonitoringW6547OnTheMastersStartUp) {
  HSys s;
  s.line[0].set_power(s.one_att[0], false);
  HDpStartupMonitor mon(
      [&](int r, bus::Ticks, std::string t, std::uint16_t c) { s.h->log_entry(r, std::move(t), c); },
      10, {kFast, kSlow, kOneA});
  s.at(kT0);
  s.h->power_on_both();
  mon.start(0, kT0);
  const bus::Ticks end = kT0 + 1000 * kMs;
  ASSERT_EQ(mon.next_deadline(), end);
  for (bus::Ticks t = kT0 + kMs; t < end; t += kMs) {  // 1 ms steps, virtual time
    s.run_until(t);
    for (std::uint8_t a : {kFast, kSlow, kOneA})
      if (s.sys->master(0).slave_state(a) == dp::SlaveStatusState::DataExchange)
        mon.data_exchange(a, t);
  }
  s.run_until(end);
  mon.on_time(end);
  EXPECT_EQ(mon.late(), (std::vector<std::uint8_t>{kOneA}));
  int n = 0;
  for (const auto& d : s.h->diag_buffer(0))
    if (d.code == 0x6547) {
      ++n;
      EXPECT_EQ(d.at, end);
      EXPECT_EQ(d.text, "transfer of parameters to modules: monitoring time exceeded, stations 10");
    }
  EXPECT_EQ(n, 1);
  EXPECT_EQ(s.h->pair().state(0), CpuState::Run);
}

}  // namespace
}  // namespace pbvbus::devices
