#pragma once
// A scenario's h_system entries (docs/h-system.md; docs/h-timing.md): the inputs of the T_P15 procedure
// and the configured H parameters, checked by the loader (FILE:LINE:COLUMN) and turned into a
// devices::UpdatePlanInput by h_update_input() (the DP master systems that name a
// redundant_master_system take T_TR, T_DP_UM and T_SLAVE_UM from redundancy::plan_switchover:
// the larger line's T_TR, the larger direction's T_DP_UM, the slowest station's T_SLAVE_UM;
// a figure given in the entry wins).
//
// An h_system with a `cpu` part is also a simulated CPU pair (docs/h-scenarios.md):
// HSystemPlan::runtime holds the devices::HCpuPairParams, the power-on time of each rack, the
// user program (devices::ProgramSpec) and the redundant master systems the pair drives.
// Decisions:
// - The systems a pair drives are its dp_system entries that name a redundant_master_system;
//   such a system may appear in at most one h_system that has a `cpu` part and only once in
//   it (timing-only entries may still share one: they only study it).
// - A simulated pair's configured H parameters must pass devices::check_h_parameters against
//   the planned update (errors refuse the file, warnings pass): a pair must not run on a bad
//   set. Timing-only entries keep being reported by `pbvbus timing` as before.
// - update_db_kb defaults to work_memory_db_kb (the update copies the DBs in work memory), or
//   to HCpuPairParams' 100 KB when that is 0.
// - power_on "off" = not powered during the run; unset = "0s". Equal times for both racks are
//   the simultaneous POWER ON (HCpuPair::power_on_both).
// - expansion_rack entries (F8, needs `cpu`): number 1..21 unique and side 0/1 required, at
//   least one module, each with in_len/out_len not both 0 and <= 244, a behaviour (constant,
//   counter, ramp, echo of a module of the same rack that has outputs; default constant 0).
//   max_cycle_time > 0 (OB 80).
// - Program networks are checked as devices::ProgramSpec requires: width 1/2/4, period > 0,
//   length > 0, discrepancy_time > 0, pulse_high < period, pulse_bit 0..7, scan_time > 0.
#include <array>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "pbvbus/s7h/h_connections.hpp"
#include "pbvbus/s7h/h_cpu_pair.hpp"
#include "pbvbus/s7h/h_expansion_rack.hpp"
#include "pbvbus/s7h/h_program_spec.hpp"
#include "pbvbus/s7h/h_redundant_io.hpp"
#include "pbvbus/s7h/h_update_timing.hpp"
#include "pbvbus/scenario/h_changes_plan.hpp"
#include "pbvbus/scenario/dp_plan.hpp"
#include "scenario.pb.h"

