// A scenario's h_system entries (h_plan.hpp).
#include "pbvbus/scenario/h_plan.hpp"

#include <algorithm>
#include <exception>
#include <map>

#include "pbvbus/scenario/h_config_rules.hpp"
#include "pbvbus/scenario/scenario.hpp"
#include "pbvbus/scenario/timing_plan.hpp"

namespace pbvbus::tools {

namespace {

class HPlanner {
 public:
  HPlanner(ScenarioPlan& plan, const DpLocator& locate, const HLocator& hlocate,
           std::vector<Diagnostic>& errors)
      : m_plan(plan), m_locate(locate), m_hlocate(hlocate), m_errors(errors) {}

  void run() {
    for (int i = 0; i < m_plan.proto.h_system_size(); ++i) plan_one(i);
    check_shared_systems();
  }

 private:
  void error(int i, const char* field, std::string msg) {
    auto [l, c] = m_locate("h_system", i, field, -1);
    m_errors.push_back({m_plan.file, l, c, std::move(msg)});
  }
  void error_at(int i, const std::vector<HPathStep>& path, std::string msg) {
    auto [l, c] = m_hlocate(i, path);
    m_errors.push_back({m_plan.file, l, c, std::move(msg)});
  }

  /// A duration field inside the entry (nested path); nullopt with an error if it is bad or
  /// not above 0 when `positive`.
  std::optional<bus::Ticks> ticks(int i, const std::vector<HPathStep>& path, const std::string& text,
                                  bool positive) {
    auto t = bus::parse_duration(text);
    const std::string name = path.back().field;
    if (!t) {
      error_at(i, path, "bad duration \"" + text + "\" for " + name + " (e.g. \"100ms\")");
      return std::nullopt;
    }
    if (positive && *t <= 0) {
      error_at(i, path, name + " must be longer than 0");
      return std::nullopt;
    }
    return t;
  }

  /// A duration in whole µs (ns precision is not needed for ms-scale H parameters).
  std::optional<devices::Us> us(int i, const char* field, const std::string& text,
                                bool zero_ok = true) {
    auto t = bus::parse_duration(text);
    if (!t) {
      error(i, field, "bad duration \"" + text + "\" (e.g. \"25ms\")");
      return std::nullopt;
    }
    if (*t % bus::kTicksPerUs != 0) {
      error(i, field, std::string(field) + " \"" + text + "\" is not a whole number of µs");
      return std::nullopt;
    }
    if (!zero_ok && *t == 0) {
      error(i, field, std::string(field) + " must be longer than 0");
      return std::nullopt;
    }
    return *t / bus::kTicksPerUs;
  }

