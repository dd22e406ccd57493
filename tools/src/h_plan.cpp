// A scenario's h_system entries (h_plan.hpp).
#include "pbvbus/tools/h_plan.hpp"

#include "pbvbus/tools/scenario.hpp"
#include "pbvbus/tools/timing_plan.hpp"

namespace pbvbus::tools {

namespace {

class HPlanner {
 public:
  HPlanner(ScenarioPlan& plan, const DpLocator& locate, std::vector<Diagnostic>& errors)
      : m_plan(plan), m_locate(locate), m_errors(errors) {}

  void run() {
    for (int i = 0; i < m_plan.proto.h_system_size(); ++i) plan_one(i);
  }

 private:
  void error(int i, const char* field, std::string msg) {
    auto [l, c] = m_locate("h_system", i, field, -1);
    m_errors.push_back({m_plan.file, l, c, std::move(msg)});
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
    m_plan.h_systems.push_back(std::move(hp));
  }

  ScenarioPlan& m_plan;
  const DpLocator& m_locate;
  std::vector<Diagnostic>& m_errors;
};

}  // namespace

void plan_h(ScenarioPlan& plan, const DpLocator& locate, std::vector<Diagnostic>& errors) {
  HPlanner(plan, locate, errors).run();
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

}  // namespace pbvbus::tools
