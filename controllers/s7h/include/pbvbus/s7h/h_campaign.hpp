#pragma once
// A seeded fault campaign over the whole H-system (docs/h-system.md; seeds-digest.md §1, §7
// F1, F5, F6, F9, F10, F14, F16, F17, §11 R1-R5; docs/h-campaign.md): the HSystemModel (CPU
// pair) driving one redundant DP master system on two lines (rack r <-> line r), two switched
// stations (PBVB0A10 at 20, PBVB0A11 at 21, the slow one) and one one-sided slave per line
// (PBVB0A01 at 40 on A, 60 on B). The program (OB 1 every scan_time) writes one 16-bit counter
// (never 0) into every output module through the I/O map.
//
// Start: power_on_both, wait for Redundant. Then, one at a time, a fault drawn with a seeded
// std::mt19937_64 and its repair; after each cycle the campaign waits (bounded by settle_limit,
// a mismatch when exceeded) for Redundant mode with every reachable channel in data exchange.
//   MasterPower / StandbyPower (F1)    power_off(M|S); repair power_on -> standby, link-up, update
//   MasterStop / StandbyStop           switch_to_stop; repair switch_to_run
//   OneFibre (F5)                      cut_fibre(f); repair repair_fibre + switch_to_run(standby)
//   BothFibres (F6)                    cut_both_fibres: two masters; repair both fibres and
//                                      switch_to_stop(X) (X random: it becomes standby), later
//                                      switch_to_run(X)
//   ActiveIm / PassiveIm (F10)         one interface of a switched station fails; repaired
//   ShortCircuit (F14)                 line l short-circuited; repaired
//   DpMasterFailure (F9)               line l's DP master module fails; repaired
//   ComparisonError (F16)              standby -> ERROR-SEARCH (self_test_time, 2 s here instead
//                                      of 90 s), re-link, automatic swap (R5); the repair is
//                                      automatic. Repeated within the first self-test cycle after
//                                      such a swap (cyclic_self_test_period, 30 s here instead of
//                                      90 min, so both branches occur): standby STOP; repair
//                                      switch_to_run.
//   OneSidedOb121 (F17)                OB 121 on rack r (random) -> ERROR-SEARCH, swap to r
//                                      after it; repeated within 7 days -> DEFECTIVE; repair
//                                      repair_cpu + switch_to_run (history cleared)
//   MasterSwap                         the operator's swap: standby switch STOP, request, the
//                                      old master STOPs at the end of the update; switch_to_run
// The link-up/update reactions (the pair runs with the manual's four H parameters, checked with
// check_h_parameters: T_P15 194 ms, T_PH 90 ms, so W = MAX(75 ms + 0.7 ms/KB, 50 ms + T_PH)):
//   MasterHold (F21/R4)                hold(master) in Redundant must be refused; then standby
//                                      STOP, hold(master) (Solo: accepted; no OB 1, the master's
//                                      DP master Clear -> outputs to the safe state 0, allowed),
//                                      switch_to_run(standby): refused (stays STOP, no event, the
//                                      entry on the master); release_hold; the refused request
//                                      is not remembered (HCpuPair), so switch_to_run again ->
//                                      link-up and update at the predicted times
//   LoadMemoryError (F2)               load_memory_error(r), r random: as a STOP of r (OB 72
//                                      MasterStop/StandbyStop on the partner); switch_to_run is
//                                      refused (reset request); repair memory_reset + RUN
//   SyncError (F18)                    inject_sync_error: standby STOP, OB 72 StandbyStop, the
//                                      "sync error (F18)" entry on both; repair switch_to_run
//   UpdateTimeout (F19/R6)             set_changed_db_kb(update_timeout_kb) (W > T_P15) and
//                                      standby STOP; RUN: each update aborts at t3 + T_P15 (OB 72
//                                      UpdateTimeout on the master, 39C3 of the standby's line),
//                                      the standby retries exactly 60 s later; n in 1..
//                                      update_timeout_failures_max updates fail, then the KB are
//                                      reset (the repair) and the retry succeeds (n = 10: no
//                                      retry left, the repair is KB + switch_to_run)
//   StandbyLostDuringLinkUp (F20/R9)   standby STOP, RUN (LINK-UP), power_off inside the
//                                      load-memory copy (half of link_up_time): no event, the
//                                      W#16#6523 entry on it; repair power_on + memory_reset + RUN
//   LoadChange (F22)                   load_change(structural FB interface | global DB, drawn)
//                                      in Redundant: both STOP, no OB 72; the standby's 39C3 is
//                                      no OB (no CPU runs a program: a diagnostic entry only);
//                                      the master (STOP, still accessing the switched I/O) keeps
//                                      its side in Clear: the outputs go to 0 - the safe state
//                                      by command, not a pulse, and no Output_Hold_Time applies
//                                      (no switchover). Repair: switch_to_run of both at once ->
//                                      master STARTUP, the standby links up at its end
//   ParameterChangeSwap (F23)          standby STOP, set_standby_parameter_change(true), swap
//                                      request: refused, W#16#5966 on both, no role change;
//                                      repair: the change undone, switch_to_run(standby)
// The kinds of the later fault paths (docs/h-campaign.md "With the new fault kinds"):
//   PsHalf (F1, PS 407 10A R)          ps_failure(r, h), r and h random: W#16#3923 on r only,
//                                      no event, no role change; repair ps_repair(r, h):
//                                      W#16#3823. Drawn half the time: the other half fails too
//                                      (as MasterPower/StandbyPower); repair: that half replaced
//                                      (power back: standby, link-up, update), then the first
//   ChecksumError (001 Table 5-6)      checksum_error(r) in Redundant, r random: r ERROR-SEARCH,
//                                      OB 72 ChecksumError on the partner (master), re-link and
//                                      automatic swap to r as F17; repeated on r within 7 days:
//                                      DEFECTIVE, repair repair_cpu + switch_to_run
//   SecondFibre (F5, 000 L2594-2597)   cut_fibre(f) (F5), later cut_fibre(1 - f): the standby's
//                                      reset request, no event; repair: both fibres, RUN refused,
//                                      memory_reset + switch_to_run
//   UpdateBlocked (SFC 90 MODE 3/4)    standby STOP, h_ctrl(3, 0), switch_to_run(standby): it
//                                      waits in LINK-UP (no update, no Redundant) until
//                                      h_ctrl(4, 0); then the normal update from that instant
// The observer allows outputs 0 on the switched stations only while no channel reaches them or
// while, in its model, no CPU runs the program (HOLD, F22); the window ends with the first new
// counter value. I/O events while no CPU runs a program are no OBs: not expected in events().
// Each injection is one step (faults + repairs; automatic recoveries are no injection).
//
// The observer is independent of HSystemModel's reconciliation: it keeps its own model of the
// master rack (from the faults it injected and the role rules: F1/STOP of the master -> the
// standby; F6 -> two masters until one is stopped; ERROR-SEARCH without fault -> the searched
// CPU; the operator swap -> the old standby), of which side's DP master runs (a timed model:
// from restart + link_up_time (+ self_test_time) on; the update formula 75 ms + 0.7 ms/KB), of
// which channels are reachable and of which line each switched station is active on (away from
// a lost line, never back). From these it derives every event the manual asks for:
//   OB 72 with its reason on the right rack and role; OB 121; W#16#39C3/38C3 for a side whose
//   DP master stops/starts again (CPU, STOP, ERROR-SEARCH, DEFECTIVE, short circuit); 73A3/72A3
//   per switched station and 39C4/38C4 per one-sided slave (F9, F10); the rack an I/O OB runs
//   on (-1 when both CPUs run the program, else the one that does),
// each with the time window it must occur in (the CPU's own reactions at the instant, the
// update start at restart + link_up_time exactly, bus detection within `recognition`, a bus
// repair within `startup`), and compares them with HSystemModel::events() as a multiset per
// step (an event belongs to the step in whose time span it lies).
// Per frame (a whole-line tap on both lines):
//   - two masters driving: the racks that are master (HCpuPair roles) AND whose DP master is in
//     Operate with its attachment powered (dp::Master::mode, RedundantMasterSystemModel) - never
//     two unless the observer's model is in the F6 split. The wire cannot tell (one program
//     writes both lines alike; in Redundant both lines carry Data_Exchange with outputs), so
//     this is read from the pair's roles and the DP masters, not from HSystemModel's SideMode;
//   - from the wire: a Data_Exchange request with outputs to a switched station on line l while
//     the observer's model says side l's DP master does not run (started after the stop);
//   - every switched station's backplane outputs: never 0 once started (except while the
//     observer says no channel is reachable), never an older counter value (mod 2^16).
// After each settled cycle: the role rules (pair master == the observer's), the stations'
// primary interface and MasterSystem::active() == the observer's active line.
//
// The IM's own switchover time (S5; 000 L1822 "DP error recognition time + DP switch-over time +
// switch-over time of DP slave interface module"; docs/h-campaign.md "With the IM's own
// switchover time"), on by default (im_time): each switched station draws its switchover time
// in [T_SLAVE_UM / 2, T_SLAVE_UM] from its GSD. The observer checks, for every switchover the
// stations record: PRIMARY no earlier than trigger + the drawn time (early), no later than the
// planner's bound (redundancy::plan_switchover) from the fault that caused it (late), the
// backplane outputs frozen from trigger + one link delay until PRIMARY (§G.1, S1; a change is a
// pulse); a cycle is settled only when the master system has seen the new PRIMARY
// (MasterSystem::active, switching_to). Output_Hold_Time 1 s >= the worst bound (828 ms).
//
// Tamper options (the observer's own tests): a fault it is not told about, a doctored event
// list, a program glitch writing 0, a forced second master outside F6 (both fibres cut while
// the observer is told one fibre), an update timeout (changed DBs set large without telling it),
// a planner told a too small T_SLAVE_UM (late switchovers).

