// DP master systems in scenarios: GSD-driven slave configuration and derived bus parameters
// (decisions in scenario/include/pbvbus/scenario/dp_plan.hpp).
#include "pbvbus/scenario/dp_plan.hpp"

#include <algorithm>
#include <filesystem>
#include <map>

#include "pbvbus/gsd/gsd.hpp"
#include "pbvbus/dp/prm.hpp"
#include "pbvbus/scenario/dp_equidistance_plan.hpp"
#include "pbvbus/scenario/dp_link_plan.hpp"
#include "pbvbus/scenario/scenario.hpp"

namespace pbvbus::tools {

namespace {

constexpr bus::Ticks kTenMs = bus::kTicksPerSecond / 100;


/// Smallest factor pair (f1 <= f2, both 1..255) with f1 * f2 == units; nullopt if none.
std::optional<std::pair<std::uint8_t, std::uint8_t>> wd_factors(std::uint64_t units) {
  for (std::uint64_t f1 = 1; f1 <= 255; ++f1) {
    if (units % f1 != 0) continue;
    const std::uint64_t f2 = units / f1;
    if (f2 >= f1 && f2 <= 255)
      return std::pair(static_cast<std::uint8_t>(f1), static_cast<std::uint8_t>(f2));
  }
  return std::nullopt;
}

dp::SlaveFeatures features_of(const devices::GsdFile& g) {
  dp::SlaveFeatures f;
  const auto& s = g.slave_features();
  const auto& v = g.dpv1();
  f.sync = s.sync_mode_supp;
  f.freeze = s.freeze_mode_supp;
  f.fail_safe = s.fail_safe;
  f.set_slave_add = s.set_slave_add_supp;
  f.dpv1 = v.dpv1_slave;
  f.c1_read_write = v.c1_read_write_supp;
  f.c2 = v.c2_read_write_supp;
  f.c2_connections = std::max<std::uint8_t>(1, v.c2_max_count_channels);
  std::uint8_t al = 0;
  if (v.pull_plug_alarm_supp) al |= dp::kEnablePullPlugAlarm;
  if (v.process_alarm_supp) al |= dp::kEnableProcessAlarm;
  if (v.diagnostic_alarm_supp) al |= dp::kEnableDiagnosticAlarm;
  if (v.manufacturer_specific_alarm_supp) al |= dp::kEnableManufacturerAlarm;
  if (v.status_alarm_supp) al |= dp::kEnableStatusAlarm;
  if (v.update_alarm_supp) al |= dp::kEnableUpdateAlarm;
  f.alarms_supported = al;
  f.max_alarm_mode = v.alarm_type_mode_supp ? 7 : 0;
  f.wd_base_1ms = v.wd_base_1ms_supp;
  f.check_cfg_mode = v.check_cfg_mode;
  f.prm_structure = v.prm_block_structure_supp;
  f.prm_cmd = g.redundancy().prm_cmd_supp;
  return f;
}

class DpPlanner {
 public:
  DpPlanner(ScenarioPlan& plan, const DpLocator& locate, std::vector<Diagnostic>& errors)
      : m_plan(plan), m_locate(locate), m_errors(errors) {}

  void run() {
    const auto& proto = m_plan.proto;
    const std::filesystem::path base = std::filesystem::path(m_plan.file).parent_path();
    for (int i = 0; i < proto.dp_master_size(); ++i) plan_master(i);
    for (int i = 0; i < proto.dp_slave_size(); ++i) plan_slave(i, base);
    for (int i = 0; i < proto.redundant_master_system_size(); ++i) plan_system(i);
    for (int i = 0; i < proto.switched_station_size(); ++i) plan_switched(i, base);
    // IM 157 links (dp_link_plan.hpp): each upper interface planned as a switched station's,
    // from the generated link GSD; errors point at the link entry itself.
    const DpLocator at_entry = [this](const char* rep, int index, const char*, int) {
      return m_locate(rep, index, nullptr, -1);
    };
    plan_dp_links(m_plan, m_locate, m_errors,
                  [&](const scenario::DpSlave& d, const devices::GsdFile& g, const char* rep,
                      int i, int switched, int side) {
                    DpPlanner sub(m_plan, at_entry, m_errors);
                    sub.m_wd = m_wd;
                    const std::size_t before = m_plan.dp_slaves.size();
                    sub.plan_slave(d, rep, i, base, switched, side, &g);
                    return m_plan.dp_slaves.size() == before ? -1 : static_cast<int>(before);
                  });
    derive_line_params();
  }

