#pragma once
// The switchover-time planner's input from a scenario (redundancy::plan_switchover, docs/
// switchover-timing.md): a redundant_master_system or a plain dp_master as the list of
// redundancy::PlannedSlave the planner reads, and the plan. Used by `pbvbus timing`
// (cmd_timing.cpp); RedundantSystemNode (redundancy_system.cpp) builds the same list itself.
//
// Decisions:
// - One entry per switched station (its line-A interface's DpSlavePlan: address, model, input
//   and output octets, GSD MaxTsdr at the line's baud, Max_Diag_Data_Len) with its T_SLAVE_UM
//   (SwitchedPlan::t_slave_um), one per one-sided slave on the side of its master.
// - The bus parameters are line A's effective ones (PlanLine::params), as the simulation plans
//   a system; when line B's differ, a note says so.
// - A plain dp_master: its slaves, all one-sided on line 0 (A), none switched; only the plan's
//   line[0] means anything (line B is empty).
// - A line with more than one master (FDL or DP) gets a note: the planner counts this master's
//   own pass only, not the other masters' token holding times.

#include <string>
#include <vector>

#include "pbvbus/redundancy/switchover_timing.hpp"
#include "pbvbus/scenario/scenario.hpp"

namespace pbvbus::tools {

/// The planner's slaves of redundant system `system` (index into plan.redundant_systems).
std::vector<redundancy::PlannedSlave> planned_slaves_of_system(const ScenarioPlan& plan,
                                                               int system);
/// The planner's slaves of dp_master `dp_master` (index into plan.dp_masters), all on line 0.
std::vector<redundancy::PlannedSlave> planned_slaves_of_master(const ScenarioPlan& plan,
                                                               int dp_master);

/// plan_switchover for redundant system `system`, with the notes above added. Throws
/// std::invalid_argument as plan_switchover does.
redundancy::SwitchoverPlan plan_system_timing(const ScenarioPlan& plan, int system);
/// plan_switchover for a plain dp_master (line[0] only); the planner's notes about the empty
/// line B and the missing switched stations are left out.
redundancy::SwitchoverPlan plan_master_timing(const ScenarioPlan& plan, int dp_master);

}  // namespace pbvbus::tools
