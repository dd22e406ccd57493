#pragma once
// SDO server codec (CiA 301 §7.2.4.3, expedited transfers only): the request parser and the
// three responses this server sends. Sans-I/O and allocation-free: octets in, a value out.
//
// Decisions (also in docs/gateway-canopen.md):
// - Only expedited transfers exist here: every object is at most 4 octets (the raw diagnosis is
//   one octet per sub-index of 0x2001 for exactly that reason). Segmented and block transfers,
//   and segment requests without an open transfer, are answered with abort 0x05040001.
// - A request must be 8 octets (CiA 301 fixes the SDO frame length). A shorter one is answered
//   with abort 0x05040001 so that a client never waits for a timeout; index and sub-index are
//   taken from the octets present (0 for missing ones). An abort from the client (ccs 4) gets
//   no response, as CiA 301 says.
// - Expedited download with the size not indicated (e = 1, s = 0) is accepted: the object's own
//   length applies (CiA 301 allows it; CANopenNode does the same).
// - Reserved bits of the command specifier are not checked (a lenient server; CiA 301 says
//   "shall be 0" for the sender, not "reject" for the receiver).

#include <array>
#include <cstdint>
#include <span>

namespace pbvbus::gateways::canopen {

enum class SdoRequestKind : std::uint8_t {
  Upload,       ///< initiate upload (ccs 2): read index/sub
  Download,     ///< initiate expedited download (ccs 1, e = 1): write index/sub
  ClientAbort,  ///< abort transfer (ccs 4) from the client: no response
  Invalid,      ///< anything else: answer with abort `abort`
};

struct SdoRequest {
  SdoRequestKind kind = SdoRequestKind::Invalid;
  std::uint16_t index = 0;
  std::uint8_t sub = 0;
  std::uint8_t size = 0;      ///< Download: 1..4 octets, 0 = size not indicated
  std::uint32_t value = 0;    ///< Download: the data octets little endian (only `size` of them)
  std::uint32_t abort = 0;    ///< Invalid: the abort code to answer with
};

/// Parses one SDO request frame's data (the CAN frame's DLC octets). Never fails: a malformed
/// request is an Invalid request with its abort code.
SdoRequest parse_sdo_request(std::span<const std::uint8_t> data);

/// 8 octets of an SDO response.
using SdoFrame = std::array<std::uint8_t, 8>;
/// Expedited upload response: 0x43 | (4 - size) << 2 | index LE | sub | value LE padded with 0.
/// `size` 1..4 (clamped).
SdoFrame sdo_upload_response(std::uint16_t index, std::uint8_t sub, std::uint32_t value,
                             std::uint8_t size);
/// Download response: 0x60 | index LE | sub | 0 0 0 0.
SdoFrame sdo_download_response(std::uint16_t index, std::uint8_t sub);
/// Abort: 0x80 | index LE | sub | abort code u32 LE.
SdoFrame sdo_abort(std::uint16_t index, std::uint8_t sub, std::uint32_t code);

}  // namespace pbvbus::gateways::canopen
