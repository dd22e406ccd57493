#pragma once
// DP master systems at run time (design.md "Configuration and command line"; protocol-facts.md
// §D.9 class-1 master): the scenario's dp_master becomes an fdl::ActiveStation driven by a
// dp::Master, each dp_slave an fdl::PassiveStation driven by a dp::SlaveEngine, with small
// models on both sides so that data exchange is visible:
//  - master side (DpMasterNode, "the test program"): at every token receipt it writes every
//    output octet of every slave = the number of token receipts so far (mod 256), or zeros;
//    nothing at all when a gateway serves the master (its clients own the outputs);
//  - device side (DpSlaveNode): a devices::SlaveModel built from the GSD and module list, with
//    one I/O behaviour per module that has inputs: COUNTER = a big-endian counter of the DP
//    cycles over the module's input octets; ECHO = the module's own outputs, or, for an
//    input-only module, those of the first module with outputs; ZERO = constant zeros.
// The master-side hook is a decorator of fdl::InitiatorUser, so the DP stack stays untouched
// and the wire timing is exactly the stacks' (the hooks take no virtual time).
//
// Report (DpSlaveReport, DpMasterReport): the master's view of each slave (state, stored
// diagnosis with decoded bits, in/out octets and their current values, DP cycle time
// min/median/max from dp::MasterSlaveStats, failures/returns) and the slave's own state.
// Global_Control frames are counted as the master hands them to its station.
// DpSlaveView: every slave's own view (state, owner, the inputs it sent and the outputs it
// received last, what it was asked: dp::SlaveStats, fdl::PassiveStats), whether or not a
// pbvbus master is configured for it — the only view there is with a master outside pbvbus.

#include <cstdint>
#include <functional>
#include <iosfwd>
#include <span>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "pbvbus/dp/master.hpp"
#include "pbvbus/dp/slave_engine.hpp"
#include "pbvbus/fdl/active_station.hpp"
#include "pbvbus/slaves/slave_model.hpp"
#include "pbvbus/fdl/passive_station.hpp"
#include "pbvbus/scenario/dp_plan.hpp"

namespace pbvbus::tools {

/// dp::Master with the master-side test program and a Global_Control counter.
class DpMasterNode final : public fdl::InitiatorUser {
 public:
  DpMasterNode(const DpMasterPlan& plan, const std::vector<DpSlavePlan>& slaves,
               const fdl::BusParams& params);
  fdl::ActiveStation& station() { return *m_station; }
  const fdl::ActiveStation& station() const { return *m_station; }
  dp::Master& master() { return m_master; }
  const dp::Master& master() const { return m_master; }
  std::uint64_t global_controls() const { return m_global_controls; }
  /// The master is a CPU's DP interface (s7_nodes.hpp): at every token receipt `cpu` exchanges
  /// the CPU's process image with the slaves instead of the master-side test program.
  void set_cpu(std::function<void(dp::Master&)> cpu) { m_cpu = std::move(cpu); }

  void on_power_on(bus::Ticks now) override;
  bool next_request(fdl::Priority prio, bus::Ticks now, fdl::Request& out) override;
  void on_confirmation(const fdl::Confirmation& con) override { m_master.on_confirmation(con); }
  void on_request(const fdl::Indication& ind, fdl::Reply& reply) override {
    m_master.on_request(ind, reply);
  }
  void on_token(bus::Ticks now, bus::Ticks trr) override;
  /// Equidistance (docs/dp-equidistance.md): the master's pause.
  bus::Ticks pause_until(bus::Ticks now) override { return m_master.pause_until(now); }

 private:
  dp::Master m_master;
  scenario::DpMaster::Outputs m_program;
  bool m_program_off = false;  ///< a gateway's clients own the outputs
  std::function<void(dp::Master&)> m_cpu;  ///< a CPU owns the outputs
  std::unique_ptr<fdl::ActiveStation> m_station;
  std::uint64_t m_tokens = 0;
  std::uint64_t m_global_controls = 0;
  std::vector<std::uint8_t> m_buf;
  /// The master's slaves (fixed when the master is built): the program walks them at every
  /// token receipt, without building the list each time.
  std::vector<std::uint8_t> m_addresses;
};

/// The I/O behaviours of a planned slave (its `inputs` default per input module, then its `io`
/// entries) through a model's set_behaviour/add_channel_behaviour; throws std::runtime_error
/// if the model refuses one (the loader checks the same). Shared by SlaveModel and
/// SwitchedStationModel.
void apply_io_plan(const DpSlavePlan& plan, const dp::SlaveApplication& app,
                   const std::function<std::string(std::size_t, devices::IoBehaviour)>& set,
                   const std::function<std::string(std::size_t, std::size_t, std::size_t,
                                                   devices::IoBehaviour)>& add);

/// A DP slave: devices::SlaveModel (PassiveStation + SlaveEngine + I/O behaviours).
class DpSlaveNode {
 public:
  /// Throws std::runtime_error if the model cannot be built (the loader checks the same).
  DpSlaveNode(const DpSlavePlan& plan, const fdl::BusParams& params);
  ~DpSlaveNode();
  /// The device to attach to the line.
  bus::Device& station() { return *m_model; }
  devices::SlaveModel& model() { return *m_model; }
  dp::SlaveEngine& engine();
  const dp::SlaveEngine& engine() const;
  std::uint64_t data_exchanges() const;

