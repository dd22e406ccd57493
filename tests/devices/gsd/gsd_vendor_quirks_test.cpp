// GSD files as vendors write them (tests/data/gsd/vendor-quirks): values outside PI 2.122 that
// are clamped, common misspellings, PROFIsafe modules, revision-5 diagnosis blocks (UnitDiagType
// with X_ keywords) and X_ blocks the reader does not know. Each test asserts the exact warnings, the
// values the model keeps and, where bytes are assembled, bytes worked out by hand.
// Parser robustness (duplicates, unterminated blocks) is in gsd_quirks_parser_test.cpp.

#include <gtest/gtest.h>

#include <cstdint>
#include <map>
#include <optional>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "pbvbus/gsd/gsd.hpp"
#include "pbvbus/slaves/slave_model.hpp"

using namespace pbvbus::devices;

namespace {

std::string src(const std::string& rel) { return std::string(PBVBUS_SOURCE_DIR) + "/" + rel; }

std::vector<std::string> texts(const std::vector<GsdMessage>& messages) {
  std::vector<std::string> out;
  for (const auto& m : messages) out.push_back(m.to_string());
  return out;
}

}  // namespace

// --- (b) Max_Input_Len / Max_Output_Len 249, Max_Data_Len 498 ------------------------------------

TEST(GsdVendorQuirks, DataLengthsAboveTheDpLimitsAreClamped) {
  const std::string path = src("tests/data/gsd/vendor-quirks/max-len-249.gsd");
  const GsdParseResult r = load_gsd(path);
  ASSERT_TRUE(r.ok()) << (r.errors.empty() ? "" : r.errors[0].to_string());
  EXPECT_EQ(texts(r.warnings),
            (std::vector<std::string>{path + ":23: Max_Input_Len 249 above the DP limit 244; clamped to 244",
                                      path + ":24: Max_Output_Len 249 above the DP limit 244; clamped to 244",
                                      path + ":25: Max_Data_Len 498 above the DP limit 488; clamped to 488"}));
  const GsdFile& f = *r.file;
  EXPECT_EQ(f.slave_features().max_input_len, 244);
  EXPECT_EQ(f.slave_features().max_output_len, 244);
  EXPECT_EQ(f.slave_features().max_data_len, 488);

  // 0x40,0x7F = 64 words = 128 bytes in; 0x40,0x79 = 58 words = 116 bytes in: 244 exactly.
  auto full = f.check_modules({2, 4});
  ASSERT_TRUE(full.ok()) << full.errors[0];
  EXPECT_EQ(full.value->first, 244u);
  // One more input byte (0x10) is beyond the clamped limit, not the file's 249.
  auto over = f.check_modules({2, 4, 0});
  ASSERT_EQ(over.errors.size(), 1u);
  EXPECT_EQ(over.errors[0], "inputs of 245 bytes exceed Max_Input_Len 244");
  // 244 in + 128 out = 372 <= 488.
  EXPECT_TRUE(f.check_modules({2, 4, 3}).ok());
}

TEST(GsdVendorQuirks, DataLengthsWithinTheLimitsAndBeyondSixteenBits) {
  const std::string head =
      "#Profibus_DP\nIdent_Number=0x1234\nStation_Type=0\n12M_supp=1\nMaxTsdr_12M=800\n"
      "Min_Slave_Intervall=1\nMax_Diag_Data_Len=6\nModule=\"m\" 0x10\nEndModule\n";
  GsdParseResult r = parse_gsd(head + "Max_Input_Len=244\nMax_Output_Len=0\nMax_Data_Len=488\n", "l.gsd");
  ASSERT_TRUE(r.ok());
  EXPECT_TRUE(r.warnings.empty());
  EXPECT_EQ(r.file->slave_features().max_output_len, 0);
  // Not a quirk but garbage: still an error.
  r = parse_gsd(head + "Max_Data_Len=70000\n", "l.gsd");
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.errors[0].to_string(), "l.gsd:10: value 70000 out of range for Max_Data_Len (0..65535)");
}

