#pragma once
// A seeded random fault campaign for switched I/O (docs/redundancy.md; seeds-digest.md §2, §7
// F9–F14, F24, §11 S1–S4, S8): a redundant DP master system (RedundantMasterSystemModel) on two
// lines, N switched stations (SwitchedStationModel; PBVB0A10, the second one PBVB0A11, the slow
// one) and one-sided slaves (PBVB0A01) on each line. A program writes one 16-bit counter
// (never 0: it skips 0 when it wraps) into every output module through MasterSystem::
// write_outputs at every token receipt of either master.
//
// Faults are drawn with a seeded std::mt19937_64, one at a time, each followed by its repair:
//   ActiveInterface  (F10/S1/S2) the active interface of one switched station fails
//   PassiveInterface (F10)       its passive interface fails
//   SecondInterface  (F11/S3)    one interface, then (later) the other; repaired one by one
//   CableCut         (F13)       line l cut at a random position (behind the master)
//   ShortCircuit     (F14/S4)    line l short-circuited
//   MasterStop       (F14)       line l's master RUN -> STOP (start_master repairs)
//   MasterFailure    (F9)        line l's master module fails (repair_master repairs)
//   SwitchoverLoss   (F24)       the active interface fails, and the other one 50..500 µs later
//                                (during the switchover); repaired one by one
// Every injection (fault or repair) is one "step"; CampaignResult::faults + repairs count them.
//
// The observer is independent of the stations and of MasterSystem's logic. It keeps its own
// model of which channel (station, line) is physically reachable (from the faults it injected
// and the cable positions) and of which line each switched station should be active on (line
// A at start-up; the other line when the active one becomes unreachable while the other is
// reachable; the first channel back after a total loss; no switch back), and derives the S7
// events each step must raise from the rules of master_system.hpp / seeds-digest §7:
//   a switched channel becomes unreachable, the other still reachable   -> 73A3 (that line)
//   a switched channel becomes unreachable, the other one already not   -> 39C4 (that line)
//   a one-sided slave becomes unreachable                               -> 39C4 (its line)
//   a switched channel comes back, the other reachable                  -> 72A3 (that line)
//   a switched channel comes back, the other not                        -> 38C4 (that line)
//   a one-sided slave comes back                                        -> 38C4 (its line)
//   except: short circuit / master stop on line l -> exactly one 39C3 (line l, station 0xFF),
//   nothing per station; their repair -> exactly one 38C3, nothing per station.
//   F24 (both channels lost within microseconds): one 73A3 and one 39C4 for the station, on
//   different lines, in either order (which master notices first is not a rule).
// It compares them with MasterSystem::events() as a multiset of (code, line, station): each
// expected event must come within `recognition` (faults) or `startup` (repairs) of the step,
// and no other S7 event may come before the next step. Before each fault it checks that the
// station's primary interface (SwitchedStationModel::primary()) and MasterSystem::active() are
// on the line its own model says, and that both masters have every reachable slave in data
// exchange again (dp::Master::slave_state; a system that does not recover within
// `recover_limit` is a mismatch).
// Outputs: a whole-line tap on both lines samples every switched station's backplane after
// every frame: once outputs started, never 0 (except while the observer's model says the
// station has no reachable channel, until its first non-zero value afterwards: the safe state
// after Output_Hold_Time is expected then), never an older counter value (compared modulo
// 2^16).
// Alarms (S8, options.alarms): a DP-V1 alarm (Diagnostic, slot 2, payload = a 4-octet id) on a
// random switched station 0..3 ms before a fault (probability 0.5) and at a random time of the
// gap after a repair (0.3), through SwitchedStationModel::raise_alarm. Each must be reported
// exactly once as a dp::MasterEvent::Kind::Alarm (the masters' event handler), compared by
// (station, slot, type, payload) as the Seq_Nr may change on a repeat, and on the line the
// observer expects active; 0 deliveries = lost, more = duplicated (each also a mismatch).
// Known finding (docs/benchmarks.md): an alarm read by the active line's master just before
// that channel is lost is delivered again through the new active channel.
//
// Tamper options exist for the observer's own tests (a fault it is not told about, a doctored
// event list, a program glitch writing 0): each must make it report a mismatch or a pulse.

#include <array>
#include <cstdint>
#include <functional>
#include <string>
#include <string_view>
#include <vector>

#include "pbvbus/bus/time.hpp"
#include "pbvbus/redundancy/master_system.hpp"

