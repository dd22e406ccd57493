// Variable specifications and data items (protocol-facts.md §H.4; s7_item.hpp).
#include "pbvbus/s7/s7_item.hpp"

#include <algorithm>

#include "be.hpp"

namespace pbvbus::s7 {

Decoded<VarItem> decode_var_item(std::span<const std::uint8_t> item) {
  if (item.size() < 3) return {{}, Error::S7BadParameterLength, item.size()};
  if (item[0] != kVarSpecification) return {{}, Error::S7BadItemHeader, 0};
  if (item[2] != kSyntaxIdS7Any) return {{}, Error::S7UnsupportedSyntaxId, 2};
  if (item[1] != kS7AnyLength) return {{}, Error::S7BadItemLength, 1};
  if (item.size() != kVarItemLength) return {{}, Error::S7BadParameterLength, item.size()};
  VarItem v;
  v.transport_size = item[3];
  v.count = be::u16(item, 4);
  v.db_number = be::u16(item, 6);
  v.area = item[8];
  v.address = be::u24(item, 9);
  return {v};
}

Error append_var_item(std::vector<std::uint8_t>& out, const VarItem& v) {
  if (v.address > kMaxBitAddress) return Error::S7AddressTooLarge;
  out.push_back(kVarSpecification);
  out.push_back(kS7AnyLength);
  out.push_back(kSyntaxIdS7Any);
  out.push_back(v.transport_size);
  be::put_u16(out, v.count);
  be::put_u16(out, v.db_number);
  out.push_back(v.area);
  be::put_u24(out, v.address);
  return Error::None;
}

std::size_t element_size(std::uint8_t transport_size) {
  switch (transport_size) {
    case transport::kBit:
    case transport::kByte:
    case transport::kChar:
      return 1;
    case transport::kWord:
    case transport::kInt:
    case transport::kCounter:
    case transport::kTimer:
      return 2;
    case transport::kDWord:
    case transport::kDInt:
    case transport::kReal:
      return 4;
    default:
      return 0;
  }
}

std::uint8_t data_transport_for(std::uint8_t transport_size) {
  switch (transport_size) {
    case transport::kBit:
      return data_transport::kBit;
    case transport::kInt:
    case transport::kDInt:
      return data_transport::kInteger;
    case transport::kReal:
      return data_transport::kReal;
    case transport::kChar:
    case transport::kCounter:
    case transport::kTimer:
      return data_transport::kOctetString;
    default:
      return data_transport::kByte;
  }
}

namespace {

enum class Unit { Bits, Octets, Unknown };

Unit unit_of(std::uint8_t data_transport_size) {
  switch (data_transport_size) {
    case data_transport::kBit:
    case data_transport::kByte:
    case data_transport::kInteger:
      return Unit::Bits;
    case data_transport::kDInteger:
    case data_transport::kReal:
    case data_transport::kOctetString:
      return Unit::Octets;
    default:
      return Unit::Unknown;
  }
}

}  // namespace

Decoded<std::size_t> data_octets(std::uint8_t data_transport_size, std::uint16_t length) {
  switch (unit_of(data_transport_size)) {
    case Unit::Bits:
      return {(std::size_t{length} + 7) / 8};
    case Unit::Octets:
      return {length};
    case Unit::Unknown:
      break;
  }
  return {0, Error::S7BadDataTransportSize, 0};
}

Decoded<std::uint16_t> length_field(std::uint8_t data_transport_size, std::size_t octets) {
  const Unit u = unit_of(data_transport_size);
  if (u == Unit::Unknown) return {0, Error::S7BadDataTransportSize, 0};
  if (data_transport_size == data_transport::kBit) {
    if (octets > 1) return {0, Error::S7ItemLengthMismatch, 0};
    return {static_cast<std::uint16_t>(octets)};
  }
  const std::size_t len = u == Unit::Bits ? octets * 8 : octets;
  if (len > 0xFFFF) return {0, Error::S7ItemTooLong, 0};
  return {static_cast<std::uint16_t>(len)};
}

Decoded<std::vector<DataItem>> decode_data_items(std::span<const std::uint8_t> block,
                                                 std::size_t count, bool failed_items_are_short,
                                                 std::size_t base) {
  Decoded<std::vector<DataItem>> r;
  r.value.reserve(std::min(count, block.size() / kDataItemHeaderLength + 1));
  std::size_t at = 0;
  for (std::size_t i = 0; i < count; ++i) {
    if (at + kDataItemHeaderLength > block.size()) return {{}, Error::S7DataTruncated, base + at};
    DataItem d;
    d.return_code = block[at];
    d.transport_size = block[at + 1];
    d.length = be::u16(block, at + 2);
    at += kDataItemHeaderLength;
    if (!(failed_items_are_short && d.return_code != return_code::kSuccess)) {
      const auto n = data_octets(d.transport_size, d.length);
      if (!n.ok()) return {{}, n.error, base + at - 3};
      if (at + n.value > block.size()) return {{}, Error::S7DataTruncated, base + at - 2};
      d.data = block.subspan(at, n.value);
      at += n.value;
      if (n.value % 2 == 1 && i + 1 < count) {
        if (at >= block.size()) return {{}, Error::S7DataTruncated, base + at};
        ++at;  // fill octet
      }
    }
    r.value.push_back(d);
  }
  if (at != block.size()) return {{}, Error::S7TrailingData, base + at};
  return r;
}

Error append_data_item(std::vector<std::uint8_t>& out, std::uint8_t return_code,
                       std::uint8_t data_transport_size, std::span<const std::uint8_t> data,
                       bool more_follow, bool failed_items_are_short) {
  if (failed_items_are_short && return_code != return_code::kSuccess) {
    out.push_back(return_code);
    out.push_back(data_transport::kNull);
    be::put_u16(out, 0);
    return Error::None;
  }
  const auto len = length_field(data_transport_size, data.size());
  if (!len.ok()) return len.error;
  out.push_back(return_code);
  out.push_back(data_transport_size);
  be::put_u16(out, len.value);
  be::append(out, data);
  if (more_follow && data.size() % 2 == 1) out.push_back(0x00);
  return Error::None;
}

}  // namespace pbvbus::s7
