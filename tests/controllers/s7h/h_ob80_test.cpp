// OB 80 (time error, W#16#3501 cycle time exceeded) of HSystemModel: the maximum cycle time,
// the cycle_overload fault and the update's no-I/O window within the max scan-cycle extension
// (h_system.hpp block "F8 expansion racks, OB 80"; seeds-digest.md §3.1, §6).
//
// A model without DP master systems, times as in h_expansion_rack_test.cpp: power_on_both at 0
// -> master (rack 0) RUN Solo at 1000 ms; standby LINK-UP 1000..3000 ms, UPDATE 3000..3145 ms
// (W = 145 ms) -> Redundant at 3145 ms. OB 1 every 10 ms from 1000 ms (start to start).
#include <gtest/gtest.h>

#include <stdexcept>
#include <vector>

#include "pbvbus/bus/scheduler.hpp"
#include "pbvbus/s7h/h_system.hpp"

namespace pbvbus::devices {
namespace {

using bus::Ticks;
constexpr Ticks ms(std::int64_t v) { return v * bus::kTicksPerMs; }

struct Pair {
  bus::Scheduler sched;
  HSystemModel h;
  explicit Pair(HCpuPairParams p = {}) : h(sched, std::move(p), {}) {
    h.set_program([](std::span<const std::uint8_t>, std::span<std::uint8_t>, bus::Ticks) {},
                  ms(10));
    h.power_on_both();
  }
  std::vector<HSystemEvent> ob80() const {
    std::vector<HSystemEvent> out;
    for (const auto& e : h.events())
      if (e.ob == 80) out.push_back(e);
    return out;
  }
};

TEST(HOb80, OverloadInSoloOncePerOverrunCycle) {
  Pair p;
  EXPECT_EQ(p.h.max_cycle_time(), ms(150));  // the S7 default
  EXPECT_THROW(p.h.set_max_cycle_time(0), std::invalid_argument);
  EXPECT_FALSE(p.h.cycle_overload(0));
  // Overload 200 ms at 1503: the OB 1 at 1510 lasts 10 + 200 = 210 ms -> next OB 1 at 1720.
  // The monitoring expires at 1510 + 150 = 1660: OB 80 on the master alone (Solo).
  p.sched.run_until(ms(1503));
  EXPECT_TRUE(p.h.cycle_overload(ms(200)));
  p.sched.run_until(ms(1725));
  // OB 1 at 1000, 1010, ..., 1510 (52), then 1720 (53).
  EXPECT_EQ(p.h.scans(), 53U);
  auto e = p.ob80();
  ASSERT_EQ(e.size(), 1U);
  EXPECT_EQ(e[0].time, ms(1660));
  EXPECT_EQ(e[0].code, 0x3501);
  EXPECT_EQ(e[0].rack, 0);
  EXPECT_EQ(e[0].role, CpuRole::Master);
  EXPECT_EQ(e[0].text, "OB 80 W#16#3501 cycle time exceeded: OB 1 started at 1510 ms, max cycle time 150 ms");
  // Both powered CPUs log it (CPU 1 is in LINK-UP).
  for (int r = 0; r < 2; ++r) {
    const auto d = p.h.diag_buffer(r);
    bool found = false;
    for (const auto& x : d) found |= x.at == ms(1660) && x.code == 0x3501;
    EXPECT_TRUE(found) << r;
  }

  // 140 ms at 1803: the OB 1 at 1810 lasts exactly 150 ms (next at 1960): no overrun.
  p.sched.run_until(ms(1803));
  p.h.cycle_overload(ms(140));
  p.sched.run_until(ms(2000));
  EXPECT_EQ(p.h.ob80_count(), 1U);

  // Two overloads before one OB 1 add up: 300 + 110 ms at 2003 -> the OB 1 at 2010 lasts
  // 420 ms (> 2 x 150): one OB 80 at 2160 (the STOP for a second OB 80 is not modelled).
  p.sched.run_until(ms(2003));
  p.h.cycle_overload(ms(300));
  p.h.cycle_overload(ms(110));
  p.sched.run_until(ms(2495));
  e = p.ob80();
  ASSERT_EQ(e.size(), 2U);
  EXPECT_EQ(e[1].time, ms(2160));
  EXPECT_EQ(p.h.pair().state(0), CpuState::Run);
  // The OB 1 after 2010 at 2430, then every 10 ms: 2430..2490 = 7 more.
  EXPECT_EQ(p.h.scans(), 53U + 9U /*1730..1810*/ + 5U /*1960..2000*/ + 1U /*2010*/ + 7U);
}

TEST(HOb80, RedundantOverloadOnBothCpus) {
  Pair p;
  p.sched.run_until(ms(3203));
  ASSERT_EQ(p.h.pair().system_mode(), SystemMode::Redundant);
  // OB 1 at 3145, 3155, ..., 3195, 3205: the one at 3205 lasts 10 + 145 = 155 ms -> OB 80 at
  // 3205 + 150 = 3355 on both CPUs (rack -1), next OB 1 at 3360.
  p.h.cycle_overload(ms(145));
  p.sched.run_until(ms(3400));
  const auto e = p.ob80();
  ASSERT_EQ(e.size(), 1U);
  EXPECT_EQ(e[0].time, ms(3355));
  EXPECT_EQ(e[0].rack, -1);
  EXPECT_EQ(e[0].role, CpuRole::Master);
  EXPECT_EQ(p.h.diag_buffer(0).back().code, 0x3501);
  EXPECT_EQ(p.h.diag_buffer(1).back().code, 0x3501);
  EXPECT_EQ(p.h.pair().system_mode(), SystemMode::Redundant);
}

TEST(HOb80, UpdateWithinTheCycleExtensionGivesNoOb80) {
  HCpuPairParams params;
  // A valid set: extension 2000 > communication delay 800 > T_P15 200 > T_PH 90 ms, 50 + 90 <=
  // 200; W = MAX(145, 50 + 90) = 145 ms < T_P15: the update is not aborted.
  params.h_parameters.max_cycle_extension = 2'000'000;  // µs
  params.h_parameters.max_comm_delay = 800'000;
  params.h_parameters.t_p15 = 200'000;
  params.h_parameters.t_ph = 90'000;
  Pair p(params);
  p.h.set_max_cycle_time(ms(100));
  p.sched.run_until(ms(3500));
  ASSERT_EQ(p.h.pair().system_mode(), SystemMode::Redundant);
  // The cycle across the update: last OB 1 before t3 = 2990, first after = t5 = 3145: 155 ms,
  // more than the 100 ms maximum but within 100 ms + 2000 ms: no OB 80.
  ASSERT_EQ(p.h.update_measures().size(), 1U);
  EXPECT_EQ(p.h.update_measures()[0].no_io_window(), ms(155));
  EXPECT_EQ(p.h.ob80_count(), 0U);
  EXPECT_TRUE(p.ob80().empty());
  // The monitoring still works after the update: 95 ms at 3503 -> the OB 1 at 3505 lasts
  // 105 ms > 100: OB 80 at 3605 on both.
  p.h.cycle_overload(ms(95));
  p.sched.run_until(ms(3700));
  const auto e = p.ob80();
  ASSERT_EQ(e.size(), 1U);
  EXPECT_EQ(e[0].time, ms(3605));
  EXPECT_EQ(e[0].rack, -1);
}

TEST(HOb80, NoOb80WhileNoProgramRuns) {
  Pair p;
  // Overload at 1503, then the master STOPs at 1600 (before 1510 + 150): no cycle to monitor.
  p.sched.run_until(ms(1503));
  p.h.cycle_overload(ms(200));
  p.sched.run_until(ms(1600));
  p.h.switch_to_stop(0);
  p.sched.run_until(ms(2000));
  EXPECT_EQ(p.h.ob80_count(), 0U);
}

}  // namespace
}  // namespace pbvbus::devices
