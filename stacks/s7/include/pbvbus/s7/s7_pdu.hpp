#pragma once
// The S7 PDU header (protocol-facts.md §H.4; tools-and-formats.md §3.4), big-endian:
//   32 ROSCTR reserved(2) pdu-ref(2) param-len(2) data-len(2) [error-class error-code]
// The error octets exist only in Ack (2) and Ack-Data (3): a 12-octet header, else 10.
//
// Decisions (docs/s7.md "S7 header"): the reserved word is neither checked nor kept (snap7 calls
// it "AB_EX, unknown") and is written as 0; the PDU must end exactly after param-len + data-len
// octets (one S7 PDU per COTP TSDU), anything else is S7LengthMismatch.
#include <cstdint>
#include <span>
#include <vector>

#include "pbvbus/s7/error.hpp"

namespace pbvbus::s7 {

inline constexpr std::uint8_t kS7ProtocolId = 0x32;

/// ROSCTR (PDU type).
inline constexpr std::uint8_t kS7Job = 1;
inline constexpr std::uint8_t kS7Ack = 2;
inline constexpr std::uint8_t kS7AckData = 3;
inline constexpr std::uint8_t kS7Userdata = 7;

/// Function codes (parameter octet 0).
inline constexpr std::uint8_t kFnSetupCommunication = 0xF0;
inline constexpr std::uint8_t kFnReadVar = 0x04;
inline constexpr std::uint8_t kFnWriteVar = 0x05;

/// Header error classes (Wireshark's s7comm dissector, errcls_names).
namespace error_class {
inline constexpr std::uint8_t kNone = 0x00;
inline constexpr std::uint8_t kApplicationRelationship = 0x81;
inline constexpr std::uint8_t kObjectDefinition = 0x82;
inline constexpr std::uint8_t kNoResources = 0x83;
inline constexpr std::uint8_t kServiceProcessing = 0x84;
inline constexpr std::uint8_t kSupplies = 0x85;
inline constexpr std::uint8_t kAccess = 0x87;
}  // namespace error_class

constexpr std::size_t s7_header_length(std::uint8_t type) {
  return type == kS7Ack || type == kS7AckData ? 12 : 10;
}

struct S7Header {
  std::uint8_t type = kS7Job;
  std::uint16_t pdu_ref = 0;
  std::uint8_t error_class = 0;  ///< Ack/Ack-Data only
  std::uint8_t error_code = 0;   ///< Ack/Ack-Data only
  bool operator==(const S7Header&) const = default;
};

/// A decoded PDU; `params` and `data` point into the decoded octets.
struct S7Pdu {
  S7Header header;
  std::span<const std::uint8_t> params;
  std::span<const std::uint8_t> data;
};

Decoded<S7Pdu> decode_s7_pdu(std::span<const std::uint8_t> pdu);

/// Where the parameter / data block starts in the PDU: the decoders of the functions (Setup
/// Communication, Read/Write Var, SZL) report `Decoded::at` as an offset in the whole PDU.
constexpr std::size_t params_offset(const S7Pdu& p) {
  return s7_header_length(p.header.type);
}
constexpr std::size_t data_offset(const S7Pdu& p) {
  return params_offset(p) + p.params.size();
}

/// Header + params + data. S7PduTooLarge if either block exceeds 65535 octets.
Encoded encode_s7_pdu(const S7Header& h, std::span<const std::uint8_t> params,
                      std::span<const std::uint8_t> data);

}  // namespace pbvbus::s7
