#pragma once
// H-system update planner and H-parameter checks (docs/h-system.md; seeds-digest.md
// §3.1, §10 item 6, §11 T1–T8). A pure library: no I/O, no clock, no exceptions for bad values.
// docs/h-timing.md has every term, the procedure, the decisions and the worked example.
//
// Units: every time is an exact integer count of microseconds (`Us`); `to_ticks()` converts to
// bus::Ticks exactly (1 µs = 3 636 ticks). Nothing here uses floating point.
//
// Terms (S7-400H manual, seeds §3.1):
//   T_PH       = MAX(30 ms, 3·T_TRmax) with DP I/O, 30 ms with central I/O only
//   [1]  T_P15(i)  = T_PTO − (2·T_TR + T_WA + T_PROG + T_DP_UM + T_SLAVE_UM)  per DP master system
//                    abort if < 0;  T_P15_HW = min over the systems
//   [2]  T_P15_OD  = 50 ms + T_PH                     abort if > T_P15_HW
//        T_P15_AWP = 75 ms + 0.7 ms · KB              abort if > T_P15_HW
//   [3]  T_P15     = MAX(T_P15_AWP, T_P15_OD)
//   recommended max communication delay = 4·T_P15, max scan-cycle extension = 10·T_P15
//   update time = 75 ms + 0.7 ms · KB of changed DBs (the same formula as T_P15_AWP)
//   min input-signal duration across an update
//              = 2·t_IO + t_call + t_run + update time + t_higher  (a pulse must be longer)
//
// Rounding: 0.7 ms per KB is 700 µs per KB exactly, so every formula on a whole number of KB is
// exact. KB = 1024 bytes, MB = 1024 KB. A byte count is turned into KB rounding UP (a partial KB
// counts whole: the longer time is the safe side). Ticks from the switchover planner are turned
// into µs rounding UP (larger T_TR / T_DP_UM / T_SLAVE_UM → smaller T_P15_HW, larger T_PH: the
// safe side). Formula over table: the manual's Table 5-3 (500 KB 430 ms, 1 MB 800 ms, ...) is
// NOT used; the planner applies the formula (500 KB → 425 ms, 1024 KB → 791.8 ms), §10 item 6.

#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "pbvbus/bus/time.hpp"
#include "pbvbus/redundancy/switchover_timing.hpp"

