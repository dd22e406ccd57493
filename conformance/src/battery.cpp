// The battery runner (battery.hpp): the test list, the two kinds of DUT context, and the loop
// that runs each test and never lets one abort the run.
//
// Decisions:
// - Slave model DUT: every open() builds a FRESH SlaveModel on a fresh TestBus, so no test sees
//   another's state. Bus parameters at a baud: the DP-profile defaults (fdl::BusParams::
//   defaults) with max TSDR = the GSD's MaxTsdr there and TSL = max(default TSL, max TSDR + 15);
//   the model's own delay is the line's min TSDR (a fast ASIC, SlaveModel's default).
// - Outside DUT (a program behind a pty): ONE paced TestBus with a PtyStation (Station mode at
//   the DUT's address, Interface timing, reply window = the plan's TSL) for the whole run; only
//   the main baud. The pty path given is a symlink to the pty. Before the first test the runner
//   waits (DutSpec::open_wait) until a program has opened the pty.
// - Every outside session starts from a VERIFIED state (establish_start): the program is found
//   (at the DUT's address, else where an earlier test may have left it, and moved back with
//   Set_Slave_Add), its owner is read from the Slave_Diag and that owner's unlocking Set_Prm is
//   sent (waiting out a watchdog if the owner is gone), and the diagnosis must then show Wait_Prm
//   with no master. When that cannot be established the session is not opened: the test's
//   verdict is Error (its rule was not tested), with the telegrams that showed why.
// - Main baud: DutSpec::baud, else the highest rate the GSD supports up to 1.5 Mbit/s (else its
//   lowest rate).
// - Evidence: every session a test opened contributes its own exchanges (from its opening on,
//   reset included), unless the body filled result.evidence itself.
// - Every reply of every test is checked for its addressing (reply_addressing_fault, §B.2): a
//   reply with wrong addresses or SAPs fails the test whatever its own rule.
// - An exception out of a body is a Fail with its message; the run goes on.

#include <algorithm>
#include <filesystem>
#include <system_error>

#include "groups.hpp"
#include "pbvbus/bus/pty_station.hpp"
#include "pbvbus/conformance/battery.hpp"

#include "pbvbus/bus/pty.hpp"
#include "pbvbus/dp/diagnosis.hpp"
#include "pbvbus/dp/prm.hpp"
#include "pbvbus/dp/sap.hpp"
#include "steps.hpp"
#include "timing_plan.hpp"

namespace pbvbus::conformance {

namespace {

using detail::set_prm;

/// Mutants come with branch `mut` (SlaveModelOptions::mutant); detected at compile time so this
/// file builds with and without it.
template <class O>
constexpr bool kHasMutant = requires(O o) { o.mutant = std::optional<devices::SlaveMutant>{}; };

template <class O>
void apply_mutant(O& o, const std::optional<devices::SlaveMutant>& m) {
  if constexpr (kHasMutant<O>) o.mutant = m;
}

std::optional<fdl::BusParams> params_at(const devices::GsdFile& gsd, bus::Baud baud) {
  const auto max_tsdr = gsd.max_tsdr(baud);
  if (!max_tsdr) return std::nullopt;
  fdl::BusParams p = fdl::BusParams::defaults(baud);
  p.max_tsdr = std::max<std::uint32_t>(*max_tsdr, p.min_tsdr + 1);
  p.tsl = std::max<std::uint32_t>(p.tsl, p.max_tsdr + fdl::BusParams::kTslMargin);
  return p;
}

bus::Baud main_baud(const DutSpec& spec) {
  if (spec.baud) return *spec.baud;
  if (!spec.gsd) return bus::Baud::k1_5M;
  const auto& rates = spec.gsd->baud_rates();
  std::optional<bus::Baud> best;
  for (const auto& r : rates)
    if (static_cast<std::uint32_t>(r.baud) <= static_cast<std::uint32_t>(bus::Baud::k1_5M)) best = r.baud;
  if (best) return *best;
  return rates.empty() ? bus::Baud::k1_5M : rates.front().baud;
}

std::string baud_text(bus::Baud b) { return std::string(bus::baud_name(b)); }

/// Collects a test's evidence from the sessions it opens.
struct EvidenceSink {
  std::vector<Exchange> exchanges;
};

// --- slave model DUT ------------------------------------------------------------------------

class ModelSession final : public Session {
 public:
  ModelSession(std::unique_ptr<devices::SlaveModel> model, TestBusOptions opt, EvidenceSink* sink)
      : m_model(std::move(model)), m_bus(std::make_unique<TestBus>(std::move(opt))), m_sink(sink) {
    m_bus->attach_dut(*m_model, m_model->name());
    m_bus->start();
  }
  ~ModelSession() override {
    if (m_sink) {
      const auto t = m_bus->transcript();
      m_sink->exchanges.insert(m_sink->exchanges.end(), t.begin(), t.end());
    }
    m_bus.reset();  // the line refers to the model
  }
  TestBus& bus() override { return *m_bus; }
  std::uint8_t dut_address() const override { return m_model->address(); }
  devices::SlaveModel* model() override { return m_model.get(); }
  std::span<const Exchange> exchanges() const override { return m_bus->transcript(); }

