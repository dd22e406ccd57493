// The GSD reader (PI 2.122; protocol-facts.md §I.1 syntax, §I.2 keywords). It works in three
// passes: bytes -> UTF-8 text, physical lines -> logical lines (comments and `\` continuations
// removed), logical lines -> statements applied to the model by a small block state machine.
// Semantic checks that need the whole file (references, mandatory keywords) run at the end.
// Decisions where the specification is silent are listed in gsd.hpp.

#include <algorithm>
#include <array>
#include <cctype>
#include <charconv>
#include <cstdio>
#include <fstream>
#include <limits>
#include <sstream>
#include <string>
#include <type_traits>
#include <unordered_map>

#include "pbvbus/gsd/gsd.hpp"

namespace pbvbus::devices {

namespace {

constexpr std::size_t kMaxErrors = 50;
constexpr std::size_t kMaxWarnings = 500;

std::string lower(std::string_view s) {
  std::string r(s);
  for (char& c : r) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return r;
}

bool is_space(char c) { return c == ' ' || c == '\t' || c == '\v' || c == '\f' || c == '\r' || c == '\0'; }

std::string_view trim(std::string_view s) {
  while (!s.empty() && is_space(s.front())) s.remove_prefix(1);
  while (!s.empty() && is_space(s.back())) s.remove_suffix(1);
  return s;
}

// ISO-8859-1 maps byte b to code point b; UTF-8 needs two bytes for 0x80..0xFF.
std::string latin1_to_utf8(std::string_view in) {
  std::string out;
  out.reserve(in.size() + in.size() / 8);
  for (char ch : in) {
    const auto b = static_cast<unsigned char>(ch);
    if (b < 0x80) {
      out += ch;
    } else {
      out += static_cast<char>(0xC0 | (b >> 6));
      out += static_cast<char>(0x80 | (b & 0x3F));
    }
  }
  return out;
}

bool valid_utf8(std::string_view s) {
  std::size_t i = 0;
  while (i < s.size()) {
    const auto b = static_cast<unsigned char>(s[i]);
    std::size_t n = 0;
    std::uint32_t cp = 0;
    if (b < 0x80) {
      ++i;
      continue;
    } else if ((b & 0xE0) == 0xC0) {
      n = 1;
      cp = b & 0x1Fu;
    } else if ((b & 0xF0) == 0xE0) {
      n = 2;
      cp = b & 0x0Fu;
    } else if ((b & 0xF8) == 0xF0) {
      n = 3;
      cp = b & 0x07u;
    } else {
      return false;
    }
    if (s.size() - i <= n) return false;
    for (std::size_t k = 1; k <= n; ++k) {
      const auto c = static_cast<unsigned char>(s[i + k]);
      if ((c & 0xC0) != 0x80) return false;
      cp = (cp << 6) | (c & 0x3Fu);
    }
    static constexpr std::uint32_t kMin[4] = {0, 0x80, 0x800, 0x10000};
    if (cp < kMin[n] || cp > 0x10FFFF || (cp >= 0xD800 && cp <= 0xDFFF)) return false;
    i += n + 1;
  }
  return true;
}

// Baud keyword suffixes as GSD files spell them ("9.6_supp", "MaxTsdr_1.5M").
struct BaudName {
  std::string_view gsd;
  bus::Baud baud;
};
constexpr std::array<BaudName, 11> kBaudNames{{
    {"9.6", bus::Baud::k9_6},     {"19.2", bus::Baud::k19_2},   {"31.25", bus::Baud::k31_25},
    {"45.45", bus::Baud::k45_45}, {"93.75", bus::Baud::k93_75}, {"187.5", bus::Baud::k187_5},
    {"500", bus::Baud::k500},     {"1.5m", bus::Baud::k1_5M},   {"3m", bus::Baud::k3M},
    {"6m", bus::Baud::k6M},       {"12m", bus::Baud::k12M},
}};

std::optional<bus::Baud> baud_from_gsd(std::string_view lower_name) {
  for (const auto& b : kBaudNames)
    if (b.gsd == lower_name) return b.baud;
  return std::nullopt;
}

// A per-baud keyword (lower case): "<rate>_supp" gives kind "_supp"; "maxtsdr_<rate>" and the
// master's "trdy_", "tqui_", "tset_", "tsdi_" give that prefix as the kind.
struct BaudKey {
  std::string_view kind;
  bus::Baud baud;
};
std::optional<BaudKey> split_baud_key(std::string_view k) {
  static constexpr std::array<std::string_view, 5> kPrefixes = {"maxtsdr_", "trdy_", "tqui_", "tset_", "tsdi_"};
  constexpr std::string_view kSupp = "_supp";
  if (k.size() > kSupp.size() && k.substr(k.size() - kSupp.size()) == kSupp)
    if (auto b = baud_from_gsd(k.substr(0, k.size() - kSupp.size()))) return BaudKey{kSupp, *b};
  for (std::string_view prefix : kPrefixes)
    if (k.size() > prefix.size() && k.substr(0, prefix.size()) == prefix)
      if (auto b = baud_from_gsd(k.substr(prefix.size()))) return BaudKey{prefix, *b};
  return std::nullopt;
}

std::string gsd_baud_spelling(bus::Baud b) {
  for (const auto& n : kBaudNames)
    if (n.baud == b) {
      std::string s(n.gsd);
      if (!s.empty() && s.back() == 'm') s.back() = 'M';
      return s;
    }
  return "?";
}


// Keywords that take a plain value and map onto one field of the model.
enum class Kind { Bool, Uint, String };
struct ScalarKeyword {
  std::string_view name;  // canonical spelling, used in messages
  Kind kind;
  std::uint64_t max;  // for Uint
  void (*set_uint)(GsdFile&, std::uint64_t);
  std::string& (*string_field)(GsdFile&);
};

}  // namespace

class GsdParser {
 public:
  GsdParser(std::string_view bytes, std::string_view file_name) : m_bytes(bytes) {
    m_result_file.m_file_name = std::string(file_name);
    m_file = std::string(file_name);
  }

  GsdParseResult run();

 private:
  struct Stmt {
    std::string keyword;  // as written
    std::string key;      // lower case
    bool has_index = false;
    std::string index;
    bool has_eq = false;
    std::string value;  // after '=' (or the rest of the line when there is no '=')
    std::uint32_t line = 0;
  };

  enum class Block { Top, Module, PrmText, ExtPrm, DiagArea, DiagType, Slots, Opaque, UnknownX };
  struct OpenBlock {
    Block kind = Block::Top;
    std::string end;    // the end keyword as PI 2.122 spells it
    std::uint32_t line = 0;
    std::string title;  // Opaque and UnknownX blocks: the keyword that opened it
  };

  // --- messages
  void error(std::uint32_t line, std::string reason) {
    if (m_errors.size() < kMaxErrors) m_errors.push_back({m_file, line, std::move(reason)});
  }
  void warning(std::uint32_t line, std::string reason) {
    if (m_warnings.size() < kMaxWarnings) m_warnings.push_back({m_file, line, std::move(reason)});
  }
  bool too_many_errors() const { return m_errors.size() >= kMaxErrors; }

  // --- lexical
  std::string decode();
  void split_logical(const std::string& text);
  std::optional<Stmt> parse_stmt(std::string_view text, std::uint32_t line);

  // --- values
  std::optional<std::int64_t> number(std::string_view tok, std::uint32_t line);
  std::optional<std::uint64_t> unsigned_value(const Stmt& s, std::string_view name, std::uint64_t max);
  std::optional<bool> boolean(const Stmt& s, std::string_view name);
  std::optional<std::string> quoted(std::string_view v, std::uint32_t line, std::string* rest);
  std::optional<std::string> string_value(const Stmt& s, std::string_view name);
  std::optional<GsdBytes> byte_list(std::string_view v, std::uint32_t line, std::string_view what);
  std::optional<std::uint16_t> index_value(const Stmt& s, std::uint64_t max);
  bool need_value(const Stmt& s);

  // --- statements
  void statement(const Stmt& s);
  void top(const Stmt& s);
  void in_module(const Stmt& s);
  void in_prm_text(const Stmt& s);
  void in_ext_prm(const Stmt& s);
  void in_diag_area(const Stmt& s);
  void in_diag_type(const Stmt& s);
  void open_diag_area(const Stmt& s);
  bool diag_bit_text(const Stmt& s, GsdDiagBitTexts& texts, bool plain);
  void index_statements();
  bool unknown_x_block(const Stmt& s);
  void in_slots(const Stmt& s);
  bool scalar(const Stmt& s);
  bool baud_keyword(const Stmt& s);
  bool data_length_limit(const Stmt& s);
  void prm_const(const Stmt& s, GsdPrmArea& area);
  void prm_ref(const Stmt& s, GsdPrmArea& area);
  void data_type_line(const Stmt& s);
  std::string ext_what() const;
  bool f_parameter(const Stmt& s);
  bool block_start(const Stmt& s) const;
  static bool end_keyword(std::string_view key);
  static bool top_level_keyword(std::string_view key);
  static bool module_keyword(std::string_view key);
  Block block() const { return m_open.empty() ? Block::Top : m_open.back().kind; }
  void open_block(Block kind, std::string end, std::uint32_t line, std::string title = {});
  std::string block_title(const OpenBlock& b) const;
  bool own_end(const OpenBlock& b, std::string_view key) const;
  bool leaves_block(const Stmt& s) const;
  void unterminated(const Stmt& s);
  void unknown(const Stmt& s, std::string_view where);
  void defined_twice(std::uint32_t line, const std::string& what, std::uint32_t first_line);
  void remember(const Stmt& s);
  void correct_spelling(Stmt& s);
  void close_block_at_end();
  void check_f_block(const GsdModule& m);
  void finish();
  static const std::unordered_map<std::string, ScalarKeyword>& table();

  std::string m_file;
  std::string_view m_bytes;
  GsdFile m_result_file;
  std::vector<GsdMessage> m_errors;
  std::vector<GsdMessage> m_warnings;
  std::uint32_t m_section_line = 0;
  std::vector<std::pair<std::string, std::uint32_t>> m_logical;