  void plan_one(int i) {
    const auto& h = m_plan.proto.h_system(i);
    HSystemPlan hp;
    hp.source = i;
    hp.name = h.name().empty() ? "H-system" : h.name();
    for (int k = 0; k < h.dp_system_size(); ++k) {
      const auto& d = h.dp_system(k);
      HDpSystemPlan dp;
      dp.name = !d.name().empty() ? d.name() : !d.system().empty() ? d.system()
                                                                     : "DP master system " + std::to_string(k + 1);
      if (!d.system().empty()) {
        for (std::size_t s = 0; s < m_plan.redundant_systems.size(); ++s)
          if (m_plan.redundant_systems[s].name == d.system() &&
              m_plan.redundant_systems[s].line[0] >= 0)
            dp.system = static_cast<int>(s);
        if (dp.system < 0) {
          error(i, "dp_system", "h_system dp_system: no redundant_master_system \"" + d.system() + "\"");
          continue;
        }
      }
      if (!d.t_tr().empty()) dp.t_tr = us(i, "dp_system", d.t_tr());
      if (!d.t_dp_um().empty()) dp.t_dp_um = us(i, "dp_system", d.t_dp_um());
      if (!d.t_slave_um().empty()) dp.t_slave_um = us(i, "dp_system", d.t_slave_um());
      if (dp.system < 0 && (!dp.t_tr || !dp.t_dp_um || !dp.t_slave_um))
        error(i, "dp_system",
              "h_system dp_system \"" + dp.name +
                  "\" names no redundant_master_system: it needs t_tr, t_dp_um and t_slave_um");
      if (d.t_pto().empty()) {
        error(i, "dp_system", "h_system dp_system \"" + dp.name + "\" needs t_pto");
      } else if (auto t = us(i, "dp_system", d.t_pto(), false)) {
        dp.t_pto = *t;
      }
      hp.dp_systems.push_back(std::move(dp));
    }
    if (!h.t_wa().empty())
      if (auto t = us(i, "t_wa", h.t_wa())) hp.t_wa = *t;
    if (!h.t_prog().empty())
      if (auto t = us(i, "t_prog", h.t_prog())) hp.t_prog = *t;
    hp.db_kb = h.work_memory_db_kb();
    if (h.has_h_parameters()) {
      const auto& p = h.h_parameters();
      if (!p.max_cycle_extension().empty())
        hp.params.max_cycle_extension = us(i, "h_parameters", p.max_cycle_extension());
      if (!p.max_communication_delay().empty())
        hp.params.max_comm_delay = us(i, "h_parameters", p.max_communication_delay());
      if (!p.max_blocking_time().empty())
        hp.params.t_p15 = us(i, "h_parameters", p.max_blocking_time());
      if (!p.min_io_hold_time().empty())
        hp.params.t_ph = us(i, "h_parameters", p.min_io_hold_time());
    }
    if (h.has_cpu()) {
      plan_runtime(i, hp);
    } else if (h.has_program()) {
      error(i, "program", "h_system \"" + hp.name + "\": a program needs a cpu part (the simulated pair)");
    }
    // ---- F4 connections, SSL ----
    if (!h.has_cpu() && (h.cp_size() > 0 || h.connection_size() > 0))
      error(i, h.cp_size() > 0 ? "cp" : "connection",
            "h_system \"" + hp.name + "\": cp and connection entries need a cpu part (the simulated pair)");
    if (!h.has_cpu() && h.redundant_io_size() > 0)
      error(i, "redundant_io", "h_system \"" + hp.name + "\": redundant_io needs a cpu part (the simulated pair)");
    if (!h.has_cpu() && h.expansion_rack_size() > 0)
      error(i, "expansion_rack",
            "h_system \"" + hp.name + "\": expansion racks need a cpu part (the simulated pair)");
    m_plan.h_systems.push_back(std::move(hp));
  }