// --- (c) Min_Slave_Interval (one l) ---------------------------------------------------------------

TEST(GsdVendorQuirks, MinSlaveIntervalWithOneL) {
  const std::string path = src("tests/data/gsd/vendor-quirks/min-slave-interval.gsd");
  const GsdParseResult r = load_gsd(path);
  ASSERT_TRUE(r.ok()) << (r.errors.empty() ? "" : r.errors[0].to_string());
  // One warning only: no "Min_Slave_Intervall missing" after it.
  EXPECT_EQ(texts(r.warnings),
            (std::vector<std::string>{
                path + ":21: 'Min_Slave_Interval' read as 'Min_Slave_Intervall' (common misspelling)"}));
  EXPECT_EQ(r.file->slave_features().min_slave_intervall, 6);  // x 100 us = 600 us
  EXPECT_TRUE(r.file->unknown_keywords().empty());
  // The master polls it no faster than that (it was 0, raised to 1, before).
  auto p = master_slave_params(*r.file, {ModuleChoice::at(0)}, 5);
  ASSERT_TRUE(p.ok());
  EXPECT_EQ(p.value->min_slave_interval, 6);
}

TEST(GsdVendorQuirks, MisspellingsCountAsTheKeywordTheyMean) {
  const std::string head =
      "#Profibus_DP\nIdent_Number=0x1234\nStation_Type=0\n12M_supp=1\nMaxTsdr_12M=800\n"
      "Max_Diag_Data_Len=6\nModule=\"m\" 0x10\nEndModule\n";
  // Both spellings: the second is a repetition of the first, the later value wins.
  GsdParseResult r = parse_gsd(head + "Min_Slave_Intervall=2\nMIN_SLAVE_INTERVAL=3\nWB_Base_1ms_supp=1\n", "s.gsd");
  ASSERT_TRUE(r.ok());
  EXPECT_EQ(texts(r.warnings),
            (std::vector<std::string>{
                "s.gsd:10: 'MIN_SLAVE_INTERVAL' read as 'Min_Slave_Intervall' (common misspelling)",
                "s.gsd:10: 'MIN_SLAVE_INTERVAL' given twice (first at line 9); the later value wins",
                "s.gsd:11: 'WB_Base_1ms_supp' read as 'WD_Base_1ms_supp' (common misspelling)"}));
  EXPECT_EQ(r.file->slave_features().min_slave_intervall, 3);
  EXPECT_TRUE(r.file->dpv1().wd_base_1ms_supp);
  // A misspelt keyword is still checked like the right one.
  r = parse_gsd(head + "Min_Slave_Interval=70000\n", "s.gsd");
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.errors[0].to_string(), "s.gsd:9: value 70000 out of range for Min_Slave_Intervall (0..65535)");
}

// --- (e) PROFIsafe modules: F-parameters in User_Prm_Data -----------------------------------------

namespace {

GsdFile load_profisafe() {
  const GsdParseResult r = load_gsd(src("tests/data/gsd/vendor-quirks/profisafe-module.gsd"));
  for (const auto& e : r.errors) ADD_FAILURE() << e.to_string();
  for (const auto& w : r.warnings) ADD_FAILURE() << w.to_string();
  if (!r.ok()) throw std::runtime_error("profisafe-module.gsd does not parse");
  return *r.file;
}

// F block of the F-DI module with every F-parameter at its default (octet: value):
//   0 F_Prm_Flag1: Const 0x00; F_Check_SeqNr Bit(0) = 0, F_Check_iPar Bit(1) = 0,
//     F_SIL BitArea(2-3) = 2 (SIL3) -> 0x08, F_CRC_Length BitArea(4-5) = 0         -> 0x08
//   1 F_Prm_Flag2: Const 0x00; F_Block_ID BitArea(3-5) = 0, F_Par_Version BitArea(6-7) = 1 -> 0x40
//   2-3 F_Source_Add Unsigned16 1                                                  -> 00 01
//   4-5 F_Dest_Add Unsigned16 100                                                  -> 00 64
//   6-7 F_WD_Time Unsigned16 150                                                   -> 00 96
//   8-9 F_Par_CRC Unsigned16 0x4A2B (as the file gives it)                         -> 4A 2B
// (Were F_Ext_User_Prm_Data_Ref(0) = 2 resolved to ExtUserPrmData 2 "Sensor supply", Bit(0)
// default 1, octet 0 would be 0x09.)
const GsdBytes kFBlock = {0x08, 0x40, 0x00, 0x01, 0x00, 0x64, 0x00, 0x96, 0x4A, 0x2B};

}  // namespace

