#pragma once
// What the real S7-400H refuses to configure, refused by the scenario loader as FILE:LINE:COLUMN
// errors (docs/h-config-rules.md has every rule with its manual lines, the message and the
// decisions; seeds-digest §11 D4, D5, C1, C4, S10):
//  - D4: no second master (dp_master or plain FDL `master`) on a line of an H-system's
//    redundant master system (no multi-master operation in Redundant mode). Equidistance,
//    SYNC/FREEZE, slave cross traffic and SFC 12 D_ACT_DP have no field in the scenario format:
//    nothing to refuse.
//  - D5: slaves per DP master by interface (X1 MPI/DP 32; X2 DP 96 on a 414-4H, 125 on a
//    417-4H; CP 443-5 Extended 125), <= 12 DP master systems per h_system (2 integrated + 10
//    CP 443-5 per side), the lines' baud rate a DP rate (31.25 kbit/s is PA's), <= 244 input and
//    244 output octets per slave and <= 128 per slot.
//  - C1: a module consistent over its whole length: <= 32 octets per direction when all its
//    identifiers are in the general format (AKF), <= 128 with a special-format one (SKF).
//  - C4: the process-image sizes (HCpuPair input_bytes/output_bytes, default by CPU type) and
//    no module that starts inside the process image and ends outside it.
//  - S10: the masters of a redundant master system in the two central racks at the same
//    interface and slot (HMasterPlace); an interface or CP slot serves one system; X1 is either
//    the CPUs' MPI interface (HCpuPair.mpi) or a DP master.
// The rules apply to every redundant_master_system an h_system's dp_system names (simulated or
// timing-only: the entry says it is an H-system's), each system checked once.
#include <cstddef>
#include <vector>

#include "pbvbus/scenario/dp_plan.hpp"
#include "pbvbus/scenario/h_plan.hpp"
#include "scenario.pb.h"

namespace pbvbus::tools {

/// Limits of one H CPU type from the manual's technical data (001 §13.1-13.2).
struct HCpuLimits {
  const char* name;               ///< "CPU 417-4H"
  std::size_t mpi_dp_slaves;      ///< X1 in DP mode
  std::size_t dp_slaves;          ///< X2
  std::size_t process_image_max;  ///< octets per direction (the settable maximum)
  std::size_t process_image_default;
  const char* slaves_source;      ///< the manual lines of the slave limits
  const char* pi_source;          ///< the manual lines of the process-image sizes
};
const HCpuLimits& h_cpu_limits(scenario::HCpuPair::CpuType type);

/// Slaves a CP 443-5 Extended serves as DP master (000 L1724).
inline constexpr std::size_t kCp443_5Slaves = 125;
/// DP master systems per subsystem: 2 integrated + 10 external (000 L1722).
inline constexpr std::size_t kMaxHDpSystems = 12;
inline constexpr std::size_t kMaxHCpMasters = 10;
/// The H CPU's slot when HMasterPlace gives none (after a PS 407 10A in slots 1-2).
inline constexpr unsigned kDefaultHCpuSlot = 3;
/// Octets of one slot (module) per direction (001 L12006-12010).
inline constexpr std::size_t kMaxSlotOctets = 128;
/// Consistent octets of one module per direction: general (AKF) / special (SKF) identifiers.
inline constexpr std::size_t kMaxConsistentAkf = 32;
inline constexpr std::size_t kMaxConsistentSkf = 128;

/// The process-image sizes of h_system[index]'s CPUs (configured or the type's default).
struct HProcessImageSize {
  std::size_t inputs = 0;
  std::size_t outputs = 0;
};
HProcessImageSize h_process_image_size(const scenario::HCpuPair& cpu);

/// Checks the planned h_systems (after HPlanner) against the rules above; errors are appended.
void check_h_config_rules(const ScenarioPlan& plan, const DpLocator& locate, const HLocator& hlocate,
                          std::vector<Diagnostic>& errors);

}  // namespace pbvbus::tools
