#pragma once
// Scenario files (design.md "Configuration and command line"): Protocol Buffers text format
// against scenario/proto/scenario.proto, loaded into a checked ScenarioPlan that the Simulation
// builds from.
//
// Every error names the file, line and column (1-based) of the text it refers to, both for
// syntax errors reported by the protobuf parser and for semantic errors found afterwards (the
// parser's ParseInfoTree locates each field): `multimaster.textproto:12:5: address 127 is out of
// range 0..126`. All errors are collected, not only the first.
//
// Decisions (documented for users in the .proto):
//  - Stations are attached in the order in which they appear in the text, across kinds; that is
//    their position along the cable. Scenarios built in code (no text) use the order masters,
//    passive stations, serial attachments.
//  - A Line without a baud runs at 1.5 Mbit/s; unset bus parameters take the DP-profile defaults
//    of the baud rate (fdl::BusParams::defaults).
//  - Polling an address where no station sits is allowed: it is how one exercises retries and
//    "non-operational" handling. Polling the master's own address or 127 is not.
//  - A fault (or repair) later than the scenario's own duration is an error (it would never
//    happen); when the duration is overridden on the command line, faults past the end are
//    simply not reached and the report says so.
//  - `capture { line: "A" at: 14 }` must name a station on that line by its FDL address; two
//    entries for the same point (or two without `at` for one line) are an error.
//  - H-system faults (cpu_failure ... memory_reset, load_memory_error, sync_error, cp_failure (F4: an h_system
//    cp entry of that rack);
//    docs/h-scenarios.md) name an h_system with a `cpu` part (the name may be left out when
//    there is only one), a rack or fibre 0/1 where the kind needs one; repair_at only where a
//    repair exists (power returns, RUN again, spliced, replaced, released); HOLD and the
//    operator swap not on an S7-1500R/H pair. They are planned with line = -1 and are not
//    applied by the Simulation until the H-system runtime exists.
//  - slave_stop (F15) is a DP slave fault like slave_mute: a dp_slave by line and address, no
//    module; repair_at = back to RUN (docs/h-scenarios.md "F3 / F15 / OB 122 in scenarios").

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "pbvbus/bus/time.hpp"
#include "pbvbus/fdl/bus_params.hpp"
#include "pbvbus/scenario/dp_link_plan.hpp"
#include "pbvbus/scenario/dp_plan.hpp"
#include "pbvbus/scenario/gateway_plan.hpp"
#include "pbvbus/scenario/h_plan.hpp"
#include "pbvbus/scenario/quantum_plan.hpp"
#include "pbvbus/scenario/s7_plan.hpp"
#include "scenario.pb.h"

