#include "capture_names.hpp"

#include <cstdio>
#include <utility>

namespace pbvbus::captures::names {

std::string_view sap_service(std::uint8_t sap) {
  switch (sap) {
    case 49: return "MSAC_C2 RM";
    case 50: return "Alarm_Ack";
    case 51: return "MSAC_C1";
    case 55: return "Set_Slave_Add";
    case 56: return "Rd_Inp";
    case 57: return "Rd_Outp";
    case 58: return "Global_Control";
    case 59: return "Get_Cfg";
    case 60: return "Slave_Diag";
    case 61: return "Set_Prm";
    case 62: return "Chk_Cfg";
    default: return sap <= 48 ? "MSAC_C2" : "";
  }
}

std::vector<std::string_view> flag_reasons(std::uint32_t flags) {
  // What each bit means for a bus capture is the writer's choice (pcapng_writer.hpp).
  static const std::pair<std::uint32_t, std::string_view> kNames[] = {
      {pcapng::kFlagSymbolError, "symbol error (collision)"},
      {pcapng::kFlagPreambleError, "preamble error"},
      {pcapng::kFlagStartDelimiterError, "start delimiter error"},
      {pcapng::kFlagUnalignedError, "unaligned frame"},
      {pcapng::kFlagWrongIfg, "wrong inter-frame gap"},
      {pcapng::kFlagTooShort, "packet too short (partial)"},
      {pcapng::kFlagTooLong, "packet too long"},
      {pcapng::kFlagCrcError, "CRC error"}};
  std::vector<std::string_view> out;
  for (const auto& [bit, name] : kNames)
    if (flags & bit) out.push_back(name);
  return out;
}

std::string format_time_ns(std::int64_t ns) {
  char buf[48];
  const char* sign = ns < 0 ? "-" : "";
  // -(ns + 1) + 1: INT64_MIN has no positive int64 counterpart.
  const std::uint64_t a =
      ns < 0 ? static_cast<std::uint64_t>(-(ns + 1)) + 1 : static_cast<std::uint64_t>(ns);
  std::snprintf(buf, sizeof buf, "%s%llu.%09llu s", sign,
                static_cast<unsigned long long>(a / 1'000'000'000),
                static_cast<unsigned long long>(a % 1'000'000'000));
  return buf;
}

}  // namespace pbvbus::captures::names
