#pragma once
// The one error vocabulary of the S7 codecs (docs/s7.md "Errors"): every decoder refusal and
// every encoder precondition has its own code, so a test or a log names exactly what was wrong.
// Nothing in pbvbus::s7 throws; results carry the code and the offset of the offending octet.

#include <cstddef>
#include <cstdint>
#include <string_view>
#include <vector>

namespace pbvbus::s7 {

enum class Error : std::uint8_t {
  None,
  // TPKT (RFC 1006)
  TpktBadVersion,       ///< octet 0 is not 3
  TpktLengthTooSmall,   ///< length field below 7 (header plus the smallest COTP TPDU)
  TpktLengthTooLarge,   ///< length field above the negotiated maximum
  TpktPayloadTooLarge,  ///< encoder: payload does not fit a 16-bit TPKT length
  // COTP (ISO 8073 class 0)
  CotpTooShort,            ///< fewer octets than the fixed part of the TPDU
  CotpBadLengthIndicator,  ///< LI does not fit the TPDU or its fixed part
  CotpUnexpectedType,      ///< the TPDU code is not the one asked for
  CotpParameterTruncated,  ///< a parameter runs past the header
  CotpBadParameterLength,  ///< TPDU size parameter not 1 octet, or a TSAP of 0 or > 32 octets
  CotpBadTpduSize,         ///< TPDU size code outside 7..13 (128..8192 octets)
  CotpDuplicateParameter,  ///< the same parameter twice in one CR/CC
  CotpMissingTsap,         ///< CR without a calling or called TSAP
  CotpParameterTooLong,    ///< encoder: a TSAP longer than 32 octets
  // S7 PDU (protocol-facts.md §H.4)
  S7TooShort,              ///< fewer octets than the header of its type
  S7BadProtocolId,         ///< octet 0 is not 0x32
  S7UnknownPduType,        ///< ROSCTR not 1, 2, 3 or 7
  S7WrongPduType,          ///< a known ROSCTR, but not the one the decoder expects
  S7PduTooLarge,           ///< encoder: parameters or data longer than a 16-bit length
  S7TooManyItems,          ///< encoder: more than 255 items
  S7LengthMismatch,        ///< header + parameter length + data length != PDU length
  S7UnexpectedFunction,    ///< parameter octet 0 is not the function asked for
  S7BadParameterLength,    ///< parameter block length wrong for its function or item count
  S7NoItems,               ///< Read/Write Var with item count 0
  S7BadItemHeader,         ///< item does not start with 0x12 (variable specification)
  S7BadItemLength,         ///< item specification length not 10 for S7ANY
  S7UnsupportedSyntaxId,   ///< item syntax id other than 0x10 (S7ANY)
  S7DataTruncated,         ///< a data item runs past the data block
  S7TrailingData,          ///< octets left over after the last item
  S7UnexpectedData,        ///< a data block where the function has none
  S7BadDataTransportSize,  ///< data transport size whose length unit is unknown
  S7ItemTooLong,           ///< encoder: data longer than the 16-bit length field allows
  S7ItemLengthMismatch,    ///< encoder: data size does not match the length field
  S7AddressTooLarge,       ///< encoder: bit address above 24 bits
  S7BadUserdataHead,       ///< userdata parameter head is not 00 01 12
  S7BadUserdataLength,     ///< userdata parameter length not 4 or 8, or not matching
  S7UnexpectedUserdata,    ///< not the group/subfunction/type asked for
  S7BadSzlRequest,         ///< SZL request data not FF 09 00 04 ID INDEX
  S7BadSzlResponse,        ///< SZL response data inconsistent
};

std::string_view to_string(Error e);

/// A decoder's answer: the value, or the error and the offset of the octet that caused it
/// (relative to the start of the input the decoder was given).
template <class T>
struct Decoded {
  T value{};
  Error error = Error::None;
  std::size_t at = 0;
  bool ok() const { return error == Error::None; }
};

/// An encoder's answer: the octets, or why the input could not be encoded.
using Encoded = Decoded<std::vector<std::uint8_t>>;

}  // namespace pbvbus::s7
