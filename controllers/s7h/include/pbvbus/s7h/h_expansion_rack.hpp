#pragma once
// Expansion racks of the H-system's central racks (F8, docs/h-system.md; seeds-digest.md §1/§2 "one-sided
// I/O", §6 OB table, §7 F8 "IM 460/461: expansion rack off; OB 86 on both"): an expansion rack
// hangs on one CPU's central rack through IM 460 (send, in the CPU rack) -> IM 461 (receive, in
// the expansion rack). Its modules are one-sided central I/O of that CPU. HSystemModel owns the
// racks (h_system.hpp, block "F8 expansion racks, OB 80"); docs/h-system.md "Expansion racks
// (F8) and OB 80" has the decisions and their reasons.
//
// Decisions:
// - Rack numbers 1..21 (an S7-400 system has at most 21 expansion racks), unique over both
//   sides; side 0/1 = the central rack (= CPU) the rack hangs on. At least one module; a module
//   has a name, in_len/out_len octets (not both 0, each <= 244: an S7-400 module's PII/PIQ
//   share is far below that) and an IoBehaviour for its inputs (ignored without inputs).
// - Event IDs: not in the seeds (they name OB 80/85/86 only); from Siemens "System Software for
//   S7-300/400 System and Standard Functions" (A5E00709327-01, OB 86 and OB 80 start
//   information, found with `search`): OB 86 W#16#39C1 = expansion rack failure (incoming),
//   W#16#38C1 = expansion rack operational again; OB 80 event class B#16#35, fault ID B#16#01 =
//   cycle time exceeded (W#16#3501).
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "pbvbus/slaves/io_behaviour.hpp"

namespace pbvbus::devices {

inline constexpr std::uint16_t kOb86RackFailure = 0x39C1;  ///< W#16#39C1 (S7 system software manual)
inline constexpr std::uint16_t kOb86RackReturn = 0x38C1;   ///< W#16#38C1 (S7 system software manual)
inline constexpr std::uint16_t kOb80CycleTime = 0x3501;    ///< W#16#3501 (S7 system software manual)
inline constexpr int kMaxExpansionRack = 21;
inline constexpr std::size_t kMaxRackModuleOctets = 244;

/// One module of an expansion rack (central I/O).
struct HRackModule {
  std::string name;
  std::size_t in_len = 0;   ///< input octets (PII)
  std::size_t out_len = 0;  ///< output octets (PIQ)
  /// What the inputs show (Constant, Counter: n = the rack's reads so far, Ramp, Table, Echo of
  /// this rack's module `source_module`, default this module's outputs).
  IoBehaviour inputs;
  /// Outputs in a process-image partition 1..15 (docs/h-sfc90.md "OB 72 and SFC 27"): not
  /// written after OB 1, only by SFC 27 UPDAT_PO of that partition; 0 = the OB 1 image.
  int partition = 0;
};

/// An expansion rack on one side of the H-system (IM 460 in CPU `side`'s central rack).
struct HExpansionRack {
  int number = 1;  ///< 1..21, unique
  int side = 0;    ///< 0/1: the central rack (CPU) it hangs on
  std::vector<HRackModule> modules;
};

/// Every problem of a rack configuration ("expansion rack 9: module 2 \"AI8\": no inputs and no
/// outputs"); empty = valid. HSystemModel throws std::invalid_argument with the first one.
std::vector<std::string> check_expansion_racks(const std::vector<HExpansionRack>& racks);

}  // namespace pbvbus::devices