  void plan_runtime(int i, HSystemPlan& hp) {
    const auto& h = m_plan.proto.h_system(i);
    const auto& c = h.cpu();
    HRuntimePlan rt;
    auto& p = rt.pair;
    p.profile = c.profile() == scenario::HCpuPair::S7_1500RH ? devices::HProfile::S7_1500RH
                                                             : devices::HProfile::S7_400H;
    const scenario::HCpu* cpus[2] = {&c.cpu0(), &c.cpu1()};
    for (int r = 0; r < 2; ++r) {
      const char* field = r == 0 ? "cpu0" : "cpu1";
      p.switch_run[static_cast<std::size_t>(r)] = cpus[r]->switch_() == scenario::HCpu::RUN;
      if (!cpus[r]->has_power_on()) continue;  // default: 0 s
      const std::string& text = cpus[r]->power_on();
      if (text == "off") {
        rt.power_on[static_cast<std::size_t>(r)].reset();
      } else if (auto t = ticks(i, {{"cpu"}, {field}, {"power_on"}}, text, false)) {
        if (m_plan.duration && *t > *m_plan.duration)
          error_at(i, {{"cpu"}, {field}, {"power_on"}},
                   "power_on " + text + " is after the end of the run (" + m_plan.proto.duration() + ")");
        rt.power_on[static_cast<std::size_t>(r)] = *t;
      }
    }
    rt.fibres_connected_at_power_on =
        !c.has_fibres_connected_at_power_on() || c.fibres_connected_at_power_on();
    if (!c.startup_time().empty())
      if (auto t = ticks(i, {{"cpu"}, {"startup_time"}}, c.startup_time(), true)) p.startup_time = *t;
    if (!c.link_up_time().empty())
      if (auto t = ticks(i, {{"cpu"}, {"link_up_time"}}, c.link_up_time(), true)) p.link_up_time = *t;
    if (!c.self_test_time().empty())
      if (auto t = ticks(i, {{"cpu"}, {"self_test_time"}}, c.self_test_time(), true))
        p.self_test_time = *t;
    if (c.has_update_db_kb())
      p.update_db_kb = c.update_db_kb();
    else if (h.work_memory_db_kb() != 0)
      p.update_db_kb = h.work_memory_db_kb();
    p.comparison_reaction = c.comparison_reaction() == scenario::HCpuPair::STOP
                                ? devices::ComparisonReaction::Stop
                                : devices::ComparisonReaction::ErrorSearch;
    rt.param_transfer_time_100ms = c.param_transfer_time_100ms();  // 001 L8094-8114

    // The driven systems: dp_system entries naming a redundant_master_system, each once.
    for (std::size_t k = 0; k < hp.dp_systems.size(); ++k) {
      const int s = hp.dp_systems[k].system;
      if (s < 0) continue;
      bool dup = false;
      for (int x : rt.systems) dup |= x == s;
      if (dup) {
        error_at(i, {{"dp_system", static_cast<int>(k)}, {"system"}},
                 "h_system \"" + hp.name + "\": redundant_master_system \"" +
                     m_plan.redundant_systems[static_cast<std::size_t>(s)].name +
                     "\" is named twice (a pair drives a system once)");
        continue;
      }
      rt.systems.push_back(s);
    }
    if (h.has_program()) plan_program(i, h.program(), rt.program);
    plan_comms(i, rt);  // F4 connections
    for (int k = 0; k < h.expansion_rack_size(); ++k) plan_rack(i, k, rt.racks);
    plan_redundant_io(m_plan, i, rt, [&](std::vector<HPathStep> path, std::string msg) {
      error_at(i, path, std::move(msg));
    });
    if (!c.max_cycle_time().empty())
      if (auto t = ticks(i, {{"cpu"}, {"max_cycle_time"}}, c.max_cycle_time(), true))
        rt.max_cycle_time = *t;
    plan_h_changes(m_plan, i, rt, [&](std::vector<HPathStep> path, std::string msg) {
      error_at(i, path, std::move(msg));
    });  // docs/h-scenario-changes.md

    // A simulated pair must not run on a bad set of H parameters.
    try {
      const devices::UpdatePlan up = devices::plan_update(h_update_input(m_plan, hp));
      const devices::HCheckResult r = devices::check_h_parameters(hp.params, &up);
      for (const auto& v : r.violations)
        if (v.severity == devices::Severity::Error)
          error(i, "h_parameters", "h_system \"" + hp.name + "\" (simulated): H parameters: " +
                                       std::string(devices::to_string(v.check)) + ": " + v.message);
    } catch (const std::exception& e) {
      error(i, "dp_system", "h_system \"" + hp.name + "\": cannot plan the update: " + e.what());
    }
    // The pair monitors its updates with the configured set (T_P15, T_PH: HCpuPair rules 18-20).
    rt.pair.h_parameters = hp.params;
    hp.runtime = std::move(rt);
  }

  // ---- F4 connections: the h_system's cp and connection entries (devices::HConnections checks
  // them; its message is reported at the entry's field) ----
  void plan_comms(int i, HRuntimePlan& rt) {
    const auto& h = m_plan.proto.h_system(i);
    devices::HConnections check;
    for (int k = 0; k < h.cp_size(); ++k) {
      const auto& c = h.cp(k);
      if (!c.has_rack()) {
        error_at(i, {{"cp", k}}, "cp needs a rack: rack: 0 or rack: 1");
        continue;
      }
      const devices::CpConfig cfg{static_cast<int>(std::min<std::uint32_t>(c.rack(), 2)),
                                  static_cast<int>(std::min<std::uint32_t>(c.index(), 1000)),
                                  c.kind() == scenario::HCp::CP_443_5 ? devices::CpKind::Cp443_5
                                                                      : devices::CpKind::Cp443_1};
      if (c.index() > 1000) {
        error_at(i, {{"cp", k}, {"index"}}, "cp: index " + std::to_string(c.index()) + " is above 1000");
        continue;
      }
      if (std::string e = check.add_cp(cfg); !e.empty()) {
        error_at(i, {{"cp", k}, {c.rack() > 1 ? "rack" : "index"}}, e);
        continue;
      }
      rt.cps.push_back(cfg);
    }
    for (int k = 0; k < h.connection_size(); ++k) {
      const auto& c = h.connection(k);
      devices::ConnectionConfig cfg;
      cfg.name = c.name();
      cfg.kind = c.kind() == scenario::HConnection::FAULT_TOLERANT ? devices::ConnectionKind::FaultTolerant
                                                                   : devices::ConnectionKind::Standard;
      cfg.cp = static_cast<int>(std::min<std::uint32_t>(c.cp(), 1001));
      if (cfg.kind == devices::ConnectionKind::Standard) {
        if (!c.has_rack()) {
          error_at(i, {{"connection", k}}, "connection \"" + c.name() + "\": a standard connection needs a rack");
          continue;
        }
        cfg.rack = static_cast<int>(std::min<std::uint32_t>(c.rack(), 2));
      } else if (c.has_rack()) {
        error_at(i, {{"connection", k}, {"rack"}},
                 "connection \"" + c.name() + "\": a fault-tolerant connection has no rack (it uses both CPUs)");
        continue;
      }
      if (std::string e = check.add_connection(cfg); !e.empty()) {
        const char* field = c.name().empty() || e.find("duplicate") != std::string::npos ? "name"
                            : e.find("rack must") != std::string::npos                    ? "rack"
                                                                                          : "cp";
        error_at(i, {{"connection", k}, {field}}, e);
        continue;
      }
      rt.connections.push_back(std::move(cfg));
    }
  }

