#pragma once
// The Modbus register layout of one master system (docs/gateway-modbus.md), built once from a
// ProcessSource and the gateway options; `pbvbus gateway map` prints it (to_text/to_json/to_csv).
//
// Decisions fixed by the integrator (docs/gateway-modbus.md has the tables):
// - Unit id = PROFIBUS address of the slave (1..125). A slave at address 0 is not mapped
//   (unit 0 is the gateway): the map carries a warning. With `standby_units` on a redundant
//   source, unit address + 128 is the same switched station seen through the Standby side
//   (read-only); a one-sided slave has no standby unit (0x0A), nor has a slave above address
//   119 (its unit would be a reserved Modbus address 248..253; seed 003 keeps the standby
//   at <= 247): the map carries a warning.
// - Input registers (FC04) from 0: the input telegram, each module starting on a new register,
//   its first octet in the high byte; an odd-length module's last register has 0 in the low
//   byte. Holding registers (FC03/06/16/23) from 0: the output telegram, same rule.
// - Discrete inputs (FC02): bit address = input octet × 8 + bit (bit 0 = LSB) over the unpadded
//   input telegram; coils (FC01/05/15) the same over the output telegram. Word orders do not
//   apply to bits: a bit address always names one octet of the telegram.
// - Word order per slave and per module (module wins), applied within the module.
// - Status block per slave: input registers 4096..4225 (8 fixed registers + 122 for the
//   diagnosis), mirrored read-only in holding registers 4096..4225. The block has a fixed size
//   so an HMI can poll it whole; diagnosis registers past the current length read 0.
// - Gateway unit (0 and 255): input registers 0..38 (live list, configured list, master mode
//   and address, 32-bit counters high word first, H-system block), holding register 0 = master
//   mode. Addresses are the kGw* constants below.

#include <array>
#include <cstddef>
#include <cstdint>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "pbvbus/gateways/modbus_options.hpp"
#include "pbvbus/gateways/process_source.hpp"

