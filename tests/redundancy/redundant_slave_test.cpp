// The slave side of a switched station (protocol-facts.md §G; seeds-digest.md §2, S1, S2, F10,
// F24): start-up alternation, commanded and autonomous switchover over the internal link,
// supervision, Output_Hold_Time and "no pulse" at the backplane, with exact virtual times and
// octets written out by hand from §G.2/§G.3. Two masters (1 on line A, 2 on line B) are played
// by hand through each interface's ResponderUser, one DP cycle every 10 ms on each line.
#include <gtest/gtest.h>

#include <algorithm>
#include <optional>

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

TEST(RedundantSlave, MalformedPrmCmdIsAPrmFault) {
  Rig r;
  Bytes p = set_prm(1, kFnPrimaryRequest, 30);
  p[14] = 0x0E;  // Function with Stop_MSAC1S and Start_MSAC1S together
  EXPECT_EQ(r.req(0, kMs, dp::kSapSetPrm, p), Bytes{0xE5});
  EXPECT_EQ(r.rs.engine(0).state(), dp::SlaveState::WaitPrm);
  EXPECT_EQ(r.rs.role(0), Role::SPrimary);
  EXPECT_EQ(hex(r.diag(0, 2 * kMs)).substr(0, 17), "42 05 00 FF 12 34");
}

}  // namespace
}  // namespace pbvbus::redundancy
