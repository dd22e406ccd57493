#pragma once
// GSD files (PROFIBUS "Specification for PROFIBUS Device Description and Device Integration",
// PI 2.122): the typed model of a device description, and the reader that builds it from the
// bytes of a real vendor file (protocol-facts.md §I; baud keywords and MaxTsdr §C.1; Set_Prm and
// User_Prm_Data incl. DPV1_Status_1..3 §D.2; configuration identifiers §D.3; DP-V1 keywords §E;
// redundancy keywords §G.7).
//
// The reader never throws and never crashes on garbage: parse_gsd() returns either a GsdFile or
// a list of errors, each "file:line: reason". Keywords it does not know are kept (name, raw value,
// line) and reported as warnings.
//
// Decisions where PI 2.122 (or our reading of it) is silent, as a PROFIBUS engineer would expect:
// - Encoding: ISO-8859-1; strings are converted to UTF-8 in the model. A file that starts with a
//   UTF-8 byte order mark and is valid UTF-8 is read as UTF-8 (with a warning).
// - Only the `#Profibus_DP` section is read; text before it is ignored, a later `#...` line ends
//   it (warning).
// - Booleans must be 0 or 1. Numbers are decimal or 0x hex; a value out of the keyword's range is
//   an error, except Max_Input_Len/Max_Output_Len above 244 and Max_Data_Len above 488 (files
//   in the field write 249 and 498): those are clamped to the DP limit with a warning.
// - A keyword given twice: the later value wins, with a warning. Likewise a PrmText or
//   ExtUserPrmData number defined twice (vendor files repeat copied blocks): the later block
//   replaces the earlier one, with a warning at the later block's line.
// - Common misspellings are read as the keyword they mean, with a warning: Min_Slave_Interval
//   (one l) as Min_Slave_Intervall, WB_Base_1ms_supp as WD_Base_1ms_supp.
// - A block without its end keyword (EndModule, EndPrmText, EndExtUserPrmData, ...) is one error
//   at the line that opened it, naming the statement that showed the end missing: a block start,
//   another block's end keyword, or a top-level keyword the block cannot contain (a Module keeps
//   the keywords PI 2.122 allows in modules; UnitDiagType, Physical_Interface and Data_Area
//   contents are not interpreted, so only a block boundary ends them; X_Unit_Diag_Area and
//   Unit_Diag_Area blocks nest inside a UnitDiagType). The statement then counts where it
//   belongs, and the missing end keyword, if it comes later, is not reported again.
// - A keyword X_<name> the reader does not know, followed by X_<name>_End before the next block
//   boundary (a block start or end keyword), is an unknown block of a later GSD revision: one
//   warning at its start, its content is skipped, and the file stays usable. GSD revision 5 adds
//   its extensions as X_ keywords (X_Unit_Diag_*, X_Ext_Module_Prm_Data_*); an X_ keyword
//   without such an end is an unknown keyword like any other.
// - User_Prm_Data assembly (user_prm_data()): the global area is User_Prm_Data_Len bytes (or, when
//   absent, as long as its data), initialised from User_Prm_Data, then the
//   Ext_User_Prm_Data_Const(o) overlays, then the Ext_User_Prm_Data_Ref(o) defaults; every
//   selected module appends an area of Ext_Module_Prm_Data_Len bytes built the same way, then
//   its PROFIsafe F-parameter block if it has one (below). An overlay beyond the declared length
//   extends the area (with a parse warning). The whole is truncated to Max_User_Prm_Data_Len
//   (reported in the outcome's notes).
// - DP-V1 slaves: the first three bytes of the global area are DPV1_Status_1..3 as the file writes
//   them (vendors put them in Ext_User_Prm_Data_Const(0)). A DP-V1 file whose global area is
//   shorter than 3 bytes gets a warning, and the assembly fills the missing status bytes with the
//   minimal DP-V1 values 0x80 (DPV1_Enable), 0x00, 0x00.
// - Multi-byte parameters (Unsigned16/32, Signed16/32) are big-endian, as everything on PROFIBUS.
// - Bit(b) / BitArea(a-b) count bits from the LSB (bit 0 = 0x01) of the byte at the reference's
//   offset; several Ext_User_Prm_Data_Ref at one offset share that byte.
// - A module without Ext_Module_Prm_Data_Len has a parameter area as long as its overlays reach.
// - Configuration identifiers (§D.3): a special identifier's manufacturer count 15 means "none
//   follow" (Chk_Cfg semantics, since the GSD bytes are what the master sends in Chk_Cfg).
// - PROFIsafe (fail-safe) modules. protocol-facts.md is silent on them; what follows is our
//   reading of the PROFIsafe keywords of PI 2.122 (module items F_Ext_Module_Prm_Data_Len,
//   F_Ext_User_Prm_Data_Const/Ref, F_ParamDescCRC, F_IO_StructureDescCRC in the GSD grammar of
//   ISO 15745-3) and of how configuration tools fill the F-parameters:
//   * A module's part of User_Prm_Data is its Ext_Module_Prm_Data area followed by its
//     F-parameter block of F_Ext_Module_Prm_Data_Len octets (typically 10: F_Prm_Flag1,
//     F_Prm_Flag2, F_Source_Add, F_Dest_Add, F_WD_Time, F_Par_CRC; 14 with F_iPar_CRC).
//     F_Ext_User_Prm_Data_Const(o)/Ref(o) offsets count from the start of the F block, not of
//     the module's area: a module may carry both an Ext_User_Prm_Data_Const(0) and an
//     F_Ext_User_Prm_Data_Const(0) covering the whole F block, which only fits this reading [U].
//   * F_Ext_User_Prm_Data_Ref(o) = n names an `F_ExtUserPrmData = n "name" ...
//     EndF_ExtUserPrmData` block (same syntax as ExtUserPrmData, own numbering); when the file
//     has no F_ExtUserPrmData n, an ordinary ExtUserPrmData n is used [U: both forms are said to
//     occur; we could not see the PROFIsafe part of PI 2.122].
//   * The F block is assembled like any area: zeros, F_Ext_User_Prm_Data_Const overlays, then
//     the F_Ext_User_Prm_Data_Ref defaults (or settings with GsdPrmSetting::f_parameter). Without
//     F_Ext_Module_Prm_Data_Len the block is as long as its overlays reach (with a warning).
//   * F_Par_CRC (CRC1 over the F-parameters) is taken as the file gives it; a configuration tool
//     computes it, and a real F-host would reject a stale value. F_ParamDescCRC and
//     F_IO_StructureDescCRC are kept and shown, not verified (they cover the GSD description
//     text by a rule we do not have). [U: not computed]
// - Mandatory keywords: Ident_Number missing, a `*_supp = 1` baud rate without its MaxTsdr, no
//   baud rate at all, a slave without any Module, and Modular_Station = 1 without Max_Module are
//   errors; missing Station_Type, Min_Slave_Intervall or Max_Diag_Data_Len only warn.

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <map>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "pbvbus/bus/time.hpp"

