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

struct ProgramSpec {
  bus::Ticks scan_time = 10 * bus::kTicksPerMs;  ///< OB 1 cycle (start to start)
  std::vector<CopyNetwork> copies;
  std::vector<CounterNetwork> counters;
  std::vector<DiscrepancyNetwork> monitors;
  std::vector<HCtrlCall> h_ctrl_calls;  ///< SFC 90 calls (docs/h-sfc90.md)
};

}  // namespace pbvbus::devices
