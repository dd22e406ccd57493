// The planner's input from a scenario (timing_plan.hpp).
#include "pbvbus/scenario/timing_plan.hpp"

#include <algorithm>

namespace pbvbus::tools {

namespace {

redundancy::PlannedSlave planned(const DpSlavePlan& sp, int line) {
  redundancy::PlannedSlave ps;
  ps.address = sp.address;
  ps.name = sp.model;
  ps.in_len = sp.inputs;
  ps.out_len = sp.outputs;
  ps.max_tsdr_bits = sp.gsd_max_tsdr;
  ps.max_diag_len = sp.config.max_diag_len;
  ps.line = line;
  return ps;
}

/// A note when line `line` holds more masters than the one planned.
void note_other_masters(const ScenarioPlan& plan, int line, std::vector<std::string>& notes) {
  const PlanLine& pl = plan.lines.at(static_cast<std::size_t>(line));
  const auto masters =
      std::count_if(pl.stations.begin(), pl.stations.end(), [](const PlanStation& s) {
        return s.kind == StationKind::Master || s.kind == StationKind::DpMaster;
      });
  if (masters > 1)
    notes.push_back("line " + pl.name + ": " + std::to_string(masters) +
                    " masters share the token; T_TR is this master's own pass only, the token "
                    "rotation also holds the other masters' passes");
}

bool starts_with(const std::string& s, const char* prefix) {
  return s.rfind(prefix, 0) == 0;
}

/// The planner says "line A:" / "line B:"; say the scenario's names.
void name_lines(std::vector<std::string>& notes, const std::string& a, const std::string& b) {
  for (std::string& n : notes) {
    if (starts_with(n, "line A:"))
      n = "line " + a + n.substr(6);
    else if (starts_with(n, "line B:"))
      n = "line " + b + n.substr(6);
  }
}

}  // namespace

std::vector<redundancy::PlannedSlave> planned_slaves_of_system(const ScenarioPlan& plan,
                                                               int system) {
  const RedundancyPlan& rp = plan.redundant_systems.at(static_cast<std::size_t>(system));
  std::vector<redundancy::PlannedSlave> out;
  for (int side = 0; side < 2; ++side) {
    const DpMasterPlan& mp = plan.dp_masters.at(static_cast<std::size_t>(rp.master[side]));
    for (int k : mp.slaves) {
      const DpSlavePlan& sp = plan.dp_slaves.at(static_cast<std::size_t>(k));
      if (sp.switched >= 0 && side == 1) continue;  // once per switched station
      redundancy::PlannedSlave ps = planned(sp, side);
      ps.switched = sp.switched >= 0;
      if (ps.switched)
        ps.t_slave_um = plan.switched.at(static_cast<std::size_t>(sp.switched)).t_slave_um;
      out.push_back(std::move(ps));
    }
  }
  return out;
}

std::vector<redundancy::PlannedSlave> planned_slaves_of_master(const ScenarioPlan& plan,
                                                               int dp_master) {
  const DpMasterPlan& mp = plan.dp_masters.at(static_cast<std::size_t>(dp_master));
  std::vector<redundancy::PlannedSlave> out;
  for (int k : mp.slaves) out.push_back(planned(plan.dp_slaves.at(static_cast<std::size_t>(k)), 0));
  return out;
}

redundancy::SwitchoverPlan plan_system_timing(const ScenarioPlan& plan, int system) {
  const RedundancyPlan& rp = plan.redundant_systems.at(static_cast<std::size_t>(system));
  const PlanLine& a = plan.lines.at(static_cast<std::size_t>(rp.line[0]));
  const PlanLine& b = plan.lines.at(static_cast<std::size_t>(rp.line[1]));
  redundancy::SwitchoverPlan sp =
      redundancy::plan_switchover(a.params, planned_slaves_of_system(plan, system));
  const fdl::BusParams& pa = a.params;
  const fdl::BusParams& pb = b.params;
  name_lines(sp.notes, a.name, b.name);
  if (pa.baud != pb.baud || pa.tsl != pb.tsl || pa.min_tsdr != pb.min_tsdr ||
      pa.max_tsdr != pb.max_tsdr || pa.tqui != pb.tqui || pa.tset != pb.tset || pa.ttr != pb.ttr ||
      pa.max_retry != pb.max_retry || pa.tsdi != pb.tsdi)
    sp.notes.push_back("lines " + a.name + " and " + b.name +
                       " have different bus parameters; both are planned with line " + a.name +
                       "'s");
  for (int side = 0; side < 2; ++side) note_other_masters(plan, rp.line[side], sp.notes);
  return sp;
}

redundancy::SwitchoverPlan plan_master_timing(const ScenarioPlan& plan, int dp_master) {
  const DpMasterPlan& mp = plan.dp_masters.at(static_cast<std::size_t>(dp_master));
  redundancy::SwitchoverPlan sp =
      redundancy::plan_switchover(plan.lines.at(static_cast<std::size_t>(mp.line)).params,
                                  planned_slaves_of_master(plan, dp_master));
  // Only line A is planned: drop what the planner says about the empty line B and the system.
  std::erase_if(sp.notes, [](const std::string& n) {
    return starts_with(n, "line B:") || starts_with(n, "no switched stations");
  });
  const std::string& name = plan.lines.at(static_cast<std::size_t>(mp.line)).name;
  name_lines(sp.notes, name, name);
  note_other_masters(plan, mp.line, sp.notes);
  return sp;
}

}  // namespace pbvbus::tools
