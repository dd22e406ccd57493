// Diagnosis text (protocol-facts.md §D.4, §D.5, §E.5).
#include "pbvbus/dp/master_report.hpp"

#include <cstdio>
#include <vector>

#include "pbvbus/dp/diagnosis.hpp"
#include "pbvbus/dp/sap.hpp"

namespace pbvbus::dp {

std::string_view alarm_type_name(std::uint8_t type) {
  switch (type) {
    case 1: return "Diagnostic";
    case 2: return "Process";
    case 3: return "Pull";
    case 4: return "Plug";
    case 5: return "Status";
    case 6: return "Update";
    default: return type >= 32 && type <= 126 ? "manufacturer-specific" : "reserved";
  }
}

namespace {
std::string hex_octets(std::span<const std::uint8_t> b) {
  std::string s;
  char buf[4];
  for (std::size_t i = 0; i < b.size(); ++i) {
    std::snprintf(buf, sizeof buf, "%s%02X", i ? " " : "", b[i]);
    s += buf;
  }
  return s;
}
void append_bits(std::string& s, std::uint8_t v, const char* const names[8]) {
  for (int bit = 0; bit < 8; ++bit) {
    if ((v & (1u << bit)) == 0 || names[bit] == nullptr) continue;
    if (!s.empty()) s += ' ';
    s += names[bit];
  }
}
std::string_view channel_error_name(std::uint8_t e) {
  static constexpr std::string_view kNames[] = {
      "reserved",         "short circuit", "undervoltage", "overvoltage", "overload",
      "overtemperature",  "line break",    "upper limit exceeded", "lower limit undershot",
      "error"};
  if (e < 10) return kNames[e];
  return e >= 16 ? "manufacturer-specific error" : "reserved";
}
std::string_view channel_type_name(std::uint8_t t) {
  static constexpr std::string_view kNames[] = {"", "bit", "2 bits", "4 bits", "byte",
                                                "word", "2 words", "reserved"};
  return kNames[t & 7];
}
std::string_view direction_name(std::uint8_t d) {
  switch (d & 3) {
    case 1: return "input";
    case 2: return "output";
    case 3: return "input/output";
    default: return "no direction";
  }
}
std::string_view status_type_name(std::uint8_t t) {
  switch (t) {
    case kStatusMessage: return "Status_Message";
    case kModuleStatus: return "Module_Status";
    case kDxbLinkStatus: return "DXB_Link_Status";
    case kPrmCmdAck: return "Prm_Cmd_Ack";
    case kRedState: return "Red_State";
    default: return t >= 0xA0 ? "manufacturer-specific status" : "reserved status";
  }
}
std::string_view specifier_name(std::uint8_t spec) {
  switch (spec & 3) {
    case 1: return "appears";
    case 2: return "disappears";
    case 3: return "disappears, slot still disturbed";
    default: return "no specifier";
  }
}
}  // namespace

std::string describe_diag(std::span<const std::uint8_t> du, bool dpv1) {
  static const char* const kS1[8] = {"Station_Non_Existent", "Station_Not_Ready", "Cfg_Fault",
                                     "Ext_Diag",             "Not_Supported",
                                     "Invalid_Slave_Response", "Prm_Fault", "Master_Lock"};
  static const char* const kS2[8] = {"Prm_Req", "Stat_Diag", nullptr, "WD_On", "Freeze_Mode",
                                     "Sync_Mode", nullptr, "Deactivated"};
  static const char* const kS3[8] = {nullptr, nullptr, nullptr, nullptr,
                                     nullptr, nullptr, nullptr, "Ext_Diag_Overflow"};
  StandardDiag d;
  if (!StandardDiag::decode(du, d)) return "malformed diagnosis (" + hex_octets(du) + ")";
  std::string bits;
  append_bits(bits, d.status_1, kS1);
  append_bits(bits, d.status_2, kS2);
  append_bits(bits, d.status_3, kS3);
  if ((d.status_2 & kDiagAlways1) == 0) bits += bits.empty() ? "always-1 bit missing" : " always-1 bit missing";
  std::string s = bits.empty() ? std::string("ok") : bits;
  char buf[64];
  if (d.master_add == kNoMaster)
    s += " | Master_Add none";
  else {
    std::snprintf(buf, sizeof buf, " | Master_Add %u", static_cast<unsigned>(d.master_add));
    s += buf;
  }
  std::snprintf(buf, sizeof buf, " | Ident 0x%04X", static_cast<unsigned>(d.ident));
  s += buf;

  std::vector<ExtDiagBlock> blocks;
  if (!split_ext_diag(du.subspan(kStdDiagLen), blocks))
    return s + " | malformed extended diagnosis (" + hex_octets(du.subspan(kStdDiagLen)) + ")";
  for (const auto& b : blocks) {
    if (b.kind == kBlockIdentifier) {
      std::string mods;
      for (std::size_t i = 1; i < b.bytes.size(); ++i)
        for (int bit = 0; bit < 8; ++bit)
          if (b.bytes[i] & (1u << bit)) mods += (mods.empty() ? "" : " ") + std::to_string((i - 1) * 8 + bit);
      s += " | modules faulty: " + (mods.empty() ? std::string("none") : mods);
    } else if (b.kind == kBlockChannel) {
      std::snprintf(buf, sizeof buf, " | channel: module %u channel %u ", b.bytes[0] & 0x3Fu,
                    b.bytes[1] & 0x3Fu);
      s += buf;
      s += direction_name(static_cast<std::uint8_t>(b.bytes[1] >> 6));
      const auto type = channel_type_name(static_cast<std::uint8_t>(b.bytes[2] >> 5));
      if (!type.empty()) s += " " + std::string(type);
      s += " " + std::string(channel_error_name(b.bytes[2] & 0x1F));
    } else if (dpv1 && b.bytes.size() >= 4) {
      const std::uint8_t type = b.bytes[1];
      std::snprintf(buf, sizeof buf, " slot %u", static_cast<unsigned>(b.bytes[2]));
      if (type & 0x80) {
        s += " | status " + std::string(status_type_name(type)) + buf + " " +
             std::string(specifier_name(b.bytes[3]));
      } else {
        s += " | alarm " + std::string(alarm_type_name(type)) + buf;
        std::snprintf(buf, sizeof buf, " seq %u%s ", static_cast<unsigned>(alarm_seq_nr(b.bytes[3])),
                      (b.bytes[3] & 0x04) ? " add-ack" : "");
        s += buf;
        s += specifier_name(b.bytes[3]);
      }
      if (b.bytes.size() > 4) s += ": " + hex_octets(b.bytes.subspan(4));
    } else {
      s += " | device: " + hex_octets(b.bytes.subspan(1));
    }
  }
  return s;
}

}  // namespace pbvbus::dp
