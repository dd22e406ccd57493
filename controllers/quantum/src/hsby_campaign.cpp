// The Hot Standby fault campaign on a real DP line (hsby_campaign.hpp,
// docs/quantum-hsby-campaign.md).
#include "pbvbus/quantum/hsby_campaign.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <random>
#include <sstream>
#include <stdexcept>
#include <utility>

#include "pbvbus/campaign/campaign_support.hpp"
#include "pbvbus/quantum/command_register.hpp"
#include "pbvbus/quantum/hsby_dp_line.hpp"
#include "pbvbus/quantum/hsby_modbus_port.hpp"

namespace pbvbus::quantum {

std::string_view to_string(HsbyFault f) {
  switch (f) {
    case HsbyFault::PrimaryPower: return "primary power";
    case HsbyFault::PrimaryCpuStop: return "primary CPU stop";
    case HsbyFault::StandbyPower: return "standby power";
    case HsbyFault::KeyOffLine: return "primary key Off Line";
    case HsbyFault::KeyXfer: return "primary key Xfer";
    case HsbyFault::Override: return "override run bits 0/0";
    case HsbyFault::FibreCut: return "fibre cut";
    case HsbyFault::LogicMismatch: return "logic mismatch";
    case HsbyFault::StandbyUpdate: return "standby program update";
  }
  return "?";
}

namespace {

constexpr std::size_t kHcMaxReports = 20;
constexpr std::uint16_t kHcStaleSetBack = 5;
constexpr std::uint64_t kHcPoll = 0;
constexpr std::uint64_t kHcDeferredPoll = 1;

double hc_ms(bus::Ticks t) {
  return static_cast<double>(t) / static_cast<double>(bus::kTicksPerMs);
}

/// How many counter steps `v` lies behind `newest` (modulo 2^16); 0x8000.. = ahead.
std::uint16_t hc_behind(std::uint16_t newest, std::uint16_t v) {
  return static_cast<std::uint16_t>(newest - v);
}

/// The per-slave watch of the slave-side observer: started at the first value other than 0.
struct HcSlaveWatch {
  bool started = false;
  std::uint16_t newest = 0;
};

class HcRun final : public bus::EventTarget {
 public:
  explicit HcRun(const HsbyCampaignOptions& o)
      : m_o(o), m_sys(line_options(o)), m_port(m_sys.pair(), 1, 1, 1, true), m_draw(o.seed),
        m_watch(static_cast<std::size_t>(o.slaves)) {
    UserLogic counter = m_sys.counter_logic([this](std::uint16_t v, bus::Ticks) { computed(v); });
    const std::uint32_t base = m_sys.options().output_base;
    const auto n = static_cast<std::uint32_t>(o.slaves);
    m_logic = [this, counter, base, n](StateRam& ram, bus::Ticks now) {
      counter(ram, now);
      if (!m_zeroed && now >= m_o.tamper.zero_output_at) {
        m_zeroed = true;  // tamper: a program glitch writing 0 once
        for (std::uint32_t k = 0; k < n; ++k) ram.set_holding(base + k, 0);
      }
    };
    m_sys.pair().set_logic(m_logic);
    for (int k = 0; k < o.slaves; ++k)
      m_sys.slave(k).on_dx = [this](int i, std::uint16_t v, bus::Ticks now) { sample(i, v, now); };
  }

  HsbyCampaignResult run() {
    const auto w0 = std::chrono::steady_clock::now();
    m_sys.start();
    m_sys.scheduler().schedule(m_o.poll_period, *this, kHcPoll);
    m_expect_primary = 0;
    settle("start-up");
    run_to_random_phase();
    std::vector<double> w(m_o.weights.begin(), m_o.weights.end());
    std::discrete_distribution<int> pick(w.begin(), w.end());
    int cycle = 0;
    while (m_r.injections() < m_o.steps) {
      auto kind = static_cast<HsbyFault>(pick(m_draw.engine()));
      const bool stale = cycle == m_o.tamper.stale_takeover_at;
      if (stale) kind = HsbyFault::PrimaryPower;
      run_cycle(kind, stale);
      ++cycle;
    }
    check_switchovers();
    finish();
    if (m_o.keep_log)
      for (const PairEvent& e : m_sys.pair().events())
        m_r.pair_log.push_back(campaign::format_ms(e.time) + " rack " + std::to_string(e.rack) +
                               " " + std::string(to_string(e.kind)) + ": " + e.text);
    m_r.simulated = m_sys.now();
    m_r.wall_seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - w0).count();
    return std::move(m_r);
  }

