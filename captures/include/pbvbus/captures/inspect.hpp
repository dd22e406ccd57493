#pragma once
// Summary of a capture for `pbvbus inspect CAPTURE` (design.md "Configuration and command
// line"): per interface the frames by FDL frame type, by request function and response status
// and by DP service, bad frames by reason, the time span and the shortest idle gap between
// frames in bit times; and the list of events. Text and JSON renderings.
//
// Decisions:
//  - Bad-frame reasons come from the frame's opt_comment as PcapngWriter writes it ("collision,
//    FCS mismatch" counts once under each reason; "partial: 4 of 11 octets" under "partial").
//    Frames without a comment (captures from other tools) get reasons from epb_flags' error
//    bits and from the FDL decoder.
//  - The idle gap is measured between consecutive frames of one interface in file order, from
//    the end of the earlier frame (start + 11 bits per octet at if_speed) to the start of the
//    next, rounded to whole bit times (timestamps are ns, rounded down; a bit is >= 83 ns).
//    Overlapping frames (collisions) are counted as overlaps, not as gaps.
//  - The DP service is the SAP's service (the request's DSAP, the response's SSAP) or
//    Data_Exchange for SRD/data on the default SAP, as in the Lua dissector. A frame that is
//    MPI (the dissector's rule, captures/README.md "MPI and S7") counts as its MPI PDU instead.
//  - Interfaces of other link types (S7 upper-PDU records, 252, among them) are counted
//    (records, octets, time span) and not decoded.
//  - Quantum Hot Standby pair events (category 7, hsby_event.hpp) are counted apart and their
//    switchovers listed with the takeover time the record carries (docs/quantum-hsby.md
//    "Captures and timeline"); the text report shows that part only when the capture has such
//    records, the JSON always ("hsby": {"records": 0, "switchovers": []}).

#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "pbvbus/captures/pcapng_reader.hpp"

namespace pbvbus::captures {

struct InterfaceSummary {
  std::string name;
  std::string description;
  std::uint16_t link_type = 0;
  std::uint64_t speed = 0;  ///< bit/s, 0 = unknown
  std::uint64_t frames = 0;
  std::uint64_t octets = 0;
  std::map<std::string, std::uint64_t> by_type;      ///< SD1, SD2, SD3, SD4, SC, garbage
  std::map<std::string, std::uint64_t> by_request;   ///< SRD_high, SDN_high, FDL_Status ...
  std::map<std::string, std::uint64_t> by_response;  ///< DL, OK, DH, RS ...
  std::map<std::string, std::uint64_t> by_service;   ///< Slave_Diag.req, Data_Exchange.res ...
  /// MPI PDUs ("Data", "Data ack", "Connect request", ...) of the frames that are MPI by the
  /// rule of captures/README.md "MPI and S7"; such frames count under no DP service.
  std::map<std::string, std::uint64_t> by_mpi;
  std::uint64_t bad_frames = 0;
  std::map<std::string, std::uint64_t> bad_by_reason;
  std::optional<std::int64_t> first_ns;
  std::optional<std::int64_t> last_ns;
  std::optional<std::int64_t> min_idle_bits;  ///< needs if_speed and two frames
  std::uint64_t overlaps = 0;
};

struct EventSummary {
  std::int64_t ts_ns = 0;
  std::uint32_t interface = 0;
  std::string category;
  std::uint16_t code = 0;
  std::int32_t line = -1;
  std::int32_t a = -1;
  std::int32_t b = -1;
  std::uint64_t value = 0;
  std::string text;
};

/// A switchover of a Quantum Hot Standby pair (an Hsby record of kind switchover).
struct HsbySwitchoverSummary {
  std::int64_t ts_ns = 0;
  int rack = -1;                  ///< the new primary (a)
  std::uint64_t takeover_ns = 0;  ///< 0 = none given
  std::string text;
};

struct CaptureSummary {
  std::uint64_t records = 0;
  std::optional<std::int64_t> first_ns;
  std::optional<std::int64_t> last_ns;
  std::vector<InterfaceSummary> interfaces;
  std::vector<EventSummary> events;
  std::uint64_t bad_event_records = 0;  ///< USER1 packets that are no valid event record
  std::uint64_t hsby_records = 0;       ///< events of category Hsby (7)
  std::vector<HsbySwitchoverSummary> hsby_switchovers;  ///< in file order
};

/// Reads everything `reader` still has. On a read error returns nullopt and sets `error`.
std::optional<CaptureSummary> summarize(PcapngReader& reader, PcapngError& error);
std::optional<CaptureSummary> inspect_file(const std::string& path, PcapngError& error);

/// Human-readable report.
std::string to_text(const CaptureSummary& s);
/// One JSON object (stable keys, times in ns).
std::string to_json(const CaptureSummary& s);

}  // namespace pbvbus::captures
