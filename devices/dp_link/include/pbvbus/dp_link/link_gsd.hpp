#pragma once
// The GSD text of an IM 157 link as the upper (redundant) DP master system sees it
// (docs/dp-link.md "The link as a DP slave"): a modular, System Redundancy (PI 2.212) DP-V1 slave
// whose modules are the lower stations, in the order configured, each module's identifiers
// being that lower station's whole Chk_Cfg. Its Chk_Cfg and its Data_Exchange frames are
// therefore the concatenation of the lower stations' (so both stay <= 244 octets: a GSD check).
//
// Facts: the Y-link is a switched DP slave towards the H-system and a DP master towards the
// lower line; its configuration and user data frames are made of the lower slaves' frames
// (max. 244 octets each way), max. 64 lower stations (Siemens product note 6847578, the Y-link
// catalogue entry; docs/dp-link.md). The DP/PA link is the same towards the upper line.
//
// Decisions:
// - The ident numbers are pbvbus test idents (0x0A57 Y-link, 0x0A58 DP/PA link), NOT the
//   Siemens ones (the IM 157 GSD is not public here).
// - User_Prm_Data = DPV1_Status_1..3 (80 00 00) as PBVB0A10.gsd; the PrmCmd block is appended
//   by the redundant master (Max_User_Prm_Data_Len 11).
// - Slave_Max_Switch_Over_Time = the coupler's own switchover time (10 ms units, rounded up).
// - All baud rates 9.6 kbit/s .. 12 Mbit/s on the upper side (product note 6847578); the
//   1.5 Mbit/s limit of 001 L8128 is that of a CP 443-5 Extended master, checked by the
//   scenario planner, not by the link.

#include <cstdint>
#include <string>
#include <vector>

#include "pbvbus/bus/time.hpp"

namespace pbvbus::devices {

enum class DpLinkKind : std::uint8_t {
  YLink,     ///< IM 157 + Y-coupler: a single-channel DP line below (187.5 k .. 1.5 Mbit/s)
  DpPaLink,  ///< IM 157 + DP/PA coupler: PROFIBUS PA below (31.25 kbit/s)
};
const char* to_string(DpLinkKind k);

/// One lower station as the link's GSD shows it: one module.
struct LinkGsdModule {
  std::string name;               ///< module name (unique within the link)
  std::vector<std::uint8_t> cfg;  ///< the lower station's Chk_Cfg identifiers, 1..244 octets
};

inline constexpr std::uint16_t kYLinkIdent = 0x0A57;
inline constexpr std::uint16_t kDpPaLinkIdent = 0x0A58;
inline constexpr std::size_t kLinkMaxLowerStations = 64;  ///< Y-link: max. 64 lower stations

/// The GSD text (PI 2.122 syntax) for parse_gsd(). `switchover` is the coupler's T_SLAVE_UM.
std::string link_gsd_text(DpLinkKind kind, const std::vector<LinkGsdModule>& modules,
                          bus::Ticks switchover);

}  // namespace pbvbus::devices
