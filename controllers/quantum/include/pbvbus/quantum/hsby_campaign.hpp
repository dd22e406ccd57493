#pragma once
// A seeded random fault campaign over the Quantum Hot Standby pair on a real DP line
// (seeds-digest.md §8, §11 Q5-Q7; docs/quantum-hsby-campaign.md). The system is HsbyDpLine
// (hsby_dp_line.hpp): one line, both racks' DP master modules at address 1, N DP slaves
// (watchdog on), the 12K transfer plan, the counter logic (4x counter_register, never 0, into
// every slave's output word), and the Modbus view of port 1 (address 1 on both racks, swap on:
// the primary answers at 1, the standby at 129) through one HsbyModbusPort.
//
// Start: power on rack 0 then rack 1; wait for Primary + Standby with every slave in data
// exchange and the standby's module shadowing each of them. Then, one at a time, a fault drawn
// with campaign::Draw (weights per kind) and its repair, each one injection:
//   PrimaryPower     power_off(primary)           -> takeover; repair power_on: it becomes standby
//   PrimaryCpuStop   stop_cpu(primary)            -> takeover; repair start_cpu: standby
//   StandbyPower     power_off(standby)           -> the primary runs alone; repair power_on
//   KeyOffLine       set_key(primary, Off Line)   -> planned handover at its next scan boundary,
//                                                    the old primary Offline; repair key Run:
//                                                    it rejoins as standby
//   KeyXfer          set_key(primary, Xfer)       -> ignored (Q7): no switchover; repair key Run
//   Override         command register: override on with both run bits 1, then both 0 -> the
//                    switchover at the next scan boundary but one, the old primary Offline, the
//                    new one continues (seed p. 90); repair: both run bits 1 (the old primary
//                    rejoins at the next scan start), then (after the settle) override off
//   FibreCut         set_fibre(Cut)               -> the standby finds no transfer while its
//                                                    module still hears the primary's: Offline
//                                                    (CHS link failure); repair set_fibre(Ok):
//                                                    it rejoins as standby by itself (the pair
//                                                    joins an Offline unit that wants to run)
//   LogicMismatch    load_program(standby, other checksum) -> the standby goes Offline (default);
//                    repair: program update (update button, key Xfer, key Run, release): after
//                    update_time it has the primary's program and state RAM and is standby again
//   StandbyUpdate    a program update of the healthy standby: fault = button + key Xfer (the
//                    standby leaves: Offline), repair = key Run + release (update_time later:
//                    standby again)
// After each repair the campaign waits a drawn gap, then (bounded by settle_limit, a mismatch
// when exceeded) for the settled system above before the next fault.
//
// The observer is independent of the pair's reconciliation:
//  (a) the slave side: after every Data_Exchange a slave accepts (SlaveProbe) its output word
//      must never be 0 once the counter started (a pulse), never older than one scan (>= the
//      newest value that slave held - 1, modulo 2^16: a transfer lost at the failure repeats at
//      most one value), and the slave never leaves data exchange (watchdog expiries and data
//      exchange entries counted from the slave engine);
//  (b) a Modbus host polls unit 1 every poll_period: HsbyModbusPort::rack_for(1) -> that rack's
//      4x counter register; the value must be >= the newest counter value any primary has
//      computed - 1 (the logic hook records it). A poll nobody answers (the window between a
//      primary failure and the takeover) is counted as "no answer", not an error; a rack that
//      answers unit 1 and is not the primary is an error;
//  (c) every SwitchoverRecord: takeover_ticks <= scan_time (Q7), and the switchovers match the
//      observer's expectation (one per PrimaryPower / PrimaryCpuStop / KeyOffLine / Override,
//      to the old standby, none otherwise; the roles after each fault and after each settle).
//
// Tamper options (the observer's own tests): a logic that writes 0 into the outputs once, and
// a stale standby at a primary failure (its counter set back before the takeover).

#include <array>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "pbvbus/bus/scheduler.hpp"
#include "pbvbus/bus/time.hpp"

