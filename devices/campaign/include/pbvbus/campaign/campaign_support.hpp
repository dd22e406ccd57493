#pragma once
// What the seeded fault campaigns share (docs/redundancy.md "Switchover campaign",
// docs/h-campaign.md): both drive a redundant system through random faults drawn from one seed,
// count the S7 events it raises by code, and watch the switched stations' outputs for pulses
// while a program writes a 16-bit counter into them.
//
// Every random choice of a campaign comes from its one `Draw`, in program order, so a seed
// replays a campaign exactly (design.md "Time": random faults come from a seeded generator).

#include <array>
#include <cstdint>
#include <random>
#include <span>
#include <string>
#include <string_view>
#include <utility>

#include "pbvbus/bus/time.hpp"
#include "pbvbus/gsd/gsd.hpp"

namespace pbvbus::campaign {

/// "12.345 ms": how the campaigns' reports write a virtual time.
std::string format_ms(bus::Ticks t);

/// The seeded generator of one campaign.
class Draw {
 public:
  explicit Draw(std::uint64_t seed) : m_rng(seed) {}
  /// Uniform in [lo, hi].
  bus::Ticks ticks(bus::Ticks lo, bus::Ticks hi) {
    return std::uniform_int_distribution<bus::Ticks>(lo, hi)(m_rng);
  }
  /// Uniform in [lo, hi].
  int integer(int lo, int hi) { return std::uniform_int_distribution<int>(lo, hi)(m_rng); }
  /// True with probability p.
  bool chance(double p) { return std::uniform_real_distribution<double>(0, 1)(m_rng) < p; }
  /// For distributions of a campaign's own (std::discrete_distribution over the fault kinds).
  std::mt19937_64& engine() { return m_rng; }

 private:
  std::mt19937_64 m_rng;
};

/// The S7 events of a redundant DP master system that the campaigns count (seeds-digest.md §7):
/// station failure and return with the other channel still there (73A3, 72A3), a station's
/// last channel lost or its first back (39C4, 38C4), the master system failed and back (39C3,
/// 38C3).
constexpr std::array<std::uint16_t, 6> kSystemEventCodes = {0x73A3, 0x72A3, 0x39C4,
                                                            0x38C4, 0x39C3, 0x38C3};
using EventCounts = std::array<std::pair<std::uint16_t, int>, kSystemEventCodes.size()>;
/// Every code of kSystemEventCodes with a count of 0.
EventCounts zero_event_counts();
/// Adds one to `code`'s count; a code outside the table is not counted.
void count_event(EventCounts& counts, std::uint16_t code);
/// `code`'s count, 0 for a code outside the table.
int count_of(std::span<const std::pair<std::uint16_t, int>> counts, std::uint16_t code);
/// " 73A3=12 72A3=11 ..." in table order, as the campaigns' summaries print it.
std::string format_counts(std::span<const std::pair<std::uint16_t, int>> counts);

/// Watches the 16-bit counter a campaign's program writes into one switched station's outputs.
/// Once the counter has started (its first value other than 0), every later sample must be a
/// value not older than the last one (compared modulo 2^16) and never 0 — except while the
/// station may legitimately be in its safe state: from a sample at which the caller says so
/// (no channel reaches it, no CPU runs the program) until the first new value after that.
class CounterWatch {
 public:
  struct Sample {
    bool counted = false;       ///< false until the counter has started
    bool safe_state = false;    ///< 0 while the safe state is allowed
    std::string_view bad;       ///< "outputs 0", "older value", or empty
    std::uint16_t previous = 0; ///< the last value before this sample
  };
  /// `allowed_safe_state`: the station may be in its safe state now.
  Sample sample(std::uint16_t value, bool allowed_safe_state);
  std::uint16_t last() const { return m_last; }

 private:
  bool m_started = false;
  bool m_exempt = false;
  std::uint16_t m_last = 0;
};

/// `dir`/`name` read as a GSD; throws std::runtime_error ("WHO: cannot load NAME") if it cannot
/// be (a campaign cannot run without its stations' GSD files).
devices::GsdFile load_gsd_or_throw(const std::string& dir, const char* name, std::string_view who);

}  // namespace pbvbus::campaign