namespace pbvbus::devices {

/// Microseconds. All H timing is exact integer µs.
using Us = std::int64_t;

inline constexpr Us kUsPerMs = 1000;
inline constexpr Us kUsPerSecond = 1'000'000;
constexpr Us ms(std::int64_t v) {
  return v * kUsPerMs;
}

/// Exact conversion to the simulation's time base.
constexpr bus::Ticks to_ticks(Us us) {
  return us * bus::kTicksPerUs;
}
/// Ticks to µs, rounded UP (the conservative direction for the planner's inputs).
constexpr Us ticks_to_us_ceil(bus::Ticks t) {
  return t / bus::kTicksPerUs + (t % bus::kTicksPerUs > 0 ? 1 : 0);
}
/// Bytes to KB (1 KB = 1024 bytes), rounded UP.
constexpr std::int64_t kb_from_bytes(std::int64_t bytes) {
  return (bytes + 1023) / 1024;
}

// ---- constants of the manual ----------------------------------------------------------------
inline constexpr Us kTphCentral = 30'000;        ///< T_PH with central I/O (and its floor)
inline constexpr Us kOutputCopyTime = 50'000;    ///< the master's output copy in T_P15_OD
inline constexpr Us kUpdateBase = 75'000;        ///< the 75 ms of T_P15_AWP and update time
inline constexpr Us kUpdatePerKb = 700;          ///< 0.7 ms per KB = 700 µs per KB, exact
inline constexpr Us kTp15SettableMin = 100'000;  ///< STEP 7: T_P15 = 0 or 100..60000 ms
inline constexpr Us kTp15SettableMax = 60'000'000;
inline constexpr std::int64_t kRecommendedCommDelayFactor = 4;        ///< · T_P15
inline constexpr std::int64_t kRecommendedCycleExtensionFactor = 10;  ///< · T_P15
inline constexpr Us kUpdateRetryDelay = 60'000'000;  ///< after an update timeout: ≥ 1 min
inline constexpr int kUpdateMaxTries = 10;           ///< then link-up must be restarted by hand

// ---- single formulas ------------------------------------------------------------------------

/// T_PH = MAX(30 ms, 3·T_TRmax) when the system has DP I/O; 30 ms for central I/O only
/// (t_tr_max is then ignored). T1: central → 30 ms; T_TRmax 30 ms → 90 ms; 8 ms → 30 ms.
Us t_ph(Us t_tr_max, bool has_dp);

/// T_P15_AWP = 75 ms + 700 µs · KB of DBs in work memory (formula, not Table 5-3). Exact.
/// 170 KB → 194 000; 500 KB → 425 000; 1024 KB → 791 800; 2048 KB → 1 508 600;
/// 10240 KB → 7 243 000. A negative KB count is treated as 0.
Us t_p15_awp(std::int64_t db_kb);

/// Update time = 75 ms + 0.7 ms per KB of changed DBs (seeds §3.1, 001). Same formula as
/// t_p15_awp(), applied to the changed DBs only.
Us update_time(std::int64_t changed_db_kb);

/// T_P15_OD = 50 ms + T_PH.
constexpr Us t_p15_od(Us t_ph_value) {
  return kOutputCopyTime + t_ph_value;
}

/// T8: link-up time ≈ memory MB × per_mb + base (unloaded: per_mb = 1 s; under load up to
/// 1 min per MB). Memory in KB (1 MB = 1024 KB); the per-KB share is rounded UP to whole µs.
Us link_up_time(std::int64_t memory_kb, Us base, Us per_mb = kUsPerSecond);

/// Duration of a cam of `length_mm` passing at `speed_km_h`: 3600·length/speed µs, rounded
/// DOWN (the shorter value is the safe side when asking whether the pulse is seen).
/// 50 mm at 10 km/h → 18 000 µs. A speed ≤ 0 or a negative length gives 0.
Us cam_pulse_duration(std::int64_t length_mm, std::int64_t speed_km_h);

// ---- the T_P15 procedure [1]–[3] ------------------------------------------------------------

/// One DP master system as the procedure sees it (all µs).
struct DpSystemTiming {
  std::string name;
  Us t_tr = 0;        ///< target rotation time
  Us t_dp_um = 0;     ///< DP switchover time of the system
  Us t_slave_um = 0;  ///< the slowest switched station's (IM's) switchover time
  Us t_pto = 0;       ///< longest gap in I/O updates the process tolerates
};

/// Takes T_TR (the larger of the two lines), T_DP_UM (the larger of the two directions) and
/// T_SLAVE_UM (the slowest switched station) from the switchover planner, each rounded UP to
/// whole µs; T_PTO comes from the process.
DpSystemTiming dp_system_from_switchover_plan(std::string name,
                                              const redundancy::SwitchoverPlan& plan, Us t_pto);

struct UpdatePlanInput {
  std::vector<DpSystemTiming> systems;  ///< empty = central I/O only
  Us t_wa = 0;                          ///< cycle of the selected/highest watchdog OB
  Us t_prog = 0;                        ///< run time of that watchdog OB
  std::int64_t db_kb = 0;               ///< KB of DBs in work memory (for T_P15_AWP)
};

/// Step [1] for one system, every term kept for printing.
struct SystemP15 {
  DpSystemTiming in;
  Us two_t_tr = 0;    ///< 2·T_TR
  Us subtracted = 0;  ///< 2·T_TR + T_WA + T_PROG + T_DP_UM + T_SLAVE_UM
  Us t_p15 = 0;       ///< T_PTO − subtracted (may be negative: then the plan aborts)
  bool negative() const { return t_p15 < 0; }
};

/// Why the procedure gave no recommendation (T4). In procedure order; `abort` holds the first.
enum class P15Abort {
  None,
  InvalidInput,         ///< a negative time or KB count in the input
  NegativeSystemTerm,   ///< [1] T_P15 < 0 for some DP master system
  OutputCopyExceedsHw,  ///< [2] T_P15_OD > T_P15_HW
  WorkMemoryExceedsHw,  ///< [2] T_P15_AWP > T_P15_HW
};
std::string_view to_string(P15Abort a);

struct UpdatePlan {
  UpdatePlanInput input;
  std::vector<SystemP15> systems;  ///< [1], in input order
  bool has_dp = false;             ///< false when `systems` is empty
  Us t_tr_max = 0;                 ///< 0 without DP
  /// [1] min over the systems; nullopt without DP master systems (no process constraint from
  /// DP: the comparisons of [2] are then skipped).
  std::optional<Us> t_p15_hw;
  std::optional<std::size_t> hw_system;  ///< index of the system giving T_P15_HW (first on tie)
  Us t_ph = 0;
  Us t_p15_od = 0;
  Us t_p15_awp = 0;
  /// Every term above is always computed, so a command can print them even after an abort.
  /// Abort flags, each evaluated independently:
  std::vector<std::size_t> negative_systems;  ///< indices with [1] < 0
  bool od_exceeds_hw = false;
  bool awp_exceeds_hw = false;
  P15Abort abort = P15Abort::None;    ///< the first failing step in procedure order
  std::vector<std::string> messages;  ///< one per failing step / invalid input, human readable

