// The seeded random fault campaign for switched I/O (switchover_campaign.hpp).
#include "pbvbus/switched_io/switchover_campaign.hpp"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <memory>
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

namespace pbvbus::devices {

std::string_view to_string(CampaignFault f) {
  switch (f) {
    case CampaignFault::ActiveInterface:
      return "active interface (F10)";
    case CampaignFault::PassiveInterface:
      return "passive interface (F10)";
    case CampaignFault::SecondInterface:
      return "second interface (F11)";
    case CampaignFault::CableCut:
      return "cable cut (F13)";
    case CampaignFault::ShortCircuit:
      return "short circuit (F14)";
    case CampaignFault::MasterStop:
      return "master stop (F14)";
    case CampaignFault::MasterFailure:
      return "master failure (F9)";
    case CampaignFault::SwitchoverLoss:
      return "loss during switchover (F24)";
  }
  return "?";
}

int CampaignResult::events_with(std::uint16_t code) const { return campaign::count_of(events, code); }

std::string CampaignResult::summary() const {
  std::ostringstream o;
  o << "faults " << faults << " repairs " << repairs << " (cycles:";
  for (int k = 0; k < kCampaignFaultKinds; ++k)
    o << ' ' << to_string(static_cast<CampaignFault>(k)) << '=' << drawn[k];
  o << ") switchovers " << switchovers << " station switches " << station_switches << "; events"
    << campaign::format_counts(events);
  o << " (expected " << expected_events << "); samples " << output_samples << " pulses " << pulses
    << " safe-state " << safe_state_samples << "; alarms raised " << alarms_raised << " delivered "
    << alarms_delivered << " lost " << alarms_lost << " duplicated " << alarms_duplicated
    << "; mismatches " << mismatches.size() << "; max latency fault "
    << max_fault_latency / bus::kTicksPerUs << " us, repair "
    << max_repair_latency / bus::kTicksPerUs << " us; simulated "
    << static_cast<double>(simulated) / bus::kTicksPerMs / 1000.0 << " s in " << wall_seconds
    << " s wall; frames " << frames;
  return o.str();
}

namespace {

using redundancy::SystemEvent;
using Bytes = std::vector<std::uint8_t>;
constexpr bus::Ticks kMs = bus::kTicksPerMs;

std::string fmt_time(bus::Ticks t) { return campaign::format_ms(t); }

/// One expected S7 event: code, line (-1 = either) and station (0xFF = the master system).
struct Expect {
  std::uint16_t code = 0;
  int line = -1;
  std::uint8_t station = 0xFF;
};

std::string fmt(const Expect& e) {
  char buf[40];
  std::snprintf(buf, sizeof buf, "%04X L%d @%d", e.code, e.line, int(e.station));
  return buf;
}

/// One injection (or a pair within microseconds, F24) and what the observer expects from it.
struct Step {
  bus::Ticks at = 0;
  bool repair = false;
  std::string what;
  std::vector<Expect> expect;
  bool lines_differ = false;  ///< F24: the two expected events on different lines
  std::size_t ev_index = 0;   ///< MasterSystem::events().size() at the injection
};

GsdFile load(const std::string& dir, const char* name) {
  return campaign::load_gsd_or_throw(dir, name, "campaign");
}

std::vector<ModuleChoice> switched_modules() {
  return {ModuleChoice::named("16DI DC24V"), ModuleChoice::named("16DO DC24V/0.5A")};
}
std::vector<ModuleChoice> plain_modules() {
  return {ModuleChoice::named("16DI/16DO DC24V")};
}

class Campaign;

/// The output sampler: every switched station's backplane after every frame on either line.
struct Sampler final : bus::Tap {
  explicit Sampler(Campaign& c) : camp(c) {}
  void on_frame(const bus::TapFrame& f) override;
  Campaign& camp;
};

class Campaign {
 public:
  explicit Campaign(const CampaignOptions& o) : m_o(o), m_rng(o.seed), m_sampler(*this) {
    if (o.switched < 1 || o.switched > 16 || o.one_sided_per_line < 0 || o.one_sided_per_line > 8)
      throw std::invalid_argument("campaign: 1..16 switched stations, 0..8 one-sided per line");
    build();
  }

  CampaignResult run();
  void sample(const bus::TapFrame& f);

 private:
  struct Sw {
    std::uint8_t address = 0;
    std::unique_ptr<SwitchedStationModel> model;
    bool iface_ok[2] = {true, true};
    int act = 0;  ///< the observer's expected active line (-1: none)
    campaign::CounterWatch watch;  ///< the sampler's view of the backplane outputs
    int primary = -1;
  };
  struct One {
    std::uint8_t address = 0;
    int line = 0;
    int pos = 0;  ///< attachment index on its line
    std::unique_ptr<SlaveModel> model;
  };
  struct LineState {
    bool shorted = false, stopped = false, failed = false;
    int cut = -1;  ///< cut after this attachment, or -1
  };

