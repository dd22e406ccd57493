#pragma once
// The S7 reading of a 2-octet TSAP (tools-and-formats.md §3.3, §3.4): octet 0 the connection
// type (01 PG, 02 OP, 03 S7 basic), octet 1 = rack * 32 + slot. This is snap7's, nodes7's and
// current libnodave's layout (`dc->slot | dc->rack << 5`); older libnodave wrote rack+1 in
// octet 0 and the slot alone in octet 1, which reads the same for rack 0 (docs/s7.md "TSAP").
#include <cstdint>
#include <optional>
#include <span>

namespace pbvbus::s7 {

inline constexpr std::uint8_t kTsapPg = 0x01;
inline constexpr std::uint8_t kTsapOp = 0x02;
inline constexpr std::uint8_t kTsapS7Basic = 0x03;

struct S7Tsap {
  std::uint8_t connection_type = kTsapPg;
  std::uint8_t rack = 0;  ///< 0..7
  std::uint8_t slot = 0;  ///< 0..31
  bool operator==(const S7Tsap&) const = default;
};

/// The rack/slot form of a TSAP; nullopt unless it is exactly 2 octets (libnodave's 28-octet
/// routing TSAP has another layout, tools-and-formats.md §3.2).
std::optional<S7Tsap> parse_s7_tsap(std::span<const std::uint8_t> tsap);

/// Octets 0..1 of a TSAP for a rack (0..7) and slot (0..31); higher bits are cut off.
constexpr std::uint16_t s7_tsap_value(S7Tsap t) {
  return static_cast<std::uint16_t>((t.connection_type << 8) | ((t.rack & 0x07) << 5) |
                                    (t.slot & 0x1F));
}

}  // namespace pbvbus::s7
