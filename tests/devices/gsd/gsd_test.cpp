// GSD reader and model (PI 2.122, protocol-facts.md §I): every .gsd in the repository parses;
// hand-written expectations for the shipped files and the vendor-style test file; User_Prm_Data
// and Chk_Cfg assembly; module-list checks; configuration identifier lengths (§D.3).
// All expected bytes below were worked out by hand from the file contents.

#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <string>
#include <vector>

#include "pbvbus/gsd/gsd.hpp"

namespace fs = std::filesystem;
using namespace pbvbus::devices;
using pbvbus::bus::Baud;

namespace {

std::string src(const std::string& rel) { return std::string(PBVBUS_SOURCE_DIR) + "/" + rel; }

GsdFile load_ok(const std::string& rel) {
  GsdParseResult r = load_gsd(src(rel));
  for (const auto& e : r.errors) ADD_FAILURE() << e.to_string();
  if (!r.ok()) throw std::runtime_error("parse failed: " + rel);
  return std::move(*r.file);
}

std::vector<std::uint8_t> prm(const GsdFile& f, const std::vector<std::size_t>& mods) {
  auto o = f.user_prm_data(mods);
  EXPECT_TRUE(o.ok());
  return o.value.value_or(GsdBytes{});
}

std::vector<std::uint8_t> cfg(const GsdFile& f, const std::vector<std::size_t>& mods) {
  auto o = f.cfg_data(mods);
  EXPECT_TRUE(o.ok());
  return o.value.value_or(GsdBytes{});
}

const std::vector<std::pair<Baud, std::uint16_t>> kShippedTsdr = {
    {Baud::k9_6, 60},   {Baud::k19_2, 60}, {Baud::k45_45, 250}, {Baud::k93_75, 60},
    {Baud::k187_5, 60}, {Baud::k500, 100}, {Baud::k1_5M, 150},  {Baud::k3M, 250},
    {Baud::k6M, 450},   {Baud::k12M, 800}};

void expect_shipped_bauds(const GsdFile& f) {
  ASSERT_EQ(f.baud_rates().size(), kShippedTsdr.size());
  for (std::size_t i = 0; i < kShippedTsdr.size(); ++i) {
    EXPECT_EQ(f.baud_rates()[i].baud, kShippedTsdr[i].first);
    EXPECT_EQ(f.baud_rates()[i].max_tsdr, kShippedTsdr[i].second);
  }
  EXPECT_FALSE(f.supports(Baud::k31_25));
  EXPECT_EQ(f.max_tsdr(Baud::k12M), 800);
}

}  // namespace

TEST(Gsd, EveryGsdFileInTheRepositoryParses) {
  std::size_t n = 0;
  for (const char* dir : {"examples/gsd", "tests/data/gsd"}) {
    for (const auto& e : fs::recursive_directory_iterator(src(dir))) {
      std::string ext = e.path().extension().string();
      std::transform(ext.begin(), ext.end(), ext.begin(), ::tolower);
      if (ext != ".gsd") continue;
      ++n;
      GsdParseResult r = load_gsd(e.path());
      EXPECT_TRUE(r.ok()) << e.path();
      for (const auto& m : r.errors) ADD_FAILURE() << m.to_string();
    }
  }
  EXPECT_GE(n, 4u);
}

TEST(Gsd, ShippedFilesHaveNoWarnings) {
  for (const char* f : {"examples/gsd/PBVB0A01.gsd", "examples/gsd/PBVB0A02.gsd", "examples/gsd/PBVB0A03.gsd",
                        "examples/gsd/PBVB0A10.gsd", "examples/gsd/PBVB0A11.gsd"}) {
    GsdParseResult r = load_gsd(src(f));
    ASSERT_TRUE(r.ok()) << f;
    for (const auto& w : r.warnings) ADD_FAILURE() << w.to_string();
  }
}