 private:
  void error(const char* rep, int index, const char* field, int element, std::string msg) {
    auto [l, c] = m_locate(rep, index, field, element);
    m_errors.push_back({m_plan.file, l, c, std::move(msg)});
  }

  int line_index(const std::string& name) const {
    for (std::size_t i = 0; i < m_plan.lines.size(); ++i)
      if (m_plan.lines[i].name == name) return static_cast<int>(i);
    return -1;
  }

  std::optional<bus::Ticks> ten_ms(const char* rep, int i, const char* field,
                                   const std::string& text) {
    auto t = bus::parse_duration(text);
    if (!t) {
      error(rep, i, field, -1, "bad duration \"" + text + "\" (e.g. \"120ms\")");
      return std::nullopt;
    }
    if (*t == 0 || *t % kTenMs != 0) {
      error(rep, i, field, -1, std::string(field) + " \"" + text +
                                   "\" is not a positive multiple of 10 ms");
      return std::nullopt;
    }
    return t;
  }

  void plan_master(int i) {
    const auto& m = m_plan.proto.dp_master(i);
    DpMasterPlan mp;
    mp.source = i;
    mp.line = line_index(m.line());  // unknown lines are reported by the station pass
    mp.params.address = static_cast<std::uint8_t>(m.address() & 0x7F);
    mp.params.auto_clear = m.auto_clear();
    mp.outputs = m.outputs();
    switch (m.mode()) {
      case scenario::DpMaster::CLEAR: mp.params.initial_mode = dp::MasterMode::Clear; break;
      case scenario::DpMaster::STOP: mp.params.initial_mode = dp::MasterMode::Stop; break;
      default: mp.params.initial_mode = dp::MasterMode::Operate; break;
    }
    if (!m.data_control_time().empty()) {
      if (auto t = ten_ms("dp_master", i, "data_control_time", m.data_control_time())) {
        const auto units = *t / kTenMs;
        if (units > 65535)
          error("dp_master", i, "data_control_time", -1, "data_control_time is over 655.35 s");
        else
          mp.params.data_control_time = static_cast<std::uint16_t>(units);
      }
    }
    if (mp.line >= 0 && m.has_address() &&
        m.address() >= m_plan.lines[static_cast<std::size_t>(mp.line)].params.hsa)
      error("dp_master", i, "address", -1,
            "dp_master address " + std::to_string(m.address()) + " is not below HSA " +
                std::to_string(m_plan.lines[static_cast<std::size_t>(mp.line)].params.hsa));
    m_wd.push_back({dp::kPrmLockReq | dp::kPrmWdOn, 10, 10});
    if (!m.watchdog().empty()) {
      if (m.watchdog() == "off") {
        m_wd.back().status = dp::kPrmLockReq;
      } else if (auto t = ten_ms("dp_master", i, "watchdog", m.watchdog())) {
        if (auto f = wd_factors(*t / kTenMs)) {
          m_wd.back().f1 = f->first;
          m_wd.back().f2 = f->second;
        } else {
          error("dp_master", i, "watchdog", -1,
                "watchdog \"" + m.watchdog() +
                    "\" is not a product of two factors 1..255 of 10 ms (max 650.25 s)");
        }
      }
    }
    m_plan.dp_masters.push_back(std::move(mp));
  }

  void plan_slave(int i, const std::filesystem::path& base) {
    plan_slave(m_plan.proto.dp_slave(i), "dp_slave", i, base, -1, -1);
  }

