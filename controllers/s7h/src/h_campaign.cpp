// The seeded fault campaign over the H-system and its observer (h_campaign.hpp has the
// decisions, docs/h-campaign.md the reasons).
#include "pbvbus/s7h/h_campaign.hpp"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <map>
#include <memory>
#include <optional>
#include <random>
#include <sstream>
#include <stdexcept>

#include "pbvbus/bus/line.hpp"
#include "pbvbus/bus/scheduler.hpp"
#include "pbvbus/bus/tap.hpp"
#include "pbvbus/campaign/campaign_support.hpp"
#include "pbvbus/gsd/gsd.hpp"
#include "pbvbus/switched_io/redundant_master_system.hpp"
#include "pbvbus/slaves/slave_model.hpp"
#include "pbvbus/switched_io/switched_station.hpp"
#include "pbvbus/fdl/telegram.hpp"
#include "pbvbus/redundancy/switchover_timing.hpp"
#include "pbvbus/s7h/h_rack_power.hpp"

namespace pbvbus::devices {

std::string_view to_string(HFault f) {
  switch (f) {
    case HFault::MasterPower:
      return "master CPU power (F1)";
    case HFault::StandbyPower:
      return "standby CPU power (F1)";
    case HFault::MasterStop:
      return "master CPU STOP";
    case HFault::StandbyStop:
      return "standby CPU STOP";
    case HFault::OneFibre:
      return "one fibre (F5)";
    case HFault::BothFibres:
      return "both fibres at once (F6)";
    case HFault::ActiveIm:
      return "active IM (F10)";
    case HFault::PassiveIm:
      return "passive IM (F10)";
    case HFault::ShortCircuit:
      return "short circuit (F14)";
    case HFault::DpMasterFailure:
      return "DP master module (F9)";
    case HFault::ComparisonError:
      return "comparison error (F16)";
    case HFault::OneSidedOb121:
      return "one-sided OB 121 (F17)";
    case HFault::MasterSwap:
      return "operator master swap";
    case HFault::MasterHold:
      return "master HOLD, link-up refused (F21)";
    case HFault::LoadMemoryError:
      return "load-memory access error (F2)";
    case HFault::SyncError:
      return "sync error (F18)";
    case HFault::UpdateTimeout:
      return "update timeout (F19)";
    case HFault::StandbyLostDuringLinkUp:
      return "standby lost in LINK-UP (F20)";
    case HFault::LoadChange:
      return "structural change in Redundant (F22)";
    case HFault::ParameterChangeSwap:
      return "master swap with a changed parameter (F23)";
    case HFault::PsHalf:
      return "half of a PS 407 10A R (F1)";
    case HFault::ChecksumError:
      return "checksum error in Redundant";
    case HFault::SecondFibre:
      return "second fibre later (F5)";
    case HFault::UpdateBlocked:
      return "update disabled by SFC 90";
  }
  return "?";
}

int HCampaignResult::events_with(std::uint16_t code) const {
  return campaign::count_of(io_events, code);
}

std::string HCampaignResult::summary() const {
  std::ostringstream o;
  o << "faults " << faults << " repairs " << repairs << " (cycles:";
  for (int k = 0; k < kHFaultKinds; ++k)
    o << ' ' << to_string(static_cast<HFault>(k)) << '=' << drawn[k];
  o << ") defective " << defective << " comparison-stops " << comparison_stops << " role swaps "
    << role_swaps << " update-timeouts " << update_timeouts << " refusals " << refusals
    << " diag-checks " << diag_checks << " ps-cpu-failures " << ps_cpu_failures
    << " checksum-defective " << checksum_defective << " update-waits " << update_waits
    << "; events" << campaign::format_counts(io_events);
  o << " OB72=" << ob72 << " OB121=" << ob121 << " (observed " << observed_events << ", expected "
    << expected_events << "); samples " << output_samples << " pulses " << pulses << " cleared "
    << cleared_samples << "; DX "
    << dx_requests << " stray " << stray_dx << "; split frames " << split_frames
    << " second-master frames " << second_master_frames << "; IM switchovers " << im_switchovers
    << " late " << late_switchovers << " early " << early_switchovers << " max IM "
    << static_cast<double>(max_im_switchover) / bus::kTicksPerMs << " ms (drawn "
    << static_cast<double>(max_im_drawn) / bus::kTicksPerMs << " ms, from the fault "
    << static_cast<double>(max_fault_switchover) / bus::kTicksPerMs << " ms, least margin to "
    << "the bound "
    << (min_bound_margin == bus::kNever
            ? -1.0
            : static_cast<double>(min_bound_margin) / bus::kTicksPerMs)
    << " ms, worst bound " << static_cast<double>(worst_bound) / bus::kTicksPerMs
    << " ms; by cause: side stop " << im_by_cause[0] << ", short circuit " << im_by_cause[1]
    << ", interface " << im_by_cause[2] << ") frozen "
    << frozen_samples << "; mismatches " << mismatches.size()
    << "; max settle " << static_cast<double>(max_settle) / bus::kTicksPerMs << " ms; simulated "
    << static_cast<double>(simulated) / bus::kTicksPerSecond << " s in " << wall_seconds
    << " s wall; frames " << frames;
  return o.str();
}

namespace {

using Bytes = std::vector<std::uint8_t>;
using Src = HSystemEvent::Source;
constexpr bus::Ticks kMs = bus::kTicksPerMs;
constexpr bus::Ticks kDefectiveWindow = 7 * 24 * 3600 * bus::kTicksPerSecond;  // F17, fixed
/// A frame whose start lies at most this long after its side stopped was committed before.
constexpr bus::Ticks kCommitted = kMs / 2;
constexpr std::uint8_t kSw[2] = {20, 21};
constexpr std::uint8_t kOne[2] = {40, 60};

std::string fmt_time(bus::Ticks t) { return campaign::format_ms(t); }

/// One expected event: an OB of the pair (72/121, with its reason) or an I/O event.
struct Expect {
  Src src = Src::Io;
  int ob = 0;
  std::uint16_t code = 0;
  int rack = -1;
  CpuRole role = CpuRole::Master;
  int line = -1;
  std::uint8_t station = 0xFF;
  std::string text;  ///< Cpu: the OB's text ("OB 72 <reason>")
  bus::Ticks earliest = 0, latest = 0;
};

bool same(const Expect& x, const HSystemEvent& e) {
  if (x.src != e.source || x.ob != e.ob || x.code != e.code || x.rack != e.rack || x.role != e.role)
    return false;
  if (x.src == Src::Cpu) return x.text == e.text;
  return x.line == e.line && x.station == e.station && e.system == 0;
}

std::string fmt_ev(Src src, int ob, std::uint16_t code, int rack, CpuRole role, int line,
                   std::uint8_t station, const std::string& text) {
  char buf[96];
  if (src == Src::Cpu)
    std::snprintf(buf, sizeof buf, "[%s rack %d %s]", text.c_str(), rack,
                  std::string(to_string(role)).c_str());
  else
    std::snprintf(buf, sizeof buf, "[OB %d %04X L%d @%d rack %d]", ob, code, line, int(station),
                  rack);
  return buf;
}
std::string fmt(const Expect& x) {
  return fmt_ev(x.src, x.ob, x.code, x.rack, x.role, x.line, x.station, x.text);
}
std::string fmt(const HSystemEvent& e) {
  return fmt_ev(e.source, e.ob, e.code, e.rack, e.role, e.line, e.station, e.text);
}

struct Step {
  bus::Ticks at = 0;
  bool repair = false;
  std::string what;
  std::vector<Expect> expect;
};

GsdFile load(const std::string& dir, const char* name) {
  return campaign::load_gsd_or_throw(dir, name, "h campaign");
}
std::vector<ModuleChoice> switched_modules() {
  return {ModuleChoice::named("16DI DC24V"), ModuleChoice::named("16DO DC24V/0.5A")};
}
std::vector<ModuleChoice> plain_modules() {
  return {ModuleChoice::named("16DI/16DO DC24V")};
}

/// The observer's own model (nothing here is read from HSystemModel or HCpuPair).
struct Observer {
  int master = 0;
  bool split = false;  ///< F6: two masters
  // Side r's DP master runs in [run_from, run_until); CPU r runs the program in [prog_from,
  // prog_until).
  bus::Ticks run_from[2] = {bus::kNever, bus::kNever}, run_until[2] = {bus::kNever, bus::kNever};
  bus::Ticks prog_from[2] = {bus::kNever, bus::kNever};
  bus::Ticks stopped_at[2] = {bus::kNever, bus::kNever};  ///< the side's last stop
  bus::Ticks prog_until[2] = {bus::kNever, bus::kNever};
  bool iface_ok[2][2] = {{true, true}, {true, true}};
  bool shorted[2] = {false, false}, mfail[2] = {false, false};
  int act[2] = {0, 0};
  std::optional<bus::Ticks> last121[2];
  std::optional<bus::Ticks> last_checksum[2];  ///< the last checksum error per CPU (7 days)
  bus::Ticks swap_at = bus::kNever;  ///< the last automatic swap after ERROR-SEARCH
  std::uint32_t kb = 100;            ///< KB of changed DBs the next update copies