namespace pbvbus::quantum {

enum class HsbyFault : std::uint8_t {
  PrimaryPower,
  PrimaryCpuStop,
  StandbyPower,
  KeyOffLine,
  KeyXfer,
  Override,
  FibreCut,
  LogicMismatch,
  StandbyUpdate,
};
inline constexpr int kHsbyFaultKinds = 9;
std::string_view to_string(HsbyFault f);

struct HsbyCampaignTamper {
  /// The first scan at or after this time writes 0 into every output word (once).
  bus::Ticks zero_output_at = bus::kNever;
  /// At this cycle (0-based) the fault is PrimaryPower, and right after it the standby's
  /// counter register is set back by 5 (what a stale transfer would leave): -1 never.
  int stale_takeover_at = -1;
};

struct HsbyCampaignOptions {
  std::uint64_t seed = 1;
  int steps = 1000;  ///< injections (faults + repairs) to reach; the last cycle is completed
  bus::Baud baud = bus::Baud::k1_5M;
  int slaves = 3;
  bus::Ticks scan_time = 20 * bus::kTicksPerMs;
  std::uint8_t watchdog_factor = 10;  ///< slave watchdog 10 ms x this
  bus::Ticks update_time = 100 * bus::kTicksPerMs;
  /// Relative weights of the fault kinds (HsbyFault order); 0 leaves a kind out.
  std::array<int, kHsbyFaultKinds> weights{1, 1, 1, 1, 1, 1, 1, 1, 1};
  bus::Ticks fault_min = 100 * bus::kTicksPerMs, fault_max = 400 * bus::kTicksPerMs;
  bus::Ticks gap_min = 20 * bus::kTicksPerMs, gap_max = 200 * bus::kTicksPerMs;
  bus::Ticks settle_limit = 2 * bus::kTicksPerSecond;
  bus::Ticks poll_period = 3 * bus::kTicksPerMs + 170 * bus::kTicksPerUs;
  bool keep_log = false;  ///< keep the step log in the result
  HsbyCampaignTamper tamper;
};

/// min / median / p99 / max of the takeover times (ms and scans); all 0 when count is 0.
struct TakeoverDistribution {
  int count = 0;
  double min_ms = 0, median_ms = 0, p99_ms = 0, max_ms = 0;
  double min_scans = 0, median_scans = 0, p99_scans = 0, max_scans = 0;
};

struct HsbyCampaignResult {
  std::array<int, kHsbyFaultKinds> drawn{};  ///< cycles per kind
  int faults = 0;
  int repairs = 0;
  int switchovers = 0;           ///< SwitchoverRecords
  int expected_switchovers = 0;  ///< the observer's
  int late_switchovers = 0;      ///< takeover_ticks > scan_time (must be 0)
  std::vector<bus::Ticks> takeover_ticks;  ///< every switchover's, in order
  TakeoverDistribution takeover_all;        ///< every switchover
  TakeoverDistribution takeover_unplanned;  ///< PrimaryPower / PrimaryCpuStop
  std::uint64_t slave_samples = 0;
  std::uint64_t pulses = 0;        ///< a slave's outputs 0 once started (must be 0)
  std::uint64_t stale_outputs = 0; ///< older than one scan (must be 0)
  std::uint64_t dx_exits = 0;      ///< watchdog expiries + data exchange entries after the first
  std::uint64_t modbus_polls = 0;
  std::uint64_t modbus_answers = 0;
  std::uint64_t modbus_no_answer = 0;  ///< nobody at unit 1 (the takeover window)
  std::uint64_t stale_reads = 0;       ///< older than one scan (must be 0)
  std::uint64_t wrong_rack = 0;        ///< a non-primary answered unit 1 (must be 0)
  bus::Ticks longest_no_answer = 0;    ///< the longest run of unanswered polls
  std::vector<std::string> reports;    ///< the first few pulses / stale values / late switchovers
  std::vector<std::string> mismatches; ///< role or switchover expectations not met
  std::vector<std::string> log;        ///< keep_log only: the injections
  std::vector<std::string> pair_log;   ///< keep_log only: HsbyPair::events() as text
  bus::Ticks simulated = 0;
  double wall_seconds = 0;

  int injections() const { return faults + repairs; }
  /// True when the observer found nothing (0 pulses, stale values, late switchovers, exits,
  /// wrong racks, mismatches).
  bool clean() const;
  std::string summary() const;
};

/// Runs the campaign. Throws std::invalid_argument for unusable options (a negative weight, all
/// weights 0, min > max, a scan time, settle limit or poll period <= 0, fewer than 1 slave).
HsbyCampaignResult run_hsby_campaign(const HsbyCampaignOptions& o);

/// The distribution of `ticks` against `scan_time`: nearest-rank percentiles.
TakeoverDistribution takeover_distribution(std::vector<bus::Ticks> ticks, bus::Ticks scan_time);

}  // namespace pbvbus::quantum