  void on_event(bus::Ticks now, std::uint64_t tag) override {
    if (tag == kHcDeferredPoll) {
      poll(now, false);
      return;
    }
    poll(now, true);
    m_sys.scheduler().schedule(now + m_o.poll_period, *this, kHcPoll);
  }

 private:
  static HsbyDpLineOptions line_options(const HsbyCampaignOptions& o) {
    HsbyDpLineOptions l;
    l.baud = o.baud;
    l.slaves = o.slaves;
    l.scan_time = o.scan_time;
    l.watchdog_factor = o.watchdog_factor;
    l.update_time = o.update_time;
    return l;
  }

  void note(std::string s) {
    if (m_o.keep_log) m_r.log.push_back(campaign::format_ms(m_sys.now()) + " " + s);
  }
  void report(std::string s) {
    if (m_r.reports.size() < kHcMaxReports)
      m_r.reports.push_back(campaign::format_ms(m_sys.now()) + " " + std::move(s));
  }
  void mismatch(std::string s) {
    m_r.mismatches.push_back(campaign::format_ms(m_sys.now()) + " " + std::move(s));
  }

  // ---- the observer ----------------------------------------------------------------------

  void computed(std::uint16_t v) {
    if (!m_computed || hc_behind(v, m_newest) < 0x8000) m_newest = v;  // v not older
    m_computed = true;
  }

  void sample(int k, std::uint16_t v, bus::Ticks) {
    HcSlaveWatch& w = m_watch[static_cast<std::size_t>(k)];
    ++m_r.slave_samples;
    if (v == 0) {
      if (w.started) {
        ++m_r.pulses;
        report("slave " + std::to_string(m_sys.slave_address(k)) + ": outputs 0 (pulse)");
      }
      return;
    }
    if (!w.started) {
      w.started = true;
      w.newest = v;
      return;
    }
    const std::uint16_t b = hc_behind(w.newest, v);
    if (b >= 0x8000) {
      w.newest = v;  // newer
    } else if (b >= 2) {
      ++m_r.stale_outputs;
      report("slave " + std::to_string(m_sys.slave_address(k)) + ": output " + std::to_string(v) +
             " is " + std::to_string(b) + " scans behind " + std::to_string(w.newest));
    }
  }

  void poll(bus::Ticks now, bool may_defer) {
    const int r = m_port.rack_for(1);
    const auto& sw = m_sys.pair().switchovers();
    if (may_defer && r >= 0 && !sw.empty() && sw.back().time == now && sw.back().new_rack == r) {
      // Decision C9: a request reaching the new primary at the instant of its takeover is
      // served after its first scan (scheduled at this instant before this poll: FIFO).
      m_sys.scheduler().schedule(now, *this, kHcDeferredPoll);
      return;
    }
    ++m_r.modbus_polls;
    if (r < 0) {
      ++m_r.modbus_no_answer;
      if (m_silent_since == bus::kNever) m_silent_since = now;
      return;
    }
    if (m_silent_since != bus::kNever) {
      m_r.longest_no_answer = std::max(m_r.longest_no_answer, now - m_silent_since);
      m_silent_since = bus::kNever;
    }
    ++m_r.modbus_answers;
    if (r != m_sys.pair().primary()) {
      ++m_r.wrong_rack;
      report("unit 1 answered by rack " + std::to_string(r) + ", not the primary");
    }
    if (!m_computed) return;
    const std::uint16_t v = m_sys.pair().ram(r).holding(m_sys.options().counter_register);
    const std::uint16_t b = hc_behind(m_newest, v);
    if (b >= 2) {
      ++m_r.stale_reads;
      report("unit 1 (rack " + std::to_string(r) + ") read " + std::to_string(v) +
             ", newest computed " + std::to_string(m_newest));
    }
  }

