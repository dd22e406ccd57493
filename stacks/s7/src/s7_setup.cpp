// Setup Communication codec (protocol-facts.md §H.4; s7_setup.hpp).
#include "pbvbus/s7/s7_setup.hpp"

#include <algorithm>

#include "be.hpp"

namespace pbvbus::s7 {
namespace {

Encoded encode(std::uint8_t type, std::uint16_t pdu_ref, const SetupCommunication& s) {
  std::vector<std::uint8_t> params;
  params.reserve(kSetupParamLength);
  params.push_back(kFnSetupCommunication);
  params.push_back(0x00);
  be::put_u16(params, s.max_amq_calling);
  be::put_u16(params, s.max_amq_called);
  be::put_u16(params, s.pdu_length);
  return encode_s7_pdu(S7Header{type, pdu_ref, 0, 0}, params, {});
}

}  // namespace

Decoded<SetupCommunication> decode_setup_communication(const S7Pdu& pdu) {
  if (pdu.header.type != kS7Job && pdu.header.type != kS7AckData)
    return {{}, Error::S7WrongPduType, 1};
  const auto p = pdu.params;
  const std::size_t at = params_offset(pdu);
  if (p.empty()) return {{}, Error::S7BadParameterLength, 6};
  if (p[0] != kFnSetupCommunication) return {{}, Error::S7UnexpectedFunction, at};
  if (p.size() != kSetupParamLength) return {{}, Error::S7BadParameterLength, 6};
  if (!pdu.data.empty()) return {{}, Error::S7UnexpectedData, data_offset(pdu)};
  return {SetupCommunication{be::u16(p, 2), be::u16(p, 4), be::u16(p, 6)}};
}

Encoded encode_setup_communication_request(std::uint16_t pdu_ref, const SetupCommunication& s) {
  return encode(kS7Job, pdu_ref, s);
}

Encoded encode_setup_communication_response(std::uint16_t pdu_ref, const SetupCommunication& s) {
  return encode(kS7AckData, pdu_ref, s);
}

SetupCommunication negotiate(const SetupCommunication& requested, const SetupCommunication& own) {
  return {std::min(requested.max_amq_calling, own.max_amq_calling),
          std::min(requested.max_amq_called, own.max_amq_called),
          std::min(requested.pdu_length, own.pdu_length)};
}

}  // namespace pbvbus::s7
