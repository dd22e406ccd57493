#pragma once
// A scenario's simulated h_system at run time (docs/h-system.md; docs/h-scenarios.md): the CPU pair
// (devices::HSystemModel) driving the redundant master systems the entry names, its user
// program, the power-on times, the H faults of the scenario, the report part and the capture's
// CPU records.
//
// Decisions:
// - Built by Simulation::start() after the lines were started (HSystemModel unpowers the DP
//   masters of CPUs that are off), before the faults are scheduled.
// - The driven RedundantSystemNodes' own program (COUNT/ZERO at every token receipt) is
//   switched off: the pair's user program (OB 1 on the process image) writes the outputs.
//   Without program networks the outputs stay as the masters' images hold them.
// - Power-on: equal times for both racks are the simultaneous POWER ON
//   (HSystemModel::power_on_both); otherwise each rack at its time. fibres_connected_at_power_on
//   false cuts both fibres at time 0, before any power-on (F7).
// - comparison_error: with a program whose CPU memory is not empty, one bit of the standby's
//   memory is flipped (HSystemModel::inject_divergence): the program's own comparison finds it
//   at the next Redundant scan (F16 as the manual describes it); without one, the pair is told
//   directly. parameter_change: the standby's parameter that may not change, then the operator
//   master swap, which the pair refuses with W#16#5966 (F23).
// - Capture: every event of the pair (state, role, system mode, OB 72/121) as a Cpu record
//   (h_event_record); the model's other OBs (85, the alarms' 40/82/83..., the program's 7960)
//   as Cpu records of kind Ob (a = rack, -1 = both CPUs); each H fault as a Note record before
//   the reactions it causes; all at their virtual time. OB 70/86 are the redundancy records.
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "pbvbus/bus/scheduler.hpp"
#include "pbvbus/s7h/h_system.hpp"
#include "pbvbus/simulation/h_report.hpp"
#include "pbvbus/scenario/scenario.hpp"

namespace pbvbus::captures {
class PcapngWriter;
}

namespace pbvbus::tools {

class RedundantSystemNode;

class HSystemNode {
 public:
  /// `systems[k]` = the node of ScenarioPlan::redundant_systems[k]. Throws std::runtime_error
  /// with the h_system's name if the model cannot be built (e.g. a program address outside the
  /// process images).
  HSystemNode(const ScenarioPlan& plan, int index, bus::Scheduler& sched,
              const std::vector<RedundantSystemNode*>& systems);
  ~HSystemNode();
  HSystemNode(const HSystemNode&) = delete;
  HSystemNode& operator=(const HSystemNode&) = delete;

  /// Schedules the power-on of each rack (once).
  void start();
  void set_capture(captures::PcapngWriter* w) { m_capture = w; }
  /// Applies an H fault (is_h_fault) or its repair; returns the text for the report.
  std::string apply(const PlanFault& f, bool on);

  const HSystemPlan& plan() const;
  devices::HSystemModel& model() { return *m_model; }
  const devices::HSystemModel& model() const { return *m_model; }
  HSystemReport report() const;

 private:
  void on_pair_event(const devices::HEvent& e);
  void on_model_event(const devices::HSystemEvent& e);
  /// An I/O event as the report shows it beside its OB and code: "master system failure: DP
  /// master system \"H-DP 1\", line DP_B".
  std::string io_event_text(const devices::HSystemEvent& e) const;
  void note(std::string text);
  // ---- docs/h-scenario-changes.md (h_system_node_changes.cpp) ----
  void setup_changes();   ///< constructor: RAM test, OB 72's SFC 27
  void start_changes();   ///< start(): the watchdog OBs at their phase
  std::string apply_switch(const PlanFault& f);  ///< switch_to_cpu: "" or ": refused ..."
  void equal_db_blocks();  ///< master_swap after a switch_to_cpu: both CPUs' DBs alike again
  void report_changes(HSystemReport& r) const;   ///< OB1_SCAN_1 B#16#05, OB 72's SFC 27

  const ScenarioPlan& m_plan;
  int m_index;
  bus::Scheduler& m_sched;
  std::unique_ptr<devices::HSystemModel> m_model;
  captures::PcapngWriter* m_capture = nullptr;
  bool m_started = false;
  std::vector<std::pair<bus::Ticks, std::string>> m_faults;
  std::optional<bus::Ticks> m_planned_t_p15, m_planned_t_ph;
  bool m_db_blocks_set = false;  ///< a switch_to_cpu set the DBs' 5.2.3 attributes
};

}  // namespace pbvbus::tools
