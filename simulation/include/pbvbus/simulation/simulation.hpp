#pragma once
// A running scenario (design.md "Time", "The line", "Captures"): the scheduler, one bus::Line
// per scenario line, the FDL stations with their users, pty attachments, the faults scheduled
// at their times, and the taps (statistics, optional pcapng capture).
//
// Decisions:
//  - Line i is seeded with a value derived from the scenario seed and i (splitmix64), so two
//    lines never share a noise pattern and adding a line does not change the others'.
//  - Stations are attached in cable order (ScenarioPlan), labelled "master N", "slave N",
//    "serial monitor" or "serial station N" (the labels appear in fault descriptions).
//  - Everything is powered at time 0; faults and repairs run as scheduler events at their
//    time, before any station event of the same tick that was scheduled later.
//  - A serial attachment opens a pseudo-terminal (bus::PtyStation); its `link`, if given, is
//    created as a symbolic link to the pty (replacing an earlier symlink, never a file) and
//    removed when the Simulation ends.
//  - A capture listens at probe points (capture_probes.hpp); the constructor throws
//    std::runtime_error if the default probe cannot be placed (cmd_run checks that first).
//  - Faults scheduled after the end of the run (possible with a shorter --duration) are not
//    applied and are listed in the report.
//  - A serial attachment's slot time (bus::PtyStation reply window and Interface timing) is
//    the line's TSL, so it waits as long for a reply as the line's masters would.
//  - Gateways (gateway_node.hpp) are external attachments too: a scenario with one runs paced.
//    start() builds their cores after the h_systems (a source reads the H-system's model);
//    paced_runner() opens their doors on the runner's io_context and throws
//    std::runtime_error if one cannot open (a port in use). They are declared last, so they
//    are destroyed first: before the H-systems, lines and redundant systems they read and
//    before the runner whose io_context their doors use.

#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "pbvbus/bus/line.hpp"
#include "pbvbus/bus/paced_runner.hpp"
#include "pbvbus/bus/scheduler.hpp"
#include "pbvbus/simulation/capture_probes.hpp"
#include "pbvbus/simulation/gateway_node.hpp"
#include "pbvbus/simulation/h_system_node.hpp"
#include "pbvbus/simulation/quantum_node.hpp"
#include "pbvbus/simulation/redundancy_system.hpp"
#include "pbvbus/simulation/s7_door_node.hpp"
#include "pbvbus/simulation/s7_nodes.hpp"
#include "pbvbus/simulation/report.hpp"
#include "pbvbus/scenario/scenario.hpp"

namespace pbvbus::captures {
class PcapngWriter;
}
namespace pbvbus::devices {
class FdlPoller;
class FdlResponder;
}  // namespace pbvbus::devices

namespace pbvbus::tools {

struct SimulationOptions {
  std::optional<bus::Ticks> duration;  ///< overrides the scenario's
  std::optional<std::uint64_t> seed;   ///< overrides the scenario's
  /// The capture (not owned; must outlive the Simulation's runs): probes on every line as
  /// capture_probes.hpp places them; `probe` is the default position.
  captures::PcapngWriter* capture = nullptr;
  ProbeDefault probe;
  /// Replay (`pbvbus replay`, docs/replay.md): build no FDL masters and no DP masters (sides of
  /// a redundant master system excepted); each takes its cable position with an inert device
  /// (so fault positions and probes stay where the scenario put them), except the first master
  /// of `extra_line`, whose position `extra_device` takes.
  bool omit_masters = false;
  /// One device from outside (not owned; must outlive the Simulation) attached to the line named
  /// `extra_line` before the run: at its first omitted master's position, else after its last
  /// station. Powered with the line. Ignored if no line has that name.
  bus::Device* extra_device = nullptr;
  std::string extra_line;
  std::string extra_label = "replayer";
};

class Simulation {
 public:
  /// Builds everything; throws std::runtime_error if a resource cannot be had (a pty).
  Simulation(const ScenarioPlan& plan, const SimulationOptions& opts = {});
  ~Simulation();
  Simulation(const Simulation&) = delete;
  Simulation& operator=(const Simulation&) = delete;

