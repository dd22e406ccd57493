#pragma once
// Write Var (function 05; protocol-facts.md §H.4):
//   Job:      params `05 <count> <count x variable specification>`,
//             data = <count> data items `00 <data transport size> <length> <data> [fill]`
//   Ack-Data: params `05 <count>`, data = one return code per item (FF = success)
#include <cstdint>
#include <span>
#include <vector>

#include "pbvbus/s7/error.hpp"
#include "pbvbus/s7/s7_item.hpp"
#include "pbvbus/s7/s7_pdu.hpp"

namespace pbvbus::s7 {

struct WriteVarRequest {
  std::vector<VarItem> items;
  std::vector<DataItem> values;  ///< one per item, data pointing into the decoded PDU
};

/// One item of a Write Var Job as a client gives it.
struct WriteVarItem {
  VarItem var;
  std::uint8_t transport_size = data_transport::kByte;  ///< data transport size
  std::span<const std::uint8_t> data;
};

/// The data items' first octet (reserved, 00) is not checked.
Decoded<WriteVarRequest> decode_write_var_request(const S7Pdu& pdu);
Encoded encode_write_var_request(std::uint16_t pdu_ref, std::span<const WriteVarItem> items);

/// The return codes, one per item.
Decoded<std::vector<std::uint8_t>> decode_write_var_response(const S7Pdu& pdu);
Encoded encode_write_var_response(std::uint16_t pdu_ref, std::span<const std::uint8_t> codes);

}  // namespace pbvbus::s7
