#pragma once
// COTP, ISO 8073 class 0, as ISO-on-TCP uses it (RFC 1006; tools-and-formats.md §3.4): the TPDU
// codes and what all TPDUs share, `LI code ...` with LI = header length without the LI octet.
#include <cstdint>
#include <span>

#include "pbvbus/s7/error.hpp"

namespace pbvbus::s7 {

/// TPDU codes (high nibble of octet 1; CR/CC carry the credit, 0 in class 0, in the low nibble).
inline constexpr std::uint8_t kCotpCr = 0xE0;  ///< connection request
inline constexpr std::uint8_t kCotpCc = 0xD0;  ///< connection confirm
inline constexpr std::uint8_t kCotpDr = 0x80;  ///< disconnect request
inline constexpr std::uint8_t kCotpDc = 0xC0;  ///< disconnect confirm
inline constexpr std::uint8_t kCotpDt = 0xF0;  ///< data
inline constexpr std::uint8_t kCotpEr = 0x70;  ///< TPDU error

/// The TPDU code of a COTP TPDU (high nibble only, so a CR with credit bits is still kCotpCr),
/// after checking that the LI fits: CotpTooShort for fewer than 2 octets,
/// CotpBadLengthIndicator when LI is 0, 255 (reserved) or longer than the TPDU.
Decoded<std::uint8_t> cotp_code(std::span<const std::uint8_t> tpdu);

}  // namespace pbvbus::s7
