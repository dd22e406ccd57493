// The MPI bus parameter set (decisions in mpi_bus_params.hpp and docs/mpi.md).
#include "pbvbus/mpi_station/mpi_bus_params.hpp"

namespace pbvbus::mpi_station {

fdl::BusParams mpi_bus_params(bus::Baud baud, std::uint8_t hsa) {
  fdl::BusParams p = fdl::BusParams::defaults(baud);
  p.hsa = hsa;
  if (baud != bus::Baud::k187_5) return p;
  p.tsl = 415;
  p.min_tsdr = 20;
  p.max_tsdr = 400;
  p.tqui = 0;
  p.tset = 1;
  p.ttr = 20'000;
  p.gap_factor = 10;
  p.max_retry = 1;
  return p;
}

std::uint32_t idle_rotation_bits(const fdl::BusParams& p, unsigned active_stations) {
  return active_stations * (3 * 11 + p.tid1());
}

}  // namespace pbvbus::mpi_station