  bus::Scheduler& scheduler() { return m_sched; }
  /// The run's length: the option, else the scenario's; nullopt if neither gives one.
  std::optional<bus::Ticks> duration() const { return m_duration; }
  std::uint64_t seed() const { return m_seed; }
  const ScenarioPlan& plan() const { return m_plan; }

  std::size_t line_count() const { return m_lines.size(); }
  bus::Line& line(std::size_t i);
  const LineStats& stats(std::size_t i) const;
  /// The traffic user of master `addr` on line `li`, or nullptr.
  const devices::FdlPoller* poller(std::size_t li, std::uint8_t addr) const;
  /// The user of passive station `addr` on line `li`, or nullptr.
  const devices::FdlResponder* responder(std::size_t li, std::uint8_t addr) const;

  /// The DP master / DP slave node at `addr` on line `li`, or nullptr.
  const DpMasterNode* dp_master(std::size_t li, std::uint8_t addr) const;
  DpMasterNode* dp_master(std::size_t li, std::uint8_t addr);
  const DpSlaveNode* dp_slave(std::size_t li, std::uint8_t addr) const;
  /// The redundant_master_system nodes, in file order.
  std::size_t redundant_system_count() const { return m_redundant.size(); }
  RedundantSystemNode& redundant_system(std::size_t i) { return *m_redundant.at(i); }
  const RedundantSystemNode& redundant_system(std::size_t i) const { return *m_redundant.at(i); }
  /// The simulated h_systems (entries with a cpu part), in file order; built by start().
  std::size_t h_system_count() const { return m_h.size(); }
  HSystemNode& h_system(std::size_t i) { return *m_h.at(i); }
  const HSystemNode& h_system(std::size_t i) const { return *m_h.at(i); }

  /// Whether something outside the process is attached (a pty, a gateway): then the run must
  /// be paced.
  bool has_external_attachments() const {
    if (!m_serial.empty() || !m_plan.gateways.empty() || !m_plan.s7.doors.empty()) return true;
    for (const auto& q : m_plan.quantum)
      if (!q.modbus.empty()) return true;
    return false;
  }
  /// The Quantum Hot Standby pairs, in file order (quantum_node.hpp).
  std::size_t quantum_count() const { return m_quantum.size(); }
  QuantumNode& quantum(std::size_t i) { return *m_quantum.at(i); }
  const QuantumNode& quantum(std::size_t i) const { return *m_quantum.at(i); }
  /// The gateways, in file order; built by start(), their doors opened by paced_runner().
  std::size_t gateway_count() const { return m_gateways.size(); }
  GatewayNode& gateway(std::size_t i) { return *m_gateways.at(i); }
  const GatewayNode& gateway(std::size_t i) const { return *m_gateways.at(i); }
  const std::vector<SerialReport>& serial_ports() const { return m_serial; }
  /// The s7_cpu entries, in file order.
  std::size_t s7_cpu_count() const { return m_s7_cpus.size(); }
  S7CpuNode& s7_cpu(std::size_t i) { return *m_s7_cpus.at(i); }
  const S7CpuNode& s7_cpu(std::size_t i) const { return *m_s7_cpus.at(i); }
  /// The s7_door entries, in file order; their doors opened by paced_runner().
  std::size_t s7_door_count() const { return m_s7_doors.size(); }
  S7DoorNode& s7_door(std::size_t i) { return *m_s7_doors.at(i); }
  const S7DoorNode& s7_door(std::size_t i) const { return *m_s7_doors.at(i); }
  /// The mpi_station entries (PGs, OPs), in file order.
  std::size_t mpi_client_count() const { return m_mpi_clients.size(); }
  MpiClientNode& mpi_client(std::size_t i) { return *m_mpi_clients.at(i); }
  const MpiClientNode& mpi_client(std::size_t i) const { return *m_mpi_clients.at(i); }

