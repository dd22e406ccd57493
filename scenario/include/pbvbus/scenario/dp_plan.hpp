#pragma once
// DP master systems in scenarios (design.md "Configuration and command line"; protocol-facts.md
// §C.1/§C.2 bus parameters and timing, §D.2 Set_Prm, §D.3 Chk_Cfg, §D.9 class-1 master, §I GSD).
// The loader (scenario.cpp) calls plan_dp() after the lines are planned and before the
// stations are put in cable order; plan_dp() reads the GSD files, builds each slave's
// dp::SlaveConfig (the device) and dp::SlaveParams (the master's database entry), and derives
// the bus parameters of every line that carries a DP system.
//
// Decisions (a configuration tool such as STEP 7 does the same, as far as it is documented):
//  - GSD paths are relative to the directory of the scenario file (absolute paths as given).
//  - A compact station (Modular_Station = 0) with no module list gets its single module.
//  - Set_Prm: Lock_Req + WD_On (unless watchdog "off"), WD_Fact_1/2 from the master's
//    watchdog (the smallest factor pair, factor 1 first, whose product is the watchdog in
//    10 ms units), min TSDR = the line's, Group_Ident 0, User_Prm_Data = the GSD's defaults for
//    the chosen modules (GsdFile::user_prm_data). Chk_Cfg = the modules' config bytes.
//  - Bus parameters of a line with DP slaves, for every field its `bus_params` does not set:
//    max TSDR = max(the baud default, every slave's GSD MaxTsdr at that baud); TSL = max(the
//    baud default, max TSDR + 15) (§C.1); TTR = 2 × P + TSL + 100, at least 256, where P is one
//    worst-case pass: for every slave a Data_Exchange at max TSDR, the token pass, a
//    Global_Control and one unanswered GAP poll. Why twice: the token hold time is TTR − TRR,
//    so in steady state the previous rotation (≈ P) is spent before this visit's pass may
//    start; and fdl::ActiveStation keeps TSL + 100 bit times back for its GAP poll. With less,
//    a pass is cut by the hold time and finishes at the next visit, which doubles the DP cycle
//    of every other rotation.
//  - Errors: unknown or broken GSD file, a GSD that describes a master, a baud rate the GSD does
//    not support, unknown module name, a module selection the GSD refuses (Max_Module, lengths),
//    tsdr_bits above the GSD's MaxTsdr (or below min TSDR), a slave whose master is not a
//    dp_master on its line, a dp_master address not below HSA.
//  - A slave without `master` is planned like any other (configuration, the line's derived bus
//    parameters) but belongs to no pbvbus master: it serves whatever class-1 master
//    parameterises it (DpSlavePlan::master = dp::kNoMaster; its SlaveParams are what a
//    configuration tool would give that master, with the default watchdog of a dp_master).
//    Addresses used twice on a line are reported by the loader like any other station.

#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "pbvbus/bus/time.hpp"
#include "pbvbus/slaves/io_behaviour.hpp"
#include "pbvbus/slaves/slave_mutant.hpp"
#include "pbvbus/dp/master.hpp"
#include "pbvbus/dp/slave_config.hpp"
#include "pbvbus/fdl/bus_params.hpp"
#include "pbvbus/scenario/prm_record_plan.hpp"
#include "scenario.pb.h"

namespace pbvbus::devices {
class GsdFile;
}