  /// A dp_slave, or one interface of a switched_station (`rep` = "switched_station", the
  /// synthesised entry `s` carries its line and master); errors point into `rep`[i].
  void plan_slave(const scenario::DpSlave& s, const char* rep, int i,
                  const std::filesystem::path& base, int switched, int side,
                  const devices::GsdFile* given = nullptr) {
    m_rep = rep;
    DpSlavePlan sp;
    sp.source = i;
    sp.switched = switched;
    sp.side = side;
    sp.repeated = rep;
    sp.line = line_index(s.line());
    sp.address = static_cast<std::uint8_t>(s.address() & 0x7F);
    sp.io = s.inputs();
    sp.tsdr = s.tsdr_bits();
    bool ok = true;
    // A mutant (test-only, devices/slave_mutant.hpp): by name; never on a switched station.
    if (!s.mutant().empty()) {
      if (switched >= 0) {
        error(m_rep, i, "mutant", -1, "a switched_station cannot be a mutant slave");
        ok = false;
      } else if (auto mu = devices::parse_slave_mutant(s.mutant())) {
        sp.mutant = *mu;
      } else {
        std::string known;
        for (const auto& info : devices::slave_mutants())
          known += (known.empty() ? "" : ", ") + std::string(info.name);
        error(m_rep, i, "mutant", -1,
              "unknown mutant \"" + s.mutant() + "\" (known: " + known + ")");
        ok = false;
      }
    }
    // The master: none = whoever parameterises it (a master outside pbvbus).
    int mi = -1;
    sp.master = dp::kNoMaster;
    if (s.has_master()) {
      for (std::size_t k = 0; k < m_plan.dp_masters.size(); ++k) {
        const auto& mm = m_plan.proto.dp_master(m_plan.dp_masters[k].source);
        if (mm.has_address() && mm.address() == s.master() && mm.line() == s.line())
          mi = static_cast<int>(k);
      }
      if (mi < 0) {
        error(m_rep, i, "master", -1,
              "no dp_master " + std::to_string(s.master()) + " on line \"" + s.line() + "\"");
        ok = false;
      }
      sp.master = static_cast<std::uint8_t>(s.master() & 0x7F);
    }
    // The GSD.
    if (s.gsd().empty()) {
      error(m_rep, i, nullptr, -1, "dp_slave needs a gsd file");
      return;
    }
    std::filesystem::path p(s.gsd());
    if (p.is_relative() && given == nullptr) p = base / p;
    sp.gsd_path = p.string();
    // An IM 157 link's generated GSD comes in `given` (dp_link_plan.hpp).
    auto loaded = given != nullptr ? devices::GsdParseResult{*given, {}, {}} : devices::load_gsd(p);
    if (!loaded.ok()) {
      std::string why = loaded.errors.empty() ? "cannot be read" : loaded.errors.front().to_string();
      error(m_rep, i, "gsd", -1, "GSD file \"" + s.gsd() + "\": " + why);
      return;
    }
    const devices::GsdFile& g = *loaded.file;
    sp.model = g.info().model_name;
    if (g.is_master()) {
      error(m_rep, i, "gsd", -1, "GSD file \"" + s.gsd() + "\" describes a DP master");
      return;
    }
    if (sp.line >= 0) {
      const bus::Baud baud = m_plan.lines[static_cast<std::size_t>(sp.line)].baud;
      if (auto mt = g.max_tsdr(baud)) {
        sp.gsd_max_tsdr = *mt;
      } else {
        error(m_rep, i, "gsd", -1,
              "\"" + sp.model + "\" (" + s.gsd() + ") does not support " +
                  std::string(bus::baud_name(baud)) + "bit/s of line \"" + s.line() + "\"");
        ok = false;
      }
      const auto& lp = m_plan.lines[static_cast<std::size_t>(sp.line)].params;
      if (s.has_tsdr_bits() && sp.gsd_max_tsdr != 0 &&
          (s.tsdr_bits() > sp.gsd_max_tsdr || s.tsdr_bits() < lp.min_tsdr)) {
        error(m_rep, i, "tsdr_bits", -1,
              "tsdr_bits " + std::to_string(s.tsdr_bits()) + " is outside [min TSDR " +
                  std::to_string(lp.min_tsdr) + ", MaxTsdr " + std::to_string(sp.gsd_max_tsdr) +
                  " of " + s.gsd() + "]");
        ok = false;
      }
    }
    // Modules.
    std::vector<std::size_t> mods;
    if (s.modules_size() == 0 && !g.slave_features().modular_station && g.modules().size() == 1) {
      mods.push_back(0);
    } else if (s.modules_size() == 0) {
      // Name the station kind the GSD declares: a compact station whose GSD offers several
      // variants needs its one module chosen, it is not "modular".
      const bool modular = g.slave_features().modular_station;
      error(m_rep, i, nullptr, -1,
            modular ? "dp_slave with the modular GSD \"" + s.gsd() +
                          "\" needs a module list (modules: [\"...\"], at most Max_Module = " +
                          std::to_string(g.slave_features().max_module) + ")"
                    : "dp_slave with the compact GSD \"" + s.gsd() + "\" offers " +
                          std::to_string(g.modules().size()) +
                          " modules: choose one (modules: \"name\")");
      ok = false;
    }
    for (int k = 0; k < s.modules_size(); ++k) {
      if (auto idx = g.find_module(s.modules(k))) {
        mods.push_back(*idx);
      } else {
        std::string known;
        for (const auto& gm : g.modules()) known += (known.empty() ? "\"" : ", \"") + gm.name + "\"";
        error(m_rep, i, "modules", k,
              "unknown module \"" + s.modules(k) + "\" in " + s.gsd() + " (it has " + known + ")");
        ok = false;
      }
    }
    if (!ok) return;
    auto check = g.check_modules(mods);
    if (!check.ok()) {
      error(m_rep, i, "modules", -1, "module list refused by " + s.gsd() + ": " + check.errors.front());
      return;
    }
    auto prm = g.user_prm_data(mods);
    if (!prm.ok()) {
      error(m_rep, i, "modules", -1, "User_Prm_Data of " + s.gsd() + ": " + prm.errors.front());
      return;
    }
    sp.gsd_modules = mods;
    sp.inputs = check.value->first;
    sp.outputs = check.value->second;

    dp::SlaveConfig& c = sp.config;
    c.ident = g.ident_number();
    c.features = features_of(g);
    c.min_user_prm_len = prm.value->size();
    c.max_user_prm_len = g.max_user_prm_data_len();
    c.min_slave_interval = std::max<std::uint16_t>(1, g.slave_features().min_slave_intervall);
    c.max_diag_len = std::max<std::size_t>(6, g.slave_features().max_diag_data_len);
    for (std::size_t idx : mods) {
      const auto& gm = g.modules()[idx];
      c.modules.push_back({gm.config, gm.name});
      sp.module_names.push_back(gm.name);
    }
    dp::SlaveParams& sm = sp.params;
    sm.address = sp.address;
    sm.name = sp.model;
    sm.ident = c.ident;
    if (mi >= 0) {
      const auto& wd = m_wd[static_cast<std::size_t>(mi)];
      sm.station_status = wd.status;
      sm.wd_fact_1 = wd.f1;
      sm.wd_fact_2 = wd.f2;
    }
    sm.user_prm = *prm.value;
    // A switched station's Set_Prm carries a PrmCmd block; redundancy::MasterSystem writes it.
    if (switched >= 0) sm.prm_cmd.assign(dp::kPrmCmdBlockLen, 0);
    sm.modules = c.modules;
    sm.min_slave_interval = c.min_slave_interval;
    sm.fail_safe = c.features.fail_safe;
    if (g.dpv1().c1_response_timeout != 0) sm.c1_response_timeout = g.dpv1().c1_response_timeout;
    if (std::string why = dp::build_layout(c, m_layout); !why.empty()) {
      error(m_rep, i, "modules", -1, "configuration of " + s.gsd() + ": " + why);
      return;
    }
    if (!plan_io(i, s, sp)) return;
    {  // F3 parameter records (prm_record_plan.hpp)
      std::vector<std::pair<int, std::string>> errs;
      sp.prm_records = plan_prm_records(s, sp.module_names,
                                        g.dpv1().dpv1_slave && g.dpv1().c1_read_write_supp, errs);
      for (auto& [k, msg] : errs) error(m_rep, i, "parameter_record", k, std::move(msg));
      if (!errs.empty()) return;
    }
    sp.gsd = std::make_shared<const devices::GsdFile>(g);
    if (mi >= 0)
      m_plan.dp_masters[static_cast<std::size_t>(mi)].slaves.push_back(
          static_cast<int>(m_plan.dp_slaves.size()));
    m_plan.dp_slaves.push_back(std::move(sp));
  }

