// GSD slave-redundancy keywords (protocol-facts.md §G.7; PI 2.212): PrmCmd_supp,
// Slave_Redundancy_supp (bit 0 System, bit 1 Flying Redundancy: pbvbus's reading, gsd.hpp) and
// Slave_Max_Switch_Over_Time (unit 10 ms: pbvbus's reading). The shipped switched-station files
// PBVB0A10 (fast interface) and PBVB0A11 (slow interface); values, absence, range and type
// errors with file:line, and the consistency warnings. Expected values written from the files.

#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "pbvbus/gsd/gsd.hpp"

using namespace pbvbus::devices;
using pbvbus::bus::Baud;

namespace {

std::string src(const std::string& rel) { return std::string(PBVBUS_SOURCE_DIR) + "/" + rel; }

// A minimal valid DP-V1 slave; lines 1..12, the keyword under test goes to line 13 on.
std::string base(const std::vector<std::string>& extra) {
  std::string s =
      "#Profibus_DP\n"            // 1
      "GSD_Revision=5\n"          // 2
      "Ident_Number=0x1234\n"     // 3
      "Station_Type=0\n"          // 4
      "12M_supp=1\n"              // 5
      "MaxTsdr_12M=800\n"         // 6
      "Min_Slave_Intervall=1\n"   // 7
      "Max_Diag_Data_Len=32\n"    // 8
      "DPV1_Slave=1\n"            // 9
      "Prm_Block_Structure_supp=1\n"  // 10
      "Ext_User_Prm_Data_Const(0)=0x80,0x00,0x00\n"  // 11
      "Module=\"m\" 0x10\nEndModule\n";  // 12, 13
  for (const auto& l : extra) s += l + "\n";  // from line 14
  return s;
}

std::vector<std::string> texts(const std::vector<GsdMessage>& ms) {
  std::vector<std::string> out;
  for (const auto& m : ms) out.push_back(m.to_string());
  return out;
}

}  // namespace

TEST(GsdRedundancy, MissingKeywordsMeanNotSupported) {
  GsdParseResult r = parse_gsd(base({}), "r.gsd");
  ASSERT_TRUE(r.ok());
  EXPECT_TRUE(r.warnings.empty()) << texts(r.warnings).front();
  const GsdRedundancy& red = r.file->redundancy();
  EXPECT_FALSE(red.redundancy);
  EXPECT_FALSE(red.prm_cmd_supp);
  EXPECT_EQ(red.slave_redundancy_supp, 0);
  EXPECT_FALSE(red.system_redundancy());
  EXPECT_FALSE(red.flying_redundancy());
  EXPECT_FALSE(red.slave_redundancy());
  EXPECT_EQ(red.slave_max_switch_over_time, 0);
  EXPECT_FALSE(red.switch_over_time_ms().has_value());
  EXPECT_EQ(red.switch_over_time(), 0);
  EXPECT_EQ(red, GsdRedundancy{});
}

TEST(GsdRedundancy, ValuesAndUnits) {
  GsdParseResult r = parse_gsd(
      base({"PrmCmd_supp = 1", "Slave_Redundancy_supp = 0x02", "Slave_Max_Switch_Over_Time = 65535"}), "r.gsd");
  ASSERT_TRUE(r.ok());
  EXPECT_TRUE(r.warnings.empty()) << texts(r.warnings).front();
  const GsdRedundancy& red = r.file->redundancy();
  EXPECT_TRUE(red.prm_cmd_supp);
  EXPECT_FALSE(red.system_redundancy());
  EXPECT_TRUE(red.flying_redundancy());
  EXPECT_TRUE(red.slave_redundancy());
  EXPECT_EQ(red.slave_max_switch_over_time, 65535);
  EXPECT_EQ(red.switch_over_time_ms(), 655350u);  // 65535 x 10 ms
  EXPECT_EQ(red.switch_over_time(), pbvbus::bus::Ticks{655350} * pbvbus::bus::kTicksPerMs);
  EXPECT_EQ(r.file->keyword("Slave_Max_Switch_Over_Time")->line, 16u);
}

TEST(GsdRedundancy, RangeAndTypeErrorsCarryFileAndLine) {
  struct Case {
    std::string line;
    std::string error;
  };
  const std::vector<Case> cases = {
      {"PrmCmd_supp = 2", "r.gsd:14: value 2 of PrmCmd_supp is not a boolean (0 or 1)"},
      {"PrmCmd_supp = yes", "r.gsd:14: value 'yes' is not a number"},
      {"Slave_Redundancy_supp = 256", "r.gsd:14: value 256 out of range for Slave_Redundancy_supp (0..255)"},
      {"Slave_Redundancy_supp = -1", "r.gsd:14: value -1 out of range for Slave_Redundancy_supp (0..255)"},
      {"Slave_Redundancy_supp = \"SR\"", "r.gsd:14: value '\"SR\"' is not a number"},
      {"Slave_Max_Switch_Over_Time = 65536",
       "r.gsd:14: value 65536 out of range for Slave_Max_Switch_Over_Time (0..65535)"},
      {"Slave_Max_Switch_Over_Time = 30ms", "r.gsd:14: value '30ms' is not a number"},
      {"Slave_Max_Switch_Over_Time =", "r.gsd:14: value missing"},
  };
  for (const auto& c : cases) {
    GsdParseResult r = parse_gsd(base({c.line}), "r.gsd");
    EXPECT_FALSE(r.ok()) << c.line;
    ASSERT_FALSE(r.errors.empty()) << c.line;
    EXPECT_EQ(r.errors[0].to_string(), c.error) << c.line;
  }
}