  // Open blocks, innermost last (only a Data_Area nests, inside a Module); empty at the top.
  std::vector<OpenBlock> m_open;
  // End keyword (lower case) of the last block ended by a statement that cannot be inside it:
  // its real end keyword may still follow and is then not reported a second time.
  std::string m_dangling_end;
  std::size_t m_module_stmts = 0;
  GsdModule m_module;
  GsdPrmText m_prm_text;
  GsdExtUserPrmData m_ext;
  bool m_ext_f = false;  // the block is an F_ExtUserPrmData (PROFIsafe) definition
  bool m_ext_has_type = false;
  GsdUnitDiagArea m_diag_area;
  GsdUnitDiagType m_diag_type;

  // Look-ahead for unknown X_ blocks: the position of the statement being read in m_logical, the
  // positions of every X_..._End statement by keyword (lower case), and of every block boundary.
  std::size_t m_pos = 0;
  std::unordered_map<std::string, std::vector<std::size_t>> m_x_ends;
  std::vector<std::size_t> m_boundaries;

  std::unordered_map<std::string, std::uint32_t> m_seen;  // key(+index) -> line
  std::map<bus::Baud, std::uint32_t> m_supp_line;         // supported (= 1) rates
  std::map<bus::Baud, std::uint16_t> m_max_tsdr;
};


// ---------------------------------------------------------------------------------------------
// Keyword table

const std::unordered_map<std::string, ScalarKeyword>& GsdParser::table() {
  // Lambdas written here share GsdParser's access to GsdFile's members.
#define PBV_U(NAME, MAX, FIELD)                                                                  \
  ScalarKeyword {                                                                                \
    NAME, Kind::Uint, MAX,                                                                       \
        [](GsdFile& f, std::uint64_t v) { f.FIELD = static_cast<std::remove_reference_t<decltype(f.FIELD)>>(v); }, \
        nullptr                                                                                  \
  }
#define PBV_OPT(NAME, MAX, FIELD)                                                                \
  ScalarKeyword {                                                                                \
    NAME, Kind::Uint, MAX,                                                                       \
        [](GsdFile& f, std::uint64_t v) { f.FIELD = static_cast<typename decltype(f.FIELD)::value_type>(v); }, \
        nullptr                                                                                  \
  }
#define PBV_B(NAME, FIELD) \
  ScalarKeyword { NAME, Kind::Bool, 1, [](GsdFile& f, std::uint64_t v) { f.FIELD = v != 0; }, nullptr }
#define PBV_S(NAME, FIELD) \
  ScalarKeyword { NAME, Kind::String, 0, nullptr, [](GsdFile& f) -> std::string& { return f.FIELD; } }
  static const std::unordered_map<std::string, ScalarKeyword> kTable = [] {
    const ScalarKeyword list[] = {
        // Identification
        PBV_U("GSD_Revision", 255, m_info.gsd_revision),
        PBV_S("Vendor_Name", m_info.vendor_name),
        PBV_S("Model_Name", m_info.model_name),
        PBV_S("Revision", m_info.revision),
        PBV_OPT("Revision_Number", 63, m_info.revision_number),
        PBV_U("Ident_Number", 0xFFFF, m_info.ident_number),
        PBV_U("Protocol_Ident", 255, m_info.protocol_ident),
        PBV_U("Station_Type", 1, m_info.station_type),
        PBV_B("FMS_supp", m_info.fms_supp),
        PBV_S("Hardware_Release", m_info.hardware_release),
        PBV_S("Software_Release", m_info.software_release),
        PBV_S("OrderNumber", m_info.order_number),
        PBV_S("Info_Text", m_info.info_text),
        PBV_S("Implementation_Type", m_info.implementation_type),
        // DP-V0 slave features
        PBV_B("Freeze_Mode_supp", m_slave.freeze_mode_supp),
        PBV_B("Sync_Mode_supp", m_slave.sync_mode_supp),
        PBV_B("Auto_Baud_supp", m_slave.auto_baud_supp),
        PBV_B("Set_Slave_Add_supp", m_slave.set_slave_add_supp),
        PBV_B("Fail_Safe", m_slave.fail_safe),
        PBV_U("Repeater_Ctrl_Sig", 2, m_slave.repeater_ctrl_sig),
        PBV_U("24V_Pins", 2, m_slave.pins_24v),
        PBV_U("Min_Slave_Intervall", 0xFFFF, m_slave.min_slave_intervall),
        PBV_U("Max_Diag_Data_Len", 244, m_slave.max_diag_data_len),
        PBV_B("Modular_Station", m_slave.modular_station),
        PBV_U("Max_Module", 255, m_slave.max_module),
        PBV_U("Modul_Offset", 255, m_slave.modul_offset),
        // DP-V1
        PBV_B("DPV1_Slave", m_dpv1.dpv1_slave),
        PBV_B("C1_Read_Write_supp", m_dpv1.c1_read_write_supp),
        PBV_B("C1_Read_Write_required", m_dpv1.c1_read_write_required),
        PBV_U("C1_Max_Data_Len", 240, m_dpv1.c1_max_data_len),
        PBV_U("C1_Response_Timeout", 0xFFFF, m_dpv1.c1_response_timeout),
        PBV_B("C2_Read_Write_supp", m_dpv1.c2_read_write_supp),
        PBV_B("C2_Read_Write_required", m_dpv1.c2_read_write_required),
        PBV_U("C2_Max_Data_Len", 240, m_dpv1.c2_max_data_len),
        PBV_U("C2_Response_Timeout", 0xFFFF, m_dpv1.c2_response_timeout),
        PBV_U("C2_Max_Count_Channels", 32, m_dpv1.c2_max_count_channels),
        PBV_U("Max_Initiate_PDU_Length", 244, m_dpv1.max_initiate_pdu_length),
        PBV_B("Diagnostic_Alarm_supp", m_dpv1.diagnostic_alarm_supp),
        PBV_B("Process_Alarm_supp", m_dpv1.process_alarm_supp),
        PBV_B("Pull_Plug_Alarm_supp", m_dpv1.pull_plug_alarm_supp),
        PBV_B("Status_Alarm_supp", m_dpv1.status_alarm_supp),
        PBV_B("Update_Alarm_supp", m_dpv1.update_alarm_supp),
        PBV_B("Manufacturer_Specific_Alarm_supp", m_dpv1.manufacturer_specific_alarm_supp),
        PBV_B("Diagnostic_Alarm_required", m_dpv1.diagnostic_alarm_required),
        PBV_B("Process_Alarm_required", m_dpv1.process_alarm_required),
        PBV_B("Pull_Plug_Alarm_required", m_dpv1.pull_plug_alarm_required),
        PBV_B("Status_Alarm_required", m_dpv1.status_alarm_required),
        PBV_B("Update_Alarm_required", m_dpv1.update_alarm_required),
        PBV_B("Manufacturer_Specific_Alarm_required", m_dpv1.manufacturer_specific_alarm_required),
        PBV_B("Extra_Alarm_SAP_supp", m_dpv1.extra_alarm_sap_supp),
        PBV_B("Alarm_Type_Mode_supp", m_dpv1.alarm_type_mode_supp),
        PBV_U("Alarm_Sequence_Mode_Count", 32, m_dpv1.alarm_sequence_mode_count),
        PBV_B("WD_Base_1ms_supp", m_dpv1.wd_base_1ms_supp),
        PBV_B("Check_Cfg_Mode", m_dpv1.check_cfg_mode),
        PBV_B("DPV1_Data_Types", m_dpv1.dpv1_data_types),
        PBV_B("Publisher_supp", m_dpv1.publisher_supp),
        PBV_B("Ident_Maintenance_supp", m_dpv1.ident_maintenance_supp),
        PBV_B("Time_Sync_supp", m_dpv1.time_sync_supp),
        PBV_B("Prm_Block_Structure_supp", m_dpv1.prm_block_structure_supp),
        PBV_B("Prm_Block_Structure_req", m_dpv1.prm_block_structure_req),
        PBV_B("Fail_Safe_required", m_dpv1.fail_safe_required),
        PBV_B("Isochron_Mode_supp", m_dpv1.isochron_mode_supp),
        PBV_B("Isochron_Mode_required", m_dpv1.isochron_mode_required),
        // Redundancy (§G.7)
        PBV_B("Redundancy", m_redundancy.redundancy),
        PBV_B("PrmCmd_supp", m_redundancy.prm_cmd_supp),
        PBV_U("Slave_Redundancy_supp", 255, m_redundancy.slave_redundancy_supp),
        PBV_U("Slave_Max_Switch_Over_Time", 0xFFFF, m_redundancy.slave_max_switch_over_time),
        // Master GSD
        PBV_OPT("Max_Slaves_supp", 125, m_master.max_slaves_supp),
        PBV_OPT("LAS_Len", 255, m_master.las_len),
        PBV_OPT("Min_Poll_Timeout", 0xFFFF, m_master.min_poll_timeout),
        PBV_OPT("Max_MPS_Length", 255, m_master.max_mps_length),
        PBV_OPT("Max_Lsdu_MS", 255, m_master.max_lsdu_ms),
        PBV_OPT("Max_Lsdu_MM", 255, m_master.max_lsdu_mm),
        PBV_B("DPV1_Master", m_master.dpv1_master),
        PBV_B("C1_Master_Read_Write_supp", m_master.c1_master_read_write_supp),
        PBV_B("Master_Diagnostic_Alarm_supp", m_master.master_diagnostic_alarm_supp),
        PBV_B("Master_Process_Alarm_supp", m_master.master_process_alarm_supp),
        PBV_B("Master_Pull_Plug_Alarm_supp", m_master.master_pull_plug_alarm_supp),
        PBV_B("Master_Status_Alarm_supp", m_master.master_status_alarm_supp),
        PBV_B("Master_Update_Alarm_supp", m_master.master_update_alarm_supp),
        PBV_B("Master_Manufacturer_Specific_Alarm_supp", m_master.master_manufacturer_specific_alarm_supp),
        PBV_B("Master_Freeze_Mode_supp", m_master.master_freeze_mode_supp),
        PBV_B("Master_Sync_Mode_supp", m_master.master_sync_mode_supp),
        PBV_B("Master_Fail_Safe_supp", m_master.master_fail_safe_supp),
        PBV_B("Download_supp", m_master.download_supp),
        PBV_B("Upload_supp", m_master.upload_supp),
        PBV_B("Act_Para_Brct_supp", m_master.act_para_brct_supp),
        PBV_B("Act_Param_supp", m_master.act_param_supp),
    };
    std::unordered_map<std::string, ScalarKeyword> m;
    for (const auto& k : list) m.emplace(lower(k.name), k);
    return m;
  }();
#undef PBV_U
#undef PBV_OPT
#undef PBV_B
#undef PBV_S
  return kTable;
}

namespace {

// Keywords of PI 2.122 that the model does not interpret; kept raw, no warning.
bool known_raw(std::string_view key) {
  static const std::array<std::string_view, 39> kKnown = {
      "bitmap_device",        "bitmap_diag",          "bitmap_sf",
      "unit_diag_not_bit",    "x_unit_diag_bit",      "x_unit_diag_not_bit",
      "unit_diag_bit_help",   "x_unit_diag_bit_help", "unit_diag_not_bit_help",
      "channel_diag_help",    "diag_update_delay",    "tbase_dp",
      "tdp_max",              "tdp_min",              "tbase_io",
      "tio_input",            "tio_output",           "to_min",
      "ti_min",               "t_pll_w_max",          "fixpresetmodules",
      "preset",               "max_master_input_len", "max_master_output_len",
      "max_master_data_len",  "dxb_max_link_count",   "dxb_max_data_length",
      "dxb_subscribertable_block_location", "isom_sync_mode_supp", "subsys_dir_index",
      "subsys_module_dir_index", "max_iso_input_len",  "max_iso_output_len",
      "info_text_help",       "webpage",              "gsd_file_version",
      "x_channel_diag",       "prm_text_help",        "order_number",
  };
  return std::find(kKnown.begin(), kKnown.end(), key) != kKnown.end();
}

bool known_module_raw(std::string_view key) {
  static const std::array<std::string_view, 14> kKnown = {
      "x_ext_module_prm_data_len", "x_ext_user_prm_data_const", "x_ext_user_prm_data_ref",
      "preset",                    "channel_diag",              "module_reference",
      "ordernumber",               "bitmap_device",             "alarm_type_mode_supp",
      "ident_maintenance_supp",    "channel_diag_help",         "info_text_help",
      "subsys_module_dir_index",   "order_number",
  };
  return std::find(kKnown.begin(), kKnown.end(), key) != kKnown.end();
}

bool ends_with(std::string_view s, std::string_view suffix) {
  return s.size() >= suffix.size() && s.substr(s.size() - suffix.size()) == suffix;
}

std::string shorten(std::string_view s) {
  if (s.size() <= 40) return std::string(s);
  return std::string(s.substr(0, 40)) + "...";
}

}  // namespace

bool GsdParser::end_keyword(std::string_view key) {
  static const std::array<std::string_view, 9> kEnds = {
      "endmodule", "endprmtext", "endextuserprmdata", "endf_extuserprmdata", "unit_diag_area_end",
      "x_unit_diag_area_end", "endslotdefinition", "endunitdiagtype", "end_physical_interface"};
  return std::find(kEnds.begin(), kEnds.end(), key) != kEnds.end();
}

// Keywords the reader knows at the top level of the #Profibus_DP section. Help texts (*_help)
// are left out: they may accompany an item inside a block.
bool GsdParser::top_level_keyword(std::string_view key) {
  if (ends_with(key, "_help")) return false;
  static const std::array<std::string_view, 13> kOthers = {
      "unit_diag_bit", "channel_diag", "ext_user_prm_data_const", "ext_user_prm_data_ref",
      "user_prm_data", "user_prm_data_len", "max_user_prm_data_len", "slave_family",
      "max_input_len", "max_output_len", "max_data_len", "min_slave_interval", "wb_base_1ms_supp"};
  return table().count(std::string(key)) != 0 || split_baud_key(key).has_value() || known_raw(key) ||
         std::find(kOthers.begin(), kOthers.end(), key) != kOthers.end();
}

// Keywords PI 2.122 allows inside a Module (modelled or kept raw); several of them are top-level
// keywords too. Alarm requirements may be given per module [U]: accepted there.
bool GsdParser::module_keyword(std::string_view key) {
  static const std::array<std::string_view, 10> kModelled = {
      "ext_module_prm_data_len",   "ext_user_prm_data_const",   "ext_user_prm_data_ref",
      "f_ext_module_prm_data_len", "f_ext_user_prm_data_const", "f_ext_user_prm_data_ref",
      "f_paramdesccrc",            "f_io_structuredesccrc",     "info_text",
      "data_area_beg"};
  return known_module_raw(key) || std::find(kModelled.begin(), kModelled.end(), key) != kModelled.end() ||
         ends_with(key, "_alarm_required") || ends_with(key, "_alarm_supp");
}

// ---------------------------------------------------------------------------------------------
// Lexical passes

std::string GsdParser::decode() {
  std::string_view b = m_bytes;
  if (b.size() >= 3 && static_cast<unsigned char>(b[0]) == 0xEF &&
      static_cast<unsigned char>(b[1]) == 0xBB && static_cast<unsigned char>(b[2]) == 0xBF) {
    b.remove_prefix(3);
    if (valid_utf8(b)) {
      warning(1, "file starts with a UTF-8 byte order mark: read as UTF-8, not ISO-8859-1");
      return std::string(b);
    }
    warning(1, "UTF-8 byte order mark but invalid UTF-8: read as ISO-8859-1");
  }
  return latin1_to_utf8(b);
}

void GsdParser::split_logical(const std::string& text) {
  std::vector<std::string_view> phys;
  {
    std::size_t start = 0;
    std::string_view t(text);
    for (std::size_t i = 0; i < t.size(); ++i) {
      if (t[i] == '\n' || t[i] == '\r') {
        phys.push_back(t.substr(start, i - start));
        if (t[i] == '\r' && i + 1 < t.size() && t[i + 1] == '\n') ++i;
        start = i + 1;
      }
    }
    if (start < t.size()) phys.push_back(t.substr(start));
  }

  std::size_t first = phys.size();
  for (std::size_t i = 0; i < phys.size(); ++i) {
    const std::string l = lower(trim(phys[i]));
    if (l.rfind("#profibus_dp", 0) == 0 &&
        (l.size() == 12 || is_space(l[12]) || l[12] == ';')) {
      first = i;
      break;
    }
  }
  if (first == phys.size()) {
    error(0, "#Profibus_DP section missing");
    return;
  }
  m_section_line = static_cast<std::uint32_t>(first + 1);

  std::string acc;
  bool continuing = false;
  bool in_quote = false;
  std::uint32_t start_line = 0;
  auto emit = [&]() {
    if (in_quote) {
      error(start_line, "unterminated string");
      in_quote = false;
    } else if (!trim(acc).empty()) {
      m_logical.emplace_back(acc, start_line);
    }
    acc.clear();
    continuing = false;
  };
  for (std::size_t i = first + 1; i < phys.size(); ++i) {
    const auto lineno = static_cast<std::uint32_t>(i + 1);
    std::string_view line = phys[i];
    const bool quote_at_start = in_quote;
    if (!continuing) {
      start_line = lineno;
      const std::string_view t = trim(line);
      if (!t.empty() && t.front() == '#') {
        warning(lineno, "section '" + shorten(t) + "' ignored (only #Profibus_DP is read)");
        break;
      }
    }
    std::string part;
    part.reserve(line.size());
    for (char c : line) {
      if (c == '"') {
        in_quote = !in_quote;
      } else if (c == ';' && !in_quote) {
        break;
      }
      part += c;
    }
    std::string_view p = part;
    while (!p.empty() && is_space(p.back())) p.remove_suffix(1);
    if (continuing && !quote_at_start)
      while (!p.empty() && is_space(p.front())) p.remove_prefix(1);
    if (!p.empty() && p.back() == '\\') {
      p.remove_suffix(1);
      acc += p;
      if (!in_quote) acc += ' ';
      continuing = true;
      continue;
    }
    acc += p;
    emit();
  }
  if (continuing) emit();
}

std::optional<GsdParser::Stmt> GsdParser::parse_stmt(std::string_view text, std::uint32_t line) {
  const std::string_view t = trim(text);
  std::size_t i = 0;
  auto kw_char = [](char c) {
    return std::isalnum(static_cast<unsigned char>(c)) != 0 || c == '_' || c == '.';
  };
  while (i < t.size() && kw_char(t[i])) ++i;
  if (i == 0) {
    error(line, "expected a keyword, found '" + shorten(t) + "'");
    return std::nullopt;
  }
  Stmt s;
  s.line = line;
  s.keyword = std::string(t.substr(0, i));
  s.key = lower(s.keyword);
  std::size_t j = i;
  while (j < t.size() && is_space(t[j])) ++j;
  if (j < t.size() && t[j] == '(') {
    const std::size_t close = t.find(')', j);
    if (close == std::string_view::npos) {
      error(line, "missing ')' after '" + s.keyword + "('");
      return std::nullopt;
    }
    s.has_index = true;
    s.index = std::string(trim(t.substr(j + 1, close - j - 1)));
    j = close + 1;
    while (j < t.size() && is_space(t[j])) ++j;
  }
  if (j < t.size() && t[j] == '=') {
    s.has_eq = true;
    s.value = std::string(trim(t.substr(j + 1)));
  } else {
    s.value = std::string(trim(t.substr(j)));
  }
  return s;
}

// ---------------------------------------------------------------------------------------------
// Values

std::optional<std::int64_t> GsdParser::number(std::string_view tok, std::uint32_t line) {
  tok = trim(tok);
  std::string_view digits = tok;
  bool negative = false;
  if (!digits.empty() && (digits.front() == '-' || digits.front() == '+')) {
    negative = digits.front() == '-';
    digits.remove_prefix(1);
  }
  int base = 10;
  if (digits.size() > 2 && digits[0] == '0' && (digits[1] == 'x' || digits[1] == 'X')) {
    base = 16;
    digits.remove_prefix(2);
  }
  std::uint64_t v = 0;
  const char* end = digits.data() + digits.size();
  auto [p, ec] = std::from_chars(digits.data(), end, v, base);
  if (digits.empty() || p != end || ec == std::errc::invalid_argument) {
    if (tok.empty())
      error(line, "value missing");
    else
      error(line, "value '" + shorten(tok) + "' is not a number");
    return std::nullopt;
  }
  if (ec == std::errc::result_out_of_range || v > (std::uint64_t{1} << 40)) {
    error(line, "value '" + shorten(tok) + "' out of range");
    return std::nullopt;
  }
  const auto sv = static_cast<std::int64_t>(v);
  return negative ? -sv : sv;
}

bool GsdParser::need_value(const Stmt& s) {
  if (s.has_eq) return true;
  error(s.line, "expected '=' after '" + s.keyword + (s.has_index ? "(" + s.index + ")" : "") + "'");
  return false;
}

std::optional<std::uint64_t> GsdParser::unsigned_value(const Stmt& s, std::string_view name,
                                                       std::uint64_t max) {
  if (!need_value(s)) return std::nullopt;
  auto v = number(s.value, s.line);
  if (!v) return std::nullopt;
  if (*v < 0 || static_cast<std::uint64_t>(*v) > max) {
    error(s.line, "value " + s.value + " out of range for " + std::string(name) + " (0.." +
                      std::to_string(max) + ")");
    return std::nullopt;
  }
  return static_cast<std::uint64_t>(*v);
}

std::optional<bool> GsdParser::boolean(const Stmt& s, std::string_view name) {
  if (!need_value(s)) return std::nullopt;
  auto v = number(s.value, s.line);
  if (!v) return std::nullopt;
  if (*v != 0 && *v != 1) {
    error(s.line, "value " + s.value + " of " + std::string(name) + " is not a boolean (0 or 1)");
    return std::nullopt;
  }
  return *v == 1;
}

std::optional<std::string> GsdParser::quoted(std::string_view v, std::uint32_t line, std::string* rest) {
  v = trim(v);
  if (v.empty() || v.front() != '"') {
    error(line, "expected a quoted string, found '" + shorten(v) + "'");
    return std::nullopt;
  }
  const std::size_t close = v.find('"', 1);
  if (close == std::string_view::npos) {
    error(line, "unterminated string");
    return std::nullopt;
  }
  std::string s(v.substr(1, close - 1));
  const std::string_view after = trim(v.substr(close + 1));
  if (rest) {
    *rest = std::string(after);
  } else if (!after.empty()) {
    error(line, "unexpected '" + shorten(after) + "' after the string");
    return std::nullopt;
  }
  return s;
}

std::optional<std::string> GsdParser::string_value(const Stmt& s, std::string_view) {
  if (!need_value(s)) return std::nullopt;
  return quoted(s.value, s.line, nullptr);
}

std::optional<GsdBytes> GsdParser::byte_list(std::string_view v, std::uint32_t line, std::string_view what) {
  GsdBytes out;
  v = trim(v);
  if (v.empty()) return out;
  while (true) {
    const std::size_t comma = v.find(',');
    const std::string_view tok = trim(v.substr(0, comma));
    if (tok.empty()) {
      error(line, "empty entry in a list of " + std::string(what) + "s");
      return std::nullopt;
    }
    auto n = number(tok, line);
    if (!n) return std::nullopt;
    if (*n < 0 || *n > 255) {
      error(line, std::string(what) + " " + std::string(tok) + " out of range");
      return std::nullopt;
    }
    out.push_back(static_cast<std::uint8_t>(*n));
    if (comma == std::string_view::npos) break;
    v.remove_prefix(comma + 1);
  }
  return out;
}

std::optional<std::uint16_t> GsdParser::index_value(const Stmt& s, std::uint64_t max) {
  if (!s.has_index) {
    error(s.line, "'" + s.keyword + "' needs an index: " + s.keyword + "(n)");
    return std::nullopt;
  }
  auto v = number(s.index, s.line);
  if (!v) return std::nullopt;
  if (*v < 0 || static_cast<std::uint64_t>(*v) > max) {
    error(s.line, "index " + s.index + " of " + s.keyword + " out of range (0.." + std::to_string(max) + ")");
    return std::nullopt;
  }
  return static_cast<std::uint16_t>(*v);
}

// ---------------------------------------------------------------------------------------------
// Statements

namespace {

bool block_start_key(std::string_view key) {
  static const std::array<std::string_view, 9> kStarts = {
      "module", "prmtext", "extuserprmdata", "f_extuserprmdata", "slotdefinition", "unit_diag_area",
      "x_unit_diag_area", "unitdiagtype", "physical_interface"};
  return std::find(kStarts.begin(), kStarts.end(), key) != kStarts.end();
}

// The keyword a logical line starts with, lower case (the look-ahead needs no full statement).
std::string leading_key(std::string_view text) {
  text = trim(text);
  std::size_t i = 0;
  while (i < text.size() && (std::isalnum(static_cast<unsigned char>(text[i])) != 0 || text[i] == '_' || text[i] == '.'))
    ++i;
  return lower(text.substr(0, i));
}

}  // namespace

bool GsdParser::block_start(const Stmt& s) const { return block_start_key(s.key); }

// Positions for unknown_x_block(): every X_..._End statement, and every block boundary (block
// starts and end keywords, Data_Area included), so that each look-ahead is two binary searches.
void GsdParser::index_statements() {
  for (std::size_t i = 0; i < m_logical.size(); ++i) {
    const std::string key = leading_key(m_logical[i].first);
    if (block_start_key(key) || end_keyword(key) || key == "data_area_beg" || key == "data_area_end")
      m_boundaries.push_back(i);
    else if (key.rfind("x_", 0) == 0 && ends_with(key, "_end"))
      m_x_ends[key].push_back(i);
  }
}

// An unknown X_<name> followed by X_<name>_End before the next block boundary: a block of a later
// GSD revision (decision in gsd.hpp). One warning; the content is skipped up to its end.
bool GsdParser::unknown_x_block(const Stmt& s) {
  if (s.key.rfind("x_", 0) != 0 || block_start(s) || end_keyword(s.key) || top_level_keyword(s.key) ||
      module_keyword(s.key) || s.key == "x_value" || s.key == "x_value_help" ||
      s.key == "x_unit_diag_bit_help" || s.key == "x_unit_diag_not_bit_help")
    return false;
  const auto ends = m_x_ends.find(s.key + "_end");
  if (ends == m_x_ends.end()) return false;
  const auto end = std::upper_bound(ends->second.begin(), ends->second.end(), m_pos);
  if (end == ends->second.end()) return false;
  const auto boundary = std::upper_bound(m_boundaries.begin(), m_boundaries.end(), m_pos);
  if (boundary != m_boundaries.end() && *boundary < *end) return false;
  const auto& [end_text, end_line] = m_logical[*end];
  const std::string_view t = trim(end_text);
  const std::string end_keyword_written(t.substr(0, s.key.size() + 4));
  m_result_file.m_unknown.push_back({s.keyword, s.index, s.value, s.line});
  warning(s.line, "unknown block '" + s.keyword + "' ... '" + end_keyword_written + "' (line " +
                      std::to_string(end_line) + ") kept, not interpreted");
  open_block(Block::UnknownX, end_keyword_written, s.line, s.keyword);
  return true;
}

void GsdParser::unknown(const Stmt& s, std::string_view where) {
  GsdKeyword k{s.keyword, s.index, s.value, s.line};
  m_result_file.m_unknown.push_back(k);
  warning(s.line, "unknown keyword '" + s.keyword + "'" + std::string(where) + " kept");
}

// Vendor files repeat a PrmText or ExtUserPrmData number (copied blocks); like a repeated
// keyword, the later definition replaces the earlier one and the file stays usable.
void GsdParser::defined_twice(std::uint32_t line, const std::string& what, std::uint32_t first_line) {
  warning(line, what + " defined twice (first at line " + std::to_string(first_line) +
                    "); the later definition wins");
}

void GsdParser::remember(const Stmt& s) {
  m_result_file.m_keywords.push_back({s.keyword, s.index, s.value, s.line});
}

void GsdParser::statement(const Stmt& s) {
  if (block() == Block::UnknownX) {
    if (own_end(m_open.back(), s.key)) m_open.pop_back();
    return;  // the content of a block the reader does not know is not interpreted
  }
  if (unknown_x_block(s)) return;
  if (block() != Block::Top && leaves_block(s)) {
    unterminated(s);
    return;
  }
  switch (block()) {
    case Block::Top: top(s); break;
    case Block::Module: in_module(s); break;
    case Block::PrmText: in_prm_text(s); break;
    case Block::ExtPrm: in_ext_prm(s); break;
    case Block::DiagArea: in_diag_area(s); break;
    case Block::DiagType: in_diag_type(s); break;
    case Block::Slots: in_slots(s); break;
    case Block::Opaque:
      if (own_end(m_open.back(), s.key)) m_open.pop_back();
      break;
    case Block::UnknownX: break;  // handled above
  }
}

void GsdParser::open_block(Block kind, std::string end, std::uint32_t line, std::string title) {
  m_open.push_back({kind, std::move(end), line, std::move(title)});
  m_dangling_end.clear();
}

std::string GsdParser::block_title(const OpenBlock& b) const {
  switch (b.kind) {
    case Block::Module: return "Module '" + m_module.name + "'";
    case Block::PrmText: return "PrmText " + std::to_string(m_prm_text.ref);
    case Block::ExtPrm: return ext_what();
    case Block::DiagArea: return m_diag_area.x_variant ? "X_Unit_Diag_Area" : "Unit_Diag_Area";
    case Block::Slots: return "SlotDefinition";
    case Block::Top:
    case Block::DiagType:
    case Block::Opaque:
    case Block::UnknownX: break;
  }
  return b.title;
}

bool GsdParser::own_end(const OpenBlock& b, std::string_view key) const {
  // Either diagnosis-area end closes either variant, as files mix them.
  if (b.kind == Block::DiagArea) return key == "unit_diag_area_end" || key == "x_unit_diag_area_end";
  return key == lower(b.end);
}

// A statement that cannot be inside the open block: the block's end keyword is missing. Block
// starts and other blocks' end keywords never belong inside a block; keywords of the top level
// end the blocks whose content the reader knows (a Module accepts the keywords PI 2.122 allows in
// it even where they are top-level keywords too). Opaque blocks end only at a block boundary.
bool GsdParser::leaves_block(const Stmt& s) const {
  const OpenBlock& b = m_open.back();
  if (own_end(b, s.key)) return false;
  // A UnitDiagType holds its diagnosis areas (GSD revision 5, gsd.hpp GsdUnitDiagType).
  if (b.kind == Block::DiagType && (s.key == "unit_diag_area" || s.key == "x_unit_diag_area")) return false;
  if (block_start(s) || end_keyword(s.key)) return true;
  switch (b.kind) {
    case Block::Opaque:
    case Block::DiagType:
    case Block::UnknownX: return false;
    case Block::Module: return top_level_keyword(s.key) && !module_keyword(s.key);
    default: return top_level_keyword(s.key);
  }
}

// Reported once, at the line that opened the block, with the statement that showed the end
// missing; the statement then counts where it belongs. A wrong end keyword is taken as the end
// of this block (so that it is not reported again as an end without its block).
void GsdParser::unterminated(const Stmt& s) {
  const OpenBlock b = m_open.back();
  const bool is_end = end_keyword(s.key);
  error(b.line, block_title(b) + " without " + b.end + "; '" + s.keyword + "' at line " +
                    std::to_string(s.line) +
                    (is_end ? " ends another kind of block" : " cannot be inside it"));
  m_open.pop_back();
  if (is_end && (m_open.empty() || !own_end(m_open.back(), s.key))) return;
  if (!is_end) m_dangling_end = lower(b.end);
  statement(s);
}

bool GsdParser::scalar(const Stmt& s) {
  const auto& t = table();
  auto it = t.find(s.key);
  if (it == t.end()) return false;
  const ScalarKeyword& k = it->second;
  switch (k.kind) {
    case Kind::Bool:
      if (auto v = boolean(s, k.name)) k.set_uint(m_result_file, *v ? 1 : 0);
      break;
    case Kind::Uint:
      if (auto v = unsigned_value(s, k.name, k.max)) k.set_uint(m_result_file, *v);
      break;
    case Kind::String:
      if (auto v = string_value(s, k.name)) k.string_field(m_result_file) = *v;
      break;
  }
  return true;
}

bool GsdParser::baud_keyword(const Stmt& s) {
  const auto bk = split_baud_key(s.key);
  if (!bk) return false;
  if (bk->kind == "_supp") {
    if (auto v = boolean(s, s.keyword)) {
      if (*v)
        m_supp_line[bk->baud] = s.line;
      else
        m_supp_line.erase(bk->baud);
    }
    return true;
  }
  auto v = unsigned_value(s, s.keyword, 0xFFFF);
  if (!v) return true;
  const auto val = static_cast<std::uint16_t>(*v);
  auto& m = m_result_file.m_master;
  if (bk->kind == "maxtsdr_") m_max_tsdr[bk->baud] = val;
  else if (bk->kind == "trdy_") m.trdy[bk->baud] = val;
  else if (bk->kind == "tqui_") m.tqui[bk->baud] = val;
  else if (bk->kind == "tset_") m.tset[bk->baud] = val;
  else m.tsdi[bk->baud] = val;
  return true;
}

// Max_Input_Len, Max_Output_Len, Max_Data_Len. A DP slave exchanges at most 244 octets in each
// direction (protocol-facts.md §D.3 "per slave <= 244 B in and <= 244 B out"; §A: 244 octets of
// DP payload per telegram), so PI 2.122 allows 0..244, 0..244 and 0..488. Files in the field
// write more (249, the FDL LE limit, and 498): such a value is clamped to the limit with a
// warning instead of refusing the file, since the limit is what any master will use anyway.
bool GsdParser::data_length_limit(const Stmt& s) {
  struct Limit {
    std::string_view key;
    std::string_view name;
    std::uint16_t limit;
  };
  static constexpr Limit kLimits[] = {{"max_input_len", "Max_Input_Len", 244},
                                      {"max_output_len", "Max_Output_Len", 244},
                                      {"max_data_len", "Max_Data_Len", 488}};
  const Limit* l = nullptr;
  for (const auto& k : kLimits)
    if (k.key == s.key) l = &k;
  if (l == nullptr) return false;
  auto v = unsigned_value(s, l->name, 0xFFFF);
  if (!v) return true;
  if (*v > l->limit) {
    warning(s.line, std::string(l->name) + " " + std::to_string(*v) + " above the DP limit " +
                        std::to_string(l->limit) + "; clamped to " + std::to_string(l->limit));
    v = l->limit;
  }
  auto& sf = m_result_file.m_slave;
  if (s.key == "max_input_len") sf.max_input_len = static_cast<std::uint8_t>(*v);
  else if (s.key == "max_output_len") sf.max_output_len = static_cast<std::uint8_t>(*v);
  else sf.max_data_len = static_cast<std::uint16_t>(*v);
  return true;
}

void GsdParser::prm_const(const Stmt& s, GsdPrmArea& area) {
  auto off = index_value(s, 236);
  if (!off || !need_value(s)) return;
  auto bytes = byte_list(s.value, s.line, "byte value");
  if (!bytes) return;
  if (bytes->empty()) {
    error(s.line, s.keyword + "(" + s.index + ") has no bytes");
    return;
  }
  area.consts.push_back({*off, std::move(*bytes), s.line});
}

void GsdParser::prm_ref(const Stmt& s, GsdPrmArea& area) {
  auto off = index_value(s, 236);
  if (!off) return;
  auto ref = unsigned_value(s, s.keyword + "(" + s.index + ")", 0xFFFF);
  if (!ref) return;
  area.refs.push_back({*off, static_cast<std::uint16_t>(*ref), s.line});
}

// Misspellings common in real files, read as the keyword they mean (with a warning, so that the
// vendor can fix the file). Min_Slave_Interval: the standard's keyword has two l; read with one,
// the poll interval would silently become 0. WB_Base_1ms_supp: listed by S10 (protocol-facts.md
// §I.2) next to the right spelling.
void GsdParser::correct_spelling(Stmt& s) {
  struct Misspelling {
    std::string_view wrong;
    std::string_view right;
  };
  static constexpr Misspelling kMisspellings[] = {{"min_slave_interval", "Min_Slave_Intervall"},
                                                  {"wb_base_1ms_supp", "WD_Base_1ms_supp"}};
  for (const auto& m : kMisspellings) {
    if (s.key != m.wrong) continue;
    warning(s.line, "'" + s.keyword + "' read as '" + std::string(m.right) + "' (common misspelling)");
    s.key = lower(m.right);
    return;
  }
}

void GsdParser::top(const Stmt& written) {
  remember(written);
  Stmt s = written;
  correct_spelling(s);
  if (!m_dangling_end.empty() && s.key == m_dangling_end) {
    m_dangling_end.clear();  // already reported as the missing end of its block
    return;
  }
  // Blocks repeat; several Ext_User_Prm_Data_Ref at one offset are the normal way to place
  // several bit parameters in one byte.
  static const std::array<std::string_view, 20> kRepeatable = {
      "ext_user_prm_data_ref", "ext_user_prm_data_const", "module", "endmodule", "prmtext", "endprmtext", "extuserprmdata", "endextuserprmdata",
      "f_extuserprmdata", "endf_extuserprmdata",
      "unit_diag_area", "unit_diag_area_end", "x_unit_diag_area", "x_unit_diag_area_end",
      "slotdefinition", "endslotdefinition", "unitdiagtype", "endunitdiagtype",
      "physical_interface", "end_physical_interface"};
  if (std::find(kRepeatable.begin(), kRepeatable.end(), s.key) == kRepeatable.end()) {
    const std::string id = s.key + (s.has_index ? "(" + lower(s.index) + ")" : "");
    auto [it, fresh] = m_seen.emplace(id, s.line);
    if (!fresh) {
      warning(s.line, "'" + s.keyword + (s.has_index ? "(" + s.index + ")" : "") +
                          "' given twice (first at line " + std::to_string(it->second) +
                          "); the later value wins");
      it->second = s.line;
    }
  }
  const std::string& k = s.key;
  auto& f = m_result_file;
  if (k == "module") {
    if (!need_value(s)) return;
    std::string rest;
    auto name = quoted(s.value, s.line, &rest);
    if (!name) return;
    m_module = GsdModule{};
    m_module.name = *name;
    m_module.line = s.line;
    open_block(Block::Module, "EndModule", s.line);
    m_module_stmts = 0;
    auto bytes = byte_list(rest, s.line, "config byte");
    if (!bytes) return;
    if (bytes->empty()) error(s.line, "Module '" + *name + "': no config bytes");
    m_module.config = std::move(*bytes);
  } else if (k == "endmodule") {
    error(s.line, "EndModule without Module");
  } else if (k == "prmtext") {
    auto ref = unsigned_value(s, "PrmText", 0xFFFF);
    m_prm_text = GsdPrmText{};
    m_prm_text.ref = static_cast<std::uint16_t>(ref.value_or(0));
    m_prm_text.line = s.line;
    open_block(Block::PrmText, "EndPrmText", s.line);
  } else if (k == "endprmtext") {
    error(s.line, "EndPrmText without PrmText");
  } else if (k == "extuserprmdata" || k == "f_extuserprmdata") {
    m_ext = GsdExtUserPrmData{};
    m_ext.line = s.line;
    m_ext_f = k[0] == 'f';
    m_ext_has_type = false;
    const std::string kind = m_ext_f ? "F_ExtUserPrmData" : "ExtUserPrmData";
    open_block(Block::ExtPrm, m_ext_f ? "EndF_ExtUserPrmData" : "EndExtUserPrmData", s.line);
    if (!need_value(s)) return;
    const std::string_view v = s.value;
    const std::size_t q = v.find('"');
    auto ref = number(v.substr(0, q), s.line);
    if (!ref) return;
    if (*ref < 0 || *ref > 0xFFFF) {
      error(s.line, kind + " reference " + std::to_string(*ref) + " out of range (0..65535)");
      return;
    }
    m_ext.ref = static_cast<std::uint16_t>(*ref);
    if (q == std::string_view::npos) {
      error(s.line, kind + " " + std::to_string(*ref) + ": name missing");
      return;
    }
    if (auto name = quoted(v.substr(q), s.line, nullptr)) m_ext.name = *name;
  } else if (k == "endextuserprmdata") {
    error(s.line, "EndExtUserPrmData without ExtUserPrmData");
  } else if (k == "endf_extuserprmdata") {
    error(s.line, "EndF_ExtUserPrmData without F_ExtUserPrmData");
  } else if (k == "unit_diag_area" || k == "x_unit_diag_area") {
    open_diag_area(s);
  } else if (k == "unit_diag_area_end" || k == "x_unit_diag_area_end") {
    error(s.line, s.keyword + " without Unit_Diag_Area");
  } else if (k == "slotdefinition") {
    open_block(Block::Slots, "EndSlotDefinition", s.line);
  } else if (k == "endslotdefinition") {
    error(s.line, "EndSlotDefinition without SlotDefinition");
  } else if (k == "unitdiagtype") {
    m_diag_type = GsdUnitDiagType{};
    m_diag_type.line = s.line;
    open_block(Block::DiagType, "EndUnitDiagType", s.line, s.keyword);
    // The type octet. The block was read without interpretation before, so a value that is no
    // octet only warns: the file stays as usable as it was.
    const std::string_view v = trim(s.value);
    unsigned t = 0;
    const auto [p, ec] = std::from_chars(v.data(), v.data() + v.size(), t);
    if (ec == std::errc{} && p == v.data() + v.size() && t <= 0xFF)
      m_diag_type.type = static_cast<std::uint8_t>(t);
    else
      warning(s.line, "UnitDiagType value '" + shorten(v) + "' is not a type octet (0..255); its texts are kept "
                      "without a type");
  } else if (k == "physical_interface") {
    open_block(Block::Opaque, "End_Physical_Interface", s.line, s.keyword);
  } else if (k == "endunitdiagtype" || k == "end_physical_interface") {
    error(s.line, s.keyword + " without its block start");
  } else if (k == "unit_diag_bit" || k == "channel_diag") {
    auto idx = index_value(s, 0xFFFF);
    if (!idx) return;
    auto text = string_value(s, s.keyword);
    if (!text) return;
    (k == "unit_diag_bit" ? f.m_unit_diag_bits : f.m_channel_diag)[*idx] = *text;
  } else if (diag_bit_text(s, f.m_x_unit_diag, false)) {
    // X_Unit_Diag_Bit(n) and its help / Not_Bit texts outside a UnitDiagType
  } else if (k == "ext_user_prm_data_const") {
    prm_const(s, f.m_global_prm);
  } else if (k == "ext_user_prm_data_ref") {
    prm_ref(s, f.m_global_prm);
  } else if (k == "user_prm_data") {
    if (!need_value(s)) return;
    if (auto bytes = byte_list(s.value, s.line, "byte value")) f.m_global_prm.initial = std::move(*bytes);
  } else if (k == "user_prm_data_len") {
    if (auto v = unsigned_value(s, "User_Prm_Data_Len", 237))
      f.m_global_prm.declared_len = static_cast<std::uint16_t>(*v);
  } else if (k == "max_user_prm_data_len") {
    if (auto v = unsigned_value(s, "Max_User_Prm_Data_Len", 237))
      f.m_max_user_prm_data_len = static_cast<std::uint8_t>(*v);
  } else if (k == "slave_family") {
    // "main@sub@...", unquoted in most files; quotes tolerated.
    if (!need_value(s)) return;
    std::string v = s.value;
    if (v.size() >= 2 && v.front() == '"' && v.back() == '"') v = v.substr(1, v.size() - 2);
    f.m_info.slave_family = v;
  } else if (baud_keyword(s) || data_length_limit(s) || scalar(s)) {
    // handled
  } else if (known_raw(k)) {
    // kept in keywords() only
  } else {
    unknown(s, "");
  }
}

void GsdParser::in_module(const Stmt& s) {
  ++m_module_stmts;
  const std::string& k = s.key;
  const std::string where = " in Module '" + m_module.name + "'";
  if (k == "endmodule") {
    m_result_file.m_modules.push_back(std::move(m_module));
    m_module = GsdModule{};
    m_open.pop_back();
    return;
  }
  if (!s.has_eq && !s.has_index && s.value.empty() &&
      std::isdigit(static_cast<unsigned char>(s.keyword[0])) != 0) {
    // The module reference number line (PI 2.122: directly after the Module line).
    if (m_module_stmts != 1) {
      error(s.line, "unexpected number '" + s.keyword + "'" + where);
      return;
    }
    auto v = number(s.keyword, s.line);
    if (!v) return;
    if (*v < 0 || *v > 0xFFFFFFFF) {
      error(s.line, "module reference number " + s.keyword + " out of range");
      return;
    }
    m_module.reference = static_cast<std::uint32_t>(*v);
    return;
  }
  if (k == "ext_module_prm_data_len") {
    if (auto v = unsigned_value(s, "Ext_Module_Prm_Data_Len", 237))
      m_module.prm.declared_len = static_cast<std::uint16_t>(*v);
  } else if (k == "ext_user_prm_data_const") {
    prm_const(s, m_module.prm);
  } else if (k == "ext_user_prm_data_ref") {
    prm_ref(s, m_module.prm);
  } else if (f_parameter(s)) {
    // PROFIsafe F-parameters (decisions in gsd.hpp)
  } else if (k == "info_text") {
    if (auto v = string_value(s, "Info_Text")) m_module.info_text = *v;
  } else if (k == "data_area_beg") {
    open_block(Block::Opaque, "Data_Area_End", s.line, s.keyword);
  } else {
    m_module.other_keywords.push_back({s.keyword, s.index, s.value, s.line});
    if (!known_module_raw(k)) {
      warning(s.line, "unknown keyword '" + s.keyword + "'" + where + " kept");
    }
  }
}

// PROFIsafe module keywords: the F-parameter block, its description CRCs.
bool GsdParser::f_parameter(const Stmt& s) {
  GsdFParameters& f = m_module.f;
  const std::string& k = s.key;
  if (k == "f_ext_module_prm_data_len") {
    if (auto v = unsigned_value(s, "F_Ext_Module_Prm_Data_Len", 237))
      f.prm.declared_len = static_cast<std::uint16_t>(*v);
  } else if (k == "f_ext_user_prm_data_const") {
    prm_const(s, f.prm);
  } else if (k == "f_ext_user_prm_data_ref") {
    prm_ref(s, f.prm);
  } else if (k == "f_paramdesccrc") {
    if (auto v = unsigned_value(s, "F_ParamDescCRC", 0xFFFF)) f.param_desc_crc = static_cast<std::uint16_t>(*v);
  } else if (k == "f_io_structuredesccrc") {
    if (auto v = unsigned_value(s, "F_IO_StructureDescCRC", 0xFFFFFFFF))
      f.io_structure_desc_crc = static_cast<std::uint32_t>(*v);
  } else {
    return false;
  }
  return true;
}

void GsdParser::in_prm_text(const Stmt& s) {
  const std::string where = " in PrmText " + std::to_string(m_prm_text.ref);
  if (s.key == "endprmtext") {
    auto& texts = m_result_file.m_prm_texts;
    if (auto it = texts.find(m_prm_text.ref); it != texts.end())
      defined_twice(m_prm_text.line, "PrmText " + std::to_string(m_prm_text.ref), it->second.line);
    texts[m_prm_text.ref] = std::move(m_prm_text);
    m_open.pop_back();
  } else if (s.key == "text") {
    if (!s.has_index) {
      error(s.line, "'Text' needs an index: Text(value)");
      return;
    }
    auto v = number(s.index, s.line);
    if (!v) return;
    auto t = string_value(s, "Text");
    if (!t) return;
    m_prm_text.texts.emplace_back(*v, *t);
  } else {
    unknown(s, where);
  }
}

std::string GsdParser::ext_what() const {
  return (m_ext_f ? "F_ExtUserPrmData " : "ExtUserPrmData ") + std::to_string(m_ext.ref) + " '" + m_ext.name + "'";
}

void GsdParser::data_type_line(const Stmt& s) {
  const std::string what = ext_what();
  if (m_ext_has_type) {
    error(s.line, what + ": more than one data type line");
    return;
  }
  const std::string& k = s.key;
  std::int64_t lo = 0;
  std::int64_t hi = 0;
  if (k == "bit" || k == "bitarea") {
    if (!s.has_index) {
      error(s.line, what + ": " + s.keyword + " needs a bit position in parentheses");
      return;
    }
    const std::size_t dash = s.index.find('-');
    if (k == "bit" && dash != std::string::npos) {
      error(s.line, what + ": Bit(" + s.index + ") takes one bit position");
      return;
    }
    auto a = number(std::string_view(s.index).substr(0, dash), s.line);
    if (!a) return;
    std::optional<std::int64_t> b = a;
    if (k == "bitarea") {
      if (dash == std::string::npos) {
        error(s.line, what + ": BitArea(" + s.index + ") needs first-last");
        return;
      }
      b = number(std::string_view(s.index).substr(dash + 1), s.line);
      if (!b) return;
    }
    if (*a < 0 || *b > 7 || *a > *b) {
      error(s.line, what + ": bit positions " + s.index + " outside 0..7 or out of order");
      return;
    }
    m_ext.type = k == "bit" ? GsdDataType::Bit : GsdDataType::BitArea;
    m_ext.bit_first = static_cast<std::uint8_t>(*a);
    m_ext.bit_last = static_cast<std::uint8_t>(*b);
    hi = (std::int64_t{1} << (*b - *a + 1)) - 1;
  } else {
    if (s.has_index) {
      error(s.line, what + ": " + s.keyword + " takes no index");
      return;
    }
    struct T { std::string_view key; GsdDataType type; std::int64_t lo, hi; };
    static constexpr T kTypes[] = {
        {"unsigned8", GsdDataType::Unsigned8, 0, 0xFF},
        {"unsigned16", GsdDataType::Unsigned16, 0, 0xFFFF},
        {"unsigned32", GsdDataType::Unsigned32, 0, 0xFFFFFFFF},
        {"signed8", GsdDataType::Signed8, -128, 127},
        {"signed16", GsdDataType::Signed16, -32768, 32767},
        {"signed32", GsdDataType::Signed32, -2147483648LL, 2147483647},
    };
    for (const auto& t : kTypes)
      if (t.key == k) {
        m_ext.type = t.type;
        lo = t.lo;
        hi = t.hi;
      }
  }
  m_ext_has_type = true;
  const std::string type_range = std::string(gsd_data_type_name(m_ext.type)) + " (" +
                                 std::to_string(lo) + ".." + std::to_string(hi) + ")";
  // "<default> <min>-<max>" or "<default> <a>,<b>,...": the allowed part may contain spaces.
  std::string_view rest = trim(s.value);
  std::size_t sp = 0;
  while (sp < rest.size() && !is_space(rest[sp])) ++sp;
  const std::string_view def_tok = rest.substr(0, sp);
  if (def_tok.empty()) {
    error(s.line, what + ": default value missing");
    return;
  }
  auto def = number(def_tok, s.line);
  if (!def) return;
  std::string allowed;
  for (char c : rest.substr(sp))
    if (!is_space(c)) allowed += c;
  m_ext.min_value = lo;
  m_ext.max_value = hi;
  auto in_type = [&](std::int64_t v) { return v >= lo && v <= hi; };
  if (allowed.find(',') != std::string::npos) {
    std::string_view a = allowed;
    while (true) {
      const std::size_t comma = a.find(',');
      auto v = number(a.substr(0, comma), s.line);
      if (!v) return;
      if (!in_type(*v)) {
        error(s.line, what + ": allowed value " + std::to_string(*v) + " outside " + type_range);
        return;
      }
      m_ext.allowed.push_back(*v);
      if (comma == std::string_view::npos) break;
      a.remove_prefix(comma + 1);
    }
    m_ext.min_value = *std::min_element(m_ext.allowed.begin(), m_ext.allowed.end());
    m_ext.max_value = *std::max_element(m_ext.allowed.begin(), m_ext.allowed.end());
  } else if (!allowed.empty()) {
    // A range min-max; either bound may carry a minus sign ("-100--50").
    const std::size_t dash = allowed.find('-', allowed[0] == '-' ? 1 : 0);
    auto a = number(std::string_view(allowed).substr(0, dash), s.line);
    if (!a) return;
    std::optional<std::int64_t> b = a;
    if (dash != std::string::npos) {
      b = number(std::string_view(allowed).substr(dash + 1), s.line);
      if (!b) return;
    }
    if (*a > *b || !in_type(*a) || !in_type(*b)) {
      error(s.line, what + ": range " + allowed + " out of order or outside " + type_range);
      return;
    }
    m_ext.min_value = *a;
    m_ext.max_value = *b;
    if (dash == std::string::npos) m_ext.allowed.push_back(*a);
  }
  m_ext.default_value = *def;
  if (!m_ext.accepts(*def)) {
    error(s.line, what + ": default " + std::to_string(*def) + " not allowed by '" +
                      (allowed.empty() ? type_range : allowed) + "'");
  }
}

void GsdParser::in_ext_prm(const Stmt& s) {
  const std::string& k = s.key;
  const std::string what = ext_what();
  if (own_end(m_open.back(), k)) {
    m_open.pop_back();
    if (!m_ext_has_type) {
      error(m_ext.line, what + ": data type line missing");
      return;
    }
    auto& defs = m_ext_f ? m_result_file.m_f_ext_prm : m_result_file.m_ext_prm;
    if (auto it = defs.find(m_ext.ref); it != defs.end())
      defined_twice(m_ext.line, (m_ext_f ? "F_ExtUserPrmData " : "ExtUserPrmData ") + std::to_string(m_ext.ref),
                    it->second.line);
    defs[m_ext.ref] = m_ext;
  } else if (k == "bit" || k == "bitarea" || k == "unsigned8" || k == "unsigned16" ||
             k == "unsigned32" || k == "signed8" || k == "signed16" || k == "signed32") {
    data_type_line(s);
  } else if (k == "prm_text_ref") {
    if (auto v = unsigned_value(s, "Prm_Text_Ref", 0xFFFF)) m_ext.prm_text_ref = static_cast<std::uint16_t>(*v);
  } else if (k == "changeable") {
    if (auto v = boolean(s, "Changeable")) m_ext.changeable = *v;
  } else if (k == "visible") {
    if (auto v = boolean(s, "Visible")) m_ext.visible = *v;
  } else {
    unknown(s, " in " + what);
  }
}

void GsdParser::open_diag_area(const Stmt& s) {
  m_diag_area = GsdUnitDiagArea{};
  m_diag_area.x_variant = s.key[0] == 'x';
  m_diag_area.line = s.line;
  open_block(Block::DiagArea, m_diag_area.x_variant ? "X_Unit_Diag_Area_End" : "Unit_Diag_Area_End", s.line);
  if (!need_value(s)) return;
  const std::size_t dash = s.value.find('-');
  auto a = number(std::string_view(s.value).substr(0, dash), s.line);
  if (!a) return;
  auto b = dash == std::string::npos ? a : number(std::string_view(s.value).substr(dash + 1), s.line);
  if (!b) return;
  if (*a < 0 || *b < *a || *b > 0xFFFF) {
    error(s.line, s.keyword + " " + s.value + ": bits out of order or out of range");
    return;
  }
  m_diag_area.first_bit = static_cast<std::uint16_t>(*a);
  m_diag_area.last_bit = static_cast<std::uint16_t>(*b);
}

// Value(n) / X_Value(n) name a value of the area's bits; Value_Help(n) / X_Value_Help(n) explain it.
void GsdParser::in_diag_area(const Stmt& s) {
  if (s.key == "unit_diag_area_end" || s.key == "x_unit_diag_area_end") {
    m_open.pop_back();
    auto& areas = block() == Block::DiagType ? m_diag_type.areas : m_result_file.m_unit_diag_areas;
    areas.push_back(std::move(m_diag_area));
    m_diag_area = GsdUnitDiagArea{};
  } else if (s.key == "value" || s.key == "x_value" || s.key == "value_help" || s.key == "x_value_help") {
    if (!s.has_index) {
      error(s.line, "'" + s.keyword + "' needs an index: " + s.keyword + "(n)");
      return;
    }
    auto v = number(s.index, s.line);
    if (!v) return;
    auto t = string_value(s, s.keyword);
    if (!t) return;
    (ends_with(s.key, "_help") ? m_diag_area.value_help : m_diag_area.values).emplace_back(*v, *t);
  } else {
    unknown(s, m_diag_area.x_variant ? " in X_Unit_Diag_Area" : " in Unit_Diag_Area");
  }
}

// (X_)Unit_Diag_Bit(n), (X_)Unit_Diag_Bit_Help(n), (X_)Unit_Diag_Not_Bit(n),
// (X_)Unit_Diag_Not_Bit_Help(n) into `texts`; the plain spellings only with `plain` (inside a
// UnitDiagType, gsd.hpp). False when the statement is none of them.
bool GsdParser::diag_bit_text(const Stmt& s, GsdDiagBitTexts& texts, bool plain) {
  std::string_view k = s.key;
  if (k.rfind("x_", 0) == 0)
    k.remove_prefix(2);
  else if (!plain)
    return false;
  std::map<std::uint32_t, std::string>* target = k == "unit_diag_bit"            ? &texts.bits
                                                 : k == "unit_diag_bit_help"     ? &texts.bit_help
                                                 : k == "unit_diag_not_bit"      ? &texts.not_bits
                                                 : k == "unit_diag_not_bit_help" ? &texts.not_bit_help
                                                                                 : nullptr;
  if (target == nullptr) return false;
  auto idx = index_value(s, 0xFFFF);
  if (!idx) return true;
  if (auto text = string_value(s, s.keyword)) (*target)[*idx] = *text;
  return true;
}

void GsdParser::in_diag_type(const Stmt& s) {
  if (s.key == "endunitdiagtype") {
    m_result_file.m_unit_diag_types.push_back(std::move(m_diag_type));
    m_diag_type = GsdUnitDiagType{};
    m_open.pop_back();
  } else if (s.key == "unit_diag_area" || s.key == "x_unit_diag_area") {
    open_diag_area(s);
  } else if (!diag_bit_text(s, m_diag_type.texts, true)) {
    unknown(s, " in UnitDiagType");
  }
}

void GsdParser::in_slots(const Stmt& s) {
  if (s.key == "endslotdefinition") {
    m_open.pop_back();
    return;
  }
  if (s.key != "slot") {
    unknown(s, " in SlotDefinition");
    return;
  }
  GsdSlot slot;
  slot.line = s.line;
  auto n = index_value(s, 255);
  if (!n || !need_value(s)) return;
  slot.number = *n;
  std::string rest;
  auto name = quoted(s.value, s.line, &rest);
  if (!name) return;
  slot.name = *name;
  std::string_view r = trim(rest);
  std::size_t sp = 0;
  while (sp < r.size() && !is_space(r[sp])) ++sp;
  auto def = number(r.substr(0, sp), s.line);
  if (!def) return;
  if (*def < 0 || *def > 0xFFFFFFFF) {
    error(s.line, "Slot(" + s.index + "): default module reference out of range");
    return;
  }
  slot.default_ref = static_cast<std::uint32_t>(*def);
  std::string allowed;
  for (char c : r.substr(sp))
    if (!is_space(c)) allowed += c;
  if (allowed.empty()) {
    slot.allowed.emplace_back(slot.default_ref, slot.default_ref);
  } else {
    std::string_view a = allowed;
    while (true) {
      const std::size_t comma = a.find(',');
      const std::string_view item = a.substr(0, comma);
      const std::size_t dash = item.find('-');
      auto lo = number(item.substr(0, dash), s.line);
      if (!lo) return;
      auto hi = dash == std::string_view::npos ? lo : number(item.substr(dash + 1), s.line);
      if (!hi) return;
      if (*lo < 0 || *hi < *lo || *hi > 0xFFFFFFFF) {
        error(s.line, "Slot(" + s.index + "): module references '" + std::string(item) + "' out of order");
        return;
      }
      slot.allowed.emplace_back(static_cast<std::uint32_t>(*lo), static_cast<std::uint32_t>(*hi));
      if (comma == std::string_view::npos) break;
      a.remove_prefix(comma + 1);
    }
  }
  m_result_file.m_slots.push_back(std::move(slot));
}

void GsdParser::close_block_at_end() {
  for (; !m_open.empty(); m_open.pop_back()) {
    const OpenBlock& b = m_open.back();
    error(b.line, block_title(b) + " without " + b.end);
  }
}

// ---------------------------------------------------------------------------------------------
// Whole-file checks

// The F-parameter block of a PROFIsafe module: its length is F_Ext_Module_Prm_Data_Len; the
// same rule as for Ext_Module_Prm_Data_Len applies when overlays reach beyond it or it is absent.
void GsdParser::check_f_block(const GsdModule& m) {
  if (!m.f.present()) return;
  const GsdPrmArea& fp = m.f.prm;
  const std::size_t len = fp.length(m_result_file.m_f_defs);
  const std::string what = "Module '" + m.name + "': ";
  if (!fp.declared_len) {
    if (len > 0)
      warning(m.line, what + "F-parameters without F_Ext_Module_Prm_Data_Len; F block of " + std::to_string(len) +
                          " bytes, as far as they reach");
  } else if (len > *fp.declared_len) {
    warning(m.line, what + "F-parameters reach byte " + std::to_string(len) + ", beyond F_Ext_Module_Prm_Data_Len " +
                        std::to_string(*fp.declared_len) + "; F block extended");
  }
}

void GsdParser::finish() {
  auto& f = m_result_file;
  auto seen = [&](std::string_view key) -> std::optional<std::uint32_t> {
    auto it = m_seen.find(std::string(key));
    if (it == m_seen.end()) return std::nullopt;
    return it->second;
  };

  if (!seen("ident_number")) error(m_section_line, "Ident_Number missing");
  if (!seen("station_type")) warning(m_section_line, "Station_Type missing; DP slave (0) assumed");

  for (const auto& [baud, line] : m_supp_line) {
    const auto it = m_max_tsdr.find(baud);
    const std::string rate = gsd_baud_spelling(baud);
    if (it == m_max_tsdr.end()) {
      error(line, "MaxTsdr_" + rate + " missing although " + rate + "_supp = 1");
      continue;
    }
    f.m_baud_rates.push_back({baud, it->second});
  }
  if (m_supp_line.empty()) error(m_section_line, "no baud rate supported (no *_supp = 1)");

  const bool slave = !f.is_master();
  if (slave) {
    if (f.m_modules.empty()) error(m_section_line, "no Module defined");
    if (!seen("min_slave_intervall")) warning(m_section_line, "Min_Slave_Intervall missing");
    if (auto l = seen("max_diag_data_len")) {
      if (f.m_slave.max_diag_data_len < 6)
        error(*l, "Max_Diag_Data_Len " + std::to_string(f.m_slave.max_diag_data_len) + " below 6");
    } else {
      warning(m_section_line, "Max_Diag_Data_Len missing; 6 assumed");
    }
  }
  if (f.m_slave.modular_station && !seen("max_module"))
    error(*seen("modular_station"), "Max_Module missing although Modular_Station = 1");
  if (!f.m_slave.modular_station && !seen("max_module")) f.m_slave.max_module = 1;
  if (!seen("max_data_len"))
    f.m_slave.max_data_len = static_cast<std::uint16_t>(f.m_slave.max_input_len + f.m_slave.max_output_len);

  if (auto l = seen("c2_max_data_len"); l && f.m_dpv1.c2_max_data_len > 0 && f.m_dpv1.c2_max_data_len < 48)
    error(*l, "C2_Max_Data_Len " + std::to_string(f.m_dpv1.c2_max_data_len) + " not allowed (0 or 48..240)");
  if (auto l = seen("max_initiate_pdu_length");
      l && f.m_dpv1.max_initiate_pdu_length > 0 && f.m_dpv1.max_initiate_pdu_length < 52)
    error(*l, "Max_Initiate_PDU_Length " + std::to_string(f.m_dpv1.max_initiate_pdu_length) +
                  " not allowed (0 or 52..244)");

  // References between blocks. F_Ext_User_Prm_Data_Ref resolves to F_ExtUserPrmData, else to
  // the ExtUserPrmData of that number (gsd.hpp).
  f.m_f_defs = f.m_ext_prm;
  for (const auto& [ref, e] : f.m_f_ext_prm) f.m_f_defs[ref] = e;
  auto check_refs = [&](const GsdPrmArea& area, const std::map<std::uint16_t, GsdExtUserPrmData>& defs,
                        std::string_view keyword, std::string_view kind) {
    for (const auto& r : area.refs)
      if (!defs.count(r.ref))
        error(r.line, std::string(keyword) + "(" + std::to_string(r.offset) + ") refers to undefined " +
                          std::string(kind) + " " + std::to_string(r.ref));
  };
  check_refs(f.m_global_prm, f.m_ext_prm, "Ext_User_Prm_Data_Ref", "ExtUserPrmData");
  for (const auto& m : f.m_modules) {
    check_refs(m.prm, f.m_ext_prm, "Ext_User_Prm_Data_Ref", "ExtUserPrmData");
    check_refs(m.f.prm, f.m_f_defs, "F_Ext_User_Prm_Data_Ref", "F_ExtUserPrmData");
  }
  auto check_texts = [&](const std::map<std::uint16_t, GsdExtUserPrmData>& defs, std::string_view kind) {
    for (const auto& [ref, e] : defs)
      if (e.prm_text_ref && !f.m_prm_texts.count(*e.prm_text_ref))
        error(e.line, std::string(kind) + " " + std::to_string(ref) + " '" + e.name +
                          "': Prm_Text_Ref refers to undefined PrmText " + std::to_string(*e.prm_text_ref));
  };
  check_texts(f.m_ext_prm, "ExtUserPrmData");
  check_texts(f.m_f_ext_prm, "F_ExtUserPrmData");

  // Modules: identifiers well formed; lengths derived from them.
  std::map<std::uint32_t, std::uint32_t> refs_seen;
  for (auto& m : f.m_modules) {
    std::string why;
    if (!m.config.empty()) {
      if (auto len = gsd_cfg_lengths(m.config, &why)) {
        m.input_len = len->input_len;
        m.output_len = len->output_len;
        m.consistent = len->consistent;
      } else {
        error(m.line, "Module '" + m.name + "': " + why);
      }
    }
    if (m.reference) {
      auto [it, fresh] = refs_seen.emplace(*m.reference, m.line);
      if (!fresh)
        warning(m.line, "Module '" + m.name + "': reference number " + std::to_string(*m.reference) +
                            " already used at line " + std::to_string(it->second));
    }
    const std::size_t len = m.prm.length(f.m_ext_prm);
    if (m.prm.declared_len && len > *m.prm.declared_len)
      warning(m.line, "Module '" + m.name + "': parameters reach byte " + std::to_string(len) +
                          ", beyond Ext_Module_Prm_Data_Len " + std::to_string(*m.prm.declared_len) +
                          "; area extended");
    check_f_block(m);
  }

  // Global parameter area.
  const auto& g = f.m_global_prm;
  if (g.declared_len) {
    const std::uint32_t l = seen("user_prm_data_len").value_or(m_section_line);
    if (g.initial.size() > *g.declared_len)
      warning(l, "User_Prm_Data has " + std::to_string(g.initial.size()) +
                     " bytes, more than User_Prm_Data_Len " + std::to_string(*g.declared_len) +
                     "; truncated");
    std::size_t ext = 0;
    for (const auto& c : g.consts) ext = std::max(ext, c.offset + c.data.size());
    for (const auto& r : g.refs) {
      auto it = f.m_ext_prm.find(r.ref);
      ext = std::max(ext, r.offset + (it != f.m_ext_prm.end() ? it->second.size() : 1));
    }
    if (ext > *g.declared_len)
      warning(l, "Ext_User_Prm_Data_Const/Ref reach byte " + std::to_string(ext) +
                     ", beyond User_Prm_Data_Len " + std::to_string(*g.declared_len) + "; area extended");
  }
  if (f.m_dpv1.dpv1_slave && g.length(f.m_ext_prm) < 3)
    warning(seen("dpv1_slave").value_or(m_section_line),
            "DPV1_Slave = 1 but User_Prm_Data has fewer than 3 bytes (DPV1_Status_1..3); "
            "missing status bytes assembled as 80 00 00");

  // Slave redundancy (§G.7; bit meanings and unit are our decisions, gsd.hpp GsdRedundancy).
  const auto& red = f.m_redundancy;
  if (auto l = seen("slave_redundancy_supp"); l && red.reserved_redundancy_bits() != 0) {
    char hex[8];
    std::snprintf(hex, sizeof hex, "0x%02X", static_cast<unsigned>(red.slave_redundancy_supp));
    warning(*l, std::string("Slave_Redundancy_supp ") + hex +
                    " sets reserved bits (bit 0 = System Redundancy, bit 1 = Flying Redundancy); kept");
  }
  if (auto l = seen("slave_redundancy_supp"); l && red.slave_redundancy() && !red.prm_cmd_supp)
    warning(*l, "Slave_Redundancy_supp without PrmCmd_supp = 1: a master cannot choose the primary");
  if (auto l = seen("prmcmd_supp"); l && red.prm_cmd_supp) {
    if (!f.m_dpv1.dpv1_slave)
      warning(*l, "PrmCmd_supp = 1 without DPV1_Slave = 1 (the PrmCmd bit is in DPV1_Status_3)");
    else if (!f.m_dpv1.prm_block_structure_supp && !f.m_dpv1.prm_block_structure_req)
      warning(*l, "PrmCmd_supp = 1 without Prm_Block_Structure_supp = 1 (PrmCmd is a structured block)");
  }

  for (const auto& slot : f.m_slots)
    if (!f.find_module_by_reference(slot.default_ref))
      warning(slot.line, "Slot(" + std::to_string(slot.number) + "): default module reference " +
                             std::to_string(slot.default_ref) + " matches no Module");
}

GsdParseResult GsdParser::run() {
  const std::string text = decode();
  split_logical(text);
  index_statements();
  for (m_pos = 0; m_pos < m_logical.size(); ++m_pos) {
    if (too_many_errors()) break;
    const auto& [line_text, line] = m_logical[m_pos];
    if (auto s = parse_stmt(line_text, line)) statement(*s);
  }
  if (m_section_line != 0 && !too_many_errors()) close_block_at_end();
  if (m_errors.empty()) finish();

  GsdParseResult r;
  r.errors = std::move(m_errors);
  r.warnings = std::move(m_warnings);
  if (r.errors.empty()) r.file = std::move(m_result_file);
  return r;
}

GsdParseResult parse_gsd(std::string_view bytes, std::string_view file_name) {
  try {
    return GsdParser(bytes, file_name).run();
  } catch (const std::exception& e) {
    // Only allocation failure can get here; report it instead of letting it escape.
    GsdParseResult r;
    r.errors.push_back({std::string(file_name), 0, std::string("internal error: ") + e.what()});
    return r;
  }
}

GsdParseResult load_gsd(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream buf;
  if (in) buf << in.rdbuf();
  if (!in) {
    GsdParseResult r;
    r.errors.push_back({path.string(), 0, "cannot read the file"});
    return r;
  }
  return parse_gsd(buf.str(), path.string());
}

}  // namespace pbvbus::devices
