// The S7 server of a CPU model (s7_server.hpp; choices in docs/s7cpu.md).
#include "pbvbus/s7cpu/s7_server.hpp"

#include <algorithm>
#include <array>
#include <cstring>

#include "pbvbus/s7/s7_item.hpp"
#include "pbvbus/s7/s7_pdu.hpp"
#include "pbvbus/s7/s7_read_var.hpp"
#include "pbvbus/s7/s7_szl.hpp"
#include "pbvbus/s7/s7_write_var.hpp"
#include "pbvbus/s7cpu/szl_lists.hpp"
#include "pbvbus/s7cpu/szl_source.hpp"

namespace pbvbus::s7cpu {
namespace {

using s7::Encoded;
using s7::VarItem;
namespace rc = s7::return_code;

/// Read Var Ack-Data header (12) + parameters `04 <count>` (2).
constexpr std::size_t kReadVarResponseOverhead = 12 + 2;

/// Read SZL answer without records: Userdata header 10, parameters 12, data header 4, list
/// header 8.
constexpr std::size_t kSzlResponseOverhead = 10 + 12 + 4 + 8;

/// Where one variable specification points in the CPU's memory.
struct Target {
  std::uint8_t return_code = rc::kSuccess;
  std::span<std::uint8_t> bytes;     ///< I, Q, M or a DB
  std::span<std::uint16_t> cells;    ///< counters or timers
  bool is_bit = false;
  std::size_t offset = 0;  ///< byte offset, or the first cell
  std::size_t octets = 0;  ///< octets of data on the wire
  std::uint8_t bit = 0;
};

Target fail(std::uint8_t code) {
  Target t;
  t.return_code = code;
  return t;
}

Target resolve(CpuMemory& memory, const VarItem& v) {
  const std::size_t element = s7::element_size(v.transport_size);
  if (element == 0) return fail(rc::kDataTypeNotSupported);
  const bool cell_size =
      v.transport_size == s7::transport::kCounter || v.transport_size == s7::transport::kTimer;
  Target t;
  switch (v.area) {
    case s7::area::kInputs:
      t.bytes = memory.area(Area::Inputs);
      break;
    case s7::area::kOutputs:
      t.bytes = memory.area(Area::Outputs);
      break;
    case s7::area::kFlags:
      t.bytes = memory.area(Area::Flags);
      break;
    case s7::area::kDataBlock: {
      const auto db = memory.db(v.db_number);
      if (!db) return fail(rc::kObjectDoesNotExist);
      t.bytes = *db;
      break;
    }
    case s7::area::kCounter:
    case s7::area::kTimer: {
      const std::uint8_t wanted =
          v.area == s7::area::kCounter ? s7::transport::kCounter : s7::transport::kTimer;
      if (v.transport_size != wanted) return fail(rc::kDataTypeNotSupported);
      t.cells = v.area == s7::area::kCounter ? memory.counters() : memory.timers();
      // For counters and timers the address is their number (s7_item.hpp).
      if (v.count == 0 || v.address > t.cells.size() || t.cells.size() - v.address < v.count) {
        return fail(rc::kAddressOutOfRange);
      }
      t.offset = v.address;
      t.octets = std::size_t{2} * v.count;
      return t;
    }
    default:
      // P, DI, L, V and the IEC counters/timers are not areas of this CPU model.
      return fail(rc::kObjectDoesNotExist);
  }
  if (cell_size) return fail(rc::kDataTypeNotSupported);
  const std::size_t byte = v.byte_offset();
  if (v.transport_size == s7::transport::kBit) {
    // One bit per item (snap7: "More than 1 bit is not supported by S7 CPU").
    if (v.count != 1) return fail(rc::kDataTypeNotSupported);
    if (byte >= t.bytes.size()) return fail(rc::kAddressOutOfRange);
    t.is_bit = true;
    t.offset = byte;
    t.bit = v.bit();
    t.octets = 1;
    return t;
  }
  // Byte-sized elements start on a byte: a bit address other than .0 is out of range.
  if (v.bit() != 0 || v.count == 0) return fail(rc::kAddressOutOfRange);
  const std::size_t octets = element * v.count;
  if (byte > t.bytes.size() || t.bytes.size() - byte < octets) {
    return fail(rc::kAddressOutOfRange);
  }
  t.offset = byte;
  t.octets = octets;
  return t;
}

/// Copies the item out of the memory in one go (one snapshot, cpu_memory.hpp).
void copy_out(const Target& t, std::vector<std::uint8_t>& out) {
  if (!t.cells.empty()) {
    for (std::size_t i = 0; i < t.octets / 2; ++i) {
      const std::uint16_t c = t.cells[t.offset + i];
      out.push_back(static_cast<std::uint8_t>(c >> 8));
      out.push_back(static_cast<std::uint8_t>(c));
    }
  } else if (t.is_bit) {
    out.push_back(static_cast<std::uint8_t>((t.bytes[t.offset] >> t.bit) & 1U));
  } else {
    const auto src = t.bytes.subspan(t.offset, t.octets);
    out.assign(src.begin(), src.end());
  }
}

void copy_in(const Target& t, std::span<const std::uint8_t> data) {
  if (!t.cells.empty()) {
    for (std::size_t i = 0; i < t.octets / 2; ++i) {
      t.cells[t.offset + i] = static_cast<std::uint16_t>((data[2 * i] << 8) | data[2 * i + 1]);
    }
  } else if (t.is_bit) {
    set_bit(t.bytes, t.offset, t.bit, (data[0] & 1U) != 0);
  } else {
    std::copy(data.begin(), data.end(), t.bytes.begin() + static_cast<std::ptrdiff_t>(t.offset));
  }
}

Encoded refuse(std::uint16_t pdu_ref) {
  return s7::encode_s7_pdu(s7::S7Header{s7::kS7Ack, pdu_ref, kRefusedErrorClass, kRefusedErrorCode},
                           {}, {});
}

Encoded read_var(CpuMemory& memory, const s7::S7Pdu& pdu, std::size_t pdu_length) {
  const auto req = s7::decode_read_var_request(pdu);
  if (!req.ok()) return refuse(pdu.header.pdu_ref);
  const auto& items = req.value;
  std::vector<std::vector<std::uint8_t>> values(items.size());
  std::vector<s7::ReadVarResult> results(items.size());
  std::size_t total = kReadVarResponseOverhead;
  for (std::size_t i = 0; i < items.size(); ++i) {
    const Target t = resolve(memory, items[i]);
    auto& r = results[i];
    r.transport_size = s7::data_transport_for(items[i].transport_size);
    if (t.return_code != rc::kSuccess) {
      r.return_code = t.return_code;
      total += s7::kDataItemHeaderLength;
      continue;
    }
    const bool last = i + 1 == items.size();
    const std::size_t size =
        s7::kDataItemHeaderLength + t.octets + ((t.octets % 2 != 0 && !last) ? 1 : 0);
    if (total + size > pdu_length) {
      // The answer would exceed the negotiated PDU: this item only (snap7's RA_SizeOverPDU).
      r.return_code = kReturnCodeDataOverPdu;
      total += s7::kDataItemHeaderLength;
      continue;
    }
    copy_out(t, values[i]);
    r.data = values[i];
    total += size;
  }
  return s7::encode_read_var_response(pdu.header.pdu_ref, results);
}

std::uint8_t write_item(CpuMemory& memory, CpuMemory* mirror, const VarItem& v,
                        const s7::DataItem& value) {
  const Target t = resolve(memory, v);
  if (t.return_code != rc::kSuccess) return t.return_code;
  // A BIT item must come as a BIT data item and the rest must not (s7_item.hpp).
  if (t.is_bit != (value.transport_size == s7::data_transport::kBit)) {
    return rc::kDataTypeNotSupported;
  }
  // The data must be exactly what the variable specification addresses (snap7:
  // Code7WriteDataSizeMismatch).
  const auto length = s7::length_field(value.transport_size, t.octets);
  if (!length.ok() || length.value != value.length || value.data.size() != t.octets) {
    return rc::kDataTypeInconsistent;
  }
  copy_in(t, value.data);
  if (mirror != nullptr) {
    // The partner's copy (s7_server.hpp set_mirror): the same octets or nothing.
    const Target m = resolve(*mirror, v);
    if (m.return_code == rc::kSuccess && m.octets == t.octets && m.is_bit == t.is_bit)
      copy_in(m, value.data);
  }
  return rc::kSuccess;
}

Encoded write_var(CpuMemory& memory, CpuMemory* mirror, const s7::S7Pdu& pdu) {
  const auto req = s7::decode_write_var_request(pdu);
  if (!req.ok()) return refuse(pdu.header.pdu_ref);
  std::vector<std::uint8_t> codes(req.value.items.size());
  for (std::size_t i = 0; i < codes.size(); ++i) {
    codes[i] = write_item(memory, mirror, req.value.items[i], req.value.values[i]);
  }
  return s7::encode_write_var_response(pdu.header.pdu_ref, codes);
}

Encoded read_szl(const CpuInfo& info, SzlSource* source, const s7::S7Pdu& pdu,
                 std::size_t pdu_length) {
  const auto params = s7::decode_userdata_params(pdu);
  if (!params.ok() || params.value.method != s7::kUserdataMethodRequest ||
      params.value.group != s7::kUserdataGroupCpu ||
      params.value.subfunction != s7::kSubfunctionReadSzl) {
    return refuse(pdu.header.pdu_ref);
  }
  const auto req = s7::decode_szl_request(pdu);
  if (!req.ok()) return refuse(pdu.header.pdu_ref);
  // The owner's lists first, then the standard ones (szl_source.hpp).
  std::optional<SzlList> list;
  if (source != nullptr) list = source->read_szl(req.value.id, req.value.index);
  if (!list) list = standard_szl(info, req.value.id, req.value.index);
  if (!list) list = SzlList{SzlStatus::UnknownId, 0, 0, {}};
  s7::SzlResponse r;
  r.sequence = req.value.sequence;
  const std::size_t whole = std::size_t{list->record_length} * list->record_count;
  if (list->status != SzlStatus::Ok || list->records.size() != whole) {
    // A source whose records do not add up is treated as having nothing now.
    r.error_code = szl_error_code(list->status == SzlStatus::Ok ? SzlStatus::NotAvailableNow
                                                                : list->status);
    return s7::encode_szl_response(pdu.header.pdu_ref, r);
  }
  // One data unit: the records that fit the negotiated PDU, N_DR counting those
  // (docs/s7cpu.md "Read SZL").
  std::uint16_t count = list->record_count;
  if (list->record_length != 0 && kSzlResponseOverhead + whole > pdu_length) {
    const std::size_t room = pdu_length > kSzlResponseOverhead ? pdu_length - kSzlResponseOverhead : 0;
    count = static_cast<std::uint16_t>(room / list->record_length);
  }
  r.id = req.value.id;
  r.index = req.value.index;
  r.record_length = list->record_length;
  r.record_count = count;
  r.records = std::span<const std::uint8_t>(list->records)
                  .first(std::size_t{count} * list->record_length);
  return s7::encode_szl_response(pdu.header.pdu_ref, r);
}

}  // namespace

S7Server::S7Server(CpuMemory& memory, const CpuInfo& info, const s7::SetupCommunication& own)
    : memory_(memory), info_(info), own_(own), negotiated_(own) {}

Encoded S7Server::handle(std::span<const std::uint8_t> octets) {
  const auto decoded = s7::decode_s7_pdu(octets);
  if (!decoded.ok()) return {{}, decoded.error, decoded.at};
  const s7::S7Pdu& pdu = decoded.value;
  const std::uint16_t ref = pdu.header.pdu_ref;
  if (pdu.header.type != s7::kS7Job && pdu.header.type != s7::kS7Userdata) {
    return {{}, s7::Error::S7WrongPduType, 1};
  }
  if (pdu.header.type == s7::kS7Job && !pdu.params.empty() &&
      pdu.params[0] == s7::kFnSetupCommunication) {
    const auto req = s7::decode_setup_communication(pdu);
    if (!req.ok()) return refuse(ref);
    negotiated_ = s7::negotiate(req.value, own_);
    setup_done_ = true;
    return s7::encode_setup_communication_response(ref, negotiated_);
  }
  // Anything before Setup Communication is refused (docs/s7cpu.md).
  if (!setup_done_) return refuse(ref);
  if (pdu.header.type == s7::kS7Userdata)
    return read_szl(info_, szl_source_, pdu, negotiated_.pdu_length);
  if (pdu.params.empty()) return refuse(ref);
  switch (pdu.params[0]) {
    case s7::kFnReadVar:
      return read_var(memory_, pdu, negotiated_.pdu_length);
    case s7::kFnWriteVar:
      return write_var(memory_, mirror_, pdu);
    default:
      return refuse(ref);
  }
}

}  // namespace pbvbus::s7cpu
