#pragma once
// Small text helpers shared by the reports and subcommands (text and JSON output).

#include <cstdint>
#include <span>
#include <string>
#include <string_view>

#include "pbvbus/bus/time.hpp"

namespace pbvbus::tools {

/// `s` as a JSON string literal, quotes included: RFC 8259 short escapes for ", \, newline,
/// carriage return and tab; every other control character (and DEL) as \u00XX.
std::string json_quote(std::string_view s);

/// Octets as upper-case hex pairs separated by spaces ("08 0C 00"), as the reports print them.
std::string hex_octets(std::span<const std::uint8_t> v);

/// Microseconds with three decimals ("12.345"), from ticks, exact, without floating point.
std::string format_us(bus::Ticks t);

}  // namespace pbvbus::tools
