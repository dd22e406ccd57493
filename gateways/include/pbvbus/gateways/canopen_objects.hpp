#pragma once
// CiA 301 names and the object dictionary of one gateway node (docs/gateway-canopen.md; tools-and-formats.md
// §2.6; docs/gateway-canopen.md). A node is one DP slave of the master system; its dictionary is
// computed from what the ProcessSource says at the moment of the SDO request, so it never holds
// a copy that could go stale.
//
// Decisions (also in docs/gateway-canopen.md):
// - The dictionary is the smallest CiA 301 one a tool expects (0x1000, 0x1001, 0x1017, 0x1018)
//   plus two manufacturer objects: 0x2000 the DP status block (the same state codes and flag
//   bits as the Modbus status block, so both gateways say the same thing) and 0x2001 the raw
//   Slave_Diag, one octet per sub-index.
// - Only 0x1017 (producer heartbeat time) is writable. Everything else of CiA 301 that is not
//   here (PDO communication/mapping 0x1400..0x1BFF, 0x1016 consumer heartbeat) does not exist:
//   the PDO layout is fixed by the DP slave's telegram, so there is nothing to configure.
// - Checks of a download run in the order of CiA 301's abort codes a client can act on: object
//   exists (0x06020000), sub-index exists (0x06090011), writable (0x06010002), length
//   (0x06070010).
// - The error register (0x1001) has bit 0 (generic) set whenever any other bit is, as CiA 301
//   requires; bit 4 (communication) while a station failure is active, bit 7 (manufacturer)
//   while the slave reports Ext_Diag.
// - 0x1018 sub 1..4 are UNSIGNED32 as CiA 301 declares them (product code = Ident_Number,
//   serial number = PROFIBUS address): a tool that reads the identity by its declared type
//   rejects a shorter answer. The 16-bit ident is also at 0x2000 sub 4.

#include <cstdint>
#include <optional>
#include <string_view>

#include "pbvbus/dp/master.hpp"
#include "pbvbus/gateways/process_source.hpp"