  /// [3] and the recommendations: set only when the procedure did not abort.
  std::optional<Us> t_p15;
  std::optional<Us> recommended_comm_delay;       ///< 4·T_P15
  std::optional<Us> recommended_cycle_extension;  ///< 10·T_P15
  /// The smallest value STEP 7 accepts that is ≥ T_P15: T_P15 rounded up to a whole ms and
  /// raised to 100 ms; nullopt when T_P15 > 60 000 ms (or when aborted).
  std::optional<Us> settable_t_p15;
  std::vector<std::string> notes;  ///< e.g. the settable value lies above T_P15_HW

  bool ok() const { return abort == P15Abort::None; }
};

/// Runs [1]–[3]. Never throws; bad input gives abort = InvalidInput with messages.
UpdatePlan plan_update(const UpdatePlanInput& in);

// ---- checks of a configured set of the four H parameters ------------------------------------

/// The four H parameters as configured (µs). nullopt = not configured. A value of 0 means
/// "not monitored" as in STEP 7: all four 0 is the same as none configured.
struct HParameters {
  std::optional<Us> max_cycle_extension;
  std::optional<Us> max_comm_delay;
  std::optional<Us> t_p15;
  std::optional<Us> t_ph;
};

enum class HCheck {
  PartiallyConfigured,         ///< all four or none (0 counts as none)
  NegativeValue,               ///< a configured value < 0
  ExtensionNotAboveCommDelay,  ///< max cycle extension > max communication delay
  CommDelayNotAboveTp15,       ///< max communication delay > T_P15
  Tp15NotAboveTph,             ///< T_P15 > T_PH
  OutputCopyMargin,            ///< 50 ms + T_PH ≤ T_P15
  Tp15OutOfRange,              ///< T_P15 ∈ {0} ∪ [100, 60000] ms
  Tp15NotWholeMs,              ///< STEP 7 sets T_P15 in whole milliseconds
  PlanAborted,                 ///< the planner gave no T_P15 (its abort is in the message)
  Tp15BelowPlan,               ///< configured T_P15 < planned T_P15 (the update does not fit)
  Tp15AboveHw,                 ///< configured T_P15 > T_P15_HW (the process misses I/O)
  TphBelowPlan,                ///< configured T_PH < planned T_PH (outputs may dip)
  CommDelayBelowRecommended,   ///< warning: < 4·planned T_P15
  ExtensionBelowRecommended,   ///< warning: < 10·planned T_P15
  NoneConfigured,              ///< warning: the update must fit in the cycle monitoring time
};
std::string_view to_string(HCheck c);

enum class Severity { Error, Warning };

struct HViolation {
  HCheck check;
  Severity severity = Severity::Error;
  std::string message;
};

struct HCheckResult {
  bool all_configured = false;         ///< all four present and not all zero
  std::vector<HViolation> violations;  ///< errors and warnings, in check order
  bool ok() const;                     ///< no Error (warnings allowed)
  bool has(HCheck c) const;
};

/// T6 alone: T_P15 ∈ {0} ∪ [100 ms, 60 000 ms].
constexpr bool t_p15_settable(Us t_p15) {
  return t_p15 == 0 || (t_p15 >= kTp15SettableMin && t_p15 <= kTp15SettableMax);
}

/// All checks of the set on its own and, when `plan` is given, against it. Never throws.
HCheckResult check_h_parameters(const HParameters& p, const UpdatePlan* plan = nullptr);

// ---- minimum input-signal duration across an update (T7) -----------------------------------

struct SignalDurationInput {
  Us t_io = 0;                     ///< DP I/O update time (counted twice)
  Us t_call = 0;                   ///< call interval of the OB class reading the input
  Us t_run = 0;                    ///< its run time
  std::int64_t changed_db_kb = 0;  ///< for the update time
  Us t_higher = 0;                 ///< run time of higher-priority classes
};

struct SignalDuration {
  Us two_t_io = 0;
  Us t_call = 0;
  Us t_run = 0;
  Us update_time = 0;  ///< 75 ms + 0.7 ms · KB
  Us t_higher = 0;
  Us total = 0;  ///< a pulse must be LONGER than this to be seen across an update
};

/// Every term and the total; negative inputs count as 0.
SignalDuration min_signal_duration(const SignalDurationInput& in);

/// A pulse is guaranteed seen across an update only if it lasts longer than the bound.
constexpr bool pulse_seen_across_update(Us pulse, const SignalDuration& bound) {
  return pulse > bound.total;
}

/// "194 ms", "1508.6 ms", "0.001 ms": µs as milliseconds, exact, trailing zeros dropped.
std::string format_ms(Us us);

}  // namespace pbvbus::devices
