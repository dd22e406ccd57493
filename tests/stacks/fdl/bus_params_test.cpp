// Bus parameter defaults, idle times, token-loss timeout and the §C.1 constraint check
// (protocol-facts.md §C.1, §C.2). Expected values are computed by hand from the formulas.
#include "pbvbus/fdl/bus_params.hpp"

#include <gtest/gtest.h>

#include <string>

namespace pbvbus::fdl {
namespace {

using bus::Baud;

struct Row {
  Baud baud;
  std::uint32_t tsl, min_tsdr, max_tsdr, tqui, tset, tid1, tid2;
};

// §C.1 table; TID1 = max(33 + 2 + 2·TSET + TQUI, min TSDR), TID2 = max(33 + TSM, max TSDR).
// 45.45k and 31.25k: our documented decision (bus_params.hpp): TID1 = 33 + 2 + 190 = 225.
constexpr Row kTable[] = {
    {Baud::k9_6, 100, 11, 60, 0, 1, 37, 60},       {Baud::k19_2, 100, 11, 60, 0, 1, 37, 60},
    {Baud::k31_25, 640, 11, 400, 0, 95, 225, 400}, {Baud::k45_45, 640, 11, 400, 0, 95, 225, 400},
    {Baud::k93_75, 100, 11, 60, 0, 1, 37, 60},     {Baud::k187_5, 100, 11, 60, 0, 1, 37, 60},
    {Baud::k500, 200, 11, 100, 0, 1, 37, 100},     {Baud::k1_5M, 300, 11, 150, 0, 1, 37, 150},
    {Baud::k3M, 400, 11, 250, 3, 4, 46, 250},      {Baud::k6M, 600, 11, 450, 6, 8, 57, 450},
    {Baud::k12M, 1000, 11, 800, 9, 16, 76, 800},
};

TEST(BusParams, DefaultsFollowTheDpProfileTableForEveryBaud) {
  ASSERT_EQ(std::size(kTable), std::size(bus::kAllBauds));
  for (const Row& r : kTable) {
    SCOPED_TRACE(std::string(bus::baud_name(r.baud)));
    const BusParams p = BusParams::defaults(r.baud);
    EXPECT_EQ(p.baud, r.baud);
    EXPECT_EQ(p.tsl, r.tsl);
    EXPECT_EQ(p.min_tsdr, r.min_tsdr);
    EXPECT_EQ(p.max_tsdr, r.max_tsdr);
    EXPECT_EQ(p.tqui, r.tqui);
    EXPECT_EQ(p.tset, r.tset);
    EXPECT_EQ(p.tid1(), r.tid1);
    EXPECT_EQ(p.tid2(), r.tid2);
    EXPECT_EQ(p.gap_factor, 10u);
    EXPECT_EQ(p.hsa, 126);
    EXPECT_EQ(p.max_retry, 1);
    EXPECT_EQ(p.tsdi, 0u);
    EXPECT_EQ(p.validate(), "") << "defaults must satisfy §C.1";
  }
}

TEST(BusParams, FortyFiveKilobaudCoversTheExampleGsdMaxTsdr) {
  const BusParams p = BusParams::defaults(Baud::k45_45);
  EXPECT_GE(p.max_tsdr, 250u);  // S1 example GSD MaxTsdr_45.45 = 250
  EXPECT_GE(p.tsl, p.max_tsdr + 15);
}

TEST(BusParams, IdleTimesFromTheFormula) {
  // 1.5M: TSM = 2 + 2·1 + 0 = 4; TID1 = max(33 + 4, 11) = 37; TID2 = max(37, 150) = 150.
  const BusParams p15 = BusParams::defaults(Baud::k1_5M);
  EXPECT_EQ(p15.tsm(), 4u);
  EXPECT_EQ(p15.tid1(), 37u);
  EXPECT_EQ(p15.tid2(), 150u);
  // 500k: TID2 = max(37, 100) = 100.
  EXPECT_EQ(BusParams::defaults(Baud::k500).tid2(), 100u);
  // 3M: TSM = 2 + 8 + 3 = 13; TID1 = 33 + 13 = 46.
  EXPECT_EQ(BusParams::defaults(Baud::k3M).tid1(), 46u);
  // 6M: TSM = 2 + 16 + 6 = 24; TID1 = 57.
  EXPECT_EQ(BusParams::defaults(Baud::k6M).tid1(), 57u);
  // 12M: TSM = 2 + 32 + 9 = 43; TID1 = 76; TID2 = max(76, 800) = 800.
  const BusParams p12 = BusParams::defaults(Baud::k12M);
  EXPECT_EQ(p12.tsm(), 43u);
  EXPECT_EQ(p12.tid1(), 76u);
  EXPECT_EQ(p12.tid2(), 800u);
}

TEST(BusParams, Tid1TakesTheLargestOfItsThreeTerms) {
  BusParams p = BusParams::defaults(Baud::k1_5M);
  p.min_tsdr = 100;  // min TSDR above TSYN + TSM = 37
  EXPECT_EQ(p.tid1(), 100u);
  p.tsdi = 120;  // the initiator's own station delay dominates
  EXPECT_EQ(p.tid1(), 120u);
  p.min_tsdr = 11;
  p.tsdi = 20;  // both below 37
  EXPECT_EQ(p.tid1(), 37u);
}

TEST(BusParams, Tid2NeverBelowSyncPlusSafetyMargin) {
  BusParams p = BusParams::defaults(Baud::k12M);
  p.max_tsdr = 60;  // below TSYN + TSM = 76
  EXPECT_EQ(p.tid2(), 76u);
}

TEST(BusParams, TokenLossTimeout) {
  BusParams p = BusParams::defaults(Baud::k1_5M);  // TSL 300
  EXPECT_EQ(p.tto(0), 1800u);                       // 6·300
  EXPECT_EQ(p.tto(1), 2400u);                       // 6·300 + 2·1·300
  EXPECT_EQ(p.tto(2), 3000u);
  EXPECT_EQ(p.tto(125), 76'800u);                   // 1800 + 250·300
  p = BusParams::defaults(Baud::k12M);              // TSL 1000
  EXPECT_EQ(p.tto(3), 12'000u);                     // 6000 + 6000
  p.tsl = BusParams::kTslMax;                       // largest TSL, largest address: no overflow
  EXPECT_EQ(p.tto(126), 16'383u * 258u);
  // A lower address times out first and wins the claim (§C.2).
  EXPECT_LT(p.tto(4), p.tto(5));
}

TEST(BusParams, TtrEstimateIsTheSumOfMessageCycles) {
  const BusParams p = BusParams::defaults(Baud::k1_5M);  // TSL 300, max TSDR 150, TID1 37
  // 1 slave, 2 octets each way: SD2 of 11 octets -> 121 + 150 + 121 + 37 = 429;
  // token 33 + 37 = 70; GAP poll 66 + 300 + 37 = 403.
  EXPECT_EQ(p.ttr_estimate(1, 2), 429u + 70u + 403u);
  // 8 octets go as SD3 (14 octets = 154 bits): 154 + 150 + 154 + 37 = 495.
  EXPECT_EQ(p.ttr_estimate(1, 8), 495u + 70u + 403u);
  // No data: SD1 request (66) and SC reply (11): 66 + 150 + 11 + 37 = 264.
  EXPECT_EQ(p.ttr_estimate(2, 0), 2 * 264u + 70u + 403u);
  EXPECT_EQ(p.ttr_estimate(0, 0), 473u);
  // The default TTR is this estimate for 32 slaves with 16 octets: SD2 of 25 octets = 275 bits,
  // 275 + 150 + 275 + 37 = 737 per slave.
  EXPECT_EQ(p.ttr, 32 * 737u + 473u);
  EXPECT_EQ(p.ttr_estimate(1'000'000, 246), BusParams::kTtrMax);  // saturates
}

// --- validate(): one test per constraint -----------------------------------------------------

BusParams valid() { return BusParams::defaults(Baud::k1_5M); }

TEST(BusParamsValidate, TslBelowMaxTsdrPlus15) {
  BusParams p = valid();
  p.tsl = 160;  // max TSDR 150
  EXPECT_EQ(p.validate(), "TSL 160 must be at least max TSDR + 15 = 165");
  p.tsl = 165;
  EXPECT_EQ(p.validate(), "");
}

TEST(BusParamsValidate, TslAbove16383) {
  BusParams p = valid();
  p.tsl = 16'384;
  EXPECT_EQ(p.validate(), "TSL 16384 must be at most 16383");
  p.tsl = 16'383;
  EXPECT_EQ(p.validate(), "");
}

TEST(BusParamsValidate, MaxTsdrBelowSetupAndQuietFloor) {
  BusParams p = BusParams::defaults(Baud::k12M);  // TSET 16, TQUI 9: floor 35 + 32 + 9 = 76
  p.max_tsdr = 75;
  EXPECT_EQ(p.validate(), "max TSDR 75 must be at least 35 + 2*TSET + TQUI = 76");
  p.max_tsdr = 76;
  EXPECT_EQ(p.validate(), "");
}

TEST(BusParamsValidate, MaxTsdrAbove1023) {
  BusParams p = valid();
  p.max_tsdr = 1024;
  p.tsl = 2000;
  EXPECT_EQ(p.validate(), "max TSDR 1024 must be at most 1023");
  p.max_tsdr = 1023;
  EXPECT_EQ(p.validate(), "");
}

TEST(BusParamsValidate, MinTsdrBelow11) {
  BusParams p = valid();
  p.min_tsdr = 10;
  EXPECT_EQ(p.validate(), "min TSDR 10 must be at least 11");
}

TEST(BusParamsValidate, MinTsdrNotBelowMaxTsdr) {
  BusParams p = valid();
  p.min_tsdr = 150;  // max TSDR 150
  EXPECT_EQ(p.validate(), "min TSDR 150 must be at most max TSDR - 1 = 149");
  p.min_tsdr = 149;
  EXPECT_EQ(p.validate(), "");
}

TEST(BusParamsValidate, MinTsdrFitsOneSetPrmOctet) {
  BusParams p = valid();
  p.max_tsdr = 400;
  p.tsl = 500;
  p.min_tsdr = 256;
  EXPECT_EQ(p.validate(), "min TSDR 256 must be at most 255 (one Set_Prm octet)");
  p.min_tsdr = 255;
  EXPECT_EQ(p.validate(), "");
}

TEST(BusParamsValidate, QuietAndSetupTimesFitOneOctet) {
  BusParams p = valid();
  p.max_tsdr = 1000;
  p.tsl = 1100;
  p.tqui = 256;  // 35 + 2 + 256 = 293 <= 1000: only the octet limit catches it
  EXPECT_EQ(p.validate(), "TQUI 256 must be at most 255");
  p.tqui = 255;
  EXPECT_EQ(p.validate(), "");
  p.tset = 256;  // 35 + 512 + 255 = 802 <= 1000
  EXPECT_EQ(p.validate(), "TSET 256 must be at most 255");
  // Without room in max TSDR the floor reports them first, with no wrap-around in the sum.
  p = valid();
  p.tqui = 4'000'000'000u;
  EXPECT_EQ(p.validate(), "max TSDR 150 must be at least 35 + 2*TSET + TQUI = 4000000037");
}

TEST(BusParamsValidate, TtrRange) {
  BusParams p = valid();
  p.ttr = 255;
  EXPECT_EQ(p.validate(), "TTR 255 must be at least 256");
  p.ttr = 256;
  EXPECT_EQ(p.validate(), "");
  p.ttr = 16'777'961;
  EXPECT_EQ(p.validate(), "TTR 16777961 must be at most 16777960");
  p.ttr = 16'777'960;
  EXPECT_EQ(p.validate(), "");
}

TEST(BusParamsValidate, GapFactorRange) {
  BusParams p = valid();
  p.gap_factor = 0;
  EXPECT_EQ(p.validate(), "G (GAP factor) 0 must be at least 1");
  p.gap_factor = 101;
  EXPECT_EQ(p.validate(), "G (GAP factor) 101 must be at most 100");
  p.gap_factor = 100;
  EXPECT_EQ(p.validate(), "");
  p.gap_factor = 1;
  EXPECT_EQ(p.validate(), "");
}

TEST(BusParamsValidate, HsaRange) {
  BusParams p = valid();
  p.hsa = 0;
  EXPECT_EQ(p.validate(), "HSA 0 must be at least 1");
  p.hsa = 127;
  EXPECT_EQ(p.validate(), "HSA 127 must be at most 126");
  p.hsa = 1;
  EXPECT_EQ(p.validate(), "");
}

TEST(BusParamsValidate, RetryLimitRange) {
  BusParams p = valid();
  p.max_retry = 16;
  EXPECT_EQ(p.validate(), "retry limit 16 must be at most 15");
  p.max_retry = 0;
  EXPECT_EQ(p.validate(), "");
  p.max_retry = 15;
  EXPECT_EQ(p.validate(), "");
}

TEST(BusParamsValidate, HugeValuesDoNotWrapAround) {
  BusParams p = valid();
  p.max_tsdr = 0xFFFF'FFFFu;  // max TSDR + 15 would wrap in 32 bits
  EXPECT_EQ(p.validate(), "TSL 300 must be at least max TSDR + 15 = 4294967310");
  p = valid();
  p.min_tsdr = 0xFFFF'FFFFu;  // min TSDR + 1 would wrap
  EXPECT_EQ(p.validate(), "min TSDR 4294967295 must be at most max TSDR - 1 = 149");
}

}  // namespace
}  // namespace pbvbus::fdl
