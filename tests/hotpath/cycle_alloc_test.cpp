// The whole per-frame path of a running scenario allocates nothing once warmed up: line,
// stations, their users, the statistics tap and the pcapng capture together (design.md
// "Definition of done": hot paths avoid per-frame heap allocation; tests/bus/line_alloc_test.cpp
// checks the line alone). Speed itself is measured by benchmarks only (docs/benchmarks.md).

#include <gtest/gtest.h>

#include <cstdint>
#include <span>
#include <sstream>
#include <string>

#include "alloc_count.hpp"
#include "pbvbus/captures/pcapng_writer.hpp"
#include "pbvbus/scenario/scenario.hpp"
#include "pbvbus/simulation/simulation.hpp"

namespace pbvbus {
namespace {

/// Runs `text` with a capture into a counting sink, warms up for `warm`, then counts the
/// allocations of the next `span` of virtual time. Returns {allocations, frames in the span}.
std::pair<std::uint64_t, std::uint64_t> steady_allocations(const std::string& text, bus::Ticks warm,
                                                           bus::Ticks span) {
  const auto loaded = tools::parse_scenario(text, PBVBUS_SOURCE_DIR "/examples/hotpath.textproto");
  EXPECT_TRUE(loaded.ok()) << (loaded.ok() ? "" : loaded.errors.front().str());
  if (!loaded.ok()) return {~0ull, 0};
  std::uint64_t octets = 0;
  captures::PcapngWriter writer([&octets](std::span<const std::uint8_t> b) {
    octets += b.size();
    return true;
  });
  tools::SimulationOptions opts;
  opts.capture = &writer;
  tools::Simulation sim(*loaded.plan, opts);
  sim.start();
  sim.run_until(warm);
  const std::uint64_t frames0 = sim.stats(0).frames;
  const std::uint64_t allocs0 = test::allocation_count();
  sim.run_until(warm + span);
  const std::uint64_t allocs = test::allocation_count() - allocs0;
  const std::uint64_t frames = sim.stats(0).frames - frames0;
  EXPECT_EQ(sim.stats(0).error_frames(), 0u);
  writer.flush();
  EXPECT_GT(octets, 0u);
  return {allocs, frames};
}

TEST(CycleAlloc, FdlPollingWithCaptureAndStatistics) {
  // bench/sim_speed_bench.cpp case (a): 1 master + 32 passive stations, 32-octet SRD, 12 Mbit/s.
  std::ostringstream s;
  s << "name: \"hotpath\"\nseed: 1\nline { name: \"A\" baud: \"12M\" }\n";
  s << "master { address: 1 line: \"A\" poll { address: [";
  for (int i = 0; i < 32; ++i) s << (i ? ", " : "") << 2 + i;
  s << "] length: 32 } }\n";
  for (int i = 0; i < 32; ++i)
    s << "passive_station { address: " << 2 + i << " line: \"A\" response_length: 32 }\n";
  const auto [allocs, frames] = steady_allocations(s.str(), 50 * bus::kTicksPerMs, 100 * bus::kTicksPerMs);
  // Nothing per frame. The one thing that grows: devices::FdlPoller keeps every token rotation
  // time for its report (fdl_poller.hpp: 8 octets per token), a vector that doubles now and then
  // (twice in these 100 ms, about 40 token rotations after 20).
  EXPECT_LE(allocs, 2u);
  EXPECT_GT(frames, 2000u);
}

TEST(CycleAlloc, DpCycleWithCaptureAndStatistics) {
  // A DP master (OPERATE) and 16 DP slaves in data exchange at 1.5 Mbit/s.
  std::ostringstream s;
  s << "name: \"hotpath\"\nseed: 1\nline { name: \"DP\" baud: \"1.5M\" }\n";
  s << "dp_master { address: 1 line: \"DP\" mode: OPERATE }\n";
  for (int i = 0; i < 16; ++i)
    s << "dp_slave { address: " << 2 + i << " line: \"DP\" gsd: \"gsd/PBVB0A01.gsd\" master: 1 }\n";
  const auto [allocs, frames] = steady_allocations(s.str(), bus::kTicksPerSecond, 200 * bus::kTicksPerMs);
  EXPECT_EQ(allocs, 0u);
  EXPECT_GT(frames, 2000u);
}

}  // namespace
}  // namespace pbvbus
