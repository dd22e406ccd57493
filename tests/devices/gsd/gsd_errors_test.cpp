// Broken GSD files: one case per error class, each asserting the exact "file:line: reason" of the
// first error, and that no model is returned.

#include <gtest/gtest.h>

#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "pbvbus/gsd/gsd.hpp"

using namespace pbvbus::devices;

namespace {

// A minimal valid slave file; lines are numbered 1..10.
const std::vector<std::string> kBase = {
    "#Profibus_DP",           // 1
    "GSD_Revision=1",         // 2
    "Ident_Number=0x1234",    // 3
    "Station_Type=0",         // 4
    "12M_supp=1",             // 5
    "MaxTsdr_12M=800",        // 6
    "Min_Slave_Intervall=1",  // 7
    "Max_Diag_Data_Len=6",    // 8
    "Module=\"m\" 0x10",      // 9
    "EndModule",              // 10
};

std::string make(std::set<int> omit, const std::vector<std::string>& extra) {
  std::string s;
  for (std::size_t i = 0; i < kBase.size(); ++i) {
    // Omitted lines stay as comments so that line numbers do not move.
    s += omit.count(static_cast<int>(i + 1)) ? ";" : kBase[i];
    s += "\n";
  }
  for (const auto& l : extra) s += l + "\n";
  return s;
}

struct Case {
  const char* name;
  std::string text;
  std::string expected;
};

std::vector<Case> cases() {
  return {
      {"Valid", make({}, {}), ""},
      {"SectionMissing", "GSD_Revision=1\nIdent_Number=1\n", "e.gsd: #Profibus_DP section missing"},
      {"UnterminatedString", make({}, {"Vendor_Name = \"abc"}), "e.gsd:11: unterminated string"},
      {"UnterminatedStringAcrossContinuation", make({}, {"Vendor_Name = \"abc \\", "def"}),
       "e.gsd:11: unterminated string"},
      {"EndModuleWithoutModule", make({}, {"EndModule"}), "e.gsd:11: EndModule without Module"},
      {"ConfigByteOutOfRange", make({}, {"Module=\"x\" 0x10,0x1FF", "EndModule"}),
       "e.gsd:11: config byte 0x1FF out of range"},
      {"IdentNumberMissing", make({3}, {}), "e.gsd:1: Ident_Number missing"},
      {"MaxTsdrMissing", make({6}, {}), "e.gsd:5: MaxTsdr_12M missing although 12M_supp = 1"},
      {"MaxTsdr45Missing", make({}, {"45.45_supp = 1"}),
       "e.gsd:11: MaxTsdr_45.45 missing although 45.45_supp = 1"},
      {"ModuleWithoutConfigBytes", make({}, {"Module=\"x\"", "EndModule"}),
       "e.gsd:11: Module 'x': no config bytes"},
      {"UndefinedExtUserPrmData", make({}, {"User_Prm_Data_Len=4", "Ext_User_Prm_Data_Ref(3)=7"}),
       "e.gsd:12: Ext_User_Prm_Data_Ref(3) refers to undefined ExtUserPrmData 7"},
      {"UndefinedExtUserPrmDataInModule",
       make({}, {"Module=\"p\" 0x20", "Ext_Module_Prm_Data_Len=1", "Ext_User_Prm_Data_Ref(0)=9", "EndModule"}),
       "e.gsd:13: Ext_User_Prm_Data_Ref(0) refers to undefined ExtUserPrmData 9"},
      {"NotANumber", make({8}, {"Max_Diag_Data_Len = abc"}), "e.gsd:11: value 'abc' is not a number"},
      {"NumberTooLarge", make({}, {"Min_Slave_Intervall = 99999999999999999999999"}),
       "e.gsd:11: value '99999999999999999999999' out of range"},
      {"ValueOutOfRange", make({}, {"C1_Max_Data_Len = 241"}),
       "e.gsd:11: value 241 out of range for C1_Max_Data_Len (0..240)"},
      {"NotABoolean", make({}, {"Sync_Mode_supp = 2"}),
       "e.gsd:11: value 2 of Sync_Mode_supp is not a boolean (0 or 1)"},
      {"ValueMissing", make({}, {"Ident_Number ="}), "e.gsd:11: value missing"},
      {"ExpectedKeyword", make({}, {"= 5"}), "e.gsd:11: expected a keyword, found '= 5'"},
      {"ExpectedEquals", make({}, {"Vendor_Name \"x\""}), "e.gsd:11: expected '=' after 'Vendor_Name'"},
      {"MissingParenthesis", make({}, {"Unit_Diag_Bit(3 = \"x\""}),
       "e.gsd:11: missing ')' after 'Unit_Diag_Bit('"},
      {"IndexMissing", make({}, {"Unit_Diag_Bit = \"x\""}),
       "e.gsd:11: 'Unit_Diag_Bit' needs an index: Unit_Diag_Bit(n)"},
      {"JunkAfterString", make({}, {"Vendor_Name = \"x\" y"}), "e.gsd:11: unexpected 'y' after the string"},
      {"NotAString", make({}, {"Model_Name = 12"}), "e.gsd:11: expected a quoted string, found '12'"},
      {"EmptyListEntry", make({}, {"User_Prm_Data = 0x01,,0x02"}),
       "e.gsd:11: empty entry in a list of byte values"},
      {"ModuleWithoutEndModule", make({}, {"Module=\"open\" 0x10"}),
       "e.gsd:11: Module 'open' without EndModule"},
      {"ModuleInsideModule", make({}, {"Module=\"a\" 0x10", "Module=\"b\" 0x20", "EndModule"}),
       "e.gsd:11: Module 'a' without EndModule; 'Module' at line 12 cannot be inside it"},
      {"UnexpectedNumberInModule", make({}, {"Module=\"a\" 0x10", "1", "2", "EndModule"}),
       "e.gsd:13: unexpected number '2' in Module 'a'"},
      {"SpecialIdentifierCutShort", make({}, {"Module=\"s\" 0xC3,0x01", "EndModule"}),
       "e.gsd:11: Module 's': special identifier 0xC3 at position 0 needs 5 more bytes, only 1 follow"},
      {"DefaultNotAllowed", make({}, {"ExtUserPrmData = 5 \"r\"", "Unsigned8 7 0-3", "EndExtUserPrmData"}),
       "e.gsd:12: ExtUserPrmData 5 'r': default 7 not allowed by '0-3'"},
      {"DefaultNotInList", make({}, {"ExtUserPrmData = 5 \"r\"", "Unsigned8 3 1,2,4", "EndExtUserPrmData"}),
       "e.gsd:12: ExtUserPrmData 5 'r': default 3 not allowed by '1,2,4'"},
      {"AllowedValueOutsideType",
       make({}, {"ExtUserPrmData = 5 \"r\"", "Unsigned8 1 1,300", "EndExtUserPrmData"}),
       "e.gsd:12: ExtUserPrmData 5 'r': allowed value 300 outside Unsigned8 (0..255)"},
      {"RangeOutOfOrder", make({}, {"ExtUserPrmData = 5 \"r\"", "Signed8 0 10--10", "EndExtUserPrmData"}),
       "e.gsd:12: ExtUserPrmData 5 'r': range 10--10 out of order or outside Signed8 (-128..127)"},
      {"BitAreaOutOfByte", make({}, {"ExtUserPrmData = 5 \"r\"", "BitArea(5-9) 0 0-3", "EndExtUserPrmData"}),
       "e.gsd:12: ExtUserPrmData 5 'r': bit positions 5-9 outside 0..7 or out of order"},
      {"DataTypeLineMissing", make({}, {"ExtUserPrmData = 5 \"r\"", "Changeable = 1", "EndExtUserPrmData"}),
       "e.gsd:11: ExtUserPrmData 5 'r': data type line missing"},
      {"TwoDataTypeLines",
       make({}, {"ExtUserPrmData = 5 \"r\"", "Bit(0) 0 0-1", "Bit(1) 0 0-1", "EndExtUserPrmData"}),
       "e.gsd:13: ExtUserPrmData 5 'r': more than one data type line"},
      {"PrmTextRefUndefined",
       make({}, {"ExtUserPrmData = 5 \"r\"", "Bit(0) 0 0-1", "Prm_Text_Ref = 3", "EndExtUserPrmData"}),
       "e.gsd:11: ExtUserPrmData 5 'r': Prm_Text_Ref refers to undefined PrmText 3"},
      {"EndPrmTextWithoutPrmText", make({}, {"EndPrmText"}), "e.gsd:11: EndPrmText without PrmText"},
      {"PrmTextWithoutEnd", make({}, {"PrmText = 1", "Text(0) = \"a\""}), "e.gsd:11: PrmText 1 without EndPrmText"},
      {"ExtUserPrmDataWithoutEnd", make({}, {"ExtUserPrmData = 5 \"r\"", "Bit(0) 0 0-1"}),
       "e.gsd:11: ExtUserPrmData 5 'r' without EndExtUserPrmData"},
      {"DiagAreaWithoutEnd", make({}, {"Unit_Diag_Area = 16-17", "Value(0) = \"x\""}),
       "e.gsd:11: Unit_Diag_Area without Unit_Diag_Area_End"},
      {"SlotDefinitionWithoutEnd", make({}, {"SlotDefinition", "Slot(1) = \"s\" 1 1"}),
       "e.gsd:11: SlotDefinition without EndSlotDefinition"},
      {"MaxModuleMissing", make({}, {"Modular_Station = 1"}),
       "e.gsd:11: Max_Module missing although Modular_Station = 1"},
      {"NoModule", make({9, 10}, {}), "e.gsd:1: no Module defined"},
      {"NoBaudRate", make({5, 6}, {}), "e.gsd:1: no baud rate supported (no *_supp = 1)"},
      {"MaxDiagDataLenTooSmall", make({8}, {"Max_Diag_Data_Len = 5"}), "e.gsd:11: Max_Diag_Data_Len 5 below 6"},
      {"C2MaxDataLen", make({}, {"C2_Max_Data_Len = 20"}),
       "e.gsd:11: C2_Max_Data_Len 20 not allowed (0 or 48..240)"},
      {"MaxInitiatePduLength", make({}, {"Max_Initiate_PDU_Length = 51"}),
       "e.gsd:11: Max_Initiate_PDU_Length 51 not allowed (0 or 52..244)"},
      {"UserPrmDataLenTooLarge", make({}, {"User_Prm_Data_Len = 238"}),
       "e.gsd:11: value 238 out of range for User_Prm_Data_Len (0..237)"},
  };
}

class GsdError : public ::testing::TestWithParam<Case> {};

}  // namespace