TEST(GsdVendorQuirks, ProfisafeModuleModel) {
  const GsdFile f = load_profisafe();
  ASSERT_EQ(f.modules().size(), 2u);
  EXPECT_FALSE(f.modules()[0].f.present());
  const GsdModule& m = f.modules()[1];
  ASSERT_TRUE(m.f.present());
  EXPECT_EQ(m.f.prm.declared_len, 10u);
  EXPECT_EQ(m.f.prm.consts.size(), 1u);
  EXPECT_EQ(m.f.prm.refs.size(), 10u);
  EXPECT_EQ(m.f.param_desc_crc, 0x1D6E);
  EXPECT_EQ(m.f.io_structure_desc_crc, 0x0000A3F1u);
  EXPECT_TRUE(m.other_keywords.empty());
  // 0xC1: output and input length octets, one manufacturer octet; 0x85 = 6 octets, consistent
  // (2 octets of F-data + the 4-octet PROFIsafe status/control byte and CRC).
  EXPECT_EQ(m.input_len, 6u);
  EXPECT_EQ(m.output_len, 6u);
  // F_ExtUserPrmData and ExtUserPrmData number separately.
  ASSERT_EQ(f.f_ext_user_prm_data().size(), 10u);
  EXPECT_EQ(f.f_ext_user_prm_data().at(2).name, "F_Check_iPar");
  EXPECT_EQ(f.ext_user_prm_data().at(2).name, "Sensor supply");
  EXPECT_EQ(f.f_prm_defs().at(2).name, "F_Check_iPar");
  EXPECT_FALSE(f.f_ext_user_prm_data().at(6).changeable);

  EXPECT_EQ(f.f_prm_defaults(m), kFBlock);
  // Module part: Ext_Module_Prm_Data_Len 2, then F_Ext_Module_Prm_Data_Len 10.
  EXPECT_EQ(f.module_prm_length(m), 12u);
}

TEST(GsdVendorQuirks, ProfisafeUserPrmDataAssembly) {
  const GsdFile f = load_profisafe();
  // 80 00 00      station area: DPV1_Status_1..3 (Ext_User_Prm_Data_Const(0))
  // 01            8DI: Input delay BitArea(0-1) default 1
  // 01 0A         F-DI: Sensor supply Bit(0) = 1, Discrepancy time Unsigned8 10
  // 08 40 .. 2B   F-DI: F-parameter block (kFBlock above)
  GsdBytes expected = {0x80, 0x00, 0x00, 0x01, 0x01, 0x0A};
  expected.insert(expected.end(), kFBlock.begin(), kFBlock.end());
  auto prm = f.user_prm_data({0, 1});
  ASSERT_TRUE(prm.ok()) << prm.errors[0];
  EXPECT_EQ(*prm.value, expected);
  EXPECT_TRUE(prm.notes.empty());
  ASSERT_TRUE(f.check_modules({0, 1}).ok());
  // Slot order decides the order of the parts: F-DI first.
  prm = f.user_prm_data({1, 0});
  ASSERT_TRUE(prm.ok());
  EXPECT_EQ(prm.value->size(), 3u + 12u + 1u);
  EXPECT_EQ((*prm.value)[15], 0x01);  // the 8DI byte now comes last
}

