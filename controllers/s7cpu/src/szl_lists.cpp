// The standard SZL lists from CpuInfo (szl_lists.hpp) and the SZL error codes (szl_source.hpp).
#include "pbvbus/s7cpu/szl_lists.hpp"

#include <string_view>

namespace pbvbus::s7cpu {
namespace {

/// W#16#xy11 record: index, MlfB 20, BGTyp, Ausbg1, Ausbg2.
constexpr std::uint16_t kModuleRecordLength = 28;
constexpr std::size_t kMlfbLength = 20;
/// W#16#xy1C record: index and 32 octets.
constexpr std::uint16_t kComponentRecordLength = 34;
/// W#16#0424 record: ereig u16, ae, bzu-id, then reserved, event info and a time stamp.
constexpr std::uint16_t kStateRecordLength = 20;
constexpr std::size_t kStateOctet = 3;
/// The copyright entry of index 0004 (the manual's constant).
constexpr std::string_view kCopyright = "Original Siemens Equipment";

void put_u16(std::vector<std::uint8_t>& out, std::uint16_t v) {
  out.push_back(static_cast<std::uint8_t>(v >> 8));
  out.push_back(static_cast<std::uint8_t>(v));
}

/// `text` in `width` octets, cut or filled with `fill`.
void put_text(std::vector<std::uint8_t>& out, std::string_view text, std::size_t width,
              std::uint8_t fill) {
  for (std::size_t i = 0; i < width; ++i)
    out.push_back(i < text.size() ? static_cast<std::uint8_t>(text[i]) : fill);
}

void module_record(std::vector<std::uint8_t>& out, const CpuInfo& info) {
  put_u16(out, 0x0001);
  put_text(out, info.order_number, kMlfbLength, ' ');  // 19 characters and a blank
  put_u16(out, 0x0000);                                // BGTyp: reserved
  put_u16(out, info.module_version);                   // Ausbg1: version of the module
  put_u16(out, 0x0000);                                // Ausbg2: reserved for index 0001
}

constexpr std::uint16_t kComponents[] = {0x0001, 0x0002, 0x0003, 0x0004, 0x0005, 0x0007};

/// One xy1C record; false for an index the model has not.
bool component_record(std::vector<std::uint8_t>& out, const CpuInfo& info, std::uint16_t index) {
  std::string_view text;
  std::size_t width = 24;
  switch (index) {
    case 0x0001: text = info.plc_name; break;
    case 0x0002: text = info.module_name; break;
    case 0x0003: text = info.plant_id; width = 32; break;
    case 0x0004: text = kCopyright; width = 26; break;
    case 0x0005: text = info.serial_number; break;
    case 0x0007: text = info.module_type_name; width = 32; break;
    default: return false;
  }
  put_u16(out, index);
  put_text(out, text, width, 0x00);
  for (std::size_t i = width; i < 32; ++i) out.push_back(0x00);  // reserved
  return true;
}

SzlList list(std::uint16_t record_length) {
  SzlList l;
  l.record_length = record_length;
  return l;
}

SzlList failed(SzlStatus s) {
  SzlList l;
  l.status = s;
  return l;
}

}  // namespace

std::uint16_t szl_error_code(SzlStatus s) {
  switch (s) {
    case SzlStatus::Ok: return 0;
    case SzlStatus::UnknownId: return kSzlErrorInvalidId;
    case SzlStatus::UnknownIndex: return kSzlErrorInvalidIndex;
    case SzlStatus::NotAvailableNow: break;
  }
  return kSzlErrorNotAvailable;
}

std::optional<SzlList> standard_szl(const CpuInfo& info, std::uint16_t id, std::uint16_t index) {
  switch (id) {
    case kSzlModuleIdentification: {
      // All records: the model has the module's (W#16#0001) only.
      SzlList l = list(kModuleRecordLength);
      module_record(l.records, info);
      l.record_count = 1;
      return l;
    }
    case kSzlOneModuleIdentification: {
      if (index != 0x0001) return failed(SzlStatus::UnknownIndex);
      SzlList l = list(kModuleRecordLength);
      module_record(l.records, info);
      l.record_count = 1;
      return l;
    }
    case kSzlComponentIdentification: {
      SzlList l = list(kComponentRecordLength);
      for (const std::uint16_t i : kComponents) component_record(l.records, info, i);
      l.record_count = static_cast<std::uint16_t>(std::size(kComponents));
      return l;
    }
    case kSzlOneComponentIdentification: {
      SzlList l = list(kComponentRecordLength);
      if (!component_record(l.records, info, index)) return failed(SzlStatus::UnknownIndex);
      l.record_count = 1;
      return l;
    }
    case kSzlCpuState: {
      SzlList l = list(kStateRecordLength);
      l.records.assign(kStateRecordLength, 0);
      l.records[kStateOctet] = info.state;
      l.record_count = 1;
      return l;
    }
    default:
      return std::nullopt;
  }
}

}  // namespace pbvbus::s7cpu