  void check_switchovers() {
    const auto& sw = m_sys.pair().switchovers();
    for (; m_seen < sw.size(); ++m_seen) {
      const SwitchoverRecord& s = sw[m_seen];
      ++m_r.switchovers;
      m_r.takeover_ticks.push_back(s.takeover_ticks);
      if (s.cause == SwitchoverCause::PrimaryPowerOff || s.cause == SwitchoverCause::PrimaryCpuStop ||
          s.cause == SwitchoverCause::LinkSilent)
        m_unplanned.push_back(s.takeover_ticks);
      if (s.takeover_ticks > m_o.scan_time) {
        ++m_r.late_switchovers;
        report("switchover (" + std::string(to_string(s.cause)) + ") took " +
               campaign::format_ms(s.takeover_ticks));
      }
    }
  }

  std::uint64_t dx_exits() const {
    std::uint64_t n = 0;
    for (int k = 0; k < m_sys.slave_count(); ++k) {
      const auto& st = m_sys.slave(k).engine().stats();
      n += st.watchdog_expiries + (st.data_exch_entries > 0 ? st.data_exch_entries - 1 : 0);
    }
    return n;
  }

  void finish() {
    if (m_silent_since != bus::kNever)
      m_r.longest_no_answer = std::max(m_r.longest_no_answer, m_sys.now() - m_silent_since);
    m_r.dx_exits = dx_exits();
    m_r.takeover_all = takeover_distribution(m_r.takeover_ticks, m_o.scan_time);
    m_r.takeover_unplanned = takeover_distribution(m_unplanned, m_o.scan_time);
  }

  // ---- the cycle -------------------------------------------------------------------------

  // Redundant again: a primary and a standby, every slave in data exchange, the standby's module
  // shadowing each of them, and at least one transfer completed since this standby was first
  // seen (only a standby receives transfers, so that one carried a scan of the current primary:
  // its state RAM is no older than one scan; docs/quantum-hsby-campaign.md, finding F1).
  bool settled() {
    const HsbyPair& p = m_sys.pair();
    const int s = p.standby();
    if (s != m_standby_seen) {
      m_standby_seen = s;
      m_transfers_at_join = p.transfers_completed();
    }
    return p.primary() >= 0 && s >= 0 && p.transfers_completed() > m_transfers_at_join &&
           m_sys.all_in_data_exchange() && m_sys.standby_shadows_all();
  }

  void settle(const std::string& what) {
    const bus::Ticks limit = m_sys.now() + m_o.settle_limit;
    m_standby_seen = -2;
    while (!settled() && m_sys.now() < limit) m_sys.run_until(m_sys.now() + bus::kTicksPerMs);
    check_switchovers();
    if (!settled()) {
      mismatch("not settled within " + campaign::format_ms(m_o.settle_limit) + " after " + what);
      return;
    }
    if (m_sys.pair().primary() != m_expect_primary)
      mismatch("after " + what + ": primary rack " + std::to_string(m_sys.pair().primary()) +
               ", expected " + std::to_string(m_expect_primary));
    if (m_override_on) {
      // The override's restore ends here: keys decide again, the command word cleared.
      m_sys.pair().set_keyswitch_override(false);
      m_sys.pair().ram(m_sys.pair().primary()).set_holding(0, 0);
      m_override_on = false;
    }
    if (m_sys.pair().switchovers().size() != m_expected_total)
      mismatch("after " + what + ": " + std::to_string(m_sys.pair().switchovers().size()) +
               " switchovers, expected " + std::to_string(m_expected_total));
  }

  // The settle is seen at a fixed phase of the scan (a transfer's completion); the next fault
  // falls anywhere in the scan: up to one scan time later, drawn.
  void run_to_random_phase() {
    m_sys.run_until(m_sys.now() + m_draw.ticks(0, m_o.scan_time - 1));
  }

  // After a mismatch the observer takes the pair's roles and switchover count as they are, so
  // that one finding is reported once, not again at every later cycle.
  void resync() {
    m_expected_total = m_sys.pair().switchovers().size();
    if (m_sys.pair().primary() >= 0) m_expect_primary = m_sys.pair().primary();
  }