TEST(GsdVendorQuirks, ProfisafeParameterSettings) {
  const GsdFile f = load_profisafe();
  // F-DI in slot 1: F_Dest_Add (F ref 8) = 200 -> octets 4-5 of the F block 00 C8; F_SIL (F ref 3)
  // = 1 (SIL2) -> octet 0 bits 2-3 = 01 -> 0x04. Ordinary ref 2 (Sensor supply) = 0 in the same
  // slot addresses the module's own area: 01 0A -> 00 0A.
  auto prm = f.user_prm_data({0, 1}, {{1, 8, 200, std::nullopt, true},
                                      {1, 3, 1, std::nullopt, true},
                                      {1, 2, 0, std::nullopt, false}});
  ASSERT_TRUE(prm.ok()) << prm.errors[0];
  EXPECT_EQ(*prm.value, (GsdBytes{0x80, 0x00, 0x00, 0x01, 0x00, 0x0A,
                                  0x04, 0x40, 0x00, 0x01, 0x00, 0xC8, 0x00, 0x96, 0x4A, 0x2B}));

  auto bad = f.user_prm_data({0, 1}, {{1, 2, 1, std::nullopt, true},
                                      {0, 8, 200, std::nullopt, true},
                                      {1, 8, 0, std::nullopt, true},
                                      {std::nullopt, 8, 200, std::nullopt, true},
                                      {1, 99, 1, std::nullopt, true}});
  EXPECT_EQ(bad.errors,
            (std::vector<std::string>{"F_ExtUserPrmData 2 'F_Check_iPar' is not changeable",
                                      "F_ExtUserPrmData 8 'F_Dest_Add' is not used in the F-parameters of slot 0",
                                      "F_ExtUserPrmData 8 'F_Dest_Add': value 0 not allowed",
                                      "F-parameter setting without a slot: F-parameters belong to a module",
                                      "setting for the F-parameters of slot 1: no F_ExtUserPrmData 99"}));
}