  /// Module index in the slave's list by name (first match) or position; reports errors.
  std::optional<std::size_t> module_ref(int i, int k, const DpSlavePlan& sp, bool by_index,
                                        std::uint32_t index, const std::string& name,
                                        const char* what) {
    if (by_index) {
      if (index < sp.module_names.size()) return index;
      error(m_rep, i, "io", k,
            std::string(what) + " module_index " + std::to_string(index) + " is not below the " +
                std::to_string(sp.module_names.size()) + " modules of the slave");
      return std::nullopt;
    }
    for (std::size_t m = 0; m < sp.module_names.size(); ++m)
      if (sp.module_names[m] == name) return m;
    error(m_rep, i, "io", k,
          std::string(what) + " module \"" + name + "\" is not one of the slave's modules");
    return std::nullopt;
  }

  std::optional<bus::Ticks> io_duration(int i, int k, const std::string& text, const char* what) {
    auto t = bus::parse_duration(text);
    if (!t) error(m_rep, i, "io", k, std::string("bad duration \"") + text + "\" for " + what +
                                              " (e.g. \"100ms\")");
    return t;
  }

  bool plan_io(int i, const scenario::DpSlave& s, DpSlavePlan& sp) {
    bool ok = true;
    using BC = scenario::DpSlaveIo::BehaviourCase;
    for (int k = 0; k < s.io_size(); ++k) {
      const auto& io = s.io(k);
      if (io.module_ref_case() == scenario::DpSlaveIo::MODULE_REF_NOT_SET) {
        error(m_rep, i, "io", k, "io needs a module: module: \"name\" or module_index: n");
        ok = false;
        continue;
      }
      auto m = module_ref(i, k, sp, io.has_module_index(), io.module_index(), io.module(), "io");
      if (!m) {
        ok = false;
        continue;
      }
      const dp::ModuleLayout& ml = m_layout.modules[*m];
      DpIoPlan p;
      p.module = *m;
      if (ml.in_len == 0) {
        error(m_rep, i, "io", k, "module \"" + sp.module_names[*m] + "\" has no inputs");
        ok = false;
        continue;
      }
      p.whole = !io.has_offset() && !io.has_width();
      p.offset = io.offset();
      p.width = io.has_width() ? io.width() : (io.offset() < ml.in_len ? ml.in_len - io.offset() : 0);
      if (p.width == 0 || p.offset + p.width > ml.in_len) {
        error(m_rep, i, "io", k,
              "channel offset " + std::to_string(p.offset) + " width " + std::to_string(p.width) +
                  " is outside the " + std::to_string(ml.in_len) + " input octets of module \"" +
                  sp.module_names[*m] + "\"");
        ok = false;
        continue;
      }
      const std::size_t width = p.whole ? ml.in_len : p.width;
      devices::IoBehaviour& b = p.behaviour;
      bool good = true;
      switch (io.behaviour_case()) {
        case BC::kConstant: {
          std::vector<std::uint8_t> v(width, 0);
          devices::put_big_endian(static_cast<std::int64_t>(io.constant().value()), v.begin(), width);
          b = devices::IoBehaviour::constant_value(std::move(v));
          break;
        }
        case BC::kCounter: {
          const auto& c = io.counter();
          bus::Ticks period = 0;
          if (!c.period().empty()) {
            auto t = io_duration(i, k, c.period(), "counter period");
            if (!t || *t == 0) {
              if (t) error(m_rep, i, "io", k, "counter period must be longer than 0");
              good = false;
            } else {
              period = *t;
            }
          }
          b = devices::IoBehaviour::counter_every(period, c.has_step() ? c.step() : 1, c.start());
          break;
        }
        case BC::kRamp: {
          const auto& r = io.ramp();
          auto t = r.period().empty() ? std::nullopt : io_duration(i, k, r.period(), "ramp period");
          if (r.period().empty()) error(m_rep, i, "io", k, "ramp needs a period");
          if (!t) good = false;
          b = devices::IoBehaviour::ramp(r.min(), r.max(), t.value_or(0));
          break;
        }
        case BC::kTable: {
          const auto& tb = io.table();
          std::vector<std::pair<bus::Ticks, std::int64_t>> rows;
          for (const auto& row : tb.row()) {
            auto t = io_duration(i, k, row.at(), "table row");
            if (!t) good = false;
            rows.emplace_back(t.value_or(0), row.value());
          }
          bus::Ticks period = 0;
          if (!tb.period().empty()) {
            auto t = io_duration(i, k, tb.period(), "table period");
            if (!t) good = false;
            period = t.value_or(0);
          }
          b = devices::IoBehaviour::table(std::move(rows), tb.repeat(), period);
          break;
        }
        case BC::kEcho: {
          const auto& e = io.echo();
          std::optional<std::size_t> src;
          if (e.source_case() != scenario::IoEcho::SOURCE_NOT_SET) {
            src = module_ref(i, k, sp, e.has_from_module_index(), e.from_module_index(),
                             e.from_module(), "echo from");
            if (!src) good = false;
          }
          const std::size_t from = src.value_or(*m);
          if (good && m_layout.modules[from].out_len == 0) {
            error(m_rep, i, "io", k,
                  "echo source module \"" + sp.module_names[from] + "\" has no outputs");
            good = false;
          }
          b = devices::IoBehaviour::echo(src ? src : std::optional<std::size_t>(*m));
          break;
        }
        case BC::BEHAVIOUR_NOT_SET:
          error(m_rep, i, "io", k, "io needs a behaviour: constant, counter, ramp, table or echo");
          good = false;
          break;
      }
      if (good) {
        if (std::string why = devices::check_behaviour(b, m_layout.modules.size()); !why.empty()) {
          error(m_rep, i, "io", k, why);
          good = false;
        }
      }
      if (!good) {
        ok = false;
        continue;
      }
      sp.io_behaviours.push_back(std::move(p));
    }
    return ok;
  }

