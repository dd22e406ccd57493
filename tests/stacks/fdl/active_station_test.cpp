// ActiveStation message cycles and MAC rules (protocol-facts.md §C.2, §C.3, §C.4, §C.6): retries
// with the same FCB, non-operational marking, SDN and TID2, priorities against the token hold
// time, the slot time with carrier sense, Listen_Token answers, token acceptance and duplicate
// address detection. Times in bit times at 1.5 Mbit/s (TSL 300, min TSDR 11, TID1 37, TID2 150).

#include "pbvbus/fdl/active_station.hpp"

#include <gtest/gtest.h>

#include "fdl_station_helpers.hpp"
#include "frame_recorder.hpp"
#include "hex.hpp"
#include "pbvbus/bus/line.hpp"
#include "pbvbus/bus/scheduler.hpp"
#include "pbvbus/fdl/passive_station.hpp"
#include "recording_port.hpp"

namespace pbvbus::fdl {
namespace {

using pbvbus::test::bytes_from_hex;
using pbvbus::test::FrameRecorder;
using pbvbus::test::RecordingPort;
using pbvbus::test::to_hex;
using test::DataSlaveUser;
using test::QueueMasterUser;
using Result = Confirmation::Result;

constexpr bus::Baud kBaud = bus::Baud::k1_5M;
constexpr bus::Ticks kBit = bus::ticks_per_bit(kBaud);
constexpr bus::Ticks bits(std::int64_t n) { return n * kBit; }

/// A lone master 1 with HSA 1 (its GAP is address 0 only) and G = 100, so that after the first
/// scan no GAP poll disturbs the visits under test.
BusParams lone_params() {
  BusParams p = BusParams::defaults(kBaud);
  p.hsa = 1;
  p.gap_factor = 100;
  p.ttr = 20'000;
  return p;
}

/// A responder that answers requests to `addr` with SC after `delay` bit times (possibly longer
/// than a PassiveStation's max TSDR would allow).
class LateResponder final : public bus::Device {
 public:
  LateResponder(std::uint8_t addr, std::int64_t delay) : m_addr(addr), m_delay(delay) {}
  void on_power_on(bus::Ticks) override {}
  void on_timer(bus::Ticks) override {}
  int receive_filter() const override { return m_addr; }
  void on_frame(const bus::RxFrame& f) override {
    if (!f.intact() || f.bytes.size() < 2 || f.bytes[0] == 0xDC) return;
    const std::uint8_t sc = 0xE5;
    port().transmit(f.end + m_delay * ticks_per_bit(port().baud()), std::span(&sc, 1));
  }

 private:
  std::uint8_t m_addr;
  std::int64_t m_delay;
};

class LoneMaster : public ::testing::Test {
 protected:
  void SetUp() override { line.add_tap(rec); }
  void start() {
    line.attach(master, "master 1");
    line.start();
  }
  void run_ms(std::int64_t ms) { sched.run_until(sched.now() + ms * bus::kTicksPerMs); }