  // ---- F8 expansion racks ----
  /// h_system[i].expansion_rack[k] -> racks (nothing on an error; h_plan.hpp has the rules).
  void plan_rack(int i, int k, std::vector<devices::HExpansionRack>& racks) {
    const auto& x = m_plan.proto.h_system(i).expansion_rack(k);
    const HPathStep at{"expansion_rack", k};
    devices::HExpansionRack r;
    bool good = true;
    if (!x.has_number()) {
      error_at(i, {at}, "expansion rack needs a number: number: 1..21");
      good = false;
    } else if (x.number() < 1 || x.number() > static_cast<std::uint32_t>(devices::kMaxExpansionRack)) {
      error_at(i, {at, {"number"}}, "expansion rack number " + std::to_string(x.number()) + " is not 1..21");
      good = false;
    } else {
      r.number = static_cast<int>(x.number());
      for (const auto& o : racks)
        if (o.number == r.number) {
          error_at(i, {at, {"number"}}, "expansion rack " + std::to_string(r.number) + " is defined twice");
          good = false;
        }
    }
    const std::string who = "expansion rack " + (x.has_number() ? std::to_string(x.number()) : std::string("?"));
    if (!x.has_side()) {
      error_at(i, {at}, who + " needs a side: side: 0 or side: 1 (the CPU it hangs on)");
      good = false;
    } else if (x.side() > 1) {
      error_at(i, {at, {"side"}}, who + ": side " + std::to_string(x.side()) + " is not 0 or 1");
      good = false;
    } else {
      r.side = static_cast<int>(x.side());
    }
    if (x.module_size() == 0) {
      error_at(i, {at}, who + " has no module");
      good = false;
    }
    for (int m = 0; m < x.module_size(); ++m) {
      const auto& mod = x.module(m);
      const std::vector<HPathStep> mp{at, {"module", m}};
      devices::HRackModule out;
      out.name = mod.name().empty() ? "module " + std::to_string(m) : mod.name();
      out.in_len = mod.in_len();
      out.out_len = mod.out_len();
      const std::string mw = who + " module \"" + out.name + "\"";
      if (out.in_len == 0 && out.out_len == 0) {
        error_at(i, mp, mw + ": in_len and out_len are both 0");
        good = false;
      }
      for (auto [len, field] : {std::pair{out.in_len, "in_len"}, std::pair{out.out_len, "out_len"}})
        if (len > devices::kMaxRackModuleOctets) {
          error_at(i, {at, {"module", m}, {field}},
                   mw + ": " + field + " " + std::to_string(len) + " is more than 244 octets");
          good = false;
        }
      using BC = scenario::HRackModule::BehaviourCase;
      switch (mod.behaviour_case()) {
        case BC::kConstant: {
          std::vector<std::uint8_t> v(out.in_len, 0);
          devices::put_big_endian(static_cast<std::int64_t>(mod.constant().value()), v.begin(), v.size());
          out.inputs = devices::IoBehaviour::constant_value(std::move(v));
          break;
        }
        case BC::kCounter: {
          const auto& c = mod.counter();
          bus::Ticks period = 0;
          if (!c.period().empty()) {
            auto t = ticks(i, {at, {"module", m}, {"counter"}}, c.period(), true);
            if (!t) good = false;
            period = t.value_or(0);
          }
          out.inputs = devices::IoBehaviour::counter_every(period, c.has_step() ? c.step() : 1, c.start());
          break;
        }
        case BC::kRamp: {
          const auto& rp = mod.ramp();
          auto t = rp.period().empty() ? std::nullopt
                                       : ticks(i, {at, {"module", m}, {"ramp"}}, rp.period(), true);
          if (rp.period().empty()) error_at(i, {at, {"module", m}, {"ramp"}}, mw + ": ramp needs a period");
          if (!t || rp.max() < rp.min()) {
            if (t) error_at(i, {at, {"module", m}, {"ramp"}}, mw + ": ramp max is below min");
            good = false;
          }
          out.inputs = devices::IoBehaviour::ramp(rp.min(), rp.max(), t.value_or(1));
          break;
        }
        case BC::kEcho: {
          const auto& e = mod.echo();
          std::optional<std::size_t> src;
          if (e.has_from_module_index()) {
            src = e.from_module_index();
          } else if (e.has_from_module()) {
            for (int q = 0; q < x.module_size() && !src; ++q)
              if (x.module(q).name() == e.from_module()) src = static_cast<std::size_t>(q);
            if (!src) {
              error_at(i, {at, {"module", m}, {"echo"}}, mw + ": echo from_module \"" + e.from_module() +
                                                             "\" is not a module of this rack");
              good = false;
            }
          }
          const std::size_t from = src.value_or(static_cast<std::size_t>(m));
          if (from >= static_cast<std::size_t>(x.module_size())) {
            error_at(i, {at, {"module", m}, {"echo"}},
                     mw + ": echo from_module_index " + std::to_string(from) + " is not a module of this rack");
            good = false;
          } else if (x.module(static_cast<int>(from)).out_len() == 0 && out.in_len > 0) {
            error_at(i, {at, {"module", m}, {"echo"}},
                     mw + ": echo source module " + std::to_string(from) + " has no outputs");
            good = false;
          }
          out.inputs = devices::IoBehaviour::echo(from);
          break;
        }
        case BC::BEHAVIOUR_NOT_SET: out.inputs = devices::IoBehaviour::constant_value({}); break;
      }
      r.modules.push_back(std::move(out));
    }
    if (good) racks.push_back(std::move(r));
  }

