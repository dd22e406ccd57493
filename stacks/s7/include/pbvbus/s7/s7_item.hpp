#pragma once
// Read/Write Var item addressing and the data items that carry values (protocol-facts.md §H.4;
// Wireshark's s7comm dissector for the names and the length units; snap7's server for what a
// server answers).
//
// Variable specification (12 octets, syntax id S7ANY):
//   12 0A 10 | transport size | count u16 | DB number u16 | area | address u24 (bit address)
// The address is byte * 8 + bit; for counters and timers (area 1C/1D) it is their number.
//
// Data item (Read Var response, Write Var request):
//   return code | data transport size | length u16 | data | fill 00 if the data length is odd
//   and another item follows.
// Length unit by data transport size: BIT (03), BYTE/WORD/DWORD (04), INTEGER (05) in bits;
// DINTEGER (06), REAL (07), OCTET STRING (09) in octets.
//
// Decisions (docs/s7.md "Items"):
// - An item whose return code is not FF (success) in a Read Var response is 4 octets and carries
//   no data, whatever its length field says (a CPU sends `0A 00 00 00`; snap7's server writes a
//   length of 4 with no data); the encoder writes `RC 00 00 00`.
// - The fill octet is written as 00 and not checked when decoding.
// - A BIT item carries one bit in one octet (length 1); S7 CPUs refuse more than one bit per
//   item (snap7: "More than 1 bit is not supported by S7 CPU").
#include <cstdint>
#include <span>
#include <vector>

#include "pbvbus/s7/error.hpp"

namespace pbvbus::s7 {

inline constexpr std::uint8_t kVarSpecification = 0x12;
inline constexpr std::uint8_t kS7AnyLength = 0x0A;
inline constexpr std::uint8_t kSyntaxIdS7Any = 0x10;
inline constexpr std::size_t kVarItemLength = 12;
inline constexpr std::size_t kDataItemHeaderLength = 4;
inline constexpr std::uint32_t kMaxBitAddress = 0xFFFFFF;

/// Area codes (protocol-facts.md §H.4).
namespace area {
inline constexpr std::uint8_t kPeripheral = 0x80;
inline constexpr std::uint8_t kInputs = 0x81;
inline constexpr std::uint8_t kOutputs = 0x82;
inline constexpr std::uint8_t kFlags = 0x83;
inline constexpr std::uint8_t kDataBlock = 0x84;
inline constexpr std::uint8_t kInstanceDataBlock = 0x85;
inline constexpr std::uint8_t kLocal = 0x86;
inline constexpr std::uint8_t kPreviousLocal = 0x87;  ///< "V"
inline constexpr std::uint8_t kCounter = 0x1C;
inline constexpr std::uint8_t kTimer = 0x1D;
inline constexpr std::uint8_t kIecCounter = 0x1E;
inline constexpr std::uint8_t kIecTimer = 0x1F;
}  // namespace area

/// Transport sizes of a variable specification (the element type asked for).
namespace transport {
inline constexpr std::uint8_t kBit = 0x01;
inline constexpr std::uint8_t kByte = 0x02;
inline constexpr std::uint8_t kChar = 0x03;
inline constexpr std::uint8_t kWord = 0x04;
inline constexpr std::uint8_t kInt = 0x05;
inline constexpr std::uint8_t kDWord = 0x06;
inline constexpr std::uint8_t kDInt = 0x07;
inline constexpr std::uint8_t kReal = 0x08;
inline constexpr std::uint8_t kCounter = 0x1C;
inline constexpr std::uint8_t kTimer = 0x1D;
}  // namespace transport

/// Transport sizes of a data item (how the length field counts).
namespace data_transport {
inline constexpr std::uint8_t kNull = 0x00;
inline constexpr std::uint8_t kBit = 0x03;          ///< length in bits
inline constexpr std::uint8_t kByte = 0x04;         ///< BYTE/WORD/DWORD, length in bits
inline constexpr std::uint8_t kInteger = 0x05;      ///< length in bits
inline constexpr std::uint8_t kDInteger = 0x06;     ///< length in octets
inline constexpr std::uint8_t kReal = 0x07;         ///< length in octets
inline constexpr std::uint8_t kOctetString = 0x09;  ///< length in octets
}  // namespace data_transport

/// Item return codes (Wireshark packet-s7comm.h; snap7 s7_types.h).
namespace return_code {
inline constexpr std::uint8_t kReserved = 0x00;  ///< also the first octet of Write Var data items
inline constexpr std::uint8_t kHardwareFault = 0x01;
inline constexpr std::uint8_t kAccessDenied = 0x03;
inline constexpr std::uint8_t kAddressOutOfRange = 0x05;
inline constexpr std::uint8_t kDataTypeNotSupported = 0x06;  ///< bad transport size
inline constexpr std::uint8_t kDataTypeInconsistent = 0x07;  ///< write data size mismatch
inline constexpr std::uint8_t kObjectDoesNotExist = 0x0A;    ///< e.g. a DB that is not loaded
inline constexpr std::uint8_t kSuccess = 0xFF;
}  // namespace return_code

struct VarItem {
  std::uint8_t transport_size = transport::kByte;
  std::uint16_t count = 1;
  std::uint16_t db_number = 0;
  std::uint8_t area = area::kDataBlock;
  std::uint32_t address = 0;  ///< bit address, 24 bits