namespace pbvbus::devices {

using GsdBytes = std::vector<std::uint8_t>;

/// One error or warning, located in the file.
struct GsdMessage {
  std::string file;
  std::uint32_t line = 0;  ///< 1-based; 0 = the file as a whole (e.g. cannot be read)
  std::string reason;
  /// "file:line: reason" (or "file: reason" for line 0).
  std::string to_string() const;
};

/// A keyword as written, kept raw: unknown keywords, and every keyword for keyword() look-ups.
struct GsdKeyword {
  std::string name;   ///< as written, without the index, e.g. "Bitmap_Device"
  std::string index;  ///< the text inside "(...)" if the keyword is indexed, else empty
  std::string value;  ///< the raw value text after '=' (UTF-8), trimmed
  std::uint32_t line = 0;
};

/// A supported baud rate and the slave's (or master's) max TSDR there, in bit times (§C.1).
struct GsdBaudRate {
  bus::Baud baud{};
  std::uint16_t max_tsdr = 0;
};

/// Identification and general keywords.
struct GsdInfo {
  std::uint8_t gsd_revision = 0;
  std::string vendor_name;
  std::string model_name;
  std::string revision;
  std::optional<std::uint8_t> revision_number;
  std::uint16_t ident_number = 0;
  std::uint8_t protocol_ident = 0;  ///< 0 = DP
  std::uint8_t station_type = 0;    ///< 0 = DP slave, 1 = DP master (class 1)
  bool fms_supp = false;
  std::string hardware_release;
  std::string software_release;
  std::string order_number;
  std::string info_text;
  std::string slave_family;         ///< raw "main@sub@..."
  std::string implementation_type;  ///< e.g. "VPC3"
};

/// DP-V0 slave features.
struct GsdSlaveFeatures {
  bool freeze_mode_supp = false;
  bool sync_mode_supp = false;
  bool auto_baud_supp = false;
  bool set_slave_add_supp = false;
  bool fail_safe = false;
  std::uint8_t repeater_ctrl_sig = 0;  ///< 0 none, 1 RS-485, 2 TTL
  std::uint8_t pins_24v = 0;            ///< 24V_Pins
  std::uint16_t min_slave_intervall = 0;  ///< unit 100 us
  std::uint8_t max_diag_data_len = 6;
  bool modular_station = false;
  std::uint8_t max_module = 1;
  std::uint8_t max_input_len = 244;
  std::uint8_t max_output_len = 244;
  std::uint16_t max_data_len = 488;
  std::uint16_t modul_offset = 0;
};

/// Data types of ExtUserPrmData (PI 2.122).
enum class GsdDataType { Bit, BitArea, Unsigned8, Unsigned16, Unsigned32, Signed8, Signed16, Signed32 };
std::string_view gsd_data_type_name(GsdDataType t);

/// PrmText = n ... EndPrmText: names for parameter values.
struct GsdPrmText {
  std::uint16_t ref = 0;
  std::vector<std::pair<std::int64_t, std::string>> texts;  ///< Text(value) = "..."
  std::uint32_t line = 0;
  const std::string* text_for(std::int64_t value) const;
};

/// ExtUserPrmData = ref "name" ... EndExtUserPrmData: one parameter's type, default and range.
struct GsdExtUserPrmData {
  std::uint16_t ref = 0;
  std::string name;
  GsdDataType type = GsdDataType::Unsigned8;
  std::uint8_t bit_first = 0;  ///< Bit(b): b; BitArea(a-b): a
  std::uint8_t bit_last = 0;   ///< Bit(b): b; BitArea(a-b): b
  std::int64_t default_value = 0;
  std::int64_t min_value = 0;  ///< range form (also set to the extremes of an enumeration)
  std::int64_t max_value = 0;
  std::vector<std::int64_t> allowed;  ///< enumerated form "a,b,c"; empty for the range form
  std::optional<std::uint16_t> prm_text_ref;
  bool changeable = true;
  bool visible = true;
  std::uint32_t line = 0;

