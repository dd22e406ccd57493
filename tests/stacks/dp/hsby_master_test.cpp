// A hot-standby pair of DP master modules on one line at 1.5 Mbit/s (docs/quantum-hsby-dp.md):
// two fdl::ActiveStation + dp::Master at address 1, one active, one passive (listen-only,
// standby), and three DP slaves with a 50 ms watchdog whose outputs are a counter. The active
// module loses power; the passive one takes over. Checked on the wire, byte by byte, with the
// bytes and times worked out here: the claim DC 01 01 twice, then the first Data_Exchange to
// each slave with the FCB the slave expects (the old master's last one toggled) and the outputs
// the slave holds; the takeover time in bit times; every slave stays in data exchange (no
// watchdog expiry, outputs never 0, no Set_Prm). Also: a take_over while the old master still
// runs (misuse) is resolved by the MAC's duplicate-address rule, and a slave the shadow does
// not see in data exchange is started up normally.
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
#include "pbvbus/fdl/telegram.hpp"

namespace pbvbus::dp {
namespace {

using pbvbus::test::FrameRecorder;
using Bytes = std::vector<std::uint8_t>;

constexpr bus::Baud kBaud = bus::Baud::k1_5M;
constexpr bus::Ticks kBit = bus::ticks_per_bit(kBaud);
constexpr bus::Ticks kMs = bus::kTicksPerMs;
const std::vector<std::uint8_t> kSlaves{10, 11, 12};

// Hand-computed line timing at 1.5 Mbit/s with the DP-profile defaults (protocol-facts.md §C.1):
// TSL = 300, TSYN = 33, TSM = 2 + 2·TSET + TQUI = 4, TID1 = max(TSYN + TSM, min TSDR) = 37,
// TTO(1) = 6·TSL + 2·1·TSL = 2400 t_bit; a character is 11 t_bit.
constexpr std::int64_t kTid1 = 37;
constexpr std::int64_t kTto1 = 6 * 300 + 2 * 1 * 300;
constexpr std::int64_t kTokenBits = 3 * 11;  // DC 01 01
constexpr std::int64_t kDxBits = 10 * 11;    // 68 04 04 68 DA SA FC out FCS 16
constexpr std::int64_t kMinTsdr = 11;        // the slaves' TSDR after Set_Prm (min_tsdr = 11)
// Claim (§C.4): DC TS TS at t, again TID1 after its end; the second one is the token receipt,
// and the first request starts TID1 after its end.
constexpr std::int64_t kClaimToFirstRequest = kTokenBits + kTid1 + kTokenBits + kTid1;  // 140

SlaveParams slave_params(std::uint8_t a) {
  SlaveParams p;
  p.address = a;
  p.ident = 0x1234;
  p.wd_fact_1 = 1;  // watchdog 10 ms · 1 · 5 = 50 ms
  p.wd_fact_2 = 5;
  p.modules = {{{0x10}, "DI 8"}, {{0x20}, "DO 8"}};
  return p;
}
SlaveConfig slave_config() {
  SlaveConfig c;
  c.ident = 0x1234;
  c.modules = {{{0x10}, "DI 8"}, {{0x20}, "DO 8"}};
  return c;
}

std::string hex(const Bytes& b) {
  static const char* d = "0123456789ABCDEF";
  std::string s;
  for (auto v : b) {
    if (!s.empty()) s += ' ';
    s += d[v >> 4];
    s += d[v & 15];
  }
  return s;
}
/// SD2 Data_Exchange request 1 → da with one output octet, FCS = DA + SA + FC + data.
std::string dx_request(std::uint8_t da, std::uint8_t fc, std::uint8_t out) {
  const auto fcs = static_cast<std::uint8_t>(da + 1 + fc + out);
  return hex({0x68, 0x04, 0x04, 0x68, da, 0x01, fc, out, fcs, 0x16});
}

struct Pair {
  bus::Scheduler sched;
  bus::Line line{sched, "dp", kBaud};
  FrameRecorder rec;
  fdl::BusParams bp;
  std::unique_ptr<Master> ma, mb;  // rack A (active at first), rack B (standby)
  std::unique_ptr<fdl::ActiveStation> sa, sb;
  bus::AttachmentId att_a = 0, att_b = 0;
  std::vector<std::unique_ptr<SlaveEngine>> engines;
  std::vector<std::unique_ptr<fdl::PassiveStation>> slaves;
  std::vector<bus::AttachmentId> slave_att;
  std::vector<MasterEvent> events_b;
  std::uint8_t counter = 0;
  bool outputs_ever_zero = false;
  bool left_dx = false;

