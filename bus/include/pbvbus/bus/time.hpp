#pragma once
// Virtual time base (design.md "Time"): an integer count of ticks, 1 s = 3 636 000 000 ticks,
// chosen so that one bit time is a whole number of ticks at every PROFIBUS baud rate.
// Nothing on a timing path uses floating point.

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>

namespace pbvbus::bus {

using Ticks = std::int64_t;

inline constexpr Ticks kTicksPerSecond = 3'636'000'000;
inline constexpr Ticks kTicksPerMs = kTicksPerSecond / 1000;
inline constexpr Ticks kTicksPerUs = kTicksPerSecond / 1'000'000;
static_assert(kTicksPerSecond % 1'000'000 == 0);

/// PROFIBUS baud rates (DP, MPI and the MBP/PA rate 31.25k). Values are bit/s.
enum class Baud : std::uint32_t {
  k9_6 = 9'600,
  k19_2 = 19'200,
  k31_25 = 31'250,
  k45_45 = 45'450,
  k93_75 = 93'750,
  k187_5 = 187'500,
  k500 = 500'000,
  k1_5M = 1'500'000,
  k3M = 3'000'000,
  k6M = 6'000'000,
  k12M = 12'000'000,
};

inline constexpr Baud kAllBauds[] = {Baud::k9_6,   Baud::k19_2, Baud::k31_25, Baud::k45_45,
                                     Baud::k93_75, Baud::k187_5, Baud::k500,  Baud::k1_5M,
                                     Baud::k3M,    Baud::k6M,   Baud::k12M};

/// Ticks per bit time; exact for every member of Baud (checked at compile time below).
constexpr Ticks ticks_per_bit(Baud b) { return kTicksPerSecond / static_cast<Ticks>(b); }

namespace detail {
constexpr bool all_exact() {
  for (Baud b : kAllBauds)
    if (kTicksPerSecond % static_cast<Ticks>(b) != 0) return false;
  return true;
}
}  // namespace detail
static_assert(detail::all_exact(), "every baud rate must have an integral bit time");

/// Bits per UART character on PROFIBUS: start, 8 data, even parity, stop.
inline constexpr std::int64_t kBitsPerChar = 11;

/// Duration of `bits` bit times at `baud`, in ticks.
constexpr Ticks bits_to_ticks(std::int64_t bits, Baud baud) { return bits * ticks_per_bit(baud); }
/// Whole bit times contained in `t` (rounded down).
constexpr std::int64_t ticks_to_bits(Ticks t, Baud baud) { return t / ticks_per_bit(baud); }
/// Duration of `n` characters on the wire.
constexpr Ticks chars_to_ticks(std::int64_t n, Baud baud) {
  return bits_to_ticks(n * kBitsPerChar, baud);
}

/// Virtual time in nanoseconds (rounded down), without overflow for any int64 tick count.
constexpr std::int64_t ticks_to_ns(Ticks t) {
  return (t / 3636) * 1000 + ((t % 3636) * 1000) / 3636;
}
/// Microseconds, rounded down.
constexpr std::int64_t ticks_to_us(Ticks t) { return t / kTicksPerUs; }

/// "1.5M", "187.5k", ... as written in GSD files and reports.
std::string_view baud_name(Baud b);
/// Accepts 1500000, "1.5M", "1.5Mbit/s", "187.5k", "187.5kbit/s", "12M", "12000k" ...: any
/// decimal spelling whose value is exactly one of the PROFIBUS rates.
std::optional<Baud> parse_baud(std::string_view s);

/// Parses a duration with unit: "250ms", "5s", "2min", "100us", "1500ns", "3ticks".
/// Returns nullopt for a missing or unknown unit, a negative value or overflow.
std::optional<Ticks> parse_duration(std::string_view s);
/// Human form of a duration with three decimals, rounded down: "2.500 s", "250.000 ms",
/// "12.345 us".
std::string format_duration(Ticks t);

}  // namespace pbvbus::bus
