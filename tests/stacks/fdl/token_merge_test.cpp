// Two logical rings meeting after a repaired cable cut (docs/fdl-stations.md "Two rings meet"):
// the stations and traffic of examples/multimaster.textproto (masters 1, 2, 3; slaves 10-14;
// 1.5 Mbit/s, TSL 300, min TSDR 11, TID1 37, TTR 30000, HSA 126), built directly on a Line.
// Rule under test (IEC 61158-4-3 token procedures): a station that holds the token, or has just
// passed it, and receives a valid frame it did not expect concludes that a second token exists
// and gives its own up; afterwards exactly one token circulates and the stations of the other
// ring re-enter through the survivor's GAP polls (one address per token receipt). All times in
// bit times since the repair.
#include <gtest/gtest.h>

#include <memory>
#include <set>
#include <string>

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

constexpr bus::Baud kBaud = bus::Baud::k1_5M;
constexpr bus::Ticks kBit = bus::ticks_per_bit(kBaud);

struct Poll {
  std::uint8_t da;
  RequestFn fn;
  std::size_t len;
};

class PollListUser final : public InitiatorUser {
 public:
  explicit PollListUser(std::vector<Poll> p) : polls(std::move(p)) {}
  bool next_request(Priority prio, bus::Ticks, Request& out) override {
    while (m_next < polls.size()) {
      const Poll& p = polls[m_next];
      const bool high = p.fn == RequestFn::SrdHigh || p.fn == RequestFn::SdaHigh;
      if (high != (prio == Priority::High)) {
        if (prio == Priority::High) {
          // Look further for a high one.
          for (std::size_t i = m_next; i < polls.size(); ++i) {
            const bool h = polls[i].fn == RequestFn::SrdHigh || polls[i].fn == RequestFn::SdaHigh;
            if (h && !m_done[i]) {
              m_done[i] = true;
              fill(polls[i], out);
              return true;
            }
          }
          return false;
        }
      }
      if (m_done[m_next]) {
        ++m_next;
        continue;
      }
      m_done[m_next] = true;
      fill(p, out);
      ++m_next;
      return true;
    }
    return false;
  }
  void on_confirmation(const Confirmation&) override {}
  void on_token(bus::Ticks, bus::Ticks) override {
    m_next = 0;
    m_done.assign(polls.size(), false);
  }
  std::vector<Poll> polls;

 private:
  void fill(const Poll& p, Request& out) {
    out.da = p.da;
    out.fn = p.fn;
    out.data.assign(p.len, 0x5A);
  }
  std::size_t m_next = 0;
  std::vector<bool> m_done;
};

struct Example {
  Example() {
    params.ttr = 30000;
    line.add_tap(rec);
    line.attach(m1, "master 1");   // attachment 0
    line.attach(p10, "slave 10");  // 1
    line.attach(p11, "slave 11");  // 2
    line.attach(m2, "master 2");   // 3
    line.attach(p12, "slave 12");  // 4
    line.attach(p13, "slave 13");  // 5
    line.attach(p14, "slave 14");  // 6
    line.attach(m3, "master 3");   // 7
  }
  /// Cut between slave 14 and master 3 from `cut` to `repair`, then run `after` more.
  void run(bus::Ticks cut, bus::Ticks repair, bus::Ticks after) {
    line.start();
    sched.run_until(cut);
    line.set_cut_between(6, 7, true);
    sched.run_until(repair);
    line.set_cut_between(6, 7, false);
    sched.run_until(repair + after);
  }
  static bool ring12(std::uint16_t sender) { return sender == 0 || sender == 3; }
  std::int64_t bits_since(bus::Ticks t, bus::Ticks repair) const { return (t - repair) / kBit; }

  BusParams params = BusParams::defaults(kBaud);
  bus::Scheduler sched;
  bus::Line line{sched, "A", kBaud};
  FrameRecorder rec;
  PollListUser u1{{{10, RequestFn::SrdLow, 8}, {11, RequestFn::SrdLow, 8}}};
  PollListUser u2{{{12, RequestFn::SrdHigh, 32}, {10, RequestFn::SdaLow, 4}}};
  PollListUser u3{{{13, RequestFn::SrdLow, 4}, {14, RequestFn::SrdLow, 4}}};
  DataSlaveUser s10{test::Bytes(8, 1)}, s11{test::Bytes(8, 2)}, s12{test::Bytes(32, 3)},
      s13{test::Bytes(4, 4)}, s14{test::Bytes(16, 5)};
  ActiveStation m1{1, params, u1}, m2{2, params, u2}, m3{3, params, u3};
  PassiveStation p10{10, params, s10}, p11{11, params, s11, 30}, p12{12, params, s12},
      p13{13, params, s13}, p14{14, params, s14};
};

