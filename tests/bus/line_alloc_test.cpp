// The per-frame path of the line allocates nothing once warmed up (design.md "Definition of
// done": hot paths avoid per-frame heap allocation). Speed itself is measured by benchmarks.

#include <gtest/gtest.h>

#include <array>
#include <memory>
#include <vector>

#include "alloc_count.hpp"
#include "pbvbus/bus/line.hpp"

namespace pbvbus::bus {
namespace {

constexpr Ticks kBit = 303;  // 12 Mbit/s

/// Answers a request to its address with a 16-octet SD2 after min TSDR (11 bit times).
struct Slave final : Device {
  explicit Slave(int a) : addr(a) {}
  void on_power_on(Ticks) override {}
  void on_frame(const RxFrame& f) override {
    reply[5] = static_cast<std::uint8_t>(addr);
    port().transmit(f.end + 11 * kBit, reply);
  }
  void on_timer(Ticks) override {}
  int receive_filter() const override { return addr; }
  int addr;
  std::array<std::uint8_t, 16> reply{0x68, 10, 10, 0x68, 1, 0, 8, 1, 2, 3, 4, 5, 6, 7, 0, 0x16};
};

/// Polls 32 slaves round robin; a slot-time timer covers a missing reply.
struct Master final : Device {
  void poll(Ticks at) {
    request[4] = static_cast<std::uint8_t>(3 + next);
    next = (next + 1) % 32;
    port().transmit(at, request);
    port().set_timer(at + (16 * 11 + 1000) * kBit);
  }
  void on_power_on(Ticks now) override { poll(now); }
  void on_frame(const RxFrame& f) override { poll(f.end + 33 * kBit); }
  void on_timer(Ticks now) override { poll(now); }
  int next = 0;
  std::array<std::uint8_t, 16> request{0x68, 10, 10, 0x68, 3, 1, 0x7D, 1, 2, 3, 4, 5, 6, 7, 0, 0x16};
};

TEST(LineAlloc, SteadyStateTrafficDoesNotAllocate) {
  Scheduler sched;
  Line line(sched, "A", Baud::k12M);
  Master master;
  line.attach(master);
  std::vector<std::unique_ptr<Slave>> slaves;
  for (int i = 0; i < 32; ++i) {
    slaves.push_back(std::make_unique<Slave>(3 + i));
    line.attach(*slaves.back());
  }
  line.start();
  sched.run_until(10 * kTicksPerMs);  // warm-up: pools and queues reach their size
  const auto frames0 = line.stats().frames;
  const auto allocs0 = test::allocation_count();
  sched.run_until(110 * kTicksPerMs);
  EXPECT_EQ(test::allocation_count() - allocs0, 0u);
  EXPECT_GT(line.stats().frames - frames0, 5000u);
  EXPECT_EQ(line.stats().collisions, 0u);
}

/// Counts what reaches it (a probe tap that keeps nothing).
struct CountingTap final : Tap {
  void on_frame(const TapFrame& f) override { octets += f.bytes.size(); }
  std::uint64_t octets = 0;
};

TEST(LineAlloc, ProbeTapsDoNotAllocateEither) {
  Scheduler sched;
  Line line(sched, "A", Baud::k12M);
  Master master;
  line.attach(master);
  std::vector<std::unique_ptr<Slave>> slaves;
  for (int i = 0; i < 32; ++i) {
    slaves.push_back(std::make_unique<Slave>(3 + i));
    line.attach(*slaves.back());
  }
  CountingTap first, last;
  line.add_tap(first, ProbePoint{0});
  line.add_tap(last, ProbePoint{32});
  line.start();
  sched.run_until(10 * kTicksPerMs);
  const auto allocs0 = test::allocation_count();
  sched.run_until(110 * kTicksPerMs);
  EXPECT_EQ(test::allocation_count() - allocs0, 0u);
  EXPECT_EQ(first.octets, last.octets);
  EXPECT_GT(first.octets, 5000u * 16u);
}

TEST(LineAlloc, CounterWorks) {
  const auto a = test::allocation_count();
  auto p = std::make_unique<int>(5);
  EXPECT_EQ(test::allocation_count() - a, 1u);
  EXPECT_EQ(*p, 5);
}

}  // namespace
}  // namespace pbvbus::bus