  /// Paced driver: creates the simulation's PacedRunner (once) and registers every pty
  /// attachment's I/O on its io_context. The Simulation owns the runner so that the order of
  /// tear-down is fixed: the doors (ptys) go first, then the runner and its io_context, then
  /// the scheduler — a door never cancels I/O on a dead io_context. Anything else registered
  /// on runner.io_context() by the caller must be gone before the Simulation. Opens the
  /// gateways' doors (start() first); throws std::runtime_error if a door cannot open.
  bus::PacedRunner& paced_runner(bus::Speed speed);
  /// Fast driver with ptys: reads what the programs wrote so far (call between slices).
  void poll_serial();

  /// Powers every station and schedules the faults (done once; run_until calls it).
  void start();
  /// Fast driver: runs every event up to `t` as fast as the CPU allows.
  void run_until(bus::Ticks t);

  /// The report as of now. `wall_seconds` is how long the run took (for the speed figure).
  Report report(double wall_seconds) const;
  /// The S7 part of the report as of now.
  S7Report s7_report() const;

 private:
  struct Station;
  struct LineState;
  void build_line(std::size_t li);
  void schedule_faults();
  void build_gateways();
  void attach_s7_capture(S7DoorNode& door);
  /// The running model of h_systems[plan_index] (nullptr before start() or without a `cpu`).
  devices::HSystemModel* h_model(int plan_index);
  /// Powers the MPI stations of h_systems[plan_index]'s CPU `rack` with the CPU.
  void set_h_mpi_power(int plan_index, int rack, bool on);
  void apply_fault(const PlanFault& f, bool on);
  void apply_slave_fault(const PlanFault& f, bool on);
  void apply_channel_stuck(const PlanFault& f, bool on);  ///< redundant I/O (h-redundant-io.md)
  void make_link(const std::string& target, const std::string& link);

  ScenarioPlan m_plan;
  SimulationOptions m_opts;
  std::optional<bus::Ticks> m_duration;
  std::uint64_t m_seed = 0;
  bus::Scheduler m_sched;
  // Declared after the scheduler and before the lines: destroyed after every door, before the
  // scheduler it drives.
  std::unique_ptr<bus::PacedRunner> m_runner;
  // Redundant master systems own devices on several lines: built before the lines, destroyed
  // after them.
  std::vector<std::unique_ptr<RedundantSystemNode>> m_redundant;
  // CPUs and PGs/OPs own MPI stations the lines hold: built before the lines, destroyed after.
  std::vector<std::unique_ptr<S7CpuNode>> m_s7_cpus;
  std::vector<std::unique_ptr<MpiClientNode>> m_mpi_clients;
  std::vector<std::unique_ptr<S7DoorNode>> m_s7_doors;
  std::vector<std::unique_ptr<HCpuMpiNode>> m_h_mpi;  ///< the H CPUs' MPI interfaces
  // Quantum pairs own DP master modules the lines hold, and Modbus doors on the runner's
  // io_context: built before the lines, destroyed after them and before the runner.
  std::vector<std::unique_ptr<QuantumNode>> m_quantum;
  std::vector<std::unique_ptr<LineState>> m_lines;
  // H-systems drive the redundant systems' models and schedule on m_sched: destroyed first.
  std::vector<std::unique_ptr<HSystemNode>> m_h;
  // Gateways read the master systems (and H-systems) and use the runner's io_context:
  // declared last, destroyed first.
  std::vector<std::unique_ptr<GatewayNode>> m_gateways;
  std::vector<SerialReport> m_serial;
  std::vector<std::string> m_not_reached;
  std::vector<std::string> m_links;  ///< symlinks to ptys, removed at the end
  bool m_started = false;
};

}  // namespace pbvbus::tools
