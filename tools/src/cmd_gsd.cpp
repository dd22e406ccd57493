// `pbvbus gsd FILE [--json]`: reads a GSD file (PI 2.122) and prints what it describes: ident,
// station type, vendor/model, baud rates with MaxTsdr, modules with their config bytes and
// lengths and PROFIsafe F-parameters, parameters (ExtUserPrmData, F_ExtUserPrmData), DP-V1 and
// redundancy features. Warnings go to stderr.
// Exit 0 on success, 2 for bad usage or a broken file ("file:line: reason" on stderr).

#include <cstdint>
#include <cstdio>
#include <map>
#include <ostream>
#include <sstream>
#include <string>

#include "pbvbus/gsd/gsd.hpp"
#include "pbvbus/reports/json_text.hpp"
#include "pbvbus/tools/commands.hpp"

namespace pbvbus::tools {

namespace {

using devices::GsdBytes;
using devices::GsdFile;

constexpr const char* kGsdUsage =
    "usage: pbvbus gsd FILE [--json]\n"
    "\n"
    "Reads a GSD device description (PI 2.122, ISO-8859-1) and prints its ident number,\n"
    "station type, vendor and model, supported baud rates with MaxTsdr, modules (config bytes,\n"
    "input/output lengths, PROFIsafe F-parameters), parameters (ExtUserPrmData and\n"
    "F_ExtUserPrmData with defaults, ranges and texts), DP-V1 and redundancy features.\n"
    "Warnings go to stderr.\n"
    "\n"
    "  --json    print the same as one JSON object\n"
    "  --help    this text\n"
    "\n"
    "Exit status: 0 success, 2 bad usage or a broken file (file:line: reason on stderr).\n";

std::string hex_byte(std::uint8_t b) {
  char buf[8];
  std::snprintf(buf, sizeof buf, "0x%02X", b);
  return buf;
}

std::string hex_list(const GsdBytes& bytes, const char* sep) {
  std::string s;
  for (std::size_t i = 0; i < bytes.size(); ++i) {
    if (i) s += sep;
    s += hex_byte(bytes[i]);
  }
  return s;
}

std::string gsd_hex(const GsdBytes& bytes) { return hex_octets(bytes); }

std::string hex16(std::uint16_t v) {
  char buf[8];
  std::snprintf(buf, sizeof buf, "0x%04X", v);
  return buf;
}

std::string hex32(std::uint32_t v) {
  char buf[12];
  std::snprintf(buf, sizeof buf, "0x%08X", static_cast<unsigned>(v));
  return buf;
}

const char* yn(bool b) { return b ? "1" : "0"; }

std::string station_type_name(std::uint8_t t) { return t == 1 ? "DP master" : "DP slave"; }

std::string allowed_text(const devices::GsdExtUserPrmData& e) {
  if (e.allowed.empty()) return std::to_string(e.min_value) + "-" + std::to_string(e.max_value);
  std::string s;
  for (std::size_t i = 0; i < e.allowed.size(); ++i) {
    if (i) s += ',';
    s += std::to_string(e.allowed[i]);
  }
  return s;
}

std::string type_text(const devices::GsdExtUserPrmData& e) {
  std::string t(devices::gsd_data_type_name(e.type));
  if (e.type == devices::GsdDataType::Bit) t += "(" + std::to_string(e.bit_first) + ")";
  if (e.type == devices::GsdDataType::BitArea)
    t += "(" + std::to_string(e.bit_first) + "-" + std::to_string(e.bit_last) + ")";
  return t;
}

// --- text output -------------------------------------------------------------------------------

// A PROFIsafe module's F-parameter block (defaults) and its description CRCs, under its module.
void print_f_parameters(const GsdFile& f, const devices::GsdModule& m, std::ostream& out) {
  const GsdBytes block = f.f_prm_defaults(m);
  out << "      F-parameters " << (block.empty() ? std::string("(none)") : gsd_hex(block))
      << "; F_Ext_Module_Prm_Data_Len "
      << (m.f.prm.declared_len ? std::to_string(*m.f.prm.declared_len) : std::string("-"));
  if (m.f.param_desc_crc) out << ", F_ParamDescCRC " << hex16(*m.f.param_desc_crc);
  if (m.f.io_structure_desc_crc) out << ", F_IO_StructureDescCRC " << hex32(*m.f.io_structure_desc_crc);
  out << "\n";
}

void print_ext_user_prm_data(const GsdFile& f, const char* kind,
                             const std::map<std::uint16_t, devices::GsdExtUserPrmData>& defs, std::ostream& out) {
  for (const auto& [ref, e] : defs) {
    out << "  " << kind << " " << ref << " \"" << e.name << "\": " << type_text(e) << ", default "
        << e.default_value << ", allowed " << allowed_text(e);
    if (!e.changeable) out << ", not changeable";
    if (!e.visible) out << ", hidden";
    out << "\n";
    if (e.prm_text_ref) {
      auto it = f.prm_texts().find(*e.prm_text_ref);
      if (it != f.prm_texts().end())
        for (const auto& [v, t] : it->second.texts) out << "      " << v << " = " << t << "\n";
    }
  }
}

void print_text(const GsdFile& f, std::ostream& out) {
  const auto& i = f.info();
  out << "File:               " << f.file_name() << "\n";
  out << "Ident_Number:       " << hex16(i.ident_number) << "\n";
  out << "Station_Type:       " << int(i.station_type) << " (" << station_type_name(i.station_type) << ")\n";
  out << "Vendor_Name:        " << i.vendor_name << "\n";
  out << "Model_Name:         " << i.model_name << "\n";
  out << "Revision:           " << i.revision << "\n";
  out << "GSD_Revision:       " << int(i.gsd_revision) << "\n";
  if (!i.order_number.empty()) out << "OrderNumber:        " << i.order_number << "\n";
  if (!i.info_text.empty()) out << "Info_Text:          " << i.info_text << "\n";

  out << "\nBaud rates (MaxTsdr in bit times):\n";
  for (const auto& b : f.baud_rates()) {
    std::string name(bus::baud_name(b.baud));
    out << "  " << name << std::string(name.size() < 8 ? 8 - name.size() : 1, ' ') << "MaxTsdr "
        << b.max_tsdr << "\n";
  }

  const auto& s = f.slave_features();
  out << "\nSlave features:\n";
  out << "  Freeze_Mode_supp " << yn(s.freeze_mode_supp) << ", Sync_Mode_supp " << yn(s.sync_mode_supp)
      << ", Auto_Baud_supp " << yn(s.auto_baud_supp) << ", Set_Slave_Add_supp "
      << yn(s.set_slave_add_supp) << ", Fail_Safe " << yn(s.fail_safe) << "\n";
  out << "  Min_Slave_Intervall " << s.min_slave_intervall << " (x 100 us), Max_Diag_Data_Len "
      << int(s.max_diag_data_len) << "\n";
  out << "  Modular_Station " << yn(s.modular_station) << ", Max_Module " << int(s.max_module)
      << ", Max_Input_Len " << int(s.max_input_len) << ", Max_Output_Len " << int(s.max_output_len)
      << ", Max_Data_Len " << s.max_data_len << "\n";

  out << "\nModules (" << f.modules().size() << "):\n";
  for (std::size_t n = 0; n < f.modules().size(); ++n) {
    const auto& m = f.modules()[n];
    out << "  [" << n << "] \"" << m.name << "\"";
    if (m.reference) out << " ref " << *m.reference;
    out << ": cfg " << hex_list(m.config, ",") << ", in " << m.input_len << ", out " << m.output_len;
    if (m.consistent) out << ", consistent";
    const GsdBytes prm = f.prm_area_defaults(m.prm);
    if (!prm.empty()) out << ", prm " << gsd_hex(prm);
    out << "\n";
    if (m.f.present()) print_f_parameters(f, m, out);
  }

  out << "\nParameters:\n";
  const auto& g = f.global_prm();
  out << "  User_Prm_Data_Len "
      << (g.declared_len ? std::to_string(*g.declared_len) : std::string("-"))
      << ", Max_User_Prm_Data_Len " << int(f.max_user_prm_data_len()) << "\n";
  out << "  station defaults: " << (gsd_hex(f.prm_area_defaults(g)).empty() ? "(none)" : gsd_hex(f.prm_area_defaults(g))) << "\n";
  print_ext_user_prm_data(f, "ExtUserPrmData", f.ext_user_prm_data(), out);
  print_ext_user_prm_data(f, "F_ExtUserPrmData", f.f_ext_user_prm_data(), out);

  const auto& d = f.dpv1();
  out << "\nDP-V1:              " << (d.dpv1_slave ? "yes" : "no") << "\n";
  // Every DP-V1 keyword the model holds, also for a file that sets some without DPV1_Slave.
  if (d != devices::GsdDpv1Features{}) {
    out << "  C1_Read_Write_supp " << yn(d.c1_read_write_supp) << ", C1_Max_Data_Len "
        << int(d.c1_max_data_len) << ", C1_Response_Timeout " << d.c1_response_timeout << "\n";
    out << "  C2_Read_Write_supp " << yn(d.c2_read_write_supp) << ", C2_Max_Data_Len "
        << int(d.c2_max_data_len) << ", C2_Response_Timeout " << d.c2_response_timeout
        << ", C2_Max_Count_Channels " << int(d.c2_max_count_channels) << "\n";
    out << "  alarms: Diagnostic " << yn(d.diagnostic_alarm_supp) << ", Process "
        << yn(d.process_alarm_supp) << ", Pull_Plug " << yn(d.pull_plug_alarm_supp) << ", Status "
        << yn(d.status_alarm_supp) << ", Update " << yn(d.update_alarm_supp)
        << ", Manufacturer_Specific " << yn(d.manufacturer_specific_alarm_supp)
        << "; Alarm_Sequence_Mode_Count " << int(d.alarm_sequence_mode_count) << "\n";
    out << "  alarms required: Diagnostic " << yn(d.diagnostic_alarm_required) << ", Process "
        << yn(d.process_alarm_required) << ", Pull_Plug " << yn(d.pull_plug_alarm_required) << ", Status "
        << yn(d.status_alarm_required) << ", Update " << yn(d.update_alarm_required)
        << ", Manufacturer_Specific " << yn(d.manufacturer_specific_alarm_required) << "\n";
    out << "  Extra_Alarm_SAP_supp " << yn(d.extra_alarm_sap_supp) << ", Alarm_Type_Mode_supp "
        << yn(d.alarm_type_mode_supp) << "\n";
    out << "  C1_Read_Write_required " << yn(d.c1_read_write_required) << ", C2_Read_Write_required "
        << yn(d.c2_read_write_required) << ", Max_Initiate_PDU_Length " << int(d.max_initiate_pdu_length) << "\n";
    out << "  WD_Base_1ms_supp " << yn(d.wd_base_1ms_supp) << ", Check_Cfg_Mode "
        << yn(d.check_cfg_mode) << ", Ident_Maintenance_supp " << yn(d.ident_maintenance_supp) << "\n";
    out << "  DPV1_Data_Types " << yn(d.dpv1_data_types) << ", Publisher_supp " << yn(d.publisher_supp)
        << ", Time_Sync_supp " << yn(d.time_sync_supp) << "\n";
    out << "  Prm_Block_Structure_supp " << yn(d.prm_block_structure_supp) << ", Prm_Block_Structure_req "
        << yn(d.prm_block_structure_req) << ", Fail_Safe_required " << yn(d.fail_safe_required) << "\n";
    out << "  Isochron_Mode_supp " << yn(d.isochron_mode_supp) << ", Isochron_Mode_required "
        << yn(d.isochron_mode_required) << "\n";
  }
  if (f.is_master()) {
    const auto& m = f.master();
    out << "\nMaster:\n";
    if (m.max_slaves_supp) out << "  Max_Slaves_supp " << int(*m.max_slaves_supp) << "\n";
    if (m.min_poll_timeout) out << "  Min_Poll_Timeout " << *m.min_poll_timeout << "\n";
    out << "  DPV1_Master " << yn(m.dpv1_master) << ", C1_Master_Read_Write_supp "
        << yn(m.c1_master_read_write_supp) << "\n";
    for (const auto& [baud, trdy] : m.trdy) out << "  Trdy_" << bus::baud_name(baud) << " " << trdy << "\n";
    for (const auto& [baud, tsdi] : m.tsdi) out << "  Tsdi_" << bus::baud_name(baud) << " " << tsdi << "\n";
  }
  const auto& r = f.redundancy();
  out << "\nRedundancy:         Redundancy " << yn(r.redundancy) << ", PrmCmd_supp " << yn(r.prm_cmd_supp)
      << ", Slave_Redundancy_supp " << int(r.slave_redundancy_supp)
      << ", Slave_Max_Switch_Over_Time " << r.slave_max_switch_over_time << "\n";
  // Bit meanings and unit are pbvbus's reading (gsd.hpp GsdRedundancy).
  if (!r.prm_cmd_supp && r.slave_redundancy_supp == 0 && r.slave_max_switch_over_time == 0) {
    out << "  slave redundancy: not supported\n";
  } else {
    out << "  slave redundancy: System " << yn(r.system_redundancy()) << ", Flying " << yn(r.flying_redundancy());
    if (r.reserved_redundancy_bits() != 0) out << ", reserved bits " << hex_byte(r.reserved_redundancy_bits());
    out << "; max switchover ";
    if (auto ms = r.switch_over_time_ms())
      out << *ms << " ms";
    else
      out << "not stated";
    out << "\n";
  }
}

// --- JSON output -------------------------------------------------------------------------------

const char* jb(bool b) { return b ? "true" : "false"; }

std::string jbytes(const GsdBytes& b) {
  std::string s = "[";
  for (std::size_t i = 0; i < b.size(); ++i) {
    if (i) s += ",";
    s += std::to_string(b[i]);
  }
  return s + "]";
}

std::string json_f_parameters(const GsdFile& f, const devices::GsdModule& m) {
  if (!m.f.present()) return "null";
  auto opt = [](const auto& o) { return o ? std::to_string(*o) : std::string("null"); };
  return "{\"f_ext_module_prm_data_len\": " + opt(m.f.prm.declared_len) + ", \"defaults\": " +
         jbytes(f.f_prm_defaults(m)) + ", \"f_param_desc_crc\": " + opt(m.f.param_desc_crc) +
         ", \"f_io_structure_desc_crc\": " + opt(m.f.io_structure_desc_crc) + "}";
}

std::string json_ext_user_prm_data(const GsdFile& f, const std::map<std::uint16_t, devices::GsdExtUserPrmData>& defs) {
  std::ostringstream out;
  out << "[";
  bool first = true;
  for (const auto& [ref, e] : defs) {
    out << (first ? "" : ",") << "\n    {\"ref\": " << ref << ", \"name\": " << json_quote(e.name)
        << ", \"type\": " << json_quote(devices::gsd_data_type_name(e.type)) << ", \"bit_first\": " << int(e.bit_first)
        << ", \"bit_last\": " << int(e.bit_last) << ", \"default\": " << e.default_value
        << ", \"min\": " << e.min_value << ", \"max\": " << e.max_value << ", \"allowed\": [";
    for (std::size_t k = 0; k < e.allowed.size(); ++k) out << (k ? "," : "") << e.allowed[k];
    out << "], \"changeable\": " << jb(e.changeable) << ", \"visible\": " << jb(e.visible) << ", \"texts\": [";
    if (e.prm_text_ref) {
      auto it = f.prm_texts().find(*e.prm_text_ref);
      if (it != f.prm_texts().end()) {
        bool ft = true;
        for (const auto& [v, t] : it->second.texts) {
          out << (ft ? "" : ", ") << "{\"value\": " << v << ", \"text\": " << json_quote(t) << "}";
          ft = false;
        }
      }
    }
    out << "]}";
    first = false;
  }
  out << (first ? "]" : "\n  ]");
  return out.str();
}

void print_json(const GsdFile& f, const std::vector<devices::GsdMessage>& warnings, std::ostream& out) {
  const auto& i = f.info();
  out << "{\n";
  out << "  \"file\": " << json_quote(f.file_name()) << ",\n";
  out << "  \"ident_number\": " << i.ident_number << ",\n";
  out << "  \"ident_number_hex\": " << json_quote(hex16(i.ident_number)) << ",\n";
  out << "  \"station_type\": " << int(i.station_type) << ",\n";
  out << "  \"gsd_revision\": " << int(i.gsd_revision) << ",\n";
  out << "  \"vendor_name\": " << json_quote(i.vendor_name) << ",\n";
  out << "  \"model_name\": " << json_quote(i.model_name) << ",\n";
  out << "  \"revision\": " << json_quote(i.revision) << ",\n";
  out << "  \"hardware_release\": " << json_quote(i.hardware_release) << ",\n";
  out << "  \"software_release\": " << json_quote(i.software_release) << ",\n";
  out << "  \"order_number\": " << json_quote(i.order_number) << ",\n";
  out << "  \"slave_family\": " << json_quote(i.slave_family) << ",\n";
  out << "  \"info_text\": " << json_quote(i.info_text) << ",\n";
  out << "  \"baud_rates\": [";
  for (std::size_t n = 0; n < f.baud_rates().size(); ++n) {
    const auto& b = f.baud_rates()[n];
    out << (n ? ", " : "") << "{\"baud\": " << json_quote(bus::baud_name(b.baud))
        << ", \"bit_per_s\": " << static_cast<std::uint32_t>(b.baud) << ", \"max_tsdr\": " << b.max_tsdr << "}";
  }
  out << "],\n";
  const auto& s = f.slave_features();
  out << "  \"slave\": {\"freeze_mode_supp\": " << jb(s.freeze_mode_supp)
      << ", \"sync_mode_supp\": " << jb(s.sync_mode_supp) << ", \"auto_baud_supp\": " << jb(s.auto_baud_supp)
      << ", \"set_slave_add_supp\": " << jb(s.set_slave_add_supp) << ", \"fail_safe\": " << jb(s.fail_safe)
      << ", \"min_slave_intervall\": " << s.min_slave_intervall
      << ", \"max_diag_data_len\": " << int(s.max_diag_data_len)
      << ", \"modular_station\": " << jb(s.modular_station) << ", \"max_module\": " << int(s.max_module)
      << ", \"max_input_len\": " << int(s.max_input_len) << ", \"max_output_len\": " << int(s.max_output_len)
      << ", \"max_data_len\": " << s.max_data_len << "},\n";
  out << "  \"modules\": [";
  for (std::size_t n = 0; n < f.modules().size(); ++n) {
    const auto& m = f.modules()[n];
    out << (n ? "," : "") << "\n    {\"index\": " << n << ", \"name\": " << json_quote(m.name) << ", \"reference\": "
        << (m.reference ? std::to_string(*m.reference) : std::string("null")) << ", \"config\": "
        << jbytes(m.config) << ", \"config_hex\": " << json_quote(hex_list(m.config, ","))
        << ", \"input_len\": " << m.input_len << ", \"output_len\": " << m.output_len
        << ", \"consistent\": " << jb(m.consistent) << ", \"prm_defaults\": " << jbytes(f.prm_area_defaults(m.prm))
        << ", \"f_parameters\": " << json_f_parameters(f, m) << ", \"info_text\": " << json_quote(m.info_text) << "}";
  }
  out << "\n  ],\n";
  const auto& g = f.global_prm();
  out << "  \"parameters\": {\"user_prm_data_len\": "
      << (g.declared_len ? std::to_string(*g.declared_len) : std::string("null"))
      << ", \"max_user_prm_data_len\": " << int(f.max_user_prm_data_len())
      << ", \"station_defaults\": " << jbytes(f.prm_area_defaults(g))
      << ", \"ext_user_prm_data\": " << json_ext_user_prm_data(f, f.ext_user_prm_data())
      << ", \"f_ext_user_prm_data\": " << json_ext_user_prm_data(f, f.f_ext_user_prm_data()) << "},\n";
  const auto& d = f.dpv1();
  out << "  \"dpv1\": {\"dpv1_slave\": " << jb(d.dpv1_slave) << ", \"c1_read_write_supp\": " << jb(d.c1_read_write_supp)
      << ", \"c1_read_write_required\": " << jb(d.c1_read_write_required)
      << ", \"c1_max_data_len\": " << int(d.c1_max_data_len) << ", \"c1_response_timeout\": " << d.c1_response_timeout
      << ", \"c2_read_write_supp\": " << jb(d.c2_read_write_supp)
      << ", \"c2_read_write_required\": " << jb(d.c2_read_write_required)
      << ", \"c2_max_data_len\": " << int(d.c2_max_data_len)
      << ", \"c2_response_timeout\": " << d.c2_response_timeout
      << ", \"c2_max_count_channels\": " << int(d.c2_max_count_channels)
      << ", \"max_initiate_pdu_length\": " << int(d.max_initiate_pdu_length)
      << ", \"diagnostic_alarm_supp\": " << jb(d.diagnostic_alarm_supp)
      << ", \"process_alarm_supp\": " << jb(d.process_alarm_supp)
      << ", \"pull_plug_alarm_supp\": " << jb(d.pull_plug_alarm_supp)
      << ", \"status_alarm_supp\": " << jb(d.status_alarm_supp) << ", \"update_alarm_supp\": " << jb(d.update_alarm_supp)
      << ", \"manufacturer_specific_alarm_supp\": " << jb(d.manufacturer_specific_alarm_supp)
      << ", \"diagnostic_alarm_required\": " << jb(d.diagnostic_alarm_required)
      << ", \"process_alarm_required\": " << jb(d.process_alarm_required)
      << ", \"pull_plug_alarm_required\": " << jb(d.pull_plug_alarm_required)
      << ", \"status_alarm_required\": " << jb(d.status_alarm_required)
      << ", \"update_alarm_required\": " << jb(d.update_alarm_required)
      << ", \"manufacturer_specific_alarm_required\": " << jb(d.manufacturer_specific_alarm_required)
      << ", \"extra_alarm_sap_supp\": " << jb(d.extra_alarm_sap_supp)
      << ", \"alarm_type_mode_supp\": " << jb(d.alarm_type_mode_supp)
      << ", \"alarm_sequence_mode_count\": " << int(d.alarm_sequence_mode_count)
      << ", \"wd_base_1ms_supp\": " << jb(d.wd_base_1ms_supp) << ", \"check_cfg_mode\": " << jb(d.check_cfg_mode)
      << ", \"dpv1_data_types\": " << jb(d.dpv1_data_types) << ", \"publisher_supp\": " << jb(d.publisher_supp)
      << ", \"ident_maintenance_supp\": " << jb(d.ident_maintenance_supp)
      << ", \"time_sync_supp\": " << jb(d.time_sync_supp)
      << ", \"prm_block_structure_supp\": " << jb(d.prm_block_structure_supp)
      << ", \"prm_block_structure_req\": " << jb(d.prm_block_structure_req)
      << ", \"fail_safe_required\": " << jb(d.fail_safe_required)
      << ", \"isochron_mode_supp\": " << jb(d.isochron_mode_supp)
      << ", \"isochron_mode_required\": " << jb(d.isochron_mode_required) << "},\n";
  const auto& r = f.redundancy();
  out << "  \"redundancy\": {\"redundancy\": " << jb(r.redundancy) << ", \"prm_cmd_supp\": " << jb(r.prm_cmd_supp)
      << ", \"slave_redundancy_supp\": " << int(r.slave_redundancy_supp)
      << ", \"slave_max_switch_over_time\": " << r.slave_max_switch_over_time
      << ", \"system_redundancy\": " << jb(r.system_redundancy())
      << ", \"flying_redundancy\": " << jb(r.flying_redundancy())
      << ", \"switch_over_time_ms\": "
      << (r.switch_over_time_ms() ? std::to_string(*r.switch_over_time_ms()) : std::string("null")) << "},\n";
  const auto& m = f.master();
  auto opt = [](const auto& o) { return o ? std::to_string(*o) : std::string("null"); };
  auto per_baud = [](const std::map<bus::Baud, std::uint16_t>& mp) {
    std::string o = "{";
    for (const auto& [b, v] : mp) o += (o.size() > 1 ? ", " : "") + json_quote(bus::baud_name(b)) + ": " + std::to_string(v);
    return o + "}";
  };
  out << "  \"master\": {\"is_master\": " << jb(f.is_master()) << ", \"max_slaves_supp\": " << opt(m.max_slaves_supp)
      << ", \"min_poll_timeout\": " << opt(m.min_poll_timeout) << ", \"dpv1_master\": " << jb(m.dpv1_master)
      << ", \"c1_master_read_write_supp\": " << jb(m.c1_master_read_write_supp) << ", \"trdy\": " << per_baud(m.trdy)
      << ", \"tqui\": " << per_baud(m.tqui) << ", \"tset\": " << per_baud(m.tset) << ", \"tsdi\": " << per_baud(m.tsdi)
      << "},\n";
  out << "  \"unknown_keywords\": [";
  for (std::size_t n = 0; n < f.unknown_keywords().size(); ++n) {
    const auto& k = f.unknown_keywords()[n];
    out << (n ? ", " : "") << "{\"name\": " << json_quote(k.name) << ", \"value\": " << json_quote(k.value) << ", \"line\": " << k.line << "}";
  }
  out << "],\n";
  out << "  \"warnings\": [";
  for (std::size_t n = 0; n < warnings.size(); ++n) out << (n ? ", " : "") << json_quote(warnings[n].to_string());
  out << "]\n}\n";
}

}  // namespace

int cmd_gsd(const Args& args, std::ostream& out, std::ostream& err) {
  bool json = false;
  std::string file;
  for (const auto& a : args) {
    if (a == "--help" || a == "-h") {
      out << kGsdUsage;
      return 0;
    }
    if (a == "--json") {
      json = true;
    } else if (!a.empty() && a[0] == '-' && a != "-") {
      err << "pbvbus gsd: unknown option '" << a << "'\n" << kGsdUsage;
      return 2;
    } else if (!file.empty()) {
      err << "pbvbus gsd: only one FILE, got '" << file << "' and '" << a << "'\n";
      return 2;
    } else {
      file = a;
    }
  }
  if (file.empty()) {
    err << kGsdUsage;
    return 2;
  }
  const devices::GsdParseResult r = devices::load_gsd(file);
  for (const auto& w : r.warnings) {
    devices::GsdMessage m = w;
    m.reason = "warning: " + m.reason;
    err << m.to_string() << "\n";
  }
  if (!r.ok()) {
    for (const auto& e : r.errors) err << e.to_string() << "\n";
    return 2;
  }
  if (json)
    print_json(*r.file, r.warnings, out);
  else
    print_text(*r.file, out);
  return 0;
}

}  // namespace pbvbus::tools
