// DP-V1 response decoding shared by the class-1 and class-2 masters (protocol-facts.md §E.2, §E.3).
#include "pbvbus/dp/master_acyclic.hpp"

#include <cstdio>

namespace pbvbus::dp {

std::string_view to_string(AcyclicStatus s) {
  switch (s) {
    case AcyclicStatus::Ok: return "ok";
    case AcyclicStatus::Negative: return "negative response";
    case AcyclicStatus::NoResponse: return "no response";
    case AcyclicStatus::NotAvailable: return "service not available";
    case AcyclicStatus::Timeout: return "timeout";
    case AcyclicStatus::InvalidResponse: return "invalid response";
    case AcyclicStatus::Rejected: return "rejected";
  }
  return "?";
}

namespace {
std::string_view error_code_name(std::uint8_t code_1) {
  const std::uint8_t cls = code_1 >> 4;
  const std::uint8_t code = code_1 & 0x0F;
  switch (cls) {
    case 0xA:
      switch (code) {
        case 0: return "read error";
        case 1: return "write error";
        case 2: return "module failure";
        case 8: return "version conflict";
        case 9: return "feature not supported";
        default: return code >= 0xA ? "user-specific" : "reserved";
      }
    case 0xB:
      switch (code) {
        case 0: return "invalid index";
        case 1: return "write length error";
        case 2: return "invalid slot";
        case 3: return "type conflict";
        case 4: return "invalid area";
        case 5: return "state conflict";
        case 6: return "access denied";
        case 7: return "invalid range";
        case 8: return "invalid parameter";
        case 9: return "invalid type";
        default: return "user-specific";
      }
    case 0xC:
      switch (code) {
        case 0: return "read constraint conflict";
        case 1: return "write constraint conflict";
        case 2: return "resource busy";
        case 3: return "resource unavailable";
        default: return code >= 8 ? "user-specific" : "reserved";
      }
    case 0xD:
    case 0xE:
    case 0xF: return "user-specific";
    default: return "reserved";
  }
}
std::string_view error_class_name(std::uint8_t code_1) {
  switch (code_1 >> 4) {
    case 0xA: return "application";
    case 0xB: return "access";
    case 0xC: return "resource";
    case 0xD:
    case 0xE:
    case 0xF: return "user";
    default: return "reserved";
  }
}
}  // namespace

std::string describe(const Dpv1Error& e) {
  char codes[32];
  std::snprintf(codes, sizeof codes, " (%02X), code 2 %02X", e.code_1, e.code_2);
  switch (e.decode) {
    case kErrorDecodeDpv1:
      return "DP-V1 " + std::string(error_class_name(e.code_1)) + ": " +
             std::string(error_code_name(e.code_1)) + codes;
    case 0xFE: return std::string("FMS error") + codes;
    case 0xFF: return std::string("HART error") + codes;
    default: {
      char dec[16];
      std::snprintf(dec, sizeof dec, "%02X", e.decode);
      return "unknown Error_Decode " + std::string(dec) + codes;
    }
  }
}

Dpv1Match match_record_response(std::span<const std::uint8_t> pdu, std::uint8_t fn,
                                std::uint8_t slot, std::uint8_t index, std::uint8_t length,
                                Dpv1Error& err) {
  if (pdu.size() == 4 && pdu[0] == (fn | kFnErrorBit)) {
    err = {pdu[1], pdu[2], pdu[3]};
    return Dpv1Match::Negative;
  }
  if (pdu.size() < 4 || pdu[0] != fn || pdu[1] != slot || pdu[2] != index)
    return Dpv1Match::Invalid;
  switch (fn) {
    case kFnRead:
      // The slave may return fewer octets than asked for, never more.
      if (pdu[3] > length || pdu.size() != 4u + pdu[3]) return Dpv1Match::Invalid;
      return Dpv1Match::Ok;
    case kFnWrite:
      if (pdu.size() != 4 || pdu[3] != length) return Dpv1Match::Invalid;
      return Dpv1Match::Ok;
    case kFnAlarmAck:
      // Echo of `5C Slot Alarm_Type Specifier`: index = type, length = specifier.
      if (pdu.size() != 4 || pdu[3] != length) return Dpv1Match::Invalid;
      return Dpv1Match::Ok;
    default: return Dpv1Match::Invalid;
  }
}

}  // namespace pbvbus::dp