namespace pbvbus::gateways {

enum class ModbusTable : std::uint8_t { InputRegister, HoldingRegister, DiscreteInput, Coil };
std::string_view to_string(ModbusTable t);  ///< "input_register", "holding_register", ...
std::string_view to_string(WordOrder o);    ///< "AB CD", "BA DC", "CD AB", "DC BA"
std::string_view to_string(StaleReaction r);

// --- status block (per slave unit; input registers, mirrored in holding registers) ---
inline constexpr std::uint16_t kStatusBase = 0x1000;            ///< 4096
inline constexpr std::uint16_t kStatusState = kStatusBase + 0;  ///< DP state code 1..8
inline constexpr std::uint16_t kStatusFlags = kStatusBase + 1;
inline constexpr std::uint16_t kStatusLifeCounter = kStatusBase + 2;  ///< data_exchanges mod 2^16
inline constexpr std::uint16_t kStatusIdent = kStatusBase + 3;
inline constexpr std::uint16_t kStatusActiveChannel = kStatusBase + 4;  ///< 0 A, 1 B, 0xFFFF none
inline constexpr std::uint16_t kStatusFailures = kStatusBase + 5;       ///< mod 2^16
inline constexpr std::uint16_t kStatusReturns = kStatusBase + 6;        ///< mod 2^16
inline constexpr std::uint16_t kStatusDiagLength = kStatusBase + 7;     ///< octets
inline constexpr std::uint16_t kStatusDiag = kStatusBase + 8;           ///< raw diagnosis, HBF
inline constexpr std::uint16_t kStatusDiagRegisters = 122;
inline constexpr std::uint16_t kStatusRegisters = 8 + kStatusDiagRegisters;  ///< 130

/// Flag bits of kStatusFlags.
inline constexpr std::uint16_t kFlagDataValid = 1u << 0;
inline constexpr std::uint16_t kFlagExtDiag = 1u << 1;           ///< Slave_Diag octet 1 bit 3
inline constexpr std::uint16_t kFlagStationFailure = 1u << 2;    ///< not existent / NotPresent
inline constexpr std::uint16_t kFlagPrmFault = 1u << 3;          ///< Slave_Diag octet 1 bit 6
inline constexpr std::uint16_t kFlagCfgFault = 1u << 4;          ///< Slave_Diag octet 1 bit 2
inline constexpr std::uint16_t kFlagSwitched = 1u << 5;
inline constexpr std::uint16_t kFlagRedundancyLost = 1u << 6;
inline constexpr std::uint16_t kFlagActiveChannelB = 1u << 7;
inline constexpr std::uint16_t kFlagStandbyView = 1u << 8;

/// DP state codes of kStatusState: dp::SlaveStatusState + 1 (1 Inactive .. 8 Locked).
std::uint16_t modbus_state_code(dp::SlaveStatusState s);
/// Master mode codes (gateway IR 16, HR 0): dp::MasterMode + 1 (1 Offline .. 4 Operate).
std::uint16_t modbus_mode_code(dp::MasterMode m);

// --- gateway unit (0 and 255): input registers ---
inline constexpr std::uint16_t kGwLiveList = 0;         ///< 0..7: stations in data exchange
inline constexpr std::uint16_t kGwConfigured = 8;       ///< 8..15: configured stations
inline constexpr std::uint16_t kGwMasterMode = 16;      ///< 1 Offline 2 Stop 3 Clear 4 Operate
inline constexpr std::uint16_t kGwMasterAddress = 17;
inline constexpr std::uint16_t kGwStationFailures = 18; ///< 32-bit counters, high word first
inline constexpr std::uint16_t kGwStationReturns = 20;
inline constexpr std::uint16_t kGwDiagnoses = 22;
inline constexpr std::uint16_t kGwAlarms = 24;
inline constexpr std::uint16_t kGwSwitchovers = 26;
inline constexpr std::uint16_t kGwModbusRequests = 28;
inline constexpr std::uint16_t kGwModbusExceptions = 30;
inline constexpr std::uint16_t kGwHPresent = 32;        ///< 1 = driven by an H-system
inline constexpr std::uint16_t kGwHCpuState = 33;       ///< 33 rack 0, 34 rack 1
inline constexpr std::uint16_t kGwHCpuRole = 35;        ///< 35 rack 0, 36 rack 1
inline constexpr std::uint16_t kGwHSystemMode = 37;
inline constexpr std::uint16_t kGwHMasterRack = 38;     ///< 0/1, 0xFFFF none
inline constexpr std::uint16_t kGwInputRegisters = 39;
// --- gateway unit: holding registers ---
inline constexpr std::uint16_t kGwHrMasterMode = 0;     ///< read: current; write 2/3/4
inline constexpr std::uint16_t kGwHoldingRegisters = 1;

struct ModbusModuleMap {
  std::size_t module = 0;  ///< index in slot order
  std::string name;
  std::size_t in_offset = 0;
  std::size_t in_len = 0;
  std::size_t out_offset = 0;
  std::size_t out_len = 0;
  std::uint16_t input_register = 0;     ///< first input register (if in_len > 0)
  std::uint16_t input_registers = 0;    ///< (in_len + 1) / 2
  std::uint16_t holding_register = 0;   ///< first holding register (if out_len > 0)
  std::uint16_t holding_registers = 0;  ///< (out_len + 1) / 2
  WordOrder order = WordOrder::HighByteFirst;
};

/// One process-data unit (a slave, or its standby view).
struct ModbusUnitMap {
  std::uint8_t unit = 0;
  std::uint8_t address = 0;
  Side side = Side::Primary;
  std::string model;
  std::uint16_t ident = 0;
  bool writable = true;  ///< Primary side and outputs_writable
  StaleReaction stale = StaleReaction::Exception;
  std::uint16_t stale_value = 0;
  std::vector<ModbusModuleMap> modules;
  std::size_t input_len = 0;             ///< octets; discrete inputs = input_len * 8
  std::size_t output_len = 0;            ///< octets; coils = output_len * 8
  std::uint16_t input_registers = 0;     ///< data area: 0..input_registers-1
  std::uint16_t holding_registers = 0;
  /// For each data register: the index into `modules` that holds it.
  std::vector<std::uint16_t> input_register_module;
  std::vector<std::uint16_t> holding_register_module;
};

class ModbusMap {
 public:
  ModbusMap(const ProcessSource& source, const ModbusGatewayOptions& options);

  std::span<const ModbusUnitMap> units() const { return m_units; }
  /// A process-data unit (1..125, or 129..247 standby); nullptr for any other unit.
  const ModbusUnitMap* unit(std::uint8_t unit) const;
  bool gateway_units() const { return m_gateway_units; }
  /// E.g. a slave at address 0 that could not be mapped.
  std::span<const std::string> warnings() const { return m_warnings; }
  const std::string& source_name() const { return m_source_name; }

  /// A human-readable listing.
  std::string to_text() const;
  /// {"source":..., "gateway_units":..., "units":[...], "warnings":[...]}.
  std::string to_json() const;
  /// Header `unit,table,first_address,count,slave,slot,module,data_type,description`, then one
  /// row per module and table and per status field (slot = module index, 0-based; empty for
  /// status rows).
  std::string to_csv() const;

 private:
  std::vector<ModbusUnitMap> m_units;
  std::vector<std::string> m_warnings;
  std::string m_source_name;
  bool m_gateway_units = true;
  std::array<int, 256> m_index{};
};

}  // namespace pbvbus::gateways
