// A scenario's simulated h_system at run time (h_system_node.hpp).
#include "pbvbus/simulation/h_system_node.hpp"

#include <functional>
#include <stdexcept>

#include "pbvbus/captures/cpu_event.hpp"
#include "pbvbus/captures/pcapng_writer.hpp"
#include "pbvbus/s7h/h_update_timing.hpp"
#include "pbvbus/scenario/h_config_rules.hpp"
#include "pbvbus/scenario/h_plan.hpp"
#include "pbvbus/simulation/redundancy_system.hpp"

namespace pbvbus::tools {

namespace {

bool has_networks(const devices::ProgramSpec& p) {
  return !p.copies.empty() || !p.counters.empty() || !p.monitors.empty() ||
         !p.h_ctrl_calls.empty() ||  // SFC 90 calls alone are a program too (docs/h-sfc90.md)
         !p.dprd_dat.empty() || !p.dpwr_dat.empty();  // so are SFC 14/15 (docs/h-dp-sfc.md)
}

devices::HChange to_change(HProgramChangeKind k) {
  switch (k) {
    case HProgramChangeKind::StructuralFbInterface: return devices::HChange::StructuralFbInterface;
    case HProgramChangeKind::GlobalDb: return devices::HChange::GlobalDb;
    case HProgramChangeKind::Allowed: break;
  }
  return devices::HChange::Allowed;
}

}  // namespace

std::string HSystemNode::io_event_text(const devices::HSystemEvent& e) const {
  if (e.source != devices::HSystemEvent::Source::Io && e.source != devices::HSystemEvent::Source::Image)
    return e.text;
  if (e.system < 0) return e.text;  // an expansion rack's OB 85/86: the model's text names it
  std::string kind;
  switch (e.code) {
    case 0x39B1: kind = "process-image transfer error incoming"; break;
    case 0x38B1: kind = "process-image transfer error outgoing"; break;
    case 0x73A3: kind = "redundancy loss"; break;
    case 0x72A3: kind = "redundancy restored"; break;
    case 0x39C4: kind = "station failure"; break;
    case 0x38C4: kind = "station return"; break;
    case 0x39C3: kind = "master system failure"; break;
    case 0x38C3: kind = "master system return"; break;
    default: return e.text;
  }
  const HRuntimePlan& rt = *plan().runtime;
  std::string text = kind;
  if (e.system >= 0 && static_cast<std::size_t>(e.system) < rt.systems.size()) {
    const RedundancyPlan& rp =
        m_plan.redundant_systems.at(static_cast<std::size_t>(rt.systems[static_cast<std::size_t>(e.system)]));
    text += ": DP master system \"" + rp.name + "\"";
    if (e.line == 0 || e.line == 1)
      text += ", line " + m_plan.lines.at(static_cast<std::size_t>(rp.line[e.line])).name;
  }
  if (e.station != 0xFF) text += ", station " + std::to_string(e.station);
  return text;
}

HSystemNode::HSystemNode(const ScenarioPlan& plan, int index, bus::Scheduler& sched,
                         const std::vector<RedundantSystemNode*>& systems)
    : m_plan(plan), m_index(index), m_sched(sched) {
  const HSystemPlan& hp = this->plan();
  if (!hp.runtime) throw std::runtime_error("h_system \"" + hp.name + "\" has no cpu part");
  const HRuntimePlan& rt = *hp.runtime;
  std::vector<devices::RedundantMasterSystemModel*> models;
  for (int k : rt.systems) {
    RedundantSystemNode* node = systems.at(static_cast<std::size_t>(k));
    // The pair's program writes the outputs, not the system's own counter.
    node->model().set_cycle_hook({});
    models.push_back(&node->model());
  }
  try {
    m_model = std::make_unique<devices::HSystemModel>(sched, rt.pair, std::move(models), rt.racks);
    m_model->set_max_cycle_time(rt.max_cycle_time);
    // D1: diagnostic addresses from the top of the CPU type's I/O address area (001 Table 4-5).
    if (const auto& hs = plan.proto.h_system(hp.source); hs.has_cpu())
      m_model->set_diag_address_top(
          static_cast<std::uint16_t>(h_cpu_limits(hs.cpu().cpu_type()).process_image_max - 1));
    m_model->set_param_transfer_time(rt.param_transfer_time_100ms);  // W#16#6547
    setup_changes();  // docs/h-scenario-changes.md
    if (has_networks(rt.program)) m_model->set_program(rt.program);
    if (!rt.redundant_io.empty()) {  // docs/h-redundant-io.md
      std::vector<devices::HSystemModel::RedIoPair> pairs;
      for (const HRedIoPlan& x : rt.redundant_io) {
        devices::HSystemModel::RedIoPair p;
        p.spec = x.spec;
        p.a = {x.system[0], x.station[0], x.module[0]};
        p.b = {x.system[1], x.station[1], x.module[1]};
        pairs.push_back(p);
      }
      m_model->set_redundant_io(pairs);
    }
    // F4 connections: checked by the planner already; an error here is a planner bug.
    for (const devices::CpConfig& c : rt.cps)
      if (std::string e = m_model->add_cp(c); !e.empty()) throw std::invalid_argument(e);
    for (const devices::ConnectionConfig& c : rt.connections)
      if (std::string e = m_model->add_connection(c); !e.empty()) throw std::invalid_argument(e);
    // F3: the modules' parameter records, written after a plug (docs/h-reparameterisation.md):
    // every station of each master system, a switched station once (through line A's entry).
    for (std::size_t i = 0; i < rt.systems.size(); ++i) {
      const RedundancyPlan& rp = plan.redundant_systems.at(static_cast<std::size_t>(rt.systems[i]));
      for (int side = 0; side < 2; ++side)
        for (int si : plan.dp_masters.at(static_cast<std::size_t>(rp.master[side])).slaves) {
          const DpSlavePlan& d = plan.dp_slaves.at(static_cast<std::size_t>(si));
          if (d.switched >= 0 && d.side != 0) continue;
          for (const DpPrmRecordPlan& r : d.prm_records)
            if (!m_model->set_module_parameters(i, d.address, r.module, r.index, r.data))
              throw std::invalid_argument("parameter_record of station " +
                                          std::to_string(d.address) + " module " +
                                          std::to_string(r.module) + " not taken");
        }
    }
  } catch (const std::exception& e) {
    throw std::runtime_error("h_system \"" + hp.name + "\": " + e.what());
  }
  m_model->set_pair_event_handler([this](const devices::HEvent& e) { on_pair_event(e); });
  m_model->set_event_handler([this](const devices::HSystemEvent& e) { on_model_event(e); });
  try {
    const devices::UpdatePlan up = devices::plan_update(h_update_input(plan, hp));
    m_planned_t_ph = devices::to_ticks(up.t_ph);
    if (up.t_p15) m_planned_t_p15 = devices::to_ticks(*up.t_p15);
  } catch (const std::exception&) {
    // No plan (the switchover planner refused the lines): the report shows no bounds.
  }
}

HSystemNode::~HSystemNode() = default;

const HSystemPlan& HSystemNode::plan() const {
  return m_plan.h_systems.at(static_cast<std::size_t>(m_index));
}

void HSystemNode::start() {
  if (m_started) return;
  m_started = true;
  const HRuntimePlan& rt = *plan().runtime;
  start_changes();  // docs/h-scenario-changes.md
  if (!rt.fibres_connected_at_power_on) {
    m_model->cut_both_fibres();
    note("sync link: both fibres not connected at power-on");
  }
  // A power-on at the start of the run happens now (part of powering up, not a later event).
  const auto at = [this](bus::Ticks t, std::function<void()> fn) {
    if (t <= m_sched.now()) fn();
    else m_sched.schedule(t, std::move(fn));
  };
  const auto& on = rt.power_on;
  if (on[0] && on[1] && *on[0] == *on[1]) {
    at(*on[0], [this] { m_model->power_on_both(); });
    return;
  }
  for (int r = 0; r < 2; ++r)
    if (on[static_cast<std::size_t>(r)])
      at(*on[static_cast<std::size_t>(r)], [this, r] { m_model->power_on(r); });
}

std::string HSystemNode::apply(const PlanFault& f, bool on) {
  using K = PlanFault::Kind;
  devices::HSystemModel& m = *m_model;
  std::string text = on ? f.description : "repair of " + f.description;
  // The record before the reactions it causes (same instant, earlier in the capture).
  note(text);
  switch (f.kind) {
    case K::CpuFailure: on ? m.power_off(f.rack) : m.power_on(f.rack); break;
    case K::CpuStop: on ? m.switch_to_stop(f.rack) : m.switch_to_run(f.rack); break;
    case K::FibreCut: on ? m.cut_fibre(f.fibre) : m.repair_fibre(f.fibre); break;
    case K::FibresCut:
      if (on) {
        m.cut_both_fibres();
      } else {
        m.repair_fibre(0);
        m.repair_fibre(1);
      }
      break;
    case K::ComparisonError: {
      const devices::RedundantExecution* x = m.execution();
      const int standby = m.pair().master() >= 0 ? 1 - m.pair().master() : 1;
      if (x != nullptr && !x->image(standby).memory().empty()) {
        m.inject_divergence(standby, devices::Area::Memory, 0, 0x01);
        text += " (one bit of CPU " + std::to_string(standby) + "'s memory)";
      } else if (!m.inject_comparison_error()) {
        text += ": not in Redundant mode, nothing happens";
      }
      break;
    }
    case K::OneSidedOb121:
      if (!m.one_sided_ob121(f.rack)) text += ": not in Redundant mode, nothing happens";
      break;
    case K::HardwareFault: on ? m.inject_hardware_fault(f.rack) : m.repair_cpu(f.rack); break;
    case K::CpuHold:
      if (on ? !m.hold(f.rack) : !m.release_hold(f.rack)) text += ": refused";
      break;
    case K::HMasterSwap:
      equal_db_blocks();  // nothing changed (docs/h-scenario-changes.md)
      if (!m.request_master_swap()) text += ": refused";
      break;
    case K::HSwitchToCpu: text += apply_switch(f); break;  // docs/h-scenario-changes.md
    case K::UpdateLoad: m.set_changed_db_kb(static_cast<std::uint32_t>(f.kb)); break;
    case K::ProgramChange:
      text += std::string(": ") + std::string(devices::to_string(m.load_change(to_change(f.change))));
      break;
    case K::ParameterChange:
      m.set_standby_parameter_change(true);
      if (!m.request_master_swap()) text += ": swap refused";
      break;
    case K::MemoryReset:
      if (!m.memory_reset(f.rack)) text += ": refused";
      break;
    case K::LoadMemoryError:
      if (!m.load_memory_error(f.rack)) text += ": refused (CPU off or DEFECTIVE)";
      break;
    case K::SyncError:
      if (!m.inject_sync_error()) text += ": not in Redundant mode, nothing happens";
      break;
    case K::CpFailure:  // F4; the repair re-establishes the standard connections over the CP
      if (on ? !m.cp_failure(f.rack, f.cp) : !m.repair_cp(f.rack, f.cp)) text += ": nothing to do";
      break;
    case K::ExpansionRackFailure:
      if (on ? !m.expansion_rack_off(f.rack_number) : !m.expansion_rack_on(f.rack_number))
        text += on ? ": off already, nothing happens" : ": on already, nothing happens";
      break;
    case K::CycleOverload: m.cycle_overload(f.extra); break;
    case K::RedDepa:  // FC 451 (docs/h-redundant-io.md)
      if (!m.red_depa()) text += ": nothing passivated, refused";
      break;
    case K::ChecksumError:  // docs/h-changes.md (001 Table 5-6)
      if (!m.checksum_error(f.rack)) text += ": refused (CPU off or DEFECTIVE)";
      break;
    case K::PsFailure:  // F1 with a PS 407 10A R pair (docs/h-changes.md)
      if (on) {
        text += m.ps_failure(f.rack, f.half) ? ": no half left, the CPU fails" : ": the other half supplies the rack";
      } else if (!m.ps_repair(f.rack, f.half)) {
        text += ": nothing to do";
      }
      break;
    default: break;
  }
  m_faults.back().second = text;  // with what the pair answered ("refused", ...)
  return text;
}

void HSystemNode::note(std::string text) {
  m_faults.emplace_back(m_sched.now(), text);
  if (m_capture == nullptr) return;
  captures::EventRecord r;
  r.category = captures::EventCategory::Note;
  r.text = plan().name + ": " + text;
  m_capture->write_event(m_sched.now(), r);
}

void HSystemNode::on_model_event(const devices::HSystemEvent& e) {
  // OB 72/121 come with the pair's events, OB 70/86 with the redundancy records: the rest
  // (OB 85, the alarms' OB 40/82/83..., the program's 7960) as Cpu records of kind Ob.
  if (m_capture == nullptr || e.source == devices::HSystemEvent::Source::Cpu ||
      (e.source == devices::HSystemEvent::Source::Io && e.system >= 0))  // racks' OB 86: here
    return;
  captures::CpuEventFields f;
  f.kind = captures::CpuEventKind::Ob;
  f.rack = e.rack;  // -1: both CPUs
  f.role = static_cast<int>(e.role);
  f.event_id = e.code;
  f.ob = static_cast<std::uint8_t>(e.ob);
  f.text = plan().name + ": " + (e.rack < 0 ? std::string("CPU 0+1") : "CPU " + std::to_string(e.rack)) +
           ": " + io_event_text(e);
  m_capture->write_event(e.time, captures::cpu_event_record(f));
}

void HSystemNode::on_pair_event(const devices::HEvent& e) {
  if (m_capture == nullptr) return;
  m_capture->write_event(e.at, h_event_record(e, m_model->pair().params().profile, plan().name));
}

HSystemReport HSystemNode::report() const {
  HSystemReport r = make_h_report(plan().name, m_model->pair());
  for (int rack = 0; rack < 2; ++rack) {
    HCpuReport& c = r.cpus[static_cast<std::size_t>(rack)];
    for (devices::BusLed l : m_model->leds(rack).busf) c.busf.emplace_back(devices::to_string(l));
    // The buffer as the CPU has it: its own entries and the I/O events it logged.
    c.diag = m_model->diag_buffer(rack);
  }
  r.planned_t_p15 = m_planned_t_p15;
  r.planned_t_ph = m_planned_t_ph;
  r.faults = m_faults;
  for (const devices::HSystemEvent& e : m_model->events()) {
    if (e.source == devices::HSystemEvent::Source::Cpu) continue;  // in the timeline already
    HIoEvent x;
    x.at = e.time;
    if (e.rack < 0) x.racks = {0, 1};
    else x.racks = {e.rack};
    x.ob = e.ob;
    x.code = e.code;
    x.text = io_event_text(e);
    if (e.ob == 82 || e.ob == 83 || e.ob == 122 ||
        (e.ob == 86 && e.source == devices::HSystemEvent::Source::Io && e.system >= 0)) {  // D1
      x.mdl_addr = e.mdl_addr;
      x.mdl_stop = e.mdl_stop;
    }
    r.io_events.push_back(std::move(x));
  }
  // The phases of each update as the model measured them (t1 matches the pair's).
  for (const devices::UpdateMeasure& u : m_model->update_measures())
    for (HUpdateWindow& w : r.updates)
      if (w.t1 == u.t1 && u.done) {
        w.t3 = u.t3;
        if (u.standby_operate_from != bus::kNever) w.t4 = u.standby_operate_from;
        if (u.last_scan_before != bus::kNever) w.last_io_before = u.last_scan_before;
        if (u.first_scan_after != bus::kNever) w.first_io_after = u.first_scan_after;
        w.scan_time = plan().runtime->program.scan_time;
      }
  // F4 connections: state, active path and their events.
  const devices::HConnections& comms = m_model->comms();
  for (std::size_t i = 0; i < comms.connections().size(); ++i) {
    const devices::Connection& c = comms.connections()[i];
    HConnectionRow row;
    row.name = c.config.name;
    row.kind = std::string(devices::to_string(c.config.kind));
    row.state = std::string(devices::to_string(c.state));
    if (c.active >= 0) {
      const devices::ConnectionPath& p = c.paths[static_cast<std::size_t>(c.active)];
      for (const devices::CpConfig& cp : comms.cps())
        if (cp.rack == p.rack && cp.index == p.cp) row.active = std::string(devices::to_string(cp.kind)) + " ";
      row.active += "rack " + std::to_string(p.rack) + " CP " + std::to_string(p.cp);
    }
    for (const devices::CommEvent& e : comms.events())
      if (e.connection == static_cast<int>(i)) row.events.emplace_back(e.at, e.text);
    r.connections.push_back(std::move(row));
  }
  for (const devices::HIoEntry& e : m_model->io_map().entries()) {
    HIoMapRow row;
    row.address = e.address;
    row.module = e.module;
    row.in_addr = e.in_addr;
    row.in_len = e.in_len;
    row.out_addr = e.out_addr;
    row.out_len = e.out_len;
    if (e.central) row.rack = e.rack;
    r.io_map.push_back(row);
  }
  for (const devices::HExpansionRack& x : m_model->expansion_racks()) {
    HRackReport rr;
    rr.number = x.number;
    rr.side = x.side;
    rr.on = m_model->expansion_rack_is_on(x.number);
    rr.reachable = m_model->expansion_rack_reachable(x.number);
    rr.ob85 = m_model->expansion_rack_ob85(x.number);
    for (std::size_t m = 0; m < x.modules.size(); ++m) {
      const auto out = m_model->rack_outputs(x.number, m);
      rr.modules.push_back({x.modules[m].name, {out.begin(), out.end()}});
    }
    r.racks.push_back(std::move(rr));
  }
  r.ob80 = m_model->ob80_count();
  report_changes(r);  // docs/h-scenario-changes.md
  return r;
}

}  // namespace pbvbus::tools
