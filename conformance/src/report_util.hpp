#pragma once
// Internal: small text helpers shared by the report writers (hex, JSON and XML escaping).

#include <cstdint>
#include <span>
#include <string>
#include <string_view>

namespace pbvbus::conformance::detail {

/// "68 05 05 68" (uppercase, space-separated).
std::string hex_octets(std::span<const std::uint8_t> b);
/// A JSON string literal with quotes; control characters as \u00XX, invalid UTF-8 passed through.
std::string json_str(std::string_view s);
/// XML 1.0 text/attribute escaping (& < > " '); characters XML forbids (C0 controls except TAB,
/// LF, CR) are dropped.
std::string xml_escape(std::string_view s);

}  // namespace pbvbus::conformance::detail