namespace pbvbus::tools {

struct Diagnostic;
struct ScenarioPlan;

/// One `io` entry of a dp_slave: a behaviour for module `module` (0-based in the slave's module
/// list), over all its inputs (`whole`) or input octets [offset, offset + width).
/// Decisions: a constant's uint64 value is written big-endian over the channel width (cut to
/// its low octets); a counter's step defaults to 1; `io` on a module without inputs, a channel
/// outside the module, or an echo source without outputs is an error (it would show nothing).
struct DpIoPlan {
  std::size_t module = 0;
  bool whole = true;
  std::size_t offset = 0;
  std::size_t width = 0;
  devices::IoBehaviour behaviour;
};

struct DpSlavePlan {
  int source = 0;  ///< index into Scenario.dp_slave
  int line = -1;   ///< index into ScenarioPlan::lines
  std::uint8_t address = 0;
  std::uint8_t master = 0;              ///< its dp_master, or dp::kNoMaster (none in pbvbus)
  std::string gsd_path;                 ///< resolved path
  std::string model;                    ///< GSD Model_Name
  std::vector<std::string> module_names;
  std::shared_ptr<const devices::GsdFile> gsd;  ///< the parsed file (devices::SlaveModel)
  std::vector<std::size_t> gsd_modules;          ///< indices into gsd->modules()
  dp::SlaveConfig config;               ///< the device
  dp::SlaveParams params;               ///< the master's database entry
  std::uint32_t tsdr = 0;               ///< own response delay; 0 = min TSDR
  std::uint16_t gsd_max_tsdr = 0;       ///< MaxTsdr at the line's baud
  std::size_t inputs = 0;               ///< octets
  std::size_t outputs = 0;
  scenario::DpSlave::Inputs io = scenario::DpSlave::COUNTER;
  std::vector<DpIoPlan> io_behaviours;  ///< the `io` entries, in file order
  std::vector<DpPrmRecordPlan> prm_records;  ///< F3 `parameter_record` (prm_record_plan.hpp)
  /// Test-only: the `mutant` it was asked to be (devices/slave_mutant.hpp); none = conformant.
  std::optional<devices::SlaveMutant> mutant;
  /// One interface of a switched_station (source = its index there, not a dp_slave's): the
  /// index into ScenarioPlan::switched and the side (0 = line A, 1 = line B); -1 otherwise.
  int switched = -1;
  int side = -1;
  const char* repeated = "dp_slave";  ///< the Scenario field `source` indexes
};

/// A switched_station: planned as one DpSlavePlan per line (`slave`), built as one
/// devices::SwitchedStationModel.
struct SwitchedPlan {
  int source = 0;  ///< index into Scenario.switched_station
  int system = -1; ///< index into ScenarioPlan::redundant_systems
  std::uint8_t address = 0;
  int slave[2] = {-1, -1};  ///< indices into ScenarioPlan::dp_slaves (line A, line B)
  /// T_SLAVE_UM: the scenario's switchover_time, else the GSD's Slave_Max_Switch_Over_Time.
  std::optional<bus::Ticks> t_slave_um;
  bool t_slave_um_from_gsd = false;
  /// An IM 157 link's upper side (dp_link_plan.hpp): index into ScenarioPlan::dp_links, and
  /// `source` indexes its y_link / dp_pa_link entry; -1 for a switched_station.
  int link = -1;
};

/// A redundant_master_system: two dp_masters (one per line) as one logical master system.
struct RedundancyPlan {
  int source = 0;  ///< index into Scenario.redundant_master_system
  std::string name;
  int line[2] = {-1, -1};    ///< indices into ScenarioPlan::lines
  int master[2] = {-1, -1};  ///< indices into ScenarioPlan::dp_masters
  std::uint16_t output_hold_10ms = 100;
  int preferred = 0;
  std::vector<int> switched;  ///< indices into ScenarioPlan::switched, file order
};

struct DpMasterPlan {
  int source = 0;  ///< index into Scenario.dp_master
  int line = -1;
  dp::MasterParams params;
  scenario::DpMaster::Outputs outputs = scenario::DpMaster::COUNT;
  /// A gateway serves this master (system): no master-side test program, the gateway's
  /// clients own the outputs (gateway_plan.hpp; set by plan_gateways).
  bool gateway_outputs = false;
  std::vector<int> slaves;  ///< indices into ScenarioPlan::dp_slaves, in file order
};

/// Locates a field of the scenario text for diagnostics: the message `repeated`[index] of the
/// Scenario and, if `field` is given, its field (element `element` of a repeated one).
/// Returns {line, column}, 1-based, or {0, 0} when unknown.
using DpLocator = std::function<std::pair<int, int>(const char* repeated, int index,
                                                    const char* field, int element)>;

/// Plans the DP systems of `plan` (its lines must be planned). Errors are appended to `errors`.
/// Line bus parameters are derived here for the fields the line's bus_params leaves unset.
void plan_dp(ScenarioPlan& plan, const DpLocator& locate, std::vector<Diagnostic>& errors);

/// TTR the loader derives for a DP line (see above); exposed for tests and the benchmark.
std::uint32_t dp_ttr(const fdl::BusParams& p, const std::vector<std::pair<std::size_t, std::size_t>>& io);

}  // namespace pbvbus::tools
