// GSD files as vendors write them (tests/data/gsd/vendor-quirks): values outside PI 2.122 that
// are clamped, common misspellings, PROFIsafe modules. Each test asserts the exact warnings, the
// values the model keeps and, where bytes are assembled, bytes worked out by hand.
// Parser robustness (duplicates, unterminated blocks) is in gsd_quirks_parser_test.cpp.

#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "pbvbus/devices/gsd.hpp"
#include "pbvbus/devices/slave_model.hpp"

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
