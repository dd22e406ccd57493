// Write Var codec (protocol-facts.md §H.4; s7_write_var.hpp).
#include "pbvbus/s7/s7_write_var.hpp"

#include "pbvbus/s7/s7_read_var.hpp"

namespace pbvbus::s7 {

Decoded<WriteVarRequest> decode_write_var_request(const S7Pdu& pdu) {
  const auto items = decode_var_items(pdu, kFnWriteVar);
  if (!items.ok()) return {{}, items.error, items.at};
  auto values = decode_data_items(pdu.data, items.value.size(), false, data_offset(pdu));
  if (!values.ok()) return {{}, values.error, values.at};
  return {WriteVarRequest{items.value, std::move(values.value)}};
}

Encoded encode_write_var_request(std::uint16_t pdu_ref, std::span<const WriteVarItem> items) {
  if (items.empty()) return {{}, Error::S7NoItems, 0};
  if (items.size() > kMaxItems) return {{}, Error::S7TooManyItems, 0};
  std::vector<std::uint8_t> params{kFnWriteVar, static_cast<std::uint8_t>(items.size())};
  std::vector<std::uint8_t> data;
  for (std::size_t i = 0; i < items.size(); ++i) {
    const auto& it = items[i];
    if (const Error e = append_var_item(params, it.var); e != Error::None) return {{}, e, i};
    const Error e = append_data_item(data, return_code::kReserved, it.transport_size, it.data,
                                     i + 1 < items.size(), false);
    if (e != Error::None) return {{}, e, i};
  }
  return encode_s7_pdu(S7Header{kS7Job, pdu_ref, 0, 0}, params, data);
}

Decoded<std::vector<std::uint8_t>> decode_write_var_response(const S7Pdu& pdu) {
  if (pdu.header.type != kS7AckData) return {{}, Error::S7WrongPduType, 1};
  const auto p = pdu.params;
  const std::size_t base = params_offset(pdu);
  if (p.size() != 2) return {{}, Error::S7BadParameterLength, 6};
  if (p[0] != kFnWriteVar) return {{}, Error::S7UnexpectedFunction, base};
  if (p[1] == 0) return {{}, Error::S7NoItems, base + 1};
  if (pdu.data.size() < p[1])
    return {{}, Error::S7DataTruncated, data_offset(pdu) + pdu.data.size()};
  if (pdu.data.size() > p[1]) return {{}, Error::S7TrailingData, data_offset(pdu) + p[1]};
  return {std::vector<std::uint8_t>(pdu.data.begin(), pdu.data.end())};
}

Encoded encode_write_var_response(std::uint16_t pdu_ref, std::span<const std::uint8_t> codes) {
  if (codes.empty()) return {{}, Error::S7NoItems, 0};
  if (codes.size() > kMaxItems) return {{}, Error::S7TooManyItems, 0};
  const std::vector<std::uint8_t> params{kFnWriteVar, static_cast<std::uint8_t>(codes.size())};
  return encode_s7_pdu(S7Header{kS7AckData, pdu_ref, 0, 0}, params, codes);
}

}  // namespace pbvbus::s7
