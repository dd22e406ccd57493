// `pbvbus gsd`: called through the tools library (no process), asserting output lines and exit
// codes; the --json output is checked to be valid JSON with python3 -m json.tool.

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include "pbvbus/tools/commands.hpp"

using pbvbus::tools::cmd_gsd;

namespace {

struct GsdRun {
  int rc;
  std::string out;
  std::string err;
};

GsdRun run(const pbvbus::tools::Args& args) {
  std::ostringstream out;
  std::ostringstream err;
  const int rc = cmd_gsd(args, out, err);
  return {rc, out.str(), err.str()};
}

std::string src(const std::string& rel) { return std::string(PBVBUS_SOURCE_DIR) + "/" + rel; }

bool has_line(const std::string& text, const std::string& line) {
  std::istringstream in(text);
  for (std::string l; std::getline(in, l);)
    if (l == line) return true;
  return false;
}

// Runs a python3 expression on the parsed JSON document `d` and returns what it prints; the
// process fails (and the test with it) if the text is not one valid JSON document.
std::string python_on_json(const std::string& json, const std::string& expression) {
  // One file per test and call: ctest runs the tests of this file in parallel processes.
  static int calls = 0;
  const std::string path = std::string(PBVBUS_BINARY_DIR) + "/cmd_gsd_test_" +
                           ::testing::UnitTest::GetInstance()->current_test_info()->name() + "_" +
                           std::to_string(++calls) + ".json";
  {
    std::ofstream o(path, std::ios::binary);
    o << json;
  }
  const std::string cmd = "python3 -c \"import json,sys; d=json.load(open(sys.argv[1])); print(" + expression +
                          ")\" " + path;
  std::string result;
  FILE* p = popen(cmd.c_str(), "r");
  if (p == nullptr) return "popen failed";
  char buf[4096];
  for (std::size_t n; (n = std::fread(buf, 1, sizeof buf, p)) > 0;) result.append(buf, n);
  const int status = pclose(p);
  std::remove(path.c_str());
  if (status != 0) return "python3 failed: " + result;
  return result;
}

// "key=value" lines of a JSON object, sorted by key.
std::string sorted_items(const std::string& object_expr) {
  return "'\\n'.join(k + '=' + json.dumps(v) for k, v in sorted(" + object_expr + ".items()))";
}

}  // namespace

TEST(CmdGsd, Help) {
  GsdRun r = run({"--help"});
  EXPECT_EQ(r.rc, 0);
  EXPECT_TRUE(has_line(r.out, "usage: pbvbus gsd FILE [--json]"));
  EXPECT_TRUE(r.err.empty());
}

TEST(CmdGsd, BadUsage) {
  EXPECT_EQ(run({}).rc, 2);
  GsdRun r = run({"--frobnicate", "x.gsd"});
  EXPECT_EQ(r.rc, 2);
  EXPECT_TRUE(has_line(r.err, "pbvbus gsd: unknown option '--frobnicate'"));
  EXPECT_EQ(run({"a.gsd", "b.gsd"}).rc, 2);
}

TEST(CmdGsd, CompactStationText) {
  const std::string f = src("examples/gsd/PBVB0A01.gsd");
  GsdRun r = run({f});
  ASSERT_EQ(r.rc, 0) << r.err;
  EXPECT_TRUE(r.err.empty()) << r.err;
  EXPECT_TRUE(has_line(r.out, "Ident_Number:       0x0A01"));
  EXPECT_TRUE(has_line(r.out, "Station_Type:       0 (DP slave)"));
  EXPECT_TRUE(has_line(r.out, "Vendor_Name:        pbvbus"));
  EXPECT_TRUE(has_line(r.out, "Model_Name:         pbvbus CS16 16DI/16DO"));
  EXPECT_TRUE(has_line(r.out, "  9.6k    MaxTsdr 60"));
  EXPECT_TRUE(has_line(r.out, "  45.45k  MaxTsdr 250"));
  EXPECT_TRUE(has_line(r.out, "  12M     MaxTsdr 800"));
  EXPECT_TRUE(has_line(r.out, "  [0] \"16DI/16DO DC24V\" ref 1: cfg 0x11,0x21, in 2, out 2"));
  EXPECT_TRUE(has_line(r.out, "  station defaults: 12"));
  EXPECT_TRUE(has_line(r.out, "  ExtUserPrmData 2 \"Input delay\": BitArea(4-5), default 1, allowed 0-3"));
  EXPECT_TRUE(has_line(r.out, "      2 = 15 ms"));
  EXPECT_TRUE(has_line(r.out, "DP-V1:              no"));
}

