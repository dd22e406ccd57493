#pragma once
// Text for reports and the command line (protocol-facts.md §D.4, §D.5, §E.5): a Slave_Diag DU
// as the names of its set bits and its extended blocks, the way a bus analyzer prints it.
// Used for the class-1 master's stored diagnosis and class-2 Slave_Diag results.
//
// Example: "Station_Not_Ready Prm_Req | Master_Add none | Ident 0x1234" or
// "Ext_Diag | Master_Add 1 | Ident 0x1234 | modules faulty: 8 | channel: module 8 channel 1
// input bit short circuit | device: 10 20 30".
// For a DP-V1 slave (dpv1 = true) device-related blocks are decoded as alarm and status PDUs.

#include <cstdint>
#include <span>
#include <string>
#include <string_view>

namespace pbvbus::dp {

/// Names of the alarm types 1..6 ("Diagnostic", ...); "manufacturer-specific" for 32..126.
std::string_view alarm_type_name(std::uint8_t type);

/// One line describing a diagnosis; malformed input is described, never rejected.
std::string describe_diag(std::span<const std::uint8_t> du, bool dpv1 = false);

}  // namespace pbvbus::dp
