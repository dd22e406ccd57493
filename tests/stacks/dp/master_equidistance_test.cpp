// DP master equidistance (constant bus cycle time T_DP, docs/dp-equidistance.md) on a real line
// at 12 Mbit/s: fdl::ActiveStation + dp::Master and one DP slave (1 octet in, 1 out). Every time
// below is worked out by hand in bit times from the frame sizes (11 bits per octet) and the
// 12 Mbit/s bus parameters (protocol-facts.md §C.1): TSL = 1000, min TSDR = 11,
// TID1 = max(TSYN 33 + TSM (2 + 2·TSET 16 + TQUI 9 = 43), min TSDR 11) = 76.
#include <gtest/gtest.h>

#include <memory>
#include <string>
#include <vector>

#include "frame_recorder.hpp"
#include "pbvbus/bus/line.hpp"
#include "pbvbus/bus/scheduler.hpp"
#include "pbvbus/dp/master.hpp"
#include "pbvbus/dp/slave_engine.hpp"
#include "pbvbus/fdl/active_station.hpp"
#include "pbvbus/fdl/passive_station.hpp"

namespace pbvbus::dp {
namespace {

using pbvbus::test::FrameRecorder;

constexpr bus::Baud kBaud = bus::Baud::k12M;
constexpr bus::Ticks kBit = bus::ticks_per_bit(kBaud);
// Frames (octets × 11 bits).
constexpr std::int64_t kDxReq = 10 * 11;  // SD2 68 04 04 68 DA SA FC out FCS 16
constexpr std::int64_t kDxRes = 10 * 11;  // SD2 with the 1 input octet
constexpr std::int64_t kToken = 3 * 11;   // SD4 DC DA SA
constexpr std::int64_t kStatus = 6 * 11;  // SD1 10 DA SA FC FCS 16 (FDL Status request)
constexpr std::int64_t kTsl = 1000, kTsdr = 11, kTid1 = 76;

struct Bench {
  bus::Scheduler sched;
  bus::Line line{sched, "dp", kBaud};
  FrameRecorder rec;
  fdl::BusParams bp;
  std::unique_ptr<Master> master;
  std::unique_ptr<fdl::ActiveStation> station;
  std::unique_ptr<SlaveEngine> engine;
  std::unique_ptr<fdl::PassiveStation> slave;
  bus::AttachmentId slave_att{};

