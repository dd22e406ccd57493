#pragma once
// The MPI connection rows of a timeline lane (timeline.hpp "MPI connections"; the detection
// rule is the Lua dissector's, captures/README.md "MPI and S7"). Internal to the captures layer.

#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "pbvbus/captures/timeline.hpp"
#include "pbvbus/mpi/pdu.hpp"
#include "saturate.hpp"

namespace pbvbus::captures {

/// Whether an interface description marks an MPI line (PcapngWriter::mark_mpi()).
bool is_mpi_description(std::string_view description);

/// An MPI PDU found in one frame by the detection rule.
struct MpiFrame {
  std::uint8_t sa = 0, ssap = 0, da = 0, dsap = 0;
  mpi::Pdu pdu;  ///< pdu.data points into the frame's octets
};
/// The MPI PDU of a frame's octets, if the frame is MPI (`marked`: the interface is marked MPI).
std::optional<MpiFrame> mpi_frame(std::span<const std::uint8_t> bytes, bool marked);

/// "Connect request", "Connect confirm", "Connection ack", "Data", "Data ack",
/// "Disconnect request" (the Lua dissector's pbmpi.pdu_name).
std::string_view mpi_pdu_name(mpi::PduType t);

/// "connect request", "data 0", "data ack 7", ... (the timeline's marks).
std::string mpi_pdu_words(const mpi::Pdu& p);

/// A few words on an S7 PDU for a mark: "S7 job Read Var, 1 item", "S7 ack-data Read Var,
/// 1 item", "S7 ack-data error 0x81/0x04"; "" when it does not start like an S7 PDU (0x32).
std::string s7_summary(std::span<const std::uint8_t> s7);

/// The connections of a lane whose `frames` are sorted by start, cut to the window [from, to).
std::vector<MpiConnection> mpi_connections(const std::vector<TimelineFrame>& frames, bool marked,
                                           std::int64_t lane_end, std::int64_t from, i128 to);

}  // namespace pbvbus::captures