  void build();
  bus::Ticks now() const { return m_sched.now(); }
  int pos_of_switched(int k) const { return 1 + k; }
  bool line_ok(int l) const {
    return !m_line[l].shorted && !m_line[l].stopped && !m_line[l].failed;
  }
  bool behind_cut(int l, int pos) const { return m_line[l].cut >= 0 && pos > m_line[l].cut; }
  bool reach_sw(int k, int l) const {
    return m_sw[k].iface_ok[l] && line_ok(l) && !behind_cut(l, pos_of_switched(k));
  }
  bool reach_one(const One& s) const { return line_ok(s.line) && !behind_cut(s.line, s.pos); }

  struct Snapshot {
    std::vector<std::array<bool, 2>> sw;
    std::vector<bool> one;
  };
  Snapshot snapshot() const {
    Snapshot s;
    for (std::size_t k = 0; k < m_sw.size(); ++k)
      s.sw.push_back({reach_sw(static_cast<int>(k), 0), reach_sw(static_cast<int>(k), 1)});
    for (const auto& o : m_one) s.one.push_back(reach_one(o));
    return s;
  }
  /// The per-station events the rules derive from a change of reachability (before → now),
  /// and the observer's expected active lines updated.
  std::vector<Expect> derive(const Snapshot& before, bool silent);

  bus::Ticks draw(bus::Ticks lo, bus::Ticks hi) { return m_rng.ticks(lo, hi); }
  int draw_int(int lo, int hi) { return m_rng.integer(lo, hi); }

  /// Starts a step now (the injection already done by the caller).
  void begin_step(std::string what, bool repair, std::vector<Expect> ex, bool lines_differ = false);
  /// Runs until the current step's expectations are met or its window passed; returns when.
  bus::Ticks settle_step();
  void run_to(bus::Ticks t) { m_sched.run_until(t); }
  bool satisfied(const Step& s) const;
  /// Before a fault: every reachable slave back in data exchange on its masters.
  bool recovered() const;
  void wait_recovered();
  void check_active();
  void match_all(CampaignResult& r);
  void check_im_times();

  // Fault cycles.
  void cycle(CampaignFault f);
  void hidden_cycle();
  void fail_iface(int k, int l, bool tell = true);
  void repair_iface(int k, int l, bool tell = true);
  void after_fault(bus::Ticks t0, bus::Ticks max_dwell = 0);
  void after_repair(bus::Ticks t0, bus::Ticks settle);
  std::string sw_name(int k) const { return "station " + std::to_string(m_sw[k].address); }

  CampaignOptions m_o;
  campaign::Draw m_rng;
  bus::Scheduler m_sched;
  std::unique_ptr<bus::Line> m_bus[2];
  fdl::BusParams m_bp;
  std::unique_ptr<RedundantMasterSystemModel> m_sys;
  std::vector<Sw> m_sw;
  std::vector<One> m_one;
  LineState m_line[2];
  int m_atts[2] = {0, 0};
  std::uint16_t m_counter = 0;
  Sampler m_sampler;
  std::vector<Step> m_steps;
  CampaignResult m_r;