namespace pbvbus::devices {

enum class CampaignFault : std::uint8_t {
  ActiveInterface,
  PassiveInterface,
  SecondInterface,
  CableCut,
  ShortCircuit,
  MasterStop,
  MasterFailure,
  SwitchoverLoss,
};
inline constexpr int kCampaignFaultKinds = 8;
std::string_view to_string(CampaignFault f);

struct CampaignTamper {
  /// At the fault cycle with this index (0-based), instead of the drawn fault, fail and later
  /// repair one switched station's passive interface WITHOUT telling the observer (-1: never).
  int hidden_fault_at = -1;
  /// Applied to (a copy of) MasterSystem::events() before the observer compares.
  std::function<void(std::vector<redundancy::SystemEvent>&)> doctor_events;
  /// From this virtual time on, the program writes 0 once (one cycle) into every module.
  bus::Ticks zero_output_at = bus::kNever;
};

struct CampaignOptions {
  std::uint64_t seed = 1;
  int faults = 1000;  ///< injections (faults + repairs) to reach; the last cycle is completed
  bus::Baud baud = bus::Baud::k1_5M;
  int switched = 4;  ///< switched stations (>= 2: the second is PBVB0A11)
  int one_sided_per_line = 1;
  std::string gsd_dir;  ///< where PBVB0A10/0A11/0A01.gsd are (e.g. <source>/examples/gsd)
  bool alarms = true;   ///< raise DP-V1 alarms (when the station model supports them)
  /// Relative weights of the fault kinds (CampaignFault order).
  std::array<int, kCampaignFaultKinds> weights{3, 3, 2, 2, 2, 2, 2, 2};
  bus::Ticks fault_min = 100 * bus::kTicksPerMs, fault_max = 600 * bus::kTicksPerMs;
  bus::Ticks gap_min = 200 * bus::kTicksPerMs, gap_max = 800 * bus::kTicksPerMs;
  /// How long a station may stay without any channel (F11, F24): up to beyond the
  /// Output_Hold_Time (1 s), so the safe state (outputs 0) is reached now and then.
  bus::Ticks both_down_max = 1500 * bus::kTicksPerMs;
  bus::Ticks f24_min = 50 * bus::kTicksPerUs, f24_max = 500 * bus::kTicksPerUs;
  bus::Ticks recognition = 50 * bus::kTicksPerMs;  ///< window for a fault's events
  bus::Ticks startup = 2000 * bus::kTicksPerMs;    ///< window for a repair's events
  bus::Ticks recover_limit = 5000 * bus::kTicksPerMs;
  /// S5: the stations take their IM's own switchover time (the GSD's T_SLAVE_UM, drawn in
  /// [T/2, T] per switchover from `seed` and the address; redundant_slave.hpp). The windows
  /// above are for the S7 events (OB 70/86), which the IM's time does not delay: a switchover's
  /// end is no S7 event, and the no-pulse sampler covers the longer hold.
  bool im_time = false;
  CampaignTamper tamper;
};

struct CampaignResult {
  std::array<int, kCampaignFaultKinds> drawn{};  ///< fault cycles per kind
  int faults = 0;                      ///< fault injections (an F11/F24 cycle injects two)
  int repairs = 0;                     ///< repair injections
  std::uint64_t switchovers = 0;       ///< MasterSystem::switchovers()
  std::uint64_t station_switches = 0;  ///< primary-interface changes seen on the stations
  /// With im_time: switchovers that drew an IM time, and the longest trigger → PRIMARY. One
  /// that took longer than max(T_SLAVE_UM, the 10 ms switch timeout) is a mismatch ("late").
  std::uint64_t im_switchovers = 0;
  bus::Ticks max_im_switchover = 0;
  /// S7 events raised by the MasterSystem, by code (0x73A3, 0x72A3, 0x39C4, 0x38C4, 0x39C3,
  /// 0x38C3), and the ones the observer expected.
  std::array<std::pair<std::uint16_t, int>, 6> events{};
  int expected_events = 0;
  std::uint64_t output_samples = 0;        ///< backplane samples checked
  std::uint64_t pulses = 0;                ///< 0 outputs or older values (must be 0)
  std::uint64_t safe_state_samples = 0;    ///< 0 while the station had no channel (expected)
  std::vector<std::string> pulse_reports;  ///< the first few pulses
  // Alarms (S8)
  bool alarms_supported = false;
  int alarms_raised = 0;
  int alarms_delivered = 0;
  int alarms_lost = 0;
  int alarms_duplicated = 0;
  /// Each: virtual time, the step, expected vs observed events (or what else went wrong).
  std::vector<std::string> mismatches;
  bus::Ticks max_fault_latency = 0;   ///< latest expected event after a fault
  bus::Ticks max_repair_latency = 0;  ///< latest expected event after a repair
  bus::Ticks simulated = 0;           ///< virtual time simulated
  double wall_seconds = 0;
  std::uint64_t frames = 0;  ///< frames on both lines

  int injections() const { return faults + repairs; }
  int events_with(std::uint16_t code) const;
  std::string summary() const;
};

/// Runs the campaign. Throws std::runtime_error when the system cannot be built (GSD missing).
CampaignResult run_campaign(const CampaignOptions& o);

}  // namespace pbvbus::devices
