// A scenario h_system's redundant_io entries (h_plan.hpp plan_redundant_io;
// docs/h-redundant-io.md "In a scenario").
#include <algorithm>

#include "pbvbus/scenario/h_plan.hpp"
#include "pbvbus/scenario/scenario.hpp"

namespace pbvbus::tools {

namespace {

/// The module named by `m` as (model system index, station, module index); false after an
/// error at `at` + the field.
bool resolve(const ScenarioPlan& plan, const HRuntimePlan& rt, const scenario::HRedIoModule& m,
             const std::vector<HPathStep>& at, const ProgramError& error, HRedIoPlan& out,
             int k) {
  auto path = [&](const char* field) {
    auto p = at;
    p.push_back({field});
    return p;
  };
  int sys = -1;
  for (std::size_t s = 0; s < rt.systems.size(); ++s)
    if (plan.redundant_systems[static_cast<std::size_t>(rt.systems[s])].name == m.system())
      sys = static_cast<int>(s);
  if (sys < 0) {
    error(path("system"), "redundant_io: \"" + m.system() +
                              "\" is not a redundant_master_system this h_system drives "
                              "(a dp_system of it)");
    return false;
  }
  if (!m.has_address()) {
    error(at, "redundant_io: a module needs the address of its station");
    return false;
  }
  const RedundancyPlan& rp =
      plan.redundant_systems[static_cast<std::size_t>(rt.systems[static_cast<std::size_t>(sys)])];
  const DpSlavePlan* station = nullptr;
  for (int sw : rp.switched) {
    const SwitchedPlan& x = plan.switched[static_cast<std::size_t>(sw)];
    if (x.address == m.address() && x.slave[0] >= 0)
      station = &plan.dp_slaves[static_cast<std::size_t>(x.slave[0])];
  }
  for (const DpSlavePlan& d : plan.dp_slaves) {
    if (station != nullptr || d.switched >= 0 || d.address != m.address()) continue;
    for (int side = 0; side < 2; ++side) {
      const int mi = rp.master[side];
      if (mi >= 0 && d.line == rp.line[side] &&
          d.master == plan.dp_masters[static_cast<std::size_t>(mi)].params.address)
        station = &d;
    }
  }
  if (station == nullptr) {
    error(path("address"), "redundant_io: redundant_master_system \"" + m.system() +
                               "\" has no station " + std::to_string(m.address()));
    return false;
  }
  std::size_t module = 0;
  if (m.has_module_index()) {
    module = m.module_index();
    if (module >= station->module_names.size()) {
      error(path("module_index"), "redundant_io: module_index " + std::to_string(module) +
                                      " is not below the " +
                                      std::to_string(station->module_names.size()) +
                                      " modules of station " + std::to_string(m.address()));
      return false;
    }
  } else if (m.has_module()) {
    const auto it =
        std::find(station->module_names.begin(), station->module_names.end(), m.module());
    if (it == station->module_names.end()) {
      error(path("module"), "redundant_io: module \"" + m.module() +
                                "\" is not one of the modules of station " +
                                std::to_string(m.address()));
      return false;
    }
    module = static_cast<std::size_t>(it - station->module_names.begin());
  } else {
    error(at, "redundant_io: a module needs module: \"name\" or module_index: n");
    return false;
  }
  out.system[k] = sys;
  out.station[k] = static_cast<std::uint8_t>(m.address());
  out.module[k] = module;
  return true;
}

}  // namespace

void plan_redundant_io(const ScenarioPlan& plan, int i, HRuntimePlan& rt,
                       const ProgramError& error) {
  const auto& h = plan.proto.h_system(i);
  for (int k = 0; k < h.redundant_io_size(); ++k) {
    const auto& x = h.redundant_io(k);
    const HPathStep at{"redundant_io", k};
    HRedIoPlan p;
    using PK = scenario::HRedundantIo;
    switch (x.kind()) {
      case PK::AI: p.spec.kind = devices::RedIoKind::AI; break;
      case PK::DO: p.spec.kind = devices::RedIoKind::DO; break;
      case PK::AO: p.spec.kind = devices::RedIoKind::AO; break;
      default: p.spec.kind = devices::RedIoKind::DI; break;
    }
    bool good = true;
    if (!x.has_module_a() || !x.has_module_b()) {
      error({at}, "redundant_io needs two modules: module_a and module_b");
      continue;
    }
    good &= resolve(plan, rt, x.module_a(), {at, {"module_a"}}, error, p, 0);
    good &= resolve(plan, rt, x.module_b(), {at, {"module_b"}}, error, p, 1);
    if (good && p.system[0] == p.system[1] && p.station[0] == p.station[1] &&
        p.module[0] == p.module[1]) {
      error({at, {"module_b"}}, "redundant_io: module_a and module_b are the same module");
      good = false;
    }
    const bool input = p.spec.kind == devices::RedIoKind::DI || p.spec.kind == devices::RedIoKind::AI;
    if (input) {
      if (x.discrepancy_time().empty()) {
        error({at}, "redundant_io: an input pair needs a discrepancy_time, e.g. \"100ms\"");
        good = false;
      } else if (auto t = bus::parse_duration(x.discrepancy_time())) {
        p.spec.discrepancy_time = *t;
      } else {
        error({at, {"discrepancy_time"}},
              "bad duration \"" + x.discrepancy_time() + "\" for discrepancy_time (e.g. \"100ms\")");
        good = false;
      }
    }
    p.spec.di_reaction =
        x.di_reaction() == PK::VALUE_1 ? devices::DiReaction::Value1 : devices::DiReaction::LastValidValue;
    p.spec.accepted = x.accepted() == PK::MIN ? devices::AiAcceptedValue::Min : devices::AiAcceptedValue::Max;
    if (x.tolerance_permille() > 1000) {
      error({at, {"tolerance_permille"}}, "redundant_io: tolerance_permille " +
                                              std::to_string(x.tolerance_permille()) +
                                              " is above 1000 (100 %)");
      good = false;
    }
    p.spec.tolerance_permille = x.tolerance_permille();
    if (x.has_end_value()) {
      if (x.end_value() <= 0) {
        error({at, {"end_value"}}, "redundant_io: end_value must be above 0");
        good = false;
      }
      p.spec.end_value = x.end_value();
    }
    if (good) rt.redundant_io.push_back(p);
  }
}

}  // namespace pbvbus::tools