 private:
  std::unique_ptr<devices::SlaveModel> m_model;
  std::unique_ptr<TestBus> m_bus;
  EvidenceSink* m_sink;
};

class ContextBase : public TestContext {
 public:
  void set_sink(EvidenceSink* s) { m_sink = s; }
  bool init(const DutSpec& spec, std::string& error) {
    m_spec = &spec;
    std::vector<devices::ModuleChoice> mods = spec.modules;
    if (mods.empty() && !spec.gsd->modules().empty()) mods.push_back(devices::ModuleChoice::at(0));
    m_modules = mods;
    auto params = devices::master_slave_params(*spec.gsd, mods, spec.address);
    if (!params.ok()) {
      error = "DUT parameters: ";
      for (const auto& e : params.errors) error += e + "; ";
      return false;
    }
    m_params = *params.value;
    auto idx = devices::resolve_modules(*spec.gsd, mods);
    if (!idx.ok()) {
      error = "modules: " + (idx.errors.empty() ? std::string("?") : idx.errors.front());
      return false;
    }
    auto lens = spec.gsd->check_modules(*idx.value);
    if (!lens.ok()) {
      error = "modules: " + (lens.errors.empty() ? std::string("?") : lens.errors.front());
      return false;
    }
    m_in = lens.value->first;
    m_out = lens.value->second;
    m_baud = main_baud(spec);
    if (const auto bp = params_at(*spec.gsd, m_baud))
      m_timing = detail::plan_timing(spec, m_params, m_in, m_out, m_baud, bp->tsl, dx_interval());
    return true;
  }
  bus::Baud baud() const { return m_baud; }
  /// The tester's Data_Exchange spacing: 10 × Min_Slave_Interval (100 µs units), see steps.hpp.
  bus::Ticks dx_interval() const {
    return 10 * static_cast<bus::Ticks>(m_params.min_slave_interval) * (bus::kTicksPerMs / 10);
  }