  /// Bytes the parameter occupies in User_Prm_Data (1 for Bit/BitArea).
  std::size_t size() const;
  bool accepts(std::int64_t v) const;
};

/// Ext_User_Prm_Data_Const(offset) = bytes.
struct GsdPrmConst {
  std::uint16_t offset = 0;
  GsdBytes data;
  std::uint32_t line = 0;
};

/// Ext_User_Prm_Data_Ref(offset) = ref.
struct GsdPrmRef {
  std::uint16_t offset = 0;
  std::uint16_t ref = 0;
  std::uint32_t line = 0;
};

/// One area of User_Prm_Data: the global one or a module's.
struct GsdPrmArea {
  std::optional<std::uint16_t> declared_len;  ///< User_Prm_Data_Len / Ext_Module_Prm_Data_Len
  GsdBytes initial;                           ///< User_Prm_Data (global area only)
  std::vector<GsdPrmConst> consts;
  std::vector<GsdPrmRef> refs;
  /// Length the area takes in User_Prm_Data (declared length, extended to cover every overlay).
  std::size_t length(const std::map<std::uint16_t, GsdExtUserPrmData>& defs) const;
};

/// A PROFIsafe module's F-parameters (see the PROFIsafe decisions above).
struct GsdFParameters {
  /// F_Ext_Module_Prm_Data_Len, F_Ext_User_Prm_Data_Const(o), F_Ext_User_Prm_Data_Ref(o); offsets
  /// count from the start of the F-parameter block.
  GsdPrmArea prm;
  std::optional<std::uint16_t> param_desc_crc;         ///< F_ParamDescCRC (not verified)
  std::optional<std::uint32_t> io_structure_desc_crc;  ///< F_IO_StructureDescCRC (not verified)
  /// Any F-parameter keyword given: a fail-safe (PROFIsafe) module.
  bool present() const {
    return prm.declared_len || !prm.consts.empty() || !prm.refs.empty() || param_desc_crc ||
           io_structure_desc_crc;
  }
};

/// Module = "name" cfg bytes ... EndModule.
struct GsdModule {
  std::string name;
  GsdBytes config;  ///< identifier bytes as sent in Chk_Cfg (§D.3)
  std::optional<std::uint32_t> reference;  ///< the module reference number line
  std::size_t input_len = 0;   ///< bytes, derived from the identifiers (§D.3)
  std::size_t output_len = 0;  ///< bytes
  bool consistent = false;     ///< any identifier asks for consistency over the whole length
  GsdPrmArea prm;
  GsdFParameters f;  ///< PROFIsafe F-parameters, appended after prm in User_Prm_Data
  std::string info_text;
  std::vector<GsdKeyword> other_keywords;  ///< module-local keywords not modelled (raw)
  std::uint32_t line = 0;
};

/// Unit_Diag_Area = first-last / Value(n) = "..." / Unit_Diag_Area_End, and the X_ variant
/// X_Unit_Diag_Area / X_Value(n) / X_Unit_Diag_Area_End (see GsdUnitDiagType).
struct GsdUnitDiagArea {
  std::uint16_t first_bit = 0;
  std::uint16_t last_bit = 0;
  std::vector<std::pair<std::int64_t, std::string>> values;      ///< Value(n) / X_Value(n)
  std::vector<std::pair<std::int64_t, std::string>> value_help;  ///< Value_Help(n) / X_Value_Help(n)
  bool x_variant = false;
  std::uint32_t line = 0;
};

/// Texts for single bits of the device-related diagnosis: (X_)Unit_Diag_Bit(n),
/// (X_)Unit_Diag_Bit_Help(n), (X_)Unit_Diag_Not_Bit(n), (X_)Unit_Diag_Not_Bit_Help(n). A "Not_Bit"
/// text is shown while the bit is 0 (PI 2.122).
struct GsdDiagBitTexts {
  std::map<std::uint32_t, std::string> bits;
  std::map<std::uint32_t, std::string> bit_help;
  std::map<std::uint32_t, std::string> not_bits;
  std::map<std::uint32_t, std::string> not_bit_help;
  bool empty() const { return bits.empty() && bit_help.empty() && not_bits.empty() && not_bit_help.empty(); }
};

/// UnitDiagType = n ... EndUnitDiagType (GSD revision 4 and later): the texts of a DP-V1
/// device-related diagnosis block whose type octet (Alarm_Type, or Status_Type with bit 7 set,
/// the octet after the block's header; §E) is n — e.g. 129 = 0x81, a status message, which
/// PROFIsafe devices use for the F-parameter faults 64..71. Inside the block the file writes the
/// X_ keywords: X_Unit_Diag_Bit(n), X_Unit_Diag_Bit_Help(n), X_Unit_Diag_Not_Bit(n),
/// X_Unit_Diag_Not_Bit_Help(n) and X_Unit_Diag_Area = a-b / X_Value(v) / X_Value_Help(v) /
/// X_Unit_Diag_Area_End.
///
/// Decisions (PI 2.122 revision 5's keyword list as seen in vendor files and open-source readers;
/// the spec's own text was not consulted) [U]:
/// - Bit numbers are kept as written: like Unit_Diag_Bit they count from bit 0 of the first octet
///   after the block's header octet, so a PROFIsafe code area 24-31 is the first octet after
///   type, slot and specifier. The reader does not interpret them against a telegram.
/// - Inside the block the plain spellings (Unit_Diag_Bit, Unit_Diag_Area, Value, ...) count as
///   their X_ variants, as files mix them (like the two diagnosis-area end keywords).
/// - The X_ keywords are also accepted outside any UnitDiagType (GsdFile::x_unit_diag(), and
///   X_Unit_Diag_Area in unit_diag_areas() with x_variant set), as older revision-4 files do.
/// - A type value that is not a number 0..255 is a warning; the block's texts are kept with
///   `type` unset.
struct GsdUnitDiagType {
  std::optional<std::uint8_t> type;
  GsdDiagBitTexts texts;
  std::vector<GsdUnitDiagArea> areas;
  std::uint32_t line = 0;
};

/// SlotDefinition: Slot(n) = "name" default allowed.
struct GsdSlot {
  std::uint16_t number = 0;
  std::string name;
  std::uint32_t default_ref = 0;
  std::vector<std::pair<std::uint32_t, std::uint32_t>> allowed;  ///< inclusive ranges of refs
  std::uint32_t line = 0;
};

/// DP-V1 features (§E and I.2).
struct GsdDpv1Features {
  bool dpv1_slave = false;
  bool c1_read_write_supp = false;
  bool c1_read_write_required = false;
  std::uint8_t c1_max_data_len = 0;       ///< <= 240
  std::uint16_t c1_response_timeout = 0;  ///< unit 10 ms [U]
  bool c2_read_write_supp = false;
  bool c2_read_write_required = false;
  std::uint8_t c2_max_data_len = 0;  ///< 0 or 48..240
  std::uint16_t c2_response_timeout = 0;
  std::uint8_t c2_max_count_channels = 0;
  std::uint8_t max_initiate_pdu_length = 0;  ///< 0 or 52..244
  bool diagnostic_alarm_supp = false;
  bool process_alarm_supp = false;
  bool pull_plug_alarm_supp = false;
  bool status_alarm_supp = false;
  bool update_alarm_supp = false;
  bool manufacturer_specific_alarm_supp = false;
  bool diagnostic_alarm_required = false;
  bool process_alarm_required = false;
  bool pull_plug_alarm_required = false;
  bool status_alarm_required = false;
  bool update_alarm_required = false;
  bool manufacturer_specific_alarm_required = false;
  bool extra_alarm_sap_supp = false;
  bool alarm_type_mode_supp = false;
  std::uint8_t alarm_sequence_mode_count = 0;
  bool wd_base_1ms_supp = false;
  bool check_cfg_mode = false;
  bool dpv1_data_types = false;
  bool publisher_supp = false;
  bool ident_maintenance_supp = false;
  bool time_sync_supp = false;
  bool prm_block_structure_supp = false;
  bool prm_block_structure_req = false;
  bool fail_safe_required = false;
  bool isochron_mode_supp = false;      ///< DP-V2 isochronous mode (Isochron_Mode_supp)
  bool isochron_mode_required = false;  ///< Isochron_Mode_required
  bool operator==(const GsdDpv1Features&) const = default;
};

/// Redundancy keywords (§G.7): the redundant medium and slave redundancy (PI 2.212).
///
/// A keyword that is missing means "not supported": PrmCmd_supp 0, Slave_Redundancy_supp 0,
/// Slave_Max_Switch_Over_Time not stated (0). Values outside Boolean / Unsigned8 / Unsigned16 are
/// errors ("file:line: ..."); the raw values are kept as the file writes them.
///
/// Decisions where our sources are silent (protocol-facts.md §G.7 marks both [U]; PI 2.212 and
/// the redundancy part of PI 2.122 were not consulted):
/// - Slave_Redundancy_supp is a bit set of the redundancy types of PI 2.212 (§G.1): bit 0 (0x01)
///   = System Redundancy (two lines, same address), bit 1 (0x02) = Flying Redundancy (one line,
///   backup at address + 64). Bits 2..7 are taken as reserved: kept, and the reader warns.
///   [assumption: the order follows the order in which PI 2.212 and the device manuals (Stahl,
///   AUMA) introduce the two types; the value 0 = no slave redundancy is certain]
/// - Slave_Max_Switch_Over_Time is in units of 10 ms, 0 = not stated. [assumption: every time in
///   a DP GSD or telegram that is not a bit time is in 10 ms (C1/C2_Response_Timeout,
///   Min_Poll_Timeout, the watchdog base), and above all the PrmCmd Output_Hold_Time (§G.2) that
///   a master derives from this value is in 10 ms; with 10 ms, Unsigned16 reaches 655 s, while the
///   device figures of §G.5 (tens of ms up to about 1 s) would leave 1 ms or 100 us units
///   needlessly fine and 100 ms too coarse for a fast interface module]
/// - The reader also warns when the keywords contradict each other: slave redundancy without
///   PrmCmd_supp (the master could not choose the primary), PrmCmd_supp without DPV1_Slave
///   (the PrmCmd bit is in DPV1_Status_3) or without Prm_Block_Structure_supp (the PrmCmd is a
///   structured parameter block, §D.2/§G.2).
/// Nothing here drives behaviour by itself: the redundancy layer reads these values.
struct GsdRedundancy {
  static constexpr std::uint8_t kSystemRedundancy = 0x01;  ///< Slave_Redundancy_supp bit 0 [U]
  static constexpr std::uint8_t kFlyingRedundancy = 0x02;  ///< Slave_Redundancy_supp bit 1 [U]
  static constexpr std::uint8_t kReservedBits = 0xFC;
  static constexpr std::uint32_t kSwitchOverUnitMs = 10;  ///< Slave_Max_Switch_Over_Time unit [U]

