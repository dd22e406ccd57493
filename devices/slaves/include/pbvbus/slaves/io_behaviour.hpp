#pragma once
// Input behaviours of a simulated DP slave's modules (used by slave_model.hpp): what the
// slave's inputs show, as a function of virtual time, of the DP cycle count, or of the outputs
// the master sent. A behaviour fills a channel: `width` input octets of one module. Values wider
// than one octet are big-endian (the DP convention for words and double words, §D.3).
//
// Decisions:
// - Time is absolute virtual time (tick 0 = line start); nothing reads a clock.
// - Counter: value = start + step × n, wrapping modulo 2^(8 × width). With a period, n = number of
//   whole periods elapsed (so it changes exactly at k × period); without one, n = the number of
//   the owner's Data_Exchange requests answered before this one (the first answer shows start).
// - Ramp: a sawtooth from min to max over `period`: min + (max − min) × (t mod period) / period,
//   integer arithmetic rounding toward min; reaches max only as the limit. Written as a two's
//   complement value of the channel width, so negative values suit Signed16 analog words.
// - Table: rows (time, value), times relative to the table's start; the value is that of the last
//   row whose time has passed (before the first row: the first row's value). With `repeat`, time is
//   taken modulo `period` (which must be longer than the last row time).
// - Echo: the outputs of a module (this one unless `source_module` is set) copied to the channel,
//   cut or zero-padded to its width.
// - Constant: the octets given, cut or zero-padded to the width.

#include <cstdint>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "pbvbus/bus/time.hpp"

namespace pbvbus::devices {

struct IoBehaviour {
  enum class Kind : std::uint8_t { Constant, Counter, Echo, Ramp, Table };
  Kind kind = Kind::Constant;

  std::vector<std::uint8_t> constant;  ///< Constant

  std::uint64_t start = 0;  ///< Counter
  std::uint64_t step = 1;   ///< Counter
  bus::Ticks period = 0;    ///< Counter (0 = per DP cycle), Ramp, repeating Table

  std::optional<std::size_t> source_module;  ///< Echo: module whose outputs are mirrored

  std::int64_t min = 0;  ///< Ramp
  std::int64_t max = 0;  ///< Ramp

  std::vector<std::pair<bus::Ticks, std::int64_t>> rows;  ///< Table: (time, value), ascending
  bool repeat = false;                                    ///< Table

  static IoBehaviour constant_value(std::vector<std::uint8_t> v) {
    IoBehaviour b;
    b.kind = Kind::Constant;
    b.constant = std::move(v);
    return b;
  }
  static IoBehaviour counter_every(bus::Ticks period, std::uint64_t step = 1, std::uint64_t start = 0) {
    IoBehaviour b;
    b.kind = Kind::Counter;
    b.period = period;
    b.step = step;
    b.start = start;
    return b;
  }
  static IoBehaviour counter_per_cycle(std::uint64_t step = 1, std::uint64_t start = 0) {
    return counter_every(0, step, start);
  }
  static IoBehaviour echo(std::optional<std::size_t> source = std::nullopt) {
    IoBehaviour b;
    b.kind = Kind::Echo;
    b.source_module = source;
    return b;
  }
  static IoBehaviour ramp(std::int64_t lo, std::int64_t hi, bus::Ticks period) {
    IoBehaviour b;
    b.kind = Kind::Ramp;
    b.min = lo;
    b.max = hi;
    b.period = period;
    return b;
  }
  static IoBehaviour table(std::vector<std::pair<bus::Ticks, std::int64_t>> rows, bool repeat = false,
                           bus::Ticks period = 0) {
    IoBehaviour b;
    b.kind = Kind::Table;
    b.rows = std::move(rows);
    b.repeat = repeat;
    b.period = period;
    return b;
  }
};

/// Why a behaviour cannot be used (empty string if it can). `modules` = number of modules.
std::string check_behaviour(const IoBehaviour& b, std::size_t modules);

/// The value of a numeric behaviour (Counter, Ramp, Table) at `now` after `cycles` DP cycles.
std::int64_t behaviour_value(const IoBehaviour& b, bus::Ticks now, std::uint64_t cycles);

/// Writes `value` big-endian into `out` (two's complement, modulo 2^(8 × out.size())).
void put_big_endian(std::int64_t value, std::vector<std::uint8_t>::iterator out, std::size_t width);

}  // namespace pbvbus::devices
