#pragma once
// A scenario's h_system entries (issue 8; docs/h-timing.md): the inputs of the T_P15 procedure
// and the configured H parameters, checked by the loader (FILE:LINE:COLUMN) and turned into a
// devices::UpdatePlanInput by h_update_input() (the DP master systems that name a
// redundant_master_system take T_TR, T_DP_UM and T_SLAVE_UM from redundancy::plan_switchover:
// the larger line's T_TR, the larger direction's T_DP_UM, the slowest station's T_SLAVE_UM;
// a figure given in the entry wins).
#include <optional>
#include <string>
#include <vector>

#include "pbvbus/devices/h_update_timing.hpp"
#include "pbvbus/tools/dp_plan.hpp"

namespace pbvbus::tools {

struct HDpSystemPlan {
  std::string name;
  int system = -1;  ///< index into ScenarioPlan::redundant_systems, or -1 (figures given)
  std::optional<devices::Us> t_tr, t_dp_um, t_slave_um;
  devices::Us t_pto = 0;
};

struct HSystemPlan {
  int source = 0;  ///< index into Scenario.h_system
  std::string name;
  std::vector<HDpSystemPlan> dp_systems;
  devices::Us t_wa = 0;
  devices::Us t_prog = 0;
  std::int64_t db_kb = 0;
  devices::HParameters params;  ///< what the scenario configures (all unset = none)
};

struct ScenarioPlan;
/// Plans the h_system entries (after plan_dp: they refer to redundant_master_systems).
void plan_h(ScenarioPlan& plan, const DpLocator& locate, std::vector<Diagnostic>& errors);
/// The procedure's input for h_systems[k] (may throw like redundancy::plan_switchover).
devices::UpdatePlanInput h_update_input(const ScenarioPlan& plan, const HSystemPlan& h);

}  // namespace pbvbus::tools