  bool redundancy = false;  ///< `Redundancy`: redundant transmission medium, not slave redundancy
  bool prm_cmd_supp = false;  ///< PrmCmd_supp: understands the PrmCmd block in Set_Prm (§G.2)
  std::uint8_t slave_redundancy_supp = 0;  ///< raw bit set, see above
  std::uint16_t slave_max_switch_over_time = 0;  ///< raw, unit 10 ms; 0 = not stated

  bool system_redundancy() const { return (slave_redundancy_supp & kSystemRedundancy) != 0; }
  bool flying_redundancy() const { return (slave_redundancy_supp & kFlyingRedundancy) != 0; }
  std::uint8_t reserved_redundancy_bits() const { return slave_redundancy_supp & kReservedBits; }
  /// Any slave redundancy type declared (System or Flying).
  bool slave_redundancy() const { return system_redundancy() || flying_redundancy(); }
  /// The station's own switchover time T_SLAVE_UM in ms, nullopt when the file does not state it.
  std::optional<std::uint32_t> switch_over_time_ms() const {
    if (slave_max_switch_over_time == 0) return std::nullopt;
    return std::uint32_t{slave_max_switch_over_time} * kSwitchOverUnitMs;
  }
  /// The same in scheduler ticks (0 when not stated).
  bus::Ticks switch_over_time() const {
    return static_cast<bus::Ticks>(slave_max_switch_over_time) * kSwitchOverUnitMs * bus::kTicksPerMs;
  }
  bool operator==(const GsdRedundancy&) const = default;
};

/// Master GSD keywords (Station_Type = 1), §I.2.
struct GsdMasterFeatures {
  std::optional<std::uint8_t> max_slaves_supp;
  std::optional<std::uint8_t> las_len;
  std::map<bus::Baud, std::uint16_t> trdy, tqui, tset, tsdi;  ///< bit times
  std::optional<std::uint16_t> min_poll_timeout;  ///< unit 10 ms
  std::optional<std::uint8_t> max_mps_length;
  std::optional<std::uint8_t> max_lsdu_ms;
  std::optional<std::uint8_t> max_lsdu_mm;
  bool dpv1_master = false;
  bool c1_master_read_write_supp = false;
  bool master_diagnostic_alarm_supp = false;
  bool master_process_alarm_supp = false;
  bool master_pull_plug_alarm_supp = false;
  bool master_status_alarm_supp = false;
  bool master_update_alarm_supp = false;
  bool master_manufacturer_specific_alarm_supp = false;
  bool master_freeze_mode_supp = false;
  bool master_sync_mode_supp = false;
  bool master_fail_safe_supp = false;
  bool download_supp = false;
  bool upload_supp = false;
  bool act_para_brct_supp = false;
  bool act_param_supp = false;
};

/// A parameter value other than the default, for user_prm_data(). `slot` is nullopt for the
/// station (global) area, otherwise the position in the module list passed alongside. The value
/// goes to every Ext_User_Prm_Data_Ref(o) = ref of that area, or only to the one at `offset`.
/// With `f_parameter`, the setting addresses the slot's F-parameter block instead (its
/// F_Ext_User_Prm_Data_Ref, `offset` within the F block), e.g. F_Dest_Add.
struct GsdPrmSetting {
  std::optional<std::size_t> slot;
  std::uint16_t ref = 0;
  std::int64_t value = 0;
  std::optional<std::uint16_t> offset;
  bool f_parameter = false;
};

/// Result of an assembly or a check on a module selection.
template <class T>
struct GsdOutcome {
  std::optional<T> value;           ///< set when errors is empty
  std::vector<std::string> errors;  ///< why the selection cannot be used
  std::vector<std::string> notes;   ///< e.g. truncation to Max_User_Prm_Data_Len
  bool ok() const { return errors.empty(); }
};

/// A parsed GSD file.
class GsdFile {
 public:
  const std::string& file_name() const { return m_file_name; }
  const GsdInfo& info() const { return m_info; }
  std::uint16_t ident_number() const { return m_info.ident_number; }
  std::uint8_t station_type() const { return m_info.station_type; }
  bool is_master() const { return m_info.station_type == 1; }

