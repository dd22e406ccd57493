#pragma once
// The PrmCmd block of PI 2.212 slave redundancy (protocol-facts.md §G.2): an 8-octet structured
// Set_Prm block (DPV1_Status_3 PrmCmd + Prm_Structure) by which a master commands a redundant
// slave interface (Primary_Request, Master_State_Clear, MSAC_C1 start/stop) and sets the
// Output_Hold_Time.
//
// assumption: modelled as PI 2.212 System Redundancy; the Siemens IM 153-2 wire protocol is
// not public (§G.6). The PI 2.212 text itself is not among our sources either; the layout is
// the AUMA table (S8) and the VPC3+ stack (S3). Decisions on the items §G marks [U]
// (docs/redundancy.md lists them all):
//
//  - Octet 4 (specifier): bits 1..0 Specifier, bit 2 reserved, bits 7..3 Seq_Nr (0..31), by
//    analogy with the DP-V1 alarm/status specifier. A master counts Seq_Nr up per command; the
//    slave echoes it in Prm_Cmd_Ack. Specifier values 0..3 are carried, not interpreted.
//  - Octet 5 (Function): bit 1 Primary_Request, bit 2 Stop_MSAC1S, bit 3 Start_MSAC1S, bit 4
//    Check_Properties, bit 6 Master_State_Clear; bits 0, 5, 7 reserved. Stop and Start of
//    MSAC1S in one command contradict each other and are rejected.
//  - Octet 6 (Properties): bit 0 Primary_Req_MS0_MS1_used, bit 1 Start_Stop_MSAC1S_used,
//    bit 2 Address_Change, bit 3 Address_Offset64; bits 4..7 reserved. (AUMA: Address_Change +
//    Address_Offset64 = flying redundancy, Address_Change alone = system redundancy.)
//  - Octets 7..8: Output_Hold_Time, big-endian, unit 10 ms (0..655.35 s). 0 = no hold: outputs
//    go to the fail-safe state at once when the primary changes without fresh outputs.
//  - Strict decoding: reserved bits set, a Structure_Length other than 8, a type other than
//    0x02, a slot other than 0 or a length other than 8 octets are errors (never exceptions).
//    The encoder cannot produce any of them (it rejects Seq_Nr > 31 and Specifier > 3).

#include <array>
#include <cstdint>
#include <span>
#include <string_view>

#include "pbvbus/bus/time.hpp"

namespace pbvbus::redundancy {

inline constexpr std::size_t kPrmCmdLen = 8;
inline constexpr std::uint8_t kPrmCmdStructureType = 0x02;

// Function (octet 5).
inline constexpr std::uint8_t kFnPrimaryRequest = 0x02;
inline constexpr std::uint8_t kFnStopMsac1s = 0x04;
inline constexpr std::uint8_t kFnStartMsac1s = 0x08;
inline constexpr std::uint8_t kFnCheckProperties = 0x10;
inline constexpr std::uint8_t kFnMasterStateClear = 0x40;
inline constexpr std::uint8_t kFnReserved = 0xA1;
// Properties (octet 6).
inline constexpr std::uint8_t kPropPrimaryReqMs0Ms1Used = 0x01;
inline constexpr std::uint8_t kPropStartStopMsac1sUsed = 0x02;
inline constexpr std::uint8_t kPropAddressChange = 0x04;
inline constexpr std::uint8_t kPropAddressOffset64 = 0x08;
inline constexpr std::uint8_t kPropReserved = 0xF0;
// Specifier (octet 4).
inline constexpr std::uint8_t kSpecReserved = 0x04;

struct PrmCmd {
  std::uint8_t seq_nr = 0;     ///< 0..31
  std::uint8_t specifier = 0;  ///< 0..3, carried as is
  bool primary_request = false;
  bool stop_msac1s = false;
  bool start_msac1s = false;
  bool check_properties = false;
  bool master_state_clear = false;
  bool primary_req_ms0_ms1_used = false;
  bool start_stop_msac1s_used = false;
  bool address_change = false;
  bool address_offset64 = false;
  std::uint16_t output_hold_time = 0;  ///< 10 ms units

  std::uint8_t function() const;
  std::uint8_t properties() const;
  std::uint8_t specifier_octet() const {
    return static_cast<std::uint8_t>(((seq_nr & 0x1F) << 3) | (specifier & 0x03));
  }
  bus::Ticks output_hold_ticks() const {
    return static_cast<bus::Ticks>(output_hold_time) * 10 * bus::kTicksPerMs;
  }
  bool operator==(const PrmCmd&) const = default;
};

enum class PrmCmdError : std::uint8_t {
  None,
  TooShort,            ///< fewer than 8 octets
  TooLong,             ///< more than 8 octets
  BadStructureLength,  ///< octet 1 is not 0x08
  BadStructureType,    ///< octet 2 is not 0x02
  BadSlot,             ///< octet 3 is not 0
  ReservedBits,        ///< a reserved bit of octet 4, 5 or 6 is set
  Msac1sConflict,      ///< Stop_MSAC1S and Start_MSAC1S together
  BadSeqNr,            ///< encode only: Seq_Nr > 31
  BadSpecifier,        ///< encode only: Specifier > 3
};
std::string_view to_string(PrmCmdError e);

/// Decodes exactly one 8-octet PrmCmd block (header included).
PrmCmdError decode_prm_cmd(std::span<const std::uint8_t> block, PrmCmd& out);
/// Encodes `cmd`; the octets are valid only when the result is None.
PrmCmdError encode_prm_cmd(const PrmCmd& cmd, std::array<std::uint8_t, kPrmCmdLen>& out);

}  // namespace pbvbus::redundancy
