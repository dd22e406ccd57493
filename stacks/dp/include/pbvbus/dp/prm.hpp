#pragma once
// Set_Prm request layout (IEC 61158-6 DP; protocol-facts.md §D.2), shared by the slave engine
// (parse) and the master (encode): Station_Status, watchdog factors, min TSDR, Ident_Number,
// Group_Ident, then User_Prm_Data whose first three octets are DPV1_Status_1..3 for a DP-V1
// slave.
//
// Naming: "user prm data" in this code is everything after octet 7, i.e. what GSD calls
// User_Prm_Data (it includes DPV1_Status_1..3 when the slave is DP-V1).

#include <cstdint>
#include <span>
#include <vector>

#include "pbvbus/bus/time.hpp"

namespace pbvbus::dp {

// Station_Status (Set_Prm octet 1).
inline constexpr std::uint8_t kPrmLockReq = 0x80;
inline constexpr std::uint8_t kPrmUnlockReq = 0x40;
inline constexpr std::uint8_t kPrmSyncReq = 0x20;
inline constexpr std::uint8_t kPrmFreezeReq = 0x10;
inline constexpr std::uint8_t kPrmWdOn = 0x08;

// DPV1_Status_1 (octet 8).
inline constexpr std::uint8_t kDpv1Enable = 0x80;
inline constexpr std::uint8_t kDpv1FailSafe = 0x40;
inline constexpr std::uint8_t kDpv1PublisherEnable = 0x20;
inline constexpr std::uint8_t kDpv1WdBase1ms = 0x04;
// DPV1_Status_2 (octet 9): alarm enables and Check_Cfg_Mode.
inline constexpr std::uint8_t kEnablePullPlugAlarm = 0x80;
inline constexpr std::uint8_t kEnableProcessAlarm = 0x40;
inline constexpr std::uint8_t kEnableDiagnosticAlarm = 0x20;
inline constexpr std::uint8_t kEnableManufacturerAlarm = 0x10;
inline constexpr std::uint8_t kEnableStatusAlarm = 0x08;
inline constexpr std::uint8_t kEnableUpdateAlarm = 0x04;
inline constexpr std::uint8_t kAlarmEnableMask = 0xFC;
inline constexpr std::uint8_t kCheckCfgMode = 0x01;
// DPV1_Status_3 (octet 10).
inline constexpr std::uint8_t kPrmCmd = 0x80;
inline constexpr std::uint8_t kIsoMReq = 0x10;
inline constexpr std::uint8_t kPrmStructure = 0x08;
inline constexpr std::uint8_t kAlarmModeMask = 0x07;

inline constexpr std::size_t kPrmLenNorm = 7;   ///< DP-V0 header
inline constexpr std::size_t kPrmLenDpv1 = 10;  ///< header + DPV1_Status_1..3
inline constexpr std::size_t kMaxUserPrmLen = 237;
/// A "pure PrmCmd" Set_Prm (§G.2, VPC3 PRM_CMD_LENGTH, value decided here): the DP-V1 header
/// and one 8-octet PrmCmd block, 7 + 3 + 8 octets.
inline constexpr std::size_t kPrmLenPureCmd = 18;
inline constexpr std::size_t kPrmCmdBlockLen = 8;

/// Alarms in total that Alarm_Mode 0..7 allows outstanding (0 = one of each type).
constexpr unsigned alarm_mode_limit(std::uint8_t alarm_mode) {
  constexpr unsigned kLimits[8] = {1, 2, 4, 8, 12, 16, 24, 32};
  return kLimits[alarm_mode & 7];
}

/// The fixed part of Set_Prm.
struct PrmHeader {
  std::uint8_t station_status = 0;
  std::uint8_t wd_fact_1 = 1;
  std::uint8_t wd_fact_2 = 1;
  std::uint8_t min_tsdr = 0;  ///< bit times; 0 = leave unchanged
  std::uint16_t ident = 0;
  std::uint8_t group_ident = 0;