TEST(Gsd, CompactStation) {
  const GsdFile f = load_ok("examples/gsd/PBVB0A01.gsd");
  EXPECT_EQ(f.ident_number(), 0x0A01);
  EXPECT_EQ(f.station_type(), 0);
  EXPECT_FALSE(f.is_master());
  EXPECT_EQ(f.info().vendor_name, "pbvbus");
  EXPECT_EQ(f.info().model_name, "pbvbus CS16 16DI/16DO");
  EXPECT_EQ(f.info().revision, "V1.0");
  EXPECT_EQ(f.info().gsd_revision, 5);
  EXPECT_EQ(f.info().revision_number, 1);
  EXPECT_EQ(f.info().slave_family, "3@Digital@24V");
  EXPECT_EQ(f.info().implementation_type, "VPC3+S");
  // The Info_Text string is continued with a trailing backslash inside the quotes.
  EXPECT_EQ(f.info().info_text,
            "Compact station, 16 digital inputs DC 24 V, 16 digital outputs DC 24 V / 0.5 A");
  expect_shipped_bauds(f);

  const auto& s = f.slave_features();
  EXPECT_TRUE(s.freeze_mode_supp);
  EXPECT_TRUE(s.sync_mode_supp);
  EXPECT_TRUE(s.auto_baud_supp);
  EXPECT_TRUE(s.set_slave_add_supp);
  EXPECT_TRUE(s.fail_safe);
  EXPECT_FALSE(s.modular_station);
  EXPECT_EQ(s.min_slave_intervall, 1);
  EXPECT_EQ(s.max_diag_data_len, 8);
  EXPECT_EQ(s.max_module, 1);
  EXPECT_EQ(s.max_data_len, 4);
  EXPECT_EQ(f.unit_diag_bits().at(9), "Output short circuit");

  ASSERT_EQ(f.modules().size(), 1u);
  const auto& m = f.modules()[0];
  EXPECT_EQ(m.name, "16DI/16DO DC24V");
  EXPECT_EQ(m.reference, 1u);
  EXPECT_EQ(m.config, (GsdBytes{0x11, 0x21}));
  EXPECT_EQ(m.input_len, 2u);
  EXPECT_EQ(m.output_len, 2u);
  EXPECT_FALSE(m.consistent);

  // User_Prm_Data 0x00; Bit(1) default 1 -> 0x02; BitArea(4-5) default 1 -> 0x10; Bit(0) 0.
  EXPECT_EQ(prm(f, {0}), (GsdBytes{0x12}));
  EXPECT_EQ(cfg(f, {0}), (GsdBytes{0x11, 0x21}));
  auto chk = f.check_modules({0});
  ASSERT_TRUE(chk.ok());
  EXPECT_EQ(*chk.value, std::make_pair(std::size_t{2}, std::size_t{2}));
  // A compact station takes exactly one module.
  EXPECT_FALSE(f.check_modules({0, 0}).ok());
  EXPECT_FALSE(f.check_modules({}).ok());

  const auto& e = f.ext_user_prm_data().at(2);
  EXPECT_EQ(e.name, "Input delay");
  EXPECT_EQ(e.type, GsdDataType::BitArea);
  EXPECT_EQ(e.bit_first, 4);
  EXPECT_EQ(e.bit_last, 5);
  EXPECT_EQ(e.default_value, 1);
  EXPECT_EQ(e.max_value, 3);
  ASSERT_TRUE(e.prm_text_ref);
  EXPECT_EQ(*f.prm_texts().at(*e.prm_text_ref).text_for(2), "15 ms");
  EXPECT_FALSE(f.dpv1().dpv1_slave);
}

