// S7 PDU header codec (protocol-facts.md §H.4; s7_pdu.hpp).
#include "pbvbus/s7/s7_pdu.hpp"

#include "be.hpp"

namespace pbvbus::s7 {

Decoded<S7Pdu> decode_s7_pdu(std::span<const std::uint8_t> pdu) {
  if (pdu.size() < 2) return {{}, Error::S7TooShort, pdu.size()};
  if (pdu[0] != kS7ProtocolId) return {{}, Error::S7BadProtocolId, 0};
  const std::uint8_t type = pdu[1];
  if (type != kS7Job && type != kS7Ack && type != kS7AckData && type != kS7Userdata)
    return {{}, Error::S7UnknownPduType, 1};
  const std::size_t hlen = s7_header_length(type);
  if (pdu.size() < hlen) return {{}, Error::S7TooShort, pdu.size()};
  S7Pdu p;
  p.header.type = type;
  p.header.pdu_ref = be::u16(pdu, 4);
  const std::size_t plen = be::u16(pdu, 6);
  const std::size_t dlen = be::u16(pdu, 8);
  if (hlen == 12) {
    p.header.error_class = pdu[10];
    p.header.error_code = pdu[11];
  }
  if (hlen + plen + dlen != pdu.size()) return {{}, Error::S7LengthMismatch, 6};
  p.params = pdu.subspan(hlen, plen);
  p.data = pdu.subspan(hlen + plen, dlen);
  return {p};
}

Encoded encode_s7_pdu(const S7Header& h, std::span<const std::uint8_t> params,
                      std::span<const std::uint8_t> data) {
  Encoded e;
  if (params.size() > 0xFFFF || data.size() > 0xFFFF) {
    e.error = Error::S7PduTooLarge;
    return e;
  }
  const std::size_t hlen = s7_header_length(h.type);
  auto& out = e.value;
  out.reserve(hlen + params.size() + data.size());
  out.push_back(kS7ProtocolId);
  out.push_back(h.type);
  be::put_u16(out, 0);
  be::put_u16(out, h.pdu_ref);
  be::put_u16(out, static_cast<std::uint16_t>(params.size()));
  be::put_u16(out, static_cast<std::uint16_t>(data.size()));
  if (hlen == 12) {
    out.push_back(h.error_class);
    out.push_back(h.error_code);
  }
  be::append(out, params);
  be::append(out, data);
  return e;
}

}  // namespace pbvbus::s7
