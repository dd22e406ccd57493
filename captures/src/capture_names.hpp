#pragma once
// Names and predicates shared by the capture readers (inspect, timeline): which interfaces carry
// FDL telegrams and which event records, the DP service behind a SAP (protocol-facts.md §D.1;
// the same table as the Lua dissector), and the words for the epb_flags error bits the writer
// sets (pcapng_writer.hpp). Internal to the captures layer.

#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "pbvbus/captures/pcapng_format.hpp"

namespace pbvbus::captures::names {

inline bool is_line_link(std::uint16_t lt) {
  return lt == static_cast<std::uint16_t>(pcapng::LinkType::User0) ||
         lt == static_cast<std::uint16_t>(pcapng::LinkType::ProfibusDl);
}
inline bool is_events_link(std::uint16_t lt) {
  return lt == static_cast<std::uint16_t>(pcapng::LinkType::User1);
}

/// The DP service of a SAP; SAPs 0..48 are MSAC_C2 connections; "" for none.
std::string_view sap_service(std::uint8_t sap);

/// The link-layer error bits of an epb_flags value, in bit order, as words ("symbol error
/// (collision)", "packet too short (partial)", ...).
std::vector<std::string_view> flag_reasons(std::uint32_t flags);

/// A capture time in ns as seconds with nine decimals: "2.000985333 s", "-0.000000001 s".
std::string format_time_ns(std::int64_t ns);

}  // namespace pbvbus::captures::names