  /// The dp_master at `address` on line `li`, as an index into dp_masters, or -1.
  int master_at(int li, std::uint32_t address) const {
    for (std::size_t k = 0; k < m_plan.dp_masters.size(); ++k) {
      const auto& mm = m_plan.proto.dp_master(m_plan.dp_masters[k].source);
      if (m_plan.dp_masters[k].line == li && mm.has_address() && mm.address() == address)
        return static_cast<int>(k);
    }
    return -1;
  }

  void plan_system(int i) {
    const auto& r = m_plan.proto.redundant_master_system(i);
    const char* rep = "redundant_master_system";
    RedundancyPlan rp;
    rp.source = i;
    rp.name = r.name();
    bool ok = true;
    if (r.name().empty()) {
      error(rep, i, nullptr, -1, "redundant_master_system needs a name");
      ok = false;
    }
    for (const auto& other : m_plan.redundant_systems)
      if (!r.name().empty() && other.name == r.name()) {
        error(rep, i, "name", -1, "redundant_master_system \"" + r.name() + "\" is defined twice");
        ok = false;
      }
    const std::string* lines[2] = {&r.line_a(), &r.line_b()};
    const bool has[2] = {r.has_master_a(), r.has_master_b()};
    const std::uint32_t addr[2] = {r.master_a(), r.master_b()};
    const char* lf[2] = {"line_a", "line_b"};
    const char* mf[2] = {"master_a", "master_b"};
    for (int side = 0; side < 2; ++side) {
      rp.line[side] = line_index(*lines[side]);
      if (rp.line[side] < 0) {
        error(rep, i, lf[side], -1,
              lines[side]->empty() ? std::string(lf[side]) + " is missing"
                                   : "unknown line \"" + *lines[side] + "\"");
        ok = false;
        continue;
      }
      if (!has[side]) {
        error(rep, i, mf[side], -1, std::string(mf[side]) + " (the dp_master's address) is missing");
        ok = false;
        continue;
      }
      rp.master[side] = master_at(rp.line[side], addr[side]);
      if (rp.master[side] < 0) {
        error(rep, i, mf[side], -1, "no dp_master " + std::to_string(addr[side]) + " on line \"" +
                                        *lines[side] + "\"");
        ok = false;
        continue;
      }
      for (const auto& other : m_plan.redundant_systems)
        if (other.master[0] == rp.master[side] || other.master[1] == rp.master[side]) {
          error(rep, i, mf[side], -1, "dp_master " + std::to_string(addr[side]) + " on line \"" +
                                          *lines[side] + "\" is already in system \"" +
                                          other.name + "\"");
          ok = false;
        }
    }
    if (ok && rp.line[0] == rp.line[1]) {
      error(rep, i, "line_b", -1, "line_a and line_b must be two different lines");
      ok = false;
    }
    if (ok && m_plan.lines[static_cast<std::size_t>(rp.line[0])].baud !=
                  m_plan.lines[static_cast<std::size_t>(rp.line[1])].baud) {
      error(rep, i, "line_b", -1, "the two lines of a redundant master system run at one baud rate");
      ok = false;
    }
    if (!r.output_hold_time().empty()) {
      if (auto t = ten_ms(rep, i, "output_hold_time", r.output_hold_time())) {
        if (*t / kTenMs > 65535) {
          error(rep, i, "output_hold_time", -1, "output_hold_time is over 655.35 s");
          ok = false;
        } else {
          rp.output_hold_10ms = static_cast<std::uint16_t>(*t / kTenMs);
        }
      } else {
        ok = false;
      }
    }
    rp.preferred = r.preferred() == scenario::RedundantMasterSystem::B ? 1 : 0;
    if (!ok) rp.line[0] = rp.line[1] = -1;  // kept for names, never built
    m_plan.redundant_systems.push_back(std::move(rp));
  }