TEST_P(GsdError, FirstErrorIsExact) {
  const Case& c = GetParam();
  GsdParseResult r = parse_gsd(c.text, "e.gsd");
  if (c.expected.empty()) {
    EXPECT_TRUE(r.ok());
    for (const auto& e : r.errors) ADD_FAILURE() << e.to_string();
    for (const auto& w : r.warnings) ADD_FAILURE() << w.to_string();
    return;
  }
  EXPECT_FALSE(r.ok());
  EXPECT_FALSE(r.file.has_value());
  ASSERT_FALSE(r.errors.empty());
  EXPECT_EQ(r.errors[0].to_string(), c.expected);
}

INSTANTIATE_TEST_SUITE_P(Classes, GsdError, ::testing::ValuesIn(cases()),
                         [](const ::testing::TestParamInfo<Case>& i) { return std::string(i.param.name); });

TEST(GsdWarnings, UnknownKeywordsAreKeptWithTheirLine) {
  std::string text = make({}, {"Some_Vendor_Thing = 0x42", "Module=\"w\" 0x20", "Funny_Module_Key = 1", "EndModule"});
  GsdParseResult r = parse_gsd(text, "w.gsd");
  ASSERT_TRUE(r.ok());
  ASSERT_EQ(r.warnings.size(), 2u);
  EXPECT_EQ(r.warnings[0].to_string(), "w.gsd:11: unknown keyword 'Some_Vendor_Thing' kept");
  EXPECT_EQ(r.warnings[1].to_string(), "w.gsd:13: unknown keyword 'Funny_Module_Key' in Module 'w' kept");
  ASSERT_EQ(r.file->unknown_keywords().size(), 1u);
  EXPECT_EQ(r.file->unknown_keywords()[0].value, "0x42");
  EXPECT_EQ(r.file->modules()[1].other_keywords.at(0).name, "Funny_Module_Key");
}

