#pragma once
// COTP CR and CC (ISO 8073 §13.3/§13.4, class 0; tools-and-formats.md §3.2, §3.4):
//   LI  E0|D0  dst-ref u16  src-ref u16  class/option  parameters...
// Parameters: C0 TPDU size (1 octet, size = 2^code), C1 calling TSAP, C2 called TSAP.
//
// Decisions (docs/s7.md "COTP"):
// - Parameters may come in any order (nodes7/snap7 send C0 C1 C2, libnodave C1 C2 C0); unknown
//   parameters are skipped (ISO 8073 lets a receiver ignore what it does not know); a known one
//   twice is CotpDuplicateParameter.
// - The class/option octet is decoded, not judged: the server decides (S7 clients send 0x00,
//   snap7 notes that RFC 983's 0x40 is not what S7 wants).
// - A CR must carry both TSAPs (an S7 server routes by the called TSAP): CotpMissingTsap.
//   A TSAP is 1..32 octets (ISO 8073 limit; libnodave's routing TSAP is 28).
// - The encoder writes C0, C1, C2 in that order, each only if present. libnodave insists on a
//   22-octet CC (TPKT included), i.e. all three echoed with 2-octet TSAPs: confirm_for() echoes.
#include <cstdint>
#include <span>
#include <vector>

#include "pbvbus/s7/cotp.hpp"
#include "pbvbus/s7/error.hpp"

namespace pbvbus::s7 {

inline constexpr std::uint8_t kParamTpduSize = 0xC0;
inline constexpr std::uint8_t kParamCallingTsap = 0xC1;
inline constexpr std::uint8_t kParamCalledTsap = 0xC2;
inline constexpr std::uint8_t kTpduSizeMinCode = 0x07;  ///< 128 octets
inline constexpr std::uint8_t kTpduSizeMaxCode = 0x0D;  ///< 8192 octets
/// Class 0 allows TPDUs up to 2048 octets (ISO 8073 class 0 rules; not in the reference notes,
/// docs/s7.md): the most a server confirms.
inline constexpr std::uint8_t kTpduSizeClass0MaxCode = 0x0B;
inline constexpr std::size_t kMaxTsapLength = 32;

constexpr std::size_t tpdu_size_octets(std::uint8_t code) {
  return std::size_t{1} << code;
}

/// A CR or a CC. The TSAP spans point into the decoded TPDU (keep it alive) or, for encoding,
/// at the caller's octets. An empty span / tpdu_size_code 0 = parameter absent.
struct ConnectTpdu {
  std::uint8_t code = kCotpCr;  ///< kCotpCr or kCotpCc
  std::uint16_t dst_ref = 0;
  std::uint16_t src_ref = 0;
  std::uint8_t class_option = 0;  ///< high nibble = class
  std::uint8_t tpdu_size_code = 0;
  std::span<const std::uint8_t> calling_tsap;
  std::span<const std::uint8_t> called_tsap;
};

Decoded<ConnectTpdu> decode_connect_request(std::span<const std::uint8_t> tpdu);
/// As for the CR, but the TSAPs are optional.
Decoded<ConnectTpdu> decode_connect_confirm(std::span<const std::uint8_t> tpdu);

/// Appends the TPDU (no TPKT). CotpParameterTooLong for a TSAP over 32 octets, CotpBadTpduSize
/// for a size code outside 7..13 (0 = absent is fine); `out` is unchanged on an error.
Error append_connect(std::vector<std::uint8_t>& out, const ConnectTpdu& t);

/// The CC a server answers to `cr`: dst-ref = the CR's src-ref, src-ref = `own_ref`, class 0,
/// the TPDU size the CR asked for lowered to `max_size_code` (absent stays absent), both TSAPs
/// echoed. Spans point into `cr`'s TPDU.
ConnectTpdu confirm_for(const ConnectTpdu& cr, std::uint16_t own_ref,
                        std::uint8_t max_size_code = kTpduSizeClass0MaxCode);

}  // namespace pbvbus::s7