  void plan_program(int i, const scenario::HProgram& pr, devices::ProgramSpec& spec) {
    plan_program_spec(pr, spec, [&](std::vector<HPathStep> path, std::string msg) {
      path.insert(path.begin(), HPathStep{"program"});
      error_at(i, path, std::move(msg));
    });
  }

  /// A redundant_master_system is driven by at most one simulated pair; simulated pairs have
  /// distinct names (faults name them).
  void check_shared_systems() {
    std::map<int, std::size_t> owner;  // system -> h_systems index
    std::map<std::string, std::size_t> names;
    for (std::size_t k = 0; k < m_plan.h_systems.size(); ++k) {
      const auto& hp = m_plan.h_systems[k];
      if (!hp.runtime) continue;
      if (!names.emplace(hp.name, k).second)
        error(hp.source, "name", "h_system \"" + hp.name + "\" is defined twice (faults name it)");
      for (int s : hp.runtime->systems) {
        auto [it, fresh] = owner.emplace(s, k);
        if (!fresh)
          error(hp.source, "dp_system",
                "redundant_master_system \"" + m_plan.redundant_systems[static_cast<std::size_t>(s)].name +
                    "\" is already driven by h_system \"" + m_plan.h_systems[it->second].name + "\"");
      }
    }
  }