TEST(GsdWarnings, KeywordGivenTwice) {
  GsdParseResult r = parse_gsd(make({}, {"Ident_Number = 0x4321"}), "w.gsd");
  ASSERT_TRUE(r.ok());
  ASSERT_EQ(r.warnings.size(), 1u);
  EXPECT_EQ(r.warnings[0].to_string(), "w.gsd:11: 'Ident_Number' given twice (first at line 3); the later value wins");
  EXPECT_EQ(r.file->ident_number(), 0x4321);
}

TEST(GsdWarnings, MissingRecommendedKeywords) {
  GsdParseResult r = parse_gsd(make({4, 7, 8}, {}), "w.gsd");
  ASSERT_TRUE(r.ok());
  ASSERT_EQ(r.warnings.size(), 3u);
  EXPECT_EQ(r.warnings[0].to_string(), "w.gsd:1: Station_Type missing; DP slave (0) assumed");
  EXPECT_EQ(r.warnings[1].to_string(), "w.gsd:1: Min_Slave_Intervall missing");
  EXPECT_EQ(r.warnings[2].to_string(), "w.gsd:1: Max_Diag_Data_Len missing; 6 assumed");
}

TEST(GsdSyntax, CommentsContinuationsCaseAndLineEndings) {
  // CR-only and CRLF line ends, a semicolon in a string, a continued byte list.
  const std::string text =
      "; header\r#PROFIBUS_DP   ; section\r\n"
      "ident_number = 4660\r\n"
      "STATION_TYPE=0\r\n"
      "12m_SUPP = 0x01\r\n"
      "maxtsdr_12m = 800\r\n"
      "Min_Slave_Intervall=1\r\nMax_Diag_Data_Len=6\r\n"
      "Vendor_Name = \"a;b\" ; c\r\n"
      "User_Prm_Data_Len = 3\r\n"
      "User_Prm_Data = 0x01, \\\r\n"
      "   2, \\\r\n"
      "   0x03\r\n"
      "module = \"m\" 0x10 ; comment\r\n"
      "endmodule\r\n";
  GsdParseResult r = parse_gsd(text, "s.gsd");
  ASSERT_TRUE(r.ok()) << r.errors[0].to_string();
  EXPECT_EQ(r.file->ident_number(), 0x1234);
  EXPECT_EQ(r.file->info().vendor_name, "a;b");
  EXPECT_EQ(r.file->global_prm().initial, (GsdBytes{1, 2, 3}));
  EXPECT_EQ(r.file->modules().at(0).line, 14u);
  EXPECT_EQ(r.file->keyword("user_prm_data")->line, 11u);
}

TEST(GsdWarnings, UnknownKeywordsInsideBlocksAreKept) {
  std::string text = make({}, {"PrmText = 1", "Text(0) = \"a\"", "Odd = 1", "EndPrmText", "ExtUserPrmData = 2 \"p\"",
                               "Bit(0) 0 0-1", "Help = \"x\"", "EndExtUserPrmData"});
  GsdParseResult r = parse_gsd(text, "w.gsd");
  ASSERT_TRUE(r.ok());
  ASSERT_EQ(r.warnings.size(), 2u);
  EXPECT_EQ(r.warnings[0].to_string(), "w.gsd:13: unknown keyword 'Odd' in PrmText 1 kept");
  EXPECT_EQ(r.warnings[1].to_string(), "w.gsd:17: unknown keyword 'Help' in ExtUserPrmData 2 'p' kept");
  ASSERT_EQ(r.file->unknown_keywords().size(), 2u);
  EXPECT_EQ(r.file->unknown_keywords()[1].value, "\"x\"");
}
