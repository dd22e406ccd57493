#pragma once
// DP service access points (IEC 61158-6 DP; protocol-facts.md §D.1). Shared by the DP slave
// engine and the DP master: a request to slave SAP x comes from master SSAP 62 (MS0) for the
// DP-V0 services, from SSAP 51 for MSAC_C1 and from SSAP 50 for MSAC_C2.

#include <cstdint>

namespace pbvbus::dp {

// Slave-side SAPs.
inline constexpr std::uint8_t kSapC2ConnectionHigh = 48;  ///< C2 connection SAPs 48, 47, ... 0
inline constexpr std::uint8_t kSapC2ResourceManager = 49;  ///< MSAC_C2 resource manager
inline constexpr std::uint8_t kSapC1Alarm = 50;             ///< MSAC_C1 Alarm_Ack
inline constexpr std::uint8_t kSapC1ReadWrite = 51;         ///< MSAC_C1 Read/Write
inline constexpr std::uint8_t kSapExtUserPrm = 53;
inline constexpr std::uint8_t kSapSetSlaveAdd = 55;
inline constexpr std::uint8_t kSapRdInp = 56;
inline constexpr std::uint8_t kSapRdOutp = 57;
inline constexpr std::uint8_t kSapGlobalControl = 58;
inline constexpr std::uint8_t kSapGetCfg = 59;
inline constexpr std::uint8_t kSapSlaveDiag = 60;
inline constexpr std::uint8_t kSapSetPrm = 61;
inline constexpr std::uint8_t kSapChkCfg = 62;

// Master-side source SAPs.
inline constexpr std::uint8_t kSapMs0 = 62;  ///< DP-V0 services of a class-1 or class-2 master
inline constexpr std::uint8_t kSapMs1 = 51;  ///< DP-V1 MSAC_C1 source SAP of the class-1 master
inline constexpr std::uint8_t kSapMs2 = 50;  ///< MSAC_C2 source SAP of the class-2 master
inline constexpr std::uint8_t kSapMm = 54;   ///< master-to-master

/// Addresses with a DP meaning.
inline constexpr std::uint8_t kDefaultSlaveAddress = 126;  ///< "not yet addressed" (Set_Slave_Add)
inline constexpr std::uint8_t kMaxSlaveAddress = 125;
inline constexpr std::uint8_t kNoMaster = 0xFF;  ///< Diag.Master_Add when not parameterised

}  // namespace pbvbus::dp
