// Passive (listen-only) mode of the active station (active_station.hpp; docs/quantum-hsby-dp.md)
// on a real Line + Scheduler at 1.5 Mbit/s (TSL 300, TSYN 33, TID1 37, min TSDR 11): a passive
// station sends nothing over 10 000 token rotations — neither at its own address (never
// admitted, GAP polls unanswered) nor at the active master's address — yet reports every frame
// to its user and shadows the active master's FCB; leaving passive on a silent line claims the
// token TTO after the last frame heard (or at once if that is past) and carries on with the FCB
// the slave expects. Expectations are worked out by hand from frame lengths (11 bit/octet).

#include <gtest/gtest.h>

#include <algorithm>
#include <memory>

#include "fdl_station_helpers.hpp"
#include "frame_recorder.hpp"

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

/// A user that must never be asked for a request while its station is passive, and counts the
/// frames reported to it (with their SAs).
class ObservingUser final : public InitiatorUser {
 public:
  bool next_request(Priority prio, bus::Ticks now, Request& out) override {
    ++asked;
    return inner != nullptr && inner->next_request(prio, now, out);
  }
  void on_confirmation(const Confirmation& c) override {
    if (inner != nullptr) inner->on_confirmation(c);
  }
  void on_token(bus::Ticks now, bus::Ticks trr) override {
    ++tokens;
    if (inner != nullptr) inner->on_token(now, trr);
  }
  void on_observed(bus::Ticks, const Telegram& t) override {
    ++observed;
    if (t.type != FrameType::SC && t.sa == 1) ++observed_from_1;
  }
  InitiatorUser* inner = nullptr;
  int asked = 0;
  int tokens = 0;
  std::uint64_t observed = 0;
  std::uint64_t observed_from_1 = 0;
};

struct Line1 {
  bus::Scheduler sched;
  bus::Line line{sched, "dp", kBaud};
  FrameRecorder rec;
  BusParams p;
  QueueMasterUser mu;
  DataSlaveUser su{{0x11}};
  std::unique_ptr<ActiveStation> master;
  PassiveStation slave;
  bus::AttachmentId att_master = 0;

  explicit Line1(std::uint8_t hsa) : p(params(hsa)), slave(10, p, su) {
    mu.high_per_visit = 1;
    mu.high.da = 10;
    mu.high.fn = RequestFn::SrdHigh;
    mu.high.data = {0x42};
    master = std::make_unique<ActiveStation>(1, p, mu);
    line.add_tap(rec);
    att_master = line.attach(*master, "master 1");
    line.attach(slave, "slave 10");
  }
  static BusParams params(std::uint8_t hsa) {
    BusParams b = BusParams::defaults(kBaud);
    b.hsa = hsa;
    b.gap_factor = 1;
    return b;
  }
  int frames_from(bus::AttachmentId a) const {
    int n = 0;
    for (const auto& f : rec.frames()) n += f.sender == a ? 1 : 0;
    return n;
  }
  void run_rotations(std::uint64_t n) {
    while (master->stats().tokens_received < n) sched.run_until(sched.now() + bus::kTicksPerMs);
  }
};

