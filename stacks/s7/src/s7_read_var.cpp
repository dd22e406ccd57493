// Read Var codec (protocol-facts.md §H.4; s7_read_var.hpp).
#include "pbvbus/s7/s7_read_var.hpp"

namespace pbvbus::s7 {

Decoded<std::vector<VarItem>> decode_var_items(const S7Pdu& pdu, std::uint8_t function) {
  if (pdu.header.type != kS7Job) return {{}, Error::S7WrongPduType, 1};
  const auto p = pdu.params;
  const std::size_t base = params_offset(pdu);
  if (p.size() < 2) return {{}, Error::S7BadParameterLength, 6};
  if (p[0] != function) return {{}, Error::S7UnexpectedFunction, base};
  const std::size_t count = p[1];
  if (count == 0) return {{}, Error::S7NoItems, base + 1};
  if (p.size() != 2 + count * kVarItemLength) return {{}, Error::S7BadParameterLength, 6};
  Decoded<std::vector<VarItem>> r;
  r.value.reserve(count);
  for (std::size_t i = 0; i < count; ++i) {
    const std::size_t at = 2 + i * kVarItemLength;
    const auto v = decode_var_item(p.subspan(at, kVarItemLength));
    if (!v.ok()) return {{}, v.error, base + at + v.at};
    r.value.push_back(v.value);
  }
  return r;
}

Decoded<std::vector<VarItem>> decode_read_var_request(const S7Pdu& pdu) {
  auto r = decode_var_items(pdu, kFnReadVar);
  if (r.ok() && !pdu.data.empty()) return {{}, Error::S7UnexpectedData, data_offset(pdu)};
  return r;
}

Encoded encode_read_var_request(std::uint16_t pdu_ref, std::span<const VarItem> items) {
  if (items.empty()) return {{}, Error::S7NoItems, 0};
  if (items.size() > kMaxItems) return {{}, Error::S7TooManyItems, 0};
  std::vector<std::uint8_t> params{kFnReadVar, static_cast<std::uint8_t>(items.size())};
  params.reserve(2 + items.size() * kVarItemLength);
  for (std::size_t i = 0; i < items.size(); ++i) {
    if (const Error e = append_var_item(params, items[i]); e != Error::None) return {{}, e, i};
  }
  return encode_s7_pdu(S7Header{kS7Job, pdu_ref, 0, 0}, params, {});
}

Decoded<std::vector<DataItem>> decode_read_var_response(const S7Pdu& pdu) {
  if (pdu.header.type != kS7AckData) return {{}, Error::S7WrongPduType, 1};
  const auto p = pdu.params;
  const std::size_t base = params_offset(pdu);
  if (p.size() != 2) return {{}, Error::S7BadParameterLength, 6};
  if (p[0] != kFnReadVar) return {{}, Error::S7UnexpectedFunction, base};
  if (p[1] == 0) return {{}, Error::S7NoItems, base + 1};
  return decode_data_items(pdu.data, p[1], true, data_offset(pdu));
}

Encoded encode_read_var_response(std::uint16_t pdu_ref, std::span<const ReadVarResult> items) {
  if (items.empty()) return {{}, Error::S7NoItems, 0};
  if (items.size() > kMaxItems) return {{}, Error::S7TooManyItems, 0};
  const std::vector<std::uint8_t> params{kFnReadVar, static_cast<std::uint8_t>(items.size())};
  std::vector<std::uint8_t> data;
  for (std::size_t i = 0; i < items.size(); ++i) {
    const auto& it = items[i];
    const Error e = append_data_item(data, it.return_code, it.transport_size, it.data,
                                     i + 1 < items.size(), true);
    if (e != Error::None) return {{}, e, i};
  }
  return encode_s7_pdu(S7Header{kS7AckData, pdu_ref, 0, 0}, params, data);
}

}  // namespace pbvbus::s7