  BusParams params = lone_params();
  bus::Scheduler sched;
  bus::Line line{sched, "dp", kBaud};
  FrameRecorder rec;
  QueueMasterUser user;
  ActiveStation master{1, params, user};
};

TEST_F(LoneMaster, RetryWithSameFcbThenNonOperationalThenBack) {
  DataSlaveUser su({0x11});
  PassiveStation slave(5, params, su);
  user.high_per_visit = 1;
  user.high.da = 5;
  user.high.fn = RequestFn::SrdHigh;
  user.high.data = {0xAA};
  start();
  const int slave_att = line.attach(slave, "slave 5");  // attached unpowered
  run_ms(3);
  // Claim at 2400 and 2470; token receipt 2503; request TID1 later. First frame FC 6D,
  // FCS 05+01+6D+AA = 0x11D -> 1D; 10 octets = 110 bits.
  ASSERT_GT(rec.size(), 7u);
  EXPECT_EQ(rec.hex(2), "68 04 04 68 05 01 6D AA 1D 16");
  EXPECT_EQ(rec.start_bits(2), 2540);
  // No answer within TSL: the repeat (same FCB) starts exactly at slot expiry 2650 + 300.
  EXPECT_EQ(rec.hex(3), "68 04 04 68 05 01 6D AA 1D 16");
  EXPECT_EQ(rec.start_bits(3), 2650 + 300);
  // max_retry = 1: given up at 3060 + 300; then the GAP poll of address 0 and the token.
  EXPECT_EQ(rec.hex(4), "10 00 01 49 4A 16");
  EXPECT_EQ(rec.start_bits(4), 3060 + 300);
  EXPECT_EQ(rec.hex(5), "DC 01 01");
  EXPECT_EQ(rec.start_bits(5), 3426 + 300);
  // Next visit: station 5 is non-operational: first frame again, and no repeat.
  EXPECT_EQ(rec.hex(6), "68 04 04 68 05 01 6D AA 1D 16");
  EXPECT_EQ(rec.start_bits(6), 3759 + 37);
  EXPECT_EQ(rec.hex(7), "DC 01 01");
  EXPECT_EQ(rec.start_bits(7), 3906 + 300);
  ASSERT_GE(user.confirmations.size(), 2u);
  EXPECT_EQ(user.confirmations[0].result, Result::NoResponse);
  EXPECT_EQ(user.confirmations[0].retries, 1u);
  EXPECT_EQ(user.confirmations[0].now, bits(3360));
  EXPECT_EQ(user.confirmations[1].result, Result::NoResponse);
  EXPECT_EQ(user.confirmations[1].retries, 0u);
  EXPECT_TRUE(master.non_operational(5));
  EXPECT_EQ(master.stats().retries, 1u);

  // The slave comes up: it answers the next (first) frame; then the FCB toggles 5D, 7D, 5D.
  line.set_power(slave_att, true);
  const std::size_t from = rec.size();
  user.confirmations.clear();
  run_ms(2);
  std::vector<std::string> reqs;
  for (std::size_t i = from; i < rec.size(); ++i)
    if (rec.frame(i).sender == 0 && rec.frame(i).bytes[0] == 0x68) reqs.push_back(rec.hex(i));
  ASSERT_GE(reqs.size(), 5u);
  std::size_t k = 0;
  while (k < reqs.size() && reqs[k] == "68 04 04 68 05 01 6D AA 1D 16") ++k;  // until answered
  ASSERT_LT(k + 3, reqs.size());
  EXPECT_EQ(reqs[k], "68 04 04 68 05 01 5D AA 0D 16");
  EXPECT_EQ(reqs[k + 1], "68 04 04 68 05 01 7D AA 2D 16");
  EXPECT_EQ(reqs[k + 2], "68 04 04 68 05 01 5D AA 0D 16");
  EXPECT_FALSE(master.non_operational(5));
  ASSERT_FALSE(user.confirmations.empty());
  EXPECT_EQ(user.confirmations.back().result, Result::Ok);
  EXPECT_EQ(user.confirmations.back().data, (test::Bytes{0x11}));
  EXPECT_EQ(user.confirmations.back().type, StationType::Slave);
}

TEST_F(LoneMaster, RepeatKeepsTheFcbWhenOneReplyIsLost) {
  // A responder that stays silent for the 2nd request only: the repeat carries the same FCB.
  class SilentOnce final : public bus::Device {
   public:
    void on_power_on(bus::Ticks) override {}
    void on_timer(bus::Ticks) override {}
    int receive_filter() const override { return 5; }
    void on_frame(const bus::RxFrame& f) override {
      if (f.bytes[0] == 0xDC || ++n == 2) return;
      const std::uint8_t sc = 0xE5;
      port().transmit(f.end + 11 * ticks_per_bit(port().baud()), std::span(&sc, 1));
    }
    int n = 0;
  } slave;
  user.high_per_visit = 1;
  user.high.da = 5;
  user.high.fn = RequestFn::SdaHigh;
  user.high.data = {0xAA};
  start();
  line.attach(slave);
  line.set_power(1, true);
  run_ms(5);
  std::vector<std::string> reqs;
  for (std::size_t i = 0; i < rec.size(); ++i)
    if (rec.frame(i).bytes[0] == 0x68) reqs.push_back(rec.hex(i));
  ASSERT_GE(reqs.size(), 4u);
  // SDA high: first frame 65, then 55 (lost reply), repeat 55, then 75.
  // FCS: 05+01+65+AA = 0x115 -> 15; 55 -> 05; 75 -> 25.
  EXPECT_EQ(reqs[0], "68 04 04 68 05 01 65 AA 15 16");
  EXPECT_EQ(reqs[1], "68 04 04 68 05 01 55 AA 05 16");
  EXPECT_EQ(reqs[2], "68 04 04 68 05 01 55 AA 05 16");
  EXPECT_EQ(reqs[3], "68 04 04 68 05 01 75 AA 25 16");
  ASSERT_GE(user.confirmations.size(), 2u);
  EXPECT_TRUE(user.confirmations[0].short_ack);
  EXPECT_EQ(user.confirmations[1].result, Result::Ok);
  EXPECT_EQ(user.confirmations[1].retries, 1u);
}

TEST_F(LoneMaster, SdnIsConfirmedSentAndFollowedAfterTid2) {
  user.high_per_visit = 1;
  user.high.da = 127;
  user.high.fn = RequestFn::SdnHigh;
  user.high.dsap = 58;
  user.high.ssap = 62;
  user.high.data = {0x02, 0x00};
  start();
  run_ms(5);
  ASSERT_GT(rec.size(), 4u);
  // Appendix 1: Global_Control Clear, broadcast (from master 1).
  EXPECT_EQ(rec.hex(2), "68 07 07 68 FF 81 46 3A 3E 02 00 40 16");
  EXPECT_EQ(rec.start_bits(2), 2540);
  // Unacknowledged: the next frame (the GAP poll of 0) waits TID2 = max TSDR = 150 bits.
  EXPECT_EQ(rec.hex(3), "10 00 01 49 4A 16");
  EXPECT_EQ(rec.start_bits(3), 2540 + 143 + 150);
  ASSERT_FALSE(user.confirmations.empty());
  EXPECT_EQ(user.confirmations[0].result, Result::Sent);
  EXPECT_EQ(master.stats().requests_by_fn[0x6], master.stats().requests);
}

TEST_F(LoneMaster, LongReplyStillArrivingAtSlotExpiryIsAwaited) {
  // 40 data octets: SD2 with LE 43 = 49 octets = 539 bits, far longer than TSL 300. The reply
  // starts 11 bits after the request and is still on the wire when TSL expires.
  test::Bytes data(40);
  for (std::size_t i = 0; i < data.size(); ++i) data[i] = static_cast<std::uint8_t>(i);
  DataSlaveUser su(data);
  PassiveStation slave(2, params, su);
  user.high_per_visit = 1;
  user.high.da = 2;
  user.high.fn = RequestFn::SrdHigh;
  user.high.data = {0xAA};
  start();
  line.attach(slave);
  line.set_power(1, true);
  run_ms(5);
  ASSERT_GT(rec.size(), 4u);
  EXPECT_EQ(rec.frame(3).bytes.size(), 49u);
  EXPECT_EQ(rec.start_bits(3), rec.end_bits(2) + 11);
  EXPECT_EQ(line.stats().collisions, 0u);
  EXPECT_EQ(master.stats().retries, 0u);
  ASSERT_GT(user.confirmations.size(), 3u);
  for (const auto& c : user.confirmations) {
    ASSERT_EQ(c.result, Result::Ok);
    ASSERT_EQ(c.data, data);
  }
  // The next frame goes out TID1 after the reply's end.
  EXPECT_EQ(rec.start_bits(4), rec.end_bits(3) + 37);
}

TEST_F(LoneMaster, ReplyStartingAfterTslCountsAsMissing) {
  params.max_retry = 0;
  ActiveStation m2(1, params, user);
  LateResponder late(5, 310);
  user.high_per_visit = 1;
  user.high.da = 5;
  user.high.fn = RequestFn::SdaHigh;
  user.high.data = {0xAA};
  line.attach(m2);
  line.attach(late);
  line.start();
  run_ms(5);
  ASSERT_GT(rec.size(), 4u);
  EXPECT_EQ(rec.hex(2), "68 04 04 68 05 01 65 AA 15 16");
  // At slot expiry (request end + 300) the master moves on: its GAP poll collides with the SC
  // (which ends first, so the tap lists it first).
  ASSERT_EQ(rec.frame(3).sender, 1);
  EXPECT_NE(rec.frame(3).flags & bus::kRxCollision, 0);
  EXPECT_EQ(rec.start_bits(3), rec.end_bits(2) + 310);
  EXPECT_EQ(rec.frame(4).sender, 0);
  EXPECT_EQ(rec.start_bits(4), rec.end_bits(2) + 300);
  EXPECT_EQ(rec.frame(4).sent_len, 6u);  // the GAP poll 10 00 01 49 4A 16
  ASSERT_FALSE(user.confirmations.empty());
  EXPECT_EQ(user.confirmations[0].result, Result::NoResponse);
}

TEST_F(LoneMaster, ReplyStartingWithinTslIsAccepted) {
  LateResponder late(5, 290);
  user.high_per_visit = 1;
  user.high.da = 5;
  user.high.fn = RequestFn::SdaHigh;
  user.high.data = {0xAA};
  start();
  line.attach(late);
  line.set_power(1, true);
  run_ms(5);
  ASSERT_GT(rec.size(), 4u);
  EXPECT_EQ(rec.hex(3), "E5");
  EXPECT_EQ(rec.start_bits(3), rec.end_bits(2) + 290);
  ASSERT_FALSE(user.confirmations.empty());
  EXPECT_EQ(user.confirmations[0].result, Result::Ok);
  EXPECT_TRUE(user.confirmations[0].short_ack);
  EXPECT_EQ(rec.start_bits(4), rec.end_bits(3) + 37);
}

TEST_F(LoneMaster, CorruptReplyCountsAsMissingAndTheRepeatFollowsTid1AfterIt) {
  // A responder whose reply has a bad FCS (10 01 05 08 0E 16 would be right; it sends 0F).
  class BadFcs final : public bus::Device {
   public:
    void on_power_on(bus::Ticks) override {}
    void on_timer(bus::Ticks) override {}
    int receive_filter() const override { return 5; }
    void on_frame(const bus::RxFrame& f) override {
      if (f.bytes[0] == 0xDC) return;
      const auto b = bytes_from_hex("10 01 05 08 0F 16");
      port().transmit(f.end + 11 * ticks_per_bit(port().baud()), b);
    }
  } slave;
  user.high_per_visit = 1;
  user.high.da = 5;
  user.high.fn = RequestFn::SrdHigh;
  user.high.data = {0xAA};
  start();
  line.attach(slave);
  line.set_power(1, true);
  run_ms(5);
  ASSERT_GT(rec.size(), 6u);
  EXPECT_EQ(rec.hex(2), "68 04 04 68 05 01 6D AA 1D 16");
  EXPECT_EQ(rec.hex(3), "10 01 05 08 0F 16");
  // The repeat: same bytes, TID1 after the corrupt reply's end; then given up (max_retry 1).
  EXPECT_EQ(rec.hex(4), "68 04 04 68 05 01 6D AA 1D 16");
  EXPECT_EQ(rec.start_bits(4), rec.end_bits(3) + 37);
  EXPECT_EQ(rec.hex(5), "10 01 05 08 0F 16");
  EXPECT_EQ(rec.start_bits(6), rec.end_bits(5) + 37);
  ASSERT_FALSE(user.confirmations.empty());
  EXPECT_EQ(user.confirmations[0].result, Result::NoResponse);
  EXPECT_EQ(user.confirmations[0].retries, 1u);
  EXPECT_EQ(master.stats().invalid_replies, 2u + (master.stats().requests - 1));
}

// --- priorities and the token hold time -----------------------------------------------------

struct VisitCounts {
  int high = 0, low = 0, gap = 0;
};

std::vector<VisitCounts> per_visit(const FrameRecorder& rec) {
  std::vector<VisitCounts> v(1);
  for (const auto& f : rec.frames()) {
    if (f.sender != 0) continue;
    if (f.bytes[0] == 0xDC) {
      v.emplace_back();
      continue;
    }
    Telegram t;
    if (decode(f.bytes, t) != DecodeError::None || !t.is_request()) continue;
    const RequestFn fn = fc_request_fn(t.fc);
    if (fn == RequestFn::FdlStatus) ++v.back().gap;
    else if (fn_is_high_priority(fn)) ++v.back().high;
    else ++v.back().low;
  }
  return v;
}

TEST_F(LoneMaster, LowPrioritySuppressedWhenRotationExceedsTtrButOneHighCycleSent) {
  params.ttr = 256;  // any real rotation (>= 382 bits here) exceeds it: TTH <= 0 on arrival
  ActiveStation m2(1, params, user);
  DataSlaveUser su({0x11, 0x22});
  PassiveStation slave(2, params, su);
  user.high_per_visit = 3;  // more high-priority work than may go out
  user.high.da = 2;
  user.high.fn = RequestFn::SrdHigh;
  user.high.data = {1, 2, 3, 4};
  user.low_per_visit = -1;  // unlimited low-priority work
  user.low.da = 2;
  user.low.fn = RequestFn::SrdLow;
  user.low.data = {5, 6};
  line.attach(m2);
  line.attach(slave);
  line.start();
  run_ms(10);
  const auto v = per_visit(rec);
  ASSERT_GT(v.size(), 10u);
  // v[0], v[1]: the claim tokens. From the first visit on: one high cycle, no low cycle.
  for (std::size_t i = 2; i + 1 < v.size(); ++i) {
    EXPECT_EQ(v[i].high, 1) << "visit " << i;
    EXPECT_EQ(v[i].low, 0) << "visit " << i;
  }
  // GAP poll of address 0 still happens in a visit that started with TTH <= 0 (after the one
  // high-priority cycle).
  EXPECT_EQ(v[3].gap, 1);
  for (const auto& [now, trr] : user.tokens)
    if (trr != 0) {
      EXPECT_GE(trr, bits(256));
    }
}

TEST_F(LoneMaster, LowPriorityRunsWhileHoldTimeRemains) {
  params.ttr = 3000;
  ActiveStation m2(1, params, user);
  DataSlaveUser su({0x11, 0x22});
  PassiveStation slave(2, params, su);
  user.high_per_visit = 1;
  user.high.da = 2;
  user.high.fn = RequestFn::SrdHigh;
  user.high.data = {1, 2, 3, 4};
  user.low_per_visit = -1;
  user.low.da = 2;
  user.low.fn = RequestFn::SrdLow;
  user.low.data = {5, 6};
  line.attach(m2);
  line.attach(slave);
  line.start();
  run_ms(40);
  const auto v = per_visit(rec);
  ASSERT_GT(v.size(), 10u);
  // v[i] holds the frames of the visit that began with token receipt user.tokens[i - 2].
  // After the first visits (claim, first GAP scan) the rotation alternates, computed by hand:
  //  - a visit with only the high cycle: TID1 37 + request 13*11 = 143 + TSDR 11 + reply
  //    11*11 = 121 + TID1 37 + token 33 = 382 bits;
  //  - the next visit has TTH = 3000 - 382 = 2618: after the high cycle (ends at 312) low
  //    cycles of 37 + 121 + 11 + 121 = 290 bits start at 349, 639, ..., 2379 (8 cycles; 2669
  //    would be past 2618); the last ends at 2632, the token at 2669 + 33 = 2702 bits;
  //  - then TTH = 3000 - 2702 = 298 < 349: no low cycle, back to 382.
  int checked = 0;
  for (std::size_t i = 4; i + 1 < v.size() && i - 2 < user.tokens.size(); ++i) {
    const bus::Ticks trr = user.tokens[i - 2].second;
    EXPECT_EQ(v[i].high, 1) << "visit " << i;
    if (trr == bits(382)) {
      EXPECT_EQ(v[i].low, 8) << "visit " << i;
      EXPECT_EQ(user.tokens[i - 1].second, bits(2702)) << "visit " << i;
    } else {
      EXPECT_EQ(trr, bits(2702)) << "visit " << i;
      EXPECT_EQ(v[i].low, 0) << "visit " << i;
    }
    ++checked;
  }
  EXPECT_GT(checked, 20);
  // Every low-priority request starts before the visit's hold time ran out:
  // start < receipt + TTH, TTH = TTR - TRR.
  std::size_t tok = 0;
  for (const auto& f : rec.frames()) {
    while (tok + 1 < user.tokens.size() && user.tokens[tok + 1].first <= f.start) ++tok;
    if (f.sender != 0 || f.bytes[0] != 0x68 || user.tokens.empty() || user.tokens[tok].first > f.start) continue;
    if ((f.bytes[6] & 0x0F) != 0x0C) continue;
    const auto [at, trr] = user.tokens[tok];
    EXPECT_LT(f.start, at + bits(3000) - trr);
  }
  // The rotation overshoots TTR by at most one message cycle plus the token.
  for (const auto& [now, trr] : user.tokens) EXPECT_LE(trr, bits(3000 + 37 + 121 + 11 + 121 + 37 + 33));
}

// --- Listen_Token, token acceptance, duplicate address (driven by hand) ---------------------

class HandDriven : public ::testing::Test {
 protected:
  void SetUp() override {
    BusParams p = BusParams::defaults(kBaud);
    p.hsa = 4;
    station = std::make_unique<ActiveStation>(2, p, user);
    port.bind(*station);
    station->on_power_on(0);
  }
  /// Delivers `hex` as a frame ending at bit `end` after `idle` bits of silence.
  void feed(std::string_view hex, std::int64_t end, std::int64_t idle = 1000) {
    const auto b = bytes_from_hex(hex);
    bus::RxFrame f;
    f.bytes = b;
    f.end = bits(end);
    f.start = f.end - bits(11 * static_cast<std::int64_t>(b.size()));
    f.idle_before = bits(idle);
    port.set_now(f.end);
    station->on_frame(f);
  }
  void make_ready() {
    for (int i = 0; i < 4; ++i) feed("DC 01 01", 1000 + 1000 * i);
    ASSERT_TRUE(station->las_valid());
  }