 protected:
  EvidenceSink* m_sink = nullptr;
  std::vector<devices::ModuleChoice> m_modules;
  bus::Baud m_baud = bus::Baud::k1_5M;
};

class ModelContext final : public ContextBase {
 public:
  std::unique_ptr<Session> open(std::optional<bus::Baud> baud, std::string& error) override {
    const bus::Baud b = baud.value_or(m_baud);
    const auto params = params_at(*m_spec->gsd, b);
    if (!params) {
      error = "the GSD does not support " + baud_text(b);
      return nullptr;
    }
    if (m_spec->mutant && !kHasMutant<devices::SlaveModelOptions>) {
      error = "mutant slaves are not available in this build";
      return nullptr;
    }
    devices::SlaveModelOptions o;
    o.address = m_spec->address;
    o.bus_params = *params;
    apply_mutant(o, m_spec->mutant);
    auto built = devices::SlaveModel::build(*m_spec->gsd, m_modules, o);
    if (!built.ok()) {
      error = "slave model: ";
      for (const auto& e : built.errors) error += e + "; ";
      return nullptr;
    }
    TestBusOptions to;
    to.params = *params;
    to.dx_interval = dx_interval();
    return std::make_unique<ModelSession>(std::move(built.model), to, m_sink);
  }
};

// --- outside DUT behind a pty ------------------------------------------------------------------

std::string duration_text(std::chrono::milliseconds d) {
  return d.count() % 1000 == 0 ? std::to_string(d.count() / 1000) + " s" : std::to_string(d.count()) + " ms";
}

class OutsideSession final : public Session {
 public:
  OutsideSession(TestBus& bus, std::uint8_t address, EvidenceSink* sink)
      : m_bus(bus), m_address(address), m_mark(bus.mark()), m_sink(sink) {}
  ~OutsideSession() override {
    if (m_sink) {
      const auto t = m_bus.since(m_mark);
      m_sink->exchanges.insert(m_sink->exchanges.end(), t.begin(), t.end());
    }
  }
  TestBus& bus() override { return m_bus; }
  std::uint8_t dut_address() const override { return m_address; }
  devices::SlaveModel* model() override { return nullptr; }
  std::span<const Exchange> exchanges() const override { return m_bus.since(m_mark); }

 private:
  TestBus& m_bus;
  std::uint8_t m_address;
  std::size_t m_mark;
  EvidenceSink* m_sink;
};

class OutsideContext final : public ContextBase {
 public:
  ~OutsideContext() override {
    if (m_pty) m_pty->detach_io();
    m_bus.reset();
    m_pty.reset();
    if (m_link_made) {
      std::error_code ec;
      std::filesystem::remove(*m_spec->pty_path, ec);
    }
  }

  bool connect(std::string& error) {
    const auto params = params_at(*m_spec->gsd, m_baud);
    if (!params) {
      error = "the GSD does not support " + baud_text(m_baud);
      return false;
    }
    TestBusOptions to;
    to.params = *params;
    to.params.tsl = m_timing.tsl_bits;  // long enough for a program to answer (timing_plan.cpp)
    to.paced = m_spec->speed;
    to.dx_interval = dx_interval();
    try {
      m_bus = std::make_unique<TestBus>(to);
      bus::PtyStation::Options po;
      po.mode = bus::PtyStation::Mode::Station;
      po.address = m_spec->address;
      po.timing = bus::PtyStation::Timing::Interface;
      po.reply_window_bits = m_timing.tsl_bits;
      // Every frame on the line, as a UART on the cable would hear it (the program filters by
      // DA, as a slave must): a program that takes a new address without acknowledging it
      // positively is still heard, and probes at other addresses reach it.
      po.forward_all = true;
      m_pty = std::make_unique<bus::PtyStation>(po);
    } catch (const std::exception& e) {
      error = std::string("cannot open a pty: ") + e.what();
      return false;
    }
    // The program opens pty_path: a symlink to the pty's slave side (an existing symlink is
    // replaced; any other existing file is an error, never overwritten).
    const std::string e = bus::make_pty_link(m_pty->path(), *m_spec->pty_path);
    if (!e.empty()) {
      error = e;
      return false;
    }
    m_link_made = true;
    m_bus->attach_dut(*m_pty, "pty DUT");
    m_pty->attach_io(*m_bus->runner());
    // A program started after the battery must find the link and open it before the first test
    // (its first telegram would otherwise be STA-01's "no reply").
    if (progress)
      progress("waiting up to " + duration_text(m_spec->open_wait) + " for a program to open " +
               *m_spec->pty_path + " (" + m_pty->path() + ")");
    if (!m_pty->wait_program_open(m_spec->open_wait)) {
      error = "no program opened " + *m_spec->pty_path + " (" + m_pty->path() + ") within " +
              duration_text(m_spec->open_wait);
      return false;
    }
    if (progress) progress("a program opened " + *m_spec->pty_path + "; testing");
    m_bus->start();
    return true;
  }

