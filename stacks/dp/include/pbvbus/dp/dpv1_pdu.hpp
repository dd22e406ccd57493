#pragma once
// DP-V1 acyclic PDUs (IEC 61158-6 DP-V1; protocol-facts.md §E.1–§E.3, §E.6), shared by the slave
// engine and the masters: MSAC_C1 Read/Write/Alarm_Ack, MSAC_C2 Initiate/Read/Write/
// Data_Transport/Idle/Abort and the resource-manager answer, and the negative response
// `(Fn|0x80) Error_Decode Error_Code_1 Error_Code_2`.

#include <array>
#include <cstdint>
#include <span>

namespace pbvbus::dp {

// Function numbers (§E.1).
inline constexpr std::uint8_t kFnRead = 0x5E;
inline constexpr std::uint8_t kFnWrite = 0x5F;
inline constexpr std::uint8_t kFnAlarmAck = 0x5C;
inline constexpr std::uint8_t kFnInitiate = 0x57;
inline constexpr std::uint8_t kFnAbort = 0x58;
inline constexpr std::uint8_t kFnDataTransport = 0x51;
inline constexpr std::uint8_t kFnIdle = 0x48;
inline constexpr std::uint8_t kFnResourceManager = 0x56;
inline constexpr std::uint8_t kFnErrorBit = 0x80;

inline constexpr std::uint8_t kErrorDecodeDpv1 = 0x80;
inline constexpr std::size_t kMaxRecordData = 240;

/// Error_Code_1 values for Error_Decode 0x80 (class in the high nibble, §E.3).
namespace dpv1_err {
inline constexpr std::uint8_t kReadError = 0xA0;
inline constexpr std::uint8_t kWriteError = 0xA1;
inline constexpr std::uint8_t kModuleFailure = 0xA2;
inline constexpr std::uint8_t kVersionConflict = 0xA8;
inline constexpr std::uint8_t kFeatureNotSupported = 0xA9;
inline constexpr std::uint8_t kInvalidIndex = 0xB0;
inline constexpr std::uint8_t kWriteLengthError = 0xB1;
inline constexpr std::uint8_t kInvalidSlot = 0xB2;
inline constexpr std::uint8_t kTypeConflict = 0xB3;
inline constexpr std::uint8_t kInvalidArea = 0xB4;
inline constexpr std::uint8_t kStateConflict = 0xB5;
inline constexpr std::uint8_t kAccessDenied = 0xB6;
inline constexpr std::uint8_t kInvalidRange = 0xB7;
inline constexpr std::uint8_t kInvalidParameter = 0xB8;
inline constexpr std::uint8_t kInvalidType = 0xB9;
inline constexpr std::uint8_t kReadConstraint = 0xC0;
inline constexpr std::uint8_t kWriteConstraint = 0xC1;
inline constexpr std::uint8_t kResourceBusy = 0xC2;
inline constexpr std::uint8_t kResourceUnavailable = 0xC3;
}  // namespace dpv1_err

struct Dpv1Error {
  std::uint8_t decode = kErrorDecodeDpv1;
  std::uint8_t code_1 = 0;
  std::uint8_t code_2 = 0;
  bool operator==(const Dpv1Error&) const = default;
};

constexpr std::array<std::uint8_t, 4> negative_response(std::uint8_t fn, Dpv1Error e) {
  return {static_cast<std::uint8_t>(fn | kFnErrorBit), e.decode, e.code_1, e.code_2};
}

/// Read.req / Write.req / Data_Transport.req: `Fn Slot Index Length [Data]`.
struct RecordRequest {
  std::uint8_t fn = 0;
  std::uint8_t slot = 0;
  std::uint8_t index = 0;
  std::uint8_t length = 0;
  std::span<const std::uint8_t> data;  ///< Write/Data_Transport only
};
enum class RecordParse : std::uint8_t { Ok, TooShort, BadLength };
/// Checks the header; for Write/Data_Transport the Length must equal the data that follows,
/// for Read it must be 1..240 and nothing may follow.
RecordParse parse_record_request(std::span<const std::uint8_t> pdu, RecordRequest& out);

/// Alarm_Ack.req: `5C Slot Alarm_Type Specifier`.
struct AlarmAck {
  std::uint8_t slot = 0;
  std::uint8_t type = 0;
  std::uint8_t specifier = 0;
};
bool parse_alarm_ack(std::span<const std::uint8_t> pdu, AlarmAck& out);

// --- MSAC_C2 ---------------------------------------------------------------------------------
/// Initiate.req: `57 | 3 reserved | Send_Timeout u16 | Features_Supported_1..2 |
/// Profile_Features_Supported_1..2 | Profile_Ident_Number u16 | S_Type S_Len D_Type D_Len |
/// Addr_Data`.
struct InitiateRequest {
  std::uint16_t send_timeout = 0;  ///< 10 ms units
  std::uint8_t features_1 = 0;
  std::uint8_t features_2 = 0;
  std::uint8_t profile_features_1 = 0;
  std::uint8_t profile_features_2 = 0;
  std::uint16_t profile_ident = 0;
  std::uint8_t s_type = 0;
  std::uint8_t d_type = 0;
  std::span<const std::uint8_t> s_addr;
  std::span<const std::uint8_t> d_addr;
};
inline constexpr std::size_t kInitiateHeaderLen = 16;
bool parse_initiate(std::span<const std::uint8_t> pdu, InitiateRequest& out);

/// Abort instance (high nibble) and reasons (low nibble).
inline constexpr std::uint8_t kAbortSubnetNone = 0;
inline constexpr std::uint8_t kAbortSubnetLocal = 1;
inline constexpr std::uint8_t kAbortSubnetRemote = 2;
inline constexpr std::uint8_t kAbortInstanceFdl = 0x00;
inline constexpr std::uint8_t kAbortInstanceMsacC2 = 0x10;
inline constexpr std::uint8_t kAbortInstanceUser = 0x20;
inline constexpr std::uint8_t kAbortSequenceError = 1;
inline constexpr std::uint8_t kAbortInvalidRequest = 2;
inline constexpr std::uint8_t kAbortTimeout = 3;
inline constexpr std::uint8_t kAbortInvalidResponse = 4;
inline constexpr std::uint8_t kAbortInvalidService = 5;
inline constexpr std::uint8_t kAbortSendTimeoutTooSmall = 6;
inline constexpr std::uint8_t kAbortInvalidAddress = 7;
inline constexpr std::uint8_t kAbortResource = 0xF;

}  // namespace pbvbus::dp
