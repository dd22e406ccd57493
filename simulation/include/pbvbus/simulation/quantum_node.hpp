#pragma once
// A scenario's Quantum Hot Standby pair at run time (docs/quantum-hsby.md "In a scenario"): the
// pair (quantum::HsbyPair) on the simulation's scheduler, both racks' DP master modules
// (quantum::DpHead) on the DP line at the dp_master's place, the user logic, the Modbus doors
// of its ports, the Quantum faults of the scenario, the report part and the capture's records.
//
// Decisions:
// - The dp_master entry named by `dp` is not built as a plain DpMasterNode: its place on the
//   cable is taken by rack 0's module, rack 1's module right after it (the same address).
//   The modules are unpowered until the pair powers their racks.
// - The logic: `counter` counts by one every scan, skipping 0 (a value 0 on the slaves would be
//   indistinguishable from their safe state); then the `copy` blocks in file order.
// - The standby's silence bound (line_check_delay and the DP head's bound) is the DP line's
//   TTO for the module's address (protocol-facts.md §C.4), capped at half the scan (so that
//   every takeover stays within one scan: hsby_pair.hpp).
// - Modbus: per port one quantum::HsbyModbusPort; the TCP door answers 0x0B for a unit nobody
//   holds (a gateway in front of the port's network), the RTU door answers nothing (multidrop).
//   Broadcasts (RTU unit 0) go to the primary's state RAM. FC43 names the answering rack's
//   designation ("HSBY unit A").
// - The command register starts with the configuration (the Hot Standby dialog): override,
//   both run modes Run, the logic-mismatch option, each port's swap setting.
// - The command faults write the run bits into the primary's command register as a host would
//   over Modbus; the keyswitch override must be configured for them to act.
// - Capture: every pair event as an Hsby record (captures/event_record.hpp) at its virtual
//   time, each Quantum fault as a Note record before the reactions it causes.
#include <memory>
#include <string>
#include <vector>

#include "pbvbus/bus/paced_runner.hpp"
#include "pbvbus/bus/scheduler.hpp"
#include "pbvbus/quantum/dp_head.hpp"
#include "pbvbus/quantum/hsby_modbus_port.hpp"
#include "pbvbus/quantum/hsby_pair.hpp"
#include "pbvbus/scenario/scenario.hpp"
#include "pbvbus/simulation/quantum_report.hpp"

namespace pbvbus::captures {
class PcapngWriter;
}
namespace pbvbus::gateways {
class StateRamModbusHandler;
class ModbusTcpServer;
class ModbusRtuPort;
}  // namespace pbvbus::gateways

namespace pbvbus::tools {

class QuantumNode {
 public:
  QuantumNode(const ScenarioPlan& plan, int index, bus::Scheduler& sched);
  ~QuantumNode();
  QuantumNode(const QuantumNode&) = delete;
  QuantumNode& operator=(const QuantumNode&) = delete;

  const QuantumPlan& plan() const;
  /// The pair's DP master modules take the dp_master's place on `line` (rack 0, then rack 1).
  /// Returns rack 0's attachment.
  bus::AttachmentId attach_dp(bus::Line& line);
  /// After the lines have started: unpowers the modules, schedules each rack's power-on.
  void start();
  /// Opens the Modbus doors on the paced run's io_context; throws std::runtime_error.
  void open(bus::PacedRunner& runner);
  std::vector<std::string> door_lines() const;
  void set_capture(captures::PcapngWriter* w) { m_capture = w; }
  /// Applies a Quantum fault (is_quantum_fault) or its repair.
  void apply(const PlanFault& f, bool on);

  quantum::HsbyPair& pair() { return *m_pair; }
  const quantum::HsbyPair& pair() const { return *m_pair; }
  quantum::DpHead* head(int rack) { return m_heads[static_cast<std::size_t>(rack)].get(); }
  QuantumReport report() const;

 private:
  struct Port;
  void logic(quantum::StateRam& ram);
  void on_event(const quantum::PairEvent& e);
  void refresh_addresses();
  void note(const std::string& text);

  const ScenarioPlan& m_plan;
  int m_index;
  bus::Scheduler& m_sched;
  std::array<std::unique_ptr<quantum::DpHead>, 2> m_heads;
  std::unique_ptr<quantum::HsbyPair> m_pair;
  std::vector<std::unique_ptr<Port>> m_ports;
  bus::Line* m_dp_line = nullptr;
  captures::PcapngWriter* m_capture = nullptr;
  std::vector<std::array<int, 2>> m_port_addr;  ///< each port's addresses (rack 0, 1) at the last scan
  std::vector<QuantumSwitchoverReport> m_switchovers;  ///< Modbus before/after, in switchover order
  std::vector<std::pair<bus::Ticks, std::string>> m_faults;
  bool m_started = false;
};

}  // namespace pbvbus::tools