TEST(CmdGsd, ModularAndDpv1Text) {
  GsdRun r = run({src("examples/gsd/PBVB0A02.gsd")});
  ASSERT_EQ(r.rc, 0) << r.err;
  EXPECT_TRUE(has_line(r.out, "  [4] \"4AI U/I 16 bit\" ref 5: cfg 0xD3, in 8, out 0, consistent, prm 02 02 02 02 00 64"));
  EXPECT_TRUE(has_line(r.out, "  ExtUserPrmData 30 \"Output range\": Unsigned8, default 2, allowed 1,2,3,4"));
  r = run({src("examples/gsd/PBVB0A03.gsd")});
  ASSERT_EQ(r.rc, 0) << r.err;
  EXPECT_TRUE(has_line(r.out, "DP-V1:              yes"));
  EXPECT_TRUE(has_line(r.out, "  C1_Read_Write_supp 1, C1_Max_Data_Len 240, C1_Response_Timeout 100"));
  EXPECT_TRUE(has_line(r.out, "  station defaults: 80 E0 00 01"));
  EXPECT_TRUE(has_line(r.out, "  alarms: Diagnostic 1, Process 1, Pull_Plug 1, Status 0, Update 0, "
                              "Manufacturer_Specific 0; Alarm_Sequence_Mode_Count 8"));
}

TEST(CmdGsd, VendorFileWarningsGoToStderr) {
  const std::string f = src("tests/data/gsd/VNDR4711.gsd");
  GsdRun r = run({f});
  ASSERT_EQ(r.rc, 0);
  EXPECT_TRUE(has_line(r.err, f + ":51: warning: unknown keyword 'Vendor_Specific_Feature' kept"));
  EXPECT_TRUE(has_line(r.out, "Vendor_Name:        M\xC3\xBCller & S\xC3\xB6hne"));
  EXPECT_TRUE(has_line(r.out, "  31.25k  MaxTsdr 100"));
  EXPECT_TRUE(has_line(r.out, "Redundancy:         Redundancy 1, PrmCmd_supp 1, Slave_Redundancy_supp 8, "
                              "Slave_Max_Switch_Over_Time 100"));
}

TEST(CmdGsd, MasterFile) {
  GsdRun r = run({src("tests/data/gsd/PBVB0AFF.gsd")});
  ASSERT_EQ(r.rc, 0) << r.err;
  EXPECT_TRUE(r.err.empty()) << r.err;
  EXPECT_TRUE(has_line(r.out, "Station_Type:       1 (DP master)"));
  EXPECT_TRUE(has_line(r.out, "  Max_Slaves_supp 124"));
  EXPECT_TRUE(has_line(r.out, "  Tsdi_12M 76"));
  EXPECT_TRUE(has_line(r.out, "Modules (0):"));
}

