// GSD reader robustness against files as vendors write them: repeated PrmText/ExtUserPrmData
// definitions and unterminated blocks. Each case asserts the exact messages ("file:line: reason")
// and what the model keeps. This file also runs under ASan+UBSan (sanitize_devices).

#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "pbvbus/devices/gsd.hpp"

using namespace pbvbus::devices;

namespace {

std::string src(const std::string& rel) { return std::string(PBVBUS_SOURCE_DIR) + "/" + rel; }

// A minimal valid slave file; lines 1..10, extra lines start at 11.
std::string base(const std::vector<std::string>& extra) {
  std::string s =
      "#Profibus_DP\n"            // 1
      "GSD_Revision=1\n"          // 2
      "Ident_Number=0x1234\n"     // 3
      "Station_Type=0\n"          // 4
      "12M_supp=1\n"              // 5
      "MaxTsdr_12M=800\n"         // 6
      "Min_Slave_Intervall=1\n"   // 7
      "Max_Diag_Data_Len=6\n"     // 8
      "Module=\"m\" 0x10\n"       // 9
      "EndModule\n";              // 10
  for (const auto& l : extra) s += l + "\n";
  return s;
}

std::vector<std::string> texts(const std::vector<GsdMessage>& messages) {
  std::vector<std::string> out;
  for (const auto& m : messages) out.push_back(m.to_string());
  return out;
}

}  // namespace

// --- (a) a PrmText or ExtUserPrmData number defined twice ---------------------------------------

TEST(GsdDuplicates, VendorFileWithPrmTextAndExtUserPrmDataTwice) {
  const std::string path = src("tests/data/gsd/vendor-quirks/duplicate-prmtext.gsd");
  const GsdParseResult r = load_gsd(path);
  ASSERT_TRUE(r.ok()) << (r.errors.empty() ? "" : r.errors[0].to_string());
  EXPECT_EQ(texts(r.warnings),
            (std::vector<std::string>{
                path + ":44: PrmText 1 defined twice (first at line 33); the later definition wins",
                path + ":49: ExtUserPrmData 1 defined twice (first at line 38); the later definition wins"}));
  const GsdFile& f = *r.file;
  // The later blocks replaced the earlier ones.
  const GsdPrmText& t = f.prm_texts().at(1);
  EXPECT_EQ(t.line, 44u);
  ASSERT_EQ(t.texts.size(), 2u);
  EXPECT_EQ(t.texts[0].second, "disabled");
  const GsdExtUserPrmData& e = f.ext_user_prm_data().at(1);
  EXPECT_EQ(e.name, "Hold outputs on Clear");
  EXPECT_EQ(e.line, 49u);
  EXPECT_EQ(e.type, GsdDataType::Bit);
  EXPECT_EQ(e.bit_first, 1);
  // Const(0) = 0x00, then Ref(0) = 1 is the later definition: Bit(1) default 1 -> 0x02.
  auto prm = f.user_prm_data({0});
  ASSERT_TRUE(prm.ok());
  EXPECT_EQ(*prm.value, (GsdBytes{0x02}));
}

TEST(GsdDuplicates, LaterDefinitionWinsInline) {
  const GsdParseResult r = parse_gsd(base({"PrmText = 7",             // 11
                                           "Text(0) = \"a\"",          // 12
                                           "EndPrmText",               // 13
                                           "PrmText = 7",              // 14
                                           "Text(0) = \"b\"",          // 15
                                           "EndPrmText",               // 16
                                           "ExtUserPrmData = 5 \"r\"", // 17
                                           "Unsigned8 1 0-3",          // 18
                                           "EndExtUserPrmData",        // 19
                                           "ExtUserPrmData = 5 \"s\"", // 20
                                           "Unsigned8 9 0-20",         // 21
                                           "Prm_Text_Ref = 7",         // 22
                                           "EndExtUserPrmData",        // 23
                                           "PrmText = 7",              // 24: a third time
                                           "Text(0) = \"c\"",          // 25
                                           "EndPrmText"}),             // 26
                                     "d.gsd");
  ASSERT_TRUE(r.ok()) << (r.errors.empty() ? "" : r.errors[0].to_string());
  EXPECT_EQ(texts(r.warnings),
            (std::vector<std::string>{
                "d.gsd:14: PrmText 7 defined twice (first at line 11); the later definition wins",
                "d.gsd:20: ExtUserPrmData 5 defined twice (first at line 17); the later definition wins",
                "d.gsd:24: PrmText 7 defined twice (first at line 14); the later definition wins"}));
  EXPECT_EQ(r.file->prm_texts().at(7).texts.at(0).second, "c");
  EXPECT_EQ(r.file->ext_user_prm_data().at(5).name, "s");
  EXPECT_EQ(r.file->ext_user_prm_data().at(5).default_value, 9);
}

TEST(GsdDuplicates, BrokenSecondDefinitionIsStillAnError) {
  // Only a well-formed repetition is tolerated: a second block without a data type line is an
  // error as it would be the first time.
  const GsdParseResult r = parse_gsd(base({"ExtUserPrmData = 5 \"r\"", "Bit(0) 0 0-1", "EndExtUserPrmData",
                                           "ExtUserPrmData = 5 \"s\"", "EndExtUserPrmData"}),
                                     "d.gsd");
  ASSERT_FALSE(r.ok());
  ASSERT_EQ(r.errors.size(), 1u);
  EXPECT_EQ(r.errors[0].to_string(), "d.gsd:14: ExtUserPrmData 5 's': data type line missing");
}