TEST(Gsd, ModularStation) {
  const GsdFile f = load_ok("examples/gsd/PBVB0A02.gsd");
  EXPECT_EQ(f.ident_number(), 0x0A02);
  EXPECT_EQ(f.info().model_name, "pbvbus MS8 modular station");
  expect_shipped_bauds(f);
  const auto& s = f.slave_features();
  EXPECT_TRUE(s.modular_station);
  EXPECT_EQ(s.max_module, 8);
  EXPECT_EQ(s.max_input_len, 64);
  EXPECT_EQ(s.max_output_len, 64);
  EXPECT_EQ(s.max_data_len, 128);
  EXPECT_EQ(f.max_user_prm_data_len(), 64);

  struct M { const char* name; std::uint32_t ref; GsdBytes cfg; std::size_t in, out; bool cons; };
  const M expected[] = {
      {"8DI DC24V", 1, {0x10}, 1, 0, false},      {"16DI DC24V", 2, {0x11}, 2, 0, false},
      {"8DO DC24V/0.5A", 3, {0x20}, 0, 1, false}, {"16DO DC24V/0.5A", 4, {0x21}, 0, 2, false},
      {"4AI U/I 16 bit", 5, {0xD3}, 8, 0, true},  {"2AO U/I 16 bit", 6, {0x61}, 0, 4, false},
  };
  ASSERT_EQ(f.modules().size(), 6u);
  for (std::size_t i = 0; i < 6; ++i) {
    const auto& m = f.modules()[i];
    EXPECT_EQ(m.name, expected[i].name);
    EXPECT_EQ(m.reference, expected[i].ref);
    EXPECT_EQ(m.config, expected[i].cfg);
    EXPECT_EQ(m.input_len, expected[i].in) << m.name;
    EXPECT_EQ(m.output_len, expected[i].out) << m.name;
    EXPECT_EQ(m.consistent, expected[i].cons) << m.name;
  }
  EXPECT_EQ(f.find_module("4AI U/I 16 bit"), 4u);
  EXPECT_EQ(f.find_module_by_reference(6), 5u);
  EXPECT_FALSE(f.find_module("nope"));

  // 8DI, 16DO, 4AI, 2AO: station byte (Bit(0) = 1), 8DI input delay BitArea(0-1) = 1,
  // 16DO Bit(0) = 0, 4AI ranges 2,2,2,2 + Unsigned16 100 big-endian, 2AO ranges 2,2.
  const std::vector<std::size_t> sel = {0, 3, 4, 5};
  EXPECT_EQ(prm(f, sel), (GsdBytes{0x01, 0x01, 0x00, 0x02, 0x02, 0x02, 0x02, 0x00, 0x64, 0x02, 0x02}));
  EXPECT_EQ(cfg(f, sel), (GsdBytes{0x10, 0x21, 0xD3, 0x61}));
  auto chk = f.check_modules(sel);
  ASSERT_TRUE(chk.ok());
  EXPECT_EQ(chk.value->first, 9u);
  EXPECT_EQ(chk.value->second, 6u);
  // No modules: only the station byte.
  EXPECT_EQ(prm(f, {}), (GsdBytes{0x01}));

  // Nine modules exceed Max_Module 8; 9 x 4AI = 72 input bytes exceed Max_Input_Len 64.
  auto too_many = f.check_modules({4, 4, 4, 4, 4, 4, 4, 4, 4});
  ASSERT_FALSE(too_many.ok());
  EXPECT_EQ(too_many.errors[0], "9 modules selected, Max_Module = 8");
  EXPECT_EQ(too_many.errors[1], "inputs of 72 bytes exceed Max_Input_Len 64");
  auto bad = f.check_modules({0, 6});
  ASSERT_FALSE(bad.ok());
  EXPECT_EQ(bad.errors[0], "module index 6 out of range (6 modules)");
  EXPECT_FALSE(f.user_prm_data({7}).ok());
  EXPECT_FALSE(f.cfg_data({7}).ok());

  const auto& range = f.ext_user_prm_data().at(30);
  EXPECT_EQ(range.allowed, (std::vector<std::int64_t>{1, 2, 3, 4}));
  EXPECT_TRUE(range.accepts(4));
  EXPECT_FALSE(range.accepts(0));
  EXPECT_EQ(f.ext_user_prm_data().at(21).type, GsdDataType::Unsigned16);
  EXPECT_EQ(f.channel_diag().at(6), "Wire break");
}