namespace pbvbus::tools {

/// One problem in a scenario file. line/column are 1-based; 0 when unknown.
struct Diagnostic {
  std::string file;
  int line = 0;
  int column = 0;
  std::string message;
  /// "FILE:LINE:COLUMN: message" (or "FILE: message" without a position).
  std::string str() const;
};

enum class StationKind : std::uint8_t {
  Master,
  Passive,
  SerialMonitor,
  SerialStation,
  DpMaster,
  DpSlave,
  SwitchedInterface,  ///< one interface of a switched_station (source = its index)
  // MPI stations (s7_plan.hpp): active stations on a line of kind MPI.
  S7CpuMpi,    ///< an s7_cpu's MPI interface (source = its index)
  HCpuMpi,     ///< an h_system CPU's MPI interface (source = h_system index * 2 + rack)
  MpiStation,  ///< a PG or an OP (source = its mpi_station index)
  S7DoorMpi,   ///< an s7_door's own station on its mpi_line (source = its index)
};
std::string_view to_string(StationKind k);

/// A station in cable order.
struct PlanStation {
  StationKind kind = StationKind::Passive;
  int source = 0;                       ///< index into the Scenario's repeated field of `kind`
  std::optional<std::uint8_t> address;  ///< none for a serial monitor
  fdl::BusParams params;                ///< effective parameters (line's + a master's overrides)
};

/// A capture probe from the scenario (`capture { line: "A" at: 14 }`).
struct PlanProbe {
  std::optional<std::uint8_t> address;  ///< `at`; none = the run's default probe position
  int position = -1;                    ///< cable position of `address`; -1 without one
};

struct PlanLine {
  std::string name;
  bool mpi = false;  ///< kind MPI (s7_plan.hpp)
  bus::Baud baud = bus::Baud::k1_5M;
  fdl::BusParams params;
  std::vector<PlanStation> stations;  ///< cable order = attachment order
  /// Capture probes in file order (capture_probes.hpp adds the default for lines without).
  std::vector<PlanProbe> probes;
  /// Cable position of the station with FDL address `addr`, or -1.
  int position_of(std::uint8_t addr) const;
};

/// program_change (F22): what kind of change is loaded in RUN.
enum class HProgramChangeKind : std::uint8_t {
  Allowed,                ///< may be made in Redundant mode
  StructuralFbInterface,  ///< an FB interface changed: may not be made in Redundant mode
  GlobalDb,               ///< a global DB's structure changed: may not be made in Redundant mode
};
std::string_view to_string(HProgramChangeKind k);

struct PlanFault {
  enum class Kind : std::uint8_t {
    CableCut,
    ShortCircuit,
    Noise,
    PowerLoss,
    TransceiverFailure,
    Babble,
    // DP slave faults, applied through devices::SlaveModel (repair = the clearing step).
    SlaveMute,
    ChannelDiag,
    ModulePull,
    ProcessAlarm,
    SlaveStop,  ///< F15: the slave's CPU to STOP; repair: back to RUN
    // Switched I/O: applied through the redundant system's models.
    InterfaceFailure,  ///< `switched`, `side`
    StationPowerLoss,  ///< `switched`
    MasterFailure,     ///< `dp_master` (and `side`/`system` if it is part of a system)
    MasterStop,
    // H-system CPU pair faults (an h_system with a `cpu` part; docs/h-scenarios.md): `h_system`,
    // and `rack` / `fibre` / `kb` / `change` where the kind needs them; `line` is -1. Not applied
    // by the Simulation yet (the H-system runtime will apply them).
    CpuFailure,       ///< F1, `rack`; repair: power returns
    CpuStop,          ///< mode switch to STOP, `rack`; repair: STOP -> RUN
    FibreCut,         ///< F5, `fibre`; repair: spliced
    FibresCut,        ///< F6, both fibres at once; repair: both
    ComparisonError,  ///< F16
    OneSidedOb121,    ///< F17, `rack`
    HardwareFault,    ///< latent, found by the next self-test, `rack`; repair: CPU replaced
    CpuHold,          ///< `rack`; repair: release (F21 if a link-up is requested meanwhile)
    HMasterSwap,      ///< operator "switch to CPU with modified configuration"
    UpdateLoad,       ///< F19: the next update copies `kb` KB
    ProgramChange,    ///< F22, `change`
    ParameterChange,  ///< F23: a parameter that may not change, then a master swap (W#16#5966)
    MemoryReset,      ///< F20: memory reset of `rack` after its reset request
    LoadMemoryError,  ///< F2, `rack`: STOP + reset request; repair: a memory_reset fault
    SyncError,        ///< F18: diverging uninitialised data, the standby STOPs
    CpFailure,        ///< F4, `rack`, `cp`; repair: CP replaced
    // F8 expansion racks, OB 80
    ExpansionRackFailure,  ///< F8, `rack_number` (`rack` = its CPU); repair: power back
    CycleOverload,         ///< the next OB 1 lasts scan_time + `extra` (OB 80)
    // Redundant I/O (docs/h-redundant-io.md)
    ChannelStuck,  ///< DP slave `slave` module `module`'s inputs stick at `stuck_value`; repair: behaviours again
    RedDepa,       ///< H fault: FC 451 RED_DEPA on `h_system`
    // Changes in operation and self-test (docs/h-changes.md)
    ChecksumError,         ///< `rack`: a checksum error in the cyclic self-test (001 Table 5-6)
    PsFailure,             ///< F1, `rack`, `half` of its PS 407 10A R; repair: that half replaced
    HSwitchToCpu,          ///< PG/ES "switch to CPU with ...", `cpu_switch` (docs/h-scenario-changes.md)
    // Quantum Hot Standby (quantum_plan.hpp): `quantum`, and `rack` where the kind names one.
    QuantumPowerLoss,     ///< the rack's power fails; repair: power back
    QuantumCpuStop,       ///< the rack's CPU stops; repair: started again
    QuantumKey,           ///< keyswitch to `key` (1 Off Line, 2 Xfer); repair: back to Run
    QuantumUpdate,        ///< update button + key to Xfer on the standby, then back to Run
    QuantumFibre,         ///< the CHS fibre cut (`fibre` 0) or Tx/Rx not crossed (`fibre` 1); repair: mended
    QuantumCommand,       ///< a host writes the command register's run bits `run_a`, `run_b`
    QuantumLogicChange,   ///< a program with identity `checksum` is loaded into `rack`
    QuantumExecUpgrade,   ///< `rack`'s executive upgraded to version `checksum`
  };
  Kind kind = Kind::CableCut;
  bus::Ticks at = 0;
  std::optional<bus::Ticks> repair_at;
  int line = 0;                  ///< index into ScenarioPlan::lines
  int a = -1;                    ///< cable position (cut: the earlier one; station faults)
  int b = -1;                    ///< cut: the later cable position
  std::uint64_t noise_ppb = 0;   ///< noise: bit errors per 10^9 bits
  std::string description;       ///< e.g. "cable cut on line A between 3 and 10"
  std::uint8_t slave = 0;        ///< DP slave faults: the dp_slave's address
  std::size_t module = 0;        ///< DP slave faults: 0-based in the slave's module list
  std::uint8_t channel = 0;      ///< channel_diag: 0..63
  std::uint8_t error_type = 0;   ///< channel_diag: 1..31
  /// channel_diag: the channel's type and direction, from the module's first identifier
  /// (decision: a word-format identifier gives Word channels, any other Bit channels; input if
  /// the identifier has inputs, else output), as a configuration tool would show them.
  bool word_channel = false;
  bool output_channel = false;
  int switched = -1;   ///< index into ScenarioPlan::switched
  int side = -1;       ///< 0 = line A, 1 = line B of the redundant system
  int dp_master = -1;  ///< index into ScenarioPlan::dp_masters
  int system = -1;     ///< index into ScenarioPlan::redundant_systems, or -1
  int h_system = -1;   ///< H faults: index into ScenarioPlan::h_systems (one with a runtime)
  int rack = -1;       ///< H faults: 0 or 1 where the kind names a CPU
  int fibre = -1;      ///< fibre_cut: 0 = upper, 1 = lower
  int half = -1;       ///< ps_failure: 0 or 1, the PS of the rack's PS 407 10A R pair
  int cp = -1;         ///< cp_failure: the CP's index in `rack`
  std::uint32_t kb = 0;  ///< update_load: KB the next update copies
  HProgramChangeKind change = HProgramChangeKind::Allowed;  ///< program_change
  int rack_number = 0;   ///< expansion_rack_failure: the expansion rack (1..21)
  bus::Ticks extra = 0;  ///< cycle_overload: how much longer the next OB 1 lasts
  std::uint64_t stuck_value = 0;  ///< channel_stuck: big-endian over the module's input octets
  int quantum = -1;      ///< Quantum faults: index into ScenarioPlan::quantum
  int key = 0;           ///< quantum_key: 1 Off Line, 2 Xfer
  bool run_a = false, run_b = false;  ///< quantum_command
  bool keyswitch_override = false;    ///< quantum_command: the override bit written
  std::uint32_t checksum = 0;         ///< quantum_logic_change
  std::optional<HSwitchPlan> cpu_switch;  ///< switch_to_cpu: variant, memories, modules, DBs
};

/// A Quantum Hot Standby fault kind (QuantumPowerLoss .. QuantumLogicChange)?
bool is_quantum_fault(PlanFault::Kind k);
/// "rack 0 loses power", "CHS fibre cut", ... (without the pair's name).
std::string quantum_fault_description(const PlanFault& f);

/// An H-system fault kind (CpuFailure .. SyncError, ExpansionRackFailure, CycleOverload)?
bool is_h_fault(PlanFault::Kind k);
/// "CPU 0 (rack 0) fails", "sync-link fibre 1 (lower) cut", ... (without the h_system name).
std::string h_fault_description(const PlanFault& f);

struct ScenarioPlan {
  scenario::Scenario proto;  ///< the parsed file, for the station details
  std::string file;          ///< the name errors and reports use
  std::string name;
  std::uint64_t seed = 0;
  std::optional<bus::Ticks> duration;  ///< from the file; the CLI may override it
  std::vector<PlanLine> lines;
  std::vector<PlanFault> faults;  ///< ordered by time of occurrence
  std::vector<DpMasterPlan> dp_masters;  ///< in file order (dp_plan.hpp)
  std::vector<DpSlavePlan> dp_slaves;    ///< in file order, valid ones only
  std::vector<RedundancyPlan> redundant_systems;  ///< in file order
  std::vector<SwitchedPlan> switched;             ///< in file order, valid ones only
  std::vector<HSystemPlan> h_systems;  ///< h_system entries (update timing; runtime if simulated)
  std::vector<GatewayPlan> gateways;   ///< gateway entries, in file order (gateway_plan.hpp)
  S7Plan s7;  ///< s7_cpu, mpi_station, s7_door entries and the H CPUs' MPI interfaces
  std::vector<QuantumPlan> quantum;  ///< quantum_hot_standby entries, valid ones, file order
  std::vector<DpLinkPlan> dp_links;  ///< y_link, then dp_pa_link entries, valid ones (dp_link_plan.hpp)
};

struct LoadResult {
  std::optional<ScenarioPlan> plan;  ///< set only if `errors` is empty
  std::vector<Diagnostic> errors;
  bool ok() const { return plan.has_value(); }
};

/// Parses and checks scenario text. `file` is the name used in diagnostics.
LoadResult parse_scenario(std::string_view text, std::string_view file);
/// Reads and parses a file ("cannot read FILE: reason" if it cannot be opened).
LoadResult load_scenario_file(const std::string& path);
/// Checks an already-built message (no positions in diagnostics).
LoadResult plan_scenario(const scenario::Scenario& proto, std::string_view file);

/// The built-in default scenario's text (what `pbvbus run` runs without a file).
std::string_view default_scenario_text();

}  // namespace pbvbus::tools
