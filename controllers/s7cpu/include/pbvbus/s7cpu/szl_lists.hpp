#pragma once
// The SZL lists every CPU model of s7cpu answers from its CpuInfo (docs/s7cpu.md "Read SZL"),
// layouts from "System Software for S7-300/400 System and Standard Functions", Volume 2,
// ch. "System Status Lists" (found with the project's search; sections named below):
//
// - W#16#0011 / W#16#0111 "Module identification" (§ SSL-ID W#16#xy11): records of 28 octets
//   (LENTHDR W#16#001C): Index u16 | MlfB 20 characters (the order number, 19 characters and a
//   blank) | BGTyp u16 | Ausbg1 u16 | Ausbg2 u16. 0011 = all records, 0111 = the one named by
//   INDEX. The model has the record W#16#0001 (the module) only; Ausbg1 = the module version
//   (CpuInfo::module_version), BGTyp and Ausbg2 0 ("reserved"). 0111 with another INDEX:
//   UnknownIndex.
// - W#16#001C / W#16#011C "Component identification" (§ SSL-ID W#16#xy1C): records of 34
//   octets (LENTHDR W#16#0022): index u16 then 32 octets: 0001 name of the PLC (24 characters)
//   + 8 reserved; 0002 name of the module (24) + 8; 0003 plant identification (32);
//   0004 copyright, the constant "Original Siemens Equipment" (26) + 6; 0005 serial number of
//   the module (24) + 8; 0007 module type name (32). Shorter strings are filled with B#16#00
//   (the manual), reserved octets are 0. 001C = these six records in that order (6 x 34 = 204
//   octets: exactly what a 240-octet PDU carries); 011C = the one named by INDEX; the other
//   indices of the manual (0008 memory card serial number, 0009 manufacturer and profile,
//   000A OEM ID, 000B location designation) are not modelled: UnknownIndex.
// - W#16#0424 "CPU state" (docs/s7cpu.md): one record of 20 octets, the state (CpuInfo::state)
//   in octet 3; the manual's "bzu_id" names the mode codes 1..F (04 STOP, 08 RUN, 09 RUN-R ...;
//   the H models use the same codes as SSL xy71's bz_cpu).
// Any other id: nullopt (the server answers UnknownId).
#include <cstdint>
#include <optional>

#include "pbvbus/s7cpu/s7_server.hpp"
#include "pbvbus/s7cpu/szl_source.hpp"

namespace pbvbus::s7cpu {

inline constexpr std::uint16_t kSzlModuleIdentification = 0x0011;
inline constexpr std::uint16_t kSzlOneModuleIdentification = 0x0111;
inline constexpr std::uint16_t kSzlComponentIdentification = 0x001C;
inline constexpr std::uint16_t kSzlOneComponentIdentification = 0x011C;
inline constexpr std::uint16_t kSzlCpuState = 0x0424;

/// The standard lists above, nullopt for any other id.
std::optional<SzlList> standard_szl(const CpuInfo& info, std::uint16_t id, std::uint16_t index);

}  // namespace pbvbus::s7cpu
