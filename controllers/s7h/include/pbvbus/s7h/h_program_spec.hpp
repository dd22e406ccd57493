#pragma once
// What a scenario says about the user program of an H-system (docs/h-system.md): a cyclic
// OB 1 over the process image with a scan time, built from a few kinds of networks a scenario
// can combine. The scenario loader fills this struct; devices/h_program.hpp builds and runs it.
//
// Addresses are byte offsets in the CPU's process images: `input` in the process-image input
// table (PII, "IB n"), `output` in the process-image output table (PIQ, "QB n"). Which DP
// slave's module lies at which address is the owner's map (the H-system model assigns them);
// the program only sees the images. Multi-octet values are big-endian (S7 byte order).
//
// Decisions:
// - A program is a list of networks executed in order each scan: copies, then counters, then
//   discrepancy monitors (fixed order, so a copy's target can be overwritten by a counter on
//   purpose and the result is the same on both CPUs).
// - Every piece of program state (counter values, pulse phase, discrepancy timers) lives in
//   the CPU's memory area, never in the program object, so that the update can copy a CPU's
//   whole state to its partner and the comparison covers it (digest §5: RAM and output image
//   are compared).
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "pbvbus/bus/time.hpp"

namespace pbvbus::devices {

/// PII[from_input .. +length) → PIQ[to_output .. +length).
/// direct: "L PIB / T PQB" instead of the process image (docs/h-programs.md "Direct access"):
/// the same bytes (in this model the peripheral is read at the scan start, as the PII is, and
/// written at the scan end, as the PIQ is), but the owner checks every direct access: a byte of
/// a module that is not reachable reads 0 and raises OB 122 (h_system.hpp).
struct CopyNetwork {
  std::uint32_t from_input = 0;
  std::uint32_t to_output = 0;
  std::uint32_t length = 1;
  bool direct = false;
};

/// A counter in PIQ[output .. +width) (width 1, 2 or 4, big-endian, wraps), incremented by
/// `step` every `period`; optionally a pulse: bit `pulse_bit` of PIQ byte `pulse_output` is 1
/// for `pulse_high` at the start of every period, else 0 (pulse_high = 0: no pulse).
struct CounterNetwork {
  std::uint32_t output = 0;
  std::uint32_t width = 1;
  bus::Ticks period = 100 * bus::kTicksPerMs;
  std::uint32_t step = 1;
  std::uint32_t pulse_output = 0;
  std::uint8_t pulse_bit = 0;
  bus::Ticks pulse_high = 0;
};

/// Redundant inputs (two modules reading the same sensor, 001 §7.4): the bits `mask` of
/// PII[input_a .. +length) and PII[input_b .. +length) must agree; while they differ the last
/// agreed value is used, and a difference lasting longer than `discrepancy_time` raises the
/// discrepancy error (error 7960) once per pair until they agree again. The used value goes to
/// PIQ[to_output .. +length).
/// Boundary (decided in h_program.hpp): the program sees the inputs only at its scans, so the
/// difference is timed from the first scan that saw it, and 7960 is raised at the first scan at
/// which it has lasted >= discrepancy_time (then it has lasted at least that long); the episode
/// ends, with a "gone" event if 7960 was raised, at the first scan that sees all mask bits agree.
struct DiscrepancyNetwork {
  std::uint32_t input_a = 0;
  std::uint32_t input_b = 0;
  std::uint32_t length = 1;
  std::uint8_t mask = 0xFF;
  std::uint32_t to_output = 0;
  bus::Ticks discrepancy_time = 10 * bus::kTicksPerMs;
};

/// SFC 90 H_CTRL called by OB 1 (h_sfc90.hpp): at the first OB 1 at or after `at` (virtual
/// time), once. The H-system model executes it (HSystemModel::h_ctrl); RedundantExecution
/// ignores it.
struct HCtrlCall {
  bus::Ticks at = 0;
  std::uint8_t mode = 0;
  std::uint8_t submode = 0;
};

/// The DP system functions of OB 1 (h_dp_sfc.hpp has the RET_VALs, docs/h-dp-sfc.md the
/// sources). RECORD and RET_VAL are in the memory area (M): `record` is MB n, `ret_val` MW n
/// (unset: not stored).
/// SFC 14 DPRD_DAT: every OB 1 from `at` on, the consistent inputs of the module whose first
/// input byte is IB `laddr` into MB record .. +length.
struct DpReadCall {
  bus::Ticks at = 0;
  std::uint32_t laddr = 0;
  std::uint32_t record = 0;
  std::uint32_t length = 1;
  std::optional<std::uint32_t> ret_val;
};
/// SFC 15 DPWR_DAT: every OB 1 from `at` on, MB record .. +length as the consistent outputs of
/// the module whose first output byte is QB `laddr`.
struct DpWriteCall {
  bus::Ticks at = 0;
  std::uint32_t laddr = 0;
  std::uint32_t record = 0;
  std::uint32_t length = 1;
  std::optional<std::uint32_t> ret_val;
};
/// SFC 11 DPSYC_FR: once, at the first OB 1 at or after `at`: Global_Control with MODE
/// (Control_Command bits: 0x20 SYNC, 0x10 UNSYNC, 0x08 FREEZE, 0x04 UNFREEZE) to the groups
/// GROUP (bit n = group n+1) of the DP master system on `line`. A plain S7 CPU only; an H CPU
/// refuses it (001 L14095, L13670).
struct DpSyncFreezeCall {
  bus::Ticks at = 0;
  std::string line;
  std::uint8_t group = 0;
  std::uint8_t mode = 0;
  std::optional<std::uint32_t> ret_val;
};
/// SFC 12 D_ACT_DP: once, at the first OB 1 at or after `at`: MODE 0 query, 1 activate,
/// 2 deactivate the DP slave `station` of the DP master system on `line`. A plain S7 CPU
/// only; an H CPU refuses it (001 L14102).
struct DpActivateCall {
  bus::Ticks at = 0;
  std::string line;
  std::uint8_t station = 0;
  std::uint8_t mode = 0;
  std::optional<std::uint32_t> ret_val;
};
/// A configured module's place in the process images, as its owner (the H-system model's
/// I/O map, a CPU node's DP interfaces) assigned it: SFC 14/15 look LADDR up here.
struct IoModuleExtent {
  std::uint32_t in_addr = 0;
  std::uint32_t in_len = 0;
  std::uint32_t out_addr = 0;
  std::uint32_t out_len = 0;
  bool dp = true;  ///< false: a central module (expansion rack): no consistent DP data
};

struct ProgramSpec {
  bus::Ticks scan_time = 10 * bus::kTicksPerMs;  ///< OB 1 cycle (start to start)
  std::vector<CopyNetwork> copies;
  std::vector<CounterNetwork> counters;
  std::vector<DiscrepancyNetwork> monitors;
  std::vector<HCtrlCall> h_ctrl_calls;  ///< SFC 90 calls (docs/h-sfc90.md)
  std::vector<DpReadCall> dprd_dat;          ///< SFC 14 (h_dp_sfc.hpp)
  std::vector<DpWriteCall> dpwr_dat;         ///< SFC 15
  std::vector<DpSyncFreezeCall> dpsyc_fr;    ///< SFC 11: run by a plain CPU's node, not by Program
  std::vector<DpActivateCall> d_act_dp;      ///< SFC 12: likewise
  std::vector<IoModuleExtent> io_modules;    ///< filled by the owner, not by the scenario
};

}  // namespace pbvbus::devices
