// HConnections: configured S7 connections over the CPs of an H-system (F4, R8; rules in
// controllers/s7h/include/pbvbus/s7h/h_connections.hpp and docs/h-system.md).
#include "pbvbus/s7h/h_connections.hpp"

#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "pbvbus/s7h/h_cpu_pair.hpp"

namespace pbvbus::devices {
namespace {

using bus::Ticks;
constexpr Ticks ms(std::int64_t v) { return v * bus::kTicksPerMs; }
constexpr Ticks sec(std::int64_t v) { return v * bus::kTicksPerSecond; }
// Default pair: CPU 0 at 0 s -> STARTUP 1 s -> RUN Solo at 1 s; CPU 1 at 5 s -> LINK-UP
// 5 s .. 7 s -> UPDATE W = 75 ms + 0.7 ms x 100 KB = 145 ms -> Redundant at 7.145 s.
constexpr Ticks kSolo = sec(1);
constexpr Ticks kCpu1On = sec(5);
constexpr Ticks kUpdateAt = kCpu1On + sec(2);       // 7 s
constexpr Ticks kRedundantAt = kUpdateAt + ms(145);  // 7.145 s

using K = CommEvent::Kind;

struct Rig {
  HCpuPair p;
  HConnections c;
  void at(Ticks t) {  // every pair deadline is passed exactly (the tests call it at them)
    p.on_time(t);
    c.update(p, t);
  }
  void bring_up() {
    p.power_on(0, 0);
    c.update(p, 0);
    at(kSolo);
    p.power_on(1, kCpu1On);
    c.update(p, kCpu1On);
    at(kUpdateAt);
    at(kRedundantAt);
    ASSERT_EQ(p.system_mode(), SystemMode::Redundant);
  }
  const Connection& con(const char* name) const {
    return c.connections().at(static_cast<std::size_t>(c.find(name)));
  }
  std::vector<CommEvent> since(std::size_t n) const {
    return {c.events().begin() + static_cast<std::ptrdiff_t>(n), c.events().end()};
  }
};

/// One CP 443-1 per CPU, standard connections "s0" (rack 0) and "s1" (rack 1), fault-tolerant
/// "ft" over CP 0 (2 paths).
void two_path_config(HConnections& c) {
  ASSERT_EQ(c.add_cp({0, 0, CpKind::Cp443_1}), "");
  ASSERT_EQ(c.add_cp({1, 0, CpKind::Cp443_1}), "");
  ASSERT_EQ(c.add_connection({"s0", ConnectionKind::Standard, 0, 0}), "");
  ASSERT_EQ(c.add_connection({"s1", ConnectionKind::Standard, 1, 0}), "");
  ASSERT_EQ(c.add_connection({"ft", ConnectionKind::FaultTolerant, 0, 0}), "");
}

void expect_event(const CommEvent& e, Ticks at, K kind, int conn, int rack, int cp, int to_rack = -1,
                  int to_cp = -1) {
  EXPECT_EQ(e.at, at) << e.text;
  EXPECT_EQ(e.kind, kind) << e.text;
  EXPECT_EQ(e.connection, conn) << e.text;
  EXPECT_EQ(e.rack, rack) << e.text;
  EXPECT_EQ(e.cp, cp) << e.text;
  EXPECT_EQ(e.to_rack, to_rack) << e.text;
  EXPECT_EQ(e.to_cp, to_cp) << e.text;
}

TEST(HConnections, EstablishedWhenTheirCpuRunsAndAcceptsTheStandbysAfterTheUpdate) {
  Rig r;
  two_path_config(r.c);
  r.bring_up();
  const auto& ev = r.c.events();
  // s0 and ft at 1 s (master in RUN Solo; rack 1 still off: ft has only rack 0's path);
  // s1 and ft's rack-1 path only at 7.145 s (R8: none before the update ends).
  ASSERT_EQ(ev.size(), 4u);
  expect_event(ev[0], kSolo, K::Established, 0, 0, 0);
  expect_event(ev[1], kSolo, K::Established, 2, 0, 0);
  expect_event(ev[2], kRedundantAt, K::Established, 1, 1, 0);
  expect_event(ev[3], kRedundantAt, K::PathRegained, 2, 1, 0);
  EXPECT_EQ(r.con("ft").active, 0);  // rack 0 CP 0
  EXPECT_TRUE(r.con("ft").paths[1].up);
}

TEST(HConnections, F4CpFailsStandardLostFaultTolerantContinuesOnThePartner) {
  Rig r;
  two_path_config(r.c);
  r.bring_up();
  const std::size_t n = r.c.events().size();
  ASSERT_TRUE(r.c.fail_cp(0, 0, r.p, sec(10)));
  EXPECT_FALSE(r.c.fail_cp(0, 0, r.p, sec(10)));  // already failed
  auto ev = r.since(n);
  ASSERT_EQ(ev.size(), 3u);
  expect_event(ev[0], sec(10), K::CpFailed, -1, 0, 0);
  expect_event(ev[1], sec(10), K::Lost, 0, 0, 0);
  EXPECT_NE(ev[1].text.find("CP failed"), std::string::npos) << ev[1].text;
  expect_event(ev[2], sec(10), K::PathSwitched, 2, 0, 0, 1, 0);
  EXPECT_EQ(r.con("s0").state, ConnectionState::Lost);
  EXPECT_EQ(r.con("s0").lost_at, sec(10));
  EXPECT_EQ(r.con("s1").state, ConnectionState::Established);
  EXPECT_EQ(r.con("ft").state, ConnectionState::Established);
  EXPECT_EQ(r.con("ft").active, 1);
  // The CP replaced at 20 s: ft regains the path as a reserve (no switch back); s0 stays lost
  // until the partner re-establishes it (21 s).
  ASSERT_TRUE(r.c.repair_cp(0, 0, r.p, sec(20)));
  ev = r.since(n + 3);
  ASSERT_EQ(ev.size(), 2u);
  expect_event(ev[0], sec(20), K::CpRepaired, -1, 0, 0);
  expect_event(ev[1], sec(20), K::PathRegained, 2, 0, 0);
  EXPECT_EQ(r.con("ft").active, 1);
  EXPECT_EQ(r.con("s0").state, ConnectionState::Lost);
  ASSERT_TRUE(r.c.reestablish(0, r.p, sec(21)));
  EXPECT_FALSE(r.c.reestablish(0, r.p, sec(21)));  // not lost any more
  expect_event(r.c.events().back(), sec(21), K::Reestablished, 0, 0, 0);
  EXPECT_EQ(r.con("s0").state, ConnectionState::Established);
}

TEST(HConnections, FourPathsSameCpuFirstThenPartnerSameIndexLostWhenNoneLeft) {
  Rig r;
  for (int rack = 0; rack < 2; ++rack)
    for (int i = 0; i < 2; ++i) ASSERT_EQ(r.c.add_cp({rack, i, CpKind::Cp443_5}), "");
  ASSERT_EQ(r.c.add_connection({"ft", ConnectionKind::FaultTolerant, 0, 0}), "");
  r.bring_up();
  const Connection& ft = r.con("ft");
  ASSERT_EQ(ft.paths.size(), 4u);  // rack 0 CP 0, rack 0 CP 1, rack 1 CP 0, rack 1 CP 1
  EXPECT_EQ(ft.active, 0);
  std::size_t n = r.c.events().size();
  r.c.fail_cp(0, 0, r.p, sec(10));  // -> same CPU's CP 1
  expect_event(r.c.events().back(), sec(10), K::PathSwitched, 0, 0, 0, 0, 1);
  r.c.fail_cp(0, 1, r.p, sec(11));  // -> the partner's CP with the same index (1)
  expect_event(r.c.events().back(), sec(11), K::PathSwitched, 0, 0, 1, 1, 1);
  r.c.fail_cp(1, 0, r.p, sec(12));  // a reserve: only PathLost
  expect_event(r.c.events().back(), sec(12), K::PathLost, 0, 1, 0);
  EXPECT_EQ(ft.active, 3);
  r.c.fail_cp(1, 1, r.p, sec(13));  // the last path
  expect_event(r.c.events().back(), sec(13), K::Lost, 0, 1, 1);
  EXPECT_NE(r.c.events().back().text.find("no path left"), std::string::npos);
  EXPECT_EQ(ft.state, ConnectionState::Lost);
  EXPECT_EQ(r.c.events().size(), n + 8);  // 4 x CpFailed + 2 switches + PathLost + Lost
  // A repaired CP does not bring a lost connection back by itself; reestablish() does.
  r.c.repair_cp(1, 1, r.p, sec(20));
  EXPECT_EQ(ft.state, ConnectionState::Lost);
  ASSERT_TRUE(r.c.reestablish(0, r.p, sec(21)));
  EXPECT_EQ(ft.active, 3);  // rack 1 CP 1: the only CP up
  n = r.c.events().size();
  EXPECT_EQ(r.c.events()[n - 1].kind, K::Reestablished);
}

TEST(HConnections, MasterCpuFailsItsStandardConnectionLostFaultTolerantSwitches) {
  Rig r;
  two_path_config(r.c);
  r.bring_up();
  const std::size_t n = r.c.events().size();
  r.p.power_off(0, sec(10));  // F1: CPU 1 becomes master (Solo)
  r.c.update(r.p, sec(10));
  auto ev = r.since(n);
  ASSERT_EQ(ev.size(), 2u);
  expect_event(ev[0], sec(10), K::Lost, 0, 0, 0);
  EXPECT_NE(ev[0].text.find("CPU off"), std::string::npos) << ev[0].text;
  expect_event(ev[1], sec(10), K::PathSwitched, 2, 0, 0, 1, 0);
  EXPECT_EQ(r.con("s1").state, ConnectionState::Established);
  // CPU 0 returns at 20 s as standby: LINK-UP 20..22 s, UPDATE 22 s .. 22.145 s.
  r.p.power_on(0, sec(20));
  r.c.update(r.p, sec(20));
  EXPECT_FALSE(r.c.reestablish(0, r.p, sec(21)));  // R8: refused during the link-up
  r.at(sec(22));
  r.at(sec(22) + ms(145));
  ASSERT_EQ(r.p.system_mode(), SystemMode::Redundant);
  expect_event(r.c.events().back(), sec(22) + ms(145), K::PathRegained, 2, 0, 0);
  EXPECT_EQ(r.con("ft").active, 1);  // no switch back
  EXPECT_EQ(r.con("s0").state, ConnectionState::Lost);
  EXPECT_TRUE(r.c.reestablish(0, r.p, sec(23)));
}

TEST(HConnections, R8LinkUpBreaksTheStandbysStandardConnectionsKeepsTheMasters) {
  Rig r;
  two_path_config(r.c);
  r.bring_up();
  // F5 at 10 s: the standby (rack 1) STOPs; a CPU in STOP keeps its connections.
  r.p.cut_fibre(0, sec(10));
  r.c.update(r.p, sec(10));
  ASSERT_EQ(r.p.state(1), CpuState::Stop);
  EXPECT_EQ(r.con("s1").state, ConnectionState::Established);
  EXPECT_TRUE(r.con("ft").paths[1].up);
  r.p.repair_fibre(0, sec(11));
  r.c.update(r.p, sec(11));
  const std::size_t n = r.c.events().size();
  r.p.switch_to_run(1, sec(12));  // LINK-UP 12..14 s, UPDATE 14 s .. 14.145 s
  r.c.update(r.p, sec(12));
  auto ev = r.since(n);
  ASSERT_EQ(ev.size(), 2u);
  expect_event(ev[0], sec(12), K::Lost, 1, 1, 0);
  EXPECT_NE(ev[0].text.find("link-up of the standby (R8)"), std::string::npos) << ev[0].text;
  expect_event(ev[1], sec(12), K::PathLost, 2, 1, 0);
  EXPECT_EQ(r.con("s0").state, ConnectionState::Established);  // the master's kept
  EXPECT_EQ(r.con("ft").active, 0);
  r.at(sec(13));
  EXPECT_FALSE(r.p.accepts_connections(0));  // no new ones on either CPU
  EXPECT_FALSE(r.c.reestablish(1, r.p, sec(13)));
  r.at(sec(14));
  r.at(sec(14) + ms(145));
  expect_event(r.c.events().back(), sec(14) + ms(145), K::PathRegained, 2, 1, 0);
  EXPECT_EQ(r.con("s1").state, ConnectionState::Lost);  // standard: not by itself
  EXPECT_TRUE(r.c.reestablish(1, r.p, sec(15)));
}

TEST(HConnections, ErrorSearchOfTheStandbyLosesItsStandardConnectionAndReservePath) {
  Rig r;
  two_path_config(r.c);
  r.bring_up();
  const std::size_t n = r.c.events().size();
  ASSERT_TRUE(r.p.inject_comparison_error(sec(10)));  // F16: standby ERROR-SEARCH
  r.c.update(r.p, sec(10));
  auto ev = r.since(n);
  ASSERT_EQ(ev.size(), 2u);
  expect_event(ev[0], sec(10), K::Lost, 1, 1, 0);
  EXPECT_NE(ev[0].text.find("ERROR-SEARCH"), std::string::npos) << ev[0].text;
  expect_event(ev[1], sec(10), K::PathLost, 2, 1, 0);
}

TEST(HConnections, BadConfigurationIsRefusedWithATextAndChangesNothing) {
  HConnections c;
  EXPECT_EQ(c.add_cp({2, 0, CpKind::Cp443_1}), "cp: rack must be 0 or 1");
  EXPECT_EQ(c.add_cp({0, -1, CpKind::Cp443_1}), "cp: index must be >= 0");
  ASSERT_EQ(c.add_cp({0, 0, CpKind::Cp443_1}), "");
  EXPECT_EQ(c.add_cp({0, 0, CpKind::Cp443_5}), "cp: rack 0 already has a CP 0");
  EXPECT_EQ(c.add_connection({"", ConnectionKind::Standard, 0, 0}), "connection: name is empty");
  EXPECT_EQ(c.add_connection({"a", ConnectionKind::Standard, 1, 0}),
            "connection \"a\": rack 1 has no CP 0");
  EXPECT_EQ(c.add_connection({"f", ConnectionKind::FaultTolerant, 0, 0}),
            "connection \"f\": a fault-tolerant connection needs one or two CP 443-1 in each "
            "rack, the same number (found 1 and 0)");
  ASSERT_EQ(c.add_connection({"a", ConnectionKind::Standard, 0, 0}), "");
  EXPECT_EQ(c.add_connection({"a", ConnectionKind::Standard, 0, 0}),
            "connection: duplicate name \"a\"");
  EXPECT_EQ(c.connections().size(), 1u);
  HCpuPair p;
  EXPECT_FALSE(c.fail_cp(1, 0, p, 0));
  EXPECT_FALSE(c.repair_cp(0, 0, p, 0));  // not failed
  EXPECT_FALSE(c.reestablish(5, p, 0));
  EXPECT_EQ(c.find("nope"), -1);
}

}  // namespace
}  // namespace pbvbus::devices
