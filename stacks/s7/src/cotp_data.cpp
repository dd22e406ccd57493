// COTP DT codec (ISO 8073 §13.7, class 0; cotp_data.hpp).
#include "pbvbus/s7/cotp_data.hpp"

#include "pbvbus/s7/cotp.hpp"
#include "pbvbus/s7/tpkt.hpp"

namespace pbvbus::s7 {

Decoded<DataTpdu> decode_data(std::span<const std::uint8_t> tpdu) {
  const auto code = cotp_code(tpdu);
  if (!code.ok()) return {{}, code.error, code.at};
  if (tpdu[1] != kCotpDt) return {{}, Error::CotpUnexpectedType, 1};
  if (tpdu[0] != kDtHeaderLength - 1) return {{}, Error::CotpBadLengthIndicator, 0};
  DataTpdu d;
  d.eot = (tpdu[2] & kDtEot) != 0;
  d.number = static_cast<std::uint8_t>(tpdu[2] & 0x7F);
  d.user_data = tpdu.subspan(kDtHeaderLength);
  return {d};
}

void append_data(std::vector<std::uint8_t>& out, std::span<const std::uint8_t> user_data,
                 bool eot) {
  out.push_back(kDtHeaderLength - 1);
  out.push_back(kCotpDt);
  out.push_back(eot ? kDtEot : 0x00);
  out.insert(out.end(), user_data.begin(), user_data.end());
}

Encoded encode_tpkt_data(std::span<const std::uint8_t> user_data, bool eot) {
  std::vector<std::uint8_t> tpdu;
  tpdu.reserve(kDtHeaderLength + user_data.size());
  append_data(tpdu, user_data, eot);
  Encoded e;
  e.value.reserve(kTpktHeaderLength + tpdu.size());
  e.error = append_tpkt(e.value, tpdu);
  if (!e.ok()) e.value.clear();
  return e;
}

}  // namespace pbvbus::s7