TEST(Gsd, Dpv1Station) {
  const GsdFile f = load_ok("examples/gsd/PBVB0A03.gsd");
  EXPECT_EQ(f.ident_number(), 0x0A03);
  expect_shipped_bauds(f);
  const auto& d = f.dpv1();
  EXPECT_TRUE(d.dpv1_slave);
  EXPECT_TRUE(d.c1_read_write_supp);
  EXPECT_EQ(d.c1_max_data_len, 240);
  EXPECT_EQ(d.c1_response_timeout, 100);
  EXPECT_TRUE(d.c2_read_write_supp);
  EXPECT_EQ(d.c2_max_data_len, 240);
  EXPECT_EQ(d.c2_max_count_channels, 2);
  EXPECT_EQ(d.max_initiate_pdu_length, 52);
  EXPECT_TRUE(d.diagnostic_alarm_supp);
  EXPECT_TRUE(d.process_alarm_supp);
  EXPECT_TRUE(d.pull_plug_alarm_supp);
  EXPECT_FALSE(d.status_alarm_supp);
  EXPECT_FALSE(d.update_alarm_supp);
  EXPECT_TRUE(d.extra_alarm_sap_supp);
  EXPECT_EQ(d.alarm_sequence_mode_count, 8);
  EXPECT_TRUE(d.alarm_type_mode_supp);
  EXPECT_TRUE(d.wd_base_1ms_supp);
  EXPECT_FALSE(d.check_cfg_mode);
  EXPECT_TRUE(d.ident_maintenance_supp);
  ASSERT_EQ(f.unit_diag_areas().size(), 1u);
  EXPECT_EQ(f.unit_diag_areas()[0].first_bit, 16);
  EXPECT_EQ(f.unit_diag_areas()[0].last_bit, 17);
  EXPECT_EQ(f.unit_diag_areas()[0].values[2].second, "Module missing");

  ASSERT_EQ(f.modules().size(), 4u);
  // 0x40 0xC3: special format, one input length octet: consistent, words, 4 units = 8 bytes.
  EXPECT_EQ(f.modules()[3].input_len, 8u);
  EXPECT_EQ(f.modules()[3].output_len, 0u);
  EXPECT_TRUE(f.modules()[3].consistent);
  EXPECT_EQ(f.modules()[2].input_len, 4u);

  // DPV1_Status_1 = 0x80; DPV1_Status_2 = diag (0x20) + process (0x40) + pull/plug (0x80)
  // alarms enabled = 0xE0; DPV1_Status_3 = 0; station byte Bit(0) = 1. Then 8DI: BitArea(0-1) = 1;
  // 8DO: nothing; 2AI: range 3, Signed16 27648 = 0x6C00.
  EXPECT_EQ(prm(f, {0, 1, 2}), (GsdBytes{0x80, 0xE0, 0x00, 0x01, 0x01, 0x03, 0x6C, 0x00}));
  EXPECT_EQ(cfg(f, {0, 1, 2, 3}), (GsdBytes{0x10, 0x20, 0xD1, 0x40, 0xC3}));
  auto chk = f.check_modules({0, 1, 2, 3});
  ASSERT_TRUE(chk.ok());
  EXPECT_EQ(chk.value->first, 13u);
  EXPECT_EQ(chk.value->second, 1u);
  EXPECT_EQ(f.ext_user_prm_data().at(12).min_value, -27648);
}

TEST(Gsd, EveryDpv1Keyword) {
  // PBVB0A04 sets every DP-V1 keyword the model holds; spot checks of the less common ones.
  const GsdFile f = load_ok("tests/data/gsd/PBVB0A04.gsd");
  const auto& d = f.dpv1();
  EXPECT_TRUE(d.isochron_mode_supp);
  EXPECT_FALSE(d.isochron_mode_required);
  EXPECT_TRUE(d.time_sync_supp);
  EXPECT_TRUE(d.publisher_supp);
  EXPECT_FALSE(d.prm_block_structure_supp);
  EXPECT_TRUE(d.prm_block_structure_req);
  EXPECT_TRUE(d.c2_read_write_required);
  EXPECT_TRUE(d.manufacturer_specific_alarm_required);
  EXPECT_FALSE(d.dpv1_data_types);
  EXPECT_TRUE(f.unknown_keywords().empty());
  EXPECT_EQ(f.keyword("Isochron_Mode_supp")->line, 60u);
}