  /// Supported baud rates in ascending order, each with its MaxTsdr.
  const std::vector<GsdBaudRate>& baud_rates() const { return m_baud_rates; }
  bool supports(bus::Baud b) const;
  /// MaxTsdr for a supported rate (bit times), nullopt if the rate is not supported.
  std::optional<std::uint16_t> max_tsdr(bus::Baud b) const;

  const GsdSlaveFeatures& slave_features() const { return m_slave; }
  const GsdDpv1Features& dpv1() const { return m_dpv1; }
  const GsdRedundancy& redundancy() const { return m_redundancy; }
  const GsdMasterFeatures& master() const { return m_master; }

  const std::vector<GsdModule>& modules() const { return m_modules; }
  /// Index of the first module with this name (exact, UTF-8) or reference number.
  std::optional<std::size_t> find_module(std::string_view name) const;
  std::optional<std::size_t> find_module_by_reference(std::uint32_t reference) const;

  /// Global parameter area (User_Prm_Data_Len, User_Prm_Data, Ext_User_Prm_Data_Const/Ref).
  const GsdPrmArea& global_prm() const { return m_global_prm; }
  std::uint8_t max_user_prm_data_len() const { return m_max_user_prm_data_len; }
  const std::map<std::uint16_t, GsdExtUserPrmData>& ext_user_prm_data() const { return m_ext_prm; }
  const std::map<std::uint16_t, GsdPrmText>& prm_texts() const { return m_prm_texts; }
  /// F_ExtUserPrmData blocks as the file defines them.
  const std::map<std::uint16_t, GsdExtUserPrmData>& f_ext_user_prm_data() const { return m_f_ext_prm; }
  /// What F_Ext_User_Prm_Data_Ref resolves to: the F_ExtUserPrmData blocks, and for numbers
  /// without one, the ExtUserPrmData of that number.
  const std::map<std::uint16_t, GsdExtUserPrmData>& f_prm_defs() const { return m_f_defs; }

