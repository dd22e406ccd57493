#pragma once
// Setup Communication (protocol-facts.md §H.4; tools-and-formats.md §3.4): parameters
//   F0 00 | max AmQ calling u16 | max AmQ called u16 | PDU length u16
// in a Job and, with the same layout, in the Ack-Data answer.
//
// Decisions (docs/s7.md "Setup Communication"): the reserved octet is not checked; the server
// answers each of the three values as the lower of the client's and its own (the sources say so
// for the PDU length; for the AmQ values snap7 echoes the client's, a CPU cannot promise more
// parallel jobs than it has, so the minimum is used for them too).
#include <cstdint>
#include <span>
#include <vector>

#include "pbvbus/s7/error.hpp"
#include "pbvbus/s7/s7_pdu.hpp"

namespace pbvbus::s7 {

inline constexpr std::size_t kSetupParamLength = 8;

struct SetupCommunication {
  std::uint16_t max_amq_calling = 1;
  std::uint16_t max_amq_called = 1;
  std::uint16_t pdu_length = 240;
  bool operator==(const SetupCommunication&) const = default;
};

/// From a decoded Job or Ack-Data PDU (S7WrongPduType for another type).
Decoded<SetupCommunication> decode_setup_communication(const S7Pdu& pdu);

Encoded encode_setup_communication_request(std::uint16_t pdu_ref, const SetupCommunication& s);
Encoded encode_setup_communication_response(std::uint16_t pdu_ref, const SetupCommunication& s);

/// What a server with limits `own` answers to `requested`: the lower value of each field.
SetupCommunication negotiate(const SetupCommunication& requested, const SetupCommunication& own);

}  // namespace pbvbus::s7