  void plan_switched(int i, const std::filesystem::path& base) {
    const auto& w = m_plan.proto.switched_station(i);
    const char* rep = "switched_station";
    int sys = -1;
    for (std::size_t k = 0; k < m_plan.redundant_systems.size(); ++k)
      if (!w.system().empty() && m_plan.redundant_systems[k].name == w.system())
        sys = static_cast<int>(k);
    if (sys < 0) {
      error(rep, i, "system", -1,
            w.system().empty() ? std::string("switched_station needs a system (a redundant_master_system's name)")
                               : "no redundant_master_system \"" + w.system() + "\"");
      return;
    }
    RedundancyPlan& rp = m_plan.redundant_systems[static_cast<std::size_t>(sys)];
    if (rp.line[0] < 0) return;  // the system itself is broken (reported)
    if (!w.has_address()) {
      error(rep, i, nullptr, -1, "switched_station needs an address");
      return;
    }
    if (w.address() > dp::kMaxSlaveAddress) {
      error(rep, i, "address", -1, "switched_station address " + std::to_string(w.address()) +
                                       " is out of range 0..125");
      return;
    }
    SwitchedPlan swp;
    swp.source = i;
    swp.system = sys;
    swp.address = static_cast<std::uint8_t>(w.address());
    const int index = static_cast<int>(m_plan.switched.size());
    for (int side = 0; side < 2; ++side) {
      scenario::DpSlave d;
      d.set_address(w.address());
      d.set_line(m_plan.lines[static_cast<std::size_t>(rp.line[side])].name);
      d.set_master(m_plan.proto.dp_master(m_plan.dp_masters[static_cast<std::size_t>(rp.master[side])].source).address());
      d.set_gsd(w.gsd());
      for (const auto& m : w.modules()) d.add_modules(m);
      if (w.has_tsdr_bits()) d.set_tsdr_bits(w.tsdr_bits());
      d.set_inputs(w.inputs());
      for (const auto& io : w.io()) *d.add_io() = io;
      for (const auto& r : w.parameter_record()) *d.add_parameter_record() = r;
      const std::size_t before = m_plan.dp_slaves.size();
      const std::size_t errors_before = m_errors.size();
      plan_slave(d, rep, i, base, index, side);
      if (m_plan.dp_slaves.size() == before) return;  // reported
      swp.slave[side] = static_cast<int>(before);
      if (side == 1 && m_errors.size() > errors_before) return;
    }
    const DpSlavePlan& a = m_plan.dp_slaves[static_cast<std::size_t>(swp.slave[0])];
    const devices::GsdRedundancy& red = a.gsd->redundancy();
    if (!red.system_redundancy() || !red.prm_cmd_supp) {
      error(rep, i, "gsd", -1,
            "GSD file \"" + w.gsd() + "\" does not declare System Redundancy "
            "(Slave_Redundancy_supp bit 0 and PrmCmd_supp = 1)");
      m_plan.dp_slaves.resize(static_cast<std::size_t>(swp.slave[0]));
      return;
    }
    if (!w.switchover_time().empty()) {
      auto t = bus::parse_duration(w.switchover_time());
      if (!t || *t == 0) {
        error(rep, i, "switchover_time", -1,
              "bad switchover_time \"" + w.switchover_time() + "\" (e.g. \"30ms\")");
      } else {
        swp.t_slave_um = *t;
      }
    } else if (red.slave_max_switch_over_time != 0) {
      swp.t_slave_um = static_cast<bus::Ticks>(red.slave_max_switch_over_time) *
                       devices::GsdRedundancy::kSwitchOverUnitMs * bus::kTicksPerMs;
      swp.t_slave_um_from_gsd = true;
    }
    rp.switched.push_back(index);
    m_plan.switched.push_back(swp);
  }