TEST(Gsd, VendorStyleFile) {
  GsdParseResult r = load_gsd(src("tests/data/gsd/VNDR4711.gsd"));
  ASSERT_TRUE(r.ok());
  const GsdFile& f = *r.file;
  // Latin-1 bytes 0xFC, 0xF6, 0xDC, 0xDF, 0xE4 arrive as UTF-8.
  EXPECT_EQ(f.info().vendor_name, "M\xC3\xBCller & S\xC3\xB6hne");
  EXPECT_EQ(f.info().model_name, "Ventilinsel VI-8 \xC3\x9C" "berdruck");
  EXPECT_EQ(f.info().revision, "Ausgabe A; Stand 2/2026");
  EXPECT_EQ(f.info().gsd_revision, 3);
  EXPECT_EQ(f.ident_number(), 0x4711);
  EXPECT_EQ(f.unit_diag_bits().at(17), "Kurzschlu\xC3\x9F Magnetspule");
  EXPECT_EQ(f.unit_diag_areas().at(0).values.at(2).second, "\xC3\x9C" "bertemperatur");
  EXPECT_EQ(f.prm_texts().at(2).texts.at(0).second, "r\xC3\xBC" "ckw\xC3\xA4rts");
  EXPECT_EQ(f.prm_texts().at(2).texts.at(0).first, -1);

  const std::vector<std::pair<Baud, std::uint16_t>> bauds = {
      {Baud::k9_6, 60},    {Baud::k19_2, 60}, {Baud::k31_25, 100}, {Baud::k45_45, 250},
      {Baud::k93_75, 60},  {Baud::k187_5, 60}, {Baud::k500, 100},  {Baud::k1_5M, 150},
      {Baud::k12M, 800}};
  ASSERT_EQ(f.baud_rates().size(), bauds.size());
  for (std::size_t i = 0; i < bauds.size(); ++i) {
    EXPECT_EQ(f.baud_rates()[i].baud, bauds[i].first);
    EXPECT_EQ(f.baud_rates()[i].max_tsdr, bauds[i].second);
  }
  EXPECT_FALSE(f.supports(Baud::k3M));
  EXPECT_FALSE(f.supports(Baud::k6M));

  EXPECT_TRUE(f.redundancy().redundancy);
  EXPECT_TRUE(f.redundancy().prm_cmd_supp);
  EXPECT_EQ(f.redundancy().slave_redundancy_supp, 0x08);
  EXPECT_EQ(f.redundancy().slave_max_switch_over_time, 100);
  EXPECT_EQ(f.slave_features().max_module, 10);
  EXPECT_FALSE(f.slave_features().freeze_mode_supp);

  ASSERT_EQ(f.unknown_keywords().size(), 1u);
  EXPECT_EQ(f.unknown_keywords()[0].name, "Vendor_Specific_Feature");
  EXPECT_EQ(f.unknown_keywords()[0].value, "42, \"kept\"");
  EXPECT_EQ(f.unknown_keywords()[0].line, 51u);
  ASSERT_NE(f.keyword("bitmap_device"), nullptr);
  EXPECT_EQ(f.keyword("BITMAP_DEVICE")->value, "\"VI8_N\"");
  EXPECT_EQ(f.keyword("Vendor_Name")->line, 12u);

  std::vector<std::string> warnings;
  for (const auto& w : r.warnings) warnings.push_back(w.to_string());
  const std::string p = src("tests/data/gsd/VNDR4711.gsd");
  EXPECT_NE(std::find(warnings.begin(), warnings.end(), p + ":51: unknown keyword 'Vendor_Specific_Feature' kept"),
            warnings.end());
  EXPECT_NE(std::find(warnings.begin(), warnings.end(),
                      p + ":147: section '#Profibus_PA' ignored (only #Profibus_DP is read)"),
            warnings.end());
  EXPECT_NE(std::find(warnings.begin(), warnings.end(),
                      p + ":111: User_Prm_Data has 6 bytes, more than User_Prm_Data_Len 5; truncated"),
            warnings.end());

  const auto& e2 = f.ext_user_prm_data().at(2);
  EXPECT_EQ(e2.name, "Schaltverz\xC3\xB6gerung");
  EXPECT_EQ(e2.bit_first, 4);
  EXPECT_EQ(e2.bit_last, 6);
  EXPECT_EQ(e2.max_value, 7);
  const auto& e4 = f.ext_user_prm_data().at(4);
  EXPECT_EQ(e4.type, GsdDataType::Unsigned32);
  EXPECT_EQ(e4.default_value, 100000);
  EXPECT_FALSE(e4.changeable);
  const auto& e5 = f.ext_user_prm_data().at(5);
  EXPECT_EQ(e5.min_value, -1000);
  EXPECT_EQ(e5.max_value, -100);
  EXPECT_FALSE(e5.visible);

  ASSERT_EQ(f.modules().size(), 4u);
  EXPECT_EQ(f.modules()[0].info_text, "8 Magnetventile, je 0,5 A");
  // 0x31 = 2 bytes in + 2 bytes out, 0x10 = 1 byte in.
  EXPECT_EQ(f.modules()[1].config, (GsdBytes{0x31, 0x10}));
  EXPECT_EQ(f.modules()[1].input_len, 3u);
  EXPECT_EQ(f.modules()[1].output_len, 2u);
  // 0xC2: output then input length octet, 2 manufacturer bytes; 0x81 = 2 bytes out consistent,
  // 0xC1 = 2 words in consistent.
  EXPECT_EQ(f.modules()[2].output_len, 2u);
  EXPECT_EQ(f.modules()[2].input_len, 4u);
  // F_Ext_Module_Prm_Data_Len = 0: a PROFIsafe module keyword with an empty F-parameter block.
  EXPECT_TRUE(f.modules()[2].other_keywords.empty());
  EXPECT_TRUE(f.modules()[2].f.present());
  EXPECT_EQ(f.modules()[2].f.prm.declared_len, 0u);
  EXPECT_TRUE(f.f_prm_defaults(f.modules()[2]).empty());
  EXPECT_EQ(f.modules()[3].input_len + f.modules()[3].output_len, 0u);

  ASSERT_EQ(f.slots().size(), 2u);
  EXPECT_EQ(f.slots()[1].name, "Erweiterung");
  EXPECT_EQ(f.slots()[1].default_ref, 4u);
  EXPECT_EQ(f.slots()[1].allowed,
            (std::vector<std::pair<std::uint32_t, std::uint32_t>>{{1, 1}, {3, 4}}));

  // Global: User_Prm_Data 00 00 00 00 A5 (6th byte truncated), Const(0) 40 0F, Ref(0)=1 Bit(2)
  // default 1 -> 0x44, Ref(0)=2 BitArea(4-6) default 3 -> (0x44 & ~0x70) | 0x30 = 0x34,
  // Ref(1)=3 Signed8 0 -> 0x00. Module 0: Unsigned32 100000 = 00 01 86 A0. Module 2: Signed16
  // -300 = FE D4.
  EXPECT_EQ(prm(f, {0, 1, 2, 3}),
            (GsdBytes{0x34, 0x00, 0x00, 0x00, 0xA5, 0x00, 0x01, 0x86, 0xA0, 0xFE, 0xD4}));
  EXPECT_EQ(cfg(f, {0, 2}), (GsdBytes{0x20, 0xC2, 0x81, 0xC1, 0x55, 0xAA}));
}