TEST(CmdGsd, BrokenFileExits2WithFileLineReason) {
  const std::string path = std::string(PBVBUS_BINARY_DIR) + "/cmd_gsd_broken.gsd";
  {
    std::ofstream o(path, std::ios::binary);
    o << "#Profibus_DP\nIdent_Number = 0x1234\nModule = \"x\" 0x10,0x1FF\nEndModule\n";
  }
  GsdRun r = run({path});
  EXPECT_EQ(r.rc, 2);
  EXPECT_TRUE(r.out.empty());
  EXPECT_TRUE(has_line(r.err, path + ":3: config byte 0x1FF out of range")) << r.err;
  std::remove(path.c_str());

  r = run({src("tests/data/gsd/no-such-file.gsd")});
  EXPECT_EQ(r.rc, 2);
  EXPECT_TRUE(has_line(r.err, src("tests/data/gsd/no-such-file.gsd") + ": cannot read the file"));
}

TEST(CmdGsd, JsonIsValid) {
  for (const char* rel : {"examples/gsd/PBVB0A01.gsd", "examples/gsd/PBVB0A02.gsd", "examples/gsd/PBVB0A03.gsd",
                          "tests/data/gsd/VNDR4711.gsd", "tests/data/gsd/PBVB0AFF.gsd"}) {
    GsdRun r = run({src(rel), "--json"});
    ASSERT_EQ(r.rc, 0) << rel;
    const std::string path = std::string(PBVBUS_BINARY_DIR) + "/cmd_gsd_test.json";
    {
      std::ofstream o(path, std::ios::binary);
      o << r.out;
    }
    // json.tool rejects anything that is not one valid JSON document.
    const std::string cmd =
        "python3 -c \"import json,sys; d=json.load(open(sys.argv[1])); "
        "m=d['modules']; print(d['ident_number'], len(m), m[0]['config'][0] if m else '-', "
        "d['baud_rates'][-1]['max_tsdr'], d['master']['tsdi'].get('12M', '-'))\" " +
        path;
    FILE* p = popen(cmd.c_str(), "r");
    ASSERT_NE(p, nullptr);
    char buf[256] = {};
    const std::size_t n = std::fread(buf, 1, sizeof buf - 1, p);
    const int status = pclose(p);
    ASSERT_EQ(status, 0) << rel << "\n" << r.out;
    const std::string line(buf, n);
    const std::string name(rel);
    if (name == "examples/gsd/PBVB0A01.gsd") {
      EXPECT_EQ(line, "2561 1 17 800 -\n");
    } else if (name == "examples/gsd/PBVB0A02.gsd") {
      EXPECT_EQ(line, "2562 6 16 800 -\n");
    } else if (name == "tests/data/gsd/VNDR4711.gsd") {
      EXPECT_EQ(line, "18193 4 32 800 -\n");
    } else if (name == "tests/data/gsd/PBVB0AFF.gsd") {
      EXPECT_EQ(line, "2815 0 - 800 76\n");
    }
    std::remove(path.c_str());
  }
}

// Every DP-V1 keyword the model holds (GsdDpv1Features) appears in both outputs. PBVB0A04 sets
// each to a value that differs from its neighbours.
TEST(CmdGsd, EveryDpv1FeatureInText) {
  GsdRun r = run({src("tests/data/gsd/PBVB0A04.gsd")});
  ASSERT_EQ(r.rc, 0) << r.err;
  EXPECT_TRUE(r.err.empty()) << r.err;
  for (const char* line : {
           "DP-V1:              yes",
           "  C1_Read_Write_supp 1, C1_Max_Data_Len 200, C1_Response_Timeout 50",
           "  C2_Read_Write_supp 1, C2_Max_Data_Len 100, C2_Response_Timeout 60, C2_Max_Count_Channels 3",
           "  alarms: Diagnostic 1, Process 0, Pull_Plug 1, Status 0, Update 1, Manufacturer_Specific 0; "
           "Alarm_Sequence_Mode_Count 4",
           "  alarms required: Diagnostic 0, Process 1, Pull_Plug 0, Status 1, Update 0, Manufacturer_Specific 1",
           "  Extra_Alarm_SAP_supp 0, Alarm_Type_Mode_supp 1",
           "  C1_Read_Write_required 0, C2_Read_Write_required 1, Max_Initiate_PDU_Length 64",
           "  WD_Base_1ms_supp 0, Check_Cfg_Mode 1, Ident_Maintenance_supp 0",
           "  DPV1_Data_Types 0, Publisher_supp 1, Time_Sync_supp 1",
           "  Prm_Block_Structure_supp 0, Prm_Block_Structure_req 1, Fail_Safe_required 0",
           "  Isochron_Mode_supp 1, Isochron_Mode_required 0",
       })
    EXPECT_TRUE(has_line(r.out, line)) << line << "\n--- output:\n" << r.out;
  // A DP-V0 file without any DP-V1 keyword gets no DP-V1 details.
  r = run({src("examples/gsd/PBVB0A01.gsd")});
  EXPECT_TRUE(has_line(r.out, "DP-V1:              no"));
  EXPECT_EQ(r.out.find("Isochron_Mode_supp"), std::string::npos);
}