  const std::map<std::uint32_t, std::string>& unit_diag_bits() const { return m_unit_diag_bits; }
  /// Unit_Diag_Area blocks outside any UnitDiagType (X_Unit_Diag_Area ones with x_variant).
  const std::vector<GsdUnitDiagArea>& unit_diag_areas() const { return m_unit_diag_areas; }
  /// X_Unit_Diag_Bit(n), X_Unit_Diag_Bit_Help(n), X_Unit_Diag_Not_Bit(n), ..._Help(n) outside any
  /// UnitDiagType block.
  const GsdDiagBitTexts& x_unit_diag() const { return m_x_unit_diag; }
  /// UnitDiagType blocks in file order.
  const std::vector<GsdUnitDiagType>& unit_diag_types() const { return m_unit_diag_types; }
  const std::map<std::uint32_t, std::string>& channel_diag() const { return m_channel_diag; }
  const std::vector<GsdSlot>& slots() const { return m_slots; }

  /// Every top-level keyword as written, in file order (including modelled ones).
  const std::vector<GsdKeyword>& keywords() const { return m_keywords; }
  /// The last top-level occurrence of a keyword (case-insensitive; name without index).
  const GsdKeyword* keyword(std::string_view name) const;
  /// Keywords the reader does not know (also reported as warnings).
  const std::vector<GsdKeyword>& unknown_keywords() const { return m_unknown; }