  void derive_line_params() {
    for (std::size_t li = 0; li < m_plan.lines.size(); ++li) {
      PlanLine& line = m_plan.lines[li];
      const scenario::BusParameters& given = m_plan.proto.line(static_cast<int>(li)).bus_params();
      std::vector<std::pair<std::size_t, std::size_t>> io;
      std::uint32_t max_tsdr = line.params.max_tsdr;
      for (const auto& s : m_plan.dp_slaves) {
        if (s.line != static_cast<int>(li)) continue;
        io.emplace_back(s.outputs, s.inputs);
        max_tsdr = std::max<std::uint32_t>(max_tsdr, s.gsd_max_tsdr);
      }
      if (io.empty()) continue;
      if (!given.has_max_tsdr()) line.params.max_tsdr = max_tsdr;
      if (!given.has_tsl())
        line.params.tsl = std::max(line.params.tsl, line.params.max_tsdr + fdl::BusParams::kTslMargin);
      if (!given.has_ttr()) line.params.ttr = dp_ttr(line.params, io);
      if (std::string why = line.params.validate(); !why.empty()) {
        auto [l, c] = m_locate("line", static_cast<int>(li), nullptr, -1);
        m_errors.push_back({m_plan.file, l, c,
                            "bus parameters derived for the DP slaves of line \"" + line.name +
                                "\": " + why});
      }
      for (const auto& s : m_plan.dp_slaves) {
        if (s.line != static_cast<int>(li) || s.gsd_max_tsdr == 0) continue;
        if (s.gsd_max_tsdr > line.params.max_tsdr) {
          auto [l, c] = m_locate(s.repeated, s.source, nullptr, -1);
          m_errors.push_back({m_plan.file, l, c,
                              "MaxTsdr " + std::to_string(s.gsd_max_tsdr) + " of " +
                                  s.gsd_path +
                                  " is above the max TSDR " + std::to_string(line.params.max_tsdr) +
                                  " given for line \"" + line.name + "\""});
        }
      }
    }
    // Each slave's Set_Prm carries the line's min TSDR.
    for (auto& s : m_plan.dp_slaves)
      if (s.line >= 0)
        s.params.min_tsdr = static_cast<std::uint8_t>(
            m_plan.lines[static_cast<std::size_t>(s.line)].params.min_tsdr);
  }

