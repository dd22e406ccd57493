#pragma once
// Results of the masters' acyclic DP-V1 services (IEC 61158-6 DP-V1; protocol-facts.md §E.1–§E.5):
// MSAC_C1 Read/Write/Alarm_Ack of dp::Master and the MSAC_C2 services of dp::Class2Master, with
// negative responses `(Fn|0x80) Error_Decode Error_Code_1 Error_Code_2` decoded into text.

#include <cstdint>
#include <functional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "pbvbus/dp/dpv1_pdu.hpp"

namespace pbvbus::dp {

enum class AcyclicStatus : std::uint8_t {
  Ok,               ///< positive response
  Negative,         ///< the slave's negative response; see `error`
  NoResponse,       ///< no FDL reply after the retries (the station counts as failed)
  NotAvailable,     ///< RS/UE/RR: the service is not open (slave not in data exchange with
                    ///< DP-V1, connection closed, wrong master), or the slave left data exchange
  Timeout,          ///< the slave kept answering "not ready" past the response timeout
  InvalidResponse,  ///< a response that does not fit the request (function, slot, index, length)
  Rejected,         ///< the FDL station could not send it (encoding, ring left)
};
std::string_view to_string(AcyclicStatus s);

struct AcyclicResult {
  std::uint32_t id = 0;       ///< as returned when the request was queued
  std::uint8_t slave = 0;     ///< FDL address
  std::uint8_t fn = 0;        ///< function number of the request (kFnRead, kFnWrite, ...)
  std::uint8_t slot = 0;
  std::uint8_t index = 0;     ///< Alarm_Ack: the alarm type
  AcyclicStatus status = AcyclicStatus::Ok;
  Dpv1Error error;            ///< for Negative
  std::vector<std::uint8_t> data;  ///< Read: the record; other services: the response PDU
  bool ok() const { return status == AcyclicStatus::Ok; }
};
using AcyclicCallback = std::function<void(const AcyclicResult&)>;

/// "DP-V1 access: invalid index (B0), code 2 00" — names from protocol-facts.md §E.3.
std::string describe(const Dpv1Error& e);

/// Outcome of matching a DP-V1 response PDU against the request that caused it.
enum class Dpv1Match : std::uint8_t { Ok, Negative, Invalid };
/// Checks `pdu` as the response to `fn` (slot/index/length as requested). For a read, `length`
/// is the maximum, and the record data is the octets after the 4-octet header. Negative
/// responses must be exactly `fn|0x80 decode code_1 code_2`.
Dpv1Match match_record_response(std::span<const std::uint8_t> pdu, std::uint8_t fn,
                                std::uint8_t slot, std::uint8_t index, std::uint8_t length,
                                Dpv1Error& err);

}  // namespace pbvbus::dp