namespace pbvbus::tools {

struct HDpSystemPlan {
  std::string name;
  int system = -1;  ///< index into ScenarioPlan::redundant_systems, or -1 (figures given)
  std::optional<devices::Us> t_tr, t_dp_um, t_slave_um;
  devices::Us t_pto = 0;
};

/// A redundant_io pair (docs/h-redundant-io.md "In a scenario"): the spec (addresses and length
/// are resolved by the model from its I/O map) and the two modules by model system index
/// (position in HRuntimePlan::systems), station address and module index.
struct HRedIoPlan {
  devices::RedIoPairSpec spec;
  int system[2] = {-1, -1};
  std::uint8_t station[2] = {0, 0};
  std::size_t module[2] = {0, 0};
};

/// What the Simulation needs to run an h_system's CPU pair.
struct HRuntimePlan {
  devices::HCpuPairParams pair;
  /// Power-on time per rack; nullopt = not powered during the run ("off").
  std::array<std::optional<bus::Ticks>, 2> power_on{bus::Ticks{0}, bus::Ticks{0}};
  /// Both fibres plugged at power-on (false: both cut before the first power-on, F7).
  bool fibres_connected_at_power_on = true;
  devices::ProgramSpec program;
  std::vector<int> systems;  ///< indices into ScenarioPlan::redundant_systems (driven systems)
  // ---- F4 connections (h_system cp/connection; devices/h_connections.hpp) ----
  std::vector<devices::CpConfig> cps;
  std::vector<devices::ConnectionConfig> connections;
  // F8 expansion racks, OB 80 (HPlanner::plan_racks): the racks as HSystemModel takes them, and
  // OB 80's maximum cycle time (HCpuPair.max_cycle_time, default 150 ms).
  std::vector<devices::HExpansionRack> racks;
  bus::Ticks max_cycle_time = 150 * bus::kTicksPerMs;
  std::vector<HRedIoPlan> redundant_io;  ///< plan_redundant_io
  /// HCpuPair.param_transfer_time_100ms (0 = off; HSystemModel::set_param_transfer_time).
  std::uint32_t param_transfer_time_100ms = 0;
  HChangesPlan changes;  ///< plan_h_changes (docs/h-scenario-changes.md)
};

struct HSystemPlan {
  int source = 0;  ///< index into Scenario.h_system
  std::string name;
  std::vector<HDpSystemPlan> dp_systems;
  devices::Us t_wa = 0;
  devices::Us t_prog = 0;
  std::int64_t db_kb = 0;
  devices::HParameters params;  ///< what the scenario configures (all unset = none)
  std::optional<HRuntimePlan> runtime;  ///< set when the entry has a `cpu` part
};

/// One step of a path from an h_system entry to a field in it: {"cpu"}, {"program"},
/// {"counter", 2}, then the field {"width"}. index -1 = a singular field.
struct HPathStep {
  const char* field;
  int index = -1;
};
/// 1-based line and column of the field at the end of `path` inside h_system[index] (the
/// nearest known position when the field is not in the text).
using HLocator = std::function<std::pair<int, int>(int index, const std::vector<HPathStep>& path)>;

/// Where a program's error is: the path inside the `program` message ({"counter", 2},
/// {"width"}), and the message.
using ProgramError = std::function<void(std::vector<HPathStep> path, std::string msg)>;
/// The checked ProgramSpec of a `program` (h_system's or s7_cpu's; rules above: width 1/2/4,
/// period > 0, ...). Errors go to `error`.
void plan_program_spec(const scenario::HProgram& program, devices::ProgramSpec& spec,
                       const ProgramError& error);
/// The program's SFC 90 calls (`h_ctrl`) into spec.h_ctrl_calls; a MODE/SUBMODE that SFC 90
/// would refuse (W#16#8090/8091) or a bad time is an error (h_plan_sfc90.cpp).
void plan_h_ctrl_calls(const scenario::HProgram& program, devices::ProgramSpec& spec,
                       const ProgramError& error);
/// The program's DP system function calls (SFC 11/12/14/15) into spec (h_plan_dp_sfc.cpp):
/// only their form (a time, octets that fit); the run answers the rest with RET_VALs.
void plan_dp_sfc_calls(const scenario::HProgram& program, devices::ProgramSpec& spec,
                       const ProgramError& error);

struct ScenarioPlan;
/// h_system[i].redundant_io -> rt.redundant_io (h_redundant_io_plan.cpp): each module a station
/// of a system the pair drives (a switched_station, or a dp_slave of one of its masters) and a
/// module of it, two different modules; inputs need a discrepancy_time; tolerance_permille
/// <= 1000; end_value > 0. The two modules' lengths are checked when the model is built.
void plan_redundant_io(const ScenarioPlan& plan, int i, HRuntimePlan& rt,
                       const ProgramError& error);
/// h_system[i]'s battery/RAM, T8 link-up, DB attributes, watchdog OBs, OB 72's SFC 27 and rack
/// module partitions into rt (h_changes_plan.cpp); after the program and the racks are planned.
void plan_h_changes(const ScenarioPlan& plan, int i, HRuntimePlan& rt, const ProgramError& error);
/// The fault switch_to_cpu for the simulated h_systems[h] (h_changes_plan.cpp): an added module
/// is a module of a switched_station of a system the pair drives; a changed_db a DB of
/// cpu.s7_memory. Errors at paths inside the switch_to_cpu message.
bool plan_switch_to_cpu(const ScenarioPlan& plan, int h, const scenario::HSwitchToCpu& s,
                        HSwitchPlan& out, const ProgramError& error);
/// Plans the h_system entries (after plan_dp: they refer to redundant_master_systems).
void plan_h(ScenarioPlan& plan, const DpLocator& locate, const HLocator& hlocate,
            std::vector<Diagnostic>& errors);
/// The procedure's input for h_systems[k] (may throw like redundancy::plan_switchover).
devices::UpdatePlanInput h_update_input(const ScenarioPlan& plan, const HSystemPlan& h);

}  // namespace pbvbus::tools