TEST(GsdRedundancy, ContradictionsWarn) {
  // Reserved bits are kept, with a warning.
  GsdParseResult r = parse_gsd(base({"PrmCmd_supp = 1", "Slave_Redundancy_supp = 0x81"}), "w.gsd");
  ASSERT_TRUE(r.ok());
  EXPECT_EQ(texts(r.warnings),
            std::vector<std::string>{"w.gsd:15: Slave_Redundancy_supp 0x81 sets reserved bits (bit 0 = System "
                                     "Redundancy, bit 1 = Flying Redundancy); kept"});
  EXPECT_EQ(r.file->redundancy().slave_redundancy_supp, 0x81);
  EXPECT_EQ(r.file->redundancy().reserved_redundancy_bits(), 0x80);
  EXPECT_TRUE(r.file->redundancy().system_redundancy());

  // Slave redundancy, but no PrmCmd to choose the primary.
  r = parse_gsd(base({"Slave_Redundancy_supp = 1"}), "w.gsd");
  ASSERT_TRUE(r.ok());
  EXPECT_EQ(texts(r.warnings),
            std::vector<std::string>{
                "w.gsd:14: Slave_Redundancy_supp without PrmCmd_supp = 1: a master cannot choose the primary"});

  // PrmCmd without the structured Set_Prm, and without DP-V1 at all (lines 9 and 10 commented
  // out keep the numbering).
  std::string no_struct = base({"PrmCmd_supp = 1"});
  no_struct.replace(no_struct.find("Prm_Block_Structure_supp=1"), 1, ";");
  r = parse_gsd(no_struct, "w.gsd");
  ASSERT_TRUE(r.ok());
  EXPECT_EQ(texts(r.warnings), std::vector<std::string>{"w.gsd:14: PrmCmd_supp = 1 without "
                                                        "Prm_Block_Structure_supp = 1 (PrmCmd is a structured block)"});
  std::string v0 = no_struct;
  v0.replace(v0.find("DPV1_Slave=1"), 1, ";");
  r = parse_gsd(v0, "w.gsd");
  ASSERT_TRUE(r.ok());
  EXPECT_EQ(texts(r.warnings), std::vector<std::string>{"w.gsd:14: PrmCmd_supp = 1 without DPV1_Slave = 1 "
                                                        "(the PrmCmd bit is in DPV1_Status_3)"});
}