  // Alarms (S8): payload = a 4-octet id; each must reach exactly one master, the active line's.
  struct AlarmRec {
    std::uint8_t station = 0;
    bus::Ticks raised = 0;
    int deliveries = 0;
    std::string lines;
  };
  std::vector<AlarmRec> m_alarms;
  std::uint32_t m_alarm_id = 0;
  void maybe_raise_alarm(double p);
  void on_master_event(int line, const dp::MasterEvent& e);
  void count_alarms();
};

void Sampler::on_frame(const bus::TapFrame& f) {
  camp.sample(f);
}

void Campaign::build() {
  const GsdFile fast = load(m_o.gsd_dir, "PBVB0A10.gsd");
  const GsdFile slow = load(m_o.gsd_dir, "PBVB0A11.gsd");
  const GsdFile plain = load(m_o.gsd_dir, "PBVB0A01.gsd");
  m_bp = fdl::BusParams::defaults(m_o.baud);
  m_bp.hsa = 12;
  m_bus[0] = std::make_unique<bus::Line>(m_sched, "A", m_o.baud, m_o.seed * 2 + 1);
  m_bus[1] = std::make_unique<bus::Line>(m_sched, "B", m_o.baud, m_o.seed * 2 + 2);

  m_sw.resize(static_cast<std::size_t>(m_o.switched));
  for (int k = 0; k < m_o.switched; ++k) m_sw[k].address = static_cast<std::uint8_t>(20 + k);
  for (int l = 0; l < 2; ++l)
    for (int j = 0; j < m_o.one_sided_per_line; ++j) {
      One o;
      o.address = static_cast<std::uint8_t>(40 + 20 * l + j);
      o.line = l;
      o.pos = 1 + m_o.switched + j;
      m_one.push_back(std::move(o));
    }
  auto gsd_of = [&](int k) -> const GsdFile& { return k == 1 ? slow : fast; };

  std::vector<dp::SlaveParams> cfg[2];
  std::vector<redundancy::SwitchedStationRef> refs;
  for (int k = 0; k < m_o.switched; ++k) {
    SwitchedStationOptions so;
    so.address = m_sw[k].address;
    so.bus_params = m_bp;
    if (m_o.im_time) {
      // The GSD's T_SLAVE_UM (Slave_Max_Switch_Over_Time × 10 ms), as SwitchedStationModel reads it.
      const auto& red = gsd_of(k).redundancy();
      if (auto ms = red.switch_over_time_ms())
        so.redundancy.im_switchover_bound = bus::Ticks{*ms} * bus::kTicksPerMs;
      so.redundancy.im_seed = m_o.seed * 0x100000001B3ull + m_sw[k].address;
    }
    auto b = SwitchedStationModel::build(gsd_of(k), switched_modules(), so);
    if (!b.ok())
      throw std::runtime_error("campaign: switched station: " +
                               (b.errors.empty() ? std::string("?") : b.errors[0]));
    m_sw[k].model = std::move(b.model);
    auto sp = master_slave_params(gsd_of(k), switched_modules(), m_sw[k].address);
    if (!sp.ok()) throw std::runtime_error("campaign: master params of a switched station");
    dp::SlaveParams p = *sp.value;
    p.prm_cmd.assign(8, 0);
    cfg[0].push_back(p);
    cfg[1].push_back(p);
    refs.push_back({m_sw[k].address, m_sw[k].model->t_slave_um().value_or(0), false});
  }
  for (auto& o : m_one) {
    auto sp = master_slave_params(plain, plain_modules(), o.address);
    if (!sp.ok()) throw std::runtime_error("campaign: master params of a one-sided slave");
    cfg[o.line].push_back(*sp.value);
    SlaveModelOptions so;
    so.address = o.address;
    so.bus_params = m_bp;
    auto b = SlaveModel::build(plain, plain_modules(), so);
    if (!b.ok()) throw std::runtime_error("campaign: one-sided slave");
    o.model = std::move(b.model);
  }
  RedundantMasterSystemOptions mo;
  mo.bus_params = m_bp;
  m_sys = std::make_unique<RedundantMasterSystemModel>(mo, cfg[0], cfg[1], refs);
  m_sys->set_cycle_hook([this](RedundantMasterSystemModel& m, int, bus::Ticks t) {
    if (++m_counter == 0) m_counter = 1;  // 0 is the modules' safe state: never written
    std::uint16_t v = m_counter;
    if (t >= m_o.tamper.zero_output_at && t < m_o.tamper.zero_output_at + 20 * kMs) v = 0;
    const Bytes b{static_cast<std::uint8_t>(v >> 8), static_cast<std::uint8_t>(v)};
    for (const auto& s : m_sw) m.system().write_outputs(s.address, 1, b);
    for (const auto& o : m_one) m.system().write_outputs(o.address, 0, b);
  });
  if (m_o.alarms) {
    m_r.alarms_supported = true;
    // What the program receives: the system's alarms (each once; a station's repeat after a
    // switchover is recognised there). The masters' own Alarm events may show a repeat.
    m_sys->system().on_alarm([this](const redundancy::SystemAlarm& a) {
      dp::MasterEvent e;
      e.kind = dp::MasterEvent::Kind::Alarm;
      e.time = a.time;
      e.slave = a.station;
      e.alarm_type = a.type;
      e.alarm_slot = a.slot;
      e.alarm_specifier = a.specifier;
      e.alarm_data = a.data;
      on_master_event(a.line, e);
    });
  }
  // Cable order on each line: master, switched stations, one-sided slaves.
  for (int l = 0; l < 2; ++l) m_sys->attach(l, *m_bus[l], "master");
  for (auto& s : m_sw)
    for (int l = 0; l < 2; ++l) s.model->attach(l, *m_bus[l]);
  for (auto& o : m_one) m_bus[o.line]->attach(*o.model, "one-sided");
  for (int l = 0; l < 2; ++l) {
    m_atts[l] = m_bus[l]->attachment_count();
    m_bus[l]->add_tap(m_sampler);
  }
}

void Campaign::sample(const bus::TapFrame& f) {
  for (std::size_t k = 0; k < m_sw.size(); ++k) {
    Sw& s = m_sw[k];
    const auto out = s.model->outputs();
    const auto v = static_cast<std::uint16_t>((out[0] << 8) | out[1]);
    const int p = s.model->primary();
    if (p >= 0 && p != s.primary) {  // -1 (none, e.g. mid-handover) does not count
      if (s.primary >= 0) ++m_r.station_switches;
      s.primary = p;
    }
    const bool no_channel = !reach_sw(static_cast<int>(k), 0) && !reach_sw(static_cast<int>(k), 1);
    const campaign::CounterWatch::Sample c = s.watch.sample(v, no_channel);
    if (!c.counted) continue;
    ++m_r.output_samples;
    if (c.safe_state) ++m_r.safe_state_samples;
    if (!c.bad.empty()) {
      ++m_r.pulses;
      if (m_r.pulse_reports.size() < 20)
        m_r.pulse_reports.push_back(fmt_time(f.end) + ": " + sw_name(static_cast<int>(k)) + " " +
                                    std::string(c.bad) + " (" + std::to_string(v) + " after " +
                                    std::to_string(c.previous) + ")");
    }
  }
}

std::vector<Expect> Campaign::derive(const Snapshot& before, bool silent) {
  std::vector<Expect> ex;
  for (std::size_t k = 0; k < m_sw.size(); ++k) {
    const int ki = static_cast<int>(k);
    const bool now_r[2] = {reach_sw(ki, 0), reach_sw(ki, 1)};
    for (int l = 0; l < 2; ++l) {
      if (before.sw[k][l] == now_r[l] || silent) continue;
      // The other channel's reachability at the moment of this change: for two changes in one
      // step, the later one sees the earlier one (the caller orders single changes).
      const bool other = now_r[1 - l];
      if (!now_r[l])
        ex.push_back({std::uint16_t(other ? 0x73A3 : 0x39C4), l, m_sw[k].address});
      else
        ex.push_back({std::uint16_t(other ? 0x72A3 : 0x38C4), l, m_sw[k].address});
    }
    // The expected active line: away from an unreachable one, to the first one back.
    Sw& s = m_sw[k];
    if (s.act >= 0 && !now_r[s.act]) s.act = now_r[1 - s.act] ? 1 - s.act : -1;
    if (s.act < 0) {
      if (now_r[0] && !now_r[1])
        s.act = 0;
      else if (now_r[1] && !now_r[0])
        s.act = 1;
      else if (now_r[0] && now_r[1])
        s.act = m_sw[k].model->primary();  // both at once: either
    }
  }
  for (std::size_t j = 0; j < m_one.size(); ++j) {
    const bool r = reach_one(m_one[j]);
    if (r == before.one[j] || silent) continue;
    ex.push_back({std::uint16_t(r ? 0x38C4 : 0x39C4), m_one[j].line, m_one[j].address});
  }
  return ex;
}

void Campaign::begin_step(std::string what, bool repair, std::vector<Expect> ex,
                          bool lines_differ) {
  Step s;
  s.at = now();
  s.repair = repair;
  s.what = std::move(what);
  s.expect = std::move(ex);
  s.lines_differ = lines_differ;
  s.ev_index = m_sys->system().events().size();
  m_r.expected_events += static_cast<int>(s.expect.size());
  m_steps.push_back(std::move(s));
  if (repair)
    ++m_r.repairs;
  else
    ++m_r.faults;
}

bool Campaign::satisfied(const Step& s) const {
  std::vector<bool> used(s.expect.size(), false);
  const auto& all = m_sys->system().events();
  for (std::size_t n = s.ev_index; n < all.size(); ++n) {
    const auto& e = all[n];
    if (!e.s7()) continue;
    for (std::size_t i = 0; i < s.expect.size(); ++i) {
      const Expect& x = s.expect[i];
      if (used[i] || x.code != e.code() || x.station != e.station) continue;
      if (x.line >= 0 && x.line != e.line) continue;
      used[i] = true;
      break;
    }
  }
  return std::all_of(used.begin(), used.end(), [](bool b) { return b; });
}

bus::Ticks Campaign::settle_step() {
  const Step& s = m_steps.back();
  const bus::Ticks limit = s.at + (s.repair ? m_o.startup : m_o.recognition);
  while (!satisfied(s) && now() < limit) run_to(std::min(limit, now() + 2 * kMs));
  return now();
}

bool Campaign::recovered() const {
  using St = dp::SlaveStatusState;
  for (std::size_t k = 0; k < m_sw.size(); ++k)
    for (int l = 0; l < 2; ++l)
      if (reach_sw(static_cast<int>(k), l) &&
          m_sys->master(l).slave_state(m_sw[k].address) != St::DataExchange)
        return false;
  for (const auto& o : m_one)
    if (reach_one(o) && m_sys->master(o.line).slave_state(o.address) != St::DataExchange)
      return false;
  // Every switched station has a primary interface and, when both are reachable, a backup.
  for (const auto& s : m_sw) {
    if (s.model->primary() < 0) return false;
    for (int l = 0; l < 2; ++l)
      if (s.iface_ok[l] && s.model->role(l) != redundancy::Role::Primary &&
          s.model->role(l) != redundancy::Role::Backup)
        return false;
  }
  return true;
}

void Campaign::wait_recovered() {
  const bus::Ticks limit = now() + m_o.recover_limit;
  while (!recovered() && now() < limit) run_to(now() + 10 * kMs);
  if (!recovered())
    m_r.mismatches.push_back(fmt_time(now()) + ": after '" + m_steps.back().what +
                             "': the system did not return to data exchange on every channel "
                             "within " +
                             fmt_time(m_o.recover_limit));
}

void Campaign::check_active() {
  for (std::size_t k = 0; k < m_sw.size(); ++k) {
    const Sw& s = m_sw[k];
    const int prim = s.model->primary();
    const int sys = m_sys->system().active(s.address);
    if (prim != s.act || sys != s.act)
      m_r.mismatches.push_back(fmt_time(now()) + ": after '" + m_steps.back().what +
                               "': " + sw_name(static_cast<int>(k)) + " expected active line " +
                               std::to_string(s.act) + ", station primary " + std::to_string(prim) +
                               ", MasterSystem active " + std::to_string(sys));
  }
}

void Campaign::fail_iface(int k, int l, bool tell) {
  if (tell) m_sw[k].iface_ok[l] = false;
  m_sw[k].model->fail_interface(l);
}

void Campaign::repair_iface(int k, int l, bool tell) {
  if (tell) m_sw[k].iface_ok[l] = true;
  m_sw[k].model->repair_interface(l);
}

void Campaign::after_fault(bus::Ticks t0, bus::Ticks max_dwell) {
  const bus::Ticks sat = settle_step();
  const bus::Ticks hi = max_dwell > m_o.fault_min ? max_dwell : m_o.fault_max;
  run_to(std::max(t0 + draw(m_o.fault_min, hi), sat + 20 * kMs));
}

void Campaign::after_repair(bus::Ticks t0, bus::Ticks settle) {
  const bus::Ticks sat = settle_step();
  const bus::Ticks end = std::max(t0 + settle, sat) + draw(m_o.gap_min, m_o.gap_max);
  // An alarm at a random time of the gap (the repaired channel may still be starting up).
  run_to(draw(sat, end));
  maybe_raise_alarm(0.3);
  run_to(end);
}

void Campaign::cycle(CampaignFault f) {
  const std::string name(to_string(f));
  const bus::Ticks t0 = now();
  switch (f) {
    case CampaignFault::ActiveInterface:
    case CampaignFault::PassiveInterface: {
      const int k = draw_int(0, static_cast<int>(m_sw.size()) - 1);
      const int a = m_sw[k].act;
      const int l = f == CampaignFault::ActiveInterface ? a : 1 - a;
      auto before = snapshot();
      fail_iface(k, l);
      begin_step(name + ": " + sw_name(k) + " interface " + std::to_string(l), false,
                 derive(before, false));
      after_fault(t0);
      const bus::Ticks t1 = now();
      before = snapshot();
      repair_iface(k, l);
      begin_step("repair " + sw_name(k) + " interface " + std::to_string(l), true,
                 derive(before, false));
      after_repair(t1, 300 * kMs);
      break;
    }
    case CampaignFault::SecondInterface:
    case CampaignFault::SwitchoverLoss: {
      const bool f24 = f == CampaignFault::SwitchoverLoss;
      const int k = draw_int(0, static_cast<int>(m_sw.size()) - 1);
      const int first = f24 ? m_sw[k].act : draw_int(0, 1);
      const std::size_t ev0 = m_sys->system().events().size();
      auto before = snapshot();
      fail_iface(k, first);
      if (f24) {
        // The other interface fails while the switchover to it is under way.
        const bus::Ticks d = draw(m_o.f24_min, m_o.f24_max);
        run_to(now() + d);
        auto mid = snapshot();
        auto ex = derive(before, false);
        fail_iface(k, 1 - first);
        auto ex2 = derive(mid, false);
        ex.insert(ex.end(), ex2.begin(), ex2.end());
        for (auto& e : ex) e.line = -1;  // which master notices first is not a rule
        begin_step(name + ": " + sw_name(k) + " interface " + std::to_string(first) + ", then " +
                       std::to_string(1 - first) + " after " +
                       std::to_string(d / bus::kTicksPerUs) + " us",
                   false, ex, true);
        m_steps.back().at = t0;
        m_steps.back().ev_index = ev0;
        ++m_r.faults;  // two injections
        after_fault(t0, m_o.both_down_max);
      } else {
        begin_step(name + ": " + sw_name(k) + " interface " + std::to_string(first), false,
                   derive(before, false));
        after_fault(t0);
        before = snapshot();
        fail_iface(k, 1 - first);
        begin_step(name + ": " + sw_name(k) + " interface " + std::to_string(1 - first) + " too",
                   false, derive(before, false));
        after_fault(now(), m_o.both_down_max);
      }
      // Repairs one by one, in random order.
      const int r1 = draw_int(0, 1);
      before = snapshot();
      repair_iface(k, r1);
      begin_step("repair " + sw_name(k) + " interface " + std::to_string(r1) + " (first)", true,
                 derive(before, false));
      {
        const bus::Ticks t1 = now();
        const bus::Ticks sat = settle_step();
        run_to(std::max(t1 + draw(m_o.fault_min, m_o.fault_max), sat + 20 * kMs));
      }
      const bus::Ticks t2 = now();
      before = snapshot();
      repair_iface(k, 1 - r1);
      begin_step("repair " + sw_name(k) + " interface " + std::to_string(1 - r1) + " (second)",
                 true, derive(before, false));
      after_repair(t2, 300 * kMs);
      break;
    }
    case CampaignFault::CableCut: {
      const int l = draw_int(0, 1);
      const int at = draw_int(0, m_atts[l] - 2);
      auto before = snapshot();
      m_line[l].cut = at;
      m_bus[l]->set_cut_after(at, true);
      begin_step(name + ": line " + std::to_string(l) + " after attachment " + std::to_string(at),
                 false, derive(before, false));
      after_fault(t0);
      const bus::Ticks t1 = now();
      before = snapshot();
      m_line[l].cut = -1;
      m_bus[l]->set_cut_after(at, false);
      begin_step("repair cable line " + std::to_string(l), true, derive(before, false));
      after_repair(t1, 1500 * kMs);
      break;
    }
    case CampaignFault::ShortCircuit:
    case CampaignFault::MasterStop:
    case CampaignFault::MasterFailure: {
      const int l = draw_int(0, 1);
      auto before = snapshot();
      std::vector<Expect> ex;
      const bool silent = f != CampaignFault::MasterFailure;
      if (f == CampaignFault::ShortCircuit) {
        m_line[l].shorted = true;
        m_bus[l]->set_short_circuit(true);
      } else if (f == CampaignFault::MasterStop) {
        m_line[l].stopped = true;
        m_sys->stop_master(l);
      } else {
        m_line[l].failed = true;
        m_sys->fail_master(l);
      }
      ex = derive(before, silent);
      if (silent) ex.push_back({0x39C3, l, 0xFF});
      begin_step(name + ": line " + std::to_string(l), false, ex);
      after_fault(t0);
      const bus::Ticks t1 = now();
      before = snapshot();
      if (f == CampaignFault::ShortCircuit) {
        m_line[l].shorted = false;
        m_bus[l]->set_short_circuit(false);
      } else if (f == CampaignFault::MasterStop) {
        m_line[l].stopped = false;
        m_sys->start_master(l);
      } else {
        m_line[l].failed = false;
        m_sys->repair_master(l);
      }
      ex = derive(before, silent);
      if (silent) ex.push_back({0x38C3, l, 0xFF});
      begin_step("repair " + name + ": line " + std::to_string(l), true, ex);
      after_repair(t1, 1500 * kMs);
      break;
    }
  }
}

void Campaign::hidden_cycle() {
  // Tamper: a passive-interface failure and its repair the observer is not told about.
  const bus::Ticks t0 = now();
  const int k = 0;
  const int l = 1 - m_sw[k].act;
  fail_iface(k, l, false);
  begin_step("(hidden fault: nothing expected)", false, {});
  after_fault(t0);
  const bus::Ticks t1 = now();
  repair_iface(k, l, false);
  begin_step("(hidden repair: nothing expected)", true, {});
  run_to(t1 + 500 * kMs + draw(m_o.gap_min, m_o.gap_max));
}

void Campaign::maybe_raise_alarm(double p) {
  if (!m_o.alarms || !m_rng.chance(p)) return;
  const int k = draw_int(0, static_cast<int>(m_sw.size()) - 1);
  const std::uint32_t id = ++m_alarm_id;
  const Bytes data{static_cast<std::uint8_t>(id >> 24), static_cast<std::uint8_t>(id >> 16),
                   static_cast<std::uint8_t>(id >> 8), static_cast<std::uint8_t>(id)};
  // Diagnostic alarm, slot 2 (the output module), appears.
  const auto res = m_sw[k].model->raise_alarm(1, 2, dp::AlarmSpec::Appears, false, data);
  if (res != dp::AlarmResult::Ok) {
    m_r.mismatches.push_back(fmt_time(now()) + ": " + sw_name(k) + " refused alarm " +
                             std::to_string(id) + " (result " +
                             std::to_string(static_cast<int>(res)) + ")");
    return;
  }
  if (m_alarms.size() < id) m_alarms.resize(id);
  m_alarms[id - 1] = {m_sw[k].address, now(), 0, {}};
  ++m_r.alarms_raised;
}

void Campaign::on_master_event(int line, const dp::MasterEvent& e) {
  if (e.kind != dp::MasterEvent::Kind::Alarm) return;
  // Compared by (station, slot, type, payload): the Seq_Nr may change on a repeat.
  if (e.alarm_type != 1 || e.alarm_slot != 2 || e.alarm_data.size() != 4) {
    m_r.mismatches.push_back(fmt_time(e.time) + ": an alarm nobody raised from station " +
                             std::to_string(e.slave));
    return;
  }
  const std::uint32_t id = (std::uint32_t{e.alarm_data[0]} << 24) |
                           (std::uint32_t{e.alarm_data[1]} << 16) |
                           (std::uint32_t{e.alarm_data[2]} << 8) | e.alarm_data[3];
  if (id == 0 || id > m_alarms.size() || m_alarms[id - 1].station != e.slave) {
    m_r.mismatches.push_back(fmt_time(e.time) + ": alarm " + std::to_string(id) + " from station " +
                             std::to_string(e.slave) + " was never raised");
    return;
  }
  AlarmRec& a = m_alarms[id - 1];
  ++a.deliveries;
  a.lines += (a.lines.empty() ? "" : ",") + std::to_string(line) + "@" + fmt_time(e.time);
  // Only the active channel carries alarms (S6): the line the observer expects active.
  for (std::size_t k = 0; k < m_sw.size(); ++k)
    if (m_sw[k].address == e.slave && m_sw[k].act >= 0 && m_sw[k].act != line)
      m_r.mismatches.push_back(fmt_time(e.time) + ": alarm " + std::to_string(id) + " of " +
                               sw_name(static_cast<int>(k)) + " delivered on line " +
                               std::to_string(line) + ", expected active line " +
                               std::to_string(m_sw[k].act));
}

void Campaign::count_alarms() {
  for (std::size_t i = 0; i < m_alarms.size(); ++i) {
    const AlarmRec& a = m_alarms[i];
    if (a.station == 0) continue;  // refused
    if (a.deliveries == 1) {
      ++m_r.alarms_delivered;
      continue;
    }
    if (a.deliveries == 0)
      ++m_r.alarms_lost;
    else
      ++m_r.alarms_duplicated;
    // The steps around it: the one it was raised in and the next one.
    std::string ctx;
    for (std::size_t si = 0; si < m_steps.size(); ++si)
      if (m_steps[si].at <= a.raised &&
          (si + 1 == m_steps.size() || m_steps[si + 1].at > a.raised)) {
        ctx = "; raised after '" + m_steps[si].what + "' (" + fmt_time(m_steps[si].at) + ")";
        if (si + 1 < m_steps.size())
          ctx += ", before '" + m_steps[si + 1].what + "' (" + fmt_time(m_steps[si + 1].at) + ")";
      }
    m_r.mismatches.push_back(
        fmt_time(a.raised) + ": alarm " + std::to_string(i + 1) + " of station " +
        std::to_string(a.station) + " delivered " + std::to_string(a.deliveries) + " times" +
        (a.lines.empty() ? std::string() : " (line@time: " + a.lines + ")") + ctx);
  }
}

void Campaign::check_im_times() {
  // S5: no IM takes longer than its bound T_SLAVE_UM from its trigger to PRIMARY (the link
  // steps run inside it; a silent partner costs at most the switch timeout).
  for (const auto& sw : m_sw) {
    const auto& rs = sw.model->redundant_slave();
    const bus::Ticks limit =
        std::max(rs.params().im_switchover_bound, rs.params().switch_timeout);
    for (const auto& im : rs.im_switchovers()) {
      ++m_r.im_switchovers;
      if (im.primary_at == bus::kNever) continue;  // abandoned (the interface failed meanwhile)
      const bus::Ticks took = im.primary_at - im.trigger;
      m_r.max_im_switchover = std::max(m_r.max_im_switchover, took);
      if (took > limit)
        m_r.mismatches.push_back(fmt_time(im.trigger) + ": station " +
                                 std::to_string(sw.address) + " IM switchover late: " +
                                 fmt_time(took) + " > " + fmt_time(limit));
    }
  }
}

void Campaign::match_all(CampaignResult& r) {
  std::vector<SystemEvent> ev;
  for (const auto& e : m_sys->system().events())
    if (e.s7()) ev.push_back(e);
  if (m_o.tamper.doctor_events) m_o.tamper.doctor_events(ev);
  std::size_t i = 0;
  for (std::size_t si = 0; si < m_steps.size(); ++si) {
    const Step& s = m_steps[si];
    const bus::Ticks end = si + 1 < m_steps.size() ? m_steps[si + 1].at : bus::kNever;
    const bus::Ticks window = s.repair ? m_o.startup : m_o.recognition;
    std::vector<SystemEvent> seen;
    while (i < ev.size() && ev[i].time < s.at) {
      // Before the first step, or events out of order: the start-up step covers time 0.
      r.mismatches.push_back(fmt_time(ev[i].time) + ": event " +
                             std::string(to_string(ev[i].kind)) + " out of any step");
      ++i;
    }
    while (i < ev.size() && ev[i].time < end) seen.push_back(ev[i++]);
    std::vector<bool> used(seen.size(), false);
    std::vector<std::string> missing, late, extra;
    std::vector<int> f24_lines;
    for (const auto& x : s.expect) {
      bool found = false;
      for (std::size_t j = 0; j < seen.size(); ++j) {
        const auto& e = seen[j];
        if (used[j] || e.code() != x.code || e.station != x.station) continue;
        if (x.line >= 0 && e.line != x.line) continue;
        used[j] = found = true;
        const bus::Ticks lat = e.time - s.at;
        if (lat > window) late.push_back(fmt(x) + " after " + fmt_time(lat));
        auto& mx = s.repair ? r.max_repair_latency : r.max_fault_latency;
        mx = std::max(mx, lat);
        f24_lines.push_back(e.line);
        break;
      }
      if (!found) missing.push_back(fmt(x));
    }
    for (std::size_t j = 0; j < seen.size(); ++j)
      if (!used[j])
        extra.push_back(fmt({seen[j].code(), seen[j].line, seen[j].station}) + " at +" +
                        fmt_time(seen[j].time - s.at));
    if (s.lines_differ && f24_lines.size() == 2 && f24_lines[0] == f24_lines[1])
      late.push_back("both events on line " + std::to_string(f24_lines[0]));
    if (missing.empty() && late.empty() && extra.empty()) continue;
    std::string m = fmt_time(s.at) + ": " + s.what + ": expected {";
    for (std::size_t j = 0; j < s.expect.size(); ++j) m += (j ? ", " : "") + fmt(s.expect[j]);
    m += "}, observed {";
    for (std::size_t j = 0; j < seen.size(); ++j)
      m += (j ? ", " : "") + fmt({seen[j].code(), seen[j].line, seen[j].station}) + " +" +
           fmt_time(seen[j].time - s.at);
    m += "}";
    if (!missing.empty()) m += "; missing " + std::to_string(missing.size());
    if (!extra.empty()) m += "; unexpected " + std::to_string(extra.size());
    for (const auto& x : late) m += "; " + x;
    r.mismatches.push_back(std::move(m));
  }
}

CampaignResult Campaign::run() {
  const auto w0 = std::chrono::steady_clock::now();
  m_bus[0]->start();
  m_bus[1]->start();
  begin_step("start-up", true, {});
  --m_r.repairs;  // the start-up is no injection
  run_to(300 * kMs);
  int index = 0;
  std::vector<int> weights(m_o.weights.begin(), m_o.weights.end());
  std::discrete_distribution<int> pick(weights.begin(), weights.end());
  while (m_r.injections() < m_o.faults) {
    wait_recovered();
    check_active();
    const auto f = static_cast<CampaignFault>(pick(m_rng.engine()));
    // An alarm just before the fault (0..3 ms), on a random station.
    maybe_raise_alarm(0.5);
    run_to(now() + draw(0, 3 * kMs));
    if (index == m_o.tamper.hidden_fault_at) {
      hidden_cycle();
      m_r.faults -= 1;  // not counted as campaign injections
      m_r.repairs -= 1;
    } else {
      ++m_r.drawn[static_cast<int>(f)];
      cycle(f);
    }
    ++index;
  }
  wait_recovered();
  check_active();
  run_to(now() + 500 * kMs);
  match_all(m_r);
  count_alarms();
  m_r.switchovers = m_sys->system().switchovers();
  check_im_times();
  m_r.events = campaign::zero_event_counts();
  for (const auto& e : m_sys->system().events())
    if (e.s7()) campaign::count_event(m_r.events, e.code());
  m_r.simulated = now();
  m_r.frames = m_bus[0]->stats().frames + m_bus[1]->stats().frames;
  m_r.wall_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - w0).count();
  return m_r;
}

}  // namespace

CampaignResult run_campaign(const CampaignOptions& o) {
  auto c = std::make_unique<Campaign>(o);
  return c->run();
}

}  // namespace pbvbus::devices