std::size_t first_from(const FrameRecorder& rec, bus::Ticks from, const std::string& hex) {
  for (std::size_t i = 0; i < rec.size(); ++i)
    if (rec.frame(i).start >= from && rec.hex(i) == hex) return i;
  return rec.size();
}

TEST(TokenMerge, ExampleRepairLeavesOneTokenAndTheGapPollMergesTheRings) {
  // The example's own times: cut at 2 s, repair at 3 s.
  Example x;
  const bus::Ticks repair = 3 * bus::kTicksPerSecond;
  x.run(2 * bus::kTicksPerSecond, repair, 100 * bus::kTicksPerMs);
  const FrameRecorder& rec = x.rec;

  // The first intact frame after the repair: master 3's SRD to 14 (13 octets, 143 bits),
  // starting at 695. Every frame before it collided (both sides were sending when the cable
  // joined them).
  std::size_t first = rec.size();
  for (std::size_t i = 0; i < rec.size(); ++i)
    if (rec.frame(i).start >= repair && rec.frame(i).intact()) {
      first = i;
      break;
    }
  ASSERT_LT(first, rec.size());
  EXPECT_EQ(rec.frame(first).sender, 7);
  EXPECT_EQ(rec.hex(first), "68 07 07 68 0E 03 6C 5A 5A 5A 5A E5 16");
  EXPECT_EQ(x.bits_since(rec.frame(first).start, repair), 695);
  const bus::Ticks heard = rec.frame(first).end;  // 695 + 143 = 838
  EXPECT_EQ(x.bits_since(heard, repair), 838);

  // Master 3 admits master 1 with the GAP poll of address 1. Its GAP walk was at 70 at the
  // repair (poll 10 46 03 49 at 1112); one address per token receipt, and a rotation of the
  // lone master with both slaves answering and nobody at the polled address is
  //   token 33 + TID1 37 + SRD 143 + TSDR 11 + reply 143 + TID1 37 + SRD 143 + TSDR 11
  //   + reply 275 + TID1 37 + FDL Status 66 + TSL 300 = 1236 bits.
  // Address 1 is the 59th poll (70..126 are 57, then 0, 1): 1112 + 58 * 1236 = 72 800; the
  // "ready" answer follows min TSDR after it (72 800 + 66 + 11 = 72 877) and the token to 1
  // TID1 after that (72 877 + 66 + 37 = 72 980).
  const std::size_t poll1 = first_from(rec, repair, "10 01 03 49 4D 16");
  ASSERT_LT(poll1 + 2, rec.size());
  EXPECT_EQ(x.bits_since(rec.frame(poll1).start, repair), 72'800);
  EXPECT_EQ(rec.hex(poll1 + 1), "10 03 01 20 24 16");
  EXPECT_EQ(x.bits_since(rec.frame(poll1 + 1).start, repair), 72'877);
  EXPECT_EQ(rec.hex(poll1 + 2), "DC 01 03");
  EXPECT_EQ(x.bits_since(rec.frame(poll1 + 2).start, repair), 72'980);

  // Bound from the rule: the token of ring 1-2 is given up at the first foreign frame its
  // stations hear intact. Master 1 had just passed the token (DC 02 01 at 599, destroyed by
  // master 3's frame) and was checking the pass when master 3's SRD arrived: no frame of
  // master 1 or 2 starts after the end of that frame (838) until master 3 polls master 1.
  for (std::size_t i = 0; i < poll1; ++i) {
    const auto& f = rec.frame(i);
    if (f.start < repair || !Example::ring12(f.sender)) continue;
    EXPECT_LT(f.start, heard) << "master at attachment " << f.sender << " sent " << rec.hex(i)
                              << " at " << x.bits_since(f.start, repair);
  }
  // One token from then on: every token frame until the merge is DC 03 03, 1236 bits apart.
  std::int64_t prev = -1;
  int lone = 0;
  for (std::size_t i = first; i < poll1; ++i) {
    if (rec.frame(i).bytes[0] != 0xDC) continue;
    EXPECT_EQ(rec.hex(i), "DC 03 03") << x.bits_since(rec.frame(i).start, repair);
    const std::int64_t at = x.bits_since(rec.frame(i).start, repair);
    if (prev >= 0) {
      EXPECT_EQ(at - prev, 1236);
    }
    prev = at;
    ++lone;
  }
  // 1478 (the poll of 70 at 1112, then 66 + TSL 300), 2714, ..., 1478 + 57 * 1236 = 71 930.
  EXPECT_EQ(lone, 58);
  EXPECT_EQ(prev, 71'930);
  // Nobody counted a duplicate token: master 1 gave its token up as the sender checking a pass
  // (activity within TSL ends Check_Token_Pass), master 2 never received it, and master 3 never
  // heard an intact frame of ring 1-2 while holding.
  EXPECT_EQ(x.m1.stats().duplicate_token + x.m2.stats().duplicate_token, 0u);
  EXPECT_EQ(x.m3.stats().duplicate_token, 0u);

  // Then 1 admits 2 in turn, and one ring 1 -> 2 -> 3 -> 1 runs (the last 20 ms).
  std::set<std::string> tokens;
  for (std::size_t i = poll1 + 2; i < rec.size(); ++i)
    if (rec.frame(i).bytes[0] == 0xDC && rec.frame(i).start > repair + 80 * bus::kTicksPerMs)
      tokens.insert(rec.hex(i));
  EXPECT_EQ(tokens, (std::set<std::string>{"DC 01 03", "DC 02 01", "DC 03 02"}));
  for (const ActiveStation* m : {&x.m1, &x.m2, &x.m3})
    EXPECT_EQ(m->las(), (std::vector<std::uint8_t>{1, 2, 3})) << int(m->address());
}

TEST(TokenMerge, LoneHolderHearingTheOtherRingGivesUpItsToken) {
  // A repair 194 bits later in the rotation (cut at 200 ms, repair at 400 ms + 194 bits): now
  // master 3 holds its token when the first intact frame of ring 1-2 (master 2's token
  // DC 01 02) reaches it. By the rule it drops its token at the end of that frame, so no frame
  // of master 3 starts after that until master 2's GAP poll of address 3 admits it.
  Example x;
  const bus::Ticks repair = 400 * bus::kTicksPerMs + 194 * kBit;
  x.run(200 * bus::kTicksPerMs, repair, 400 * bus::kTicksPerMs);
  const FrameRecorder& rec = x.rec;
  std::size_t foreign = rec.size();
  for (std::size_t i = 0; i < rec.size(); ++i)
    if (rec.frame(i).start >= repair && rec.frame(i).intact() && rec.frame(i).sender != 7) {
      foreign = i;
      break;
    }
  ASSERT_LT(foreign, rec.size());
  EXPECT_EQ(rec.hex(foreign), "DC 01 02");
  const bus::Ticks heard = rec.frame(foreign).end;
  const std::size_t poll3 = first_from(rec, repair, "10 03 02 49 4E 16");
  ASSERT_LT(poll3 + 2, rec.size());
  EXPECT_EQ(rec.hex(poll3 + 2), "DC 03 02");
  for (std::size_t i = 0; i < poll3; ++i) {
    const auto& f = rec.frame(i);
    if (f.start < repair || f.sender != 7) continue;
    EXPECT_LT(f.start, heard) << "master 3 sent " << rec.hex(i) << " at "
                              << x.bits_since(f.start, repair);
  }
  EXPECT_EQ(x.m3.stats().duplicate_token, 1u);
  // One token from the first foreign frame on: no DC 03 03 any more, only ring 1-2's tokens
  // until 3 is admitted, then ring 1-2-3.
  for (std::size_t i = foreign; i < poll3; ++i) {
    if (rec.frame(i).bytes[0] == 0xDC) {
      EXPECT_TRUE(rec.hex(i) == "DC 01 02" || rec.hex(i) == "DC 02 01") << rec.hex(i);
    }
  }
  std::set<std::string> tokens;
  for (std::size_t i = poll3 + 2; i < rec.size(); ++i)
    if (rec.frame(i).bytes[0] == 0xDC && rec.frame(i).start > repair + 380 * bus::kTicksPerMs)
      tokens.insert(rec.hex(i));
  EXPECT_EQ(tokens, (std::set<std::string>{"DC 01 03", "DC 02 01", "DC 03 02"}));
  for (const ActiveStation* m : {&x.m1, &x.m2, &x.m3})
    EXPECT_EQ(m->las(), (std::vector<std::uint8_t>{1, 2, 3})) << int(m->address());
}

}  // namespace
}  // namespace pbvbus::fdl