TEST(Gsd, UserPrmDataTruncatedToMaxLen) {
  const std::string text =
      "#Profibus_DP\nIdent_Number=1\nStation_Type=0\n12M_supp=1\nMaxTsdr_12M=800\n"
      "Min_Slave_Intervall=1\nMax_Diag_Data_Len=6\nModular_Station=1\nMax_Module=4\n"
      "Max_User_Prm_Data_Len=3\nUser_Prm_Data_Len=2\nUser_Prm_Data=0x11,0x22\n"
      "Module=\"m\" 0x10\nExt_Module_Prm_Data_Len=2\nExt_User_Prm_Data_Const(0)=0x33,0x44\nEndModule\n";
  GsdParseResult r = parse_gsd(text, "t.gsd");
  ASSERT_TRUE(r.ok());
  auto o = r.file->user_prm_data({0});
  ASSERT_TRUE(o.ok());
  EXPECT_EQ(*o.value, (GsdBytes{0x11, 0x22, 0x33}));
  ASSERT_EQ(o.notes.size(), 1u);
  EXPECT_EQ(o.notes[0], "User_Prm_Data of 4 bytes truncated to Max_User_Prm_Data_Len 3");
  auto chk = r.file->check_modules({0});
  ASSERT_EQ(chk.errors.size(), 1u);
  EXPECT_EQ(chk.errors[0], "User_Prm_Data of 4 bytes exceeds Max_User_Prm_Data_Len 3");
}

