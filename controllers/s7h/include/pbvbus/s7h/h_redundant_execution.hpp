#pragma once
// Redundant execution of the user program on both CPUs of an H-system (docs/h-system.md;
// seeds-digest.md §1 sync points, §5 identical values and the RAM/output-image comparison,
// §7 F16/F18, §11 C3). The pair's view: rack 0 and rack 1, each with its own ProcessImage,
// running the same Program. docs/h-programs.md has the decisions.
//
// Sans-I/O: no bus, no threads, no clock. The owner (the H-system model) drives it:
//   at each sync point with inputs: set_inputs(bytes read from the I/O)   (both PIIs)
//   at each OB 1 start:             scan(now, running, master)            (≥ next_scan(now))
//   at the update's output copy:    copy_state(master, standby)
// and sends the PIQ of ScanResult::output_rack to the I/O. The owner does not start a scan
// while I/O is frozen (during the update's I/O freeze, digest §4): that check is the owner's.
//
// Decisions:
// - One sync point per scan: the inputs the owner passes to set_inputs() go into BOTH PIIs (the
//   sync link carries the master's reading to the standby, digest §5), so two running CPUs
//   always start OB 1 on identical PIIs.
// - The comparison (digest §5: RAM and output image) runs after every scan in which both CPUs
//   ran; it covers the PIQ, then the memory area, each from offset 0, and reports the first
//   differing byte. PII is not compared: it is overwritten from the same bytes at every sync
//   point, and an injected PII difference shows up through what the program makes of it.
//   A difference is reported at every compared scan until copy_state() makes the images equal
//   again (the owner's reaction, F16: the standby goes to ERROR-SEARCH or STOP and stops
//   running, so the comparison stops).
// - Events: both CPUs run the same program on the same data, so each event is reported once:
//   the master's (rack = master) when the master ran, else the running CPU's (rack 0 first).
// - F18 (diverging uninitialised data → sync error) is modelled cheaply: if the two runs raised
//   different program events, the CPUs took different paths through the program and would have
//   asked for different sync points, which the pair sees as a sync error (ScanResult::
//   sync_error); the owner's reaction is Solo with one CPU in STOP. To provoke it, inject a
//   divergence into a monitor's state (e.g. its timer) on one CPU. No model of real
//   uninitialised local data: the programs here have none.
// - next_scan(now): OB 1 runs start to start every scan_time: the last scan's start +
//   scan_time, but never before `now` (a scan that is late, e.g. after an I/O freeze, starts at
//   once and the cycle continues from there); before the first scan: `now`.
// - The output rack: the master's PIQ is the one sent, when the master ran; nullopt when it did
//   not (no output from this scan). Two masters (F6: both fibres cut) are no longer redundant:
//   the owner then calls scan() once per CPU with only that CPU running and itself as master
//   (no comparison, each sends its own PIQ).
#include <array>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>
#include <vector>

#include "pbvbus/bus/time.hpp"
#include "pbvbus/s7h/h_process_image.hpp"
#include "pbvbus/s7h/h_program.hpp"

namespace pbvbus::devices {

struct ScanResult {
  std::array<bool, 2> ran = {false, false};  ///< OB 1 executed on rack 0 / rack 1
  bool compared = false;                     ///< both ran, so PIQ and memory were compared
  /// The comparison error (F16): where the two CPUs first differ (PIQ before memory).
  std::optional<ImageDifference> comparison_error;
  bool sync_error = false;  ///< F18: the two runs raised different program events
  std::optional<int> output_rack;  ///< whose PIQ goes to the I/O (the master's, if it ran)
  std::vector<ProgramEvent> events;  ///< raised by this scan, reported once (see above)
};

class RedundantExecution {
 public:
  /// Throws std::invalid_argument with the first validate() message. `memory_bytes`: the
  /// memory area of each image is max(the program's memory_size(), memory_bytes) — the CPU's
  /// S7 memory (flags and DBs, h_s7_memory.hpp) lives there too, so the comparison and the
  /// update's copy cover it.
  RedundantExecution(const ProgramSpec& spec, std::size_t pii_bytes, std::size_t piq_bytes,
                     std::size_t memory_bytes = 0);

  const Program& program() const { return program_; }

  /// The inputs read at the sync point; the SAME bytes go into both CPUs' PII. Returns false
  /// (and changes nothing) unless the size is exactly the PII size.
  bool set_inputs(std::span<const std::uint8_t> pii_from_io);

  /// OB 1 on every running CPU at `now`; then, if both ran, the comparison. `master` is the
  /// master rack (0 or 1; anything else: no output rack). A negative `now` runs nothing.
  ScanResult scan(bus::Ticks now, std::array<bool, 2> running, int master);

  /// The update: PII, PIQ and memory of `from` copied to `to`. False for a bad rack.
  bool copy_state(int from, int to);

  /// Flips the bits `xor_mask` of one byte on one CPU only (a test or scenario fault). False
  /// (nothing changed) for a bad rack or an offset outside the area.
  bool inject_divergence(int rack, Area area, std::uint32_t offset, std::uint8_t xor_mask);

  /// Throws std::out_of_range for a rack other than 0 or 1.
  const ProcessImage& image(int rack) const;
  /// The same, writable: the CPU's S7 server reads and writes it (h_s7_session.hpp).
  ProcessImage& image(int rack);
  /// OB 1 runs on that rack (0 for a bad rack).
  std::uint64_t scans(int rack) const;
  /// Every event reported so far, in order.
  const std::vector<ProgramEvent>& events() const { return events_; }

  bus::Ticks scan_time() const { return program_.scan_time(); }
  /// Start of the next OB 1 (start to start, never before `now`).
  bus::Ticks next_scan(bus::Ticks now) const;

 private:
  static bool valid_rack(int r) { return r == 0 || r == 1; }

  Program program_;
  std::array<ProcessImage, 2> images_;
  std::array<std::uint64_t, 2> scans_ = {0, 0};
  std::optional<bus::Ticks> last_start_;
  std::vector<ProgramEvent> events_;
  std::array<std::vector<ProgramEvent>, 2> run_events_;  // per-scan scratch, kept for capacity
};

}  // namespace pbvbus::devices
