#pragma once
// The capture hook of the ISO-on-TCP door (docs/iso-on-tcp.md "Capture hook"): every S7 PDU that
// passes the door, in or out, is offered to it, with what a capture writer needs to make an
// upper-PDU record (connection, TSAPs, direction, time). The hook is called on the door's thread
// at the moment the PDU passes, so an owner on the paced runner may read the virtual time itself.
#include <chrono>
#include <cstdint>
#include <functional>
#include <span>

namespace pbvbus::iso_on_tcp {

enum class PduDirection : std::uint8_t {
  FromClient,  ///< a Job or Userdata the client sent (after `02 F0 80`, segments joined)
  ToClient,    ///< the answer the door sends back
};

struct PduRecord {
  PduDirection direction = PduDirection::FromClient;
  std::uint64_t connection_id = 0;
  std::span<const std::uint8_t> calling_tsap;  ///< the CR's C1 (the client's)
  std::span<const std::uint8_t> called_tsap;   ///< the CR's C2 (the CPU's)
  std::chrono::system_clock::time_point wall{};
  std::span<const std::uint8_t> pdu;  ///< valid during the call only
};

/// Empty = no capture.
using PduCapture = std::function<void(const PduRecord&)>;

}  // namespace pbvbus::iso_on_tcp
