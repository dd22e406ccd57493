// The GSD text of an IM 157 link (link_gsd.hpp).
#include "pbvbus/dp_link/link_gsd.hpp"

#include <cstdio>

namespace pbvbus::devices {

const char* to_string(DpLinkKind k) {
  return k == DpLinkKind::YLink ? "Y-link" : "DP/PA link";
}

std::string link_gsd_text(DpLinkKind kind, const std::vector<LinkGsdModule>& modules,
                          bus::Ticks switchover) {
  const bool y = kind == DpLinkKind::YLink;
  const bus::Ticks unit = 10 * bus::kTicksPerMs;
  const unsigned long long so = static_cast<unsigned long long>((switchover + unit - 1) / unit);
  std::string t;
  t += "#Profibus_DP\nGSD_Revision = 5\nVendor_Name = \"pbvbus\"\n";
  t += std::string("Model_Name = \"pbvbus IM 157 ") + (y ? "Y-link" : "DP/PA link") + "\"\n";
  char buf[160];
  std::snprintf(buf, sizeof buf, "Ident_Number = 0x%04X\n", y ? kYLinkIdent : kDpPaLinkIdent);
  t += buf;
  t += "Revision = \"V1.0\"\nRevision_Number = 1\nProtocol_Ident = 0\nStation_Type = 0\n"
       "FMS_supp = 0\nHardware_Release = \"HW 1\"\nSoftware_Release = \"FW 1.0\"\n"
       "Implementation_Type = \"VPC3+S\"\n";
  static const char* const kBauds[] = {"9.6", "19.2", "45.45", "93.75", "187.5",
                                       "500", "1.5M", "3M",    "6M",    "12M"};
  static const unsigned kTsdr[] = {60, 60, 250, 60, 60, 100, 150, 250, 450, 800};
  for (std::size_t i = 0; i < std::size(kBauds); ++i) {
    std::snprintf(buf, sizeof buf, "%s_supp = 1\nMaxTsdr_%s = %u\n", kBauds[i], kBauds[i], kTsdr[i]);
    t += buf;
  }
  t += "Redundancy = 0\nRepeater_Ctrl_Sig = 2\n24V_Pins = 0\nFreeze_Mode_supp = 0\n"
       "Sync_Mode_supp = 0\nAuto_Baud_supp = 1\nSet_Slave_Add_supp = 0\nFail_Safe = 1\n"
       "Min_Slave_Intervall = 1\nMax_Diag_Data_Len = 128\nModular_Station = 1\n";
  std::snprintf(buf, sizeof buf, "Max_Module = %zu\n", kLinkMaxLowerStations);
  t += buf;
  t += "Max_Input_Len = 244\nMax_Output_Len = 244\nMax_Data_Len = 488\n"
       "DPV1_Slave = 1\nC1_Read_Write_supp = 1\nC1_Max_Data_Len = 240\n"
       "C1_Response_Timeout = 100\nDiagnostic_Alarm_supp = 1\nPull_Plug_Alarm_supp = 1\n"
       "Prm_Block_Structure_supp = 1\nPrmCmd_supp = 1\nSlave_Redundancy_supp = 1\n";
  std::snprintf(buf, sizeof buf, "Slave_Max_Switch_Over_Time = %llu\n", so);
  t += buf;
  t += "Max_User_Prm_Data_Len = 11\nUser_Prm_Data_Len = 3\n"
       "Ext_User_Prm_Data_Const(0) = 0x80,0x00,0x00\n";
  for (std::size_t m = 0; m < modules.size(); ++m) {
    t += "Module = \"" + modules[m].name + "\" ";
    for (std::size_t i = 0; i < modules[m].cfg.size(); ++i) {
      std::snprintf(buf, sizeof buf, "%s0x%02X", i == 0 ? "" : ",", modules[m].cfg[i]);
      t += buf;
    }
    t += "\n" + std::to_string(m + 1) + "\nEndModule\n";
  }
  return t;
}

}  // namespace pbvbus::devices