TEST(CmdGsd, EveryDpv1FeatureInJson) {
  GsdRun r = run({src("tests/data/gsd/PBVB0A04.gsd"), "--json"});
  ASSERT_EQ(r.rc, 0) << r.err;
  // 37 keys: one per field of GsdDpv1Features.
  EXPECT_EQ(python_on_json(r.out, sorted_items("d['dpv1']")),
            "alarm_sequence_mode_count=4\n"
            "alarm_type_mode_supp=true\n"
            "c1_max_data_len=200\n"
            "c1_read_write_required=false\n"
            "c1_read_write_supp=true\n"
            "c1_response_timeout=50\n"
            "c2_max_count_channels=3\n"
            "c2_max_data_len=100\n"
            "c2_read_write_required=true\n"
            "c2_read_write_supp=true\n"
            "c2_response_timeout=60\n"
            "check_cfg_mode=true\n"
            "diagnostic_alarm_required=false\n"
            "diagnostic_alarm_supp=true\n"
            "dpv1_data_types=false\n"
            "dpv1_slave=true\n"
            "extra_alarm_sap_supp=false\n"
            "fail_safe_required=false\n"
            "ident_maintenance_supp=false\n"
            "isochron_mode_required=false\n"
            "isochron_mode_supp=true\n"
            "manufacturer_specific_alarm_required=true\n"
            "manufacturer_specific_alarm_supp=false\n"
            "max_initiate_pdu_length=64\n"
            "prm_block_structure_req=true\n"
            "prm_block_structure_supp=false\n"
            "process_alarm_required=true\n"
            "process_alarm_supp=false\n"
            "publisher_supp=true\n"
            "pull_plug_alarm_required=false\n"
            "pull_plug_alarm_supp=true\n"
            "status_alarm_required=true\n"
            "status_alarm_supp=false\n"
            "time_sync_supp=true\n"
            "update_alarm_required=false\n"
            "update_alarm_supp=true\n"
            "wd_base_1ms_supp=false\n");
}

// PROFIsafe module: its F-parameter block (defaults, worked out in gsd_vendor_quirks_test.cpp) and
// description CRCs under the module, the F_ExtUserPrmData definitions with the parameters.
TEST(CmdGsd, ProfisafeModuleText) {
  GsdRun r = run({src("tests/data/gsd/vendor-quirks/profisafe-module.gsd")});
  ASSERT_EQ(r.rc, 0) << r.err;
  EXPECT_TRUE(r.err.empty()) << r.err;
  EXPECT_TRUE(has_line(r.out, "  [1] \"F-DI 2x24V PROFIsafe\" ref 2: cfg 0xC1,0x85,0x85,0x0A, in 6, out 6, "
                              "consistent, prm 01 0A"));
  EXPECT_TRUE(has_line(r.out, "      F-parameters 08 40 00 01 00 64 00 96 4A 2B; F_Ext_Module_Prm_Data_Len 10, "
                              "F_ParamDescCRC 0x1D6E, F_IO_StructureDescCRC 0x0000A3F1"))
      << r.out;
  EXPECT_TRUE(has_line(r.out, "  ExtUserPrmData 2 \"Sensor supply\": Bit(0), default 1, allowed 0-1"));
  EXPECT_TRUE(has_line(r.out, "  F_ExtUserPrmData 2 \"F_Check_iPar\": Bit(1), default 0, allowed 0-1, not changeable"));
  EXPECT_TRUE(has_line(r.out, "  F_ExtUserPrmData 8 \"F_Dest_Add\": Unsigned16, default 100, allowed 1-65534"));
  // The standard module has no F-parameters line.
  EXPECT_EQ(r.out.find("F-parameters"), r.out.rfind("F-parameters"));
}

