#pragma once
// COTP DR, DC and ER (ISO 8073 §13.5, §13.6, §13.12; class 0):
//   DR: LI 80 dst-ref src-ref reason [parameters]     DC: 06 C0 dst-ref src-ref
//   ER: LI 70 dst-ref cause [C1 len <rejected TPDU octets>]
// A server refuses a CR (e.g. an unknown rack/slot) with a DR; it answers a TPDU it cannot parse
// with an ER. Parameters of a DR (additional information) are skipped when decoding.
#include <cstdint>
#include <span>
#include <vector>

#include "pbvbus/s7/error.hpp"

namespace pbvbus::s7 {

/// DR reasons (ISO 8073 §13.5.3 d; also in Wireshark's COTP dissector).
namespace dr_reason {
inline constexpr std::uint8_t kNotSpecified = 0;
inline constexpr std::uint8_t kCongestionAtTsap = 1;
inline constexpr std::uint8_t kSessionNotAttached = 2;  ///< no session entity at the TSAP
inline constexpr std::uint8_t kAddressUnknown = 3;
inline constexpr std::uint8_t kNormal = 128 + 0;
inline constexpr std::uint8_t kRemoteCongestion = 128 + 1;
inline constexpr std::uint8_t kNegotiationFailed = 128 + 2;
inline constexpr std::uint8_t kDuplicateSourceRef = 128 + 3;
inline constexpr std::uint8_t kMismatchedRefs = 128 + 4;
inline constexpr std::uint8_t kProtocolError = 128 + 5;
inline constexpr std::uint8_t kReferenceOverflow = 128 + 7;
inline constexpr std::uint8_t kRefused = 128 + 8;
inline constexpr std::uint8_t kHeaderLengthInvalid = 128 + 10;
}  // namespace dr_reason

/// ER reject causes (ISO 8073 §13.12.3 c).
namespace er_cause {
inline constexpr std::uint8_t kNotSpecified = 0;
inline constexpr std::uint8_t kInvalidParameterCode = 1;
inline constexpr std::uint8_t kInvalidTpduType = 2;
inline constexpr std::uint8_t kInvalidParameterValue = 3;
}  // namespace er_cause

inline constexpr std::uint8_t kParamInvalidTpdu = 0xC1;  ///< in an ER

struct DisconnectTpdu {
  std::uint8_t code = 0x80;  ///< kCotpDr or kCotpDc
  std::uint16_t dst_ref = 0;
  std::uint16_t src_ref = 0;
  std::uint8_t reason = 0;  ///< DR only
};

/// DR or DC (the code tells which).
Decoded<DisconnectTpdu> decode_disconnect(std::span<const std::uint8_t> tpdu);
void append_disconnect_request(std::vector<std::uint8_t>& out, std::uint16_t dst_ref,
                               std::uint16_t src_ref, std::uint8_t reason);
void append_disconnect_confirm(std::vector<std::uint8_t>& out, std::uint16_t dst_ref,
                               std::uint16_t src_ref);

struct ErrorTpdu {
  std::uint16_t dst_ref = 0;
  std::uint8_t cause = 0;
  std::span<const std::uint8_t> invalid_tpdu;  ///< the C1 parameter, empty if absent
};

Decoded<ErrorTpdu> decode_error_tpdu(std::span<const std::uint8_t> tpdu);
/// The rejected TPDU's first octets go into C1, as many as fit an LI of at most 254.
void append_error_tpdu(std::vector<std::uint8_t>& out, std::uint16_t dst_ref, std::uint8_t cause,
                       std::span<const std::uint8_t> invalid_tpdu);

}  // namespace pbvbus::s7