  ScenarioPlan& m_plan;
  const DpLocator& m_locate;
  const HLocator& m_hlocate;
  std::vector<Diagnostic>& m_errors;
};

}  // namespace

void plan_h(ScenarioPlan& plan, const DpLocator& locate, const HLocator& hlocate,
            std::vector<Diagnostic>& errors) {
  HPlanner(plan, locate, hlocate, errors).run();
  check_h_config_rules(plan, locate, hlocate, errors);  // what the real S7-400H refuses
}

devices::UpdatePlanInput h_update_input(const ScenarioPlan& plan, const HSystemPlan& h) {
  devices::UpdatePlanInput in;
  in.t_wa = h.t_wa;
  in.t_prog = h.t_prog;
  in.db_kb = h.db_kb;
  for (const auto& d : h.dp_systems) {
    devices::DpSystemTiming t;
    if (d.system >= 0)
      t = devices::dp_system_from_switchover_plan(d.name, plan_system_timing(plan, d.system), d.t_pto);
    t.name = d.name;
    t.t_pto = d.t_pto;
    if (d.t_tr) t.t_tr = *d.t_tr;
    if (d.t_dp_um) t.t_dp_um = *d.t_dp_um;
    if (d.t_slave_um) t.t_slave_um = *d.t_slave_um;
    in.systems.push_back(std::move(t));
  }
  return in;
}

namespace {
/// A duration of a program field; nullopt with an error if it is bad or not above 0 when
/// `positive`.
std::optional<bus::Ticks> program_ticks(const ProgramError& error_at, const std::vector<HPathStep>& path,
                                        const std::string& text, bool positive) {
  auto t = bus::parse_duration(text);
  const std::string name = path.back().field;
  if (!t) {
    error_at(path, "bad duration \"" + text + "\" for " + name + " (e.g. \"100ms\")");
    return std::nullopt;
  }
  if (positive && *t <= 0) {
    error_at(path, name + " must be longer than 0");
    return std::nullopt;
  }
  return t;
}
}  // namespace

void plan_program_spec(const scenario::HProgram& pr, devices::ProgramSpec& spec, const ProgramError& error_at) {
  if (!pr.scan_time().empty())
    if (auto t = program_ticks(error_at, {{"scan_time"}}, pr.scan_time(), true)) spec.scan_time = *t;
  for (int k = 0; k < pr.copy_size(); ++k) {
    const auto& n = pr.copy(k);
    devices::CopyNetwork c;
    c.from_input = n.from_input();
    c.to_output = n.to_output();
    c.direct = n.direct();
    if (n.has_length()) {
      if (n.length() == 0)
        error_at({{"copy", k}, {"length"}}, "copy network: length must be at least 1");
      c.length = n.length();
    }
    spec.copies.push_back(c);
  }
  for (int k = 0; k < pr.counter_size(); ++k) {
    const auto& n = pr.counter(k);
    devices::CounterNetwork c;
    c.output = n.output();
    if (n.has_width()) {
      if (n.width() != 1 && n.width() != 2 && n.width() != 4)
        error_at({{"counter", k}, {"width"}},
                 "counter network: width " + std::to_string(n.width()) + " is not 1, 2 or 4 octets");
      c.width = n.width();
    }
    if (!n.period().empty())
      if (auto t = program_ticks(error_at, {{"counter", k}, {"period"}}, n.period(), true)) c.period = *t;
    if (n.has_step()) c.step = n.step();
    c.pulse_output = n.pulse_output();
    if (n.pulse_bit() > 7)
      error_at({{"counter", k}, {"pulse_bit"}},
               "counter network: pulse_bit " + std::to_string(n.pulse_bit()) + " is not 0..7");
    c.pulse_bit = static_cast<std::uint8_t>(n.pulse_bit() & 7U);
    if (!n.pulse_high().empty())
      if (auto t = program_ticks(error_at, {{"counter", k}, {"pulse_high"}}, n.pulse_high(), false)) {
        c.pulse_high = *t;
        if (c.pulse_high >= c.period)
          error_at({{"counter", k}, {"pulse_high"}},
                   "counter network: pulse_high " + n.pulse_high() + " is not shorter than the period");
      }
    spec.counters.push_back(c);
  }
  for (int k = 0; k < pr.monitor_size(); ++k) {
    const auto& n = pr.monitor(k);
    devices::DiscrepancyNetwork d;
    d.input_a = n.input_a();
    d.input_b = n.input_b();
    if (n.has_length()) {
      if (n.length() == 0)
        error_at({{"monitor", k}, {"length"}}, "monitor network: length must be at least 1");
      d.length = n.length();
    }
    if (n.has_mask()) {
      if (n.mask() > 0xFF)
        error_at({{"monitor", k}, {"mask"}},
                 "monitor network: mask " + std::to_string(n.mask()) + " is more than one octet");
      d.mask = static_cast<std::uint8_t>(n.mask() & 0xFFU);
    }
    d.to_output = n.to_output();
    if (!n.discrepancy_time().empty())
      if (auto t = program_ticks(error_at, {{"monitor", k}, {"discrepancy_time"}}, n.discrepancy_time(), true))
        d.discrepancy_time = *t;
    spec.monitors.push_back(d);
  }
  plan_h_ctrl_calls(pr, spec, error_at);  // SFC 90 (h_plan_sfc90.cpp)
  plan_dp_sfc_calls(pr, spec, error_at);  // SFC 11/12/14/15 (h_plan_dp_sfc.cpp)
}

}  // namespace pbvbus::tools