  struct Wd {
    std::uint8_t status;
    std::uint8_t f1;
    std::uint8_t f2;
  };
  ScenarioPlan& m_plan;
  const DpLocator& m_locate;
  std::vector<Diagnostic>& m_errors;
  std::vector<Wd> m_wd;  // per dp_master
  dp::SlaveLayout m_layout;
  const char* m_rep = "dp_slave";
};

}  // namespace

std::uint32_t dp_ttr(const fdl::BusParams& p,
                     const std::vector<std::pair<std::size_t, std::size_t>>& io) {
  std::uint64_t pass = 0;
  for (const auto& [out, in] : io)
    pass += 11 * dp_request_octets(out) + p.max_tsdr + 11 * dp_response_octets(in) + p.tid1();
  pass += 11 * 3 + p.tid1();                   // token pass
  pass += 11 * 13 + p.tid2();                  // Global_Control: SD2 with SAPs 58/62, 2 octets
  pass += 11 * 6 + p.tsl + p.tid1();           // one unanswered GAP poll
  // The token hold time is TTR - TRR: in steady state the last rotation (one pass) is deducted
  // before this visit's pass may start, and the station keeps TSL + 100 back for its GAP poll.
  const std::uint64_t ttr = 2 * pass + p.tsl + 100;
  return static_cast<std::uint32_t>(
      std::clamp<std::uint64_t>(ttr, fdl::BusParams::kTtrMin, fdl::BusParams::kTtrMax));
}

void plan_dp(ScenarioPlan& plan, const DpLocator& locate, std::vector<Diagnostic>& errors) {
  DpPlanner(plan, locate, errors).run();
  plan_dp_equidistance(plan, locate, errors);
}

}  // namespace pbvbus::tools