  /// User_Prm_Data for Set_Prm (octets 8..) with every parameter at its default, for the modules
  /// at these indices (into modules()), in this order (§I.1). Errors: an index out of range.
  GsdOutcome<GsdBytes> user_prm_data(const std::vector<std::size_t>& modules) const;
  /// The same with some parameters set to other values. Errors: a value the ExtUserPrmData does
  /// not allow, a parameter that is not Changeable, a setting that matches no reference in its
  /// area, a slot beyond the module list.
  GsdOutcome<GsdBytes> user_prm_data(const std::vector<std::size_t>& modules,
                                     const std::vector<GsdPrmSetting>& settings) const;
  /// The bytes one parameter area (global_prm() or a module's prm) contributes, all defaults.
  GsdBytes prm_area_defaults(const GsdPrmArea& area) const;
  /// A module's F-parameter block with every F-parameter at its default (empty if none).
  GsdBytes f_prm_defaults(const GsdModule& module) const;
  /// Octets a module adds to User_Prm_Data: its parameter area plus its F-parameter block.
  std::size_t module_prm_length(const GsdModule& module) const;
  /// Chk_Cfg data: the concatenated config bytes of these modules. Errors: index out of range.
  GsdOutcome<GsdBytes> cfg_data(const std::vector<std::size_t>& modules) const;
  /// Splits Chk_Cfg (or Get_Cfg) data into modules of this file: a module list whose
  /// cfg_data() equals `cfg` (modules tried in file order at each position), or nullopt.
  std::optional<std::vector<std::size_t>> modules_for_cfg(const GsdBytes& cfg) const;
  /// Checks a module selection against Max_Module, Max_Input_Len, Max_Output_Len, Max_Data_Len,
  /// Max_User_Prm_Data_Len and the 244-byte Chk_Cfg limit (and, for a non-modular station, that
  /// exactly one module is chosen). value = {input bytes, output bytes}.
  GsdOutcome<std::pair<std::size_t, std::size_t>> check_modules(
      const std::vector<std::size_t>& modules) const;

