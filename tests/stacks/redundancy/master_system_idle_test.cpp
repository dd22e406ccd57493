// redundancy::MasterSystem additions for the H-system (master_system.hpp): the "not started"
// (idle) line and LineLoss::CpuFailure. Driven by hand-made master events (no bus): the
// S7 events are asserted with their codes, lines and times.
#include <gtest/gtest.h>

#include <vector>

#include "pbvbus/dp/master.hpp"
#include "pbvbus/redundancy/master_system.hpp"

namespace pbvbus::redundancy {
namespace {

using K = SystemEvent::Kind;
constexpr bus::Ticks kMs = bus::kTicksPerMs;

dp::SlaveParams slave(std::uint8_t a, bool switched) {
  dp::SlaveParams p;
  p.address = a;
  p.ident = 0x0A10;
  p.user_prm = {0x80, 0x00, 0x00};      // DP-V1 (the PrmCmd block needs DPV1_Status)
  p.modules = {{{0x11}, "2 byte in"}};  // 0x11: input, 2 octets
  if (switched) p.prm_cmd.assign(8, 0);
  return p;
}

struct Fix {
  dp::Master a{dp::MasterParams{}, {slave(5, true), slave(10, false)}};
  dp::Master b{dp::MasterParams{}, {slave(5, true)}};
  MasterSystem ms{a, b, {{5, 30 * kMs, false}}};

  void event(int line, dp::MasterEvent::Kind k, std::uint8_t slave, bus::Ticks t) {
    dp::MasterEvent e;
    e.kind = k;
    e.slave = slave;
    e.time = t;
    ms.on_master_event(line, e);
  }
  std::vector<SystemEvent> s7() const {
    std::vector<SystemEvent> out;
    for (const auto& e : ms.events())
      if (e.s7()) out.push_back(e);
    return out;
  }
};

TEST(MasterSystemIdle, IdleLineReportsNothingAndStartsSilently) {
  Fix f;
  ASSERT_TRUE(f.ms.mark_line_idle(1));
  EXPECT_TRUE(f.ms.line_idle(1));
  EXPECT_FALSE(f.ms.mark_line_idle(2));  // bad line: refused, nothing happens
  f.event(0, dp::MasterEvent::Kind::DataExchangeEntered, 5, 1 * kMs);
  f.event(0, dp::MasterEvent::Kind::DataExchangeEntered, 10, 1 * kMs);
  // Line B's master reports station 5 absent: bookkeeping only (no 73A3).
  f.event(1, dp::MasterEvent::Kind::StationFailure, 5, 2 * kMs);
  // Stopping a line that never ran is no master-system failure.
  f.ms.line_lost(1, LineLoss::MasterStop, 3 * kMs);
  dp::MasterEvent mc;
  mc.kind = dp::MasterEvent::Kind::ModeChange;
  mc.mode = dp::MasterMode::Stop;
  mc.time = 3 * kMs;
  f.ms.on_master_event(1, mc);
  EXPECT_FALSE(f.ms.line_is_lost(1));
  EXPECT_TRUE(f.s7().empty());
  // The start-up Primary_Request went to A (no station answers here, so no Red_Status yet).
  EXPECT_EQ(f.ms.switching_to(5), 0);

  // The line starts: its channel comes up without 72A3; then it reports like any other.
  EXPECT_TRUE(f.ms.start_line(1, 4 * kMs));
  EXPECT_FALSE(f.ms.start_line(1, 4 * kMs));  // not idle any more
  EXPECT_FALSE(f.ms.line_idle(1));
  f.event(1, dp::MasterEvent::Kind::DataExchangeEntered, 5, 5 * kMs);
  EXPECT_TRUE(f.ms.channel_up(5, 1));
  EXPECT_FALSE(f.ms.redundancy_lost(5));
  EXPECT_TRUE(f.s7().empty());
  EXPECT_FALSE(f.ms.mark_line_idle(1));  // it ran: a stop now is a lost line
  f.ms.line_lost(1, LineLoss::MasterStop, 6 * kMs);
  auto ev = f.s7();
  ASSERT_EQ(ev.size(), 1u);
  EXPECT_EQ(ev[0].code(), 0x39C3);
  EXPECT_EQ(ev[0].line, 1);
  EXPECT_EQ(ev[0].time, 6 * kMs);
}

TEST(MasterSystemIdle, CpuFailureIsOneMasterSystemFailure) {
  Fix f;
  f.event(0, dp::MasterEvent::Kind::DataExchangeEntered, 5, 1 * kMs);
  f.event(1, dp::MasterEvent::Kind::DataExchangeEntered, 5, 1 * kMs);
  f.event(0, dp::MasterEvent::Kind::DataExchangeEntered, 10, 1 * kMs);
  ASSERT_EQ(f.ms.switching_to(5), 0);  // the first channel up got Primary_Request
  f.ms.line_lost(0, LineLoss::CpuFailure, 10 * kMs);
  EXPECT_EQ(to_string(LineLoss::CpuFailure), "CPU failure");
  ASSERT_TRUE(f.ms.line_loss(0).has_value());
  EXPECT_EQ(*f.ms.line_loss(0), LineLoss::CpuFailure);
  EXPECT_FALSE(f.ms.line_loss(1).has_value());
  EXPECT_FALSE(f.ms.mark_line_idle(0));  // lost, not idle
  auto ev = f.s7();
  ASSERT_EQ(ev.size(), 1u);  // one 39C3, no 73A3 for 5, no 39C4 for the one-sided 10
  EXPECT_EQ(ev[0].kind, K::MasterSystemFailure);
  EXPECT_EQ(ev[0].line, 0);
  EXPECT_EQ(ev[0].station, 0xFF);
  EXPECT_EQ(ev[0].time, 10 * kMs);
  EXPECT_EQ(f.ms.switching_to(5), 1);  // every station of the line to the other one at once
  // A second loss report (the master's own ModeChange) changes nothing.
  f.ms.line_lost(0, LineLoss::MasterStop, 11 * kMs);
  EXPECT_EQ(f.s7().size(), 1u);
  f.ms.line_back(0, 20 * kMs);
  f.event(0, dp::MasterEvent::Kind::DataExchangeEntered, 5, 21 * kMs);
  f.event(0, dp::MasterEvent::Kind::DataExchangeEntered, 10, 21 * kMs);
  ev = f.s7();
  ASSERT_EQ(ev.size(), 2u);  // 38C3 only: the channels' returns are silent
  EXPECT_EQ(ev[1].code(), 0x38C3);
  EXPECT_EQ(ev[1].time, 20 * kMs);
}

}  // namespace
}  // namespace pbvbus::redundancy
