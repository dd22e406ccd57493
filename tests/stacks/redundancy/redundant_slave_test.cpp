// The slave side of a switched station (protocol-facts.md §G; seeds-digest.md §2, S1, S2, F10,
// F24): start-up alternation, commanded and autonomous switchover over the internal link,
// supervision, Output_Hold_Time and "no pulse" at the backplane, with exact virtual times and
// octets written out by hand from §G.2/§G.3. Two masters (1 on line A, 2 on line B) are played
// by hand through each interface's ResponderUser, one DP cycle every 10 ms on each line.
#include <gtest/gtest.h>

#include <algorithm>
#include <optional>
#include <stdexcept>
#include <vector>

#include "../dp/slave_harness.hpp"
#include "pbvbus/redundancy/redundant_slave.hpp"

namespace pbvbus::redundancy {
namespace {

using dp::test::Bytes;
using dp::test::hex;
constexpr bus::Ticks kMs = bus::kTicksPerMs;
constexpr std::uint8_t kS = 10;

dp::SlaveConfig station_config() {
  dp::SlaveConfig c;
  c.ident = 0x1234;
  c.modules = {{{0x10}, "1 byte in"}, {{0x20}, "1 byte out"}};
  c.min_user_prm_len = 3;
  c.max_user_prm_len = 3 + 8;
  return c;
}

// Set_Prm with a PrmCmd block (§D.2, §G.2): 88 (Lock_Req | WD_On), WD 0A 0A (1 s), min TSDR
// 0B, ident 12 34, group 00, DPV1_Status 80 00 88 (DPV1_Enable; PrmCmd | Prm_Structure), then
// 08 02 00 <Seq_Nr << 3> <Function> 04 (Address_Change: system redundancy) <hold hi> <hold lo>.
Bytes set_prm(std::uint8_t seq, std::uint8_t function, std::uint16_t hold_10ms) {
  return {0x88, 0x0A, 0x0A, 0x0B, 0x12, 0x34, 0x00, 0x80, 0x00, 0x88, 0x08, 0x02, 0x00,
          static_cast<std::uint8_t>(seq << 3), function, 0x04,
          static_cast<std::uint8_t>(hold_10ms >> 8), static_cast<std::uint8_t>(hold_10ms & 0xFF)};
}

struct Rig {
  explicit Rig(RedundantSlaveParams p = {}) : rs(station_config(), p) {
    rs.on_event([this](const RedEvent& e) { events.push_back(e); });
    rs.power_on(0);
    rs.write_inputs(0, Bytes{0x3C});
  }
  RedundantSlave rs;
  std::vector<RedEvent> events;
  fdl::Reply last;
  bool line_up[2] = {true, true};  ///< the master of that line keeps polling

