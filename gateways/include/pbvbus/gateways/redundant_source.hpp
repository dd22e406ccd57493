#pragma once
// ProcessSource over a redundant DP master system (devices::RedundantMasterSystemModel: two
// masters on lines A and B joined by redundancy::MasterSystem), optionally driven by an
// H-system (devices::HSystemModel). Public APIs only; all calls on the bus thread.
//
// Decisions:
// - Side::Primary of a switched station is the line of system().active(addr) (the channel the
//   station reports PRIMARY), Side::Standby the other line. With no active channel the side
//   follows system().switching_to(addr), else line A. The line is chosen at each call, so a
//   changeover swaps the two views atomically for every request.
// - A one-sided slave has only its own line, as Primary; its Standby is nullopt/false.
// - The slave list is the union of both masters' configurations (switched stations once, with
//   line A's layout); ident and layout from the line that has the slave.
// - Writes go through system().write_outputs(addr, module, data) (both images of a switched
//   station, as the H master does).
// - With an H-system: outputs_writable = false for every slave (the CPU program owns the
//   outputs), command() refused, h_status() from h->pair() (rack r = line r).
// - mode()/counters()/master_address(): the primary master = the H master's rack if there is
//   one, else line A unless its master failed or the line is lost (then B). counters() are that
//   master's sums plus system().switchovers(). command() sets both masters' mode.

#include <string>
#include <vector>

#include "pbvbus/s7h/h_system.hpp"
#include "pbvbus/switched_io/redundant_master_system.hpp"
#include "pbvbus/gateways/dp_master_source.hpp"
#include "pbvbus/gateways/process_source.hpp"

namespace pbvbus::gateways {

class RedundantSource final : public ProcessSource {
 public:
  RedundantSource(devices::RedundantMasterSystemModel& model, std::string name,
                  std::vector<SlaveNaming> naming = {}, const devices::HSystemModel* h = nullptr);

  std::string name() const override { return m_name; }
  std::span<const SourceSlave> slaves() const override { return m_slaves; }
  bool redundant() const override { return true; }
  std::optional<SlaveStatus> status(std::uint8_t address, Side side) const override;
  bool read_inputs(std::uint8_t address, Side side, std::span<std::uint8_t> out) const override;
  bool read_outputs(std::uint8_t address, Side side, std::span<std::uint8_t> out) const override;
  bool write_module_outputs(std::uint8_t address, std::size_t module,
                            std::span<const std::uint8_t> data) override;
  dp::MasterMode mode() const override;
  bool command(dp::MasterMode m) override;
  MasterCounters counters() const override;
  std::uint8_t master_address() const override;
  std::optional<HStatus> h_status() const override;

  /// The line whose master serves `side` of `address` now; -1 if none.
  int line_of(std::uint8_t address, Side side) const;

 private:
  int primary_master_line() const;
  devices::RedundantMasterSystemModel& m_model;
  std::string m_name;
  const devices::HSystemModel* m_h;
  std::vector<SourceSlave> m_slaves;
};

}  // namespace pbvbus::gateways
