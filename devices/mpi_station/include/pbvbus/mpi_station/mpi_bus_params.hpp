#pragma once
// The bus parameters of an MPI subnet (docs/mpi.md "MPI bus parameters"; protocol-facts.md §H.1,
// §C.1, §C.2). MPI is PROFIBUS FDL (§H.2), so an MPI subnet is a line whose active stations use
// one fdl::BusParams set like any DP master.
//
// At 187.5 kbit/s (the MPI default, §H.1):
//   HSA        31   §H.1: 15/31/63/126 selectable, STEP 7's default 31 [U]; libnodave's adapter
//                   initialisation (S4 `_daveInitAdapterMPI1`) also sends 0x1F = 31 as its HSA
//                   octet (tools-and-formats.md §3.2, octet 17)
//   TSL       415   } read from the same adapter-initialisation record: the little-endian words
//   max TSDR  400   } 9F 01 = 415, 90 01 = 400 and 14 00 = 20 next to the baud code; 415 is
//   min TSDR   20   } exactly max TSDR + 15, the §C.1 bound. The record's layout is not
//                   documented: this reading is ours [I]
//   TQUI 0, TSET 1  §C.1 (DP table, 9.6 .. 187.5 kbit/s); TID1 = max(33 + 2 + 2 + 0, 20) = 37
//   TTR     20000   our choice (no source): room for every station of a small MPI subnet (a
//                   CPU, a few PGs/OPs) to run two message cycles of the longest frame per visit
//                   (2 x (255 x 11 + 20 + 11 + 37) = 5 746 bits) plus its token and a GAP poll,
//                   about 107 ms at 187.5 kbit/s
//   G 10, retry 1   §C.1 defaults (no MPI-specific source)
// At any other rate: fdl::BusParams::defaults(baud) with the given HSA (the DP-profile table;
// §H.1 names rates up to 12 Mbit/s for newer CPUs but no bus parameters for them).

#include <cstdint>

#include "pbvbus/bus/time.hpp"
#include "pbvbus/fdl/bus_params.hpp"

namespace pbvbus::mpi_station {

inline constexpr bus::Baud kMpiDefaultBaud = bus::Baud::k187_5;
inline constexpr std::uint8_t kMpiDefaultHsa = 31;

/// The MPI bus parameter set for `baud` and `hsa` (see the header comment). Valid by
/// fdl::BusParams::validate() for every HSA 1..126.
fdl::BusParams mpi_bus_params(bus::Baud baud = kMpiDefaultBaud, std::uint8_t hsa = kMpiDefaultHsa);

/// Bit times of one token rotation of `active_stations` stations that send nothing but the
/// token: per station one token frame (3 octets x 11 bits) and the TID1 before the next frame
/// (§C.2). GAP polls are not included (one unanswered poll adds TID1 + 6 x 11 + TSL when a
/// station polls an empty address, §C.5).
std::uint32_t idle_rotation_bits(const fdl::BusParams& p, unsigned active_stations);

}  // namespace pbvbus::mpi_station