  std::unique_ptr<Session> open(std::optional<bus::Baud> baud, std::string& error) override {
    if (baud && *baud != m_baud) {
      error = "an outside slave runs only at the main baud " + baud_text(m_baud);
      return nullptr;
    }
    if (!m_bus) {
      error = "no pty";
      return nullptr;
    }
    auto s = std::make_unique<OutsideSession>(*m_bus, m_spec->address, m_sink);
    if (!establish_start(*s, error)) {
      error = "the test's starting state could not be established: " + error;
      return nullptr;  // the session's telegrams still go into the evidence
    }
    return s;
  }

  std::function<void(const std::string&)> progress;

 private:
  /// Slave_Diag from the tester to `address`; the decoded standard diagnosis, if any.
  std::optional<dp::StandardDiag> probe(Session& s, std::uint8_t address, const std::string& note,
                                        std::string& got) {
    const auto t = detail::srd(address, s.bus().options().tester_address, dp::kSapSlaveDiag,
                               dp::kSapMs0, {});
    const detail::Reply r = detail::reply_of(s.bus().request(t, note));
    got = r.describe();
    dp::StandardDiag d;
    if (!r.ok_with_data() || !dp::StandardDiag::decode(r.data, d)) return std::nullopt;
    return d;
  }

  /// The unlocking Set_Prm (Lock_Req 0, Unlock_Req 1) from `owner` to `address`.
  void unlock_from(Session& s, std::uint8_t address, std::uint8_t owner) {
    dp::SlaveParams p = m_params;
    p.station_status = dp::kPrmUnlockReq;
    const auto du = detail::prm_du(p);
    const auto t = detail::srd(address, owner, dp::kSapSetPrm, dp::kSapMs0, du);
    s.bus().request(t, "start state: Set_Prm Unlock_Req from master " + std::to_string(owner));
  }

