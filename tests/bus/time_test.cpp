// Virtual time base (design.md "Time"): tick values per baud, duration and baud parsing.

#include "pbvbus/bus/time.hpp"

#include <gtest/gtest.h>

namespace pbvbus::bus {
namespace {

TEST(Time, TicksPerBitMatchDesignTable) {
  // design.md "Time" and the bus brief: 1 s = 3 636 000 000 ticks.
  EXPECT_EQ(kTicksPerSecond, 3'636'000'000);
  EXPECT_EQ(ticks_per_bit(Baud::k12M), 303);
  EXPECT_EQ(ticks_per_bit(Baud::k6M), 606);
  EXPECT_EQ(ticks_per_bit(Baud::k3M), 1212);
  EXPECT_EQ(ticks_per_bit(Baud::k1_5M), 2424);
  EXPECT_EQ(ticks_per_bit(Baud::k500), 7272);
  EXPECT_EQ(ticks_per_bit(Baud::k187_5), 19'392);
  EXPECT_EQ(ticks_per_bit(Baud::k93_75), 38'784);
  EXPECT_EQ(ticks_per_bit(Baud::k45_45), 80'000);
  EXPECT_EQ(ticks_per_bit(Baud::k19_2), 189'375);
  EXPECT_EQ(ticks_per_bit(Baud::k9_6), 378'750);
  EXPECT_EQ(ticks_per_bit(Baud::k31_25), 116'352);
  // The table covers every member of kAllBauds, and each bit time is exact.
  for (Baud b : kAllBauds) EXPECT_EQ(ticks_per_bit(b) * static_cast<Ticks>(b), kTicksPerSecond) << baud_name(b);
}

TEST(Time, CharactersAndBits) {
  EXPECT_EQ(kBitsPerChar, 11);
  EXPECT_EQ(chars_to_ticks(6, Baud::k12M), 66 * 303);
  EXPECT_EQ(bits_to_ticks(33, Baud::k1_5M), 33 * 2424);
  EXPECT_EQ(ticks_to_bits(33 * 2424 + 2423, Baud::k1_5M), 33);
  // TSYN at 9.6k is 3437.5 us (protocol-facts.md §A table).
  EXPECT_EQ(ticks_to_ns(bits_to_ticks(33, Baud::k9_6)), 3'437'500);
}

TEST(Time, TicksToNsIsExact) {
  EXPECT_EQ(ticks_to_ns(0), 0);
  EXPECT_EQ(ticks_to_ns(3636), 1000);
  EXPECT_EQ(ticks_to_ns(3635), 999);
  EXPECT_EQ(ticks_to_ns(kTicksPerSecond), 1'000'000'000);
  EXPECT_EQ(ticks_to_ns(303), 83);      // 12M bit time: 83.33 ns, rounded down
  EXPECT_EQ(ticks_to_ns(2424), 666);    // 1.5M bit time: 666.67 ns
  EXPECT_EQ(ticks_to_ns(19'392), 5333);
  EXPECT_EQ(ticks_to_us(kTicksPerMs), 1000);
  // Against 128-bit arithmetic, including values where t * 1000 would overflow int64.
  __extension__ typedef __int128 Wide;
  for (Ticks t : {Ticks{1}, Ticks{7}, Ticks{123'456'789}, kTicksPerSecond * 3600 + 17,
                  Ticks{INT64_MAX / 1000 + 12345}, Ticks{INT64_MAX - 1}, Ticks{INT64_MAX}}) {
    const auto expect = static_cast<std::int64_t>(static_cast<Wide>(t) * 1000 / 3636);
    EXPECT_EQ(ticks_to_ns(t), expect) << t;
  }
}

TEST(Time, ParseDuration) {
  EXPECT_EQ(parse_duration("250ms"), 250 * kTicksPerMs);
  EXPECT_EQ(parse_duration("5s"), 5 * kTicksPerSecond);
  EXPECT_EQ(parse_duration("2min"), 120 * kTicksPerSecond);
  EXPECT_EQ(parse_duration("1h"), 3600 * kTicksPerSecond);
  EXPECT_EQ(parse_duration("1.5s"), 5'454'000'000);
  EXPECT_EQ(parse_duration("100us"), 363'600);
  EXPECT_EQ(parse_duration("0.25ms"), 909'000);
  EXPECT_EQ(parse_duration("1500ns"), 5454);
  EXPECT_EQ(parse_duration("1ns"), 4);  // 3.636 ticks, to the nearest tick
  EXPECT_EQ(parse_duration("3ticks"), 3);
  EXPECT_EQ(parse_duration("5 s"), 5 * kTicksPerSecond);
  EXPECT_EQ(parse_duration("0s"), 0);
}

TEST(Time, ParseDurationRejectsBadInput) {
  for (const char* bad : {"", "s", "ms", "5", "5parsecs", "-5s", "+5s", "1e3s", "1.5.5s", "5 S", "s5",
                          "3000000000s", "99999999999999999999s", "5ms ", "five s"}) {
    EXPECT_EQ(parse_duration(bad), std::nullopt) << '"' << bad << '"';
  }
}

TEST(Time, ParseBaud) {
  EXPECT_EQ(parse_baud("1.5M"), Baud::k1_5M);
  EXPECT_EQ(parse_baud("1.5Mbit/s"), Baud::k1_5M);
  EXPECT_EQ(parse_baud("1500000"), Baud::k1_5M);
  EXPECT_EQ(parse_baud("1500k"), Baud::k1_5M);
  EXPECT_EQ(parse_baud("187.5k"), Baud::k187_5);
  EXPECT_EQ(parse_baud("187.5kbit/s"), Baud::k187_5);
  EXPECT_EQ(parse_baud("12M"), Baud::k12M);
  EXPECT_EQ(parse_baud("12000k"), Baud::k12M);
  EXPECT_EQ(parse_baud("45.45k"), Baud::k45_45);
  EXPECT_EQ(parse_baud("31.25k"), Baud::k31_25);
  EXPECT_EQ(parse_baud("9600"), Baud::k9_6);
  EXPECT_EQ(parse_baud("19.2 kbit/s"), Baud::k19_2);
  for (Baud b : kAllBauds) EXPECT_EQ(parse_baud(baud_name(b)), b) << baud_name(b);
  for (const char* bad : {"", "M", "k", "1.5", "115200", "1.4M", "12G", "-12M", "1.5MM", "1.50001M", "abc"})
    EXPECT_EQ(parse_baud(bad), std::nullopt) << '"' << bad << '"';
}

TEST(Time, FormatDuration) {
  EXPECT_EQ(format_duration(5 * kTicksPerSecond / 2), "2.500 s");
  EXPECT_EQ(format_duration(250 * kTicksPerMs), "250.000 ms");
  EXPECT_EQ(format_duration(44'887), "12.345 us");  // 12 345.16 ns
  EXPECT_EQ(format_duration(-kTicksPerSecond), "-1.000 s");
}

}  // namespace
}  // namespace pbvbus::bus
