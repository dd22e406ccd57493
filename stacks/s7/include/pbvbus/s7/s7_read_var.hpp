#pragma once
// Read Var (function 04; protocol-facts.md §H.4; tools-and-formats.md §3.4):
//   Job:      params `04 <count> <count x 12-octet variable specification>`, no data
//   Ack-Data: params `04 <count>`, data = <count> data items (s7_item.hpp)
#include <cstdint>
#include <span>
#include <vector>

#include "pbvbus/s7/error.hpp"
#include "pbvbus/s7/s7_item.hpp"
#include "pbvbus/s7/s7_pdu.hpp"

namespace pbvbus::s7 {

inline constexpr std::size_t kMaxItems = 255;  ///< the item count is one octet

/// Parameters `Fn <count> items` as Read Var and Write Var Jobs share them.
Decoded<std::vector<VarItem>> decode_var_items(const S7Pdu& pdu, std::uint8_t function);

Decoded<std::vector<VarItem>> decode_read_var_request(const S7Pdu& pdu);
Encoded encode_read_var_request(std::uint16_t pdu_ref, std::span<const VarItem> items);

/// One result of a Read Var response as a server gives it.
struct ReadVarResult {
  std::uint8_t return_code = return_code::kSuccess;
  std::uint8_t transport_size = data_transport::kByte;  ///< data transport size
  std::span<const std::uint8_t> data;                   ///< not sent for a failed item
};

/// The response items (failed items carry no data).
Decoded<std::vector<DataItem>> decode_read_var_response(const S7Pdu& pdu);
Encoded encode_read_var_response(std::uint16_t pdu_ref, std::span<const ReadVarResult> items);

}  // namespace pbvbus::s7
