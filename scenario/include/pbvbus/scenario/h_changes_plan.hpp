#pragma once
// The scenario fields for what the H model can do about changes in operation, power and
// interrupts (docs/h-scenario-changes.md): the RAM test (HCpu.battery, ram_mb), T8's link-up
// time from the memory size (HCpuPair.load_memory_mb, work_memory_mb, link_up_base_time), the
// 5.2.3 attributes of the DBs (S7DataBlock.sfb_instances, read_only, unlinked), watchdog OBs
// (HProgram.watchdog_ob), OB 72 calling SFC 27 (HProgram.ob72_updat_po; HRackModule.partition)
// and the fault switch_to_cpu (its variant, the CPUs' memories, added modules, changed DBs).
#include <cstdint>
#include <optional>
#include <vector>

#include "pbvbus/bus/time.hpp"
#include "pbvbus/s7h/h_config_change.hpp"
#include "pbvbus/s7h/h_rack_power.hpp"

namespace pbvbus::tools {

/// A watchdog interrupt OB of the program: requests at phase + n x cycle (n >= 1) from the start
/// of the run; each execution adds 1 to the big-endian counter DB `db`.[offset, +width) (db 0:
/// the OB runs nothing).
struct HWatchdogPlan {
  int ob = 35;
  bus::Ticks cycle = 100 * bus::kTicksPerMs;
  bus::Ticks phase = 0;
  std::uint16_t db = 0;
  std::size_t offset = 0;
  std::size_t width = 2;
};

/// The fields of h_changes_plan.cpp for HRuntimePlan::changes.
struct HChangesPlan {
  /// HCpu.battery / ram_mb: set when a CPU has ram_mb > 0 or battery false
  /// (HSystemModel::set_rack_power before the first power-on).
  std::optional<devices::HRackPowerParams> rack_power;
  /// The DBs of cpu.s7_memory with their 5.2.3 attributes (interface stamp 1; a switch_to_cpu's
  /// changed_db get stamp 2 on the standby).
  std::vector<devices::HDbBlock> db_blocks;
  std::vector<HWatchdogPlan> watchdogs;
  std::vector<int> ob72_updat_po;  ///< partitions OB 72 refreshes with SFC 27
};

/// The fault switch_to_cpu as planned (PlanFault::cpu_switch).
struct HSwitchPlan {
  devices::HSwitchVariant variant = devices::HSwitchVariant::ModifiedConfiguration;
  devices::HCpuConfig master, standby;
  struct Module {
    int system = -1;  ///< position in HRuntimePlan::systems (the model's system index)
    std::uint8_t station = 0;
    std::size_t module = 0;
  };
  std::vector<Module> added;
  std::vector<int> changed_db;
};

}  // namespace pbvbus::tools
