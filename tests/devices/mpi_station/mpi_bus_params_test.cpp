// The MPI bus parameter set (mpi_bus_params.hpp; docs/mpi.md "MPI bus parameters").

#include <gtest/gtest.h>

#include "pbvbus/mpi_station/mpi_bus_params.hpp"

namespace pbvbus::mpi_station {
namespace {

TEST(MpiBusParams, DefaultsAt187_5kWithHsa31) {
  const fdl::BusParams p = mpi_bus_params();
  EXPECT_EQ(p.baud, bus::Baud::k187_5);
  EXPECT_EQ(p.hsa, 31);  // §H.1 [U]; libnodave's adapter initialisation octet 17 = 0x1F
  EXPECT_EQ(p.tsl, 415u);
  EXPECT_EQ(p.max_tsdr, 400u);
  EXPECT_EQ(p.min_tsdr, 20u);
  EXPECT_EQ(p.tqui, 0u);
  EXPECT_EQ(p.tset, 1u);
  EXPECT_EQ(p.ttr, 20'000u);
  EXPECT_EQ(p.gap_factor, 10u);
  EXPECT_EQ(p.max_retry, 1);
  EXPECT_EQ(p.validate(), "");
  // TSL = max TSDR + 15 exactly (§C.1 bound); TID1 = max(33 + 2 + 2*1 + 0, 20) = 37.
  EXPECT_EQ(p.tsl, p.max_tsdr + 15);
  EXPECT_EQ(p.tid1(), 37u);
  // TTO of the PG at address 0: 6 * 415 = 2490 bits; of the CPU at 2: 6*415 + 2*2*415 = 4150.
  EXPECT_EQ(p.tto(0), 2490u);
  EXPECT_EQ(p.tto(2), 4150u);
}

TEST(MpiBusParams, EveryHsaOfH1IsValid) {
  for (const std::uint8_t hsa : {std::uint8_t{15}, std::uint8_t{31}, std::uint8_t{63}, std::uint8_t{126}}) {
    const fdl::BusParams p = mpi_bus_params(bus::Baud::k187_5, hsa);
    EXPECT_EQ(p.hsa, hsa);
    EXPECT_EQ(p.validate(), "") << int{hsa};
  }
}

TEST(MpiBusParams, OtherRatesUseTheDpTableWithTheHsa) {
  const fdl::BusParams p = mpi_bus_params(bus::Baud::k1_5M, 31);
  fdl::BusParams dp = fdl::BusParams::defaults(bus::Baud::k1_5M);
  EXPECT_EQ(p.hsa, 31);
  EXPECT_EQ(p.tsl, dp.tsl);
  EXPECT_EQ(p.max_tsdr, dp.max_tsdr);
  EXPECT_EQ(p.validate(), "");
}

TEST(MpiBusParams, IdleRotationIsTokenPlusTid1PerStation) {
  // 5 stations: 5 x (3 octets x 11 bits + TID1 37) = 5 x 70 = 350 bits.
  EXPECT_EQ(idle_rotation_bits(mpi_bus_params(), 5), 350u);
  EXPECT_EQ(idle_rotation_bits(mpi_bus_params(), 3), 210u);
}

}  // namespace
}  // namespace pbvbus::mpi_station