TEST(GsdVendorQuirks, ProfisafeFallbacksAndChecks) {
  const std::string head =
      "#Profibus_DP\nIdent_Number=0x1234\nStation_Type=0\n12M_supp=1\nMaxTsdr_12M=800\n"
      "Min_Slave_Intervall=1\nMax_Diag_Data_Len=6\nModular_Station=1\nMax_Module=2\n"  // 1..9
      "ExtUserPrmData = 7 \"F_WD_Time\"\nUnsigned16 200 1-65535\nEndExtUserPrmData\n";  // 10..12
  // F_Ext_User_Prm_Data_Ref to a number with no F_ExtUserPrmData: the ExtUserPrmData of that
  // number. No F_Ext_Module_Prm_Data_Len: the block is as long as its overlays (warning).
  GsdParseResult r = parse_gsd(head +
                                   "Module = \"F\" 0x10\n"                          // 13
                                   "F_Ext_User_Prm_Data_Const(0) = 0x11,0x22\n"     // 14
                                   "F_Ext_User_Prm_Data_Ref(2) = 7\n"               // 15
                                   "EndModule\n",                                   // 16
                               "p.gsd");
  ASSERT_TRUE(r.ok()) << r.errors[0].to_string();
  EXPECT_EQ(texts(r.warnings),
            (std::vector<std::string>{"p.gsd:13: Module 'F': F-parameters without F_Ext_Module_Prm_Data_Len; "
                                      "F block of 4 bytes, as far as they reach"}));
  // 11 22, then Unsigned16 200 = 00 C8 at octet 2.
  EXPECT_EQ(r.file->f_prm_defaults(r.file->modules()[0]), (GsdBytes{0x11, 0x22, 0x00, 0xC8}));

  // Overlays beyond F_Ext_Module_Prm_Data_Len extend the block, with a warning.
  r = parse_gsd(head + "Module = \"F\" 0x10\nF_Ext_Module_Prm_Data_Len = 2\nF_Ext_User_Prm_Data_Ref(1) = 7\n"
                       "EndModule\n",
                "p.gsd");
  ASSERT_TRUE(r.ok());
  EXPECT_EQ(texts(r.warnings),
            (std::vector<std::string>{"p.gsd:13: Module 'F': F-parameters reach byte 3, beyond "
                                      "F_Ext_Module_Prm_Data_Len 2; F block extended"}));
  EXPECT_EQ(r.file->f_prm_defaults(r.file->modules()[0]), (GsdBytes{0x00, 0x00, 0xC8}));

  // A reference to neither kind of definition is an error, like for Ext_User_Prm_Data_Ref.
  r = parse_gsd(head + "Module = \"F\" 0x10\nF_Ext_Module_Prm_Data_Len = 2\nF_Ext_User_Prm_Data_Ref(0) = 9\n"
                       "EndModule\n",
                "p.gsd");
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.errors[0].to_string(), "p.gsd:15: F_Ext_User_Prm_Data_Ref(0) refers to undefined F_ExtUserPrmData 9");
  // An F_ExtUserPrmData block without its end keyword.
  r = parse_gsd(head + "F_ExtUserPrmData = 1 \"F_SIL\"\nBitArea(2-3) 2 0-3\nModule = \"F\" 0x10\nEndModule\n",
                "p.gsd");
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(texts(r.errors),
            (std::vector<std::string>{"p.gsd:13: F_ExtUserPrmData 1 'F_SIL' without EndF_ExtUserPrmData; "
                                      "'Module' at line 15 cannot be inside it"}));
}

// --- (f) Revision 5: UnitDiagType with X_ diagnosis keywords; unknown X_ blocks -----------------

TEST(GsdVendorQuirks, UnitDiagTypeWithXKeywordsIsReadIntoTheModel) {
  const std::string path = src("tests/data/gsd/vendor-quirks/profisafe-unit-diag-type.gsd");
  const GsdParseResult r = load_gsd(path);
  // The regression: "UnitDiagType without EndUnitDiagType; 'X_Unit_Diag_Area' at line 51 cannot be
  // inside it" and "EndUnitDiagType without its block start" at line 65.
  ASSERT_TRUE(r.ok()) << texts(r.errors).front();
  EXPECT_TRUE(r.warnings.empty()) << texts(r.warnings).front();
  const GsdFile& f = *r.file;

  // DP-V0 texts outside the block: Unit_Diag_Bit as before, the X_ ones typed beside it.
  EXPECT_EQ(f.unit_diag_bits(), (std::map<std::uint32_t, std::string>{{24, "Supply voltage missing"}}));
  EXPECT_EQ(f.x_unit_diag().bits, (std::map<std::uint32_t, std::string>{{25, "Internal fault"}}));
  EXPECT_EQ(f.x_unit_diag().bit_help, (std::map<std::uint32_t, std::string>{{25, "Replace the module"}}));
  EXPECT_TRUE(f.x_unit_diag().not_bits.empty());
  // The area inside the UnitDiagType belongs to it, not to the top-level areas.
  EXPECT_TRUE(f.unit_diag_areas().empty());

  ASSERT_EQ(f.unit_diag_types().size(), 1u);
  const GsdUnitDiagType& t = f.unit_diag_types()[0];
  EXPECT_EQ(t.type, std::optional<std::uint8_t>{0x81});  // 129: DP-V1 status message
  EXPECT_EQ(t.line, 50u);
  ASSERT_EQ(t.areas.size(), 1u);
  const GsdUnitDiagArea& a = t.areas[0];
  EXPECT_TRUE(a.x_variant);
  EXPECT_EQ(a.first_bit, 24);
  EXPECT_EQ(a.last_bit, 31);
  EXPECT_EQ(a.line, 51u);
  ASSERT_EQ(a.values.size(), 8u);  // the PROFIsafe F-parameter fault codes 64..71, in file order
  for (std::size_t i = 0; i < a.values.size(); ++i) EXPECT_EQ(a.values[i].first, 64 + static_cast<int>(i));
  EXPECT_EQ(a.values[0].second, "Mismatch of F_Dest_Add");
  EXPECT_EQ(a.values[7].second, "CRC1 fault");
  ASSERT_EQ(a.value_help.size(), 1u);
  EXPECT_EQ(a.value_help[0], (std::pair<std::int64_t, std::string>{64, "Set F_Dest_Add to the address on the DIL switch"}));
  EXPECT_EQ(t.texts.bits, (std::map<std::uint32_t, std::string>{{32, "Discrepancy error channel 0"}}));
  EXPECT_EQ(t.texts.bit_help, (std::map<std::uint32_t, std::string>{{32, "Sensors of channel 0 disagree"}}));
  EXPECT_EQ(t.texts.not_bits, (std::map<std::uint32_t, std::string>{{33, "Sensor supply off"}}));

  // The rest of the file is read as before: the PROFIsafe module and its F block.
  ASSERT_EQ(f.modules().size(), 1u);
  ASSERT_TRUE(f.modules()[0].f.present());
  // Const 00 40 00 01 00 00 00 00 12 34; F_SIL BitArea(2-3) = 2 -> octet 0 = 0x08;
  // F_Dest_Add 200 at 4-5 -> 00 C8; F_WD_Time 100 at 6-7 -> 00 64.
  EXPECT_EQ(f.f_prm_defaults(f.modules()[0]), (GsdBytes{0x08, 0x40, 0x00, 0x01, 0x00, 0xC8, 0x00, 0x64, 0x12, 0x34}));
}