 private:
  std::unique_ptr<devices::SlaveModel> m_model;
};

struct DpSlaveReport {
  std::uint8_t address = 0;
  std::uint8_t master = 0;
  std::string model;                 ///< GSD Model_Name
  std::string gsd;                   ///< GSD path as written in the scenario
  std::vector<std::string> modules;
  std::string state;                 ///< the master's view, e.g. "DataExchange"
  std::string slave_state;           ///< the slave's own, e.g. "Data_Exch"
  std::vector<std::uint8_t> diag;    ///< last diagnosis the master stored
  std::vector<std::string> diag_bits;  ///< names of the set bits of octets 1..3
  std::size_t input_len = 0;
  std::size_t output_len = 0;
  std::vector<std::uint8_t> inputs;   ///< master image, current
  std::vector<std::uint8_t> outputs;  ///< what the slave received last (Rd_Outp view)
  dp::MasterSlaveStats stats;
  bus::Ticks cycle_median = 0;
};

/// A DP slave as it sees itself (see the report schema, "dp_slaves").
struct DpSlaveView {
  std::string line;
  std::uint8_t address = 0;
  std::string model;
  std::string gsd;                       ///< the GSD file (path as resolved by the loader)
  std::vector<std::string> modules;
  std::optional<std::uint8_t> master;    ///< its dp_master in the scenario, if any
  std::string state;                     ///< e.g. "Data_Exch"
  std::optional<std::uint8_t> owner;     ///< the master that parameterised it
  std::optional<bus::Ticks> watchdog;    ///< set by the owner; none = off
  std::vector<std::uint8_t> diag;        ///< what it would answer to Slave_Diag now
  std::vector<std::string> diag_bits;
  std::size_t input_len = 0;
  std::size_t output_len = 0;
  std::vector<std::uint8_t> inputs;   ///< sent in its last Data_Exchange reply
  std::vector<std::uint8_t> outputs;  ///< received in its last accepted Data_Exchange
  dp::SlaveStats stats;
  fdl::PassiveStats fdl;
};

/// The slave's own view; `line` is the line's name.
DpSlaveView dp_slave_view(const DpSlaveNode& node, const DpSlavePlan& plan, const std::string& line);

struct DpMasterReport {
  std::uint8_t address = 0;
  std::string line;
  bus::Baud baud = bus::Baud::k1_5M;
  std::string mode;  ///< "Operate", "Clear", "Stop", "Offline"
  std::uint64_t global_controls = 0;
  std::uint16_t data_control_time = 0;  ///< 10 ms units
  dp::EquidistanceStats equidistance;    ///< period 0 = off (docs/dp-equidistance.md)
  std::vector<DpSlaveReport> slaves;
};

/// Names of the set bits of Slave_Diag octets 1..3 (Station_Non_Existent, ..., Deactivated).
std::vector<std::string> diag_bit_names(std::span<const std::uint8_t> diag);

DpMasterReport dp_master_report(const DpMasterNode& m, const std::vector<const DpSlaveNode*>& slaves,
                                const std::vector<const DpSlavePlan*>& plans,
                                const std::string& line, bus::Baud baud);
/// The same for any dp::Master (one side of a redundant system): `engines[i]` is the slave
/// engine that answers plans[i] on this line (a switched station's interface).
DpMasterReport dp_master_report(const dp::Master& m, std::uint64_t global_controls,
                                const std::vector<const dp::SlaveEngine*>& engines,
                                const std::vector<const DpSlavePlan*>& plans,
                                const std::string& line, bus::Baud baud);

// Text and JSON forms: pbvbus/reports/dp_report.hpp.

}  // namespace pbvbus::tools
