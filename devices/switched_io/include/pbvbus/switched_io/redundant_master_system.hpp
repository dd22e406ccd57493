#pragma once
// The redundant DP master system on two real lines (docs/redundancy.md "The redundant
// DP master system"): two DP masters class 1 (each a dp::Master on its own fdl::ActiveStation,
// line 0 = A, line 1 = B) joined by a redundancy::MasterSystem, as the two CPUs of an H-system
// would own them (docs/h-system.md puts CPU models on top; until then this model stands for the pair).
//
// Decisions:
// - The masters' events go to the MasterSystem first, then to the owner's handler.
// - Short circuit (F14): each master's transceiver read-back (fdl::ActiveStation::
//   medium_fault()) is looked at before every request, confirmation and token receipt of that
//   master; the first call that sees the fault tells the MasterSystem the line is lost
//   (LineLoss::ShortCircuit) BEFORE the master can report a station failure from it, so the
//   system reports one W#16#39C3 and no per-station events; the first call that sees the line
//   healthy again reports it back.
// - stop_master(): the master goes to Stop (Global_Control stops, slaves fall back by their
//   watchdog) and the system switches every station away (LineLoss::MasterStop, F14).
//   fail_master(): the master's attachment loses power (nothing more from it on the wire) and
//   the system is told LineLoss::MasterFailure (F9). The repairs undo each.
// - The program ("OB 1" of the pair): an optional cycle hook called at every token receipt of
//   either master, before that master builds its pass; it writes outputs through
//   MasterSystem::write_outputs (both lines alike) and reads inputs from the active channel.
// - Switchover supervision: MasterSystem::on_time() runs at the same calls, so its deadlines
//   are checked at least once per token rotation of either line.

#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "pbvbus/bus/line.hpp"
#include "pbvbus/dp/master.hpp"
#include "pbvbus/fdl/active_station.hpp"
#include "pbvbus/redundancy/master_system.hpp"

namespace pbvbus::devices {

struct RedundantMasterSystemOptions {
  dp::MasterParams master[2];  ///< line A's and line B's master (addresses may be equal)
  fdl::BusParams bus_params;   ///< both lines' parameters (line A's, if bus_params_b is set)
  std::optional<fdl::BusParams> bus_params_b;  ///< line B's, when they differ (e.g. TTR)
  redundancy::MasterSystemParams system;
};

class RedundantMasterSystemModel {
 public:
  using CycleHook = std::function<void(RedundantMasterSystemModel&, int line, bus::Ticks now)>;

  /// `slaves[l]` is line l's master configuration: switched stations on both (with an 8-octet
  /// SlaveParams::prm_cmd), one-sided slaves on one. Throws std::invalid_argument like
  /// dp::Master and redundancy::MasterSystem.
  RedundantMasterSystemModel(RedundantMasterSystemOptions o, std::vector<dp::SlaveParams> slaves_a,
                             std::vector<dp::SlaveParams> slaves_b,
                             std::vector<redundancy::SwitchedStationRef> switched);
  ~RedundantMasterSystemModel();
  RedundantMasterSystemModel(const RedundantMasterSystemModel&) = delete;
  RedundantMasterSystemModel& operator=(const RedundantMasterSystemModel&) = delete;

  fdl::ActiveStation& station(int line);
  const fdl::ActiveStation& station(int line) const;
  dp::Master& master(int line);
  const dp::Master& master(int line) const;
  /// Global_Control telegrams line l's master has sent.
  std::uint64_t global_controls(int line) const;
  redundancy::MasterSystem& system() { return *m_system; }
  const redundancy::MasterSystem& system() const { return *m_system; }

  /// Attaches line l's master station and remembers the attachment for fail/repair_master().
  bus::AttachmentId attach(int line, bus::Line& l, std::string label = {});

  void set_cycle_hook(CycleHook h) { m_hook = std::move(h); }
  /// Each master's events after the MasterSystem saw them.
  void set_master_event_handler(std::function<void(int line, const dp::MasterEvent&)> h) {
    m_master_events = std::move(h);
  }

  // --- faults (bus thread, at the current virtual time of the line) ---
  void stop_master(int line);
  void start_master(int line);
  void fail_master(int line);
  void repair_master(int line);
  bool master_failed(int line) const { return m_failed[line]; }

  // --- the owning CPU (devices::HSystemModel) ---
  /// The CPU that owns line l's master is powered or not. The master's attachment is powered
  /// only while its CPU is powered and the master module has not failed (fail_master), so a
  /// repair_master() of an unpowered CPU's master keeps it dark and a CPU power-on does not
  /// revive a failed module. Only the power: the owner tells the MasterSystem (line_lost with
  /// LineLoss::CpuFailure) and sets the master's mode itself. Before attach() the state is
  /// remembered and applied by attach().
  void set_cpu_power(int line, bool on);
  bool cpu_powered(int line) const { return m_cpu_on[line]; }
  /// The line's master attachment is powered (attached, CPU on, module not failed).
  bool attachment_powered(int line) const;

 private:
  class Node;
  void check_medium(int line, bus::Ticks now);
  void cycle(int line, bus::Ticks now);
  bus::Ticks now(int line) const;

  std::unique_ptr<Node> m_node[2];
  std::unique_ptr<redundancy::MasterSystem> m_system;
  bus::Line* m_line[2] = {nullptr, nullptr};
  bus::AttachmentId m_att[2] = {};
  bool m_short[2] = {false, false};
  bool m_failed[2] = {false, false};
  bool m_cpu_on[2] = {true, true};
  void apply_power(int line);
  CycleHook m_hook;
  std::function<void(int, const dp::MasterEvent&)> m_master_events;
};

}  // namespace pbvbus::devices
