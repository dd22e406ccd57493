// PrmCmd block codec (protocol-facts.md §G.2); decisions in prm_cmd.hpp.
#include "pbvbus/redundancy/prm_cmd.hpp"

namespace pbvbus::redundancy {

std::uint8_t PrmCmd::function() const {
  std::uint8_t f = 0;
  if (primary_request) f |= kFnPrimaryRequest;
  if (stop_msac1s) f |= kFnStopMsac1s;
  if (start_msac1s) f |= kFnStartMsac1s;
  if (check_properties) f |= kFnCheckProperties;
  if (master_state_clear) f |= kFnMasterStateClear;
  return f;
}

std::uint8_t PrmCmd::properties() const {
  std::uint8_t p = 0;
  if (primary_req_ms0_ms1_used) p |= kPropPrimaryReqMs0Ms1Used;
  if (start_stop_msac1s_used) p |= kPropStartStopMsac1sUsed;
  if (address_change) p |= kPropAddressChange;
  if (address_offset64) p |= kPropAddressOffset64;
  return p;
}

std::string_view to_string(PrmCmdError e) {
  switch (e) {
    case PrmCmdError::None: return "ok";
    case PrmCmdError::TooShort: return "PrmCmd block shorter than 8 octets";
    case PrmCmdError::TooLong: return "PrmCmd block longer than 8 octets";
    case PrmCmdError::BadStructureLength: return "Structure_Length is not 8";
    case PrmCmdError::BadStructureType: return "Structure_Type is not 0x02 (PrmCmd)";
    case PrmCmdError::BadSlot: return "Slot_Number is not 0";
    case PrmCmdError::ReservedBits: return "reserved bits set";
    case PrmCmdError::Msac1sConflict: return "Stop_MSAC1S and Start_MSAC1S together";
    case PrmCmdError::BadSeqNr: return "Seq_Nr above 31";
    case PrmCmdError::BadSpecifier: return "Specifier above 3";
  }
  return "?";
}

PrmCmdError decode_prm_cmd(std::span<const std::uint8_t> b, PrmCmd& out) {
  if (b.size() < kPrmCmdLen) return PrmCmdError::TooShort;
  if (b.size() > kPrmCmdLen) return PrmCmdError::TooLong;
  if (b[0] != kPrmCmdLen) return PrmCmdError::BadStructureLength;
  if (b[1] != kPrmCmdStructureType) return PrmCmdError::BadStructureType;
  if (b[2] != 0) return PrmCmdError::BadSlot;
  if ((b[3] & kSpecReserved) || (b[4] & kFnReserved) || (b[5] & kPropReserved))
    return PrmCmdError::ReservedBits;
  if ((b[4] & kFnStopMsac1s) && (b[4] & kFnStartMsac1s)) return PrmCmdError::Msac1sConflict;
  PrmCmd c;
  c.seq_nr = static_cast<std::uint8_t>(b[3] >> 3);
  c.specifier = static_cast<std::uint8_t>(b[3] & 0x03);
  c.primary_request = (b[4] & kFnPrimaryRequest) != 0;
  c.stop_msac1s = (b[4] & kFnStopMsac1s) != 0;
  c.start_msac1s = (b[4] & kFnStartMsac1s) != 0;
  c.check_properties = (b[4] & kFnCheckProperties) != 0;
  c.master_state_clear = (b[4] & kFnMasterStateClear) != 0;
  c.primary_req_ms0_ms1_used = (b[5] & kPropPrimaryReqMs0Ms1Used) != 0;
  c.start_stop_msac1s_used = (b[5] & kPropStartStopMsac1sUsed) != 0;
  c.address_change = (b[5] & kPropAddressChange) != 0;
  c.address_offset64 = (b[5] & kPropAddressOffset64) != 0;
  c.output_hold_time = static_cast<std::uint16_t>((b[6] << 8) | b[7]);
  out = c;
  return PrmCmdError::None;
}

PrmCmdError encode_prm_cmd(const PrmCmd& c, std::array<std::uint8_t, kPrmCmdLen>& out) {
  if (c.seq_nr > 31) return PrmCmdError::BadSeqNr;
  if (c.specifier > 3) return PrmCmdError::BadSpecifier;
  if (c.stop_msac1s && c.start_msac1s) return PrmCmdError::Msac1sConflict;
  out = {static_cast<std::uint8_t>(kPrmCmdLen), kPrmCmdStructureType, 0x00, c.specifier_octet(),
         c.function(), c.properties(), static_cast<std::uint8_t>(c.output_hold_time >> 8),
         static_cast<std::uint8_t>(c.output_hold_time & 0xFF)};
  return PrmCmdError::None;
}

}  // namespace pbvbus::redundancy