// PBVB0A10: the fast switched station (IM 153-2-like), System Redundancy, 30 ms.
TEST(GsdRedundancy, ShippedFastSwitchedStation) {
  GsdParseResult r = load_gsd(src("examples/gsd/PBVB0A10.gsd"));
  ASSERT_TRUE(r.ok()) << texts(r.errors).front();
  for (const auto& w : r.warnings) ADD_FAILURE() << w.to_string();
  const GsdFile& f = *r.file;
  EXPECT_EQ(f.ident_number(), 0x0A10);
  EXPECT_EQ(f.info().model_name, "pbvbus SW3 switched station");
  const GsdRedundancy& red = f.redundancy();
  EXPECT_FALSE(red.redundancy);
  EXPECT_TRUE(red.prm_cmd_supp);
  EXPECT_EQ(red.slave_redundancy_supp, 0x01);
  EXPECT_TRUE(red.system_redundancy());
  EXPECT_FALSE(red.flying_redundancy());
  EXPECT_EQ(red.slave_max_switch_over_time, 3);
  EXPECT_EQ(red.switch_over_time_ms(), 30u);
  EXPECT_TRUE(f.dpv1().dpv1_slave);
  EXPECT_TRUE(f.dpv1().prm_block_structure_supp);
  EXPECT_TRUE(f.dpv1().c1_read_write_supp);
  EXPECT_TRUE(f.dpv1().diagnostic_alarm_supp);
  EXPECT_TRUE(f.dpv1().pull_plug_alarm_supp);
  // Every rate 9.6k..12M except the PA rate, with the MaxTsdr of the other shipped files.
  const std::vector<std::pair<Baud, std::uint16_t>> bauds = {
      {Baud::k9_6, 60},   {Baud::k19_2, 60}, {Baud::k45_45, 250}, {Baud::k93_75, 60},
      {Baud::k187_5, 60}, {Baud::k500, 100}, {Baud::k1_5M, 150},  {Baud::k3M, 250},
      {Baud::k6M, 450},   {Baud::k12M, 800}};
  ASSERT_EQ(f.baud_rates().size(), bauds.size());
  for (std::size_t i = 0; i < bauds.size(); ++i) {
    EXPECT_EQ(f.baud_rates()[i].baud, bauds[i].first);
    EXPECT_EQ(f.baud_rates()[i].max_tsdr, bauds[i].second);
  }
  EXPECT_EQ(f.slave_features().min_slave_intervall, 1);
  EXPECT_TRUE(f.slave_features().modular_station);
  EXPECT_EQ(f.slave_features().max_module, 8);
  EXPECT_EQ(f.slave_features().max_diag_data_len, 64);
  // Three module kinds: 16DI (0x11: 2 B in), 16DO (0x21: 2 B out), 4AI (0xD3: 4 words in,
  // consistent).
  ASSERT_EQ(f.modules().size(), 3u);
  EXPECT_EQ(f.modules()[0].name, "16DI DC24V");
  EXPECT_EQ(f.modules()[0].config, GsdBytes{0x11});
  EXPECT_EQ(f.modules()[0].input_len, 2u);
  EXPECT_EQ(f.modules()[1].name, "16DO DC24V/0.5A");
  EXPECT_EQ(f.modules()[1].output_len, 2u);
  EXPECT_EQ(f.modules()[2].name, "4AI U/I 13 bit");
  EXPECT_EQ(f.modules()[2].input_len, 8u);
  EXPECT_TRUE(f.modules()[2].consistent);
  // User_Prm_Data: DPV1_Status_1 0x80, DPV1_Status_2 0x20 (diagnostic alarm on by default),
  // DPV1_Status_3 0x00 (a redundant master sets PrmCmd | Prm_Structure itself); the modules add
  // nothing. Max_User_Prm_Data_Len 11 leaves room for the 8-octet PrmCmd block.
  EXPECT_EQ(f.user_prm_data({0, 1, 2}).value, GsdBytes({0x80, 0x20, 0x00}));
  EXPECT_EQ(f.max_user_prm_data_len(), 11);
  EXPECT_EQ(f.cfg_data({0, 0, 1, 2}).value, GsdBytes({0x11, 0x11, 0x21, 0xD3}));
  const auto io = f.check_modules({0, 0, 1, 2});
  ASSERT_TRUE(io.ok());
  EXPECT_EQ(io.value->first, 12u);  // 2 + 2 + 8
  EXPECT_EQ(io.value->second, 2u);
}

// PBVB0A11: the slow variant (DP/PA-link-like), same modules, System + Flying Redundancy, 820 ms,
// 45.45k..1.5M only.
TEST(GsdRedundancy, ShippedSlowSwitchedStation) {
  GsdParseResult r = load_gsd(src("examples/gsd/PBVB0A11.gsd"));
  ASSERT_TRUE(r.ok()) << texts(r.errors).front();
  for (const auto& w : r.warnings) ADD_FAILURE() << w.to_string();
  const GsdFile& f = *r.file;
  EXPECT_EQ(f.ident_number(), 0x0A11);
  const GsdRedundancy& red = f.redundancy();
  EXPECT_TRUE(red.prm_cmd_supp);
  EXPECT_EQ(red.slave_redundancy_supp, 0x03);
  EXPECT_TRUE(red.system_redundancy());
  EXPECT_TRUE(red.flying_redundancy());
  EXPECT_EQ(red.slave_max_switch_over_time, 82);
  EXPECT_EQ(red.switch_over_time_ms(), 820u);
  const std::vector<std::pair<Baud, std::uint16_t>> bauds = {
      {Baud::k45_45, 400}, {Baud::k93_75, 100}, {Baud::k187_5, 100}, {Baud::k500, 200}, {Baud::k1_5M, 300}};
  ASSERT_EQ(f.baud_rates().size(), bauds.size());
  for (std::size_t i = 0; i < bauds.size(); ++i) {
    EXPECT_EQ(f.baud_rates()[i].baud, bauds[i].first);
    EXPECT_EQ(f.baud_rates()[i].max_tsdr, bauds[i].second);
  }
  EXPECT_FALSE(f.supports(Baud::k12M));
  EXPECT_FALSE(f.supports(Baud::k9_6));
  EXPECT_EQ(f.slave_features().min_slave_intervall, 10);
  // Same modules and parameters as PBVB0A10.
  GsdParseResult fast = load_gsd(src("examples/gsd/PBVB0A10.gsd"));
  ASSERT_TRUE(fast.ok());
  ASSERT_EQ(f.modules().size(), fast.file->modules().size());
  for (std::size_t i = 0; i < f.modules().size(); ++i) {
    EXPECT_EQ(f.modules()[i].name, fast.file->modules()[i].name);
    EXPECT_EQ(f.modules()[i].config, fast.file->modules()[i].config);
  }
  EXPECT_EQ(f.dpv1(), fast.file->dpv1());
  EXPECT_EQ(f.user_prm_data({0, 1, 2}).value, GsdBytes({0x80, 0x20, 0x00}));
}