  void inject(bool repair, const std::string& what) {
    if (repair)
      ++m_r.repairs;
    else
      ++m_r.faults;
    note((repair ? "repair: " : "fault: ") + what);
  }

  void expect_state(int rack, CpuState s, const std::string& what) {
    if (m_sys.pair().state(rack) != s)
      mismatch(what + ": rack " + std::to_string(rack) + " " +
               std::string(to_string(m_sys.pair().state(rack))) + ", expected " +
               std::string(to_string(s)));
  }

  void update_sequence(int rack, bool arm, bool finish) {
    HsbyPair& pair = m_sys.pair();
    if (arm) {
      pair.press_update(rack);
      pair.set_key(rack, KeySwitch::Xfer);
    }
    if (finish) {
      pair.set_key(rack, KeySwitch::Run);
      pair.release_update(rack);
    }
  }

  void write_command(int rack, bool run_a, bool run_b) {
    CommandRegister c;
    c.keyswitch_override = true;
    c.run_a = run_a;
    c.run_b = run_b;
    m_sys.pair().ram(rack).set_holding(0, encode_command(c));
  }

  void run_cycle(HsbyFault kind, bool stale) {
    HsbyPair& pair = m_sys.pair();
    const int p = pair.primary();
    const int s = pair.standby();
    if (p < 0 || s < 0) {
      mismatch("cycle without primary and standby");
      m_sys.run_until(m_sys.now() + m_o.settle_limit);
      settle("a failed settle");
      return;
    }
    ++m_r.drawn[static_cast<std::size_t>(kind)];
    const std::string name(to_string(kind));
    const bus::Ticks dur = m_draw.ticks(m_o.fault_min, m_o.fault_max);
    const std::size_t before = pair.switchovers().size();
    const std::size_t events_before = pair.events().size();
    bool switchover = false;
    SwitchoverCause cause = SwitchoverCause::PrimaryPowerOff;
    inject(false, name + " (primary rack " + std::to_string(p) + ")");
    switch (kind) {
      case HsbyFault::PrimaryPower:
        pair.power_off(p);
        if (stale) {
          // Tamper: what a stale transfer would leave in the standby.
          StateRam& ram = pair.ram(s);
          const std::uint32_t reg = m_sys.options().counter_register;
          ram.set_holding(reg, static_cast<std::uint16_t>(ram.holding(reg) - kHcStaleSetBack));
        }
        switchover = true;
        break;
      case HsbyFault::PrimaryCpuStop:
        pair.stop_cpu(p);
        switchover = true;
        cause = SwitchoverCause::PrimaryCpuStop;
        break;
      case HsbyFault::StandbyPower:
        pair.power_off(s);
        break;
      case HsbyFault::KeyOffLine:
        pair.set_key(p, KeySwitch::OffLine);
        switchover = true;
        cause = SwitchoverCause::KeyOffLine;
        break;
      case HsbyFault::KeyXfer:
        pair.set_key(p, KeySwitch::Xfer);
        break;
      case HsbyFault::Override:
        write_command(p, true, true);
        pair.set_keyswitch_override(true);  // both bits 1: nothing
        write_command(p, false, false);     // read at the next scan start
        m_override_on = true;
        switchover = true;
        cause = SwitchoverCause::CommandRegister;
        break;
      case HsbyFault::FibreCut:
        pair.set_fibre(FibreState::Cut);
        break;
      case HsbyFault::LogicMismatch:
        pair.load_program(s, 0xBAD00000u + static_cast<std::uint32_t>(m_r.faults), m_logic);
        break;
      case HsbyFault::StandbyUpdate:
        update_sequence(s, true, false);
        break;
    }
    m_sys.run_until(m_sys.now() + dur);
    check_switchovers();

    // The observer's expectation after the fault.
    const std::string what = "after " + name;
    const auto& sw = pair.switchovers();
    const std::size_t got = sw.size() - before;
    if (switchover) {
      ++m_r.expected_switchovers;
      ++m_expected_total;
      m_expect_primary = s;
      if (got != 1) {
        mismatch(what + ": " + std::to_string(got) + " switchovers, expected 1");
        resync();
      } else if (sw.back().new_rack != s || sw.back().cause != cause) {
        mismatch(what + ": switchover to rack " + std::to_string(sw.back().new_rack) + " (" +
                 std::string(to_string(sw.back().cause)) + ")");
      }
      if (pair.primary() != s) mismatch(what + ": the old standby is not primary");
    } else {
      if (got != 0) mismatch(what + ": " + std::to_string(got) + " switchovers, expected none");
      if (pair.primary() != p) mismatch(what + ": the primary changed");
      if (got != 0 || pair.primary() != p) resync();
    }
    switch (kind) {
      case HsbyFault::PrimaryPower: expect_state(p, CpuState::Off, what); break;
      case HsbyFault::StandbyPower: expect_state(s, CpuState::Off, what); break;
      case HsbyFault::PrimaryCpuStop:
      case HsbyFault::KeyOffLine:
      case HsbyFault::Override: expect_state(p, CpuState::Offline, what); break;
      case HsbyFault::KeyXfer: {
        expect_state(s, CpuState::Standby, what);
        // Q7: the primary's key to Xfer is ignored, and the pair says so.
        bool ignored = false;
        for (std::size_t i = events_before; i < pair.events().size(); ++i)
          ignored = ignored || (pair.events()[i].kind == PairEventKind::Ignored &&
                                pair.events()[i].rack == p);
        if (!ignored) mismatch(what + ": no 'ignored' event");
        break;
      }
      case HsbyFault::FibreCut:
      case HsbyFault::LogicMismatch:
      case HsbyFault::StandbyUpdate: expect_state(s, CpuState::Offline, what); break;
    }

    // The repair.
    inject(true, name);
    switch (kind) {
      case HsbyFault::PrimaryPower: pair.power_on(p); break;
      case HsbyFault::PrimaryCpuStop: pair.start_cpu(p); break;
      case HsbyFault::StandbyPower: pair.power_on(s); break;
      case HsbyFault::KeyOffLine:
      case HsbyFault::KeyXfer: pair.set_key(p, KeySwitch::Run); break;
      case HsbyFault::Override: write_command(s, true, true); break;
      case HsbyFault::FibreCut: pair.set_fibre(FibreState::Ok); break;
      case HsbyFault::LogicMismatch: update_sequence(s, true, true); break;
      case HsbyFault::StandbyUpdate: update_sequence(s, false, true); break;
    }
    m_sys.run_until(m_sys.now() + m_draw.ticks(m_o.gap_min, m_o.gap_max));
    settle("the repair of " + name);
    m_r.dx_exits = dx_exits();
    run_to_random_phase();
  }