  /// No CPU runs the program (HOLD, both STOP): no OB runs, the outputs may be 0 (Clear).
  bool no_program(bus::Ticks t) const { return !prog(0, t) && !prog(1, t); }
  bool side_runs(int r, bus::Ticks t) const { return run_from[r] <= t && t < run_until[r]; }
  bool prog(int r, bus::Ticks t) const { return prog_from[r] <= t && t < prog_until[r]; }
  /// The rack an I/O OB runs on at t: -1 when both CPUs run the program.
  int io_rack(bus::Ticks t) const {
    const bool a = prog(0, t), b = prog(1, t);
    return a && b ? -1 : (a ? 0 : (b ? 1 : -2));
  }
  bool line_ok(int l) const { return !shorted[l] && !mfail[l]; }
  bool reach(int k, int l, bus::Ticks t) const {
    return iface_ok[k][l] && line_ok(l) && side_runs(l, t);
  }
};

class HCampaignRun;

struct Tap final : bus::Tap {
  explicit Tap(HCampaignRun& c) : camp(c) {}
  void on_frame(const bus::TapFrame& f) override;
  HCampaignRun& camp;
};

class HCampaignRun {
 public:
  explicit HCampaignRun(const HCampaignOptions& o) : m_o(o), m_rng(o.seed), m_tap(*this) {
    int sum = 0;
    for (int w : o.weights) {
      if (w < 0) throw std::invalid_argument("h campaign: a negative fault weight");
      sum += w;
    }
    if (sum <= 0) throw std::invalid_argument("h campaign: every fault weight is 0");
    if (o.fault_min < 0 || o.fault_min > o.fault_max || o.gap_min < 0 || o.gap_min > o.gap_max)
      throw std::invalid_argument("h campaign: fault/gap durations: 0 <= min <= max");
    if (o.scan_time <= 0 || o.self_test_time < 0 || o.settle_limit <= 0 || o.recognition < 0 ||
        o.startup < 0)
      throw std::invalid_argument("h campaign: times must not be negative (scan, settle > 0)");
    const HCheckResult hc = check_h_parameters(o.h_parameters);
    if (!hc.ok()) {
      std::string m = "h campaign: H parameters:";
      for (const auto& v : hc.violations)
        if (v.severity == Severity::Error) m += " " + v.message + ";";
      throw std::invalid_argument(m);
    }
    if (update_abort_after(m_obs.kb) != bus::kNever)
      throw std::invalid_argument("h campaign: the normal update (100 KB) exceeds T_P15");
    if (o.update_timeout_failures_max < 1 || o.update_timeout_failures_max > kUpdateMaxTries)
      throw std::invalid_argument("h campaign: update_timeout_failures_max must be 1..10");
    if (o.weights[static_cast<int>(HFault::UpdateTimeout)] > 0 &&
        update_abort_after(o.update_timeout_kb) == bus::kNever)
      throw std::invalid_argument(
          "h campaign: update_timeout_kb gives an update that fits in T_P15 (no timeout)");
    build();
  }
  HCampaignResult run();
  void on_frame(const bus::TapFrame& f);

 private:
  struct Sw {
    std::unique_ptr<SwitchedStationModel> model;
    campaign::CounterWatch watch;  ///< the backplane outputs' counter
    std::size_t frozen_im = static_cast<std::size_t>(-1);  ///< the switchover frozen_value is of
    std::uint16_t frozen_value = 0;
  };
  /// What can make a switched station switch over, as the observer injected it (the planner's
  /// bound depends on how the loss is recognised, docs/switchover-timing.md).
  enum class CauseKind : std::uint8_t {
    SideStop,   ///< the side's DP master stops or its module fails: recognised at once
    LineLoss,   ///< short circuit: the line-loss recognition
    Interface,  ///< one station's interface: that station's recognition
  };
  struct Cause {
    bus::Ticks at = 0;
    int line = 0;  ///< the line lost
    CauseKind kind = CauseKind::SideStop;
    int station = -1;  ///< Interface: the station index
  };
  void cause(bus::Ticks at, int line, CauseKind kind, int station = -1) {
    m_causes.push_back({at, line, kind, station});
  }
  /// S5: every IM switchover within [its drawn time, the planner's bound from its cause].
  void check_im_times();
  /// False when station k's backplane outputs changed while its IM switchover runs.
  bool check_frozen(int k, std::uint16_t v, bus::Ticks t);
  void build();
  bus::Ticks now() const { return m_sched.now(); }
  void run_to(bus::Ticks t) { m_sched.run_until(t); }
  std::string step_name() const { return m_steps.empty() ? "(none)" : m_steps.back().what; }
  bus::Ticks draw(bus::Ticks lo, bus::Ticks hi) { return m_rng.ticks(lo, hi); }
  int draw_int(int lo, int hi) { return m_rng.integer(lo, hi); }
  /// The observer's W (digest §3.1): MAX(75 ms + 0.7 ms per changed KB, 50 ms + T_PH).
  bus::Ticks update_w(std::uint32_t kb) const {
    const bus::Ticks tph = to_ticks(m_o.h_parameters.t_ph.value_or(0));
    return std::max(default_update_time(kb), tph > 0 ? 50 * kMs + tph : bus::Ticks{0});
  }
  bus::Ticks update_w() const { return update_w(m_obs.kb); }
  /// F19/R6: the update is aborted this long after t3 (= the start of UPDATE here) when the
  /// first monitored limit (T_P15, then communication delay, cycle extension; 0 = not
  /// monitored) is shorter than W; kNever when it fits.
  bus::Ticks update_abort_after(std::uint32_t kb) const {
    const bus::Ticks w = update_w(kb);
    bus::Ticks best = bus::kNever;
    for (const auto& v : {m_o.h_parameters.t_p15, m_o.h_parameters.max_comm_delay,
                          m_o.h_parameters.max_cycle_extension})
      if (v && *v > 0 && to_ticks(*v) < w) best = std::min(best, to_ticks(*v));
    return best;
  }

  // Expectations.
  Expect cpu_ob(int ob, int rack, CpuRole role, HReason why, bus::Ticks at) const {
    Expect x;
    x.src = Src::Cpu;
    x.ob = ob;
    x.rack = rack;
    x.role = role;
    x.text = "OB " + std::to_string(ob) + " " + std::string(to_string(why));
    x.earliest = x.latest = at;
    return x;
  }
  Expect io(std::uint16_t code, int line, std::uint8_t station, bus::Ticks from, bus::Ticks to) {
    Expect x;
    x.src = Src::Io;
    x.ob = (code == 0x73A3 || code == 0x72A3) ? 70 : 86;
    x.code = code;
    x.line = line;
    x.station = station;
    x.rack = m_obs.io_rack(from);  // -2: no CPU runs a program, no OB (dropped at begin_step)
    x.earliest = from;
    x.latest = to;
    return x;
  }
  /// Side r's DP master stops at t (its CPU off, STOP, ERROR-SEARCH, DEFECTIVE): one 39C3,
  /// every station active on r to the other line.
  void lose_side(int r, bus::Ticks t, std::vector<Expect>& ex);
  /// CPU r (standby) starts its link-up at t0: its DP master runs from the UPDATE on (38C3),
  /// its program from the end of the update.
  void restart_side(int r, bus::Ticks t0, std::vector<Expect>& ex);
  /// CPU r goes to ERROR-SEARCH at t (OB 121 on it alone, F17, or a checksum error): the
  /// partner runs on as master, r's side is lost; unless `repeated` (-> DEFECTIVE), r re-links
  /// after the self-test and the automatic swap makes it master (R5), with OB 72 MasterSwap on
  /// both. A comparison error within the first self-test cycle after that swap repeats (swap_at).
  void expect_error_search(int r, bus::Ticks t, bool repeated, std::vector<Expect>& ex);
  void switch_away(int l);
  void set_master(int m) {
    if (m != m_obs.master) ++m_r.role_swaps;
    m_obs.master = m;
  }

  void begin_step(std::string what, bool repair, std::vector<Expect> ex);
  bool satisfied(const Step& s) const;
  void settle_step();
  bool recovered() const;
  void wait_recovered(bus::Ticks since);
  void check_roles();
  void match_all();

  void cycle(HFault f);
  /// The new kinds (link-up/update reactions); each returns when its last repair is injected
  /// and gives the time the settle counts from.
  bus::Ticks cycle_link(HFault f);
  /// The kinds of the later fault paths (PsHalf, ChecksumError, SecondFibre, UpdateBlocked),
  /// likewise.
  bus::Ticks cycle_later(HFault f);
  /// The standby to STOP by its mode switch: OB 72 StandbyStop on the master, its side lost.
  void stop_standby(const std::string& what);
  void mismatch(const std::string& m) {
    m_r.mismatches.push_back(fmt_time(now()) + ": " + m_steps.back().what + ": " + m);
  }
  /// A diagnostic entry on `rack` at exactly `at` with `code` and a text starting with
  /// `text` (empty: any); a mismatch when there is none.
  void expect_diag(int rack, bus::Ticks at, std::uint16_t code, std::string_view text);
  void pause() { run_to(now() + draw(100 * kMs, 300 * kMs)); }
  void hidden_cycle();
  void dwell() { run_to(now() + draw(m_o.fault_min, m_o.fault_max)); }
  std::string rack_name(int r) const { return "rack " + std::to_string(r); }