  explicit Bench(std::int64_t t_dp_bits) {
    bp = fdl::BusParams::defaults(kBaud);
    bp.hsa = 12;
    bp.gap_factor = 100;  // one GAP scan (12 visits), then 100 visits without GAP polls
    line.add_tap(rec);
    MasterParams mp;
    mp.equidistant_cycle = t_dp_bits * kBit;
    SlaveParams sp;
    sp.address = 10;
    sp.ident = 0x1234;
    sp.modules = {{{0x10}, "DI 8"}, {{0x20}, "DO 8"}};
    master = std::make_unique<Master>(mp, std::vector<SlaveParams>{sp});
    station = std::make_unique<fdl::ActiveStation>(mp.address, bp, *master);
    line.attach(*station, "master 1");
    SlaveConfig sc;
    sc.ident = 0x1234;
    sc.modules = sp.modules;
    engine = std::make_unique<SlaveEngine>(sc);
    slave = std::make_unique<fdl::PassiveStation>(10, bp, *engine);
    slave_att = line.attach(*slave, "slave 10");
    line.start();
  }
  void run_until_bits(std::int64_t bits) { sched.run_until(bits * kBit); }
  /// Index of the first frame sent by master 1 that is a request (the first Global_Control).
  std::size_t first_gc() const {
    for (std::size_t i = 0; i < rec.size(); ++i)
      if (rec.hex(i).rfind("68 07 07 68 FF 81", 0) == 0) return i;
    return rec.size();
  }
  /// Frames that are Data_Exchange requests to slave 10 (SD2, 1 output octet, no SAPs).
  std::vector<std::size_t> dx_requests() const {
    std::vector<std::size_t> out;
    for (std::size_t i = 0; i < rec.size(); ++i) {
      const std::string h = rec.hex(i);
      if (h.rfind("68 04 04 68 0A 01 ", 0) == 0) out.push_back(i);
    }
    return out;
  }
};

TEST(DpMasterEquidistance, PassesStartAtMultiplesOfTdp) {
  // T_DP = 1 ms = 12 000 bit times at 12 Mbit/s.
  constexpr std::int64_t kTdp = 12'000;
  Bench b(kTdp);
  b.run_until_bits(40 * kTdp);
  ASSERT_EQ(b.master->slave_state(10), SlaveStatusState::DataExchange);
  const std::size_t gc = b.first_gc();
  ASSERT_LT(gc, b.rec.size());
  const std::int64_t t0 = b.rec.start_bits(gc);  // grid origin: the first pass
  const auto dx = b.dx_requests();
  ASSERT_GE(dx.size(), 30u);
  for (std::size_t k = 0; k < dx.size(); ++k) {
    const std::int64_t s = b.rec.start_bits(dx[k]);
    EXPECT_EQ((s - t0) % kTdp, 0) << "Data_Exchange " << k << " at " << s;
    if (k > 0) {
      EXPECT_EQ(s - b.rec.start_bits(dx[k - 1]), kTdp) << k;
    }
  }
  const auto& eq = b.master->equidistance();
  EXPECT_EQ(eq.period, kTdp * kBit);
  EXPECT_EQ(eq.overruns, 0u);
  EXPECT_EQ(eq.missed, 0u);
  EXPECT_EQ(eq.max_lateness, 0);
  EXPECT_EQ(eq.jitter, 0);
  EXPECT_GE(eq.intervals, 30u);
  EXPECT_EQ(eq.interval_min, kTdp * kBit);
  EXPECT_EQ(eq.cycles, eq.intervals + 1);
}

TEST(DpMasterEquidistance, TheGapHoldsTheTokenWithFdlStatusToItself) {
  constexpr std::int64_t kTdp = 12'000;
  Bench b(kTdp);
  b.run_until_bits(40 * kTdp);
  const auto dx = b.dx_requests();
  ASSERT_GE(dx.size(), 30u);
  // Cycle 25: the GAP scan (12 visits) is over, the next Global_Control is 60 ms away.
  const std::size_t i = dx[25];
  const std::int64_t s = b.rec.start_bits(i);
  // DX request at S, reply TSDR after its end, token to itself TID1 after the reply, received
  // at its end; TID1 later the station has nothing to send: active pause, FDL Status requests
  // to itself (no answer: each takes 66 + TSL = 1066 bits) while one still fits before S + T_DP:
  // S + 416 + 1066·j + 1066 ≤ S + 12 000 → j = 0..9; then silence (924 bits) until S + T_DP.
  const std::int64_t reply = s + kDxReq + kTsdr;
  const std::int64_t token = reply + kDxRes + kTid1;
  const std::int64_t pause0 = token + kToken + kTid1;
  EXPECT_EQ(pause0 - s, 416);
  ASSERT_EQ(b.rec.start_bits(i + 1), reply);
  EXPECT_EQ(b.rec.hex(i + 1), "68 04 04 68 01 0A 08 00 13 16");
  ASSERT_EQ(b.rec.start_bits(i + 2), token);
  EXPECT_EQ(b.rec.hex(i + 2), "DC 01 01");
  for (int j = 0; j < 10; ++j) {
    const std::size_t f = i + 3 + static_cast<std::size_t>(j);
    // FC 0x49 = request FDL Status; FCS = 01 + 01 + 49 = 4B.
    EXPECT_EQ(b.rec.hex(f), "10 01 01 49 4B 16") << j;
    EXPECT_EQ(b.rec.start_bits(f), pause0 + j * (kStatus + kTsl)) << j;
  }
  EXPECT_EQ(pause0 + 10 * (kStatus + kTsl), s + kTdp - 924);
  EXPECT_EQ(i + 13, dx[26]);  // nothing else before the next cycle
  EXPECT_EQ(b.rec.start_bits(dx[26]), s + kTdp);
  EXPECT_GT(b.station->stats().pause_frames, 0u);
  EXPECT_EQ(b.station->stats().duplicate_address, 0u);  // its own pause frames are no duplicate
}

TEST(DpMasterEquidistance, AMissingReplyMakesAnOverrun) {
  // T_DP = 1500 bits (125 µs, above the slave's Min_Slave_Interval of 100 µs = 1200 bits): a
  // clean cycle (DX 307 + token 33 + TID1 76 = 416) fits, with one FDL Status to itself
  // (416 + 1066 = 1482 ≤ 1500) and 18 bits of silence. A cycle whose Data_Exchange is not
  // answered takes 110 + TSL + repeat 110 + TSL = 2220, then the token (33) and TID1 (76): the
  // next pass starts at S + 2329, due at S + 1500: an overrun, late by 829 bits.
  constexpr std::int64_t kTdp = 1500;
  Bench b(kTdp);
  b.run_until_bits(60 * kTdp);  // start-up and the GAP scan are over; the next scan is 100 away
  auto dx = b.dx_requests();
  ASSERT_GE(dx.size(), 2u);
  const std::int64_t last = b.rec.start_bits(dx.back());
  EXPECT_EQ(last - b.rec.start_bits(dx[dx.size() - 2]), kTdp);
  const std::size_t prev = dx[dx.size() - 2];
  EXPECT_EQ(b.rec.hex(prev + 3), "10 01 01 49 4B 16");
  EXPECT_EQ(b.rec.start_bits(prev + 3), last - kTdp + 416);
  EXPECT_EQ(prev + 4, dx.back());
  const auto before = b.master->equidistance();
  EXPECT_EQ(before.jitter, 0);
  // The slave goes silent just before the next cycle S = last + T_DP.
  const std::int64_t s = last + kTdp;
  b.run_until_bits(s - 1);
  b.line.set_power(b.slave_att, false);
  b.run_until_bits(s + 2329 + 1);
  const auto& eq = b.master->equidistance();
  EXPECT_EQ(eq.overruns, before.overruns + 1);
  EXPECT_EQ(eq.missed, before.missed);
  EXPECT_EQ(eq.last_lateness, (2 * (kDxReq + kTsl) + kToken + kTid1 - kTdp) * kBit);
  EXPECT_EQ(eq.last_lateness, 829 * kBit);
  EXPECT_GE(eq.max_lateness, 829 * kBit);
  EXPECT_EQ(eq.last_start, (s + 2329) * kBit);
  EXPECT_EQ(b.master->slave_state(10), SlaveStatusState::NotPresent);
  EXPECT_EQ(eq.jitter, 0);  // the late start is not a jitter sample
}

TEST(DpMasterEquidistance, TheActivePauseKeepsASecondMasterFromClaimingTheToken) {
  // A second master at address 2 (a DP master in Stop), listening for its admission (the GAP
  // scan that admits it comes only after 100 visits here). Its TTO is 6·TSL + 2·2·TSL = 10 000
  // bit times of silence, less than T_DP = 12 000: a silent pause of a whole cycle would make
  // it claim the token. The active pause never leaves the line silent for more than TSL + the
  // passive rest (< 66 + TSL = 1066 bit times).
  constexpr std::int64_t kTdp = 12'000;
  Bench b(kTdp);
  MasterParams mp2;
  mp2.address = 2;
  mp2.initial_mode = MasterMode::Stop;
  Master m2(mp2, {});
  fdl::ActiveStation st2(2, b.bp, m2);
  b.line.attach(st2, "master 2");
  b.run_until_bits(40 * kTdp);
  EXPECT_EQ(b.station->stats().token_losses, 1u);  // its own claim at power-on
  EXPECT_EQ(st2.stats().token_losses, 0u);          // never claimed
  EXPECT_EQ(st2.stats().tokens_passed, 0u);
  EXPECT_EQ(b.station->stats().duplicate_token, 0u);
  EXPECT_GT(b.station->stats().pause_frames, 300u);  // 39 clean cycles × 10, less the GAP's
  ASSERT_EQ(b.master->slave_state(10), SlaveStatusState::DataExchange);
  const auto& eq = b.master->equidistance();
  EXPECT_EQ(eq.overruns, 0u);
  EXPECT_EQ(eq.jitter, 0);
  EXPECT_GE(eq.intervals, 30u);
}

TEST(DpMasterEquidistance, OffByDefault) {
  MasterParams mp;
  EXPECT_EQ(mp.equidistant_cycle, 0);
  Master m(mp, {});
  EXPECT_EQ(m.equidistance().period, 0);
  EXPECT_EQ(m.pause_until(0), 0);
}

}  // namespace
}  // namespace pbvbus::dp