  Pair() {
    bp = fdl::BusParams::defaults(kBaud);
    bp.hsa = 12;
    line.add_tap(rec);
    std::vector<SlaveParams> sp;
    for (auto a : kSlaves) sp.push_back(slave_params(a));
    MasterParams mp;
    ma = std::make_unique<Master>(mp, sp);
    mp.standby = true;
    mb = std::make_unique<Master>(mp, sp);
    mb->set_event_handler([this](const MasterEvent& e) { events_b.push_back(e); });
    sa = std::make_unique<fdl::ActiveStation>(1, bp, *ma);
    sb = std::make_unique<fdl::ActiveStation>(1, bp, *mb);
    sb->set_passive(true, 0);
    att_a = line.attach(*sa, "master 1 (rack A)");
    att_b = line.attach(*sb, "master 1 (rack B)");
    for (auto a : kSlaves) {
      engines.push_back(std::make_unique<SlaveEngine>(slave_config()));
      slaves.push_back(std::make_unique<fdl::PassiveStation>(a, bp, *engines.back()));
      slave_att.push_back(line.attach(*slaves.back(), "slave " + std::to_string(a)));
    }
    line.start();
  }

  /// Runs to `until` in 100 µs steps; at each whole ms the application of the active module
  /// (`writer`, may be null) writes the next counter value (1..255, never 0) to every slave's
  /// outputs. After `watch_from` every slave must stay in data exchange with outputs ≠ 0.
  void run(bus::Ticks until, Master* writer, bus::Ticks watch_from) {
    while (sched.now() < until) {
      const bus::Ticks next = std::min(until, (sched.now() / (kMs / 10) + 1) * (kMs / 10));
      if (writer != nullptr && next % kMs == 0) {
        counter = static_cast<std::uint8_t>(counter % 255 + 1);
        for (auto a : kSlaves) writer->image(a).write_outputs(1, Bytes{counter});
      }
      sched.run_until(next);
      if (sched.now() < watch_from) continue;
      for (auto& e : engines) {
        Bytes o(1);
        e->application().read_outputs(1, o);
        outputs_ever_zero = outputs_ever_zero || o[0] == 0;
        left_dx = left_dx || e->state() != SlaveState::DataExch;
      }
    }
  }
  int events_b_of(MasterEvent::Kind k) const {
    int n = 0;
    for (const auto& e : events_b) n += e.kind == k ? 1 : 0;
    return n;
  }
};

/// The FC of the last Data_Exchange request 1 → da before frame `upto` that got an intact reply
/// from da (the cycle the slave completed, so its stored FCB).
std::uint8_t last_completed_dx_fc(const FrameRecorder& rec, std::size_t upto, std::uint8_t da) {
  std::uint8_t fc = 0;
  for (std::size_t i = 0; i + 1 <= upto; ++i) {
    const auto& q = rec.frame(i).bytes;
    const auto& r = rec.frame(i + 1).bytes;
    if (!rec.frame(i).intact() || !rec.frame(i + 1).intact()) continue;
    if (q.size() == 10 && q[0] == 0x68 && q[4] == da && q[5] == 0x01 && r.size() == 10 &&
        r[0] == 0x68 && r[4] == 0x01 && r[5] == da)
      fc = q[6];
  }
  return fc;
}
std::uint8_t last_completed_dx_out(const FrameRecorder& rec, std::size_t upto, std::uint8_t da) {
  std::uint8_t out = 0;
  for (std::size_t i = 0; i + 1 <= upto; ++i) {
    const auto& q = rec.frame(i).bytes;
    const auto& r = rec.frame(i + 1).bytes;
    if (!rec.frame(i).intact() || !rec.frame(i + 1).intact()) continue;
    if (q.size() == 10 && q[0] == 0x68 && q[4] == da && q[5] == 0x01 && r.size() == 10 &&
        r[4] == 0x01 && r[5] == da)
      out = q[7];
  }
  return out;
}

/// Power loss of rack A at `loss`, take_over of rack B at `take`; the whole wire check.
void takeover_case(bus::Ticks loss, bus::Ticks take) {
  Pair p;
  p.run(loss, p.ma.get(), 20 * kMs);
  ASSERT_FALSE(p.left_dx);
  for (auto a : kSlaves) {
    ASSERT_EQ(p.ma->slave_state(a), SlaveStatusState::DataExchange);
    EXPECT_TRUE(p.mb->shadow_in_dx(a)) << int(a);
    // The passive station shadows the active one's FCB towards each slave.
    EXPECT_EQ(p.sb->fcb_state(a), p.sa->fcb_state(a)) << int(a);
  }
  std::vector<std::uint64_t> set_prm_before;
  for (auto& e : p.engines) set_prm_before.push_back(e->stats().set_prm);
  EXPECT_EQ(p.mb->hsby_stats().takeovers, 0u);
  EXPECT_GT(p.mb->hsby_stats().dx_observed, 30u);

  p.line.set_power(p.att_a, false);
  p.run(take, nullptr, 0);
  p.mb->take_over(p.sched.now());
  p.sb->set_passive(false, p.sched.now());
  // Rack B's application writes again only after its first cycle; the last value settles.
  p.run(take + 5 * kMs, nullptr, 0);
  p.run(take + 20 * kMs, p.mb.get(), 0);
  p.run(take + 22 * kMs, nullptr, 0);

  // Until the claim the line is silent after the last frame in flight at the power loss
  // (rack A's frame, maybe cut short, or a slave's reply finishing).
  std::size_t claim = 0;
  while (claim < p.rec.size() && p.rec.frame(claim).sender != p.att_b) ++claim;
  ASSERT_LT(claim + 2 + 2 * kSlaves.size(), p.rec.size());
  ASSERT_GT(claim, 0u);
  // A frame cut within its first character delivers nothing to a receiver (the line hands
  // over whole characters): such a stub does not reload anyone's TTO.
  std::size_t last = claim - 1;
  while (last > 0 && p.rec.frame(last).bytes.empty()) --last;
  const bus::Ticks quiet_from = p.rec.frame(last).end;
  EXPECT_LE(p.rec.frame(last).start, loss + kMinTsdr * kBit);
  // The claim: after TTO of silence, but not before the takeover (the station listened all
  // along, so a line already silent for TTO is claimed at once).
  const bus::Ticks claim_at = std::max(take, quiet_from + kTto1 * kBit);
  EXPECT_EQ(claim_at == take, take >= quiet_from + kTto1 * kBit);
  EXPECT_EQ(p.rec.hex(claim), "DC 01 01");
  EXPECT_EQ(p.rec.frame(claim).start, claim_at);
  EXPECT_EQ(p.rec.hex(claim + 1), "DC 01 01");
  EXPECT_EQ(p.rec.frame(claim + 1).start, claim_at + (kTokenBits + kTid1) * kBit);

  // The first Data_Exchange to each slave, in configuration order, back to back: FCV = 1 and
  // the FCB toggled from rack A's last completed cycle (7D ↔ 5D), the outputs rack A last sent.
  bus::Ticks at = claim_at + kClaimToFirstRequest * kBit;
  for (std::size_t k = 0; k < kSlaves.size(); ++k) {
    const std::uint8_t a = kSlaves[k];
    const std::uint8_t old_fc = last_completed_dx_fc(p.rec, last, a);
    ASSERT_TRUE(old_fc == 0x7D || old_fc == 0x5D) << int(a);
    const std::uint8_t fc = old_fc == 0x7D ? 0x5D : 0x7D;
    const std::uint8_t out = last_completed_dx_out(p.rec, last, a);
    EXPECT_NE(out, 0);
    const std::size_t i = claim + 2 + 2 * k;
    EXPECT_EQ(p.rec.hex(i), dx_request(a, fc, out)) << int(a);
    EXPECT_EQ(p.rec.frame(i).start, at) << int(a);
    // The slave answers in data exchange (DL, its one input octet) after min TSDR.
    ASSERT_EQ(p.rec.frame(i + 1).bytes.size(), 10u);
    EXPECT_EQ(p.rec.frame(i + 1).bytes[6], 0x08) << int(a);
    EXPECT_EQ(p.rec.frame(i + 1).start, at + (kDxBits + kMinTsdr) * kBit);
    at += (kDxBits + kMinTsdr + kDxBits + kTid1) * kBit;
  }
  // Takeover time: from the power loss to the first Data_Exchange of rack B.
  const bus::Ticks takeover = p.rec.frame(claim + 2).start - loss;
  EXPECT_EQ(takeover, claim_at - loss + kClaimToFirstRequest * kBit);

  // Every slave stayed in data exchange: no watchdog expiry, no Set_Prm, outputs never 0, and
  // they follow rack B's counter now.
  EXPECT_FALSE(p.left_dx);
  EXPECT_FALSE(p.outputs_ever_zero);
  for (std::size_t k = 0; k < kSlaves.size(); ++k) {
    EXPECT_EQ(p.engines[k]->stats().watchdog_expiries, 0u);
    EXPECT_EQ(p.engines[k]->stats().set_prm, set_prm_before[k]);
    Bytes o(1);
    p.engines[k]->application().read_outputs(1, o);
    EXPECT_EQ(o[0], p.counter);
    EXPECT_EQ(p.mb->slave_state(kSlaves[k]), SlaveStatusState::DataExchange);
    EXPECT_TRUE(p.mb->image(kSlaves[k]).data_valid());
  }
  EXPECT_EQ(p.mb->hsby_stats().takeovers, 1u);
  EXPECT_EQ(p.mb->hsby_stats().resumed, 3u);
  EXPECT_EQ(p.mb->hsby_stats().restarted, 0u);
  EXPECT_EQ(p.events_b_of(MasterEvent::Kind::StationFailure), 0);
  EXPECT_TRUE(p.sb->in_ring());
  EXPECT_FALSE(p.sb->passive());
}

TEST(DpHsbyMaster, TakeoverFiveMsAfterThePowerLossKeepsEverySlaveInDataExchange) {
  // The pair detects the failure 5 ms later: the line has been silent for more than TTO, so the
  // claim goes out at the takeover.
  takeover_case(30 * kMs, 35 * kMs);
}

TEST(DpHsbyMaster, ImmediateTakeoverWaitsForTtoOfSilence) {
  // Takeover at the very tick of the power loss: the claim waits until the line has been
  // silent for TTO (from the end of the last frame, cut short or not). The loss falls at 40
  // points 13 t_bit apart (across whole message cycles: requests cut short, replies after it).
  for (int k = 0; k < 40; ++k) {
    SCOPED_TRACE(k);
    const bus::Ticks loss = 30 * kMs + k * 13 * kBit;
    takeover_case(loss, loss);
  }
}

TEST(DpHsbyMaster, TakeoverWhileTheOldMasterRunsIsResolvedByTheDuplicateAddressRule) {
  // Misuse: rack B leaves standby while rack A is alive. Rack B's station sees frames with its
  // own SA (a duplicate address, §C): it stays in Listen_Token and never claims on the busy
  // line, so it sends nothing and rack A keeps the slaves. When rack A dies, rack B claims after
  // TTO and resumes the slaves it shadowed up to the takeover.
  Pair p;
  p.run(30 * kMs, p.ma.get(), 20 * kMs);
  p.mb->take_over(p.sched.now());
  p.sb->set_passive(false, p.sched.now());
  p.run(60 * kMs, p.ma.get(), 20 * kMs);
  int from_b = 0;
  for (const auto& f : p.rec.frames()) from_b += f.sender == p.att_b ? 1 : 0;
  EXPECT_EQ(from_b, 0);
  EXPECT_EQ(p.sb->state(), fdl::MacState::Listen_Token);
  EXPECT_GT(p.sb->stats().duplicate_address, 0u);
  EXPECT_EQ(p.sb->stats().token_losses, 0u);
  EXPECT_FALSE(p.left_dx);
  EXPECT_EQ(p.sa->stats().duplicate_address, 0u);

  p.line.set_power(p.att_a, false);
  p.run(90 * kMs, p.mb.get(), 0);
  EXPECT_EQ(p.sb->stats().token_losses, 1u);
  EXPECT_FALSE(p.left_dx);
  EXPECT_FALSE(p.outputs_ever_zero);
  for (auto& e : p.engines) EXPECT_EQ(e->stats().watchdog_expiries, 0u);
  EXPECT_EQ(p.mb->hsby_stats().resumed, 3u);
  for (auto a : kSlaves) EXPECT_EQ(p.mb->slave_state(a), SlaveStatusState::DataExchange);
}

TEST(DpHsbyMaster, PassiveMasterSendsNothingAndHoldsNoRequests) {
  Pair p;
  p.run(40 * kMs, p.ma.get(), 20 * kMs);
  int from_b = 0;
  for (const auto& f : p.rec.frames()) from_b += f.sender == p.att_b ? 1 : 0;
  EXPECT_EQ(from_b, 0);
  fdl::Request r;
  EXPECT_FALSE(p.mb->next_request(fdl::Priority::High, p.sched.now(), r));
  EXPECT_TRUE(p.mb->standby());
  EXPECT_GT(p.mb->hsby_stats().frames_observed, 100u);
  EXPECT_EQ(p.sb->stats().tokens_passed, 0u);
  EXPECT_EQ(p.sb->stats().requests_answered, 0u);
  // The standby's image holds what rack A last sent (the slaves' outputs) and the inputs seen.
  for (std::size_t k = 0; k < kSlaves.size(); ++k) {
    Bytes mine(1), slave(1);
    p.mb->image(kSlaves[k]).read_outputs(1, mine);
    p.engines[k]->application().read_outputs(1, slave);
    EXPECT_EQ(mine, slave);
    EXPECT_FALSE(p.mb->image(kSlaves[k]).data_valid());
  }
}

TEST(DpHsbyMaster, SlaveNotInDataExchangeInTheShadowIsStartedUp) {
  // Slave 12 is off while rack A starts up; rack B never sees it in data exchange. It is powered
  // on just before the takeover: rack B starts it up normally (Slave_Diag first frame, Set_Prm,
  // Chk_Cfg, ...), and resumes 10 and 11 directly.
  Pair p;
  p.line.set_power(p.slave_att[2], false);
  p.run(30 * kMs, p.ma.get(), bus::kNever);
  EXPECT_FALSE(p.mb->shadow_in_dx(12));
  EXPECT_TRUE(p.mb->shadow_in_dx(10));
  p.line.set_power(p.att_a, false);
  p.line.set_power(p.slave_att[2], true);
  p.run(35 * kMs, nullptr, bus::kNever);
  p.mb->take_over(p.sched.now());
  p.sb->set_passive(false, p.sched.now());
  p.run(60 * kMs, p.mb.get(), bus::kNever);
  EXPECT_EQ(p.mb->hsby_stats().resumed, 2u);
  EXPECT_EQ(p.mb->hsby_stats().restarted, 1u);
  EXPECT_EQ(p.mb->slave_state(12), SlaveStatusState::DataExchange);
  EXPECT_EQ(p.engines[2]->stats().set_prm, 1u);
  EXPECT_EQ(p.engines[0]->stats().watchdog_expiries, 0u);
  EXPECT_EQ(p.engines[1]->stats().watchdog_expiries, 0u);
  EXPECT_EQ(p.events_b_of(MasterEvent::Kind::DataExchangeEntered), 1);
}

}  // namespace
}  // namespace pbvbus::dp
