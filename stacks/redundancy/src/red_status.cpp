// Prm_Cmd_Ack / Red_Status block codec (protocol-facts.md §G.3); decisions in red_status.hpp.
#include "pbvbus/redundancy/red_status.hpp"

#include "pbvbus/redundancy/prm_cmd.hpp"

namespace pbvbus::redundancy {

std::uint8_t RedState::octet() const {
  std::uint8_t b = 0;
  if (backup) b |= kRsBackup;
  if (primary) b |= kRsPrimary;
  if (hardware_defective) b |= kRsHardwareDefective;
  if (data_exchange) b |= kRsDataExchange;
  if (master_state_clear) b |= kRsMasterStateClear;
  if (baudrate_found) b |= kRsBaudrateFound;
  if (output_hold_started) b |= kRsOutputHoldStarted;
  return b;
}

RedState RedState::from_octet(std::uint8_t b) {
  RedState s;
  s.backup = (b & kRsBackup) != 0;
  s.primary = (b & kRsPrimary) != 0;
  s.hardware_defective = (b & kRsHardwareDefective) != 0;
  s.data_exchange = (b & kRsDataExchange) != 0;
  s.master_state_clear = (b & kRsMasterStateClear) != 0;
  s.baudrate_found = (b & kRsBaudrateFound) != 0;
  s.output_hold_started = (b & kRsOutputHoldStarted) != 0;
  return s;
}

std::string_view to_string(RedStatusError e) {
  switch (e) {
    case RedStatusError::None: return "ok";
    case RedStatusError::TooShort: return "status block shorter than 8 octets";
    case RedStatusError::TooLong: return "status block longer than 8 octets";
    case RedStatusError::BadHeader: return "header is not 0x08";
    case RedStatusError::BadType: return "status type is neither 0x9E nor 0x9F";
    case RedStatusError::BadSlot: return "slot is not 0";
    case RedStatusError::ReservedBits: return "reserved bits set";
    case RedStatusError::PrimaryAndBackup: return "Red_State both Primary and Backup";
    case RedStatusError::BadSeqNr: return "Seq_Nr above 31";
    case RedStatusError::BadSpecifier: return "Specifier above 3";
  }
  return "?";
}

RedStatusError decode_red_status(std::span<const std::uint8_t> b, RedStatusBlock& out) {
  if (b.size() < kRedStatusLen) return RedStatusError::TooShort;
  if (b.size() > kRedStatusLen) return RedStatusError::TooLong;
  if (b[0] != kRedStatusLen) return RedStatusError::BadHeader;
  if (b[1] != kStatusPrmCmdAck && b[1] != kStatusRedStatus) return RedStatusError::BadType;
  if (b[2] != 0) return RedStatusError::BadSlot;
  if ((b[3] & kSpecReserved) || (b[4] & kFnReserved) || (b[5] & kRsReserved) ||
      (b[6] & kRsReserved) || b[7] != 0)
    return RedStatusError::ReservedBits;
  const auto both = kRsPrimary | kRsBackup;
  if ((b[5] & both) == both || (b[6] & both) == both) return RedStatusError::PrimaryAndBackup;
  RedStatusBlock r;
  r.type = b[1];
  r.seq_nr = static_cast<std::uint8_t>(b[3] >> 3);
  r.specifier = static_cast<std::uint8_t>(b[3] & 0x03);
  r.function = b[4];
  r.own = RedState::from_octet(b[5]);
  r.partner = RedState::from_octet(b[6]);
  r.red_state_3 = 0;
  out = r;
  return RedStatusError::None;
}

RedStatusError encode_red_status(const RedStatusBlock& r,
                                 std::array<std::uint8_t, kRedStatusLen>& out) {
  if (r.type != kStatusPrmCmdAck && r.type != kStatusRedStatus) return RedStatusError::BadType;
  if (r.seq_nr > 31) return RedStatusError::BadSeqNr;
  if (r.specifier > 3) return RedStatusError::BadSpecifier;
  if ((r.function & kFnReserved) || r.red_state_3 != 0) return RedStatusError::ReservedBits;
  if ((r.own.primary && r.own.backup) || (r.partner.primary && r.partner.backup))
    return RedStatusError::PrimaryAndBackup;
  const auto d = r.data();
  out = {static_cast<std::uint8_t>(kRedStatusLen), r.type, 0x00, r.specifier_octet(),
         d[0], d[1], d[2], d[3]};
  return RedStatusError::None;
}

}  // namespace pbvbus::redundancy