  /// Brings the program to the state every test starts from — at the DUT's address, in
  /// Wait_Prm, owned by no master — and checks it with a Slave_Diag (battery.cpp header).
  bool establish_start(Session& s, std::string& error) {
    const std::uint8_t home = m_spec->address;
    std::string got;
    auto d = probe(s, home, "start state: Slave_Diag", got);
    if (!d) {
      // Where an earlier test may have left it: the Set_Slave_Add group's addresses and 126.
      std::uint8_t found = 0;
      for (const std::uint8_t a : {std::uint8_t{100}, std::uint8_t{101}, std::uint8_t{126}}) {
        if (a == home) continue;
        std::string g;
        if (auto da = probe(s, a, "start state: is the DUT at " + std::to_string(a) + "?", g)) {
          found = a;
          d = da;
          break;
        }
      }
      if (!d) {
        error = "the DUT answers no Slave_Diag at its address " + std::to_string(home) + " (" + got +
                "), nor at 100, 101 or 126";
        return false;
      }
      if (!m_spec->gsd->slave_features().set_slave_add_supp) {
        error = "the DUT answers at " + std::to_string(found) + ", not at its address " +
                std::to_string(home) + ", and its GSD has no Set_Slave_Add to move it back";
        return false;
      }
      if (d->master_add != dp::kNoMaster) unlock_from(s, found, d->master_add);
      const std::uint16_t ident = m_spec->gsd->ident_number();
      const std::uint8_t du[4] = {home, static_cast<std::uint8_t>(ident >> 8),
                                  static_cast<std::uint8_t>(ident & 0xFF), 0};
      const auto t = detail::srd(found, s.bus().options().tester_address, dp::kSapSetSlaveAdd,
                                 dp::kSapMs0, du);
      s.bus().request(t, "start state: Set_Slave_Add back to " + std::to_string(home));
      d = probe(s, home, "start state: Slave_Diag at " + std::to_string(home), got);
      if (!d) {
        error = "the DUT was at " + std::to_string(found) + " and does not answer at " +
                std::to_string(home) + " after Set_Slave_Add (" + got + ")";
        return false;
      }
    }
    // Release whoever owns it (the tester, the class-2 master of an earlier test, ...).
    const std::uint8_t owner =
        d->master_add == dp::kNoMaster ? s.bus().options().tester_address : d->master_add;
    unlock_from(s, home, owner);
    d = probe(s, home, "start state: Slave_Diag after the unlock", got);
    if (d && d->master_add != dp::kNoMaster && (d->status_2 & dp::kDiagWdOn) != 0) {
      // The owner's unlock did not take; a watchdog still runs: wait it out (the battery's own
      // watchdogs are at most max(TWD, 1 s)).
      s.bus().idle(std::max<bus::Ticks>(m_timing.twd, bus::kTicksPerSecond) * 3 / 2);
      d = probe(s, home, "start state: Slave_Diag after waiting out the watchdog", got);
    }
    if (!d) {
      error = "Slave_Diag after the unlock answered " + got;
      return false;
    }
    // Wait_Prm with no owner, and nothing left of an earlier test's parameterisation. An unlock
    // only releases the slave (protocol-facts.md §D.2 Lock/Unlock: parameters are not taken), so
    // a Prm_Fault, Cfg_Fault, Not_Supported or Sync/Freeze mode of an earlier test may remain:
    // then a good locking Set_Prm (the GSD's parameters, which replaces them) and an unlock.
    const auto leftover = [](const dp::StandardDiag& x) {
      return (x.status_1 & (dp::kDiagCfgFault | dp::kDiagPrmFault | dp::kDiagNotSupported)) != 0 ||
             (x.status_2 & (dp::kDiagSyncMode | dp::kDiagFreezeMode)) != 0;
    };
    if (d && d->master_add == dp::kNoMaster && leftover(*d)) {
      const std::uint8_t tester = s.bus().options().tester_address;
      const auto good = detail::prm_du(m_params);
      s.bus().request(detail::srd(home, tester, dp::kSapSetPrm, dp::kSapMs0, good),
                      "start state: Set_Prm with the GSD's parameters (clears an earlier fault)");
      unlock_from(s, home, tester);
      d = probe(s, home, "start state: Slave_Diag after the fresh Set_Prm and unlock", got);
      if (!d) {
        error = "Slave_Diag after the fresh Set_Prm and unlock answered " + got;
        return false;
      }
    }
    detail::DiagExpect e;
    e.s1_mask = dp::kDiagStationNotReady | dp::kDiagCfgFault | dp::kDiagPrmFault | dp::kDiagNotSupported;
    e.s1 = dp::kDiagStationNotReady;
    e.s2_mask = dp::kDiagSyncMode | dp::kDiagFreezeMode;
    e.s2 = 0;
    e.master = dp::kNoMaster;
    detail::Reply r;
    r.kind = detail::Reply::Kind::Telegram;
    r.status = fdl::ResponseStatus::DL;
    const auto b = d->encode();
    r.data.assign(b.begin(), b.end());
    if (const auto why = detail::check_diag(r, e); !why.empty()) {
      error = "after an unlocking Set_Prm from master " + std::to_string(owner) +
              " the slave is not in a fresh Wait_Prm: " + why;
      return false;
    }
    return true;
  }

