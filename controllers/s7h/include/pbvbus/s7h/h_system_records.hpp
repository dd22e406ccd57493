#pragma once
// Data-record jobs and the system state read of the H-system model (R7; seeds-digest.md §4
// "Update steps" 1): what HSystemModel::read_record/write_record and read_system_state return.
//
// Decisions (docs/h-system.md "Data-record jobs, SFC 51"):
// - RET_VAL codes: 0 = done (or the job started, for the immediate return); W#16#80C3 = refused
//   or interrupted by the update (SFC 13, 55..59); W#16#8085 = SFC 51 during the update;
//   W#16#8090 = no such master system/station or no active channel (the SFC's "invalid logical
//   address"); W#16#80A0 / W#16#80A1 = negative response to a read / write from the station.
// - HSystemState is the H-system part of SSL W#16#xy71 reduced to what the model knows: the
//   master's rack, each CPU's operating state and role, the system mode.
#include <array>
#include <cstdint>
#include <functional>

#include "pbvbus/s7h/h_cpu_pair.hpp"
#include "pbvbus/dp/master_acyclic.hpp"

namespace pbvbus::devices {

inline constexpr std::uint16_t kRetUpdateBusy = 0x80C3;     ///< W#16#80C3
inline constexpr std::uint16_t kRetSfc51Update = 0x8085;    ///< W#16#8085
inline constexpr std::uint16_t kRetNoAddress = 0x8090;      ///< W#16#8090
inline constexpr std::uint16_t kRetReadNegative = 0x80A0;   ///< W#16#80A0
inline constexpr std::uint16_t kRetWriteNegative = 0x80A1;  ///< W#16#80A1

/// The final result of a data-record job (SFC 59 RDREC / SFC 58 WRREC).
struct RecordJobResult {
  std::uint16_t ret_val = 0;   ///< 0 or one of the codes above
  bus::Ticks completed = 0;    ///< when the program gets it (after t5 if it fell in the update)
  dp::AcyclicResult result;    ///< the master system's result (empty when refused at once)
};
using RecordJobCallback = std::function<void(const RecordJobResult&)>;

/// SFC 51 (RDSYSST) for the H-system state (SSL W#16#xy71), as far as the model knows it.
struct HSystemState {
  std::uint16_t ret_val = 0;  ///< 0, or W#16#8085 during the update (the fields are then empty)
  int master_rack = -1;
  std::array<CpuState, 2> state{CpuState::Off, CpuState::Off};
  std::array<CpuRole, 2> role{CpuRole::None, CpuRole::None};
  SystemMode mode = SystemMode::Stop;
};

}  // namespace pbvbus::devices
