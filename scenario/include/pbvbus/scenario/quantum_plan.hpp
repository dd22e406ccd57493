#pragma once
// Quantum Hot Standby pairs in scenarios (scenario/proto/scenario.proto message
// QuantumHotStandby; docs/quantum-hsby.md; seed 003): the loader's checked form of each pair.
//
// Decisions (the loader reports each violation with FILE:LINE:COLUMN):
//  - State RAM sizes default to the CPU type's baseline (the scan-time model's, seed 003 pp.
//    33-35); 0x and 1x in multiples of 16; at most 65535 references per table.
//  - The transfer (984) is planned by quantum::plan_transfer (transfer_area.hpp): the 12K
//    default from the configured sizes, user defined, additional, transfer all; IEC always
//    transfers everything and state RAM + IEC heap must fit 128 KB. Its refusals (counts not
//    multiples of 16, fewer than 16 4x, the command register outside the per-scan 4x area or
//    inside the non-transfer area, a non-transfer area shorter than 4 registers or not inside
//    the per-scan 4x area) are reported at the field they concern, with the seed's rule.
//  - References are written as the configurators write them ("400001" or "40001").
//  - Local I/O in a rack (rack.local_io) is refused: the seed's pair supports remote I/O only.
//  - Racks: at most two entries (rack 0, rack 1); designations default A and B; rack 0 powers
//    at 0 s and rack 1 at 100 ms unless told (the first powered becomes primary). Same
//    designation on both racks is allowed: it is a fault the seed describes (the second stays
//    offline), not a configuration error.
//  - scan_time: unset, the scan-time model's estimate (quantum::estimate_scan) from the CPU
//    type, logic_time as the standalone scan and the references transferred every scan; a scan_time shorter than logic_time is
//    an error.
//  - dp: `line` + `address` must name a dp_master on a PROFIBUS-DP line; that master IS both
//    racks' DP master module (its slaves, watchdog, bus parameters). Each map entry names one
//    of its slaves; a slave without an entry gets its inputs at the next free 3x registers and
//    its outputs at the next free 4x registers after the non-transfer area and the command
//    register, in address order. Inputs go to 3x or 1x, outputs come from 4x or 0x; a slave's
//    data must fit its table and may not overlap another's or the non-transfer area (outputs);
//    outputs must lie in the per-scan transfer area (a takeover must find them one scan old).
//  - Modbus ports 1..3, each at most once; address 1..119 when the swap is on (the standby
//    answers at +128 <= 247), 1..247 with no_swap; at least one door (tcp or rtu); TCP
//    endpoints share the file's port rule with gateways and S7 doors.
//  - logic: the counter register and the copy blocks inside state RAM; copies write 4x only.
#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "pbvbus/bus/time.hpp"
#include "pbvbus/quantum/reference.hpp"
#include "pbvbus/quantum/scan_time.hpp"
#include "pbvbus/quantum/state_ram.hpp"
#include "pbvbus/quantum/transfer_area.hpp"
#include "pbvbus/quantum/transfer_plan.hpp"
#include "pbvbus/scenario/gateway_plan.hpp"
#include "pbvbus/scenario/s7_plan.hpp"

namespace pbvbus::tools {

struct QuantumRackPlan {
  bool designation_b = false;
  enum class Key : std::uint8_t { Run, OffLine, Xfer };
  Key key = Key::Run;
  bus::Ticks power_on_at = 0;
  std::uint32_t logic_checksum = 1;
  std::uint32_t firmware = 1;
};

/// Where one DP slave's data lives in state RAM.
struct QuantumIoMapPlan {
  int slave = -1;  ///< index into ScenarioPlan::dp_slaves
  std::uint8_t address = 0;
  quantum::Reference inputs;   ///< 3x (2 octets a register) or 1x (8 inputs an octet)
  quantum::Reference outputs;  ///< 4x or 0x
  std::uint32_t input_octets = 0, output_octets = 0;
};

struct QuantumModbusPortPlan {
  int port = 1;  ///< 1..3
  std::uint8_t address = 1;
  bool no_swap = false;
  std::optional<GwEndpoint> tcp;
  std::uint32_t max_clients = 0;
  std::optional<GwRtu> rtu;
  enum class Wiring : std::uint8_t { Shared, Rack0, Rack1 };
  Wiring wiring = Wiring::Shared;
};

struct QuantumCopyPlan {
  quantum::Reference from, to;
  std::uint32_t count = 1;
};

struct QuantumPlan {
  int source = 0;  ///< index into Scenario.quantum_hot_standby
  std::string name;
  quantum::CpuType cpu = quantum::CpuType::Cpu43412;
  bool iec = false;
  quantum::StateRamSizes sizes;
  quantum::TransferConfig transfer;  ///< as configured (the command register and area in it)
  quantum::TransferPlan plan;        ///< what quantum::plan_transfer made of it
  std::uint32_t command_register = 0;  ///< 0-based 4x index
  bool keyswitch_override = false;
  bool standby_stays_on_logic_mismatch = false;
  bool allow_different_firmware = false;
  bool exec_upgrade_while_running = false;
  bus::Ticks logic_time = 20 * bus::kTicksPerMs;
  bus::Ticks scan_time = 0;  ///< configured or estimated
  bool scan_time_estimated = false;
  quantum::ScanEstimate estimate;  ///< the model's figures (also when scan_time is configured)
  std::array<QuantumRackPlan, 2> racks;
  int dp_line = -1;
  int dp_master = -1;  ///< index into ScenarioPlan::dp_masters
  std::uint8_t dp_address = 0;
  std::vector<QuantumIoMapPlan> io;  ///< one per slave of the master, by address
  std::vector<QuantumModbusPortPlan> modbus;
  std::optional<quantum::Reference> counter;
  std::vector<QuantumCopyPlan> copies;
};

/// Plans the quantum_hot_standby entries (after the dp systems, the gateways and the S7 doors:
/// their TCP ports and pty links may not be used twice).
void plan_quantum(ScenarioPlan& plan, const S7Locator& locate, std::vector<Diagnostic>& errors);

}  // namespace pbvbus::tools
