// Texts of the S7 codec errors (error.hpp).
#include "pbvbus/s7/error.hpp"

namespace pbvbus::s7 {

std::string_view to_string(Error e) {
  switch (e) {
    case Error::None:
      return "no error";
    case Error::TpktBadVersion:
      return "TPKT version is not 3";
    case Error::TpktLengthTooSmall:
      return "TPKT length below 7";
    case Error::TpktLengthTooLarge:
      return "TPKT length above the negotiated maximum";
    case Error::TpktPayloadTooLarge:
      return "payload too large for one TPKT";
    case Error::CotpTooShort:
      return "COTP TPDU shorter than its fixed part";
    case Error::CotpBadLengthIndicator:
      return "COTP length indicator does not fit the TPDU";
    case Error::CotpUnexpectedType:
      return "COTP TPDU of another type";
    case Error::CotpParameterTruncated:
      return "COTP parameter runs past the header";
    case Error::CotpBadParameterLength:
      return "COTP parameter has a wrong length";
    case Error::CotpBadTpduSize:
      return "COTP TPDU size code outside 7..13";
    case Error::CotpDuplicateParameter:
      return "COTP parameter given twice";
    case Error::CotpMissingTsap:
      return "COTP CR without calling or called TSAP";
    case Error::CotpParameterTooLong:
      return "COTP parameter longer than 32 octets";
    case Error::S7TooShort:
      return "S7 PDU shorter than its header";
    case Error::S7BadProtocolId:
      return "S7 protocol id is not 0x32";
    case Error::S7UnknownPduType:
      return "S7 PDU type (ROSCTR) unknown";
    case Error::S7WrongPduType:
      return "S7 PDU type is not the one expected";
    case Error::S7PduTooLarge:
      return "S7 parameters or data too long for the header";
    case Error::S7TooManyItems:
      return "S7 more than 255 items";
    case Error::S7LengthMismatch:
      return "S7 parameter and data lengths do not match the PDU";
    case Error::S7UnexpectedFunction:
      return "S7 function is not the one expected";
    case Error::S7BadParameterLength:
      return "S7 parameter block has a wrong length";
    case Error::S7NoItems:
      return "S7 item count is 0";
    case Error::S7BadItemHeader:
      return "S7 item does not start with 0x12";
    case Error::S7BadItemLength:
      return "S7 item specification length is not 10";
    case Error::S7UnsupportedSyntaxId:
      return "S7 item syntax id is not S7ANY (0x10)";
    case Error::S7DataTruncated:
      return "S7 data item runs past the data block";
    case Error::S7TrailingData:
      return "S7 octets after the last item";
    case Error::S7UnexpectedData:
      return "S7 data block where none belongs";
    case Error::S7BadDataTransportSize:
      return "S7 data transport size unknown";
    case Error::S7ItemTooLong:
      return "S7 item data too long for its length field";
    case Error::S7ItemLengthMismatch:
      return "S7 item data size does not match its length";
    case Error::S7AddressTooLarge:
      return "S7 bit address above 24 bits";
    case Error::S7BadUserdataHead:
      return "S7 userdata parameter head is not 00 01 12";
    case Error::S7BadUserdataLength:
      return "S7 userdata parameter length wrong";
    case Error::S7UnexpectedUserdata:
      return "S7 userdata of another group or subfunction";
    case Error::S7BadSzlRequest:
      return "S7 SZL request data malformed";
    case Error::S7BadSzlResponse:
      return "S7 SZL response data malformed";
  }
  return "unknown error";
}

}  // namespace pbvbus::s7