#include <array>
#include <cstdint>
#include <functional>
#include <string>
#include <string_view>
#include <vector>

#include "pbvbus/bus/time.hpp"
#include "pbvbus/s7h/h_system.hpp"

namespace pbvbus::devices {

enum class HFault : std::uint8_t {
  MasterPower,
  StandbyPower,
  MasterStop,
  StandbyStop,
  OneFibre,
  BothFibres,
  ActiveIm,
  PassiveIm,
  ShortCircuit,
  DpMasterFailure,
  ComparisonError,
  OneSidedOb121,
  MasterSwap,
  // The link-up/update reactions (seeds-digest.md §4, §7 F2, F18-F23, §11 R6, R9):
  MasterHold,               ///< F21/R4: link-up refused while the master is in HOLD
  LoadMemoryError,          ///< F2: STOP + reset request; repair memory_reset + RUN
  SyncError,                ///< F18: standby STOP, OB 72 StandbyStop
  UpdateTimeout,            ///< F19/R6: W > T_P15 -> abort at t3 + T_P15, retry 60 s later
  StandbyLostDuringLinkUp,  ///< F20/R9: standby off in the load-memory copy -> W#16#6523
  LoadChange,               ///< F22: a structural change in Redundant -> both CPUs STOP
  ParameterChangeSwap,      ///< F23: master swap with a changed parameter -> W#16#5966
  // The later fault paths (docs/h-campaign.md "With the new fault kinds"); appended, so weights
  // 0 for these four give the 20-kind campaign's draws.
  PsHalf,         ///< F1: half of a PS 407 10A R (W#16#3923); sometimes both halves
  ChecksumError,  ///< 001 Table 5-6: checksum error in Redundant -> ERROR-SEARCH, swap
  SecondFibre,    ///< F5 second part: the other fibre later -> the standby's reset request
  UpdateBlocked,  ///< SFC 90 MODE 3: the standby waits in LINK-UP until MODE 4
};
inline constexpr int kHFaultKinds = 24;
std::string_view to_string(HFault f);

struct HCampaignTamper {
  /// At this cycle (0-based): the standby CPU is powered off and on again without telling the
  /// observer (-1: never).
  int hidden_fault_at = -1;
  /// Applied to (a copy of) HSystemModel::events() before the observer compares.
  std::function<void(std::vector<HSystemEvent>&)> doctor_events;
  /// The first scan at or after this virtual time writes 0 into every output module.
  bus::Ticks zero_output_at = bus::kNever;
  /// At this cycle: both fibres are cut while the observer is told one fibre (F5) - a second
  /// master outside its F6 model (-1: never).
  int second_master_at = -1;
  /// At this cycle (0-based): the changed DBs are set to update_timeout_kb before the drawn
  /// cycle and back after it, the observer not told: its restart's update times out (-1: never).
  int hidden_update_timeout_at = -1;
  /// >= 0: the observer's planner is given this T_SLAVE_UM for both switched stations instead
  /// of their GSDs' (the IMs still draw from the GSDs'): their switchovers exceed its bound, late.
  bus::Ticks planned_t_slave_um = -1;
};

struct HCampaignOptions {
  std::uint64_t seed = 1;
  int steps = 1000;  ///< injections (faults + repairs) to reach; the last cycle is completed
  bus::Baud baud = bus::Baud::k1_5M;
  std::string gsd_dir;  ///< where PBVB0A10/0A11/0A01.gsd are (e.g. <source>/examples/gsd)
  /// Relative weights of the fault kinds (HFault order); 0 leaves a kind out. The last four
  /// (PsHalf .. UpdateBlocked) at 0 give exactly the 20-kind campaign's draw sequence.
  std::array<int, kHFaultKinds> weights{1, 1, 1, 1, 1, 1, 1, 1, 1, 1, 1, 1,
                                       1, 1, 1, 1, 1, 1, 1, 1, 1, 1, 1, 1};
  bus::Ticks scan_time = 10 * bus::kTicksPerMs;
  bus::Ticks self_test_time = 2000 * bus::kTicksPerMs;             ///< ERROR-SEARCH (90 s default)
  bus::Ticks cyclic_self_test_period = 30 * bus::kTicksPerSecond;  ///< 90 min default
  bus::Ticks fault_min = 200 * bus::kTicksPerMs, fault_max = 1000 * bus::kTicksPerMs;
  bus::Ticks gap_min = 100 * bus::kTicksPerMs, gap_max = 500 * bus::kTicksPerMs;
  bus::Ticks recognition = 50 * bus::kTicksPerMs;       ///< window for a bus fault's events
  bus::Ticks startup = 2000 * bus::kTicksPerMs;         ///< window for a bus repair's events
  bus::Ticks settle_limit = 15 * bus::kTicksPerSecond;  ///< back to Redundant + data exchange
  /// The four H parameters of the pair (the manual's worked example, seeds-digest.md §3.1:
  /// max cycle extension 1940 ms, max communication delay 776 ms, T_P15 194 ms, T_PH 90 ms).
  /// Must pass check_h_parameters (no Error) and let the normal update (100 KB: W = 145 ms)
  /// fit in T_P15, else std::invalid_argument.
  HParameters h_parameters{ms(1940), ms(776), ms(194), ms(90)};
  /// UpdateTimeout (F19): the changed DBs of the failing updates; W(kb) must exceed the first
  /// monitored limit (T_P15). 1024 KB: W = 75 + 0.7 x 1024 = 791.8 ms > 194 ms.
  std::uint32_t update_timeout_kb = 1024;
  /// UpdateTimeout: updates that time out per cycle, drawn in 1..this (<= kUpdateMaxTries = 10;
  /// 10: the standby gives up and the repair is a manual RUN). Each failure costs 60 s + 2.2 s
  /// of virtual time (the retry delay), hence the small default.
  int update_timeout_failures_max = 2;
  /// The IM's own switchover time (seeds-digest §2 S5, 000 L1832; docs/h-campaign.md "With the
  /// IM's own switchover time"): each switched station's RedundantSlave gets its GSD's T_SLAVE_UM
  /// (Slave_Max_Switch_Over_Time: PBVB0A10 30 ms, PBVB0A11 820 ms) as im_switchover_bound and
  /// im_seed = seed x FNV prime + address; every switchover then takes a drawn time in
  /// [T_SLAVE_UM / 2, T_SLAVE_UM]. false: the link steps only (~2 ms), as before S5.
  bool im_time = true;
  /// The PrmCmd Output_Hold_Time the redundant master system sends (10 ms units). Set as a
  /// commissioning engineer would: >= the planner's worst switchover bound (recognition + T_DP_UM
  /// + T_SLAVE_UM, 828 ms for PBVB0A11: worst_bound), so the outputs are held through the slowest IM's
  /// switchover; the S7 default 1 s does. Shorter: the outputs go to 0 at its expiry (pulses).
  std::uint16_t output_hold_time = 100;
  /// Keep the step log and a copy of HSystemModel::events() in the result (tests).
  bool keep_log = false;
  HCampaignTamper tamper;
};

/// One injection (or the start-up) as the observer recorded it (HCampaignOptions::keep_log).
struct HCampaignStep {
  bus::Ticks at = 0;
  bool repair = false;
  std::string what;
  int expected = 0;  ///< events the observer expects in this step
};

struct HCampaignResult {
  std::array<int, kHFaultKinds> drawn{};  ///< cycles per kind
  int faults = 0;                         ///< fault injections
  int repairs = 0;                        ///< repair injections
  int defective = 0;                      ///< F17 cycles that made a CPU DEFECTIVE
  int comparison_stops = 0;               ///< F16 cycles that stopped the standby (repeat)
  int role_swaps = 0;                     ///< master changes the observer expected
  int update_timeouts = 0;                ///< F19 aborts the observer expected
  int refusals = 0;  ///< refused requests checked (HOLD in Redundant, RUN in HOLD/with reset
                     ///< request, F23 swap)
  int diag_checks = 0;  ///< diagnostic entries checked (6523, 5966, F18's, HOLD's refusal,
                        ///< 3923/3823, the checksum's, F5's second link, SFC 90's)
  int ps_cpu_failures = 0;     ///< PsHalf cycles in which the second half failed too (F1)
  int checksum_defective = 0;  ///< ChecksumError cycles that made a CPU DEFECTIVE (repeat)
  int update_waits = 0;        ///< UpdateBlocked cycles: LINK-UP done, waited for MODE 4
  /// Events of HSystemModel::events() by code (I/O) or OB (72, 121).
  std::array<std::pair<std::uint16_t, int>, 6> io_events{};
  int ob72 = 0, ob121 = 0;
  int ob85 = 0;  ///< OB 85 events (checked for consistency, not matched per step)
  int expected_events = 0;
  int observed_events = 0;
  std::uint64_t output_samples = 0;
  std::uint64_t pulses = 0;
  /// Samples with outputs 0 while the observer says no CPU runs the program (HOLD, F22's
  /// double STOP): the DP master's Clear, allowed (not a pulse).
  std::uint64_t cleared_samples = 0;
  std::vector<std::string> pulse_reports;  ///< the first few
  std::uint64_t dx_requests = 0;           ///< Data_Exchange requests to switched stations seen
  std::uint64_t split_frames = 0;          ///< frames while two masters drove (F6 only)
  std::uint64_t second_master_frames = 0;  ///< frames with two drivers outside F6 (must be 0)
  std::uint64_t stray_dx = 0;              ///< DX on a side that should not run (must be 0)
  /// The IMs' switchovers (RedundantSlave::im_switchovers(), HCampaignOptions::im_time): each
  /// must end (PRIMARY) no earlier than trigger + its drawn IM time (else early) and within the
  /// planner's bound from the fault that caused it (recognition + T_DP_UM + T_SLAVE_UM,
  /// redundancy::plan_switchover; else late). Both are mismatches.
  std::uint64_t im_switchovers = 0;
  int late_switchovers = 0;
  int early_switchovers = 0;
  bus::Ticks max_im_switchover = 0;  ///< longest trigger -> PRIMARY
  bus::Ticks max_im_drawn = 0;       ///< longest drawn IM time
  bus::Ticks max_fault_switchover = 0;  ///< longest fault -> PRIMARY
  bus::Ticks min_bound_margin = bus::kNever;  ///< smallest (bound - (fault -> PRIMARY))
  /// Completed IM switchovers by their cause: [0] a side's DP master stopped or its module
  /// failed (F1, STOP, F5, F9, F16/F17, the swap, ...), [1] a short circuit (F14), [2] one
  /// interface (F10).
  std::array<int, 3> im_by_cause{};
  /// The planner's largest switchover bound of a switched station (any cause): what the
  /// Output_Hold_Time must cover.
  bus::Ticks worst_bound = 0;
  /// Frames during an IM switchover (trigger + link delay .. PRIMARY): the backplane outputs
  /// must stay frozen (a change is a pulse).
  std::uint64_t frozen_samples = 0;
  std::vector<std::string> mismatches;
  bus::Ticks max_settle = 0;  ///< longest repair -> Redundant + data exchange
  bus::Ticks simulated = 0;
  double wall_seconds = 0;
  std::uint64_t frames = 0;
  std::vector<HCampaignStep> log;     ///< keep_log only
  std::vector<HSystemEvent> events;  ///< keep_log only: HSystemModel::events() at the end

  int injections() const { return faults + repairs; }
  int events_with(std::uint16_t code) const;
  std::string summary() const;
};

/// Runs the campaign. Throws std::invalid_argument for unusable options (a negative weight, all
/// weights 0, min > max, a scan time or settle limit <= 0, H parameters with a
/// check_h_parameters Error or under which the normal update exceeds T_P15, an
/// update_timeout_kb whose update fits (with UpdateTimeout drawn), update_timeout_failures_max
/// outside 1..10) and std::runtime_error when the system cannot be built (GSD missing, a baud
/// rate a station does not support).
HCampaignResult run_h_campaign(const HCampaignOptions& o);

}  // namespace pbvbus::devices