  HCampaignOptions m_o;
  campaign::Draw m_rng;
  HCpuPairParams m_params;
  bus::Scheduler m_sched;
  std::unique_ptr<bus::Line> m_bus[2];
  fdl::BusParams m_bp;
  std::unique_ptr<RedundantMasterSystemModel> m_sys;
  Sw m_sw[2];
  std::unique_ptr<SlaveModel> m_one[2];
  std::unique_ptr<HSystemModel> m_h;
  Tap m_tap;
  std::uint16_t m_counter = 0;
  bool m_zero_done = false;
  Observer m_obs;
  redundancy::SwitchoverPlan m_plan;
  std::vector<Cause> m_causes;
  std::vector<Step> m_steps;
  std::size_t m_reported_step = static_cast<std::size_t>(-1);  ///< two-master report, once
  std::size_t m_stray_step = static_cast<std::size_t>(-1);
  HCampaignResult m_r;
};

void Tap::on_frame(const bus::TapFrame& f) {
  camp.on_frame(f);
}

void HCampaignRun::build() {
  const GsdFile fast = load(m_o.gsd_dir, "PBVB0A10.gsd");
  const GsdFile slow = load(m_o.gsd_dir, "PBVB0A11.gsd");
  const GsdFile plain = load(m_o.gsd_dir, "PBVB0A01.gsd");
  m_bp = fdl::BusParams::defaults(m_o.baud);
  m_bp.hsa = 12;
  m_bus[0] = std::make_unique<bus::Line>(m_sched, "A", m_o.baud, m_o.seed * 2 + 1);
  m_bus[1] = std::make_unique<bus::Line>(m_sched, "B", m_o.baud, m_o.seed * 2 + 2);
  std::vector<dp::SlaveParams> cfg[2];
  std::vector<redundancy::SwitchedStationRef> refs;
  for (int k = 0; k < 2; ++k) {
    const GsdFile& g = k == 1 ? slow : fast;
    SwitchedStationOptions so;
    so.address = kSw[k];
    so.bus_params = m_bp;
    if (m_o.im_time) {
      // S5: the GSD's T_SLAVE_UM (Slave_Max_Switch_Over_Time x 10 ms), as the planner reads it;
      // the draws seeded like the switched-I/O campaign's (seed x FNV prime + address).
      if (auto t = g.redundancy().switch_over_time_ms())
        so.redundancy.im_switchover_bound = bus::Ticks{*t} * kMs;
      so.redundancy.im_seed = m_o.seed * 0x100000001B3ull + kSw[k];
    }
    auto b = SwitchedStationModel::build(g, switched_modules(), so);
    if (!b.ok())
      throw std::runtime_error("h campaign: switched station " + std::to_string(kSw[k]) + ": " +
                               (b.errors.empty() ? std::string("?") : b.errors[0]));
    m_sw[k].model = std::move(b.model);
    auto sp = master_slave_params(g, switched_modules(), kSw[k]);
    if (!sp.ok()) throw std::runtime_error("h campaign: master params of a switched station");
    dp::SlaveParams p = *sp.value;
    p.prm_cmd.assign(8, 0);
    cfg[0].push_back(p);
    cfg[1].push_back(p);
    refs.push_back({kSw[k], m_sw[k].model->t_slave_um().value_or(0), false});
  }
  for (int l = 0; l < 2; ++l) {
    auto sp = master_slave_params(plain, plain_modules(), kOne[l]);
    if (!sp.ok()) throw std::runtime_error("h campaign: master params of a one-sided slave");
    cfg[l].push_back(*sp.value);
    SlaveModelOptions so;
    so.address = kOne[l];
    so.bus_params = m_bp;
    auto b = SlaveModel::build(plain, plain_modules(), so);
    if (!b.ok()) throw std::runtime_error("h campaign: one-sided slave");
    m_one[l] = std::move(b.model);
  }
  RedundantMasterSystemOptions mo;
  mo.bus_params = m_bp;
  mo.system.output_hold_time = m_o.output_hold_time;
  m_sys = std::make_unique<RedundantMasterSystemModel>(mo, cfg[0], cfg[1], refs);
  // The planner's bounds (recognition + T_DP_UM + T_SLAVE_UM) for the late check: 16 DI = 2
  // input octets, 16 DO = 2 output octets (16DI/16DO likewise), MaxTsdr and Max_Diag_Data_Len
  // from the GSDs.
  {
    std::vector<redundancy::PlannedSlave> ps;
    for (int k = 0; k < 2; ++k) {
      const GsdFile& g = k == 1 ? slow : fast;
      redundancy::PlannedSlave p;
      p.address = kSw[k];
      p.in_len = p.out_len = 2;
      p.max_tsdr_bits = g.max_tsdr(m_o.baud).value_or(0);
      p.max_diag_len = m_sw[k].model->config().max_diag_len;
      p.switched = true;
      p.t_slave_um = m_o.im_time ? m_sw[k].model->t_slave_um() : std::nullopt;
      if (m_o.tamper.planned_t_slave_um >= 0) p.t_slave_um = m_o.tamper.planned_t_slave_um;
      ps.push_back(p);
    }
    for (int l = 0; l < 2; ++l) {
      redundancy::PlannedSlave p;
      p.address = kOne[l];
      p.in_len = p.out_len = 2;
      p.max_tsdr_bits = plain.max_tsdr(m_o.baud).value_or(0);
      p.max_diag_len = std::max<std::size_t>(6, plain.slave_features().max_diag_data_len);
      p.line = l;
      ps.push_back(p);
    }
    m_plan = redundancy::plan_switchover(m_bp, ps);
    for (const auto& b : m_plan.stations)
      for (int l = 0; l < 2; ++l)
        m_r.worst_bound = std::max(
            {m_r.worst_bound, b.bound[l],
             m_plan.line[l].line_loss_recognition + b.t_dp_um[l] + b.t_slave_um});
  }
  for (int l = 0; l < 2; ++l) m_sys->attach(l, *m_bus[l], "master");
  for (auto& s : m_sw)
    for (int l = 0; l < 2; ++l) s.model->attach(l, *m_bus[l]);
  for (int l = 0; l < 2; ++l) {
    m_bus[l]->attach(*m_one[l], "one-sided");
    m_bus[l]->add_tap(m_tap);
    m_bus[l]->start();
  }
  m_params.h_parameters = m_o.h_parameters;  // checked in the constructor
  m_params.self_test_time = m_o.self_test_time;
  m_params.cyclic_self_test_period = m_o.cyclic_self_test_period;
  m_h = std::make_unique<HSystemModel>(m_sched, m_params,
                                       std::vector<RedundantMasterSystemModel*>{m_sys.get()});
  m_h->set_program(
      [this](std::span<const std::uint8_t>, std::span<std::uint8_t> piq, bus::Ticks t) {
        if (++m_counter == 0) m_counter = 1;  // 0 is the modules' safe state: never written
        std::uint16_t v = m_counter;
        if (!m_zero_done && t >= m_o.tamper.zero_output_at) {
          v = 0;
          m_zero_done = true;
        }
        for (std::size_t i = 0; i + 1 < piq.size(); i += 2) {
          piq[i] = static_cast<std::uint8_t>(v >> 8);
          piq[i + 1] = static_cast<std::uint8_t>(v);
        }
      },
      m_o.scan_time);
}

// ---- the per-frame checks ------------------------------------------------------------------

void HCampaignRun::on_frame(const bus::TapFrame& f) {
  const int l = f.line == m_bus[1].get() ? 1 : 0;
  // Two masters driving the switched outputs: from the pair's roles and the DP masters' modes.
  int drivers = 0;
  for (int r = 0; r < 2; ++r)
    if (m_h->pair().is_master(r) && m_sys->master(r).mode() == dp::MasterMode::Operate &&
        m_sys->attachment_powered(r))
      ++drivers;
  if (drivers >= 2) {
    if (m_obs.split) {
      ++m_r.split_frames;
    } else {
      ++m_r.second_master_frames;
      if (m_reported_step != m_steps.size())
        m_r.mismatches.push_back(fmt_time(f.end) + ": after '" + step_name() +
                                 "': two masters drive the switched outputs outside F6");
      m_reported_step = m_steps.size();
    }
  }
  // From the wire: Data_Exchange with outputs to a switched station (SRD without SAPs).
  fdl::Telegram t;
  if (fdl::decode(f.bytes, t) == fdl::DecodeError::None && t.is_request() && !t.dsap &&
      !t.data.empty() &&
      (fdl::fc_request_fn(t.fc) == fdl::RequestFn::SrdLow ||
       fdl::fc_request_fn(t.fc) == fdl::RequestFn::SrdHigh) &&
      (t.da == kSw[0] || t.da == kSw[1])) {
    ++m_r.dx_requests;
    // A request the FDL had already committed when the side stopped (its start bit lies after
    // the stop only by the idle time) is no new Data_Exchange: kCommitted of grace.
    // A frame that was on the wire at the stop is no new one either.
    const bool committed =
        f.end >= m_obs.stopped_at[l] && f.start < m_obs.stopped_at[l] + kCommitted;
    if (!m_obs.side_runs(l, f.start) && !committed) {
      ++m_r.stray_dx;
      if (m_stray_step != m_steps.size())
        m_r.mismatches.push_back(
            fmt_time(f.start) + ": after '" + step_name() + "': Data_Exchange to station " +
            std::to_string(t.da) + " on line " + std::to_string(l) +
            " whose DP master should not run (it runs in [" + fmt_time(m_obs.run_from[l]) + ", " +
            fmt_time(m_obs.run_until[l]) + "), frame " + fmt_time(f.start) + ".." +
            fmt_time(f.end) + ", stop at " + fmt_time(m_obs.stopped_at[l]) + ", FC " +
            std::to_string(t.fc) + ")");
      m_stray_step = m_steps.size();
    }
  }
  // The backplane outputs of the switched stations.
  for (int k = 0; k < 2; ++k) {
    Sw& s = m_sw[k];
    const auto out = s.model->outputs();
    const auto v = static_cast<std::uint16_t>((out[0] << 8) | out[1]);
    // Outputs 0 are allowed while no channel reaches the station or no CPU runs the program
    // (HOLD, both STOP: the DP master in Clear drives the safe state), until the first new
    // value after it.
    const bool none = (!m_obs.reach(k, 0, f.end) && !m_obs.reach(k, 1, f.end)) ||
                      m_obs.no_program(f.end);
    const bool thawed = !check_frozen(k, v, f.end);
    const campaign::CounterWatch::Sample c = s.watch.sample(v, none);
    if (thawed && (c.bad.empty() || !c.counted)) {
      ++m_r.pulses;
      if (m_r.pulse_reports.size() < 20)
        m_r.pulse_reports.push_back(fmt_time(f.end) + ": station " + std::to_string(kSw[k]) +
                                    " outputs changed during the IM's switchover (" +
                                    std::to_string(v) + " after " + std::to_string(s.frozen_value) +
                                    "), step '" + step_name() + "'");
    }
    if (!c.counted) continue;
    ++m_r.output_samples;
    if (v == 0 && m_obs.no_program(f.end)) ++m_r.cleared_samples;
    if (!c.bad.empty()) {
      ++m_r.pulses;
      if (m_r.pulse_reports.size() < 20)
        m_r.pulse_reports.push_back(fmt_time(f.end) + ": station " + std::to_string(kSw[k]) + " " +
                                    std::string(c.bad) + " (" + std::to_string(v) + " after " +
                                    std::to_string(c.previous) + "), step '" + step_name() + "'");
    }
  }
}

// ---- the IM's own switchover time (S5) ------------------------------------------------------

bool HCampaignRun::check_frozen(int k, std::uint16_t v, bus::Ticks t) {
  // §G.1 "inputs and outputs are frozen during the switchover" (S1, no pulse): while the new
  // interface is in BP_SWITCHOVER (its IM time running) nothing reaches the backplane. The old
  // primary hands over at the latest one link delay after the trigger (the switchover request's
  // way over the internal link), so the outputs are frozen from then until PRIMARY.
  Sw& s = m_sw[k];
  const auto& rs = s.model->redundant_slave();
  const auto& ims = rs.im_switchovers();
  if (ims.empty()) return true;
  const redundancy::ImSwitchover& im = ims.back();
  if (im.primary_at != bus::kNever || rs.role(im.iface) != redundancy::Role::BpSwitchover ||
      t <= im.trigger + rs.params().link_delay)
    return true;
  ++m_r.frozen_samples;
  if (s.frozen_im != ims.size()) {
    s.frozen_im = ims.size();
    s.frozen_value = v;
    return true;
  }
  return v == s.frozen_value;
}

void HCampaignRun::check_im_times() {
  // S5 (000 L1832: the switchover time includes "the changeover time of the DP slave
  // interface"): each switchover ends (PRIMARY) no earlier than its trigger + the IM time drawn
  // for it, and within the planner's bound from the fault the observer injected (the latest
  // cause on the lost line at or before the trigger): recognition + T_DP_UM + T_SLAVE_UM, the
  // recognition by the cause (a stopped side or failed DP master module: at once; a short
  // circuit: the line-loss recognition; one interface: that station's), T_SLAVE_UM at least the
  // switch timeout (a silent partner, PI 2.212 model: redundant_slave.hpp).
  for (int k = 0; k < 2; ++k) {
    const auto& rs = m_sw[k].model->redundant_slave();
    const redundancy::StationBound* sb = nullptr;
    for (const auto& b : m_plan.stations)
      if (b.address == kSw[k]) sb = &b;
    if (sb == nullptr) throw std::logic_error("h campaign: station not planned");
    const bus::Ticks t_slave = std::max(sb->t_slave_um, rs.params().switch_timeout);
    for (const auto& im : rs.im_switchovers()) {
      ++m_r.im_switchovers;
      m_r.max_im_drawn = std::max(m_r.max_im_drawn, im.drawn);
      if (im.primary_at == bus::kNever) continue;  // abandoned (the interface failed meanwhile)
      const bus::Ticks took = im.primary_at - im.trigger;
      m_r.max_im_switchover = std::max(m_r.max_im_switchover, took);
      const std::string what = fmt_time(im.trigger) + ": station " + std::to_string(kSw[k]) +
                               " switchover to line " + std::to_string(im.iface);
      if (took < im.drawn) {
        ++m_r.early_switchovers;
        m_r.mismatches.push_back(what + " early: PRIMARY after " + fmt_time(took) +
                                 " < the IM's drawn " + fmt_time(im.drawn));
      }
      const int lost = 1 - im.iface;
      const Cause* c = nullptr;
      for (const auto& x : m_causes)
        if (x.at <= im.trigger && x.line == lost &&
            (x.kind != CauseKind::Interface || x.station == k) && (c == nullptr || x.at >= c->at))
          c = &x;
      if (c == nullptr) {
        ++m_r.late_switchovers;
        m_r.mismatches.push_back(what + " without a fault on line " + std::to_string(lost));
        continue;
      }
      ++m_r.im_by_cause[static_cast<std::size_t>(c->kind)];
      bus::Ticks recognition = 0;
      if (c->kind == CauseKind::LineLoss) recognition = m_plan.line[lost].line_loss_recognition;
      if (c->kind == CauseKind::Interface) recognition = sb->recognition[lost];
      const bus::Ticks bound = recognition + sb->t_dp_um[lost] + t_slave;
      const bus::Ticks from_fault = im.primary_at - c->at;
      m_r.max_fault_switchover = std::max(m_r.max_fault_switchover, from_fault);
      m_r.min_bound_margin = std::min(m_r.min_bound_margin, bound - from_fault);
      if (from_fault > bound) {
        ++m_r.late_switchovers;
        m_r.mismatches.push_back(what + " late: PRIMARY " + fmt_time(from_fault) +
                                 " after the fault at " + fmt_time(c->at) + " > bound " +
                                 fmt_time(bound) + " (IM drawn " + fmt_time(im.drawn) + ")");
      }
    }
  }
}

// ---- the observer's rules ------------------------------------------------------------------

void HCampaignRun::switch_away(int l) {
  const bus::Ticks t = now();
  for (int k = 0; k < 2; ++k)
    if (m_obs.act[k] == l && m_obs.reach(k, 1 - l, t)) m_obs.act[k] = 1 - l;
}

void HCampaignRun::lose_side(int r, bus::Ticks t, std::vector<Expect>& ex) {
  const bool ran = m_obs.side_runs(r, t);
  m_obs.run_until[r] = t;
  m_obs.stopped_at[r] = t;
  m_obs.prog_until[r] = std::min(m_obs.prog_until[r], t);
  if (!ran) return;
  cause(t, r, CauseKind::SideStop);
  ex.push_back(io(0x39C3, r, 0xFF, t, t));
  for (int k = 0; k < 2; ++k)
    if (m_obs.act[k] == r && m_obs.iface_ok[k][1 - r] && m_obs.line_ok(1 - r)) m_obs.act[k] = 1 - r;
}

void HCampaignRun::expect_error_search(int r, bus::Ticks t, bool repeated,
                                      std::vector<Expect>& ex) {
  const int p = 1 - r;
  m_obs.prog_until[r] = t;
  set_master(p);
  lose_side(r, t, ex);
  if (repeated) return;
  restart_side(r, t + m_o.self_test_time, ex);
  const bus::Ticks te = m_obs.prog_from[r];
  ex.push_back(cpu_ob(72, r, CpuRole::Master, HReason::MasterSwap, te));
  ex.push_back(cpu_ob(72, p, CpuRole::Standby, HReason::MasterSwap, te));
  m_obs.swap_at = te;
  set_master(r);
}

void HCampaignRun::restart_side(int r, bus::Ticks t0, std::vector<Expect>& ex) {
  const bus::Ticks up = t0 + m_params.link_up_time;
  m_obs.run_from[r] = up;
  m_obs.run_until[r] = bus::kNever;
  m_obs.prog_from[r] = up + update_w();
  m_obs.prog_until[r] = bus::kNever;
  ex.push_back(io(0x38C3, r, 0xFF, up, up));  // the OB runs on the master: r is in UPDATE
}

// ---- steps ---------------------------------------------------------------------------------

void HCampaignRun::begin_step(std::string what, bool repair, std::vector<Expect> ex) {
  Step s;
  s.at = now();
  s.repair = repair;
  s.what = std::move(what);
  // An I/O event while no CPU runs a program is only a diagnostic entry (no OB, not in
  // events()): the observer expects nothing then.
  for (auto& x : ex)
    if (x.src != Src::Io || x.rack != -2) s.expect.push_back(std::move(x));
  m_r.expected_events += static_cast<int>(s.expect.size());
  m_steps.push_back(std::move(s));
  if (repair)
    ++m_r.repairs;
  else
    ++m_r.faults;
}

bool HCampaignRun::satisfied(const Step& s) const {
  std::vector<bool> used(s.expect.size(), false);
  const auto& all = m_h->events();
  // Events are in time order; the step's begin at s.at (the injection ran just before).
  const auto first = std::lower_bound(
      all.begin(), all.end(), s.at, [](const HSystemEvent& e, bus::Ticks t) { return e.time < t; });
  for (std::size_t n = static_cast<std::size_t>(first - all.begin()); n < all.size(); ++n)
    for (std::size_t i = 0; i < s.expect.size(); ++i)
      if (!used[i] && same(s.expect[i], all[n])) {
        used[i] = true;
        break;
      }
  return std::all_of(used.begin(), used.end(), [](bool b) { return b; });
}

void HCampaignRun::settle_step() {
  const Step& s = m_steps.back();
  bus::Ticks limit = s.at;
  for (const auto& x : s.expect) limit = std::max(limit, x.latest);
  while (!satisfied(s) && now() <= limit) run_to(std::min(limit + 1, now() + 5 * kMs));
}

bool HCampaignRun::recovered() const {
  using St = dp::SlaveStatusState;
  const HCpuPair& p = m_h->pair();
  if (p.system_mode() != SystemMode::Redundant || p.state(0) != CpuState::Run ||
      p.state(1) != CpuState::Run)
    return false;
  const bus::Ticks t = now();
  for (int k = 0; k < 2; ++k) {
    for (int l = 0; l < 2; ++l) {
      if (!m_obs.reach(k, l, t)) continue;
      if (m_sys->master(l).slave_state(kSw[k]) != St::DataExchange) return false;
      const auto role = m_sw[k].model->role(l);
      if (role != redundancy::Role::Primary && role != redundancy::Role::Backup) return false;
    }
    if (m_sw[k].model->primary() < 0) return false;
    // The switchover is over when the master system has seen the new PRIMARY in the station's
    // Red_Status (the diagnosis read after the DH that the role change causes): with the IM's
    // own time (S5) the station may become PRIMARY just before a poll of this loop, the
    // master's diagnosis read a few ms later.
    if (m_sys->system().active(kSw[k]) < 0 || m_sys->system().switching_to(kSw[k]) >= 0)
      return false;
  }
  for (int l = 0; l < 2; ++l)
    if (m_obs.line_ok(l) && m_obs.side_runs(l, t) &&
        m_sys->master(l).slave_state(kOne[l]) != St::DataExchange)
      return false;
  return true;
}

void HCampaignRun::wait_recovered(bus::Ticks since) {
  const bus::Ticks limit = since + m_o.settle_limit;
  while (!recovered() && now() < limit) run_to(now() + 10 * kMs);
  if (!recovered()) {
    m_r.mismatches.push_back(fmt_time(now()) + ": after '" + step_name() +
                             "': not back in Redundant mode with every channel in data exchange "
                             "within " +
                             fmt_time(m_o.settle_limit));
    return;
  }
  m_r.max_settle = std::max(m_r.max_settle, now() - since);
}

void HCampaignRun::check_roles() {
  const HCpuPair& p = m_h->pair();
  if (p.master_count() != 1 || p.master() != m_obs.master)
    m_r.mismatches.push_back(fmt_time(now()) + ": after '" + step_name() + "': expected master " +
                             rack_name(m_obs.master) + ", the pair has " +
                             std::to_string(p.master_count()) + " master(s), master() " +
                             std::to_string(p.master()));
  for (int k = 0; k < 2; ++k) {
    const int prim = m_sw[k].model->primary();
    const int sys = m_sys->system().active(kSw[k]);
    if (prim != m_obs.act[k] || sys != m_obs.act[k])
      m_r.mismatches.push_back(
          fmt_time(now()) + ": after '" + step_name() + "': station " + std::to_string(kSw[k]) +
          " expected active line " + std::to_string(m_obs.act[k]) + ", station primary " +
          std::to_string(prim) + ", MasterSystem active " + std::to_string(sys));
  }
}

void HCampaignRun::match_all() {
  std::vector<HSystemEvent> all = m_h->events();
  if (m_o.tamper.doctor_events) m_o.tamper.doctor_events(all);
  // OB 85 (process-image transfer error) comes at the first OB 1 that misses a slave, on the
  // model's scan grid, which this observer does not model: it is checked for consistency
  // instead (only one-sided slaves, incoming and outgoing alternating per station, each
  // episode closed once the system is back) and kept out of the per-step matching.
  std::vector<HSystemEvent> ev;
  std::map<int, bool> ob85_open;
  for (const auto& e : all) {
    if (e.source != Src::Image) {
      ev.push_back(e);
      continue;
    }
    ++m_r.ob85;
    const bool one_sided = e.station == kOne[0] || e.station == kOne[1];
    const bool in = e.code == 0x39B1;
    bool& open = ob85_open[e.station];
    if (!one_sided || e.ob != 85 || (e.code != 0x39B1 && e.code != 0x38B1) || open == in)
      m_r.mismatches.push_back(fmt_time(e.time) + ": OB 85 out of order or for a switched station: " + fmt(e));
    open = in;
  }
  for (const auto& [station, open] : ob85_open)
    if (open)
      m_r.mismatches.push_back("OB 85 for station " + std::to_string(station) + " never went outgoing");
  m_r.observed_events = static_cast<int>(ev.size());
  std::size_t i = 0;
  for (std::size_t si = 0; si < m_steps.size(); ++si) {
    const Step& s = m_steps[si];
    const bus::Ticks end = si + 1 < m_steps.size() ? m_steps[si + 1].at : bus::kNever;
    while (i < ev.size() && ev[i].time < s.at) {
      m_r.mismatches.push_back(fmt_time(ev[i].time) + ": event " + fmt(ev[i]) + " out of any step");
      ++i;
    }
    std::vector<const HSystemEvent*> seen;
    while (i < ev.size() && ev[i].time < end) seen.push_back(&ev[i++]);
    std::vector<bool> used(seen.size(), false);
    std::vector<std::string> missing, late;
    for (const auto& x : s.expect) {
      bool found = false;
      for (std::size_t j = 0; j < seen.size() && !found; ++j) {
        if (used[j] || !same(x, *seen[j])) continue;
        used[j] = found = true;
        if (seen[j]->time < x.earliest || seen[j]->time > x.latest)
          late.push_back(fmt(x) + " at " + fmt_time(seen[j]->time) + ", expected " +
                         fmt_time(x.earliest) + ".." + fmt_time(x.latest));
      }
      if (!found) missing.push_back(fmt(x));
    }
    std::vector<std::string> extra;
    for (std::size_t j = 0; j < seen.size(); ++j)
      if (!used[j]) extra.push_back(fmt(*seen[j]) + " at " + fmt_time(seen[j]->time));
    if (missing.empty() && late.empty() && extra.empty()) continue;
    std::string m = fmt_time(s.at) + ": " + s.what + ":";
    for (const auto& x : missing) m += " missing " + x + ";";
    for (const auto& x : extra) m += " unexpected " + x + ";";
    for (const auto& x : late) m += " out of time " + x + ";";
    m_r.mismatches.push_back(std::move(m));
  }
}

// ---- the fault cycles ----------------------------------------------------------------------

void HCampaignRun::cycle(HFault f) {
  const std::string name(to_string(f));
  const int M = m_obs.master, S = 1 - M;
  const bus::Ticks t = now();
  std::vector<Expect> ex;
  bus::Ticks since = t;  // when the last repair began (the settle time counts from it)
  switch (f) {
    case HFault::MasterPower:
    case HFault::StandbyPower:
    case HFault::MasterStop:
    case HFault::StandbyStop: {
      const bool power = f == HFault::MasterPower || f == HFault::StandbyPower;
      const bool of_master = f == HFault::MasterPower || f == HFault::MasterStop;
      const int r = of_master ? M : S;
      // Leaving Redundant (§1, F1): the partner of a lost master is master, OB 72 on it; a lost
      // standby: OB 72 on the master.
      const HReason why = of_master ? (power ? HReason::MasterLost : HReason::MasterStop)
                                    : (power ? HReason::StandbyLost : HReason::StandbyStop);
      m_obs.prog_until[r] = t;
      ex.push_back(cpu_ob(72, 1 - r, CpuRole::Master, why, t));
      lose_side(r, t, ex);
      if (of_master) set_master(S);
      if (power)
        m_h->power_off(r);
      else
        m_h->switch_to_stop(r);
      begin_step(name + ": " + rack_name(r), false, std::move(ex));
      settle_step();
      dwell();
      since = now();
      ex.clear();
      restart_side(r, since, ex);  // the returning CPU is standby (F1)
      if (power)
        m_h->power_on(r);
      else
        m_h->switch_to_run(r);
      begin_step(std::string(power ? "power on " : "RUN ") + rack_name(r), true, std::move(ex));
      break;
    }
    case HFault::OneFibre: {
      const int fi = draw_int(0, 1);
      m_obs.prog_until[S] = t;
      ex.push_back(cpu_ob(72, M, CpuRole::Master, HReason::LinkLost, t));
      lose_side(S, t, ex);  // F5: the standby STOPs
      m_h->cut_fibre(fi);
      begin_step(name + ": fibre " + std::to_string(fi), false, std::move(ex));
      settle_step();
      dwell();
      since = now();
      ex.clear();
      restart_side(S, since, ex);
      m_h->repair_fibre(fi);
      m_h->switch_to_run(S);
      begin_step("repair fibre " + std::to_string(fi) + ", RUN " + rack_name(S), true,
                 std::move(ex));
      break;
    }
    case HFault::BothFibres: {
      // F6: both CPUs log OB 72 and both are master in RUN; no side stops.
      ex.push_back(cpu_ob(72, M, CpuRole::Master, HReason::LinkLost, t));
      ex.push_back(cpu_ob(72, S, CpuRole::Master, HReason::LinkLost, t));
      m_obs.split = true;
      m_h->cut_both_fibres();
      begin_step(name, false, std::move(ex));
      settle_step();
      dwell();
      // Repair: both fibres, then one of the masters to STOP: it becomes standby (no OB 72:
      // the system was not redundant), its side is lost (39C3).
      const int x = draw_int(0, 1);
      const bus::Ticks t1 = now();
      ex.clear();
      m_obs.split = false;
      m_obs.prog_until[x] = t1;
      lose_side(x, t1, ex);
      set_master(1 - x);
      m_h->repair_fibre(0);
      m_h->repair_fibre(1);
      m_h->switch_to_stop(x);
      begin_step("repair both fibres, STOP " + rack_name(x), true, std::move(ex));
      settle_step();
      run_to(now() + draw(100 * kMs, 300 * kMs));
      since = now();
      ex.clear();
      restart_side(x, since, ex);
      m_h->switch_to_run(x);
      begin_step("RUN " + rack_name(x), true, std::move(ex));
      break;
    }
    case HFault::ActiveIm:
    case HFault::PassiveIm: {
      const int k = draw_int(0, 1);
      const int l = f == HFault::ActiveIm ? m_obs.act[k] : 1 - m_obs.act[k];
      m_obs.iface_ok[k][l] = false;
      cause(t, l, CauseKind::Interface, k);
      ex.push_back(io(0x73A3, l, kSw[k], t, t + m_o.recognition));
      if (m_obs.act[k] == l) m_obs.act[k] = 1 - l;
      m_sw[k].model->fail_interface(l);
      begin_step(name + ": station " + std::to_string(kSw[k]) + " line " + std::to_string(l), false,
                 std::move(ex));
      settle_step();
      dwell();
      since = now();
      ex.clear();
      m_obs.iface_ok[k][l] = true;
      ex.push_back(io(0x72A3, l, kSw[k], since, since + m_o.startup));  // no switch back
      m_sw[k].model->repair_interface(l);
      begin_step("repair station " + std::to_string(kSw[k]) + " line " + std::to_string(l), true,
                 std::move(ex));
      break;
    }
    case HFault::ShortCircuit:
    case HFault::DpMasterFailure: {
      const int l = draw_int(0, 1);
      const bool sc = f == HFault::ShortCircuit;
      if (sc) {  // F14: only 39C3, every station switches
        m_obs.shorted[l] = true;
        ex.push_back(io(0x39C3, l, 0xFF, t, t + m_o.recognition));
      } else {  // F9: per station, the switched ones served by the partner
        m_obs.mfail[l] = true;
        for (int k = 0; k < 2; ++k) ex.push_back(io(0x73A3, l, kSw[k], t, t + m_o.recognition));
        ex.push_back(io(0x39C4, l, kOne[l], t, t + m_o.recognition));
      }
      switch_away(l);
      cause(t, l, sc ? CauseKind::LineLoss : CauseKind::SideStop);
      if (sc) {
        m_bus[l]->set_short_circuit(true);
      } else {
        m_sys->fail_master(l);
        m_h->reconcile();
      }
      begin_step(name + ": line " + std::to_string(l), false, std::move(ex));
      settle_step();
      dwell();
      since = now();
      ex.clear();
      if (sc) {
        m_obs.shorted[l] = false;
        ex.push_back(io(0x38C3, l, 0xFF, since, since + m_o.startup));
        m_bus[l]->set_short_circuit(false);
      } else {
        m_obs.mfail[l] = false;
        for (int k = 0; k < 2; ++k) ex.push_back(io(0x72A3, l, kSw[k], since, since + m_o.startup));
        ex.push_back(io(0x38C4, l, kOne[l], since, since + m_o.startup));
        m_sys->repair_master(l);
        m_h->reconcile();
      }
      begin_step("repair line " + std::to_string(l), true, std::move(ex));
      break;
    }
    case HFault::ComparisonError: {
      // F16: standby -> ERROR-SEARCH, OB 72 on the master; again within the first self-test
      // cycle after a search: standby STOP (000).
      const bool repeated =
          m_obs.swap_at != bus::kNever && t - m_obs.swap_at < m_o.cyclic_self_test_period;
      m_obs.swap_at = bus::kNever;
      m_obs.prog_until[S] = t;
      ex.push_back(cpu_ob(72, M, CpuRole::Master, HReason::ComparisonError, t));
      lose_side(S, t, ex);
      if (!repeated) {
        // R5: no fault found -> re-link, and the searched CPU becomes master after the update.
        restart_side(S, t + m_o.self_test_time, ex);
        const bus::Ticks te = m_obs.prog_from[S];
        ex.push_back(cpu_ob(72, S, CpuRole::Master, HReason::MasterSwap, te));
        ex.push_back(cpu_ob(72, M, CpuRole::Standby, HReason::MasterSwap, te));
        m_obs.swap_at = te;
        set_master(S);
      }
      if (!m_h->inject_comparison_error())
        m_r.mismatches.push_back(fmt_time(t) + ": comparison error refused in Redundant mode");
      begin_step(name + (repeated ? " (again: standby STOP)" : ""), false, std::move(ex));
      settle_step();
      if (repeated) {
        ++m_r.comparison_stops;
        dwell();
        since = now();
        ex.clear();
        restart_side(S, since, ex);
        m_h->switch_to_run(S);
        begin_step("RUN " + rack_name(S), true, std::move(ex));
      }
      break;
    }
    case HFault::OneSidedOb121: {
      const int r = draw_int(0, 1), p = 1 - r;
      const bool repeated = m_obs.last121[r] && t - *m_obs.last121[r] <= kDefectiveWindow;
      m_obs.last121[r] = t;
      ex.push_back(
          cpu_ob(121, r, r == M ? CpuRole::Master : CpuRole::Standby, HReason::OneSidedOb121, t));
      ex.push_back(cpu_ob(72, p, CpuRole::Master, HReason::OneSidedOb121, t));
      expect_error_search(r, t, repeated, ex);
      if (!m_h->one_sided_ob121(r))
        m_r.mismatches.push_back(fmt_time(t) + ": one-sided OB 121 refused in Redundant mode");
      begin_step(name + ": " + rack_name(r) + (repeated ? " (again: DEFECTIVE)" : ""), false,
                 std::move(ex));
      settle_step();
      if (repeated) {
        ++m_r.defective;
        dwell();
        since = now();
        ex.clear();
        m_obs.last121[r].reset();  // the CPU is replaced: no history
        m_obs.last_checksum[r].reset();
        restart_side(r, since, ex);
        m_h->repair_cpu(r);
        m_h->switch_to_run(r);
        begin_step("replace CPU " + rack_name(r) + ", RUN", true, std::move(ex));
      }
      break;
    }
    case HFault::MasterHold:
    case HFault::LoadMemoryError:
    case HFault::SyncError:
    case HFault::UpdateTimeout:
    case HFault::StandbyLostDuringLinkUp:
    case HFault::LoadChange:
    case HFault::ParameterChangeSwap:
      since = cycle_link(f);
      break;
    case HFault::PsHalf:
    case HFault::ChecksumError:
    case HFault::SecondFibre:
    case HFault::UpdateBlocked:
      since = cycle_later(f);
      break;
    case HFault::MasterSwap: {
      // The operator: the standby's switch to STOP, the swap request (the standby links up and
      // becomes master at the end of the update, the old master STOPs), then RUN again.
      m_obs.prog_until[S] = t;
      ex.push_back(cpu_ob(72, M, CpuRole::Master, HReason::StandbyStop, t));
      lose_side(S, t, ex);
      m_h->switch_to_stop(S);
      begin_step("master swap: STOP " + rack_name(S), false, std::move(ex));
      settle_step();
      run_to(now() + draw(100 * kMs, 300 * kMs));
      const bus::Ticks t1 = now();
      ex.clear();
      restart_side(S, t1, ex);
      const bus::Ticks te = m_obs.prog_from[S];
      ex.push_back(cpu_ob(72, S, CpuRole::Master, HReason::MasterSwap, te));
      m_obs.prog_until[M] = te;
      m_obs.run_until[M] = te;
      cause(te, M, CauseKind::SideStop);
      {
        Expect x = io(0x39C3, M, 0xFF, te, te);
        x.rack = S;  // at te only the new master runs the program
        ex.push_back(x);
      }
      set_master(S);
      if (!m_h->request_master_swap())
        m_r.mismatches.push_back(fmt_time(t1) + ": master swap request refused");
      begin_step("master swap: request", false, std::move(ex));
      settle_step();
      for (int k = 0; k < 2; ++k)
        if (m_obs.act[k] == M && m_obs.iface_ok[k][S] && m_obs.line_ok(S)) m_obs.act[k] = S;
      run_to(now() + draw(100 * kMs, 300 * kMs));
      since = now();
      ex.clear();
      restart_side(M, since, ex);
      m_h->switch_to_run(S);  // its mode switch back to RUN (it runs already)
      m_h->switch_to_run(M);
      begin_step("master swap: RUN " + rack_name(M), true, std::move(ex));
      break;
    }
  }
  settle_step();
  wait_recovered(since);
  check_roles();
}

// ---- the link-up/update faults -------------------------------------------------------------

void HCampaignRun::stop_standby(const std::string& what) {
  const int S = 1 - m_obs.master;
  const bus::Ticks t = now();
  std::vector<Expect> ex;
  m_obs.prog_until[S] = t;
  ex.push_back(cpu_ob(72, m_obs.master, CpuRole::Master, HReason::StandbyStop, t));
  lose_side(S, t, ex);
  m_h->switch_to_stop(S);
  begin_step(what + ": STOP " + rack_name(S), false, std::move(ex));
  settle_step();
}

void HCampaignRun::expect_diag(int rack, bus::Ticks at, std::uint16_t code, std::string_view text) {
  ++m_r.diag_checks;
  for (const auto& d : m_h->diag_buffer(rack))
    if (d.at == at && d.code == code && d.text.compare(0, text.size(), text) == 0) return;
  char buf[16];
  std::snprintf(buf, sizeof buf, "%04X", code);
  mismatch("no diagnostic entry W#16#" + std::string(buf) + " '" + std::string(text) + "' on " +
           rack_name(rack) + " at " + fmt_time(at));
}

bus::Ticks HCampaignRun::cycle_link(HFault f) {
  const std::string name(to_string(f));
  const int M = m_obs.master, S = 1 - M;
  std::vector<Expect> ex;
  bus::Ticks since = now();
  switch (f) {
    case HFault::MasterHold: {
      // HOLD is reachable only for the master in STARTUP or Solo RUN (digest §4): refused now.
      ++m_r.refusals;
      if (m_h->hold(M)) mismatch("HOLD of the master accepted in Redundant mode");
      stop_standby(name);
      pause();
      // HOLD: no OB 1 from now on; the master's DP master goes Clear (outputs 0 allowed).
      m_obs.prog_until[M] = now();
      if (!m_h->hold(M)) mismatch("HOLD of the master refused in Solo RUN");
      begin_step("HOLD " + rack_name(M), false, {});
      pause();
      // R4: no link-up while the master is in HOLD: the standby stays in STOP, no event; the
      // refusal is in the master's buffer.
      const bus::Ticks tr = now();
      m_h->switch_to_run(S);
      begin_step("RUN " + rack_name(S) + " (refused: master in HOLD)", true, {});
      ++m_r.refusals;
      expect_diag(M, tr, 0, "link-up request of the standby CPU refused: HOLD");
      dwell();
      m_obs.prog_from[M] = now();
      m_obs.prog_until[M] = bus::kNever;
      if (!m_h->release_hold(M)) mismatch("release of HOLD refused");
      begin_step("release HOLD " + rack_name(M), true, {});
      pause();
      // The refused start is not remembered: a new STOP -> RUN links up.
      since = now();
      restart_side(S, since, ex);
      m_h->switch_to_run(S);
      begin_step("RUN " + rack_name(S), true, std::move(ex));
      break;
    }
    case HFault::LoadMemoryError: {
      // F2 on rack r: as a STOP of r (the partner's OB 72), plus a reset request.
      const int r = draw_int(0, 1);
      const bool of_master = r == M;
      const bus::Ticks t = now();
      m_obs.prog_until[r] = t;
      ex.push_back(cpu_ob(72, 1 - r, CpuRole::Master,
                          of_master ? HReason::MasterStop : HReason::StandbyStop, t));
      lose_side(r, t, ex);
      if (of_master) set_master(1 - r);
      if (!m_h->load_memory_error(r)) mismatch("load-memory error refused");
      begin_step(name + ": " + rack_name(r), false, std::move(ex));
      settle_step();
      dwell();
      // The reset request: no start before a memory reset (no link-up, no 38C3).
      m_h->switch_to_run(r);
      begin_step("RUN " + rack_name(r) + " (refused: reset request)", true, {});
      ++m_r.refusals;
      pause();
      since = now();
      ex.clear();
      if (!m_h->memory_reset(r)) mismatch("memory reset refused");
      restart_side(r, since, ex);
      m_h->switch_to_run(r);
      begin_step("MRES + RUN " + rack_name(r), true, std::move(ex));
      break;
    }
    case HFault::SyncError: {
      const bus::Ticks t = now();
      m_obs.prog_until[S] = t;
      ex.push_back(cpu_ob(72, M, CpuRole::Master, HReason::StandbyStop, t));
      lose_side(S, t, ex);
      if (!m_h->inject_sync_error()) mismatch("sync error refused in Redundant mode");
      begin_step(name, false, std::move(ex));
      for (int r = 0; r < 2; ++r) expect_diag(r, t, 0, "sync error (F18)");
      settle_step();
      dwell();
      since = now();
      ex.clear();
      restart_side(S, since, ex);
      m_h->switch_to_run(S);
      begin_step("RUN " + rack_name(S), true, std::move(ex));
      break;
    }
    case HFault::UpdateTimeout: {
      // The program changed many DBs: W > T_P15. Each update aborts at t3 + T_P15 (t3 = the
      // start of UPDATE), the standby retries exactly 60 s after the abort (R6).
      m_obs.kb = m_o.update_timeout_kb;
      m_h->set_changed_db_kb(m_obs.kb);
      stop_standby(name + ": " + std::to_string(m_obs.kb) + " KB changed");
      dwell();
      const int fails = draw_int(1, m_o.update_timeout_failures_max);
      const bus::Ticks abort_after = update_abort_after(m_obs.kb);
      bus::Ticks link = now();
      for (int i = 0; i < fails; ++i) {
        restart_side(S, link, ex);  // 38C3 at the start of UPDATE
        const bus::Ticks t_abort = link + m_params.link_up_time + abort_after;
        ex.push_back(cpu_ob(72, M, CpuRole::Master, HReason::UpdateTimeout, t_abort));
        lose_side(S, t_abort, ex);  // the standby STOPs: 39C3 of its line
        ++m_r.update_timeouts;
        link = t_abort + to_ticks(kUpdateRetryDelay);
      }
      m_h->switch_to_run(S);
      begin_step("RUN " + rack_name(S) + " (" + std::to_string(fails) + " update(s) time out)",
                 true, std::move(ex));
      settle_step();
      pause();
      ex.clear();
      m_obs.kb = m_params.update_db_kb;
      m_h->set_changed_db_kb(m_obs.kb);
      if (fails < kUpdateMaxTries) {
        // The repair: the changed DBs back to normal before the automatic retry at `link`.
        since = link;
        restart_side(S, link, ex);
        begin_step("changed DBs back to " + std::to_string(m_obs.kb) + " KB, retry at " +
                       fmt_time(link),
                   true, std::move(ex));
      } else {
        // kUpdateMaxTries failed: no retry left, the link-up must be restarted by hand.
        since = now();
        restart_side(S, since, ex);
        m_h->switch_to_run(S);
        begin_step("changed DBs back to " + std::to_string(m_obs.kb) + " KB, RUN " +
                       rack_name(S),
                   true, std::move(ex));
      }
      break;
    }
    case HFault::StandbyLostDuringLinkUp: {
      stop_standby(name);
      pause();
      // LINK-UP starts: the standby's side does not run yet (no event before its UPDATE).
      const bus::Ticks t1 = now();
      m_h->switch_to_run(S);
      begin_step("RUN " + rack_name(S) + " (LINK-UP)", true, {});
      // Power off inside the load-memory copy (the first half of LINK-UP, T8): no OB 72 (the
      // system is Solo), no 39C3 (its side never ran), the reset request W#16#6523.
      const bus::Ticks copy = m_params.link_up_time / 2;
      run_to(t1 + draw(10 * kMs, copy - 10 * kMs));
      const bus::Ticks t2 = now();
      m_h->power_off(S);
      begin_step("power off " + rack_name(S) + " in LINK-UP at +" + fmt_time(t2 - t1), false,
                 {});
      expect_diag(S, t2, 0x6523, "reset request");
      dwell();
      since = now();
      m_h->power_on(S);
      if (!m_h->memory_reset(S)) mismatch("memory reset refused");
      restart_side(S, since, ex);
      m_h->switch_to_run(S);
      begin_step("power on + MRES + RUN " + rack_name(S), true, std::move(ex));
      break;
    }
    case HFault::LoadChange: {
      // F22: both CPUs STOP, no OB 72 (nobody runs). The standby's side stops; its 39C3 is no
      // OB (no program runs). The master's DP master stays (a master in STOP accesses the
      // switched I/O) in Clear: the outputs go to the safe state.
      const HChange kind = draw_int(0, 1) ? HChange::GlobalDb : HChange::StructuralFbInterface;
      const bus::Ticks t = now();
      m_obs.prog_until[M] = t;
      m_obs.prog_until[S] = t;
      lose_side(S, t, ex);
      if (m_h->load_change(kind) != HChangeResult::BothStopped)
        mismatch("structural change in Redundant mode did not stop both CPUs");
      begin_step(name + ": " + std::string(to_string(kind)), false, std::move(ex));
      settle_step();
      dwell();
      // Both switches STOP -> RUN at once: the master's STARTUP, then the standby's link-up.
      since = now();
      ex.clear();
      m_obs.prog_from[M] = since + m_params.startup_time;
      m_obs.prog_until[M] = bus::kNever;
      restart_side(S, since + m_params.startup_time, ex);
      m_h->switch_to_run(M);
      m_h->switch_to_run(S);
      begin_step("RUN both racks", true, std::move(ex));
      break;
    }
    case HFault::ParameterChangeSwap: {
      stop_standby(name);
      pause();
      const bus::Ticks t1 = now();
      m_h->set_standby_parameter_change(true);
      ++m_r.refusals;
      if (m_h->request_master_swap()) mismatch("master swap accepted with a changed parameter");
      begin_step("master swap request (refused)", false, {});
      for (int r = 0; r < 2; ++r) expect_diag(r, t1, 0x5966, "master swap refused");
      dwell();
      since = now();
      m_h->set_standby_parameter_change(false);
      restart_side(S, since, ex);
      m_h->switch_to_run(S);
      begin_step("parameter change undone, RUN " + rack_name(S), true, std::move(ex));
      break;
    }
    default:
      break;
  }
  return since;
}

// ---- the later fault paths (PS halves, checksum errors, F5's second link, SFC 90) ----------

bus::Ticks HCampaignRun::cycle_later(HFault f) {
  const std::string name(to_string(f));
  const int M = m_obs.master, S = 1 - M;
  const bus::Ticks t = now();
  std::vector<Expect> ex;
  bus::Ticks since = t;
  switch (f) {
    case HFault::PsHalf: {
      // 000 L465, L2517, 001 L8387-8390: "if a part of the redundant PS fails, the
      // corresponding CPU keeps on running": no state, role or OB event, only the entry
      // W#16#3923 (docs/h-changes.md's decision) on that CPU. Both halves: F1.
      const int r = draw_int(0, 1), h = draw_int(0, 1);
      const bool both = draw_int(0, 1) == 1;
      const std::string half = " half " + std::to_string(h);
      const bool off = m_h->ps_failure(r, h);
      begin_step(name + ": " + rack_name(r) + half, false, {});
      if (off) mismatch("the CPU failed with the other PS half still supplying it");
      expect_diag(r, t, kPsFailureIncoming,
                  "OB 81: power supply failure (PS 407 10A R" + half + ")");
      dwell();
      if (both) {
        // The other half fails too: no supply left, as power_off (F1): OB 72 MasterLost /
        // StandbyLost on the partner, the lost master's partner is master.
        const bus::Ticks t2 = now();
        const bool of_master = r == m_obs.master;
        m_obs.prog_until[r] = t2;
        ex.push_back(cpu_ob(72, 1 - r, CpuRole::Master,
                            of_master ? HReason::MasterLost : HReason::StandbyLost, t2));
        lose_side(r, t2, ex);
        if (of_master) set_master(1 - r);
        const bool off2 = m_h->ps_failure(r, 1 - h);
        begin_step("the other half of " + rack_name(r) + "'s PS fails (F1)", false,
                   std::move(ex));
        if (!off2) mismatch("the CPU kept running with both PS halves failed");
        ++m_r.ps_cpu_failures;
        settle_step();
        dwell();
        // That half replaced: power returns, the CPU starts as standby (link-up, update).
        since = now();
        ex.clear();
        restart_side(r, since, ex);
        const bool on = m_h->ps_repair(r, 1 - h);
        begin_step("replace half " + std::to_string(1 - h) + " of " + rack_name(r) +
                       " (power back)",
                   true, std::move(ex));
        if (!on) mismatch("PS half replacement refused");
        settle_step();  // the 38C3 at the start of its UPDATE lies in this step
        pause();
      }
      const bus::Ticks t3 = now();
      const bool rep = m_h->ps_repair(r, h);
      begin_step("replace" + half + " of " + rack_name(r) + "'s PS", true, {});
      if (!rep) mismatch("PS half replacement refused");
      expect_diag(r, t3, kPsFailureOutgoing, "OB 81: power supply failure gone");
      if (!both) since = t3;
      break;
    }
    case HFault::ChecksumError: {
      // 001 L4023-4065, Table 5-6: found by the cyclic self-test in Redundant -> corrected, that
      // CPU ERROR-SEARCH, the partner Solo (master if needed, 001 L3910-3913) with OB 72
      // ChecksumError; then as F16/F17 (rule 10): re-link, automatic swap to the searched CPU.
      // Again on that CPU within 7 days -> DEFECTIVE (001 L4063): repair by replacing it.
      const int r = draw_int(0, 1), p = 1 - r;
      const bool repeated =
          m_obs.last_checksum[r] && t - *m_obs.last_checksum[r] <= kDefectiveWindow;
      m_obs.last_checksum[r] = t;
      ex.push_back(cpu_ob(72, p, CpuRole::Master, HReason::ChecksumError, t));
      expect_error_search(r, t, repeated, ex);
      const bool ok = m_h->checksum_error(r);
      begin_step(name + ": " + rack_name(r) + (repeated ? " (again: DEFECTIVE)" : ""), false,
                 std::move(ex));
      if (!ok) mismatch("checksum error refused in Redundant mode");
      expect_diag(r, t, 0,
                  repeated ? "checksum error repeated within 7 days"
                           : "checksum error in the cyclic self-test: corrected, ERROR-SEARCH");
      settle_step();
      if (repeated) {
        ++m_r.checksum_defective;
        dwell();
        since = now();
        ex.clear();
        m_obs.last_checksum[r].reset();  // the CPU is replaced: no history (repair_cpu)
        m_obs.last121[r].reset();
        restart_side(r, since, ex);
        m_h->repair_cpu(r);
        m_h->switch_to_run(r);
        begin_step("replace CPU " + rack_name(r) + ", RUN", true, std::move(ex));
      }
      break;
    }
    case HFault::SecondFibre: {
      // 000 L2594-2597: both fibres damaged one after the other: the reactions of F5, "the only
      // exception is that the standby CPU does not go to STOP mode but instead requests a
      // reset" - it is in STOP already (the first fibre, F5): the second gives the reset
      // request, no OB (Solo, nothing more is lost), no role change.
      const int fi = draw_int(0, 1);
      m_obs.prog_until[S] = t;
      ex.push_back(cpu_ob(72, M, CpuRole::Master, HReason::LinkLost, t));
      lose_side(S, t, ex);
      m_h->cut_fibre(fi);
      begin_step(name + ": fibre " + std::to_string(fi), false, std::move(ex));
      settle_step();
      dwell();
      const bus::Ticks t2 = now();
      m_h->cut_fibre(1 - fi);
      begin_step("second fibre " + std::to_string(1 - fi) + " cut", false, {});
      expect_diag(S, t2, 0, "reset request: second sync link failed");
      expect_diag(M, t2, 0, "second sync link failed: the standby CPU requests a reset");
      dwell();
      // Repair: both fibres; RUN is refused (reset request), then MRES + RUN links up.
      m_h->repair_fibre(0);
      m_h->repair_fibre(1);
      m_h->switch_to_run(S);
      begin_step("repair both fibres, RUN " + rack_name(S) + " (refused: reset request)", true,
                 {});
      ++m_r.refusals;
      expect_diag(S, now(), 0, "STOP -> RUN refused: reset request");
      pause();
      if (m_h->pair().state(S) != CpuState::Stop)
        mismatch("the standby left STOP with its reset request pending");
      since = now();
      ex.clear();
      if (!m_h->memory_reset(S)) mismatch("memory reset refused");
      restart_side(S, since, ex);
      m_h->switch_to_run(S);
      begin_step("MRES + RUN " + rack_name(S), true, std::move(ex));
      break;
    }
    case HFault::UpdateBlocked: {
      // SFC 90 MODE 3 (000 L564, L1281-1285; docs/h-sfc90.md): the standby's link-up runs, then
      // it waits in LINK-UP - no update, no Redundant, its DP master does not run - until MODE 4
      // starts the update at that instant (t1 = the call): 38C3 then, the program from + W.
      stop_standby(name);
      pause();
      const bus::Ticks t0 = now();
      const std::uint16_t rv3 = m_h->h_ctrl(3, 0);
      begin_step("SFC 90 MODE 3 (update disabled)", false, {});
      if (rv3 != 0) mismatch("SFC 90 MODE 3 RET_VAL " + std::to_string(rv3) + " (not 0)");
      for (int r = 0; r < 2; ++r) expect_diag(r, t0, 0, "SFC 90: update disabled");
      pause();
      const bus::Ticks t1 = now();
      m_h->switch_to_run(S);
      begin_step("RUN " + rack_name(S) + " (LINK-UP, update disabled)", true, {});
      const bus::Ticks done = t1 + m_params.link_up_time;
      const bus::Ticks t4 = done + draw(m_o.fault_min, m_o.fault_max);
      bool left = false;
      while (now() < t4) {
        run_to(std::min(t4, now() + 50 * kMs));
        const SystemMode sm = m_h->pair().system_mode();
        if (!left && (sm == SystemMode::Update || sm == SystemMode::Redundant)) {
          left = true;
          mismatch("system mode " + std::string(to_string(sm)) +
                   " while the update is disabled (SFC 90 MODE 3)");
        }
      }
      if (m_h->pair().state(S) != CpuState::LinkUp)
        mismatch("the standby does not wait in LINK-UP with the update disabled");
      for (int r = 0; r < 2; ++r)
        expect_diag(r, done, 0, "link-up done: update disabled (SFC 90), waiting");
      ++m_r.update_waits;
      // MODE 4: the update from now on, as a link-up that ended now.
      since = now();
      restart_side(S, since - m_params.link_up_time, ex);
      const std::uint16_t rv4 = m_h->h_ctrl(4, 0);
      begin_step("SFC 90 MODE 4 (update enabled)", true, std::move(ex));
      if (rv4 != 0) mismatch("SFC 90 MODE 4 RET_VAL " + std::to_string(rv4) + " (not 0)");
      for (int r = 0; r < 2; ++r) expect_diag(r, since, 0, "SFC 90: update re-enabled");
      break;
    }
    default:
      break;
  }
  return since;
}

void HCampaignRun::hidden_cycle() {
  // Tamper: the standby CPU off and on again; the observer expects nothing.
  const int S = 1 - m_obs.master;
  m_h->power_off(S);
  begin_step("(hidden fault: nothing expected)", false, {});
  dwell();
  m_h->power_on(S);
  begin_step("(hidden repair: nothing expected)", true, {});
  run_to(now() + m_params.link_up_time + update_w() + 500 * kMs);
  wait_recovered(now());
}

HCampaignResult HCampaignRun::run() {
  const auto w0 = std::chrono::steady_clock::now();
  run_to(10 * kMs);
  // Start: both CPUs at once; rack 0 master (STARTUP), rack 1 links up once it is in Solo RUN.
  const bus::Ticks t0 = now();
  m_obs.prog_from[0] = t0 + m_params.startup_time;
  m_obs.run_from[0] = t0;  // the master's DP master runs from its STARTUP on (Clear)
  m_obs.run_from[1] = m_obs.prog_from[0] + m_params.link_up_time;
  m_obs.prog_from[1] = m_obs.run_from[1] + update_w();
  m_h->power_on_both();
  begin_step("start-up", true, {});
  --m_r.repairs;  // the start-up is no injection
  wait_recovered(t0);
  check_roles();
  int index = 0;
  std::vector<int> w(m_o.weights.begin(), m_o.weights.end());
  std::discrete_distribution<int> pick(w.begin(), w.end());
  while (m_r.injections() < m_o.steps) {
    run_to(now() + draw(m_o.gap_min, m_o.gap_max));
    int fi = pick(m_rng.engine());
    // libstdc++'s discrete_distribution returns the last index for a draw above the rounded
    // cumulative sum of the positive weights: trailing weights 0 (the four later kinds left
    // out) must give the 20-kind campaign's draw, the last kind with a weight.
    while (fi > 0 && w[static_cast<std::size_t>(fi)] == 0) --fi;
    const auto f = static_cast<HFault>(fi);
    if (index == m_o.tamper.hidden_fault_at) {
      hidden_cycle();
      m_r.faults -= 1;
      m_r.repairs -= 1;
    } else if (index == m_o.tamper.second_master_at) {
      // Tamper: the observer is told one fibre (F5), both are cut (F6).
      const int M = m_obs.master, S = 1 - M;
      const bus::Ticks t = now();
      std::vector<Expect> ex;
      m_obs.prog_until[S] = t;
      ex.push_back(cpu_ob(72, M, CpuRole::Master, HReason::LinkLost, t));
      lose_side(S, t, ex);
      m_h->cut_both_fibres();
      begin_step("one fibre (F5) [tamper: both cut]", false, std::move(ex));
      settle_step();
      dwell();
      ex.clear();
      restart_side(S, now(), ex);
      m_h->repair_fibre(0);
      m_h->repair_fibre(1);
      m_h->switch_to_stop(S);
      m_h->switch_to_run(S);
      begin_step("repair fibre, RUN " + rack_name(S), true, std::move(ex));
      settle_step();
      wait_recovered(now());
    } else {
      const bool hidden_kb = index == m_o.tamper.hidden_update_timeout_at;
      if (hidden_kb) m_h->set_changed_db_kb(m_o.update_timeout_kb);  // the observer not told
      ++m_r.drawn[static_cast<int>(f)];
      cycle(f);
      if (hidden_kb) m_h->set_changed_db_kb(m_obs.kb);
    }
    ++index;
  }
  run_to(now() + 500 * kMs);
  check_im_times();
  match_all();
  m_r.io_events = campaign::zero_event_counts();
  for (const auto& e : m_h->events()) {
    if (e.ob == 72) ++m_r.ob72;
    if (e.ob == 121) ++m_r.ob121;
    if (e.source == Src::Io) campaign::count_event(m_r.io_events, e.code);
  }
  if (m_o.keep_log) {
    for (const auto& st : m_steps)
      m_r.log.push_back({st.at, st.repair, st.what, static_cast<int>(st.expect.size())});
    m_r.events = m_h->events();
  }
  m_r.simulated = now();
  m_r.frames = m_bus[0]->stats().frames + m_bus[1]->stats().frames;
  m_r.wall_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - w0).count();
  return m_r;
}

}  // namespace

HCampaignResult run_h_campaign(const HCampaignOptions& o) {
  auto c = std::make_unique<HCampaignRun>(o);
  return c->run();
}

}  // namespace pbvbus::devices
