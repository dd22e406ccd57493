// The token ring on a real Line + Scheduler (protocol-facts.md §C.2-§C.5): claim, rotation
// timing, GAP polls, ring formation, joining, leaving, token loss, a cut line. Every expectation
// is computed by hand from frame lengths (11 bits per octet) and the bus parameters, in bit
// times at 1.5 Mbit/s (TSL 300, min TSDR 11, TID1 37, TSYN 33).

#include <gtest/gtest.h>

#include <memory>

#include "fdl_station_helpers.hpp"
#include "frame_recorder.hpp"
#include "hex.hpp"
#include "pbvbus/bus/line.hpp"
#include "pbvbus/bus/scheduler.hpp"
#include "pbvbus/fdl/active_station.hpp"
#include "pbvbus/fdl/passive_station.hpp"

namespace pbvbus::fdl {
namespace {

using pbvbus::test::FrameRecorder;
using test::DataSlaveUser;
using test::QueueMasterUser;

constexpr bus::Baud kBaud = bus::Baud::k1_5M;
constexpr bus::Ticks kBit = bus::ticks_per_bit(kBaud);

BusParams ring_params(std::uint8_t hsa, std::uint32_t g, std::uint32_t ttr) {
  BusParams p = BusParams::defaults(kBaud);
  p.hsa = hsa;
  p.gap_factor = g;
  p.ttr = ttr;
  return p;
}

/// Token frames (hex) on the wire, in order.
std::vector<std::string> tokens(const FrameRecorder& rec, std::size_t from = 0) {
  std::vector<std::string> out;
  for (std::size_t i = from; i < rec.size(); ++i)
    if (!rec.frame(i).bytes.empty() && rec.frame(i).bytes[0] == 0xDC) out.push_back(rec.hex(i));
  return out;
}

std::size_t find_frame(const FrameRecorder& rec, const std::string& hex, std::size_t from = 0) {
  for (std::size_t i = from; i < rec.size(); ++i)
    if (rec.hex(i) == hex) return i;
  return rec.size();
}

/// Whether the last `n` tokens on the wire cycle through `ring` (e.g. DC 02 01, DC 03 02, ...).
::testing::AssertionResult ring_is(const FrameRecorder& rec, const std::vector<std::string>& ring,
                                   std::size_t n) {
  const auto t = tokens(rec);
  if (t.size() < n) return ::testing::AssertionFailure() << "only " << t.size() << " tokens";
  std::size_t start = t.size() - n;
  std::size_t k = 0;
  while (k < ring.size() && ring[k] != t[start]) ++k;
  if (k == ring.size()) return ::testing::AssertionFailure() << "token " << t[start] << " not in the ring";
  for (std::size_t i = 0; i < n; ++i) {
    if (t[start + i] != ring[(k + i) % ring.size()])
      return ::testing::AssertionFailure() << "token #" << start + i << " is " << t[start + i]
                                           << ", expected " << ring[(k + i) % ring.size()];
  }
  return ::testing::AssertionSuccess();
}

// --- one master, one slave: exact rotation times --------------------------------------------

TEST(TokenRingTiming, RotationTimeFromFrameLengths) {
  // Master 1, slave 2, HSA 3 (GAP = 2, 3, 0), G = 2, TTR large enough never to limit.
  bus::Scheduler sched;
  bus::Line line{sched, "dp", kBaud};
  FrameRecorder rec;
  line.add_tap(rec);
  const BusParams p = ring_params(3, 2, 20'000);
  QueueMasterUser mu;
  mu.high_per_visit = 1;
  mu.high.da = 2;
  mu.high.fn = RequestFn::SrdHigh;
  mu.high.data = {0xA1, 0xA2, 0xA3, 0xA4};
  DataSlaveUser su({0x11, 0x22});
  ActiveStation master(1, p, mu);
  PassiveStation slave(2, p, su);
  line.attach(master, "master 1");
  line.attach(slave, "slave 2");
  line.start();
  sched.run_until(20 * bus::kTicksPerMs);

  // Claim: TTO of station 1 = 6*300 + 2*1*300 = 2400 bits of silence after power-on.
  ASSERT_GT(rec.size(), 10u);
  EXPECT_EQ(rec.hex(0), "DC 01 01");
  EXPECT_EQ(rec.start_bits(0), 2400);
  EXPECT_EQ(rec.hex(1), "DC 01 01");
  EXPECT_EQ(rec.start_bits(1), 2400 + 33 + 37);  // second claim token TID1 after the first
  // Token receipt at 2503; first request TID1 later: SRD high, first frame (FC 6D).
  // FCS = 02+01+6D+A1+A2+A3+A4 = 0x3FA -> FA.
  EXPECT_EQ(rec.hex(2), "68 07 07 68 02 01 6D A1 A2 A3 A4 FA 16");
  EXPECT_EQ(rec.start_bits(2), 2503 + 37);
  // Reply DL with 2 octets, min TSDR after the request's end (13 octets = 143 bits).
  EXPECT_EQ(rec.hex(3), "68 05 05 68 01 02 08 11 22 3E 16");
  EXPECT_EQ(rec.start_bits(3), 2540 + 143 + 11);
  // GAP poll of address 2 (the first GAP address after TS), TID1 after the reply (121 bits).
  EXPECT_EQ(rec.hex(4), "10 02 01 49 4C 16");
  EXPECT_EQ(rec.start_bits(4), 2694 + 121 + 37);
  EXPECT_EQ(rec.hex(5), "10 01 02 00 03 16");  // a slave
  EXPECT_EQ(rec.hex(6), "DC 01 01");           // alone: token to itself
  EXPECT_EQ(rec.start_bits(6), 2852 + 66 + 11 + 66 + 37);
  // Next visit: the FCB toggles after the valid reply: FCV=1, FCB=0 (FC 5D, FCS EA).
  EXPECT_EQ(rec.hex(7), "68 07 07 68 02 01 5D A1 A2 A3 A4 EA 16");

  // One visit, token receipt t0 to the next token's end:
  //   TID1 37 + request 13*11 = 143 + min TSDR 11 + reply 11*11 = 121 + TID1 37 + token 3*11 = 33
  const std::int64_t base = 37 + 143 + 11 + 121 + 37 + 33;  // = 382
  //   + GAP poll of the slave: TID1 37 + 66 + TSDR 11 + 66 (then the token after TID1 as before)
  const std::int64_t with_slave_poll = base + 37 + 66 + 11 + 66;  // = 562
  //   + GAP poll of an empty address: TID1 37 + 66 + TSL 300, token right at slot expiry
  //     (so no TID1 before the token: subtract it)
  const std::int64_t with_empty_poll = base + 37 + 66 + 300 - 37;  // = 748
  EXPECT_EQ(base, 382);
  EXPECT_EQ(with_slave_poll, 562);
  EXPECT_EQ(with_empty_poll, 748);
  // Visits after the claim: poll 2, poll 3, poll 0, (scan complete) no poll, no poll (G = 2:
  // the completing visit and one more), then poll 2 again... TRR at receipt n = visit n-1.
  const std::vector<std::int64_t> cycle = {with_slave_poll, with_empty_poll, with_empty_poll, base, base};
  const auto samples = master.rotation_samples();
  ASSERT_GT(samples.size(), 20u);
  for (std::size_t i = 0; i < samples.size(); ++i)
    ASSERT_EQ(samples[i], cycle[i % cycle.size()] * kBit) << "rotation sample " << i;
  EXPECT_EQ(master.rotation_min(), base * kBit);
  EXPECT_EQ(master.rotation_max(), with_empty_poll * kBit);

  EXPECT_EQ(master.state() == MacState::Offline, false);
  EXPECT_EQ(master.live(2), StationType::Slave);
  EXPECT_FALSE(master.live(3).has_value());
  EXPECT_FALSE(master.live(0).has_value());
  EXPECT_EQ(master.las(), (std::vector<std::uint8_t>{1}));
  EXPECT_EQ(master.stats().token_losses, 1u);
  EXPECT_EQ(master.stats().no_response, 0u);
  EXPECT_EQ(mu.confirmations.size(), master.stats().requests - (master.state() == MacState::Await_Data_Response ? 1 : 0));
  for (const auto& c : mu.confirmations) {
    ASSERT_EQ(c.result, Confirmation::Result::Ok);
    ASSERT_EQ(c.data, (test::Bytes{0x11, 0x22}));
  }
}

// --- three masters: cold start, joining, leaving, token loss, cut ----------------------------

class ThreeMasters : public ::testing::Test {
 protected:
  void SetUp() override {
    line.add_tap(rec);
    for (int i = 0; i < 3; ++i) {
      masters.push_back(std::make_unique<ActiveStation>(static_cast<std::uint8_t>(i + 1), params, users[i]));
      line.attach(*masters.back(), "master " + std::to_string(i + 1));
    }
  }
  void run_ms(std::int64_t ms) { sched.run_until(sched.now() + ms * bus::kTicksPerMs); }
  ActiveStation& m(int addr) { return *masters[static_cast<std::size_t>(addr - 1)]; }

  const std::vector<std::string> ring123 = {"DC 02 01", "DC 03 02", "DC 01 03"};
  BusParams params = ring_params(4, 1, 20'000);
  bus::Scheduler sched;
  bus::Line line{sched, "dp", kBaud};
  FrameRecorder rec;
  QueueMasterUser users[3];
  std::vector<std::unique_ptr<ActiveStation>> masters;
};

TEST_F(ThreeMasters, ColdStartLowestAddressClaimsAndAdmitsTheOthers) {
  line.start();
  run_ms(50);
  // Station 1 has the shortest TTO (2400 bits) and claims first.
  ASSERT_GT(rec.size(), 6u);
  EXPECT_EQ(rec.hex(0), "DC 01 01");
  EXPECT_EQ(rec.start_bits(0), 2400);
  EXPECT_EQ(rec.hex(1), "DC 01 01");
  // First GAP poll: address 2, which has seen only the two claim tokens: not ready (0x10).
  EXPECT_EQ(rec.hex(2), "10 02 01 49 4C 16");
  EXPECT_EQ(rec.start_bits(2), 2503 + 37);
  EXPECT_EQ(rec.hex(3), "10 01 02 10 13 16");
  EXPECT_EQ(rec.start_bits(3), 2606 + 11);
  // Later poll: station 2 has seen two complete identical rotations and answers ready (0x20);
  // station 1 passes it the token TID1 after the reply.
  const std::size_t ready2 = find_frame(rec, "10 01 02 20 23 16");
  ASSERT_LT(ready2, rec.size());
  EXPECT_EQ(rec.hex(ready2 - 1), "10 02 01 49 4C 16");
  EXPECT_EQ(rec.hex(ready2 + 1), "DC 02 01");
  EXPECT_EQ(rec.start_bits(ready2 + 1), rec.end_bits(ready2) + 37);
  // Station 2 then polls its GAP starting at 3, which answers ready and gets the token.
  EXPECT_EQ(rec.hex(ready2 + 2), "10 03 02 49 4E 16");
  EXPECT_EQ(rec.hex(ready2 + 3), "10 02 03 20 25 16");
  EXPECT_EQ(rec.hex(ready2 + 4), "DC 03 02");
  // Station 3's GAP is 4, 0: it polls 4 (nobody) and passes the token to 1 at slot expiry.
  EXPECT_EQ(rec.hex(ready2 + 5), "10 04 03 49 50 16");
  EXPECT_EQ(rec.hex(ready2 + 6), "DC 01 03");
  EXPECT_EQ(rec.start_bits(ready2 + 6), rec.end_bits(ready2 + 5) + 300);
  EXPECT_TRUE(ring_is(rec, ring123, 30));
  for (int a = 1; a <= 3; ++a) {
    EXPECT_TRUE(m(a).in_ring()) << a;
    EXPECT_EQ(m(a).las(), (std::vector<std::uint8_t>{1, 2, 3})) << a;
  }
  EXPECT_EQ(m(1).next_station(), 2);
  EXPECT_EQ(m(3).next_station(), 1);
  EXPECT_EQ(m(1).previous_station(), 3);
  EXPECT_EQ(m(1).stats().token_losses, 1u);
  EXPECT_EQ(m(2).stats().token_losses, 0u);
  EXPECT_EQ(m(3).stats().token_losses, 0u);
  EXPECT_EQ(m(1).stats().admissions, 1u);
  EXPECT_EQ(m(2).stats().admissions, 1u);
}

TEST_F(ThreeMasters, JoinLaterAndLeaveOnPowerOff) {
  line.set_power(0, true);
  line.set_power(2, true);
  run_ms(30);
  EXPECT_TRUE(ring_is(rec, {"DC 03 01", "DC 01 03"}, 10));
  // Station 2 powers on and is admitted by station 1 (2 lies in 1's GAP).
  line.set_power(1, true);
  run_ms(50);
  EXPECT_TRUE(ring_is(rec, ring123, 30));
  const std::size_t admitted = find_frame(rec, "10 01 02 20 23 16");
  ASSERT_LT(admitted, rec.size());
  EXPECT_EQ(rec.hex(admitted + 1), "DC 02 01");

  // Station 2 loses power. Station 1's pass is tried 3 times, TSL apart, then 2 is dropped.
  const std::size_t before = rec.size();
  line.set_power(1, false);
  run_ms(30);
  std::size_t i = find_frame(rec, "DC 02 01", before);
  ASSERT_LT(i + 3, rec.size());
  // Unless the cut-off hit the token just as it was passed, the three attempts follow each
  // other at token end + TSL (33 + 300 bits), then the token goes to 3.
  while (i + 3 < rec.size() && rec.hex(i + 1) != "DC 02 01") i = find_frame(rec, "DC 02 01", i + 1);
  ASSERT_LT(i + 3, rec.size());
  EXPECT_EQ(rec.hex(i + 1), "DC 02 01");
  EXPECT_EQ(rec.hex(i + 2), "DC 02 01");
  EXPECT_EQ(rec.hex(i + 3), "DC 03 01");
  EXPECT_EQ(rec.start_bits(i + 1), rec.end_bits(i) + 300);
  EXPECT_EQ(rec.start_bits(i + 2), rec.end_bits(i + 1) + 300);
  EXPECT_EQ(rec.start_bits(i + 3), rec.end_bits(i + 2) + 300);
  EXPECT_TRUE(ring_is(rec, {"DC 03 01", "DC 01 03"}, 20));
  EXPECT_EQ(m(1).stats().stations_dropped, 1u);
  EXPECT_EQ(m(1).las(), (std::vector<std::uint8_t>{1, 3}));
}

TEST_F(ThreeMasters, TokenLossAndReclaim) {
  line.start();
  run_ms(50);
  ASSERT_TRUE(ring_is(rec, ring123, 30));
  // Run until station 3 holds the token and is polling its GAP (so station 2 has already seen
  // its pass to 3 succeed), then cut its power: the token is lost with it.
  sched.step();
  while (m(3).state() != MacState::Await_Status_Response || m(2).state() != MacState::Active_Idle)
    sched.step();
  line.set_power(2, false);
  const std::size_t before = rec.size();
  const std::int64_t last_end = rec.end_bits(before - 1);  // station 3's GAP poll
  EXPECT_EQ(rec.frame(before - 1).sender, 2);
  EXPECT_EQ(rec.frame(before - 1).bytes[0], 0x10);
  run_ms(30);
  // Silence; station 1 (TTO 6*300 + 2*1*300 = 2400 bits) claims before station 2 (3000).
  ASSERT_GT(rec.size(), before + 2);
  EXPECT_EQ(rec.hex(before), "DC 01 01");
  EXPECT_EQ(rec.start_bits(before), last_end + 2400);
  EXPECT_EQ(rec.hex(before + 1), "DC 01 01");
  // Station 1 polls 2 (which saw the claim and is out of the ring: ready) and admits it.
  EXPECT_EQ(rec.hex(before + 2), "10 02 01 49 4C 16");
  EXPECT_EQ(rec.hex(before + 3), "10 01 02 20 23 16");
  EXPECT_EQ(rec.hex(before + 4), "DC 02 01");
  EXPECT_TRUE(ring_is(rec, {"DC 02 01", "DC 01 02"}, 20));
  EXPECT_EQ(m(1).stats().token_losses, 2u);  // the cold start and this one
  EXPECT_EQ(m(2).stats().token_losses, 0u);
  EXPECT_EQ(m(1).las(), (std::vector<std::uint8_t>{1, 2}));
  // Station 3 returns and is admitted again.
  line.set_power(2, true);
  run_ms(50);
  EXPECT_TRUE(ring_is(rec, ring123, 30));
}

TEST_F(ThreeMasters, CutLineSplitsIntoTwoRingsAndMergesAfterRepair) {
  line.start();
  run_ms(50);
  ASSERT_TRUE(ring_is(rec, ring123, 30));
  // Cut between station 2 (attachment 1) and station 3 (attachment 2).
  line.set_cut_between(1, 2, true);
  const std::size_t before = rec.size();
  run_ms(50);
  std::vector<std::string> left, right;
  for (std::size_t i = before; i < rec.size(); ++i) {
    if (rec.frame(i).bytes[0] != 0xDC) continue;
    (rec.frame(i).sender == 2 ? right : left).push_back(rec.hex(i));
  }
  ASSERT_GT(left.size(), 20u);
  ASSERT_GT(right.size(), 20u);
  // Left: 1 and 2 keep a ring of two; right: 3 alone, after claiming, passes to itself.
  EXPECT_EQ(left.back() == "DC 02 01" || left.back() == "DC 01 02", true) << left.back();
  for (std::size_t i = left.size() - 10; i < left.size(); ++i)
    EXPECT_TRUE(left[i] == "DC 02 01" || left[i] == "DC 01 02") << left[i];
  for (std::size_t i = right.size() - 10; i < right.size(); ++i) EXPECT_EQ(right[i], "DC 03 03");
  EXPECT_EQ(m(2).stats().stations_dropped, 1u);
  EXPECT_GE(m(3).stats().token_losses, 1u);

  // Repair: the two rings meet; one token survives and the ring 1-2-3 forms again.
  line.set_cut_between(1, 2, false);
  run_ms(100);
  EXPECT_TRUE(ring_is(rec, ring123, 30));
  for (int a = 1; a <= 3; ++a) EXPECT_EQ(m(a).las(), (std::vector<std::uint8_t>{1, 2, 3})) << a;
}

}  // namespace
}  // namespace pbvbus::fdl

namespace pbvbus::fdl {
namespace {

// Noise and random power cycles of masters and slaves; once the faults stop, the ring 1-2-3
// must form again and the slaves must be polled without errors. Several seeds.
class RingRecovery : public ::testing::TestWithParam<std::uint64_t> {};

TEST_P(RingRecovery, RingFormsAgainAfterNoiseAndPowerCycles) {
  const std::uint64_t seed = GetParam();
  bus::Scheduler sched;
  bus::Line line{sched, "dp", kBaud, seed};
  FrameRecorder rec;
  line.add_tap(rec);
  const BusParams p = ring_params(12, 3, 5000);
  QueueMasterUser u[3];
  for (auto& x : u) {
    x.high_per_visit = 1;
    x.high.da = 10;
    x.high.data = {1, 2, 3};
    x.low_per_visit = 2;
    x.low.da = 11;
    x.low.fn = RequestFn::SrdLow;
    x.low.data = {4};
  }
  ActiveStation m1(1, p, u[0]), m2(2, p, u[1]), m3(3, p, u[2]);
  DataSlaveUser s10({1}), s11({2, 3});
  PassiveStation p10(10, p, s10), p11(11, p, s11);
  line.attach(m1);
  line.attach(p10);
  line.attach(m2);
  line.attach(p11);
  line.attach(m3);
  line.start();
  sched.run_until(100 * bus::kTicksPerMs);
  line.set_noise(200'000);  // 2e-4 bit errors per bit
  std::uint64_t r = seed * 7919;
  for (int k = 0; k < 40; ++k) {
    r = r * 6364136223846793005ULL + 1442695040888963407ULL;
    const int att = static_cast<int>((r >> 33) % 5);
    line.set_power(att, !line.powered(att));
    sched.run_until(sched.now() + static_cast<bus::Ticks>((r >> 40) % 20 + 1) * bus::kTicksPerMs);
  }
  line.set_noise(0);
  for (int i = 0; i < 5; ++i) line.set_power(i, true);
  sched.run_until(sched.now() + 300 * bus::kTicksPerMs);
  EXPECT_TRUE(ring_is(rec, {"DC 02 01", "DC 03 02", "DC 01 03"}, 30));
  for (const ActiveStation* m : {&m1, &m2, &m3}) {
    EXPECT_EQ(m->las(), (std::vector<std::uint8_t>{1, 2, 3}));
    EXPECT_TRUE(m->in_ring());
  }
  for (auto& x : u) {
    ASSERT_GT(x.confirmations.size(), 10u);
    for (std::size_t i = x.confirmations.size() - 10; i < x.confirmations.size(); ++i)
      EXPECT_EQ(x.confirmations[i].result, Confirmation::Result::Ok);
  }
  EXPECT_EQ(m1.live(10), StationType::Slave);
  EXPECT_EQ(m1.live(11), StationType::Slave);
}

INSTANTIATE_TEST_SUITE_P(Seeds, RingRecovery, ::testing::Values(1, 2, 3, 4, 5, 6, 7, 8));

}  // namespace
}  // namespace pbvbus::fdl

namespace pbvbus::fdl {
namespace {

// protocol-facts.md §H.2 (MPI trace, S4): a lone PLC at address 2 passes the token to itself
// (DC 02 02) and polls one free address per visit (10 05 02 49 50 16); a PG at address 0 that
// answers "ready" gets the token (DC 00 02) and passes it back (DC 02 00).
TEST(TokenRingMpi, LonePlcPollsAndAdmitsPg) {
  constexpr bus::Baud kMpi = bus::Baud::k187_5;
  bus::Scheduler sched;
  bus::Line line{sched, "mpi", kMpi};
  FrameRecorder rec;
  line.add_tap(rec);
  BusParams p = BusParams::defaults(kMpi);
  p.hsa = 15;
  p.gap_factor = 1;
  p.ttr = 20'000;
  QueueMasterUser plc_user, pg_user;
  ActiveStation plc(2, p, plc_user);
  ActiveStation pg(0, p, pg_user);
  line.attach(plc, "PLC");
  const int pg_att = line.attach(pg, "PG");
  line.set_power(0, true);
  sched.run_until(200 * bus::kTicksPerMs);
  EXPECT_LT(find_frame(rec, "10 05 02 49 50 16"), rec.size());
  EXPECT_TRUE(ring_is(rec, {"DC 02 02"}, 5));
  // The PG joins; its TTO (6*TSL = 600 bits) would be the shortest, but the bus is busy.
  const std::size_t before = rec.size();
  line.set_power(pg_att, true);
  sched.run_until(sched.now() + 400 * bus::kTicksPerMs);
  EXPECT_EQ(pg.stats().token_losses, 0u);
  // Poll of address 0: 00+02+49 = 4B; PG ready: 02+00+20 = 22.
  const std::size_t ready = find_frame(rec, "10 02 00 20 22 16", before);
  ASSERT_LT(ready, rec.size());
  EXPECT_EQ(rec.hex(ready - 1), "10 00 02 49 4B 16");
  EXPECT_EQ(rec.hex(ready + 1), "DC 00 02");
  EXPECT_TRUE(ring_is(rec, {"DC 00 02", "DC 02 00"}, 20));
  EXPECT_EQ(plc.las(), (std::vector<std::uint8_t>{0, 2}));
  EXPECT_EQ(pg.las(), (std::vector<std::uint8_t>{0, 2}));
}

}  // namespace
}  // namespace pbvbus::fdl