  HsbyCampaignOptions m_o;
  HsbyDpLine m_sys;
  HsbyModbusPort m_port;
  campaign::Draw m_draw;
  UserLogic m_logic;
  bool m_zeroed = false;
  bool m_computed = false;
  std::uint16_t m_newest = 0;
  std::vector<HcSlaveWatch> m_watch;
  bus::Ticks m_silent_since = bus::kNever;
  std::size_t m_seen = 0;
  std::size_t m_expected_total = 0;
  int m_expect_primary = 0;
  bool m_override_on = false;
  int m_standby_seen = -2;
  std::uint64_t m_transfers_at_join = 0;
  std::vector<bus::Ticks> m_unplanned;
  HsbyCampaignResult m_r;
};

void hc_validate(const HsbyCampaignOptions& o) {
  int sum = 0;
  for (int w : o.weights) {
    if (w < 0) throw std::invalid_argument("hsby campaign: negative weight");
    sum += w;
  }
  if (sum == 0) throw std::invalid_argument("hsby campaign: every weight is 0");
  if (o.fault_min > o.fault_max || o.gap_min > o.gap_max || o.gap_min < 0)
    throw std::invalid_argument("hsby campaign: min above max");
  if (o.scan_time <= 0 || o.settle_limit <= 0 || o.poll_period <= 0 || o.update_time <= 0)
    throw std::invalid_argument("hsby campaign: scan time, settle limit, poll period and update "
                                "time must be > 0");
  // A fault must last long enough for its reaction: a fibre cut is noticed at the next
  // transfer due plus one line check (< 2 scans), a planned handover within 2 scan boundaries.
  if (o.fault_min < 3 * o.scan_time)
    throw std::invalid_argument("hsby campaign: fault_min must be >= 3 scan times");
  if (o.slaves < 1) throw std::invalid_argument("hsby campaign: at least one slave");
}

}  // namespace

