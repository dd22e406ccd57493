#pragma once
// Read SZL (system status list) in a Userdata PDU (ROSCTR 7, 10-octet header). Neither
// reference note gives these octets; the layouts are those of snap7 (s7_types.h TS7Params7,
// TS7ReqSZLData, TS7ResSZLDataFirst; s7_server.cpp PerformGroupSZL) and Wireshark's s7comm
// dissector (names). docs/s7.md "SZL" lists what is decided here.
//
// Userdata parameters:
//   00 01 12 | len (4 or 8) | method (11 request, 12 response) | type<<4 | group |
//   subfunction | sequence [| data unit ref | last data unit (00 yes, 01 no) | error code u16]
// Read SZL = group 4 (CPU functions), subfunction 01.
// Request data:   FF 09 00 04 | SZL-ID u16 | index u16
// Response data:  FF 09 <len u16> | SZL-ID | index | LENTHDR u16 | N_DR u16 | N_DR records
//                 (len counts the octets after these first 4)
// Not available:  error code D4 02 in the parameters (snap7's SZLNotAvailable), data 0A 00 00 00
//
// Decisions: a response is one data unit (data unit ref 0, last data unit "yes"); splitting a
// list larger than the PDU into several units is the server's, not the codec's. The answer's
// sequence number is the request's (snap7 does so).
#include <cstdint>
#include <span>
#include <vector>

#include "pbvbus/s7/error.hpp"
#include "pbvbus/s7/s7_pdu.hpp"

namespace pbvbus::s7 {

inline constexpr std::uint8_t kUserdataMethodRequest = 0x11;
inline constexpr std::uint8_t kUserdataMethodResponse = 0x12;
inline constexpr std::uint8_t kUserdataTypePush = 0x0;
inline constexpr std::uint8_t kUserdataTypeRequest = 0x4;
inline constexpr std::uint8_t kUserdataTypeResponse = 0x8;
inline constexpr std::uint8_t kUserdataGroupCpu = 0x4;
inline constexpr std::uint8_t kSubfunctionReadSzl = 0x01;
inline constexpr std::uint8_t kLastDataUnitYes = 0x00;
inline constexpr std::uint8_t kLastDataUnitNo = 0x01;
/// Error code of a Read SZL answer for an unknown SZL-ID or index (snap7).
inline constexpr std::uint16_t kSzlNotAvailable = 0xD402;

struct UserdataParams {
  std::uint8_t method = kUserdataMethodRequest;
  std::uint8_t type = kUserdataTypeRequest;  ///< high nibble of octet 5
  std::uint8_t group = kUserdataGroupCpu;    ///< low nibble of octet 5
  std::uint8_t subfunction = kSubfunctionReadSzl;
  std::uint8_t sequence = 0;
  bool extended = false;  ///< the 8-octet form with the fields below
  std::uint8_t data_unit_ref = 0;
  std::uint8_t last_data_unit = kLastDataUnitYes;
  std::uint16_t error_code = 0;
  bool operator==(const UserdataParams&) const = default;
};

Decoded<UserdataParams> decode_userdata_params(const S7Pdu& pdu);
void append_userdata_params(std::vector<std::uint8_t>& out, const UserdataParams& u);

struct SzlRequest {
  std::uint8_t sequence = 0;
  std::uint16_t id = 0;
  std::uint16_t index = 0;
  bool operator==(const SzlRequest&) const = default;
};

Decoded<SzlRequest> decode_szl_request(const S7Pdu& pdu);
Encoded encode_szl_request(std::uint16_t pdu_ref, const SzlRequest& r);

struct SzlResponse {
  std::uint8_t sequence = 0;
  std::uint16_t error_code = 0;  ///< 0 = the list follows; else e.g. kSzlNotAvailable
  std::uint16_t id = 0;
  std::uint16_t index = 0;
  std::uint16_t record_length = 0;  ///< LENTHDR, octets per record
  std::uint16_t record_count = 0;   ///< N_DR
  std::span<const std::uint8_t> records;
};

/// An answer with an error code carries no list (id, index and records stay 0/empty).
Decoded<SzlResponse> decode_szl_response(const S7Pdu& pdu);
/// S7BadSzlResponse unless records.size() == record_length * record_count; S7PduTooLarge if
/// the list does not fit the 16-bit length.
Encoded encode_szl_response(std::uint16_t pdu_ref, const SzlResponse& r);

}  // namespace pbvbus::s7