  std::uint32_t byte_offset() const { return address >> 3; }
  std::uint8_t bit() const { return static_cast<std::uint8_t>(address & 0x07); }
  bool operator==(const VarItem&) const = default;
};

/// One 12-octet variable specification.
Decoded<VarItem> decode_var_item(std::span<const std::uint8_t> item);
/// S7AddressTooLarge above 24 bits; `out` unchanged on an error.
Error append_var_item(std::vector<std::uint8_t>& out, const VarItem& v);

/// Octets per element of a variable transport size (BIT 1, BYTE/CHAR 1, WORD/INT 2,
/// DWORD/DINT/REAL 4, COUNTER/TIMER 2); 0 for one this codec does not know.
std::size_t element_size(std::uint8_t transport_size);
/// The data transport size a server answers for a variable transport size (snap7's server):
/// BIT -> 03, INT/DINT -> 05, REAL -> 07, CHAR/COUNTER/TIMER -> 09, the rest -> 04.
std::uint8_t data_transport_for(std::uint8_t transport_size);

/// Octets of data for a length field; S7BadDataTransportSize for an unknown data transport size.
Decoded<std::size_t> data_octets(std::uint8_t data_transport_size, std::uint16_t length);
/// The length field for `octets` of data; S7ItemTooLong if it does not fit 16 bits,
/// S7ItemLengthMismatch for a BIT item of more than one octet.
Decoded<std::uint16_t> length_field(std::uint8_t data_transport_size, std::size_t octets);

/// A data item as decoded; `data` points into the decoded PDU.
struct DataItem {
  std::uint8_t return_code = return_code::kSuccess;
  std::uint8_t transport_size = data_transport::kByte;
  std::uint16_t length = 0;  ///< as on the wire
  std::span<const std::uint8_t> data;
};

/// Decodes `count` data items from a data block. With `failed_items_are_short` (Read Var
/// responses) an item whose return code is not FF is 4 octets without data. `base` is added to
/// error offsets (the data block's offset in the PDU).
Decoded<std::vector<DataItem>> decode_data_items(std::span<const std::uint8_t> block,
                                                 std::size_t count, bool failed_items_are_short,
                                                 std::size_t base);

/// Appends one data item with its length field computed from `data`, and the fill octet when
/// `more_follow` and the data length is odd. Failed items (return code != FF and
/// `failed_items_are_short`) are written as `RC 00 00 00`.
Error append_data_item(std::vector<std::uint8_t>& out, std::uint8_t return_code,
                       std::uint8_t data_transport_size, std::span<const std::uint8_t> data,
                       bool more_follow, bool failed_items_are_short);

}  // namespace pbvbus::s7