TEST(Gsd, ModulesForCfg) {
  const GsdFile f = load_ok("examples/gsd/PBVB0A02.gsd");
  EXPECT_EQ(f.modules_for_cfg({0x10, 0x21, 0xD3, 0x61}), (std::vector<std::size_t>{0, 3, 4, 5}));
  EXPECT_EQ(f.modules_for_cfg({}), (std::vector<std::size_t>{}));
  EXPECT_FALSE(f.modules_for_cfg({0x10, 0x22}));
  // Multi-byte configs need backtracking: 0x40 alone is no module, 0x40 0xC3 is.
  const GsdFile d = load_ok("examples/gsd/PBVB0A03.gsd");
  EXPECT_EQ(d.modules_for_cfg({0x40, 0xC3, 0x10}), (std::vector<std::size_t>{3, 0}));
  EXPECT_FALSE(d.modules_for_cfg({0x40, 0xC2}));
}

TEST(Gsd, ParameterSettings) {
  const GsdFile f = load_ok("examples/gsd/PBVB0A02.gsd");
  const std::vector<std::size_t> sel = {0, 3, 4, 5};  // 8DI, 16DO, 4AI, 2AO
  // Station Bit(0) off; 4AI channel 1 (offset 1) 4..20 mA (3), smoothing 500 ms = 0x01F4;
  // 2AO both channels 0..20 mA (4).
  auto o = f.user_prm_data(sel, {{std::nullopt, 1, 0, std::nullopt},
                                 {2, 20, 3, std::uint16_t{1}},
                                 {2, 21, 500, std::nullopt},
                                 {3, 30, 4, std::nullopt}});
  ASSERT_TRUE(o.ok()) << o.errors[0];
  EXPECT_EQ(*o.value, (GsdBytes{0x00, 0x01, 0x00, 0x02, 0x03, 0x02, 0x02, 0x01, 0xF4, 0x04, 0x04}));

  auto bad = f.user_prm_data(sel, {{3, 30, 0, std::nullopt},
                                   {0, 20, 1, std::nullopt},
                                   {9, 20, 1, std::nullopt},
                                   {std::nullopt, 99, 1, std::nullopt},
                                   {2, 20, 1, std::uint16_t{4}}});
  ASSERT_EQ(bad.errors.size(), 5u);
  EXPECT_EQ(bad.errors[0], "ExtUserPrmData 30 'Output range': value 0 not allowed");
  EXPECT_EQ(bad.errors[1], "ExtUserPrmData 20 'Measuring range' is not used in slot 0");
  EXPECT_EQ(bad.errors[2], "setting for slot 9: only 4 modules selected");
  EXPECT_EQ(bad.errors[3], "setting for the station parameters: no ExtUserPrmData 99");
  EXPECT_EQ(bad.errors[4], "ExtUserPrmData 20 'Measuring range' is not used in slot 2 at offset 4");
  EXPECT_FALSE(bad.value);

  GsdParseResult v = load_gsd(src("tests/data/gsd/VNDR4711.gsd"));
  ASSERT_TRUE(v.ok());
  auto fixed = v.file->user_prm_data({0}, {{0, 4, 2000, std::nullopt}});
  ASSERT_EQ(fixed.errors.size(), 1u);
  EXPECT_EQ(fixed.errors[0], "ExtUserPrmData 4 'Pulsdauer [ms]' is not changeable");
  // Setting the default of a fixed parameter is fine; Signed16 -1000 = 0xFC18.
  auto ok = v.file->user_prm_data({0, 2}, {{0, 4, 100000, std::nullopt}, {1, 5, -1000, std::nullopt}});
  ASSERT_TRUE(ok.ok());
  EXPECT_EQ(*ok.value, (GsdBytes{0x34, 0x00, 0x00, 0x00, 0xA5, 0x00, 0x01, 0x86, 0xA0, 0xFC, 0x18}));
}

TEST(Gsd, Dpv1StatusFilledWhenTheFileGivesNone) {
  const std::string text =
      "#Profibus_DP\nIdent_Number=0x1234\nStation_Type=0\n1.5M_supp=1\nMaxTsdr_1.5M=150\n"
      "Min_Slave_Intervall=1\nMax_Diag_Data_Len=6\nDPV1_Slave=1\nUser_Prm_Data_Len=1\n"
      "User_Prm_Data=0x80\nModule=\"m\" 0x20\nEndModule\n";
  GsdParseResult r = parse_gsd(text, "t.gsd");
  ASSERT_TRUE(r.ok());
  ASSERT_EQ(r.warnings.size(), 1u);
  EXPECT_EQ(r.warnings[0].to_string(),
            "t.gsd:8: DPV1_Slave = 1 but User_Prm_Data has fewer than 3 bytes (DPV1_Status_1..3); "
            "missing status bytes assembled as 80 00 00");
  auto o = r.file->user_prm_data({0});
  EXPECT_EQ(*o.value, (GsdBytes{0x80, 0x00, 0x00}));
}