  void run_to(bus::Ticks t) { rs.on_time(t); }
  /// A request from the master of line `i` (address i + 1) at `now`; the reply frame.
  Bytes req(int i, bus::Ticks now, std::optional<std::uint8_t> dsap, const Bytes& data) {
    run_to(now);
    fdl::Indication ind;
    ind.now = now;
    ind.sa = static_cast<std::uint8_t>(i + 1);
    ind.da = kS;
    ind.fn = fdl::RequestFn::SrdHigh;
    ind.dsap = dsap;
    ind.ssap = dsap ? std::optional<std::uint8_t>(62) : std::nullopt;
    ind.data = data;
    last = fdl::Reply{};
    rs.interface(i).on_request(ind, last);
    return dp::test::encode_reply(ind, last);
  }
  Bytes diag(int i, bus::Ticks now) {
    req(i, now, dp::kSapSlaveDiag, {});
    return last.kind == fdl::Reply::Kind::Data ? last.data : Bytes{};
  }
  /// Set_Prm + Chk_Cfg on line i, then a Slave_Diag (as a master's start-up does).
  void start(int i, bus::Ticks now, std::uint8_t seq, std::uint8_t fn, std::uint16_t hold) {
    ASSERT_EQ(req(i, now, dp::kSapSetPrm, set_prm(seq, fn, hold)), Bytes{0xE5});
    ASSERT_EQ(req(i, now + kMs / 4, dp::kSapChkCfg, {0x10, 0x20}), Bytes{0xE5});
    diag(i, now + kMs / 2);
    ASSERT_EQ(rs.engine(i).state(), dp::SlaveState::DataExch);
  }
  /// One DP cycle at `now`: Data_Exchange with output `v` on each line whose master polls
  /// (line A at now, line B 100 us later); a DH reply makes that master read the diagnosis.
  void cycle(bus::Ticks now, std::uint8_t v) {
    for (int i = 0; i < 2; ++i) {
      if (!line_up[i]) continue;
      const bus::Ticks t = now + i * kMs / 10;
      req(i, t, std::nullopt, {v});
      if (last.kind == fdl::Reply::Kind::Data && last.status == fdl::ResponseStatus::DH)
        diag(i, t + kMs / 20);
    }
  }
};

TEST(RedundantSlave, StartupAlternationDoublesTsprimaryUntilPrimaryRequest) {
  Rig r;
  EXPECT_EQ(r.rs.role(0), Role::SPrimary);
  EXPECT_EQ(r.rs.role(1), Role::SWaiting);
  // Before any master: Not_Ready 02, Prm_Req|1 05, no master FF, ident; Red_Status block
  // 08 9F 00 00 00, Red_State_1 = Primary (S_PRIMARY) 0x02, Red_State_2 = 0x00, 00.
  EXPECT_EQ(hex(r.rs.engine(0).current_diag()), "02 05 00 FF 12 34 08 9F 00 00 00 02 00 00");
  EXPECT_EQ(hex(r.rs.engine(1).current_diag()), "02 05 00 FF 12 34 08 9F 00 00 00 00 02 00");
  // Swaps after Tsprimary = 2, 4, 8, 16, 32, 32 s: at 2, 6, 14, 30, 62, 94 s.
  const bus::Ticks swaps[] = {2000, 6000, 14000, 30000, 62000, 94000};
  int a_primary = 1;
  for (bus::Ticks s : swaps) {
    r.run_to(s * kMs - 1);
    EXPECT_EQ(r.rs.role(0), a_primary ? Role::SPrimary : Role::SWaiting) << s;
    r.run_to(s * kMs);
    a_primary ^= 1;
    EXPECT_EQ(r.rs.role(0), a_primary ? Role::SPrimary : Role::SWaiting) << s;
    EXPECT_EQ(r.rs.role(1), a_primary ? Role::SWaiting : Role::SPrimary) << s;
  }
  // At 100 s (interface 1 in S_WAITING... after six swaps A is S_PRIMARY again) the master of
  // line B sends Primary_Request: interface 1 is PRIMARY at once, interface 0 BACKUP when the
  // link message arrives 1 ms later; the alternation stops.
  ASSERT_EQ(r.rs.role(0), Role::SPrimary);
  r.start(1, 100000 * kMs, 1, kFnPrimaryRequest, 30);
  EXPECT_EQ(r.rs.role(1), Role::Primary);
  r.run_to(100001 * kMs - 1);
  EXPECT_EQ(r.rs.role(0), Role::SPrimary);
  r.run_to(100001 * kMs);
  EXPECT_EQ(r.rs.role(0), Role::Backup);
  r.run_to(200000 * kMs);
  EXPECT_EQ(r.rs.role(0), Role::Backup);
  EXPECT_EQ(r.rs.role(1), Role::Primary);
  EXPECT_EQ(r.rs.output_hold_time(), 300 * kMs);
}

/// Both lines in data exchange: interface 0 PRIMARY (Primary_Request from master 1 at 0.5 s),
/// interface 1 BACKUP (master 2's Set_Prm without Primary_Request), hold time `hold`.
void redundant_start(Rig& r, std::uint16_t hold) {
  r.start(0, 500 * kMs, 1, kFnPrimaryRequest, hold);
  r.start(1, 600 * kMs, 1, 0x00, hold);
  ASSERT_EQ(r.rs.role(0), Role::Primary);
  ASSERT_EQ(r.rs.role(1), Role::Backup);
}

TEST(RedundantSlave, CommandedSwitchoverBytesTimesAndNoPulse) {
  Rig r;
  redundant_start(r, 100);  // Output_Hold_Time 1 s
  std::uint8_t v = 0;
  std::uint8_t seen = 0;
  bus::Ticks t = 1000 * kMs;
  auto step = [&] {
    ++v;
    r.cycle(t, v);
    const std::uint8_t o = r.rs.outputs()[0];
    EXPECT_NE(o, 0) << "pulse at " << t;
    EXPECT_GE(o, seen) << "older value at " << t;
    seen = o;
    t += 10 * kMs;
  };
  for (int k = 0; k < 20; ++k) step();
  EXPECT_EQ(r.rs.outputs()[0], v);
  // The backup's outputs never reach the backplane.
  r.req(1, t, std::nullopt, {0xEE});
  EXPECT_EQ(r.rs.outputs()[0], v);
  // Master 2 commands interface 1 to become primary with a pure PrmCmd (18 octets), Seq_Nr 2.
  const bus::Ticks tc = t + 5 * kMs;
  EXPECT_EQ(r.req(1, tc, dp::kSapSetPrm, set_prm(2, kFnPrimaryRequest, 100)), Bytes{0xE5});
  EXPECT_EQ(r.rs.role(1), Role::BpSwitchover);
  EXPECT_EQ(r.rs.engine(1).state(), dp::SlaveState::DataExch);  // pure PrmCmd keeps it
  r.run_to(tc + kMs - 1);
  EXPECT_EQ(r.rs.role(0), Role::Primary);
  r.run_to(tc + kMs);  // switchover request arrives: PB, interface 0 becomes BACKUP
  EXPECT_EQ(r.rs.role(0), Role::Backup);
  EXPECT_TRUE(r.rs.outputs_held());
  r.run_to(tc + 2 * kMs - 1);
  EXPECT_EQ(r.rs.role(1), Role::BpSwitchover);
  r.run_to(tc + 2 * kMs);  // take-over arrives: interface 1 PRIMARY
  EXPECT_EQ(r.rs.role(1), Role::Primary);
  EXPECT_EQ(r.rs.primary(), 1);
  // Its next Data_Exchange answers DH: SD2 DA 02 SA 0A FC 0A data 3C, FCS 02+0A+0A+3C = 0x52.
  t = tc + 5 * kMs;
  ++v;
  EXPECT_EQ(hex(r.req(1, t, std::nullopt, {v})), "68 04 04 68 02 0A 0A 3C 52 16");
  EXPECT_FALSE(r.rs.outputs_held());
  EXPECT_EQ(r.rs.outputs()[0], v);
  seen = v;
  // Its diagnosis: 00 0C 00 02 12 34, then (status blocks in the order first set)
  // Red_Status 08 9F 00 <Seq_Nr 2 = 0x10> 00 <own: Primary 02 | Data_Exchange 08 |
  // Baudrate_found 20 = 2A> <partner: Backup 01 | 08 | 20 = 29> 00, and
  // Prm_Cmd_Ack 08 9E 00 10 <Function 02> <own at take-over: 02 | 08 | 20 | hold 40 = 6A> 29 00.
  EXPECT_EQ(hex(r.diag(1, t + kMs)),
            "00 0C 00 02 12 34 08 9F 00 10 00 2A 29 00 08 9E 00 10 02 6A 29 00");
  // Interface 0 shows the same pair the other way round (its own Seq_Nr is still 1 → 0x08).
  EXPECT_EQ(hex(r.rs.engine(0).current_diag()).substr(18, 23), "08 9F 00 08 00 29 2A 00");
  t += 5 * kMs;
  for (int k = 0; k < 20; ++k) step();
  EXPECT_EQ(r.rs.primary(), 1);
  const auto roles = std::count_if(r.events.begin(), r.events.end(), [](const RedEvent& e) {
    return e.kind == RedEvent::Kind::RoleChanged;
  });
  EXPECT_GE(roles, 4);  // start-up and the PB/BP sequence
}

TEST(RedundantSlave, FlyingAddressesFollowThePrimaryRole) {
  // Flying Redundancy: interface 0 starts at A (offset 0), interface 1 at A + 64; the offsets
  // swap exactly when the interface at A + 64 becomes PRIMARY (commanded: at the take-over,
  // 2 ms after the Primary_Request; autonomous: when the backup counts the primary lost).
  RedundantSlaveParams p;
  p.mode = RedundancyMode::Flying;
  Rig r(p);
  EXPECT_EQ(r.rs.address_offset(0), 0);
  EXPECT_EQ(r.rs.address_offset(1), 64);
  redundant_start(r, 100);
  EXPECT_EQ(r.rs.address_offset(0), 0);  // interface 0 became PRIMARY where it was: no swap
  for (bus::Ticks t = 1000 * kMs; t < 1200 * kMs; t += 10 * kMs) r.cycle(t, 1);
  const bus::Ticks tc = 1205 * kMs;
  EXPECT_EQ(r.req(1, tc, dp::kSapSetPrm, set_prm(2, kFnPrimaryRequest, 100)), Bytes{0xE5});
  r.run_to(tc + 2 * kMs - 1);
  EXPECT_EQ(r.rs.role(0), Role::Backup);  // handed over at tc + 1 ms, still at A
  EXPECT_EQ(r.rs.address_offset(0), 0);
  EXPECT_EQ(r.rs.address_offset(1), 64);
  r.run_to(tc + 2 * kMs);
  EXPECT_EQ(r.rs.role(1), Role::Primary);
  EXPECT_EQ(r.rs.address_offset(0), 64);
  EXPECT_EQ(r.rs.address_offset(1), 0);
  ASSERT_GE(r.events.size(), 2u);
  EXPECT_EQ(r.events.back().kind, RedEvent::Kind::AddressSwap);
  EXPECT_EQ(r.events.back().iface, 1);
  EXPECT_EQ(r.events.back().at, tc + 2 * kMs);
  // The new primary fails at 1215 ms; interface 0 last heard it at 1206 ms (the switchover
  // request), counts it lost 300 ms later and takes over, and the addresses swap back.
  r.line_up[1] = false;
  for (bus::Ticks t = 1210 * kMs; t < 1600 * kMs; t += 10 * kMs) {
    if (t == 1220 * kMs) r.rs.fail_interface(1, 1215 * kMs);
    r.cycle(t, 2);
  }
  EXPECT_EQ(r.rs.role(0), Role::Primary);
  EXPECT_EQ(r.rs.address_offset(0), 0);
  EXPECT_EQ(r.rs.address_offset(1), 64);
  const auto swap = std::find_if(r.events.rbegin(), r.events.rend(), [](const RedEvent& e) {
    return e.kind == RedEvent::Kind::AddressSwap;
  });
  ASSERT_NE(swap, r.events.rend());
  EXPECT_EQ(swap->iface, 0);
  EXPECT_EQ(swap->at, 1506 * kMs);
  // System Redundancy: always offset 0.
  Rig sys;
  EXPECT_EQ(sys.rs.address_offset(1), 0);
}

TEST(RedundantSlave, PrimaryInterfaceFailureNoticedBySupervisionNoPulse) {
  Rig r;
  redundant_start(r, 100);
  std::uint8_t v = 0, seen = 0;
  bus::Ticks t = 1000 * kMs;
  const bus::Ticks tf = 1234 * kMs;  // interface 0 fails between two cycles
  bool failed = false;
  while (t < 2500 * kMs) {
    if (!failed && t > tf) {
      r.rs.fail_interface(0, tf);
      failed = true;
    }
    ++v;
    r.cycle(t, v);
    const std::uint8_t o = r.rs.outputs()[0];
    EXPECT_NE(o, 0) << t;
    EXPECT_GE(o, seen) << t;
    seen = o;
    t += 10 * kMs;
  }
  // Heartbeats go out every 100 ms from power-on: the last one from interface 0 left at 1200 ms
  // and arrived at 1201 ms; supervision 300 ms → interface 1 notices at 1501 ms, PRIMARY then.
  const auto lost = std::find_if(r.events.begin(), r.events.end(), [](const RedEvent& e) {
    return e.kind == RedEvent::Kind::PartnerLost;
  });
  ASSERT_NE(lost, r.events.end());
  EXPECT_EQ(lost->at, 1501 * kMs);
  EXPECT_EQ(lost->iface, 1);
  EXPECT_EQ(r.rs.primary(), 1);
  EXPECT_EQ(r.rs.role(0), Role::Failed);
  EXPECT_EQ(r.rs.outputs()[0], v);  // fresh from line B
  // Interface 0 is silent; interface 1 reports its partner Hardware_defective (0x04).
  EXPECT_EQ(r.req(0, t, dp::kSapSlaveDiag, {}), Bytes{});
  EXPECT_EQ(r.rs.red_state(0).octet(), kRsHardwareDefective);
  // Repair: no switch back. The repaired interface's first heartbeat reaches the primary 1 ms
  // later (PartnerBack), which tells it to become BACKUP: 2 ms after the repair.
  const bus::Ticks tr = 3000 * kMs;
  r.rs.repair_interface(0, tr);
  EXPECT_EQ(r.rs.role(0), Role::SWaiting);
  r.run_to(tr + 2 * kMs - 1);
  EXPECT_EQ(r.rs.role(0), Role::SWaiting);
  r.run_to(tr + 2 * kMs);
  EXPECT_EQ(r.rs.role(0), Role::Backup);
  EXPECT_EQ(r.rs.primary(), 1);
  const auto back = std::find_if(r.events.begin(), r.events.end(), [](const RedEvent& e) {
    return e.kind == RedEvent::Kind::PartnerBack;
  });
  ASSERT_NE(back, r.events.end());
  EXPECT_EQ(back->at, tr + kMs);
}

TEST(RedundantSlave, OutputHoldTimeExpiresToSafeState) {
  Rig r;
  redundant_start(r, 5);  // Output_Hold_Time 50 ms: shorter than the 300 ms supervision
  for (int k = 0; k < 10; ++k) r.cycle((1000 + 10 * k) * kMs, static_cast<std::uint8_t>(k + 1));
  EXPECT_EQ(r.rs.outputs()[0], 10);
  const bus::Ticks tf = 1095 * kMs;
  r.rs.fail_interface(0, tf);
  r.run_to(tf + 50 * kMs - 1);
  EXPECT_EQ(r.rs.outputs()[0], 10);
  r.run_to(tf + 50 * kMs);
  EXPECT_EQ(r.rs.outputs()[0], 0);
  EXPECT_TRUE(std::any_of(r.events.begin(), r.events.end(), [&](const RedEvent& e) {
    return e.kind == RedEvent::Kind::OutputHoldExpired && e.at == tf + 50 * kMs;
  }));
  // Noticed at 1001 + 300 ms (last heartbeat 1000 ms): interface 1 takes over, fresh outputs.
  r.run_to(1301 * kMs);
  EXPECT_EQ(r.rs.primary(), 1);
  r.req(1, 1310 * kMs, std::nullopt, {0x42});
  EXPECT_EQ(r.rs.outputs()[0], 0x42);
}

TEST(RedundantSlave, PrimaryWatchdogExpirySwitchesToTheBackupInDataExchange) {
  Rig r;
  redundant_start(r, 100);
  std::uint8_t v = 0, seen = 0;
  bus::Ticks t = 1000 * kMs;
  for (int k = 0; k < 10; ++k, t += 10 * kMs) r.cycle(t, ++v);
  // Master 1 stops (last frame at t - 10 ms = 1090 ms): the watchdog (1 s) of interface 0
  // expires at 2090 ms; it leaves Data_Exch and hands over: interface 1 PRIMARY at 2091 ms.
  const bus::Ticks last_a = t - 10 * kMs;
  r.line_up[0] = false;
  while (t < 3000 * kMs) {
    r.cycle(t, ++v);
    const std::uint8_t o = r.rs.outputs()[0];
    EXPECT_NE(o, 0) << t;
    EXPECT_GE(o, seen) << t;
    seen = o;
    t += 10 * kMs;
  }
  const auto sw = std::find_if(r.events.begin(), r.events.end(), [](const RedEvent& e) {
    return e.kind == RedEvent::Kind::RoleChanged && e.iface == 1 && e.to == Role::Primary;
  });
  ASSERT_NE(sw, r.events.end());
  EXPECT_EQ(sw->at, last_a + 1000 * kMs + kMs);
  EXPECT_EQ(r.rs.role(0), Role::Backup);
  EXPECT_EQ(r.rs.outputs()[0], v);
}

// --- switchover request timeout -------------------------------------------------------------------

/// The events of one kind, in order.
std::vector<RedEvent> of_kind(const Rig& r, RedEvent::Kind k) {
  std::vector<RedEvent> out;
  for (const auto& e : r.events)
    if (e.kind == k) out.push_back(e);
  return out;
}

TEST(RedundantSlave, SwitchoverRequestTimesOutWhenThePartnerHasFailedSilently) {
  Rig r;
  redundant_start(r, 100);  // Output_Hold_Time 1 s
  for (bus::Ticks t = 1000 * kMs; t < 1230 * kMs; t += 10 * kMs) r.cycle(t, 7);
  // Interface 0 (PRIMARY) fails at 1234 ms. Its last heartbeat left at 1200 ms and arrived at
  // 1201 ms: the supervision would count it lost only at 1501 ms.
  r.rs.fail_interface(0, 1234 * kMs);
  r.line_up[0] = false;
  // Master 2 commands interface 1 to become primary at 1250 ms (pure PrmCmd, Seq_Nr 2).
  const bus::Ticks tc = 1250 * kMs;
  EXPECT_EQ(r.req(1, tc, dp::kSapSetPrm, set_prm(2, kFnPrimaryRequest, 100)), Bytes{0xE5});
  EXPECT_EQ(r.rs.role(1), Role::BpSwitchover);
  // Nobody answers the switchover request: PRIMARY at tc + switch_timeout (10 ms), not at
  // 1501 ms; the partner counted lost at that same tick, before the role change.
  r.run_to(tc + 10 * kMs - 1);
  EXPECT_EQ(r.rs.role(1), Role::BpSwitchover);
  EXPECT_TRUE(of_kind(r, RedEvent::Kind::PartnerLost).empty());
  r.run_to(tc + 10 * kMs);
  EXPECT_EQ(r.rs.role(1), Role::Primary);
  ASSERT_GE(r.events.size(), 2u);
  const RedEvent& lost = r.events[r.events.size() - 2];
  const RedEvent& prim = r.events.back();
  EXPECT_EQ(lost.kind, RedEvent::Kind::PartnerLost);
  EXPECT_EQ(lost.iface, 1);
  EXPECT_EQ(lost.at, 1260 * kMs);
  EXPECT_EQ(prim.kind, RedEvent::Kind::RoleChanged);
  EXPECT_EQ(prim.iface, 1);
  EXPECT_EQ(prim.from, Role::BpSwitchover);
  EXPECT_EQ(prim.to, Role::Primary);
  EXPECT_EQ(prim.at, 1260 * kMs);
  // Prm_Cmd_Ack as at a take-over: Seq_Nr 2 (0x10), Function 02, own 6A (Primary 02, DX 08,
  // Baudrate 20, Output_Hold_Time started 40: A's outputs held since 1234 ms), partner 04
  // (Hardware_defective). Red_Status the same pair, Function 00. Standard part: 00 0C 00 02
  // (master 2), ident 12 34.
  EXPECT_EQ(hex(r.diag(1, tc + 11 * kMs)),
            "00 0C 00 02 12 34 08 9F 00 10 00 6A 04 00 08 9E 00 10 02 6A 04 00");
  // The supervision does not count the partner lost a second time at 1501 ms.
  r.run_to(1600 * kMs);
  EXPECT_EQ(of_kind(r, RedEvent::Kind::PartnerLost).size(), 1u);
  EXPECT_EQ(r.rs.primary(), 1);
}

TEST(RedundantSlave, SwitchoverRequestToALivePartnerStillTakesTwoLinkDelays) {
  Rig r;
  redundant_start(r, 100);
  for (bus::Ticks t = 1000 * kMs; t < 1200 * kMs; t += 10 * kMs) r.cycle(t, 7);
  const bus::Ticks tc = 1205 * kMs;
  EXPECT_EQ(r.req(1, tc, dp::kSapSetPrm, set_prm(2, kFnPrimaryRequest, 100)), Bytes{0xE5});
  r.run_to(tc + 2 * kMs - 1);
  EXPECT_EQ(r.rs.role(1), Role::BpSwitchover);
  r.run_to(tc + 2 * kMs);  // 2 × link delay (1 ms)
  EXPECT_EQ(r.rs.role(1), Role::Primary);
  EXPECT_EQ(r.rs.role(0), Role::Backup);
  // Past the 10 ms timeout nothing more happens: the deadline died with the take-over.
  r.run_to(tc + 50 * kMs);
  EXPECT_TRUE(of_kind(r, RedEvent::Kind::PartnerLost).empty());
  EXPECT_EQ(r.rs.role(1), Role::Primary);
  EXPECT_EQ(r.rs.role(0), Role::Backup);
  // A timeout that a live partner cannot meet (≤ 2 × link delay) is refused.
  RedundantSlaveParams p;
  p.switch_timeout = 2 * p.link_delay;
  EXPECT_THROW(RedundantSlave(station_config(), p), std::invalid_argument);
  p.switch_timeout = 2 * p.link_delay + 1;
  EXPECT_NO_THROW(RedundantSlave(station_config(), p));
}

// --- FreshOutputs: the end of the hold ---------------------------------------------------------------

TEST(RedundantSlave, FreshOutputsAtStartUpAndAfterACommandedSwitchover) {
  Rig r;
  redundant_start(r, 100);
  // Start-up: the first Data_Exchange of the PRIMARY (line A at 1000 ms) ends it.
  r.cycle(1000 * kMs, 1);
  auto fresh = of_kind(r, RedEvent::Kind::FreshOutputs);
  ASSERT_EQ(fresh.size(), 1u);
  EXPECT_EQ(fresh[0].iface, 0);
  EXPECT_EQ(fresh[0].at, 1000 * kMs);
  for (bus::Ticks t = 1010 * kMs; t < 1200 * kMs; t += 10 * kMs) r.cycle(t, 2);
  EXPECT_EQ(of_kind(r, RedEvent::Kind::FreshOutputs).size(), 1u);  // steady state: none
  const bus::Ticks tc = 1205 * kMs;
  EXPECT_EQ(r.req(1, tc, dp::kSapSetPrm, set_prm(2, kFnPrimaryRequest, 100)), Bytes{0xE5});
  // Outputs while the roles move are not fresh ones: B in BP_SWITCHOVER at tc + 0.5 ms, A
  // already BACKUP at tc + 1.5 ms.
  r.req(1, tc + kMs / 2, std::nullopt, {3});
  r.req(0, tc + 3 * kMs / 2, std::nullopt, {4});
  EXPECT_EQ(r.rs.outputs()[0], 2);
  EXPECT_EQ(of_kind(r, RedEvent::Kind::FreshOutputs).size(), 1u);
  r.run_to(tc + 2 * kMs);
  ASSERT_EQ(r.rs.primary(), 1);
  // B's first Data_Exchange as PRIMARY, at tc + 5 ms: the end of the hold.
  r.req(1, tc + 5 * kMs, std::nullopt, {5});
  EXPECT_EQ(r.rs.outputs()[0], 5);
  fresh = of_kind(r, RedEvent::Kind::FreshOutputs);
  ASSERT_EQ(fresh.size(), 2u);
  EXPECT_EQ(fresh[1].iface, 1);
  EXPECT_EQ(fresh[1].at, 1210 * kMs);
  r.req(1, tc + 15 * kMs, std::nullopt, {6});
  EXPECT_EQ(of_kind(r, RedEvent::Kind::FreshOutputs).size(), 2u);
}

TEST(RedundantSlave, FreshOutputsAfterAnAutonomousSwitchover) {
  Rig r;
  redundant_start(r, 100);
  bus::Ticks t = 1000 * kMs;
  for (int k = 0; k < 10; ++k, t += 10 * kMs) r.cycle(t, 1);
  // Master 1's last request at 1090 ms; watchdog 1 s → interface 0 leaves Data_Exch at 2090 ms,
  // interface 1 PRIMARY at 2091 ms; B's next Data_Exchange: the cycle of 2100 ms, line B
  // 100 us later → FreshOutputs at 2100.1 ms from interface 1.
  r.line_up[0] = false;
  for (; t < 2200 * kMs; t += 10 * kMs) r.cycle(t, 2);
  const auto fresh = of_kind(r, RedEvent::Kind::FreshOutputs);
  ASSERT_EQ(fresh.size(), 2u);
  EXPECT_EQ(fresh[0].iface, 0);
  EXPECT_EQ(fresh[0].at, 1000 * kMs);
  EXPECT_EQ(fresh[1].iface, 1);
  EXPECT_EQ(fresh[1].at, 2100 * kMs + kMs / 10);
}

// --- station power ---------------------------------------------------------------------------------------

TEST(RedundantSlave, PowerOffIsADeadStationPowerOnAColdStart) {
  Rig r;
  redundant_start(r, 100);
  for (bus::Ticks t = 1000 * kMs; t < 1200 * kMs; t += 10 * kMs) r.cycle(t, 9);
  // A Primary_Request to B at 1203 ms puts a switchover request on the link (due 1204 ms);
  // the station loses power at 1203.5 ms, before it arrives.
  EXPECT_EQ(r.req(1, 1203 * kMs, dp::kSapSetPrm, set_prm(2, kFnPrimaryRequest, 100)),
            Bytes{0xE5});
  const bus::Ticks toff = 1203 * kMs + kMs / 2;
  r.rs.power_off(toff);
  EXPECT_FALSE(r.rs.powered());
  EXPECT_EQ(r.rs.outputs()[0], 0);  // drives nothing at once, no hold
  EXPECT_FALSE(r.rs.outputs_held());
  EXPECT_EQ(r.rs.role(0), Role::Off);
  EXPECT_EQ(r.rs.role(1), Role::Off);
  EXPECT_EQ(r.rs.primary(), -1);
  EXPECT_EQ(r.rs.next_deadline(), bus::kNever);
  // Both interfaces silent.
  EXPECT_EQ(r.req(0, 1210 * kMs, dp::kSapSlaveDiag, {}), Bytes{});
  EXPECT_EQ(r.req(1, 1210 * kMs, std::nullopt, {9}), Bytes{});
  const std::size_t n = r.events.size();
  r.run_to(2000 * kMs);
  EXPECT_EQ(r.events.size(), n);  // nothing happens in a dead station (no hold expiry either)
  EXPECT_EQ(r.rs.outputs()[0], 0);
  // Power returns at 2 s: as at the first power-on (the switchover request died with the
  // link): S_PRIMARY / S_WAITING, Wait_Prm, no Prm_Cmd_Ack, Red_Status Seq_Nr 0.
  r.rs.power_on(2000 * kMs);
  ASSERT_EQ(r.events.size(), n + 2);
  EXPECT_EQ(r.events[n].from, Role::Off);
  EXPECT_EQ(r.events[n].to, Role::SPrimary);
  EXPECT_EQ(r.events[n].at, 2000 * kMs);
  EXPECT_EQ(r.events[n + 1].to, Role::SWaiting);
  EXPECT_EQ(hex(r.rs.engine(0).current_diag()), "02 05 00 FF 12 34 08 9F 00 00 00 02 00 00");
  EXPECT_EQ(hex(r.rs.engine(1).current_diag()), "02 05 00 FF 12 34 08 9F 00 00 00 00 02 00");
  r.run_to(2001 * kMs);  // a switchover request in flight before would have arrived by now
  EXPECT_EQ(r.rs.role(0), Role::SPrimary);
  EXPECT_EQ(r.rs.role(1), Role::SWaiting);
  // Tsprimary restarts at 2 s: the first swap at 4000 ms.
  r.run_to(4000 * kMs - 1);
  EXPECT_EQ(r.rs.role(0), Role::SPrimary);
  r.run_to(4000 * kMs);
  EXPECT_EQ(r.rs.role(0), Role::SWaiting);
  EXPECT_EQ(r.rs.role(1), Role::SPrimary);
  // The next Primary_Request chooses the primary: master 2 at 4500 ms → interface 1 PRIMARY,
  // interface 0 BACKUP 1 ms later; its first Data_Exchange ends the start-up (FreshOutputs).
  r.start(1, 4500 * kMs, 3, kFnPrimaryRequest, 100);
  EXPECT_EQ(r.rs.role(1), Role::Primary);
  r.run_to(4501 * kMs);
  EXPECT_EQ(r.rs.role(0), Role::Backup);
  r.req(1, 4510 * kMs, std::nullopt, {0x21});
  EXPECT_EQ(r.rs.outputs()[0], 0x21);
  const auto fresh = of_kind(r, RedEvent::Kind::FreshOutputs);
  ASSERT_EQ(fresh.size(), 2u);
  EXPECT_EQ(fresh[1].iface, 1);
  EXPECT_EQ(fresh[1].at, 4510 * kMs);
}

TEST(RedundantSlave, AFailedInterfaceStaysFailedAcrossAPowerCycle) {
  Rig r;
  redundant_start(r, 100);
  r.rs.fail_interface(1, 1000 * kMs);
  r.rs.power_off(1100 * kMs);
  EXPECT_EQ(r.rs.role(0), Role::Off);
  EXPECT_EQ(r.rs.role(1), Role::Failed);
  r.rs.power_on(1200 * kMs);
  EXPECT_EQ(r.rs.role(0), Role::SPrimary);
  EXPECT_EQ(r.rs.role(1), Role::Failed);
  EXPECT_EQ(r.req(1, 1210 * kMs, dp::kSapSlaveDiag, {}), Bytes{});
  // Alone, interface 0 still alternates: S_WAITING after Tsprimary (2 s).
  r.run_to(3200 * kMs);
  EXPECT_EQ(r.rs.role(0), Role::SWaiting);
}


TEST(RedundantSlave, MalformedPrmCmdIsAPrmFault) {
  Rig r;
  Bytes p = set_prm(1, kFnPrimaryRequest, 30);
  p[14] = 0x0E;  // Function with Stop_MSAC1S and Start_MSAC1S together
  EXPECT_EQ(r.req(0, kMs, dp::kSapSetPrm, p), Bytes{0xE5});
  EXPECT_EQ(r.rs.engine(0).state(), dp::SlaveState::WaitPrm);
  EXPECT_EQ(r.rs.role(0), Role::SPrimary);
  EXPECT_EQ(hex(r.diag(0, 2 * kMs)).substr(0, 17), "42 05 00 FF 12 34");
}


// --- the IM's own switchover time (seeds-digest §2 S5; 000 L1832) ------------------------------
// With im_switchover_bound = T_SLAVE_UM every switchover after start-up ends no earlier than a
// time drawn uniformly in [T_SLAVE_UM / 2, T_SLAVE_UM] after its trigger; until then the new
// interface is BP_SWITCHOVER (Red_State Backup), answers Data_Exchange, and the backplane holds.

TEST(RedundantSlaveImTime, DrawIsWithinHalfTheBoundAndTheBoundAndReproducible) {
  const bus::Ticks bound = 30 * kMs;  // an IM 153-2-like 30 ms
  bus::Ticks lo = bound, hi = 0;
  for (std::uint64_t n = 0; n < 400; ++n) {
    const bus::Ticks d = draw_im_time(42, n, bound);
    ASSERT_GE(d, 15 * kMs) << n;
    ASSERT_LE(d, 30 * kMs) << n;
    EXPECT_EQ(d, draw_im_time(42, n, bound));  // same seed and count: same time
    lo = std::min(lo, d);
    hi = std::max(hi, d);
  }
  // Spread over the whole interval: 400 uniform draws come within 5 % of either end.
  EXPECT_LT(lo, 16500 * bus::kTicksPerUs);
  EXPECT_GT(hi, 28500 * bus::kTicksPerUs);
  EXPECT_NE(draw_im_time(1, 0, bound), draw_im_time(2, 0, bound));
  EXPECT_EQ(draw_im_time(42, 0, 0), 0);  // no bound: no IM time
  EXPECT_EQ(draw_im_time(42, 0, 1), 1);  // [0, 1] in ticks, bound/2 = 0: 0 or 1
}

/// A rig whose IM needs up to `bound` for a switchover.
RedundantSlaveParams im_params(bus::Ticks bound, std::uint64_t seed) {
  RedundantSlaveParams p;
  p.im_switchover_bound = bound;
  p.im_seed = seed;
  return p;
}

/// The Seq_Nr of the Prm_Cmd_Ack block (08 9E 00 <Seq_Nr << 3> ..., §G.3) in a diagnosis, or -1.
int prm_cmd_ack_seq(std::span<const std::uint8_t> diag) {
  for (std::size_t k = 0; k + 3 < diag.size(); ++k)
    if (diag[k] == 0x08 && diag[k + 1] == 0x9E) return diag[k + 3] >> 3;
  return -1;
}

TEST(RedundantSlaveImTime, CommandedSwitchoverTakesTheDrawnImTimeWithOutputsFrozen) {
  Rig r(im_params(30 * kMs, 7));
  redundant_start(r, 100);  // Output_Hold_Time 1 s
  // The first Primary_Request after power-on is no switchover: PRIMARY at once, nothing drawn.
  EXPECT_TRUE(r.rs.im_switchovers().empty());
  bus::Ticks t = 1000 * kMs;
  for (int k = 0; k < 10; ++k, t += 10 * kMs) r.cycle(t, 0x11);
  ASSERT_EQ(r.rs.outputs()[0], 0x11);
  const bus::Ticks tc = t + 5 * kMs;  // 1105 ms: master 2 commands interface 1
  EXPECT_EQ(r.req(1, tc, dp::kSapSetPrm, set_prm(2, kFnPrimaryRequest, 100)), Bytes{0xE5});
  ASSERT_EQ(r.rs.im_switchovers().size(), 1u);
  const ImSwitchover im = r.rs.im_switchovers()[0];
  EXPECT_EQ(im.iface, 1);
  EXPECT_EQ(im.trigger, tc);
  // T_SLAVE_UM 30 ms: the IM's time lies in [15 ms, 30 ms].
  ASSERT_GE(im.drawn, 15 * kMs);
  ASSERT_LE(im.drawn, 30 * kMs);
  // The link steps end at tc + 2 ms (the old primary is BACKUP at tc + 1 ms), the IM is not
  // ready: interface 1 stays BP_SWITCHOVER, Red_State Backup (bit 0), no Prm_Cmd_Ack yet.
  r.run_to(tc + 2 * kMs);
  EXPECT_EQ(r.rs.role(0), Role::Backup);
  EXPECT_EQ(r.rs.role(1), Role::BpSwitchover);
  EXPECT_EQ(r.rs.primary(), -1);
  EXPECT_TRUE(r.rs.red_state(1).backup);
  EXPECT_FALSE(r.rs.red_state(1).primary);
  EXPECT_TRUE(r.rs.outputs_held());
  // Both masters keep polling with new values every 5 ms: the backplane keeps 0x11 (S1), and
  // interface 1 keeps answering Data_Exchange on line B.
  bus::Ticks p = tc + 3 * kMs;
  for (; p < tc + im.drawn; p += 5 * kMs) {
    r.req(0, p, std::nullopt, {0x22});
    r.req(1, p + kMs / 10, std::nullopt, {0x22});
    EXPECT_EQ(r.last.kind, fdl::Reply::Kind::Data) << p;
    EXPECT_EQ(r.rs.outputs()[0], 0x11) << p;
    EXPECT_EQ(prm_cmd_ack_seq(r.rs.engine(1).current_diag()), 1) << p;  // start-up's
  }
  r.run_to(tc + im.drawn - 1);
  EXPECT_EQ(r.rs.role(1), Role::BpSwitchover);
  r.run_to(tc + im.drawn);  // the IM's time is over: PRIMARY, Prm_Cmd_Ack
  EXPECT_EQ(r.rs.primary(), 1);
  EXPECT_EQ(r.rs.im_switchovers()[0].primary_at, tc + im.drawn);
  EXPECT_EQ(prm_cmd_ack_seq(r.rs.engine(1).current_diag()), 2);  // this command's
  // Its next accepted Data_Exchange ends the hold: switchover (command → fresh outputs) =
  // drawn + the wait for the next poll (< 5 ms), within T_SLAVE_UM + one poll.
  r.req(1, p + kMs / 10, std::nullopt, {0x33});
  EXPECT_EQ(r.rs.outputs()[0], 0x33);
  const auto fresh = of_kind(r, RedEvent::Kind::FreshOutputs);
  ASSERT_FALSE(fresh.empty());
  EXPECT_EQ(fresh.back().iface, 1);
  EXPECT_GE(fresh.back().at - tc, im.drawn);
  EXPECT_LE(fresh.back().at - tc, 30 * kMs + 5 * kMs);
}

TEST(RedundantSlaveImTime, PartnerLostByTheSupervisionThenTheImTime) {
  Rig r(im_params(30 * kMs, 11));
  redundant_start(r, 100);
  for (bus::Ticks t = 1000 * kMs; t < 1100 * kMs; t += 10 * kMs) r.cycle(t, 0x44);
  // Interface 0 (PRIMARY) fails silently at 1095 ms; its last heartbeat left at 1000 ms and
  // arrived at 1001 ms: interface 1 counts it lost at 1301 ms, then needs its IM's time.
  r.rs.fail_interface(0, 1095 * kMs);
  r.line_up[0] = false;
  r.run_to(1301 * kMs);
  ASSERT_EQ(r.rs.im_switchovers().size(), 1u);
  const ImSwitchover im = r.rs.im_switchovers()[0];
  EXPECT_EQ(im.trigger, 1301 * kMs);
  ASSERT_GE(im.drawn, 15 * kMs);
  ASSERT_LE(im.drawn, 30 * kMs);
  EXPECT_EQ(r.rs.role(1), Role::BpSwitchover);
  for (bus::Ticks t = 1305 * kMs; t < 1301 * kMs + im.drawn; t += 5 * kMs) {
    r.cycle(t, 0x55);
    EXPECT_EQ(r.rs.outputs()[0], 0x44) << t;  // frozen, no pulse (hold 1 s)
  }
  r.run_to(1301 * kMs + im.drawn);
  EXPECT_EQ(r.rs.primary(), 1);
  r.cycle(1340 * kMs, 0x55);
  EXPECT_EQ(r.rs.outputs()[0], 0x55);
}

TEST(RedundantSlaveImTime, ASlowImLikeADpPaLinkDominates) {
  // A DP/PA-link-like IM: 820 ms maximum (protocol-facts.md §G.5), in [410 ms, 820 ms].
  Rig r(im_params(820 * kMs, 3));
  redundant_start(r, 100);  // hold 1 s > 820 ms: frozen for the whole switchover
  for (bus::Ticks t = 1000 * kMs; t < 1100 * kMs; t += 10 * kMs) r.cycle(t, 0x66);
  const bus::Ticks tc = 1105 * kMs;
  r.req(1, tc, dp::kSapSetPrm, set_prm(2, kFnPrimaryRequest, 100));
  ASSERT_EQ(r.rs.im_switchovers().size(), 1u);
  const bus::Ticks d = r.rs.im_switchovers()[0].drawn;
  ASSERT_GE(d, 410 * kMs);
  ASSERT_LE(d, 820 * kMs);
  bus::Ticks t = tc + 5 * kMs;
  for (; t < tc + d; t += 10 * kMs) {
    r.cycle(t, 0x77);
    ASSERT_EQ(r.rs.outputs()[0], 0x66) << t;
    ASSERT_EQ(r.rs.primary(), -1) << t;
  }
  r.cycle(t, 0x77);
  EXPECT_EQ(r.rs.primary(), 1);
  EXPECT_EQ(r.rs.outputs()[0], 0x77);
  EXPECT_TRUE(of_kind(r, RedEvent::Kind::OutputHoldExpired).empty());
  // A second switchover draws the next time of the same sequence (count 1).
  const bus::Ticks tc2 = t + 100 * kMs;
  r.req(0, tc2, dp::kSapSetPrm, set_prm(3, kFnPrimaryRequest, 100));
  ASSERT_EQ(r.rs.im_switchovers().size(), 2u);
  EXPECT_EQ(r.rs.im_switchovers()[1].drawn, draw_im_time(3, 1, 820 * kMs));
  EXPECT_EQ(r.rs.im_switchovers()[1].iface, 0);
}

TEST(RedundantSlaveImTime, AutonomousHandOverAtTheWatchdogThenTheImTime) {
  Rig r(im_params(30 * kMs, 5));
  redundant_start(r, 100);
  bus::Ticks t = 1000 * kMs;
  for (int k = 0; k < 10; ++k, t += 10 * kMs) r.cycle(t, 0x21);
  // Master 1 stops after its cycle at 1090 ms: interface 0's watchdog (1 s) expires at 2090 ms,
  // it hands over (BACKUP, take-over sent); the take-over arrives at 2091 ms: the trigger.
  r.line_up[0] = false;
  for (; t < 2200 * kMs; t += 10 * kMs) r.cycle(t, 0x31);
  ASSERT_EQ(r.rs.im_switchovers().size(), 1u);
  const ImSwitchover im = r.rs.im_switchovers()[0];
  EXPECT_EQ(im.iface, 1);
  EXPECT_EQ(im.trigger, 2091 * kMs);
  ASSERT_GE(im.drawn, 15 * kMs);
  ASSERT_LE(im.drawn, 30 * kMs);
  EXPECT_EQ(im.primary_at, 2091 * kMs + im.drawn);
  // Outputs frozen at 0x21 until the first Data_Exchange after primary_at (cycles every 10 ms
  // from 1100 ms: the first at or after primary_at + 0.1 ms on line B).
  const auto fresh = of_kind(r, RedEvent::Kind::FreshOutputs);
  ASSERT_FALSE(fresh.empty());
  EXPECT_GE(fresh.back().at, im.primary_at);
  EXPECT_LT(fresh.back().at, im.primary_at + 10 * kMs + kMs / 10 + 1);
  EXPECT_EQ(r.rs.outputs()[0], 0x31);
}

}  // namespace
}  // namespace pbvbus::redundancy