  bool lock_req() const { return (station_status & kPrmLockReq) != 0; }
  bool unlock_req() const { return (station_status & kPrmUnlockReq) != 0; }
  bool sync_req() const { return (station_status & kPrmSyncReq) != 0; }
  bool freeze_req() const { return (station_status & kPrmFreezeReq) != 0; }
  bool wd_on() const { return (station_status & kPrmWdOn) != 0; }
};

/// DPV1_Status_1..3 (all zero for a DP-V0 master).
struct Dpv1Status {
  std::uint8_t s1 = 0;
  std::uint8_t s2 = 0;
  std::uint8_t s3 = 0;
  bool dpv1_enable() const { return (s1 & kDpv1Enable) != 0; }
  bool fail_safe() const { return (s1 & kDpv1FailSafe) != 0; }
  bool wd_base_1ms() const { return (s1 & kDpv1WdBase1ms) != 0; }
  std::uint8_t alarm_enables() const { return s2 & kAlarmEnableMask; }
  bool check_cfg_mode() const { return (s2 & kCheckCfgMode) != 0; }
  bool prm_cmd() const { return (s3 & kPrmCmd) != 0; }
  bool prm_structure() const { return (s3 & kPrmStructure) != 0; }
  bool isom_req() const { return (s3 & kIsoMReq) != 0; }
  std::uint8_t alarm_mode() const { return s3 & kAlarmModeMask; }
};

/// A Set_Prm DU split into its parts. `user_prm` points into the parsed buffer.
struct PrmView {
  PrmHeader header;
  std::span<const std::uint8_t> user_prm;  ///< octets 8.. (incl. DPV1_Status for DP-V1)
  /// DPV1_Status_1..3 if user_prm has at least three octets, else zeros.
  Dpv1Status dpv1() const {
    if (user_prm.size() < 3) return {};
    return {user_prm[0], user_prm[1], user_prm[2]};
  }
};

/// Splits a Set_Prm DU; false if it is shorter than the 7-octet header.
bool parse_prm(std::span<const std::uint8_t> du, PrmView& out);

// Structured parameter blocks (Prm_Structure = 1), after DPV1_Status_3: each block is
// `Structure_Length (incl. these 4 octets), Structure_Type, Slot_Number, Specifier, data...`.
inline constexpr std::uint8_t kPrmBlockPrmCmd = 0x02;  ///< redundancy command (§G.2)
inline constexpr std::uint8_t kPrmBlockDxbLink = 0x03;
inline constexpr std::uint8_t kPrmBlockIsoM = 0x04;
inline constexpr std::uint8_t kPrmBlockDxbSubscriber = 0x07;
inline constexpr std::uint8_t kPrmBlockTimeAr = 0x08;
inline constexpr std::uint8_t kPrmBlockUser = 0x81;

struct PrmBlock {
  std::uint8_t type = 0;
  std::uint8_t slot = 0;
  std::uint8_t specifier = 0;
  std::span<const std::uint8_t> bytes;  ///< the whole block, header included
  std::span<const std::uint8_t> data() const { return bytes.subspan(4); }
};
/// Splits the octets after DPV1_Status_3 into blocks; false if a length is below 4 or runs past
/// the end.
bool split_prm_blocks(std::span<const std::uint8_t> octets, std::vector<PrmBlock>& out);

/// Builds a Set_Prm DU (master side and tests of the layout).
std::vector<std::uint8_t> encode_prm(const PrmHeader& h, std::span<const std::uint8_t> user_prm);

/// Watchdog time TWD = base × WD_Fact_1 × WD_Fact_2 with base 10 ms, or 1 ms with WD_Base_1ms.
constexpr bus::Ticks watchdog_ticks(std::uint8_t f1, std::uint8_t f2, bool base_1ms) {
  return static_cast<bus::Ticks>(f1) * f2 * (base_1ms ? 1 : 10) * bus::kTicksPerMs;
}

}  // namespace pbvbus::dp
