// The battery runner (battery.hpp): the test list, the two kinds of DUT context, and the loop
// that runs each test and never lets one abort the run.
//
// Decisions:
// - Slave model DUT: every open() builds a FRESH SlaveModel on a fresh TestBus, so no test sees
//   another's state. Bus parameters at a baud: the DP-profile defaults (fdl::BusParams::
//   defaults) with max TSDR = the GSD's MaxTsdr there and TSL = max(default TSL, max TSDR + 15);
//   the model's own delay is the line's min TSDR (a fast ASIC, SlaveModel's default).
// - Outside DUT (a program behind a pty): ONE paced TestBus with a PtyStation (Station mode at
//   the DUT's address, Interface timing, reply window = TSL) for the whole run; each open()
//   resets the program with an unlocking Set_Prm (Lock_Req 0, Unlock_Req 1) from the tester and
//   10 ms of virtual idle; only the main baud. The pty path given is a symlink to the pty.
// - Main baud: DutSpec::baud, else the highest rate the GSD supports up to 1.5 Mbit/s (else its
//   lowest rate).
// - Evidence: every session a test opened contributes its exchanges from its opening on (copied
//   when the session closes), unless the body filled result.evidence itself.
// - An exception out of a body is a Fail with its message; the run goes on.

#include <algorithm>
#include <filesystem>
#include <system_error>

#include "groups.hpp"
#include "pbvbus/bus/pty_station.hpp"
#include "pbvbus/conformance/battery.hpp"

#include "pbvbus/bus/pty.hpp"
#include "pbvbus/dp/sap.hpp"
#include "steps.hpp"

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
    to.paced = m_spec->speed;
    to.dx_interval = dx_interval();
    try {
      m_bus = std::make_unique<TestBus>(to);
      bus::PtyStation::Options po;
      po.mode = bus::PtyStation::Mode::Station;
      po.address = m_spec->address;
      po.timing = bus::PtyStation::Timing::Interface;
      po.reply_window_bits = params->tsl;
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
    // Reset: an unlocking Set_Prm (Lock_Req 0, Unlock_Req 1) releases the program from any
    // earlier test's parameterisation; then 10 ms of virtual idle.
    dp::SlaveParams p = m_params;
    p.station_status = dp::kPrmUnlockReq;
    const auto du = detail::prm_du(p);
    set_prm(*s, du, "reset: Set_Prm Unlock_Req");
    m_bus->idle(10 * bus::kTicksPerMs);
    return s;
  }

 private:
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
  std::unique_ptr<ContextBase> ctx;
  std::string error;
  if (spec.pty_path) {
    auto oc = std::make_unique<OutsideContext>();
    if (!oc->init(report.spec, error) || !oc->connect(error)) {
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
    if (r.evidence.empty()) r.evidence = std::move(sink.exchanges);
    report.results.push_back(std::move(r));
  }
  return report;
}

}  // namespace pbvbus::conformance
