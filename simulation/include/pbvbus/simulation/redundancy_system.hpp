#pragma once
// A scenario's redundant_master_system at run time (docs/redundancy.md): the two
// dp_masters of the system as one devices::RedundantMasterSystemModel, its switched_stations as
// devices::SwitchedStationModels (interface 0 on line A, 1 on line B), the program, the faults
// that concern it, the events (report, JSON and the capture's event interface) and the
// switchover measurements beside the planner's bounds (redundancy::plan_switchover).
//
// Decisions:
// - The program runs once for the system (the masters' dp_master `outputs`, line A's entry):
//   at every token receipt of either master, COUNT writes the number of such cycles (mod 256)
//   into every output octet of every slave of the system, through MasterSystem::write_outputs
//   (both channels alike, so a switchover never brings an older value); ZERO writes zeros.
// - Measured switchover: from the latest fault or repair applied to the system's lines or
//   devices at or before the switchover command, to the station's first fresh outputs on the
//   new active channel (RedundantSlave event FreshOutputs). Bound: the planner's station bound
//   for the failed channel's line (station-level), or the system bound of the lost line
//   (a short circuit: system_bound; a master stop or failure: system_bound_master_stop).
//   A switchover whose fresh outputs never came (the station failed too) has no measurement.
// - Capture events: category Redundancy, code = redundancy::SystemEvent::Kind, line = the
//   line's index, a = station address (-1 for the master system), b = the line index of the
//   channel concerned, value = the S7 event id (W#16#73A3 ...; 0 for a switchover record).
#include <cstdint>
#include <iosfwd>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "pbvbus/bus/line.hpp"
#include "pbvbus/dp_link/dp_link.hpp"
#include "pbvbus/switched_io/redundant_master_system.hpp"
#include "pbvbus/switched_io/switched_station.hpp"
#include "pbvbus/redundancy/switchover_timing.hpp"
#include "pbvbus/scenario/scenario.hpp"

namespace pbvbus::captures {
class PcapngWriter;
}

namespace pbvbus::tools {

struct RedEventReport {
  bus::Ticks time = 0;
  int ob = 0;               ///< 70, 86; 0 for a switchover record
  std::uint16_t code = 0;   ///< 0x73A3 ...
  std::string kind;         ///< "redundancy loss", ...
  std::string line;         ///< the line concerned
  int station = -1;         ///< -1: the master system
  std::string cause;
  std::string from;         ///< switchover: the previous active line ("" = none)
};

struct SwitchoverReport {
  std::uint8_t station = 0;
  std::string from;  ///< line names ("" = none)
  std::string to;
  std::string cause;
  bool system_level = false;
  bus::Ticks fault_at = 0;
  std::string fault;  ///< the fault's description
  bus::Ticks commanded = 0;
  std::optional<bus::Ticks> fresh;     ///< first fresh outputs on the new channel
  std::optional<bus::Ticks> measured;  ///< fresh − fault_at
  bus::Ticks bound = 0;
  bool exceeded = false;
  /// The IM's own switchover time drawn for this switchover (S5; nullopt: none drawn, e.g. no
  /// T_SLAVE_UM known or the station lost).
  std::optional<bus::Ticks> im_time;
};

struct SwitchedStationReport {
  std::uint8_t address = 0;
  std::string model;
  std::vector<std::string> modules;
  std::string active;         ///< line name of the active channel, "" = none
  std::string roles[2];       ///< the interfaces' roles ("PRIMARY", "BACKUP", ...)
  bool redundancy_lost = false;
  bool failed = false;
  std::vector<std::uint8_t> outputs;  ///< the backplane
  bool outputs_held = false;
  std::optional<bus::Ticks> t_slave_um;
  bus::Ticks bound[2] = {0, 0};  ///< the planner's station bound, per failing line
};

struct RedundancyReport {
  std::string name;
  std::string line[2];
  std::uint8_t master[2] = {0, 0};
  bus::Ticks t_tr[2] = {0, 0};
  bus::Ticks recognition[2] = {0, 0};
  bus::Ticks system_bound[2] = {0, 0};
  std::vector<SwitchedStationReport> stations;
  std::vector<RedEventReport> events;
  std::vector<SwitchoverReport> switchovers;
  std::uint64_t exceeded = 0;
};

// Text and JSON forms: pbvbus/reports/redundancy_report.hpp.

class RedundantSystemNode {
 public:
  /// `params[l]` = the effective bus parameters of the system's line l. Throws
  /// std::runtime_error if a model cannot be built (the loader checks the same).
  RedundantSystemNode(const ScenarioPlan& plan, int system, const fdl::BusParams params[2],
                      std::optional<std::uint64_t> seed = std::nullopt);
  ~RedundantSystemNode();
  RedundantSystemNode(const RedundantSystemNode&) = delete;
  RedundantSystemNode& operator=(const RedundantSystemNode&) = delete;

  int index() const { return m_system; }
  const RedundancyPlan& plan() const;
  devices::RedundantMasterSystemModel& model() { return *m_model; }
  const devices::RedundantMasterSystemModel& model() const { return *m_model; }
  /// The side (0/1) of dp_masters[dp_master] in this system, or -1.
  int side_of_master(int dp_master) const;
  /// The model of ScenarioPlan::switched[k], or nullptr if it is not in this system.
  devices::SwitchedStationModel* station(int k);
  const devices::SwitchedStationModel* station(int k) const;
  /// The IM 157 link of ScenarioPlan::switched[k] (dp_link_node.hpp), or nullptr.
  devices::DpLink* link(int k);

  /// Line indices (ScenarioPlan::lines) of sides A and B.
  int line(int side) const;
  void set_capture(captures::PcapngWriter* w) { m_capture = w; }

  /// A fault or repair that concerns the system (its lines or devices) was applied at `now`.
  void note_fault(bus::Ticks now, const PlanFault& f, bool on);
  /// Applies a switched-I/O fault (InterfaceFailure, StationPowerLoss, MasterFailure,
  /// MasterStop of one of its masters); returns the text for the report.
  std::string apply(const PlanFault& f, bool on);

  RedundancyReport report() const;

 private:
  void on_system_event(const redundancy::SystemEvent& e);
  const std::string& line_name(int side) const;

  const ScenarioPlan& m_plan;
  int m_system;
  std::unique_ptr<devices::RedundantMasterSystemModel> m_model;
  std::vector<std::pair<int, std::unique_ptr<devices::SwitchedStationModel>>> m_stations;
  std::vector<std::pair<int, std::unique_ptr<devices::DpLink>>> m_links;  ///< IM 157 links
  /// Every switched station's model (m_stations' and the links' upper sides), plan order.
  std::vector<std::pair<int, devices::SwitchedStationModel*>> m_models;
  captures::PcapngWriter* m_capture = nullptr;
  redundancy::SwitchoverPlan m_timing;
  scenario::DpMaster::Outputs m_program = scenario::DpMaster::COUNT;
  bool m_program_off = false;  ///< a gateway's clients own the outputs
  std::uint64_t m_cycles = 0;
  std::vector<std::uint8_t> m_buf;
  struct Fault {
    bus::Ticks at = 0;
    std::string text;
    PlanFault::Kind kind = PlanFault::Kind::CableCut;
    bool on = true;
  };
  std::vector<Fault> m_faults;
  struct Switch {
    redundancy::SystemEvent event;
    Fault fault;
    bool has_fault = false;
  };
  std::vector<Switch> m_switches;
};

}  // namespace pbvbus::tools