TEST(CmdGsd, ProfisafeModuleJson) {
  GsdRun r = run({src("tests/data/gsd/vendor-quirks/profisafe-module.gsd"), "--json"});
  ASSERT_EQ(r.rc, 0) << r.err;
  // 0x1D6E = 7534, 0x0000A3F1 = 41969; the block 08 40 00 01 00 64 00 96 4A 2B in decimal.
  EXPECT_EQ(python_on_json(r.out, "json.dumps(d['modules'][0]['f_parameters']), "
                                  "json.dumps(d['modules'][1]['f_parameters'], sort_keys=True)"),
            "null {\"defaults\": [8, 64, 0, 1, 0, 100, 0, 150, 74, 43], \"f_ext_module_prm_data_len\": 10, "
            "\"f_io_structure_desc_crc\": 41969, \"f_param_desc_crc\": 7534}\n");
  EXPECT_EQ(python_on_json(r.out, "len(d['parameters']['f_ext_user_prm_data']), "
                                  "len(d['parameters']['ext_user_prm_data']), "
                                  "[(e['ref'], e['name'], e['default'], e['changeable']) for e in "
                                  "d['parameters']['f_ext_user_prm_data'] if e['ref'] in (3, 8)]"),
            "10 3 [(3, 'F_SIL', 2, True), (8, 'F_Dest_Add', 100, True)]\n");
}

// Every GSD file of the repository (examples, test data, vendor quirks) is read without an error
// by the command, in text and JSON form, and the JSON is one valid document.
TEST(CmdGsd, ReadsEveryGsdFileOfTheRepository) {
  std::vector<std::string> files;
  for (const char* dir : {"examples/gsd", "tests/data/gsd", "tests/data/gsd/vendor-quirks"})
    for (const auto& e : std::filesystem::directory_iterator(src(dir))) {
      std::string ext = e.path().extension().string();
      std::transform(ext.begin(), ext.end(), ext.begin(), ::tolower);
      if (e.is_regular_file() && ext == ".gsd") files.push_back(e.path().string());
    }
  std::sort(files.begin(), files.end());
  EXPECT_GE(files.size(), 10u);
  for (const auto& file : files) {
    GsdRun r = run({file});
    EXPECT_EQ(r.rc, 0) << file << "\n" << r.err;
    EXPECT_TRUE(has_line(r.out, "File:               " + file)) << file;
    r = run({file, "--json"});
    ASSERT_EQ(r.rc, 0) << file << "\n" << r.err;
    EXPECT_EQ(python_on_json(r.out, "d['file']"), file + "\n");
  }
}