TakeoverDistribution takeover_distribution(std::vector<bus::Ticks> ticks, bus::Ticks scan_time) {
  TakeoverDistribution d;
  if (ticks.empty() || scan_time <= 0) return d;
  std::sort(ticks.begin(), ticks.end());
  const std::size_t n = ticks.size();
  // Nearest rank: the smallest value with at least p % of the values at or below it.
  auto rank = [&](double p) {
    const auto r = static_cast<std::size_t>(std::ceil(p / 100.0 * static_cast<double>(n)));
    return ticks[std::clamp<std::size_t>(r, 1, n) - 1];
  };
  const double s = static_cast<double>(scan_time);
  d.count = static_cast<int>(n);
  d.min_ms = hc_ms(ticks.front());
  d.median_ms = hc_ms(rank(50));
  d.p99_ms = hc_ms(rank(99));
  d.max_ms = hc_ms(ticks.back());
  d.min_scans = static_cast<double>(ticks.front()) / s;
  d.median_scans = static_cast<double>(rank(50)) / s;
  d.p99_scans = static_cast<double>(rank(99)) / s;
  d.max_scans = static_cast<double>(ticks.back()) / s;
  return d;
}

bool HsbyCampaignResult::clean() const {
  return pulses == 0 && stale_outputs == 0 && stale_reads == 0 && late_switchovers == 0 &&
         dx_exits == 0 && wrong_rack == 0 && mismatches.empty();
}

std::string HsbyCampaignResult::summary() const {
  std::ostringstream o;
  auto dist = [&o](const char* name, const TakeoverDistribution& d) {
    o << name << ": " << d.count << " (min / median / p99 / max) " << d.min_ms << " / "
      << d.median_ms << " / " << d.p99_ms << " / " << d.max_ms << " ms = " << d.min_scans
      << " / " << d.median_scans << " / " << d.p99_scans << " / " << d.max_scans << " scans\n";
  };
  o << "injections " << injections() << " (faults " << faults << ", repairs " << repairs
    << ")\ncycles:";
  for (int k = 0; k < kHsbyFaultKinds; ++k)
    o << (k == 0 ? " " : ", ") << to_string(static_cast<HsbyFault>(k)) << " "
      << drawn[static_cast<std::size_t>(k)];
  o << "\nswitchovers " << switchovers << " (expected " << expected_switchovers << "), late "
    << late_switchovers << "\n";
  dist("takeover, every switchover", takeover_all);
  dist("takeover, primary failures", takeover_unplanned);
  o << "slave samples " << slave_samples << ", pulses " << pulses << ", stale outputs "
    << stale_outputs << ", data exchange exits " << dx_exits << "\n";
  o << "Modbus polls of unit 1 " << modbus_polls << ": answered " << modbus_answers
    << ", no answer " << modbus_no_answer << " (longest " << campaign::format_ms(longest_no_answer)
    << "), stale reads " << stale_reads << ", answered by a non-primary " << wrong_rack << "\n";
  o << "mismatches " << mismatches.size() << "\n";
  for (const auto& m : mismatches) o << "  " << m << "\n";
  for (const auto& r : reports) o << "  " << r << "\n";
  o << "virtual " << static_cast<double>(simulated) / static_cast<double>(bus::kTicksPerSecond)
    << " s in " << wall_seconds << " s wall\n";
  return o.str();
}

HsbyCampaignResult run_hsby_campaign(const HsbyCampaignOptions& o) {
  hc_validate(o);
  HcRun run(o);
  return run.run();
}

}  // namespace pbvbus::quantum