TEST(Gsd, MasterFile) {
  const std::string text =
      "#Profibus_DP\nGSD_Revision=3\nVendor_Name=\"x\"\nIdent_Number=0x00FE\nStation_Type=1\n"
      "1.5M_supp=1\nMaxTsdr_1.5M=150\nTrdy_1.5M=11\nTqui_1.5M=0\nTset_1.5M=1\nTsdi_1.5M=37\n"
      "Max_Slaves_supp=124\nLAS_Len=126\nMin_Poll_Timeout=10\nDPV1_Master=1\n"
      "C1_Master_Read_Write_supp=1\nMaster_Diagnostic_Alarm_supp=1\nDownload_supp=0\n";
  GsdParseResult r = parse_gsd(text, "m.gsd");
  ASSERT_TRUE(r.ok()) << (r.errors.empty() ? "" : r.errors[0].to_string());
  const GsdFile& f = *r.file;
  EXPECT_TRUE(f.is_master());
  EXPECT_EQ(f.master().trdy.at(Baud::k1_5M), 11);
  EXPECT_EQ(f.master().tsdi.at(Baud::k1_5M), 37);
  EXPECT_EQ(f.master().max_slaves_supp, 124);
  EXPECT_EQ(f.master().las_len, 126);
  EXPECT_EQ(f.master().min_poll_timeout, 10);
  EXPECT_TRUE(f.master().dpv1_master);
  EXPECT_TRUE(f.master().c1_master_read_write_supp);
  EXPECT_TRUE(f.master().master_diagnostic_alarm_supp);
  for (const auto& w : r.warnings) ADD_FAILURE() << w.to_string();
}

TEST(Gsd, Utf8WithByteOrderMark) {
  const std::string text =
      "\xEF\xBB\xBF#Profibus_DP\nIdent_Number=1\nStation_Type=0\nVendor_Name=\"Gr\xC3\xBC\xC3\x9F" "e\"\n"
      "12M_supp=1\nMaxTsdr_12M=800\nMin_Slave_Intervall=1\nMax_Diag_Data_Len=6\nModule=\"m\" 0x10\nEndModule\n";
  GsdParseResult r = parse_gsd(text, "u.gsd");
  ASSERT_TRUE(r.ok());
  EXPECT_EQ(r.file->info().vendor_name, "Gr\xC3\xBC\xC3\x9F" "e");
  ASSERT_EQ(r.warnings.size(), 1u);
  EXPECT_EQ(r.warnings[0].line, 1u);
}

TEST(Gsd, CfgLengthsPerIdentifierFormat) {
  // General format (§D.3 examples).
  auto l = gsd_cfg_lengths({0x13, 0x31, 0x50, 0xD7});
  ASSERT_TRUE(l);
  EXPECT_EQ(l->input_len, 4u + 2u + 2u + 16u);
  EXPECT_EQ(l->output_len, 2u);
  EXPECT_TRUE(l->consistent);
  // Special format: 0x00 empty slot; 0x81 one output octet then 1 manufacturer byte.
  l = gsd_cfg_lengths({0x00, 0x81, 0x3F, 0xEE});
  ASSERT_TRUE(l);
  EXPECT_EQ(l->output_len, 64u);
  EXPECT_EQ(l->input_len, 0u);
  EXPECT_FALSE(l->consistent);
  // Manufacturer count 15 = none follow.
  l = gsd_cfg_lengths({0x4F, 0x01});
  ASSERT_TRUE(l);
  EXPECT_EQ(l->input_len, 2u);
  std::string why;
  EXPECT_FALSE(gsd_cfg_lengths({0xC3, 0x01}, &why));
  EXPECT_EQ(why, "special identifier 0xC3 at position 0 needs 5 more bytes, only 1 follow");
}

TEST(Gsd, UnreadableFile) {
  GsdParseResult r = load_gsd(src("tests/data/gsd/does-not-exist.gsd"));
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.errors[0].to_string(), src("tests/data/gsd/does-not-exist.gsd") + ": cannot read the file");
}
