// COTP DR/DC/ER codec (ISO 8073 §13.5, §13.6, §13.12; cotp_disconnect.hpp).
#include "pbvbus/s7/cotp_disconnect.hpp"

#include <algorithm>

#include "be.hpp"

#include "pbvbus/s7/cotp.hpp"

namespace pbvbus::s7 {

Decoded<DisconnectTpdu> decode_disconnect(std::span<const std::uint8_t> tpdu) {
  const auto code = cotp_code(tpdu);
  if (!code.ok()) return {{}, code.error, code.at};
  if (tpdu[1] != kCotpDr && tpdu[1] != kCotpDc) return {{}, Error::CotpUnexpectedType, 1};
  const bool dr = tpdu[1] == kCotpDr;
  const std::size_t fixed = dr ? 7 : 6;  // LI code dst(2) src(2) [reason]
  const std::size_t header = std::size_t{tpdu[0]} + 1;
  if (header < fixed || (!dr && header != fixed)) return {{}, Error::CotpBadLengthIndicator, 0};
  DisconnectTpdu d;
  d.code = tpdu[1];
  d.dst_ref = be::u16(tpdu, 2);
  d.src_ref = be::u16(tpdu, 4);
  if (dr) d.reason = tpdu[6];
  return {d};
}

void append_disconnect_request(std::vector<std::uint8_t>& out, std::uint16_t dst_ref,
                               std::uint16_t src_ref, std::uint8_t reason) {
  out.push_back(6);
  out.push_back(kCotpDr);
  be::put_u16(out, dst_ref);
  be::put_u16(out, src_ref);
  out.push_back(reason);
}

void append_disconnect_confirm(std::vector<std::uint8_t>& out, std::uint16_t dst_ref,
                               std::uint16_t src_ref) {
  out.push_back(5);
  out.push_back(kCotpDc);
  be::put_u16(out, dst_ref);
  be::put_u16(out, src_ref);
}

Decoded<ErrorTpdu> decode_error_tpdu(std::span<const std::uint8_t> tpdu) {
  const auto code = cotp_code(tpdu);
  if (!code.ok()) return {{}, code.error, code.at};
  if (tpdu[1] != kCotpEr) return {{}, Error::CotpUnexpectedType, 1};
  constexpr std::size_t kFixed = 5;  // LI code dst(2) cause
  const std::size_t header = std::size_t{tpdu[0]} + 1;
  if (header < kFixed) return {{}, Error::CotpBadLengthIndicator, 0};
  ErrorTpdu e;
  e.dst_ref = be::u16(tpdu, 2);
  e.cause = tpdu[4];
  std::size_t at = kFixed;
  while (at < header) {
    if (at + 2 > header) return {{}, Error::CotpParameterTruncated, at};
    const std::size_t len = tpdu[at + 1];
    if (at + 2 + len > header) return {{}, Error::CotpParameterTruncated, at + 1};
    if (tpdu[at] == kParamInvalidTpdu) {
      if (!e.invalid_tpdu.empty()) return {{}, Error::CotpDuplicateParameter, at};
      e.invalid_tpdu = tpdu.subspan(at + 2, len);
    }
    at += 2 + len;
  }
  return {e};
}

void append_error_tpdu(std::vector<std::uint8_t>& out, std::uint16_t dst_ref, std::uint8_t cause,
                       std::span<const std::uint8_t> invalid_tpdu) {
  // LI = 4 + (2 + n) must stay <= 254 (255 is reserved): n <= 248.
  const std::size_t n = std::min<std::size_t>(invalid_tpdu.size(), 248);
  out.push_back(static_cast<std::uint8_t>(4 + (n > 0 ? 2 + n : 0)));
  out.push_back(kCotpEr);
  be::put_u16(out, dst_ref);
  out.push_back(cause);
  if (n > 0) {
    out.push_back(kParamInvalidTpdu);
    out.push_back(static_cast<std::uint8_t>(n));
    out.insert(out.end(), invalid_tpdu.begin(),
               invalid_tpdu.begin() + static_cast<std::ptrdiff_t>(n));
  }
}

}  // namespace pbvbus::s7
