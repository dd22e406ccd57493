// H-system update planner and H-parameter checks: see h_update_timing.hpp and docs/h-timing.md.
#include "pbvbus/s7h/h_update_timing.hpp"

#include <algorithm>
#include <limits>
#include <string>
#include <utility>

namespace pbvbus::devices {
namespace {

/// Inputs above this are rejected (about 11.6 days in µs; keeps every product far from int64
/// overflow).
constexpr Us kMaxInputUs = 1'000'000'000'000;
constexpr std::int64_t kMaxInputKb = 1'000'000'000;

std::string quoted(const std::string& name, std::size_t index) {
  if (name.empty()) return "DP master system #" + std::to_string(index + 1);
  return "DP master system '" + name + "'";
}

void check_time(std::vector<std::string>& errs, const std::string& what, Us v) {
  if (v < 0)
    errs.push_back(what + " is negative (" + format_ms(v) + ")");
  else if (v > kMaxInputUs)
    errs.push_back(what + " is out of range (" + format_ms(v) + ")");
}

}  // namespace

std::string format_ms(Us us) {
  std::string sign;
  // Negate in unsigned arithmetic so that INT64_MIN works too.
  std::uint64_t mag = static_cast<std::uint64_t>(us);
  if (us < 0) {
    sign = "-";
    mag = ~mag + 1;
  }
  std::string out = sign + std::to_string(mag / 1000);
  std::uint64_t frac = mag % 1000;
  if (frac != 0) {
    std::string f = std::to_string(frac);
    f.insert(0, 3 - f.size(), '0');
    while (!f.empty() && f.back() == '0') f.pop_back();
    out += "." + f;
  }
  return out + " ms";
}

Us t_ph(Us t_tr_max, bool has_dp) {
  if (!has_dp) return kTphCentral;
  // 3·T_TRmax, saturating (no overflow for any input).
  const Us three =
      t_tr_max > std::numeric_limits<Us>::max() / 3 ? std::numeric_limits<Us>::max() : 3 * t_tr_max;
  return std::max(kTphCentral, three);
}

Us t_p15_awp(std::int64_t db_kb) {
  // 0.7 ms per KB = 700 µs per KB: exact for a whole number of KB, no rounding.
  return kUpdateBase + kUpdatePerKb * std::clamp<std::int64_t>(db_kb, 0, kMaxInputKb);
}

Us update_time(std::int64_t changed_db_kb) {
  return t_p15_awp(changed_db_kb);
}

Us link_up_time(std::int64_t memory_kb, Us base, Us per_mb) {
  const std::int64_t kb = std::clamp<std::int64_t>(memory_kb, 0, kMaxInputKb);
  const Us rate = std::clamp<Us>(per_mb, 0, kMaxInputUs);
  // kb · per_mb / 1024, rounded up; split so that kb · per_mb cannot overflow.
  const Us whole = (kb / 1024) * rate;
  const Us part = ((kb % 1024) * rate + 1023) / 1024;
  return base + whole + part;
}

Us cam_pulse_duration(std::int64_t length_mm, std::int64_t speed_km_h) {
  // v km/h = v·10^6 mm / 3.6·10^9 µs = v/3600 mm/µs, so the cam passes in 3600·L/v µs.
  if (speed_km_h <= 0 || length_mm < 0) return 0;
  return 3600 * std::min<std::int64_t>(length_mm, kMaxInputKb) / speed_km_h;
}

DpSystemTiming dp_system_from_switchover_plan(std::string name,
                                              const redundancy::SwitchoverPlan& plan, Us t_pto) {
  DpSystemTiming s;
  s.name = std::move(name);
  s.t_tr = ticks_to_us_ceil(std::max(plan.line[0].t_tr, plan.line[1].t_tr));
  s.t_dp_um = ticks_to_us_ceil(std::max(plan.system_t_dp_um[0], plan.system_t_dp_um[1]));
  s.t_slave_um = ticks_to_us_ceil(plan.max_t_slave_um);
  s.t_pto = t_pto;
  return s;
}

std::string_view to_string(P15Abort a) {
  switch (a) {
    case P15Abort::None:
      return "none";
    case P15Abort::InvalidInput:
      return "invalid input";
    case P15Abort::NegativeSystemTerm:
      return "[1] T_P15 < 0";
    case P15Abort::OutputCopyExceedsHw:
      return "[2] T_P15_OD > T_P15_HW";
    case P15Abort::WorkMemoryExceedsHw:
      return "[2] T_P15_AWP > T_P15_HW";
  }
  return "?";
}

UpdatePlan plan_update(const UpdatePlanInput& in) {
  UpdatePlan p;
  p.input = in;

  // Validation: a bad value is reported, never thrown; the terms are computed from clamped
  // values so that the printout stays defined.
  std::vector<std::string> invalid;
  check_time(invalid, "T_WA", in.t_wa);
  check_time(invalid, "T_PROG", in.t_prog);
  if (in.db_kb < 0 || in.db_kb > kMaxInputKb)
    invalid.push_back("the DB size in work memory is out of range (" + std::to_string(in.db_kb) +
                      " KB)");
  for (std::size_t i = 0; i < in.systems.size(); ++i) {
    const DpSystemTiming& s = in.systems[i];
    const std::string who = quoted(s.name, i);
    check_time(invalid, who + ": T_TR", s.t_tr);
    check_time(invalid, who + ": T_DP_UM", s.t_dp_um);
    check_time(invalid, who + ": T_SLAVE_UM", s.t_slave_um);
    check_time(invalid, who + ": T_PTO", s.t_pto);
  }
  auto clampt = [](Us v) { return std::clamp<Us>(v, 0, kMaxInputUs); };
  const Us t_wa = clampt(in.t_wa), t_prog = clampt(in.t_prog);

  // [1] per DP master system.
  for (std::size_t i = 0; i < in.systems.size(); ++i) {
    SystemP15 r;
    r.in = in.systems[i];
    r.two_t_tr = 2 * clampt(r.in.t_tr);
    r.subtracted = r.two_t_tr + t_wa + t_prog + clampt(r.in.t_dp_um) + clampt(r.in.t_slave_um);
    r.t_p15 = clampt(r.in.t_pto) - r.subtracted;
    if (r.negative()) p.negative_systems.push_back(i);
    if (!p.t_p15_hw || r.t_p15 < *p.t_p15_hw) {
      p.t_p15_hw = r.t_p15;
      p.hw_system = i;
    }
    p.t_tr_max = std::max(p.t_tr_max, clampt(r.in.t_tr));
    p.systems.push_back(std::move(r));
  }
  p.has_dp = !in.systems.empty();

  // [2]
  p.t_ph = t_ph(p.t_tr_max, p.has_dp);
  p.t_p15_od = t_p15_od(p.t_ph);
  p.t_p15_awp = t_p15_awp(in.db_kb);
  p.od_exceeds_hw = p.t_p15_hw && p.t_p15_od > *p.t_p15_hw;
  p.awp_exceeds_hw = p.t_p15_hw && p.t_p15_awp > *p.t_p15_hw;

  // Abort cases, in procedure order; every failing step gets its message.
  auto fail = [&p](P15Abort a, std::string msg) {
    if (p.abort == P15Abort::None) p.abort = a;
    p.messages.push_back(std::move(msg));
  };
  for (std::string& m : invalid) fail(P15Abort::InvalidInput, "invalid input: " + m);
  for (std::size_t i : p.negative_systems) {
    const SystemP15& r = p.systems[i];
    fail(P15Abort::NegativeSystemTerm,
         "[1] " + quoted(r.in.name, i) + ": T_P15 = T_PTO " + format_ms(r.in.t_pto) +
             " - (2*T_TR + T_WA + T_PROG + T_DP_UM + T_SLAVE_UM) " + format_ms(r.subtracted) +
             " = " + format_ms(r.t_p15) + " < 0: the process cannot tolerate the switchover");
  }
  if (p.od_exceeds_hw)
    fail(P15Abort::OutputCopyExceedsHw, "[2] T_P15_OD = 50 ms + T_PH = " + format_ms(p.t_p15_od) +
                                            " exceeds T_P15_HW = " + format_ms(*p.t_p15_hw));
  if (p.awp_exceeds_hw)
    fail(P15Abort::WorkMemoryExceedsHw,
         "[2] T_P15_AWP = 75 ms + 0.7 ms * " + std::to_string(in.db_kb) +
             " KB = " + format_ms(p.t_p15_awp) + " exceeds T_P15_HW = " + format_ms(*p.t_p15_hw));
  if (!p.ok()) return p;

  // [3] and the recommendations.
  const Us t = std::max(p.t_p15_awp, p.t_p15_od);
  p.t_p15 = t;
  p.recommended_comm_delay = kRecommendedCommDelayFactor * t;
  p.recommended_cycle_extension = kRecommendedCycleExtensionFactor * t;
  const Us whole_ms = (t + kUsPerMs - 1) / kUsPerMs * kUsPerMs;
  const Us settable = std::max(whole_ms, kTp15SettableMin);
  if (settable > kTp15SettableMax) {
    p.notes.push_back("T_P15 = " + format_ms(t) + " exceeds the largest settable value 60000 ms");
  } else {
    p.settable_t_p15 = settable;
    if (settable != t)
      p.notes.push_back("T_P15 = " + format_ms(t) +
                        " is not settable; the smallest settable value "
                        "above it is " +
                        format_ms(settable));
    if (p.t_p15_hw && settable > *p.t_p15_hw)
      p.notes.push_back("the smallest settable T_P15 " + format_ms(settable) +
                        " lies above T_P15_HW = " + format_ms(*p.t_p15_hw));
  }
  if (!p.has_dp)
    p.notes.push_back("no DP master system: T_PH = 30 ms (central I/O) and no T_P15_HW bound");
  return p;
}

std::string_view to_string(HCheck c) {
  switch (c) {
    case HCheck::PartiallyConfigured:
      return "partially configured";
    case HCheck::NegativeValue:
      return "negative value";
    case HCheck::ExtensionNotAboveCommDelay:
      return "cycle extension <= communication delay";
    case HCheck::CommDelayNotAboveTp15:
      return "communication delay <= T_P15";
    case HCheck::Tp15NotAboveTph:
      return "T_P15 <= T_PH";
    case HCheck::OutputCopyMargin:
      return "50 ms + T_PH > T_P15";
    case HCheck::Tp15OutOfRange:
      return "T_P15 out of range";
    case HCheck::Tp15NotWholeMs:
      return "T_P15 not whole ms";
    case HCheck::PlanAborted:
      return "plan aborted";
    case HCheck::Tp15BelowPlan:
      return "T_P15 below plan";
    case HCheck::Tp15AboveHw:
      return "T_P15 above T_P15_HW";
    case HCheck::TphBelowPlan:
      return "T_PH below plan";
    case HCheck::CommDelayBelowRecommended:
      return "communication delay below recommended";
    case HCheck::ExtensionBelowRecommended:
      return "cycle extension below recommended";
    case HCheck::NoneConfigured:
      return "none configured";
  }
  return "?";
}

bool HCheckResult::ok() const {
  return std::none_of(violations.begin(), violations.end(),
                      [](const HViolation& v) { return v.severity == Severity::Error; });
}

bool HCheckResult::has(HCheck c) const {
  return std::any_of(violations.begin(), violations.end(),
                     [c](const HViolation& v) { return v.check == c; });
}

HCheckResult check_h_parameters(const HParameters& p, const UpdatePlan* plan) {
  HCheckResult r;
  auto error = [&r](HCheck c, std::string m) {
    r.violations.push_back({c, Severity::Error, std::move(m)});
  };
  auto warn = [&r](HCheck c, std::string m) {
    r.violations.push_back({c, Severity::Warning, std::move(m)});
  };

  struct Named {
    const char* name;
    const std::optional<Us>& v;
  };
  const Named all[] = {{"max scan-cycle extension", p.max_cycle_extension},
                       {"max communication delay", p.max_comm_delay},
                       {"T_P15", p.t_p15},
                       {"T_PH", p.t_ph}};

  int present = 0, zero = 0;
  std::string missing;
  for (const Named& n : all) {
    if (n.v) {
      ++present;
      if (*n.v == 0) ++zero;
    } else {
      missing += missing.empty() ? n.name : std::string(", ") + n.name;
    }
  }

  // T_P15 on its own (T6), whenever it is given.
  if (p.t_p15 && *p.t_p15 >= 0) {
    if (!t_p15_settable(*p.t_p15))
      error(HCheck::Tp15OutOfRange,
            "T_P15 = " + format_ms(*p.t_p15) + " is not settable: 0 or 100..60000 ms only");
    else if (*p.t_p15 % kUsPerMs != 0)
      error(HCheck::Tp15NotWholeMs,
            "T_P15 = " + format_ms(*p.t_p15) + " is not a whole number of milliseconds");
  }
  bool negative = false;
  for (const Named& n : all)
    if (n.v && *n.v < 0) {
      negative = true;
      error(HCheck::NegativeValue, std::string(n.name) + " is negative (" + format_ms(*n.v) + ")");
    }

  if (present == 0 || (present == 4 && zero == 4)) {
    warn(HCheck::NoneConfigured,
         "no H parameters configured: the update must fit within the cycle monitoring time; an "
         "interruption leaves Solo mode with the standby in STOP");
    return r;
  }
  if (present < 4) {
    error(HCheck::PartiallyConfigured,
          "configure all four H parameters or none; missing: " + missing);
    return r;
  }
  r.all_configured = true;
  if (negative) return r;

  const Us ext = *p.max_cycle_extension, comm = *p.max_comm_delay, tp15 = *p.t_p15, tph = *p.t_ph;
  if (!(ext > comm))
    error(HCheck::ExtensionNotAboveCommDelay, "max scan-cycle extension " + format_ms(ext) +
                                                  " must be greater than max communication delay " +
                                                  format_ms(comm));
  if (!(comm > tp15))
    error(HCheck::CommDelayNotAboveTp15, "max communication delay " + format_ms(comm) +
                                             " must be greater than T_P15 " + format_ms(tp15));
  if (!(tp15 > tph))
    error(HCheck::Tp15NotAboveTph,
          "T_P15 " + format_ms(tp15) + " must be greater than T_PH " + format_ms(tph));
  // 50 ms + T_PH <= T_P15, written so that it cannot overflow (both are >= 0 here).
  if (tph > tp15 - kOutputCopyTime)
    error(HCheck::OutputCopyMargin, "50 ms + T_PH = " + format_ms(kOutputCopyTime + tph) +
                                        " must not exceed T_P15 " + format_ms(tp15));

  if (plan == nullptr) return r;
  if (plan->abort == P15Abort::InvalidInput) {
    error(HCheck::PlanAborted, "the update plan has invalid input; no comparison possible");
    return r;
  }
  // T_PH depends only on the DP master systems, so it is compared even after an abort.
  if (tph < plan->t_ph)
    error(HCheck::TphBelowPlan, "T_PH " + format_ms(tph) + " is below the planned T_PH " +
                                    format_ms(plan->t_ph) +
                                    ": outputs may dip on an update or master swap");
  if (!plan->ok()) {
    std::string m =
        "the update planner gives no T_P15 (" + std::string(to_string(plan->abort)) + ")";
    if (!plan->messages.empty()) m += ": " + plan->messages.front();
    error(HCheck::PlanAborted, std::move(m));
    return r;
  }
  const Us planned = *plan->t_p15;
  if (tp15 < planned)
    error(HCheck::Tp15BelowPlan, "T_P15 " + format_ms(tp15) + " is below the planned T_P15 " +
                                     format_ms(planned) + ": the update does not fit");
  if (plan->t_p15_hw && tp15 > *plan->t_p15_hw)
    error(HCheck::Tp15AboveHw, "T_P15 " + format_ms(tp15) + " exceeds T_P15_HW " +
                                   format_ms(*plan->t_p15_hw) +
                                   ": the process would miss I/O updates");
  if (plan->recommended_comm_delay && comm < *plan->recommended_comm_delay)
    warn(HCheck::CommDelayBelowRecommended,
         "max communication delay " + format_ms(comm) +
             " is below the recommended 4*T_P15 = " + format_ms(*plan->recommended_comm_delay));
  if (plan->recommended_cycle_extension && ext < *plan->recommended_cycle_extension)
    warn(HCheck::ExtensionBelowRecommended, "max scan-cycle extension " + format_ms(ext) +
                                                " is below the recommended 10*T_P15 = " +
                                                format_ms(*plan->recommended_cycle_extension));
  return r;
}

SignalDuration min_signal_duration(const SignalDurationInput& in) {
  auto clampt = [](Us v) { return std::clamp<Us>(v, 0, kMaxInputUs); };
  SignalDuration d;
  d.two_t_io = 2 * clampt(in.t_io);
  d.t_call = clampt(in.t_call);
  d.t_run = clampt(in.t_run);
  d.update_time = update_time(in.changed_db_kb);
  d.t_higher = clampt(in.t_higher);
  d.total = d.two_t_io + d.t_call + d.t_run + d.update_time + d.t_higher;
  return d;
}

}  // namespace pbvbus::devices