  std::unique_ptr<TestBus> m_bus;
  std::unique_ptr<bus::PtyStation> m_pty;
  bool m_link_made = false;
};

bool selected(const TestCase& t, const BatteryOptions& o) {
  if (o.only.empty()) return true;
  return std::any_of(o.only.begin(), o.only.end(),
                     [&](const std::string& s) { return s == t.id || s == t.group; });
}

}  // namespace

bus::Baud dut_main_baud(const DutSpec& spec) { return main_baud(spec); }

const std::vector<TestCase>& all_tests() {
  static const std::vector<TestCase> tests = [] {
    std::vector<TestCase> v;
    detail::add_startup_tests(v);
    detail::add_set_prm_tests(v);
    detail::add_chk_cfg_tests(v);
    detail::add_read_service_tests(v);
    detail::add_fcb_tests(v);
    detail::add_global_control_tests(v);
    detail::add_set_slave_add_tests(v);
    detail::add_timing_tests(v);
    detail::add_interruption_tests(v);
    detail::add_class2_tests(v);
    detail::add_fail_safe_tests(v);
    detail::add_dpv1_tests(v);
    detail::add_consistency_tests(v);
    detail::add_gsd_tests(v);
    return v;
  }();
  return tests;
}

BatteryReport run_battery(const DutSpec& spec, const BatteryOptions& options) {
  BatteryReport report;
  report.spec = spec;
  if (!spec.gsd) {
    report.dut_error = "no GSD";
    return report;
  }
  // The battery plays the class-1 master at 1 and a second master at 2 (TestBusOptions,
  // kOtherMaster): a DUT there would answer its own tester's frames.
  if (spec.address == 1 || spec.address == detail::kOtherMaster || spec.address > 126) {
    report.dut_error = "the DUT's address " + std::to_string(spec.address) +
                       (spec.address > 126 ? " is not a slave address 0..126"
                                           : " is the battery's own (1: the tester, 2: the second master)");
    return report;
  }
  std::unique_ptr<ContextBase> ctx;
  std::string error;
  if (spec.pty_path) {
    auto oc = std::make_unique<OutsideContext>();
    oc->progress = options.progress;
    if (!oc->init(report.spec, error)) {
      report.dut_error = error;
      return report;
    }
    report.timing = oc->timing();
    if (!oc->connect(error)) {
      report.dut_error = error;
      return report;
    }
    ctx = std::move(oc);
  } else {
    auto mc = std::make_unique<ModelContext>();
    if (!mc->init(report.spec, error)) {
      report.dut_error = error;
      return report;
    }
    // Build once at the main baud so a DUT that cannot exist is one clear error, not N failures.
    if (!mc->open(std::nullopt, error)) {
      report.dut_error = error;
      return report;
    }
    report.timing = mc->timing();
    ctx = std::move(mc);
  }

  for (const TestCase& t : all_tests()) {
    if (!selected(t, options)) continue;
    TestResult r;
    r.id = t.id;
    r.group = t.group;
    r.name = t.name;
    r.requirement = t.requirement;
    EvidenceSink sink;
    ctx->set_sink(&sink);
    try {
      if (t.run) t.run(*ctx, r);
      else detail::fail(r, "test has no body");
    } catch (const std::exception& e) {
      r.verdict = Verdict::Fail;
      r.message = std::string("exception: ") + e.what();
    } catch (...) {
      r.verdict = Verdict::Fail;
      r.message = "unknown exception";
    }
    ctx->set_sink(nullptr);
    // Every reply of the test, whatever its rule, must mirror its request's addresses and SAPs.
    if (r.verdict != Verdict::Fail) {
      for (const Exchange& e : sink.exchanges) {
        if (auto why = detail::reply_addressing_fault(e); !why.empty()) {
          r.verdict = Verdict::Fail;
          r.message = why + (r.message.empty() ? std::string() : " [the test itself: " + r.message + "]");
          break;
        }
      }
    }
    if (r.evidence.empty()) r.evidence = std::move(sink.exchanges);
    report.results.push_back(std::move(r));
  }
  return report;
}

}  // namespace pbvbus::conformance
