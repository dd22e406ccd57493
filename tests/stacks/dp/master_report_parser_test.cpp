// Diagnosis text for reports (protocol-facts.md §D.4, §D.5, §E.5), including malformed and
// random input (built into sanitize_dp: runs under ASan/UBSan).
#include <gtest/gtest.h>

#include <cstdint>
#include <random>
#include <vector>

#include "pbvbus/dp/master_report.hpp"

namespace pbvbus::dp {
namespace {

using Bytes = std::vector<std::uint8_t>;

TEST(DpDiagText, StandardOctets) {
  EXPECT_EQ(describe_diag(Bytes{0x02, 0x05, 0x00, 0xFF, 0x12, 0x34}),
            "Station_Not_Ready Prm_Req | Master_Add none | Ident 0x1234");
  EXPECT_EQ(describe_diag(Bytes{0x00, 0x0C, 0x00, 0x01, 0x12, 0x34}),
            "WD_On | Master_Add 1 | Ident 0x1234");
  EXPECT_EQ(describe_diag(Bytes{0x00, 0x04, 0x00, 0x01, 0x12, 0x34}),
            "ok | Master_Add 1 | Ident 0x1234");
  EXPECT_EQ(describe_diag(Bytes{0x81, 0x00, 0x80, 0x02, 0x00, 0x07}),
            "Station_Non_Existent Master_Lock Ext_Diag_Overflow always-1 bit missing | "
            "Master_Add 2 | Ident 0x0007");
}

TEST(DpDiagText, ExtendedBlocks) {
  // The worked example of §D.5: identifier block (module 8), channel block, device block.
  const Bytes d{0x08, 0x0C, 0x00, 0x01, 0x12, 0x34, 0x44, 0x00, 0x01,
                0x00, 0x88, 0x41, 0x21, 0x04, 0x10, 0x20, 0x30};
  EXPECT_EQ(describe_diag(d),
            "Ext_Diag WD_On | Master_Add 1 | Ident 0x1234 | modules faulty: 8 | channel: module 8 "
            "channel 1 input bit short circuit | device: 10 20 30");
}

TEST(DpDiagText, Dpv1AlarmAndStatus) {
  const Bytes d{0x00, 0x0C, 0x00, 0x01, 0x12, 0x34, 0x05, 0x01, 0x02, 0x09, 0x55,
                0x05, 0x82, 0x00, 0x00, 0x04};
  EXPECT_EQ(describe_diag(d, true),
            "WD_On | Master_Add 1 | Ident 0x1234 | alarm Diagnostic slot 2 seq 1 appears: 55 | "
            "status Module_Status slot 0 no specifier: 04");
  EXPECT_EQ(alarm_type_name(4), "Plug");
  EXPECT_EQ(alarm_type_name(40), "manufacturer-specific");
  EXPECT_EQ(alarm_type_name(0), "reserved");
}

TEST(DpDiagText, MalformedInputIsDescribed) {
  EXPECT_EQ(describe_diag(Bytes{0x00, 0x0C, 0x00}), "malformed diagnosis (00 0C 00)");
  EXPECT_EQ(describe_diag(Bytes{}), "malformed diagnosis ()");
  EXPECT_EQ(describe_diag(Bytes{0x08, 0x0C, 0x00, 0x01, 0x12, 0x34, 0x45, 0x00}),
            "Ext_Diag WD_On | Master_Add 1 | Ident 0x1234 | malformed extended diagnosis (45 00)");
  EXPECT_EQ(describe_diag(Bytes{0x08, 0x0C, 0x00, 0x01, 0x12, 0x34, 0xC0}),
            "Ext_Diag WD_On | Master_Add 1 | Ident 0x1234 | malformed extended diagnosis (C0)");
}

TEST(DpDiagText, RandomInputNeverCrashes) {
  std::mt19937 rng(42);
  for (int i = 0; i < 20000; ++i) {
    Bytes b(rng() % 40);
    for (auto& x : b) x = static_cast<std::uint8_t>(rng());
    EXPECT_FALSE(describe_diag(b, (i & 1) != 0).empty());
  }
}

}  // namespace
}  // namespace pbvbus::dp
