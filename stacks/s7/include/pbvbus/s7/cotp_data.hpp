#pragma once
// COTP DT, class 0 (ISO 8073 §13.7; tools-and-formats.md §3.4): `02 F0 <EOT|NR>` then user data.
// Bit 7 of octet 2 is EOT (last TPDU of a TSDU), bits 0..6 the TPDU number (0 in class 0).
//
// Decision (docs/s7.md "COTP"): LI must be exactly 2 — class 0 DT has no variable part.
#include <cstdint>
#include <span>
#include <vector>

#include "pbvbus/s7/error.hpp"

namespace pbvbus::s7 {

inline constexpr std::uint8_t kDtEot = 0x80;
inline constexpr std::size_t kDtHeaderLength = 3;

struct DataTpdu {
  bool eot = true;
  std::uint8_t number = 0;
  std::span<const std::uint8_t> user_data;  ///< points into the decoded TPDU
};

Decoded<DataTpdu> decode_data(std::span<const std::uint8_t> tpdu);

/// Appends `02 F0 80|0 user_data` (no TPKT).
void append_data(std::vector<std::uint8_t>& out, std::span<const std::uint8_t> user_data,
                 bool eot = true);

/// TPKT + DT + user data in one go: what a door sends for one S7 PDU. Errors as append_tpkt.
Encoded encode_tpkt_data(std::span<const std::uint8_t> user_data, bool eot = true);

}  // namespace pbvbus::s7