 private:
  friend class GsdParser;

  std::string m_file_name;
  GsdInfo m_info;
  std::vector<GsdBaudRate> m_baud_rates;
  GsdSlaveFeatures m_slave;
  GsdDpv1Features m_dpv1;
  GsdRedundancy m_redundancy;
  GsdMasterFeatures m_master;
  std::vector<GsdModule> m_modules;
  GsdPrmArea m_global_prm;
  std::uint8_t m_max_user_prm_data_len = 237;
  std::map<std::uint16_t, GsdExtUserPrmData> m_ext_prm;
  std::map<std::uint16_t, GsdPrmText> m_prm_texts;
  std::map<std::uint16_t, GsdExtUserPrmData> m_f_ext_prm;
  std::map<std::uint16_t, GsdExtUserPrmData> m_f_defs;
  std::map<std::uint32_t, std::string> m_unit_diag_bits;
  std::vector<GsdUnitDiagArea> m_unit_diag_areas;
  GsdDiagBitTexts m_x_unit_diag;
  std::vector<GsdUnitDiagType> m_unit_diag_types;
  std::map<std::uint32_t, std::string> m_channel_diag;
  std::vector<GsdSlot> m_slots;
  std::vector<GsdKeyword> m_keywords;
  std::vector<GsdKeyword> m_unknown;
};

/// What parse_gsd() returns: a model, or errors; warnings either way.
struct GsdParseResult {
  std::optional<GsdFile> file;  ///< set iff errors is empty
  std::vector<GsdMessage> errors;
  std::vector<GsdMessage> warnings;
  bool ok() const { return file.has_value(); }
};

/// Parses the raw bytes of a GSD file; `file_name` is used in messages only.
GsdParseResult parse_gsd(std::string_view bytes, std::string_view file_name);
/// Reads and parses a file. A file that cannot be read is an error at line 0.
GsdParseResult load_gsd(const std::filesystem::path& path);

/// Input and output bytes described by a list of configuration identifiers (§D.3), or an error
/// text if the list is malformed (a special identifier cut short, etc.).
struct GsdCfgLengths {
  std::size_t input_len = 0;
  std::size_t output_len = 0;
  bool consistent = false;
};
std::optional<GsdCfgLengths> gsd_cfg_lengths(const GsdBytes& config, std::string* error = nullptr);

}  // namespace pbvbus::devices
