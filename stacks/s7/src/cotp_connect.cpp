// COTP CR/CC codec (ISO 8073 §13.3, §13.4; cotp_connect.hpp).
#include "pbvbus/s7/cotp_connect.hpp"

#include <algorithm>

#include "be.hpp"

namespace pbvbus::s7 {
namespace {

constexpr std::size_t kFixedPart = 7;  // LI code dst-ref(2) src-ref(2) class

Decoded<ConnectTpdu> decode_connect(std::span<const std::uint8_t> tpdu, std::uint8_t want,
                                    bool tsaps_required) {
  const auto code = cotp_code(tpdu);
  if (!code.ok()) return {{}, code.error, code.at};
  if (code.value != want) return {{}, Error::CotpUnexpectedType, 1};
  const std::size_t header = std::size_t{tpdu[0]} + 1;
  if (header < kFixedPart) return {{}, Error::CotpBadLengthIndicator, 0};
  ConnectTpdu t;
  t.code = code.value;
  t.dst_ref = be::u16(tpdu, 2);
  t.src_ref = be::u16(tpdu, 4);
  t.class_option = tpdu[6];
  bool seen_size = false;
  std::size_t at = kFixedPart;
  while (at < header) {
    if (at + 2 > header) return {{}, Error::CotpParameterTruncated, at};
    const std::uint8_t p = tpdu[at];
    const std::size_t len = tpdu[at + 1];
    if (at + 2 + len > header) return {{}, Error::CotpParameterTruncated, at + 1};
    const auto value = tpdu.subspan(at + 2, len);
    if (p == kParamTpduSize) {
      if (seen_size) return {{}, Error::CotpDuplicateParameter, at};
      if (len != 1) return {{}, Error::CotpBadParameterLength, at + 1};
      if (value[0] < kTpduSizeMinCode || value[0] > kTpduSizeMaxCode)
        return {{}, Error::CotpBadTpduSize, at + 2};
      t.tpdu_size_code = value[0];
      seen_size = true;
    } else if (p == kParamCallingTsap || p == kParamCalledTsap) {
      auto& slot = p == kParamCallingTsap ? t.calling_tsap : t.called_tsap;
      if (!slot.empty()) return {{}, Error::CotpDuplicateParameter, at};
      if (len == 0 || len > kMaxTsapLength) return {{}, Error::CotpBadParameterLength, at + 1};
      slot = value;
    }
    at += 2 + len;
  }
  // User data after the header is not allowed in class 0 CR/CC; RFC 1006 clients send none.
  if (header != tpdu.size()) return {{}, Error::CotpBadLengthIndicator, 0};
  if (tsaps_required && (t.calling_tsap.empty() || t.called_tsap.empty()))
    return {{}, Error::CotpMissingTsap, header};
  return {t};
}

}  // namespace

Decoded<ConnectTpdu> decode_connect_request(std::span<const std::uint8_t> tpdu) {
  return decode_connect(tpdu, kCotpCr, true);
}

Decoded<ConnectTpdu> decode_connect_confirm(std::span<const std::uint8_t> tpdu) {
  return decode_connect(tpdu, kCotpCc, false);
}

Error append_connect(std::vector<std::uint8_t>& out, const ConnectTpdu& t) {
  if (t.calling_tsap.size() > kMaxTsapLength || t.called_tsap.size() > kMaxTsapLength)
    return Error::CotpParameterTooLong;
  if (t.tpdu_size_code != 0 &&
      (t.tpdu_size_code < kTpduSizeMinCode || t.tpdu_size_code > kTpduSizeMaxCode))
    return Error::CotpBadTpduSize;
  std::size_t li = kFixedPart - 1;
  if (t.tpdu_size_code != 0) li += 3;
  if (!t.calling_tsap.empty()) li += 2 + t.calling_tsap.size();
  if (!t.called_tsap.empty()) li += 2 + t.called_tsap.size();
  out.push_back(static_cast<std::uint8_t>(li));  // at most 6 + 3 + 2 * 34 = 77
  out.push_back(t.code);
  be::put_u16(out, t.dst_ref);
  be::put_u16(out, t.src_ref);
  out.push_back(t.class_option);
  if (t.tpdu_size_code != 0) {
    out.push_back(kParamTpduSize);
    out.push_back(1);
    out.push_back(t.tpdu_size_code);
  }
  for (const auto& [p, v] :
       {std::pair{kParamCallingTsap, t.calling_tsap}, std::pair{kParamCalledTsap, t.called_tsap}}) {
    if (v.empty()) continue;
    out.push_back(p);
    out.push_back(static_cast<std::uint8_t>(v.size()));
    be::append(out, v);
  }
  return Error::None;
}

ConnectTpdu confirm_for(const ConnectTpdu& cr, std::uint16_t own_ref, std::uint8_t max_size_code) {
  ConnectTpdu cc;
  cc.code = kCotpCc;
  cc.dst_ref = cr.src_ref;
  cc.src_ref = own_ref;
  cc.class_option = 0x00;
  cc.tpdu_size_code =
      cr.tpdu_size_code == 0 ? std::uint8_t{0} : std::min(cr.tpdu_size_code, max_size_code);
  cc.calling_tsap = cr.calling_tsap;
  cc.called_tsap = cr.called_tsap;
  return cc;
}

}  // namespace pbvbus::s7