TEST(FdlPassiveMode, PassiveStationAtItsOwnAddressSendsNothingIn10000Rotations) {
  // Passive station 2 inside master 1's GAP (HSA 3: GAP 2, 3, 0): polled again and again with
  // FDL Status, it never answers and never enters the ring; not one frame carries SA 2.
  Line1 l(3);
  ObservingUser ou;
  ActiveStation passive(2, l.p, ou);
  passive.set_passive(true, 0);
  const auto att = l.line.attach(passive, "passive 2");
  l.line.start();
  l.run_rotations(10'000);

  int sa2 = 0;
  std::uint64_t intact = 0;
  for (std::size_t i = 0; i < l.rec.size(); ++i) {
    const auto& b = l.rec.frame(i).bytes;
    intact += l.rec.frame(i).intact() ? 1 : 0;
    if (b.size() >= 6 && b[0] == 0x10 && (b[2] & 0x7F) == 2) ++sa2;  // SD1 SA
    if (b.size() >= 3 && b[0] == 0xDC && (b[2] & 0x7F) == 2) ++sa2;  // SD4 SA
    if (b.size() >= 7 && b[0] == 0x68 && (b[5] & 0x7F) == 2) ++sa2;  // SD2 SA
  }
  EXPECT_EQ(sa2, 0);
  EXPECT_EQ(l.frames_from(att), 0);
  EXPECT_GT(l.master->stats().gap_polls, 1000u);
  EXPECT_EQ(l.master->las(), std::vector<std::uint8_t>{1});
  EXPECT_EQ(l.master->stats().admissions, 0u);
  EXPECT_EQ(ou.asked, 0);
  EXPECT_EQ(ou.tokens, 0);
  EXPECT_EQ(passive.stats().tokens_passed, 0u);
  EXPECT_EQ(passive.stats().requests_answered, 0u);
  EXPECT_EQ(passive.stats().token_losses, 0u);
  // Every intact frame on the line was reported (the line's noise is off).
  EXPECT_EQ(ou.observed, intact);
  EXPECT_EQ(passive.stats().frames_observed, intact);
  EXPECT_TRUE(passive.passive());
  // It tracked the LAS from the tokens it heard.
  EXPECT_TRUE(passive.las_valid());
  EXPECT_EQ(passive.las(), std::vector<std::uint8_t>{1});
}

TEST(FdlPassiveMode, PassiveStationAtTheActiveMastersAddressSendsNothingAndShadowsTheFcb) {
  Line1 l(3);
  ObservingUser ou;
  ActiveStation passive(1, l.p, ou);
  passive.set_passive(true, 0);
  const auto att = l.line.attach(passive, "master 1 (passive)");
  l.line.start();
  l.run_rotations(10'000);
  EXPECT_EQ(l.frames_from(att), 0);
  // Each rotation: at least the request and the token (and a GAP poll every other visit).
  EXPECT_GT(l.frames_from(l.att_master), 20'000);
  // Its frames with SA 1 are the active master's, not a duplicate address, on either side.
  EXPECT_EQ(passive.stats().duplicate_address, 0u);
  EXPECT_EQ(l.master->stats().duplicate_address, 0u);
  EXPECT_EQ(l.master->stats().duplicate_token, 0u);
  EXPECT_EQ(ou.observed_from_1, static_cast<std::uint64_t>(l.frames_from(l.att_master)));
  EXPECT_EQ(ou.asked, 0);
  // FCB towards slave 10: the same state as the active master's, at any point.
  EXPECT_NE(l.master->fcb_state(10), 0);
  EXPECT_EQ(passive.fcb_state(10), l.master->fcb_state(10));
  l.sched.run_until(l.sched.now() + 137 * kBit);
  l.sched.run_until(l.sched.now() + 211 * kBit);
  EXPECT_EQ(passive.fcb_state(10), l.master->fcb_state(10));
}

TEST(FdlPassiveMode, LeavingPassiveOnASilentLineClaimsAfterTtoAndContinuesTheFcb) {
  Line1 l(1);  // HSA 1: no GAP addresses besides 0
  QueueMasterUser mu2;
  mu2.high_per_visit = 1;
  mu2.high.da = 10;
  mu2.high.fn = RequestFn::SrdHigh;
  mu2.high.data = {0x43};
  ActiveStation standby(1, l.p, mu2);
  standby.set_passive(true, 0);
  const auto att = l.line.attach(standby, "master 1 (standby)");
  l.line.start();
  l.sched.run_until(10 * bus::kTicksPerMs);
  l.line.set_power(l.att_master, false);
  const bus::Ticks off = l.sched.now();
  std::size_t last = l.rec.size();
  while (last > 0 && l.rec.frame(last - 1).bytes.empty()) --last;  // a stub reaches no one
  ASSERT_GT(last, 0u);
  l.sched.run_until(off + 100 * kBit);  // a reply in flight may still finish
  last = 0;
  for (std::size_t i = 0; i < l.rec.size(); ++i)
    if (!l.rec.frame(i).bytes.empty()) last = i;
  const bus::Ticks quiet_from = l.rec.frame(last).end;
  // The active master's last completed cycle with slave 10 on the wire (request SA 1 → 10,
  // then an intact reply 10 → 1) decides the FCB of the next one: toggled.
  std::uint8_t last_fc = 0;
  for (std::size_t i = 0; i + 1 <= last; ++i) {
    const auto& q = l.rec.frame(i).bytes;
    const auto& r = l.rec.frame(i + 1).bytes;
    if (l.rec.frame(i).intact() && l.rec.frame(i + 1).intact() && q.size() == 10 && q[0] == 0x68 &&
        q[4] == 10 && q[5] == 1 && r.size() == 10 && r[4] == 1 && r[5] == 10)
      last_fc = q[6];
  }
  ASSERT_TRUE(last_fc == 0x5D || last_fc == 0x7D || last_fc == 0x6D);
  const bool next_fcb_0 = last_fc != 0x5D;  // after FCB 1 (7D, or the first frame 6D) comes 0
  const bus::Ticks take = l.sched.now();
  standby.set_passive(false, take);
  EXPECT_EQ(standby.state(), MacState::Listen_Token);
  l.sched.run_until(take + 5 * bus::kTicksPerMs);

  // TTO(1) = 6·300 + 2·1·300 = 2400 bit of silence after the last frame heard.
  const bus::Ticks claim_at = std::max(take, quiet_from + 2400 * kBit);
  ASSERT_GT(l.rec.size(), last + 4);
  EXPECT_EQ(l.rec.frame(last + 1).sender, att);
  EXPECT_EQ(l.rec.hex(last + 1), "DC 01 01");
  EXPECT_EQ(l.rec.frame(last + 1).start, claim_at);
  EXPECT_EQ(l.rec.hex(last + 2), "DC 01 01");
  EXPECT_EQ(l.rec.frame(last + 2).start, claim_at + (33 + 37) * kBit);
  // First request TID1 after the second claim token: FCV=1 and the FCB the active master would
  // have sent next (FCB 0: FC 5D, FCB 1: FC 7D); FCS = 0A + 01 + FC + 43.
  const std::string expect =
      next_fcb_0 ? "68 04 04 68 0A 01 5D 43 AB 16" : "68 04 04 68 0A 01 7D 43 CB 16";
  EXPECT_EQ(l.rec.hex(last + 3), expect);
  EXPECT_EQ(l.rec.frame(last + 3).start, claim_at + (33 + 37 + 33 + 37) * kBit);
  EXPECT_EQ(l.rec.hex(last + 4), "68 04 04 68 01 0A 08 11 24 16");  // 01+0A+08+11 = 24
  EXPECT_EQ(standby.stats().token_losses, 1u);
  EXPECT_EQ(standby.stats().retries, 0u);
  EXPECT_TRUE(standby.in_ring());
}

TEST(FdlPassiveMode, GoingPassiveWhileHoldingTheRingStopsAllTraffic) {
  Line1 l(3);
  l.line.start();
  l.sched.run_until(5 * bus::kTicksPerMs);
  ASSERT_TRUE(l.master->in_ring());
  const bus::Ticks t = l.sched.now();
  l.master->set_passive(true, t);
  l.sched.run_until(t + 1 * bus::kTicksPerMs);  // a frame in flight (and its reply) ends
  const std::size_t n = l.rec.size();
  l.sched.run_until(t + 50 * bus::kTicksPerMs);
  EXPECT_EQ(l.rec.size(), n);
  EXPECT_FALSE(l.master->in_ring());
  // Back to active: it claims the silent line again.
  const auto losses = l.master->stats().token_losses;
  l.master->set_passive(false, l.sched.now());
  l.sched.run_until(l.sched.now() + 5 * bus::kTicksPerMs);
  EXPECT_EQ(l.master->stats().token_losses, losses + 1);
  EXPECT_TRUE(l.master->in_ring());
}

}  // namespace
}  // namespace pbvbus::fdl
