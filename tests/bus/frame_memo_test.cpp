// The line hands every receiver and tap of one transmission the same FrameMemo slot, empty for
// each new transmission (docs/architecture.md "Decode once per frame").

#include <gtest/gtest.h>

#include <array>
#include <vector>

#include "pbvbus/bus/line.hpp"

namespace pbvbus::bus {
namespace {

constexpr Ticks kBit = 303;  // 12 Mbit/s
const void* const kOwner = &kOwner;

struct Sender final : Device {
  void on_power_on(Ticks) override {}
  void on_frame(const RxFrame&) override {}
  void on_timer(Ticks) override {}
  void send(Ticks at) { port().transmit(at, frame); }
  std::array<std::uint8_t, 6> frame{0x10, 2, 1, 0x49, 0x4C, 0x16};
};

/// Records each frame's memo and, like fdl::decode_once(), stores an entry the first time.
struct Reader final : Device {
  void on_power_on(Ticks) override {}
  void on_frame(const RxFrame& f) override {
    memos.push_back(f.memo);
    found.push_back(f.memo != nullptr && f.memo->find(kOwner, f.bytes) != nullptr);
    if (f.memo != nullptr && !found.back()) f.memo->store(kOwner, f.bytes);
  }
  void on_timer(Ticks) override {}
  std::vector<FrameMemo*> memos;
  std::vector<bool> found;
};

struct MemoTap final : Tap {
  void on_frame(const TapFrame& f) override {
    memos.push_back(f.memo);
    found.push_back(f.memo != nullptr && f.memo->find(kOwner, f.bytes) != nullptr);
  }
  std::vector<FrameMemo*> memos;
  std::vector<bool> found;
};

TEST(FrameMemo, ReceiversAndTapsShareOneSlotPerTransmission) {
  Scheduler sched;
  Line line(sched, "A", Baud::k12M);
  Sender tx;
  Reader a, b;
  MemoTap tap;
  line.attach(tx);
  line.attach(a);
  line.attach(b);
  line.add_tap(tap, ProbePoint{0});
  line.start();
  tx.send(100 * kBit);
  sched.run_until(kTicksPerMs);
  ASSERT_EQ(a.memos.size(), 1u);
  ASSERT_EQ(b.memos.size(), 1u);
  ASSERT_EQ(tap.memos.size(), 1u);
  ASSERT_NE(a.memos[0], nullptr);
  EXPECT_EQ(a.memos[0], b.memos[0]);
  EXPECT_EQ(a.memos[0], tap.memos[0]);
  EXPECT_FALSE(a.found[0]);  // the first reader stores the entry...
  EXPECT_TRUE(b.found[0]);   // ...and the others find it
  EXPECT_TRUE(tap.found[0]);
  // The next transmission reuses the slot empty.
  tx.send(sched.now() + 100 * kBit);
  sched.run_until(2 * kTicksPerMs);
  ASSERT_EQ(a.found.size(), 2u);
  EXPECT_FALSE(a.found[1]);
}

TEST(FrameMemo, CollidingFramesAreEachReadFresh) {
  Scheduler sched;
  Line line(sched, "A", Baud::k12M);
  Sender tx1, tx2;
  Reader rx;
  line.attach(tx1);
  line.attach(rx);
  line.attach(tx2);
  line.start();
  // tx1's frame, then tx2 starts during it: both are garbled; rx reads each once, from scratch.
  tx1.send(100 * kBit);
  tx2.send(100 * kBit + 2 * 11 * kBit);
  sched.run_until(kTicksPerMs);
  ASSERT_EQ(rx.found.size(), 2u);
  EXPECT_FALSE(rx.found[0]);
  EXPECT_FALSE(rx.found[1]);
  EXPECT_EQ(line.stats().collisions, 2u);
}

}  // namespace
}  // namespace pbvbus::bus