// The shipped switched stations (PI 2.212 slave redundancy, §G.7): the redundancy keywords, and
// what pbvbus reads them as (bit 0 System, bit 1 Flying Redundancy; 10 ms units), in text and
// JSON. A file without them says "not supported".
TEST(CmdGsd, SwitchedStationRedundancyText) {
  GsdRun r = run({src("examples/gsd/PBVB0A10.gsd")});
  ASSERT_EQ(r.rc, 0) << r.err;
  EXPECT_TRUE(r.err.empty()) << r.err;
  EXPECT_TRUE(has_line(r.out, "Ident_Number:       0x0A10"));
  EXPECT_TRUE(has_line(r.out, "Redundancy:         Redundancy 0, PrmCmd_supp 1, Slave_Redundancy_supp 1, "
                              "Slave_Max_Switch_Over_Time 3"))
      << r.out;
  EXPECT_TRUE(has_line(r.out, "  slave redundancy: System 1, Flying 0; max switchover 30 ms"));
  EXPECT_TRUE(has_line(r.out, "  Prm_Block_Structure_supp 1, Prm_Block_Structure_req 0, Fail_Safe_required 0"));
  EXPECT_TRUE(has_line(r.out, "  [2] \"4AI U/I 13 bit\" ref 3: cfg 0xD3, in 8, out 0, consistent"));
  EXPECT_TRUE(has_line(r.out, "  12M     MaxTsdr 800"));

  r = run({src("examples/gsd/PBVB0A11.gsd")});
  ASSERT_EQ(r.rc, 0) << r.err;
  EXPECT_TRUE(r.err.empty()) << r.err;
  EXPECT_TRUE(has_line(r.out, "Redundancy:         Redundancy 0, PrmCmd_supp 1, Slave_Redundancy_supp 3, "
                              "Slave_Max_Switch_Over_Time 82"));
  EXPECT_TRUE(has_line(r.out, "  slave redundancy: System 1, Flying 1; max switchover 820 ms"));
  EXPECT_TRUE(has_line(r.out, "  1.5M    MaxTsdr 300"));
  EXPECT_FALSE(has_line(r.out, "  12M     MaxTsdr 800"));

  r = run({src("examples/gsd/PBVB0A01.gsd")});
  EXPECT_TRUE(has_line(r.out, "  slave redundancy: not supported"));
  // Reserved bits are named; the warning goes to stderr.
  r = run({src("tests/data/gsd/VNDR4711.gsd")});
  EXPECT_TRUE(has_line(r.out, "  slave redundancy: System 0, Flying 0, reserved bits 0x08; max switchover 1000 ms"));
  EXPECT_TRUE(has_line(r.err, src("tests/data/gsd/VNDR4711.gsd") +
                                  ":45: warning: Slave_Redundancy_supp 0x08 sets reserved bits (bit 0 = System "
                                  "Redundancy, bit 1 = Flying Redundancy); kept"))
      << r.err;
}

TEST(CmdGsd, SwitchedStationRedundancyJson) {
  GsdRun r = run({src("examples/gsd/PBVB0A10.gsd"), "--json"});
  ASSERT_EQ(r.rc, 0) << r.err;
  EXPECT_EQ(python_on_json(r.out, sorted_items("d['redundancy']")),
            "flying_redundancy=false\n"
            "prm_cmd_supp=true\n"
            "redundancy=false\n"
            "slave_max_switch_over_time=3\n"
            "slave_redundancy_supp=1\n"
            "switch_over_time_ms=30\n"
            "system_redundancy=true\n");
  EXPECT_EQ(python_on_json(r.out, "d['ident_number'], len(d['modules']), d['baud_rates'][0]['max_tsdr']"),
            "2576 3 60\n");
  r = run({src("examples/gsd/PBVB0A11.gsd"), "--json"});
  ASSERT_EQ(r.rc, 0) << r.err;
  EXPECT_EQ(python_on_json(r.out, sorted_items("d['redundancy']")),
            "flying_redundancy=true\n"
            "prm_cmd_supp=true\n"
            "redundancy=false\n"
            "slave_max_switch_over_time=82\n"
            "slave_redundancy_supp=3\n"
            "switch_over_time_ms=820\n"
            "system_redundancy=true\n");
  r = run({src("examples/gsd/PBVB0A01.gsd"), "--json"});
  ASSERT_EQ(r.rc, 0) << r.err;
  EXPECT_EQ(python_on_json(r.out, "d['redundancy']['switch_over_time_ms'], d['redundancy']['system_redundancy']"),
            "None False\n");
}
