// Userdata parameters and Read SZL (snap7 s7_types.h / s7_server.cpp, Wireshark s7comm;
// s7_szl.hpp).
#include "pbvbus/s7/s7_szl.hpp"

#include "be.hpp"

namespace pbvbus::s7 {
namespace {

constexpr std::uint8_t kHead[3] = {0x00, 0x01, 0x12};
constexpr std::uint8_t kDataOk = 0xFF;
constexpr std::uint8_t kDataOctetString = 0x09;
constexpr std::uint8_t kDataNotAvailable = 0x0A;
constexpr std::size_t kDataHeader = 4;     // return code, transport size, length
constexpr std::size_t kSzlListHeader = 8;  // SZL-ID, index, LENTHDR, N_DR

Decoded<UserdataParams> szl_params(const S7Pdu& pdu, std::uint8_t method, std::uint8_t type) {
  auto u = decode_userdata_params(pdu);
  if (!u.ok()) return u;
  const std::size_t base = params_offset(pdu);
  if (u.value.method != method || u.value.type != type)
    return {{}, Error::S7UnexpectedUserdata, base + 4};
  if (u.value.group != kUserdataGroupCpu) return {{}, Error::S7UnexpectedUserdata, base + 5};
  if (u.value.subfunction != kSubfunctionReadSzl)
    return {{}, Error::S7UnexpectedUserdata, base + 6};
  return u;
}

}  // namespace

Decoded<UserdataParams> decode_userdata_params(const S7Pdu& pdu) {
  if (pdu.header.type != kS7Userdata) return {{}, Error::S7WrongPduType, 1};
  const auto p = pdu.params;
  const std::size_t base = params_offset(pdu);
  if (p.size() < 4) return {{}, Error::S7BadUserdataLength, 6};
  if (p[0] != kHead[0] || p[1] != kHead[1] || p[2] != kHead[2])
    return {{}, Error::S7BadUserdataHead, base};
  if ((p[3] != 4 && p[3] != 8) || p.size() != 4 + std::size_t{p[3]})
    return {{}, Error::S7BadUserdataLength, base + 3};
  UserdataParams u;
  u.method = p[4];
  u.type = static_cast<std::uint8_t>(p[5] >> 4);
  u.group = static_cast<std::uint8_t>(p[5] & 0x0F);
  u.subfunction = p[6];
  u.sequence = p[7];
  if (p[3] == 8) {
    u.extended = true;
    u.data_unit_ref = p[8];
    u.last_data_unit = p[9];
    u.error_code = be::u16(p, 10);
  }
  return {u};
}

void append_userdata_params(std::vector<std::uint8_t>& out, const UserdataParams& u) {
  out.insert(out.end(), std::begin(kHead), std::end(kHead));
  out.push_back(u.extended ? 8 : 4);
  out.push_back(u.method);
  out.push_back(static_cast<std::uint8_t>((u.type << 4) | (u.group & 0x0F)));
  out.push_back(u.subfunction);
  out.push_back(u.sequence);
  if (u.extended) {
    out.push_back(u.data_unit_ref);
    out.push_back(u.last_data_unit);
    be::put_u16(out, u.error_code);
  }
}

Decoded<SzlRequest> decode_szl_request(const S7Pdu& pdu) {
  const auto u = szl_params(pdu, kUserdataMethodRequest, kUserdataTypeRequest);
  if (!u.ok()) return {{}, u.error, u.at};
  const auto d = pdu.data;
  const std::size_t base = data_offset(pdu);
  if (d.size() != kDataHeader + 4) return {{}, Error::S7BadSzlRequest, 8};
  if (d[0] != kDataOk) return {{}, Error::S7BadSzlRequest, base};
  if (d[1] != kDataOctetString) return {{}, Error::S7BadSzlRequest, base + 1};
  if (be::u16(d, 2) != 4) return {{}, Error::S7BadSzlRequest, base + 2};
  return {SzlRequest{u.value.sequence, be::u16(d, 4), be::u16(d, 6)}};
}

Encoded encode_szl_request(std::uint16_t pdu_ref, const SzlRequest& r) {
  UserdataParams u;
  u.sequence = r.sequence;
  std::vector<std::uint8_t> params;
  append_userdata_params(params, u);
  std::vector<std::uint8_t> data{kDataOk, kDataOctetString, 0x00, 0x04};
  be::put_u16(data, r.id);
  be::put_u16(data, r.index);
  return encode_s7_pdu(S7Header{kS7Userdata, pdu_ref, 0, 0}, params, data);
}

Decoded<SzlResponse> decode_szl_response(const S7Pdu& pdu) {
  const auto u = szl_params(pdu, kUserdataMethodResponse, kUserdataTypeResponse);
  if (!u.ok()) return {{}, u.error, u.at};
  const auto d = pdu.data;
  const std::size_t base = data_offset(pdu);
  SzlResponse r;
  r.sequence = u.value.sequence;
  r.error_code = u.value.error_code;
  if (d.size() < kDataHeader) return {{}, Error::S7BadSzlResponse, 8};
  if (be::u16(d, 2) != d.size() - kDataHeader) return {{}, Error::S7BadSzlResponse, base + 2};
  if (r.error_code != 0 || d[0] != kDataOk) {
    // No list: the error code (or the data return code) says why.
    if (d.size() != kDataHeader) return {{}, Error::S7BadSzlResponse, base + kDataHeader};
    return {r};
  }
  if (d[1] != kDataOctetString) return {{}, Error::S7BadSzlResponse, base + 1};
  if (d.size() < kDataHeader + kSzlListHeader) return {{}, Error::S7BadSzlResponse, 8};
  r.id = be::u16(d, 4);
  r.index = be::u16(d, 6);
  r.record_length = be::u16(d, 8);
  r.record_count = be::u16(d, 10);
  r.records = d.subspan(kDataHeader + kSzlListHeader);
  const std::size_t whole = std::size_t{r.record_length} * r.record_count;
  // A list split over several data units carries part of its records in each.
  const bool single_unit = !u.value.extended || (u.value.data_unit_ref == 0 &&
                                                 u.value.last_data_unit == kLastDataUnitYes);
  if (single_unit ? r.records.size() != whole : r.records.size() > whole)
    return {{}, Error::S7BadSzlResponse, base + 8};
  return {r};
}

Encoded encode_szl_response(std::uint16_t pdu_ref, const SzlResponse& r) {
  UserdataParams u;
  u.method = kUserdataMethodResponse;
  u.type = kUserdataTypeResponse;
  u.sequence = r.sequence;
  u.extended = true;
  u.error_code = r.error_code;
  std::vector<std::uint8_t> params;
  append_userdata_params(params, u);
  std::vector<std::uint8_t> data;
  if (r.error_code != 0) {
    data = {kDataNotAvailable, 0x00, 0x00, 0x00};
  } else {
    if (r.records.size() != std::size_t{r.record_length} * r.record_count)
      return {{}, Error::S7BadSzlResponse, 0};
    const std::size_t len = kSzlListHeader + r.records.size();
    if (len > 0xFFFF - kDataHeader) return {{}, Error::S7PduTooLarge, 0};
    data = {kDataOk, kDataOctetString};
    data.reserve(kDataHeader + len);
    be::put_u16(data, static_cast<std::uint16_t>(len));
    be::put_u16(data, r.id);
    be::put_u16(data, r.index);
    be::put_u16(data, r.record_length);
    be::put_u16(data, r.record_count);
    be::append(data, r.records);
  }
  return encode_s7_pdu(S7Header{kS7Userdata, pdu_ref, 0, 0}, params, data);
}

}  // namespace pbvbus::s7
