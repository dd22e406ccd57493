#pragma once
// What a DP slave is (IEC 61158-6 DP; protocol-facts.md §D, §E): identity, supported features,
// parameter limits and its real configuration. A plain struct, independent of GSD files; the
// GSD-driven builder in devices/ fills it.
//
// Conventions decided here:
// - The user prm data limits and the check callback see Set_Prm octets 8.. (GSD
//   User_Prm_Data, which for a DP-V1 slave begins with DPV1_Status_1..3).
// - A module is one or more configuration identifiers; its data is the concatenation of its
//   identifiers' data in the Data_Exchange telegram. The identifier-related diagnosis and the
//   DP-V1 Module_Status count modules. DP-V1 slot numbers: slot 0 = the device itself, slot
//   n (1-based) = module n-1.
// - Every module is handed over as one unit between bus and device (a seqlock per module), so
//   it is consistent over its whole length whether or not the identifiers ask for it.

#include <cstdint>
#include <functional>
#include <span>
#include <string>
#include <vector>

#include "pbvbus/bus/time.hpp"
#include "pbvbus/dp/cfg_identifier.hpp"

namespace pbvbus::dp {

struct SlaveFeatures {
  bool sync = false;           ///< Sync_Supp
  bool freeze = false;         ///< Freeze_Supp
  bool fail_safe = false;      ///< Fail_Safe: zero-length outputs in Clear accepted
  bool set_slave_add = false;  ///< Set_Slave_Add_supp
  bool dpv1 = false;           ///< DPV1_Slave: DPV1_Enable may be set
  bool c1_read_write = false;  ///< C1_Read_Write_supp
  bool c2 = false;             ///< C2_Read_Write_supp
  std::uint8_t c2_connections = 1;      ///< C2_Max_Count_Channels
  std::uint8_t alarms_supported = 0;    ///< kEnable*Alarm bits of DPV1_Status_2 it accepts
  std::uint8_t max_alarm_mode = 0;      ///< highest Alarm_Mode (0..7) it accepts
  bool wd_base_1ms = false;             ///< WD_Base_1ms_supp
  bool check_cfg_mode = false;          ///< Check_Cfg_Mode_supp
  /// Structured Set_Prm blocks (DPV1_Status_3 Prm_Structure) accepted; their content is for
  /// SlaveConfig::check_user_prm (and for a redundancy layer above the engine).
  bool prm_structure = false;
  bool prm_cmd = false;                 ///< DPV1_Status_3 PrmCmd accepted (PrmCmd_supp)
};

struct SlaveModule {
  std::vector<std::uint8_t> cfg;  ///< identifier octets as in Get_Cfg
  std::string name;               ///< for reports only
};

/// User check of User_Prm_Data (octets 8..); false → Prm_Fault.
using UserPrmCheck = std::function<bool(std::span<const std::uint8_t> user_prm)>;
/// User check of a Chk_Cfg in Check_Cfg_Mode (DPV1_Status_2 bit 0); true = accepted.
using UserCfgCheck = std::function<bool(std::span<const std::uint8_t> chk_cfg)>;

/// A PrmCmd block (PI 2.212 slave redundancy, protocol-facts.md §G.2) that a Set_Prm carried,
/// handed to SlaveConfig::on_prm_cmd. The dp layer only checks the block's frame (a structured
/// block of type 0x02, 8 octets); its meaning is for the redundancy layer above.
struct PrmCmdView {
  bus::Ticks now = 0;
  std::uint8_t master = 0;  ///< FDL address of the master that sent it
  /// A "pure PrmCmd" Set_Prm (slave_engine.hpp): it changes nothing else, the slave stays in
  /// its state (Data_Exch included). False: part of a full parameterisation.
  bool pure = false;
  std::span<const std::uint8_t> block;  ///< the 8 octets, header included
};
enum class PrmCmdResult : std::uint8_t {
  Accept,
  Reject,  ///< the Set_Prm is a parameterisation error (Prm_Fault)
};
/// Called on the bus thread inside the Set_Prm, after every other check has passed.
using PrmCmdHandler = std::function<PrmCmdResult(const PrmCmdView&)>;

/// Test-only: breaks one rule on purpose (devices/slave_mutant.hpp, docs/mutants.md). Each value
/// is checked at the one place its rule lives in SlaveEngine; None is the conformant slave.
enum class EngineMutation : std::uint8_t {
  None,
  NoPrmReqBit,            ///< Slave_Diag in Power_On/Wait_Prm lacks Prm_Req (octet 2 bit 0)
  AcceptWrongIdent,       ///< Set_Prm with another Ident_Number is accepted
  IgnoreWatchdog,         ///< the watchdog never expires (WD_On is still reported)
  TearConsistent,         ///< Data_Exchange: a consistent module's first half from the previous image
  WrongGetCfg,            ///< Get_Cfg: the last octet of the real configuration + 1
  IgnoreClearData,        ///< Global_Control Clear_Data has no effect on the outputs
  IgnoreLock,             ///< Set_Prm from another master accepted while locked
  AcceptWrongCfg,         ///< a Chk_Cfg that does not match is accepted
  IgnoreFreeze,           ///< Freeze acknowledged (Freeze_Mode) but the inputs are not frozen
  IgnoreSync,             ///< Sync acknowledged (Sync_Mode) but outputs are applied at once
  SlowSlaveInterval,      ///< Data_Exchange < 10 x Min_Slave_Interval after the last one: no answer
  KeepStateOnPowerCycle,  ///< on_power_on keeps the parameterisation and the state
  Dpv1BadIndexAccepted,   ///< MSAC_C1 Read of an unknown index answers zero data, not 80 B0 00
  RejectFailSafe,         ///< zero-length Data_Exchange refused (RS) although Fail_Safe
  WrongDiagIdent,         ///< Slave_Diag octets 5..6 = Ident_Number + 1
  GetCfgSapsNotSwapped,   ///< Get_Cfg reply with DSAP 59, SSAP 62 (the request's, not mirrored)
  DataExchangeInWaitCfg,  ///< Data_Exchange from the owner answered in Wait_Cfg (before Chk_Cfg)
};

struct SlaveConfig {
  std::uint16_t ident = 0;
  SlaveFeatures features;
  std::size_t min_user_prm_len = 0;  ///< GSD User_Prm_Data_Len bounds
  std::size_t max_user_prm_len = 0;
  UserPrmCheck check_user_prm;       ///< optional
  UserCfgCheck check_cfg_user;       ///< optional; used only in Check_Cfg_Mode
  /// Optional; PrmCmd blocks (features.prm_cmd and prm_structure) go here. Without it they are
  /// accepted and ignored.
  PrmCmdHandler on_prm_cmd;
  std::vector<SlaveModule> modules;  ///< the real configuration, in Get_Cfg order
  std::uint16_t min_slave_interval = 1;  ///< 100 us units (GSD Min_Slave_Intervall)
  std::size_t max_diag_len = 244;        ///< GSD Max_Diag_Data_Len (6..244)
  /// test-only: breaks one rule on purpose (devices/slave_mutant.hpp); default none.
  EngineMutation mutation = EngineMutation::None;
};

/// Where a module's data sits in the Data_Exchange telegrams.
struct ModuleLayout {
  std::size_t in_offset = 0;
  std::size_t in_len = 0;
  std::size_t out_offset = 0;
  std::size_t out_len = 0;
  bool consistent = false;     ///< some identifier says "consistent over the whole length"
  std::size_t first_id = 0;    ///< index of its first identifier in SlaveLayout::identifiers
  std::size_t id_count = 0;
};

/// The real configuration decoded once.
struct SlaveLayout {
  std::vector<std::uint8_t> cfg;               ///< Get_Cfg DU
  std::vector<CfgIdentifier> identifiers;
  std::vector<std::size_t> module_of_id;       ///< identifier index → module index
  std::vector<ModuleLayout> modules;
  std::size_t inputs = 0;
  std::size_t outputs = 0;
};

/// Decodes and checks a configuration; returns an empty string if it is usable, else why not.
std::string build_layout(const SlaveConfig& cfg, SlaveLayout& out);

}  // namespace pbvbus::dp
