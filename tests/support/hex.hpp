#pragma once
// Hex helpers for tests: golden byte sequences are written by hand as "68 05 05 68 8A ..." and
// compared as text so that a failing assertion shows the bytes the way a bus analyzer does.

#include <cstdint>
#include <span>
#include <string>
#include <string_view>
#include <vector>

namespace pbvbus::test {

/// Parses hex octets separated by spaces (or not separated at all): "10 03 01 49 4D 16",
/// "10030149". Throws std::invalid_argument on a non-hex character or an odd digit count, so a
/// typo in a golden sequence fails the test loudly instead of silently shortening it.
std::vector<std::uint8_t> bytes_from_hex(std::string_view hex);

/// "68 05 05 68 8A" (uppercase, single spaces, no trailing space); "" for no bytes.
std::string to_hex(std::span<const std::uint8_t> bytes);

}  // namespace pbvbus::test
