// A scenario's redundant_master_system at run time (redundancy_system.hpp).
#include "pbvbus/simulation/redundancy_system.hpp"

#include <algorithm>
#include <cstdio>
#include <stdexcept>

#include "pbvbus/captures/event_record.hpp"
#include "pbvbus/captures/pcapng_writer.hpp"
#include "pbvbus/simulation/dp_link_node.hpp"
#include "pbvbus/simulation/dp_system.hpp"
#include "pbvbus/scenario/timing_plan.hpp"

namespace pbvbus::tools {

namespace {

std::string code_text(std::uint16_t code) {
  char b[16];
  std::snprintf(b, sizeof b, "W#16#%04X", code);
  return b;
}

}  // namespace

RedundantSystemNode::RedundantSystemNode(const ScenarioPlan& plan, int system,
                                         const fdl::BusParams params[2],
                                         std::optional<std::uint64_t> seed)
    : m_plan(plan), m_system(system) {
  const RedundancyPlan& rp = this->plan();
  devices::RedundantMasterSystemOptions o;
  std::vector<dp::SlaveParams> slaves[2];
  for (int side = 0; side < 2; ++side) {
    const DpMasterPlan& mp = plan.dp_masters.at(static_cast<std::size_t>(rp.master[side]));
    o.master[side] = mp.params;
    for (int k : mp.slaves) {
      const DpSlavePlan& sp = plan.dp_slaves.at(static_cast<std::size_t>(k));
      slaves[side].push_back(sp.params);
    }
  }
  m_program = plan.dp_masters.at(static_cast<std::size_t>(rp.master[0])).outputs;
  m_program_off = plan.dp_masters.at(static_cast<std::size_t>(rp.master[0])).gateway_outputs;
  o.bus_params = params[0];
  o.bus_params_b = params[1];
  o.system.preferred = rp.preferred;
  o.system.output_hold_time = rp.output_hold_10ms;
  std::vector<redundancy::SwitchedStationRef> refs;
  for (int k : rp.switched) {
    const SwitchedPlan& swp = plan.switched.at(static_cast<std::size_t>(k));
    refs.push_back({swp.address, swp.t_slave_um.value_or(0), false});
  }
  try {
    m_model = std::make_unique<devices::RedundantMasterSystemModel>(o, slaves[0], slaves[1], refs);
    m_timing = redundancy::plan_switchover(params[0], planned_slaves_of_system(plan, system));
  } catch (const std::exception& e) {
    throw std::runtime_error("redundant master system \"" + rp.name + "\": " + e.what());
  }
  m_model->system().add_event_listener(
      [this](const redundancy::SystemEvent& e) { on_system_event(e); });
  // The program: once for the system, at every token receipt of either master.
  m_model->set_cycle_hook([this](devices::RedundantMasterSystemModel& m, int, bus::Ticks) {
    ++m_cycles;
    if (m_program_off) return;  // a gateway's clients own the outputs
    const auto value =
        static_cast<std::uint8_t>(m_program == scenario::DpMaster::COUNT ? (m_cycles & 0xFF) : 0);
    redundancy::MasterSystem& ms = m.system();
    for (std::uint8_t a : ms.addresses()) {
      const int side = ms.is_switched(a) || m.master(0).has_slave(a) ? 0 : 1;
      const dp::MasterImage& img = m.master(side).image(a);
      for (std::size_t mod = 0; mod < img.modules(); ++mod) {
        const std::size_t n = img.module(mod).out_len;
        if (n == 0) continue;
        m_buf.assign(n, value);
        ms.write_outputs(a, mod, m_buf);
      }
    }
  });
  // The switched stations.
  for (int k : rp.switched) {
    const SwitchedPlan& swp = plan.switched.at(static_cast<std::size_t>(k));
    if (swp.link >= 0) {  // an IM 157 link (dp_link_node.hpp)
      m_links.emplace_back(k, build_dp_link(plan, k, params[0]));
      m_models.emplace_back(k, &m_links.back().second->upper());
      continue;
    }
    const DpSlavePlan& sp = plan.dp_slaves.at(static_cast<std::size_t>(swp.slave[0]));
    devices::SwitchedStationOptions so;
    so.address = swp.address;
    so.bus_params = params[0];
    if (sp.tsdr != 0) so.tsdr = sp.tsdr;
    // S5: the IM takes its own switchover time, drawn within T_SLAVE_UM (GSD or scenario);
    // the draws are reproducible from the run's seed and the station address
    // (docs/switchover-timing.md "The IM's own time").
    so.redundancy.im_switchover_bound = swp.t_slave_um.value_or(0);
    so.redundancy.im_seed = seed.value_or(plan.seed) * 0x100000001B3ull + swp.address;
    std::vector<devices::ModuleChoice> mods;
    for (std::size_t i : sp.gsd_modules) mods.push_back(devices::ModuleChoice::at(i));
    auto b = devices::SwitchedStationModel::build(*sp.gsd, mods, so);
    if (!b.ok())
      throw std::runtime_error("switched station " + std::to_string(swp.address) + ": " +
                               (b.errors.empty() ? std::string("cannot be built") : b.errors.front()));
    devices::SwitchedStationModel& model = *b.model;
    apply_io_plan(
        sp, model.redundant_slave().engine(0).application(),
        [&](std::size_t m, devices::IoBehaviour beh) { return model.set_behaviour(m, std::move(beh)); },
        [&](std::size_t m, std::size_t off, std::size_t w, devices::IoBehaviour beh) {
          return model.add_channel_behaviour(m, off, w, std::move(beh));
        });
    m_models.emplace_back(k, b.model.get());
    m_stations.emplace_back(k, std::move(b.model));
  }
}

RedundantSystemNode::~RedundantSystemNode() = default;

const RedundancyPlan& RedundantSystemNode::plan() const {
  return m_plan.redundant_systems.at(static_cast<std::size_t>(m_system));
}

int RedundantSystemNode::side_of_master(int dp_master) const {
  for (int side = 0; side < 2; ++side)
    if (plan().master[side] == dp_master) return side;
  return -1;
}

int RedundantSystemNode::line(int side) const { return plan().line[side]; }

const std::string& RedundantSystemNode::line_name(int side) const {
  static const std::string none;
  if (side != 0 && side != 1) return none;
  return m_plan.lines.at(static_cast<std::size_t>(line(side))).name;
}

devices::SwitchedStationModel* RedundantSystemNode::station(int k) {
  for (auto& [idx, m] : m_models)
    if (idx == k) return m;
  return nullptr;
}
const devices::SwitchedStationModel* RedundantSystemNode::station(int k) const {
  for (const auto& [idx, m] : m_models)
    if (idx == k) return m;
  return nullptr;
}
devices::DpLink* RedundantSystemNode::link(int k) {
  for (auto& [idx, l] : m_links)
    if (idx == k) return l.get();
  return nullptr;
}

void RedundantSystemNode::note_fault(bus::Ticks now, const PlanFault& f, bool on) {
  m_faults.push_back({now, on ? f.description : "repair of " + f.description, f.kind, on});
}

std::string RedundantSystemNode::apply(const PlanFault& f, bool on) {
  using K = PlanFault::Kind;
  std::string text = on ? f.description : "repair of " + f.description;
  switch (f.kind) {
    case K::InterfaceFailure:
      if (auto* m = station(f.switched)) on ? m->fail_interface(f.side) : m->repair_interface(f.side);
      break;
    case K::StationPowerLoss:
      if (auto* m = station(f.switched)) on ? m->power_off_station() : m->power_on_station();
      break;
    case K::MasterFailure: on ? m_model->fail_master(f.side) : m_model->repair_master(f.side); break;
    case K::MasterStop: on ? m_model->stop_master(f.side) : m_model->start_master(f.side); break;
    default: break;
  }
  return text;
}

void RedundantSystemNode::on_system_event(const redundancy::SystemEvent& e) {
  bus::Ticks now = e.time;
  // A line lost because its CPU failed or stopped (an H-system drives the system): that is
  // the switchovers' fault, at this instant, unless a scenario fault was noted at it (a CPU
  // fault's reaction may come much later: a master swap ends an update seconds after it was
  // requested).
  if (e.kind == redundancy::SystemEvent::Kind::MasterSystemFailure &&
      (m_faults.empty() || m_faults.back().at < now)) {
    const auto loss = m_model->system().line_loss(e.line);
    if (loss == redundancy::LineLoss::CpuFailure || loss == redundancy::LineLoss::MasterStop) {
      const bool failed = loss == redundancy::LineLoss::CpuFailure;
      m_faults.push_back({now,
                          "line " + line_name(e.line) + "'s DP master " +
                              (failed ? "loses power with its CPU" : "stops with its CPU"),
                          failed ? PlanFault::Kind::MasterFailure : PlanFault::Kind::MasterStop,
                          true});
    }
  }
  if (e.kind == redundancy::SystemEvent::Kind::Switchover &&
      e.cause != redundancy::SystemEvent::Cause::StartUp) {
    Switch s;
    s.event = e;
    // The latest fault or repair at or before the command.
    for (auto it = m_faults.rbegin(); it != m_faults.rend(); ++it)
      if (it->at <= e.time) {
        s.fault = *it;
        s.has_fault = true;
        break;
      }
    m_switches.push_back(std::move(s));
  }
  if (m_capture == nullptr) return;
  captures::EventRecord r;
  r.category = captures::EventCategory::Redundancy;
  r.code = static_cast<std::uint16_t>(e.kind);
  // The Simulation numbers its lines (Line::index()) by their plan index.
  r.line = e.line >= 0 ? line(e.line) : -1;
  r.a = e.station == 0xFF ? -1 : e.station;
  r.b = r.line;
  r.value = e.code();
  std::string who = e.station == 0xFF ? "DP master system \"" + plan().name + "\""
                                      : "switched station " + std::to_string(e.station);
  if (!e.s7()) {
    r.text = "switchover of " + who + " to line " + line_name(e.line) + " (" +
             std::string(to_string(e.cause)) + ")";
  } else {
    r.text = "OB " + std::to_string(e.ob()) + " " + code_text(e.code()) + " " +
             std::string(to_string(e.kind)) + ": " + who + ", line " + line_name(e.line);
  }
  m_capture->write_event(now, r);
}

RedundancyReport RedundantSystemNode::report() const {
  const RedundancyPlan& rp = plan();
  const redundancy::MasterSystem& ms = m_model->system();
  RedundancyReport r;
  r.name = rp.name;
  for (int side = 0; side < 2; ++side) {
    r.line[side] = line_name(side);
    r.master[side] = m_model->master(side).address();
    r.t_tr[side] = m_timing.line[side].t_tr;
    r.recognition[side] = m_timing.line[side].recognition;
    r.system_bound[side] = m_timing.system_bound[side];
  }
  for (const auto& [k, m] : m_models) {
    const SwitchedPlan& swp = m_plan.switched.at(static_cast<std::size_t>(k));
    const DpSlavePlan& sp = m_plan.dp_slaves.at(static_cast<std::size_t>(swp.slave[0]));
    SwitchedStationReport s;
    s.address = swp.address;
    s.model = sp.model;
    s.modules = sp.module_names;
    s.active = line_name(ms.active(swp.address));
    for (int side = 0; side < 2; ++side) s.roles[side] = std::string(redundancy::to_string(m->role(side)));
    s.redundancy_lost = ms.redundancy_lost(swp.address);
    s.failed = ms.station_failed(swp.address);
    s.outputs.assign(m->outputs().begin(), m->outputs().end());
    s.outputs_held = m->outputs_held();
    s.t_slave_um = swp.t_slave_um;
    for (const auto& b : m_timing.stations)
      if (b.address == swp.address) {
        s.bound[0] = b.bound[0];
        s.bound[1] = b.bound[1];
      }
    r.stations.push_back(std::move(s));
  }
  for (const auto& e : ms.events()) {
    RedEventReport x;
    x.time = e.time;
    x.ob = e.ob();
    x.code = e.code();
    x.kind = std::string(to_string(e.kind));
    x.line = line_name(e.line);
    x.station = e.station == 0xFF ? -1 : e.station;
    x.cause = std::string(to_string(e.cause));
    x.from = line_name(e.from);
    r.events.push_back(std::move(x));
  }
  for (const Switch& sw : m_switches) {
    const auto& e = sw.event;
    SwitchoverReport x;
    x.station = e.station;
    x.from = line_name(e.from);
    x.to = line_name(e.line);
    x.cause = std::string(to_string(e.cause));
    x.system_level = e.cause == redundancy::SystemEvent::Cause::LineLost;
    x.commanded = e.time;
    x.fault_at = sw.has_fault ? sw.fault.at : e.time;
    x.fault = sw.has_fault ? sw.fault.text : "";
    // The failing channel's line is the other one.
    const int failed_line = 1 - e.line;
    if (x.system_level) {
      const bool master = sw.has_fault && (sw.fault.kind == PlanFault::Kind::MasterFailure ||
                                           sw.fault.kind == PlanFault::Kind::MasterStop);
      x.bound = master ? m_timing.system_bound_master_stop[failed_line]
                       : m_timing.system_bound[failed_line];
    } else {
      for (const auto& b : m_timing.stations)
        if (b.address == e.station) x.bound = b.bound[failed_line];
    }
    for (const auto& [k, m] : m_models) {
      if (m->address() != e.station) continue;
      for (const auto& re : m->events())
        if (re.kind == redundancy::RedEvent::Kind::FreshOutputs && re.iface == e.line &&
            re.at >= e.time) {
          x.fresh = re.at;
          break;
        }
      // The IM's time: the first draw for the new interface triggered at or after the command
      // (a PrmCmd reaches the IM after the command; an autonomous switch may come before the
      // fresh outputs) and not after them.
      for (const auto& im : m->redundant_slave().im_switchovers())
        if (im.iface == e.line && im.trigger >= x.fault_at && (!x.fresh || im.trigger <= *x.fresh)) {
          x.im_time = im.drawn;
          break;
        }
    }
    if (x.fresh) {
      x.measured = *x.fresh - x.fault_at;
      x.exceeded = *x.measured > x.bound;
      if (x.exceeded) ++r.exceeded;
    }
    r.switchovers.push_back(std::move(x));
  }
  return r;
}

}  // namespace pbvbus::tools
