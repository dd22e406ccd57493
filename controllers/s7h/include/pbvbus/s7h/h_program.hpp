#pragma once
// The user program of an H-CPU (docs/h-system.md; seeds-digest.md §1, §5, §6 error 7960):
// a cyclic OB 1 over the process image, built from a devices::ProgramSpec (the scenario
// loader's contract, h_program_spec.hpp). docs/h-programs.md has the networks, the memory
// layout and every decision; RedundantExecution (h_redundant_execution.hpp) runs one program on
// both CPUs of the pair and compares them.
//
// Sans-I/O: no bus, no threads, no clock. The owner calls scan(image, now) at each OB 1 start
// with the virtual time; everything time-dependent is computed from `now` and the state in the
// image's memory area, never from the number of scans.
//
// Decisions:
// - A Program object is immutable (scan() is const): ALL state lives in the CPU's memory area
//   (h_program_spec.hpp), so copying a CPU's image copies its program state and the RAM
//   comparison covers it.
// - Order in one scan: every copy network, then every counter, then every discrepancy monitor,
//   each in spec order.
// - Counter epoch: a counter starts at its first scan (memory all zero = not started): value 0
//   and a period starting at that instant. Period boundaries are epoch + k·period exactly; a
//   scan at `now` adds step once for every boundary in (last boundary, now], so the value does
//   not depend on how often OB 1 runs and never drifts. The value is kept as 32 bits in memory
//   and written as its low `width` octets, big-endian (it wraps at 2^(8·width)). The pulse bit
//   is 1 exactly while now ∈ [epoch + k·period, epoch + k·period + pulse_high).
// - Discrepancy (error 7960): the monitor compares the `mask` bits of both inputs at each scan.
//   An episode starts at the first scan that sees a difference (time `since`); error 7960 is
//   raised ONCE per episode at the first scan with now − since ≥ discrepancy_time (≥: like a
//   TON timer, the time has expired when it has fully run; and since the difference is first
//   seen at `since`, it has then lasted AT LEAST discrepancy_time). The episode ends at the
//   first scan with all mask bits equal; if 7960 was raised, a "gone" event (incoming = false)
//   follows at that scan; an episode that ended before expiring raises nothing. Per bit: an
//   agreeing mask bit takes input A's value (and is remembered as the last agreed value); a
//   differing one keeps the last agreed value (0 before any agreement). Bits outside the mask
//   come from input A.
// - Negative `now` or an image not made for this program (sizes differ): scan() does nothing
//   and returns false (no crash on bad input).
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "pbvbus/bus/time.hpp"
#include "pbvbus/s7h/h_process_image.hpp"
#include "pbvbus/s7h/h_program_spec.hpp"

namespace pbvbus::devices {

/// Error 7960: redundant DI discrepancy time expired (digest §6 codes table).
inline constexpr std::uint16_t kDiscrepancyError = 0x7960;

/// An event raised by the program (today only the discrepancy monitor's error 7960).
struct ProgramEvent {
  bus::Ticks time = 0;
  std::uint16_t code = kDiscrepancyError;
  bool incoming = true;       ///< true: raised; false: "gone" (the inputs agree again)
  std::uint32_t network = 0;  ///< index in ProgramSpec::monitors
  std::uint32_t input_a = 0;  ///< IB address of input A
  std::uint32_t input_b = 0;  ///< IB address of input B
  std::uint32_t length = 0;   ///< octets compared
  int rack = -1;  ///< the CPU whose run reported it (set by RedundantExecution; -1 from Program)
  friend bool operator==(const ProgramEvent&, const ProgramEvent&) = default;
};

/// Every problem of `spec` for a PII of `pii_bytes` and a PIQ of `piq_bytes`, one message each,
/// naming the network ("copy 2", "counter 0", "monitor 1") and the address (IB n / QB n).
/// Empty = valid. Checks: image sizes, scan_time > 0; copy length ≥ 1 and both ranges inside;
/// counter width 1/2/4, period > 0, value and pulse byte inside the PIQ, pulse_bit ≤ 7,
/// 0 ≤ pulse_high ≤ period, the pulse byte not inside the counter's own value; monitor
/// length ≥ 1, mask ≠ 0, discrepancy_time ≥ 0, both inputs and the output inside, input A and
/// B ranges not overlapping; outputs of two networks of the same kind not overlapping (two
/// copies, two monitors, two counters' values, a counter value over another counter's pulse
/// byte, or the same pulse bit twice). Outputs of networks of DIFFERENT kinds may overlap on
/// purpose (the later kind wins, h_program_spec.hpp).
std::vector<std::string> validate(const ProgramSpec& spec, std::size_t pii_bytes,
                                  std::size_t piq_bytes);

class Program {
 public:
  /// Memory layout (big-endian, like S7 data): per counter kCounterStateBytes
  ///   [0..8) next period boundary (ticks)  [8..12) value  [12] flags (bit 0: started)
  /// then per monitor kMonitorStateHeaderBytes + length
  ///   [0..8) time the difference was first seen  [8] flags (bit 0: differing, bit 1: 7960
  ///   raised)  [16..16+length) last agreed value of the mask bits.
  static constexpr std::size_t kCounterStateBytes = 16;
  static constexpr std::size_t kMonitorStateHeaderBytes = 16;

  /// Throws std::invalid_argument with the first validate() message.
  Program(ProgramSpec spec, std::size_t pii_bytes, std::size_t piq_bytes);

  const ProgramSpec& spec() const { return spec_; }
  bus::Ticks scan_time() const { return spec_.scan_time; }
  std::size_t pii_size() const { return pii_bytes_; }
  std::size_t piq_size() const { return piq_bytes_; }
  std::size_t memory_size() const { return memory_bytes_; }
  std::size_t counter_state_offset(std::size_t counter) const;
  std::size_t monitor_state_offset(std::size_t monitor) const;

  /// A zeroed image of the right sizes (the state of a CPU whose program has not run yet).
  ProcessImage make_image() const;
  /// The image has this program's PII and PIQ sizes and at least its memory (the rest of the
  /// memory area belongs to the CPU's S7 memory, h_s7_memory.hpp).
  bool fits(const ProcessImage& image) const;

  /// Executes one OB 1 at virtual time `now`: copies, counters, monitors. Appends the events
  /// raised to `events`. Returns false (and changes nothing) if now < 0 or !fits(image).
  bool scan(ProcessImage& image, bus::Ticks now, std::vector<ProgramEvent>& events) const;
  /// Same, returning the events (convenience for tests and one-off callers).
  std::vector<ProgramEvent> scan(ProcessImage& image, bus::Ticks now) const;

  /// The owner's module map for SFC 14/15 (ProgramSpec::io_modules): configuration, not state;
  /// set before the scans (a plain CPU's node knows its DP interfaces' modules only then).
  void set_io_modules(std::vector<IoModuleExtent> modules);

 private:
  ProgramSpec spec_;
  std::size_t pii_bytes_;
  std::size_t piq_bytes_;
  std::size_t memory_bytes_ = 0;
  std::vector<std::size_t> monitor_offsets_;
};

}  // namespace pbvbus::devices