  RecordingPort port{kBaud};
  QueueMasterUser user;
  std::unique_ptr<ActiveStation> station;
};

TEST_F(HandDriven, ListenTokenAnswersNotReadyThenReady) {
  EXPECT_EQ(station->state(), MacState::Listen_Token);
  EXPECT_EQ(to_string(station->state()), "Listen_Token");
  feed("10 02 01 49 4C 16", 500);
  ASSERT_EQ(port.transmit_count(), 1u);
  EXPECT_EQ(to_hex(port.last().bytes), "10 01 02 10 13 16");  // master not ready
  EXPECT_EQ(port.last().start, bits(511));
  // Tokens of a lone master 1: discovery needs two complete identical rotations.
  feed("DC 01 01", 1000);
  feed("DC 01 01", 2000);
  feed("DC 01 01", 3000);
  EXPECT_FALSE(station->las_valid());
  feed("DC 01 01", 4000);
  EXPECT_TRUE(station->las_valid());
  feed("10 02 01 49 4C 16", 5000);
  EXPECT_EQ(to_hex(port.last().bytes), "10 01 02 20 23 16");  // ready to enter the ring
  EXPECT_EQ(station->state(), MacState::Active_Idle);
  EXPECT_EQ(station->previous_station(), 1);
  // The poller passes the token: accepted at once (from PS); first frame TID1 later.
  feed("DC 02 01", 5200);
  EXPECT_EQ(station->state(), MacState::Use_Token);
  EXPECT_EQ(port.timer(), bits(5200 + 37));
  EXPECT_TRUE(station->in_ring());
}

TEST_F(HandDriven, TokenFromStrangerAcceptedOnlyTheSecondTime) {
  make_ready();
  feed("10 02 01 49 4C 16", 5000);
  ASSERT_EQ(station->state(), MacState::Active_Idle);
  feed("DC 02 04", 5200);  // station 4 is not our predecessor
  EXPECT_EQ(station->state(), MacState::Active_Idle);
  feed("DC 02 04", 5600);  // its repeat: accepted, 4 is now PS
  EXPECT_EQ(station->state(), MacState::Use_Token);
  EXPECT_EQ(station->previous_station(), 4);
}

TEST_F(HandDriven, TokenAfterLessThanTsynIgnored) {
  make_ready();
  feed("10 02 01 49 4C 16", 5000);
  feed("DC 02 01", 5200, 32);
  EXPECT_EQ(station->state(), MacState::Active_Idle);
  feed("DC 02 01", 5400, 33);
  EXPECT_EQ(station->state(), MacState::Use_Token);
}

TEST_F(HandDriven, DuplicateAddressLeavesTheRing) {
  make_ready();
  feed("10 02 01 49 4C 16", 5000);
  ASSERT_EQ(station->state(), MacState::Active_Idle);
  // MPI trace frame: FDL Status from a station 2 (not us) to 5. Seen twice: leave.
  feed("10 05 02 49 50 16", 5200);
  EXPECT_EQ(station->state(), MacState::Active_Idle);
  feed("10 05 02 49 50 16", 5400);
  EXPECT_EQ(station->state(), MacState::Listen_Token);
  EXPECT_EQ(station->stats().duplicate_address, 1u);
  EXPECT_FALSE(station->las_valid());
  feed("10 02 01 49 4C 16", 5600);
  EXPECT_EQ(to_hex(port.last().bytes), "10 01 02 10 13 16");
}

TEST_F(HandDriven, AnswersRequestsFromOtherMastersWithItsStationType) {
  class Mm final : public InitiatorUser {
   public:
    bool next_request(Priority, bus::Ticks, Request&) override { return false; }
    void on_confirmation(const Confirmation&) override {}
    void on_request(const Indication& ind, Reply& r) override {
      if (ind.dsap == 54) {
        const std::uint8_t d[] = {0x42};
        r.respond(ResponseStatus::DL, d);
      }
    }
  } mm;
  ActiveStation st(2, BusParams::defaults(kBaud), mm);
  RecordingPort p2{kBaud};
  p2.bind(st);
  st.on_power_on(0);
  // SRD low 1 -> 2, DSAP 54 (MM) SSAP 54, first frame: 68 05 05 68 82 81 6C 36 36 FCS 16,
  // FCS 82+81+6C+36+36 = 0x1DB -> DB. Reply from a master not ready (FC 0x18 = 0x10 | DL):
  // 68 06 06 68 81 82 18 36 36 42 FCS 16, FCS 81+82+18+36+36+42 = 0x1C9 -> C9.
  const auto b = bytes_from_hex("68 05 05 68 82 81 6C 36 36 DB 16");
  bus::RxFrame f;
  f.bytes = b;
  f.end = bits(1000);
  f.start = bits(1000 - 110);
  f.idle_before = bits(500);
  p2.set_now(f.end);
  st.on_frame(f);
  ASSERT_EQ(p2.transmit_count(), 1u);
  EXPECT_EQ(to_hex(p2.last().bytes), "68 06 06 68 81 82 18 36 36 42 C9 16");
  EXPECT_EQ(p2.last().start, bits(1011));
}

}  // namespace
}  // namespace pbvbus::fdl