namespace {

// 9 lines, so that the first extra line is line 10.
const std::string kHead =
    "#Profibus_DP\nIdent_Number=0x1234\nStation_Type=0\n12M_supp=1\nMaxTsdr_12M=800\n"
    "Min_Slave_Intervall=1\nMax_Diag_Data_Len=6\nModule=\"m\" 0x10\nEndModule\n";

GsdParseResult parse_lines(const std::vector<std::string>& lines) {
  std::string text = kHead;
  for (const auto& l : lines) text += l + "\n";
  return parse_gsd(text, "x.gsd");
}

}  // namespace

TEST(GsdVendorQuirks, UnitDiagTypeMixedSpellingsAndStructureErrors) {
  // Plain spellings inside the block count as its texts; either area end keyword closes the area.
  GsdParseResult r = parse_lines({"UnitDiagType = 130", "Unit_Diag_Bit(8) = \"a\"", "Unit_Diag_Area = 16-23",
                                  "Value(1) = \"one\"", "X_Unit_Diag_Area_End", "EndUnitDiagType"});
  ASSERT_TRUE(r.ok()) << texts(r.errors).front();
  EXPECT_TRUE(r.warnings.empty());
  ASSERT_EQ(r.file->unit_diag_types().size(), 1u);
  EXPECT_EQ(r.file->unit_diag_types()[0].texts.bits.at(8), "a");
  EXPECT_FALSE(r.file->unit_diag_types()[0].areas.at(0).x_variant);
  EXPECT_EQ(r.file->unit_diag_types()[0].areas.at(0).values.at(0).second, "one");
  EXPECT_TRUE(r.file->unit_diag_bits().empty());

  // An area inside the type without its end: one error at the area, the type still closes.
  r = parse_lines({"UnitDiagType = 129", "X_Unit_Diag_Area = 24-31", "X_Value(64) = \"x\"", "EndUnitDiagType",
                   "Max_User_Prm_Data_Len = 4"});
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(texts(r.errors), (std::vector<std::string>{"x.gsd:11: X_Unit_Diag_Area without X_Unit_Diag_Area_End; "
                                                       "'EndUnitDiagType' at line 13 ends another kind of block"}));

  // A value that is no type octet warns; the block's texts are kept without a type.
  r = parse_lines({"UnitDiagType = 0x181", "X_Unit_Diag_Bit(3) = \"b\"", "EndUnitDiagType"});
  ASSERT_TRUE(r.ok()) << texts(r.errors).front();
  EXPECT_EQ(texts(r.warnings), (std::vector<std::string>{"x.gsd:10: UnitDiagType value '0x181' is not a type octet "
                                                         "(0..255); its texts are kept without a type"}));
  EXPECT_FALSE(r.file->unit_diag_types().at(0).type.has_value());
  EXPECT_EQ(r.file->unit_diag_types().at(0).texts.bits.at(3), "b");
}

