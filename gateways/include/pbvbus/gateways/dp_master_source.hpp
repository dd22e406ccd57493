#pragma once
// ProcessSource over one plain dp::Master (docs/gateway-modbus.md): what the Modbus and CAN gateways see of a
// single master system. Public dp::Master API only; all calls on the bus thread.
//
// Decisions:
// - The slave list, module layout (master.image(addr).module(m)) and ident (slave_params) are
//   read once at construction: the master's configuration is fixed for its lifetime.
// - Names come from the SlaveNaming list (the scenario's GSD model and module names); a slave
//   without an entry gets its SlaveParams::name and modules "module N".
// - A plain master system has only Side::Primary: Standby answers nullopt/false.
// - counters(): sums of the slaves' MasterSlaveStats (failures, returns, diag_reads, alarms);
//   switchovers 0.
// - command(): Offline refused (the door is not the master's power switch); Stop/Clear/Operate
//   → Master::set_mode.

#include <string>
#include <vector>

#include "pbvbus/dp/master.hpp"
#include "pbvbus/gateways/process_source.hpp"

namespace pbvbus::gateways {

/// GSD names for one slave of the source (from the scenario).
struct SlaveNaming {
  std::uint8_t address = 0;
  std::string model;                 ///< GSD Model_Name
  std::vector<std::string> modules;  ///< in slot order; missing entries: "module N"
};

/// Builds a SourceSlave from a master's configuration of `address` (helper shared by the
/// adapters). `naming` may be null.
SourceSlave make_source_slave(const dp::Master& master, std::uint8_t address,
                              const SlaveNaming* naming);
/// The SlaveNaming entry for `address` in `list`, or nullptr.
const SlaveNaming* find_naming(const std::vector<SlaveNaming>& list, std::uint8_t address);
/// SlaveStatus of `address` as `master` sees it (side_line/active_channel left to the caller).
SlaveStatus master_slave_status(const dp::Master& master, std::uint8_t address);
/// Whole input/output telegram of `address` from `master`'s image (false: wrong size).
bool master_read_inputs(const dp::Master& master, std::uint8_t address,
                        std::span<std::uint8_t> out);
bool master_read_outputs(const dp::Master& master, std::uint8_t address,
                         std::span<std::uint8_t> out);
/// The sums over `master`'s slaves.
MasterCounters master_counters(const dp::Master& master);

class DpMasterSource final : public ProcessSource {
 public:
  DpMasterSource(dp::Master& master, std::string name, std::vector<SlaveNaming> naming = {});

  std::string name() const override { return m_name; }
  std::span<const SourceSlave> slaves() const override { return m_slaves; }
  bool redundant() const override { return false; }
  std::optional<SlaveStatus> status(std::uint8_t address, Side side) const override;
  bool read_inputs(std::uint8_t address, Side side, std::span<std::uint8_t> out) const override;
  bool read_outputs(std::uint8_t address, Side side, std::span<std::uint8_t> out) const override;
  bool write_module_outputs(std::uint8_t address, std::size_t module,
                            std::span<const std::uint8_t> data) override;
  dp::MasterMode mode() const override { return m_master.mode(); }
  bool command(dp::MasterMode m) override;
  MasterCounters counters() const override { return master_counters(m_master); }
  std::uint8_t master_address() const override { return m_master.address(); }

 private:
  bool known(std::uint8_t address, Side side) const;
  dp::Master& m_master;
  std::string m_name;
  std::vector<SourceSlave> m_slaves;
};

}  // namespace pbvbus::gateways
