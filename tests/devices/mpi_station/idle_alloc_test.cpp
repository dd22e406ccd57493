// An MPI line whose connections are open but idle runs its token ring (tokens, GAP polls, the
// stations' ring watch and deadlines) without a heap allocation (docs/mpi.md decision 9 and
// "MPI stations on a line"); an S7 exchange allocates (frames and events are vectors).

#include <gtest/gtest.h>

#include "alloc_count.hpp"
#include "mpi_line_helpers.hpp"

namespace pbvbus::mpi_station::test {
namespace {

TEST(MpiIdleRing, OpenIdleConnectionsAllocateNothing) {
  MpiLine l;
  MpiStation& pg = l.add_client(0);
  MpiStation& op = l.add_client(1);
  l.add_cpu(2);
  l.start();
  ASSERT_TRUE(l.run_until([&] { return l.ring_formed(); }, 2000));
  const auto a = pg.open(2);
  const auto b = op.open(2);
  ASSERT_TRUE(l.run_until([&] { return pg.state(*a) == mpi::State::Connected && op.state(*b) == mpi::State::Connected; }));
  l.run_ms(500);  // every buffer at its size
  l.line.remove_tap(l.rec);  // the recorder copies every frame: measure without it
  const std::uint64_t tokens = pg.mac().stats().tokens_received;
  const std::uint64_t before = pbvbus::test::allocation_count();
  l.sched.run_until(l.sched.now() + 300 * bus::kTicksPerMs);
  const std::uint64_t after = pbvbus::test::allocation_count();
  EXPECT_GT(pg.mac().stats().tokens_received - tokens, 50u);
  EXPECT_EQ(after - before, 0u);
  EXPECT_EQ(pg.state(*a), mpi::State::Connected);
}

}  // namespace
}  // namespace pbvbus::mpi_station::test