TEST(GsdVendorQuirks, UnknownXBlocksAreWarningsNotStructureErrors) {
  // At the top level and inside a UnitDiagType: one warning each, the content is not read (the
  // Module-looking and garbage lines inside would otherwise be errors), the file is usable.
  GsdParseResult r = parse_lines({"X_Vendor_Diag_Block = 3",     // 10
                                  "Text_Ref(1) = \"x\"",           // 11
                                  "X_Vendor_Diag_Block_End",       // 12
                                  "UnitDiagType = 129",            // 13
                                  "X_Unit_Diag_Type_Ext = 1",      // 14
                                  "X_Value(2) = 5",                // 15: would be an error if read
                                  "X_UNIT_DIAG_TYPE_EXT_END",      // 16
                                  "X_Unit_Diag_Bit(1) = \"kept\"", // 17
                                  "EndUnitDiagType"});             // 18
  ASSERT_TRUE(r.ok()) << texts(r.errors).front();
  EXPECT_EQ(texts(r.warnings),
            (std::vector<std::string>{
                "x.gsd:10: unknown block 'X_Vendor_Diag_Block' ... 'X_Vendor_Diag_Block_End' (line 12) kept, not "
                "interpreted",
                "x.gsd:14: unknown block 'X_Unit_Diag_Type_Ext' ... 'X_UNIT_DIAG_TYPE_EXT_END' (line 16) kept, not "
                "interpreted"}));
  ASSERT_EQ(r.file->unknown_keywords().size(), 2u);
  EXPECT_EQ(r.file->unknown_keywords()[0].name, "X_Vendor_Diag_Block");
  EXPECT_EQ(r.file->unknown_keywords()[0].value, "3");
  EXPECT_EQ(r.file->unit_diag_types().at(0).texts.bits.at(1), "kept");

  // No matching end before the next block boundary: not a block, each line an unknown keyword,
  // and the Module in between is read.
  r = parse_lines({"X_Vendor_Thing = 1", "Module = \"n\" 0x20", "EndModule", "X_Vendor_Thing_End"});
  ASSERT_TRUE(r.ok()) << texts(r.errors).front();
  EXPECT_EQ(texts(r.warnings), (std::vector<std::string>{"x.gsd:10: unknown keyword 'X_Vendor_Thing' kept",
                                                         "x.gsd:13: unknown keyword 'X_Vendor_Thing_End' kept"}));
  EXPECT_EQ(r.file->modules().size(), 2u);
  // Known X_ keywords are never taken for unknown blocks.
  r = parse_lines({"X_Unit_Diag_Bit(4) = \"d\"", "X_Unit_Diag_Bit_End"});
  ASSERT_TRUE(r.ok());
  EXPECT_EQ(r.file->x_unit_diag().bits.at(4), "d");
  EXPECT_EQ(texts(r.warnings), (std::vector<std::string>{"x.gsd:11: unknown keyword 'X_Unit_Diag_Bit_End' kept"}));
}