namespace pbvbus::gateways::canopen {

// Function codes of the predefined connection set (COB-ID = function code + node id).
inline constexpr std::uint32_t kCobNmt = 0x000;
inline constexpr std::uint32_t kCobEmcy = 0x080;
inline constexpr std::uint32_t kCobTpdo[4] = {0x180, 0x280, 0x380, 0x480};
inline constexpr std::uint32_t kCobRpdo[4] = {0x200, 0x300, 0x400, 0x500};
inline constexpr std::uint32_t kCobSdoTx = 0x580;  ///< server → client (our responses)
inline constexpr std::uint32_t kCobSdoRx = 0x600;  ///< client → server (requests)
inline constexpr std::uint32_t kCobHeartbeat = 0x700;

inline constexpr std::uint8_t kMinNode = 1;
inline constexpr std::uint8_t kMaxNode = 127;
inline constexpr std::size_t kPdoCount = 4;
inline constexpr std::size_t kPdoOctets = 8;
/// Process data octets a node can carry with the default COB-IDs: 4 PDOs × 8 octets.
inline constexpr std::size_t kMappedOctets = kPdoCount * kPdoOctets;

// NMT command specifiers.
inline constexpr std::uint8_t kNmtStart = 0x01;
inline constexpr std::uint8_t kNmtStop = 0x02;
inline constexpr std::uint8_t kNmtPreOperational = 0x80;
inline constexpr std::uint8_t kNmtResetNode = 0x81;
inline constexpr std::uint8_t kNmtResetCommunication = 0x82;

// Heartbeat / boot-up states.
inline constexpr std::uint8_t kStateBootUp = 0x00;
inline constexpr std::uint8_t kStateStopped = 0x04;
inline constexpr std::uint8_t kStateOperational = 0x05;
inline constexpr std::uint8_t kStatePreOperational = 0x7F;

// EMCY error codes.
inline constexpr std::uint16_t kEmcyErrorReset = 0x0000;
inline constexpr std::uint16_t kEmcyHeartbeatError = 0x8130;  ///< life guard / heartbeat error
inline constexpr std::uint16_t kEmcyDeviceSpecific = 0xFF00;

// Error register (0x1001) bits.
inline constexpr std::uint8_t kErrGeneric = 0x01;
inline constexpr std::uint8_t kErrCommunication = 0x10;
inline constexpr std::uint8_t kErrManufacturer = 0x80;

// SDO abort codes (CiA 301 table 22), the ones this server uses.
inline constexpr std::uint32_t kAbortCommandSpecifier = 0x05040001;
inline constexpr std::uint32_t kAbortReadOnly = 0x06010002;
inline constexpr std::uint32_t kAbortNoObject = 0x06020000;
inline constexpr std::uint32_t kAbortLength = 0x06070010;
inline constexpr std::uint32_t kAbortNoSubIndex = 0x06090011;

// Object indices.
inline constexpr std::uint16_t kObjDeviceType = 0x1000;
inline constexpr std::uint16_t kObjErrorRegister = 0x1001;
inline constexpr std::uint16_t kObjProducerHeartbeat = 0x1017;
inline constexpr std::uint16_t kObjIdentity = 0x1018;
inline constexpr std::uint16_t kObjDpStatus = 0x2000;
inline constexpr std::uint16_t kObjDpDiagnosis = 0x2001;
/// Highest sub-index of 0x2000 (sub 0 holds this number).
inline constexpr std::uint8_t kDpStatusSubs = 7;

// 0x2000 sub 2 flag bits (the Modbus status block's flags register, low octet).
inline constexpr std::uint8_t kFlagDataValid = 0x01;
inline constexpr std::uint8_t kFlagExtDiag = 0x02;
inline constexpr std::uint8_t kFlagStationFailure = 0x04;
inline constexpr std::uint8_t kFlagPrmFault = 0x08;
inline constexpr std::uint8_t kFlagCfgFault = 0x10;
inline constexpr std::uint8_t kFlagSwitched = 0x20;
inline constexpr std::uint8_t kFlagRedundancyLost = 0x40;
inline constexpr std::uint8_t kFlagChannelB = 0x80;

/// DP state code of the status block: 1 Inactive, 2 Diag, 3 Prm, 4 Cfg, 5 CheckDiag,
/// 6 DataExchange, 7 NotPresent, 8 Locked.
std::uint8_t dp_state_code(dp::SlaveStatusState s);
/// The 0x2000 sub 2 flags of a slave (see the kFlag* bits). Station failure = NotPresent or
/// Slave_Diag Station_Non_Existent; prm/cfg fault and Ext_Diag from Slave_Diag octet 1.
std::uint8_t dp_status_flags(const SourceSlave& slave, const SlaveStatus& st);
/// True when Slave_Diag octet 1 (Station_Status_1) has Ext_Diag set.
bool has_ext_diag(const SlaveStatus& st);

/// The heartbeat state a node reports now, nullopt for no heartbeat:
/// NotPresent/Locked → none (a consumer detects the loss); master Stop → 0x04; Inactive with
/// the master not in Stop (slave deactivated, master offline) → none; DataExchange with master
/// Operate → 0x05; DataExchange with master Clear, or Diag/Prm/Cfg/CheckDiag → 0x7F.
std::optional<std::uint8_t> heartbeat_state(dp::SlaveStatusState s, dp::MasterMode mode);

/// Everything the dictionary of one node is computed from.
struct NodeObjects {
  const SourceSlave* slave = nullptr;
  SlaveStatus status;
  std::uint8_t error_register = 0;
  std::uint16_t heartbeat_ms = 0;
};

/// An object's value as an SDO transfers it: `size` octets (1, 2 or 4) of `value`, little
/// endian; or an abort code.
struct ObjectAccess {
  std::uint32_t abort = 0;  ///< 0: success
  std::uint32_t value = 0;
  std::uint8_t size = 0;
};

/// Upload (read) of index/sub.
ObjectAccess read_object(const NodeObjects& node, std::uint16_t index, std::uint8_t sub);
/// Checks a download (write) of `size` octets (0 = size not indicated) to index/sub; on success
/// (abort == 0) `value` is the new value truncated to the object's size. Only 0x1017 sub 0 is
/// writable; the caller applies it.
ObjectAccess check_write(const NodeObjects& node, std::uint16_t index, std::uint8_t sub,
                         std::uint8_t size, std::uint32_t value);

/// "object does not exist" etc., for reports and test messages.
std::string_view abort_text(std::uint32_t code);

}  // namespace pbvbus::gateways::canopen
