// DP-V1 PDUs (protocol-facts.md §E.2, §E.6).
#include "pbvbus/dp/dpv1_pdu.hpp"

namespace pbvbus::dp {

RecordParse parse_record_request(std::span<const std::uint8_t> pdu, RecordRequest& out) {
  if (pdu.size() < 4) return RecordParse::TooShort;
  out.fn = pdu[0];
  out.slot = pdu[1];
  out.index = pdu[2];
  out.length = pdu[3];
  out.data = pdu.subspan(4);
  if (out.fn == kFnRead) {
    if (out.length == 0 || out.length > kMaxRecordData || !out.data.empty())
      return RecordParse::BadLength;
  } else if (out.data.size() != out.length || out.length > kMaxRecordData) {
    return RecordParse::BadLength;
  }
  return RecordParse::Ok;
}

bool parse_alarm_ack(std::span<const std::uint8_t> pdu, AlarmAck& out) {
  if (pdu.size() != 4 || pdu[0] != kFnAlarmAck) return false;
  out.slot = pdu[1];
  out.type = pdu[2];
  out.specifier = pdu[3];
  return true;
}

bool parse_initiate(std::span<const std::uint8_t> pdu, InitiateRequest& out) {
  if (pdu.size() < kInitiateHeaderLen || pdu[0] != kFnInitiate) return false;
  out.send_timeout = static_cast<std::uint16_t>((pdu[4] << 8) | pdu[5]);
  out.features_1 = pdu[6];
  out.features_2 = pdu[7];
  out.profile_features_1 = pdu[8];
  out.profile_features_2 = pdu[9];
  out.profile_ident = static_cast<std::uint16_t>((pdu[10] << 8) | pdu[11]);
  out.s_type = pdu[12];
  const std::size_t s_len = pdu[13];
  out.d_type = pdu[14];
  const std::size_t d_len = pdu[15];
  if (pdu.size() != kInitiateHeaderLen + s_len + d_len) return false;
  out.s_addr = pdu.subspan(kInitiateHeaderLen, s_len);
  out.d_addr = pdu.subspan(kInitiateHeaderLen + s_len, d_len);
  return true;
}

}  // namespace pbvbus::dp
