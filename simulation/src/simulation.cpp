#include "pbvbus/simulation/simulation.hpp"

#include "pbvbus/bus/pty.hpp"

#include <algorithm>
#include <array>
#include <stdexcept>

#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>

#include "pbvbus/bus/paced_runner.hpp"
#include "pbvbus/bus/pty_station.hpp"
#include "pbvbus/captures/pcapng_writer.hpp"
#include "pbvbus/fdl_traffic/fdl_poller.hpp"
#include "pbvbus/fdl_traffic/fdl_responder.hpp"
#include "pbvbus/fdl/active_station.hpp"
#include "pbvbus/fdl/passive_station.hpp"

namespace pbvbus::tools {

using bus::Ticks;

namespace {

std::uint64_t splitmix64(std::uint64_t x) {
  x += 0x9E3779B97F4A7C15ULL;
  x = (x ^ (x >> 30)) * 0xBF58476D1CE4E5B9ULL;
  x = (x ^ (x >> 27)) * 0x94D049BB133111EBULL;
  return x ^ (x >> 31);
}

fdl::RequestFn request_fn(scenario::Service s, scenario::Priority p) {
  const bool high = p == scenario::HIGH;
  switch (s) {
    case scenario::SDA: return high ? fdl::RequestFn::SdaHigh : fdl::RequestFn::SdaLow;
    case scenario::SDN: return high ? fdl::RequestFn::SdnHigh : fdl::RequestFn::SdnLow;
    default: return high ? fdl::RequestFn::SrdHigh : fdl::RequestFn::SrdLow;
  }
}

}  // namespace

struct Simulation::Station {
  StationKind kind = StationKind::Passive;
  std::uint8_t address = 0;
  std::unique_ptr<devices::FdlPoller> poller;
  std::unique_ptr<devices::FdlResponder> responder;
  std::unique_ptr<fdl::PassiveStation> passive;
  std::unique_ptr<fdl::ActiveStation> active;
  bus::AttachmentId position = -1;
  std::unique_ptr<bus::PtyStation> pty;
  std::unique_ptr<DpMasterNode> dp_master;
  std::unique_ptr<DpSlaveNode> dp_slave;
  const DpSlavePlan* dp_slave_plan = nullptr;
  // A side of a redundant master system (kind DpMaster) or a switched station's interface.
  RedundantSystemNode* red = nullptr;
  int red_side = -1;
  int switched = -1;  ///< index into ScenarioPlan::switched
  int quantum = -1;   ///< a Quantum pair's DP master modules: index into m_quantum
};

namespace {
/// Holds an omitted master's cable position (SimulationOptions::omit_masters): hears, says nothing.
class InertDevice final : public bus::Device {
 public:
  void on_power_on(bus::Ticks) override {}
  void on_frame(const bus::RxFrame&) override {}
  void on_timer(bus::Ticks) override {}
  const char* kind() const override { return "omitted master"; }
};
}  // namespace

struct Simulation::LineState {
  std::unique_ptr<bus::Line> line;
  std::vector<std::unique_ptr<bus::Device>> inert;  ///< omitted masters' places
  LineStats stats;
  std::string stats_probe;  ///< where the statistics tap listens ("station 1"), "" = whole line
  std::vector<Station> stations;  // cable order
};

Simulation::Simulation(const ScenarioPlan& plan, const SimulationOptions& opts)
    : m_plan(plan), m_opts(opts) {
  m_duration = opts.duration ? opts.duration : plan.duration;
  m_seed = opts.seed ? *opts.seed : plan.seed;
  for (std::size_t k = 0; k < m_plan.redundant_systems.size(); ++k) {
    const RedundancyPlan& rp = m_plan.redundant_systems[k];
    const fdl::BusParams params[2] = {m_plan.lines.at(static_cast<std::size_t>(rp.line[0])).params,
                                      m_plan.lines.at(static_cast<std::size_t>(rp.line[1])).params};
    m_redundant.push_back(
        std::make_unique<RedundantSystemNode>(m_plan, static_cast<int>(k), params, m_seed));
  }
  for (const auto& c : m_plan.s7.cpus)
    m_s7_cpus.push_back(std::make_unique<S7CpuNode>(
        m_sched, c, c.mpi_line >= 0 ? &m_plan.lines.at(static_cast<std::size_t>(c.mpi_line)).params : nullptr));
  for (const auto& m : m_plan.s7.stations)
    m_mpi_clients.push_back(std::make_unique<MpiClientNode>(
        m_sched, m, m_plan.lines.at(static_cast<std::size_t>(m.line)).params));
  for (const auto& hm : m_plan.s7.h_mpi)
    for (int rack = 0; rack < 2; ++rack) {
      const int hi = hm.h_system;
      m_h_mpi.push_back(std::make_unique<HCpuMpiNode>(
          hm, rack, m_plan.lines.at(static_cast<std::size_t>(hm.line)).params,
          [this, hi] { return h_model(hi); }));
    }
  std::vector<S7CpuNode*> cpus;
  for (auto& c : m_s7_cpus) cpus.push_back(c.get());
  for (const auto& d : m_plan.s7.doors)
    m_s7_doors.push_back(std::make_unique<S7DoorNode>(
        m_sched, d, cpus,
        d.mpi_line >= 0 ? &m_plan.lines.at(static_cast<std::size_t>(d.mpi_line)).params : nullptr,
        [this](int h) { return h_model(h); }));
  for (std::size_t k = 0; k < m_plan.quantum.size(); ++k) {
    m_quantum.push_back(std::make_unique<QuantumNode>(m_plan, static_cast<int>(k), m_sched));
    m_quantum.back()->set_capture(m_opts.capture);
  }
  for (std::size_t li = 0; li < m_plan.lines.size(); ++li) build_line(li);
  for (auto& node : m_redundant) node->set_capture(m_opts.capture);
  std::string why;
  auto probes = plan_capture_probes(m_plan, m_opts.probe, &why);
  if (!probes && m_opts.capture != nullptr) throw std::runtime_error(why);
  if (!probes) probes = plan_capture_probes(m_plan, ProbeDefault{});  // --probe needs --capture
  // The line's statistics are what an analyzer sees at the line's first probe, like the
  // capture: during a cable cut the far side's traffic does not interleave with the near
  // side's into phantom collisions, short idle times and unanswered requests. A line without
  // stations has no probe; its tap hears the whole line (there is nothing to hear).
  for (std::size_t li = 0; li < m_lines.size(); ++li) {
    LineState& ls = *m_lines[li];
    const auto first = probes ? std::find_if(probes->begin(), probes->end(),
                                             [&](const CaptureProbe& p) { return p.line == li; })
                              : std::vector<CaptureProbe>::const_iterator{};
    if (probes && first != probes->end()) {
      ls.line->add_tap(ls.stats, bus::ProbePoint{first->position});
      ls.stats_probe = first->where;
    } else {
      ls.line->add_tap(ls.stats);
    }
  }
  if (m_opts.capture != nullptr) {
    for (std::size_t li = 0; li < m_lines.size(); ++li) {
      // An MPI line's interfaces say so, for the dissector and the timeline (captures/README.md).
      if (m_plan.lines[li].mpi) m_opts.capture->mark_mpi(*m_lines[li]->line);
      attach_capture(*m_opts.capture, *m_lines[li]->line, li, *probes);
    }
    for (auto& d : m_s7_doors) attach_s7_capture(*d);
  }
}

Simulation::~Simulation() {
  // Sessions on an H model end while the model lives (m_h is destroyed before the doors and
  // m_h_mpi): the S7 doors' client connections first, then the H CPUs' MPI sessions.
  for (auto& d : m_s7_doors) d->close();
  for (auto& n : m_h_mpi) n->end_sessions(m_sched.now());
  for (const auto& l : m_links) ::unlink(l.c_str());
}

void Simulation::make_link(const std::string& target, const std::string& link) {
  const std::string e = bus::make_pty_link(target, link);
  if (!e.empty()) throw std::runtime_error(e);
  m_links.push_back(link);
}

bus::PacedRunner& Simulation::paced_runner(bus::Speed speed) {
  if (m_runner) {
    m_runner->set_speed(speed);
    return *m_runner;
  }
  m_runner = std::make_unique<bus::PacedRunner>(m_sched, speed);
  for (auto& ls : m_lines)
    for (auto& s : ls->stations)
      if (s.pty) s.pty->attach_io(*m_runner);
  for (auto& g : m_gateways) g->open(*m_runner);
  for (auto& d : m_s7_doors) d->open(*m_runner);
  for (auto& q : m_quantum) q->open(*m_runner);
  return *m_runner;
}

void Simulation::poll_serial() {
  for (auto& ls : m_lines)
    for (auto& s : ls->stations)
      if (s.pty) s.pty->poll_input();
}

void Simulation::build_line(std::size_t li) {
  const PlanLine& pl = m_plan.lines[li];
  auto ls = std::make_unique<LineState>();
  ls->line = std::make_unique<bus::Line>(m_sched, pl.name, pl.baud,
                                         splitmix64(m_seed ^ splitmix64(li + 1)));
  ls->line->set_index(static_cast<int>(li));
  ls->stations.reserve(pl.stations.size());
  const bool extra_here = m_opts.extra_device != nullptr && m_opts.extra_line == pl.name;
  bool extra_done = false;
  for (const PlanStation& ps : pl.stations) {
    if (m_opts.omit_masters && (ps.kind == StationKind::Master || ps.kind == StationKind::DpMaster)) {
      bool redundant_side = false;
      if (ps.kind == StationKind::DpMaster) {
        const auto it = std::find_if(m_plan.dp_masters.begin(), m_plan.dp_masters.end(),
                                     [&](const DpMasterPlan& m) { return m.source == ps.source; });
        const int mi = static_cast<int>(it - m_plan.dp_masters.begin());
        for (auto& node : m_redundant) redundant_side |= node->side_of_master(mi) >= 0;
      }
      if (!redundant_side) {
        if (extra_here && !extra_done) {
          ls->line->attach(*m_opts.extra_device, m_opts.extra_label);
          extra_done = true;
        } else {
          ls->inert.push_back(std::make_unique<InertDevice>());
          ls->line->attach(*ls->inert.back(), "omitted master " + std::to_string(ps.address.value_or(0)));
        }
        continue;
      }
    }
    Station st;
    st.kind = ps.kind;
    st.address = ps.address.value_or(0);
    std::string label;
    switch (ps.kind) {
      case StationKind::Master: {
        const auto& m = m_plan.proto.master(ps.source);
        std::vector<devices::PollItem> items;
        for (const auto& poll : m.poll())
          for (std::uint32_t a : poll.address())
            items.push_back({static_cast<std::uint8_t>(a), request_fn(poll.service(), poll.priority()),
                             static_cast<std::uint16_t>(poll.length())});
        st.poller = std::make_unique<devices::FdlPoller>(std::move(items));
        st.active = std::make_unique<fdl::ActiveStation>(st.address, ps.params, *st.poller);
        label = "master " + std::to_string(st.address);
        st.position = ls->line->attach(*st.active, label);
        break;
      }
      case StationKind::Passive: {
        const auto& p = m_plan.proto.passive_station(ps.source);
        st.responder =
            std::make_unique<devices::FdlResponder>(static_cast<std::uint16_t>(p.response_length()));
        st.passive = std::make_unique<fdl::PassiveStation>(
            st.address, ps.params, *st.responder, p.has_response_delay() ? p.response_delay() : 0);
        label = "slave " + std::to_string(st.address);
        st.position = ls->line->attach(*st.passive, label);
        break;
      }
      case StationKind::DpMaster: {
        const auto it = std::find_if(m_plan.dp_masters.begin(), m_plan.dp_masters.end(),
                                     [&](const DpMasterPlan& m) { return m.source == ps.source; });
        const int mi = static_cast<int>(it - m_plan.dp_masters.begin());
        label = "dp master " + std::to_string(st.address);
        for (auto& node : m_redundant)
          if (const int side = node->side_of_master(mi); side >= 0) {
            st.red = node.get();
            st.red_side = side;
          }
        if (st.red != nullptr) {
          st.position = st.red->model().attach(st.red_side, *ls->line, label);
          break;
        }
        // A Quantum pair's DP master module: both racks' modules at this place (quantum_node.hpp).
        for (std::size_t k = 0; k < m_quantum.size(); ++k)
          if (m_plan.quantum[k].dp_master == mi) st.quantum = static_cast<int>(k);
        if (st.quantum >= 0) {
          st.position = m_quantum[static_cast<std::size_t>(st.quantum)]->attach_dp(*ls->line);
          break;
        }
        st.dp_master = std::make_unique<DpMasterNode>(*it, m_plan.dp_slaves, ps.params);
        for (auto& cpu : m_s7_cpus) {
          const auto& cp = cpu->plan();
          if ((cp.x1_dp && cp.x1_dp->dp_master == mi) || (cp.x2_dp && cp.x2_dp->dp_master == mi)) {
            S7CpuNode* node = cpu.get();
            st.dp_master->set_cpu([node](dp::Master& m) { node->exchange(m); });
            node->attach_dp(pl.name, st.dp_master->master(), cp.x1_dp && cp.x1_dp->dp_master == mi);
            label = "CPU " + cp.name + " DP interface " + std::to_string(st.address);
          }
        }
        st.position = ls->line->attach(st.dp_master->station(), label);
        break;
      }
      case StationKind::SwitchedInterface: {
        // By address on this line's system: switched_station and y_link/dp_pa_link entries
        // number their sources apart, the address on a line is unique.
        const auto it = std::find_if(m_plan.switched.begin(), m_plan.switched.end(),
                                     [&](const SwitchedPlan& w) {
                                       const RedundancyPlan& r = m_plan.redundant_systems.at(
                                           static_cast<std::size_t>(w.system));
                                       return w.address == st.address &&
                                              (r.line[0] == static_cast<int>(li) ||
                                               r.line[1] == static_cast<int>(li));
                                     });
        st.switched = static_cast<int>(it - m_plan.switched.begin());
        st.red = m_redundant.at(static_cast<std::size_t>(it->system)).get();
        st.red_side = st.red->line(0) == static_cast<int>(li) ? 0 : 1;
        label = "switched station " + std::to_string(st.address) + (st.red_side == 0 ? " (A)" : " (B)");
        st.position = st.red->station(st.switched)->attach(st.red_side, *ls->line, label);
        break;
      }
      case StationKind::DpSlave: {
        // Switched stations' interfaces are DpSlavePlans too, with sources of their own list.
        const auto it2 = std::find_if(m_plan.dp_slaves.begin(), m_plan.dp_slaves.end(),
                                      [&](const DpSlavePlan& s) {
                                        return s.switched < 0 && s.source == ps.source;
                                      });
        st.dp_slave = std::make_unique<DpSlaveNode>(*it2, ps.params);
        st.dp_slave_plan = &*it2;
        label = "dp slave " + std::to_string(st.address);
        st.position = ls->line->attach(st.dp_slave->station(), label);
        break;
      }
      case StationKind::S7CpuMpi: {
        S7CpuNode& cpu = *m_s7_cpus.at(static_cast<std::size_t>(ps.source));
        label = "CPU " + cpu.plan().name + " MPI " + std::to_string(st.address);
        st.position = ls->line->attach(*cpu.mpi(), label);
        break;
      }
      case StationKind::MpiStation: {
        MpiClientNode& pg = *m_mpi_clients.at(static_cast<std::size_t>(ps.source));
        label = std::string(pg.plan().op ? "OP " : "PG ") + std::to_string(st.address);
        st.position = ls->line->attach(pg.station(), label);
        break;
      }
      case StationKind::S7DoorMpi: {
        S7DoorNode& door = *m_s7_doors.at(static_cast<std::size_t>(ps.source));
        label = "S7 door " + door.plan().name + " MPI " + std::to_string(st.address);
        st.position = ls->line->attach(*door.mpi(), label);
        break;
      }
      case StationKind::HCpuMpi: {
        // source = h_system entry * 2 + rack (scenario.hpp); the nodes are in h_mpi order.
        const int entry = ps.source / 2, rack = ps.source % 2;
        for (auto& n : m_h_mpi) {
          if (m_plan.h_systems.at(static_cast<std::size_t>(n->plan().h_system)).source != entry ||
              n->rack() != rack)
            continue;
          label = m_plan.h_systems.at(static_cast<std::size_t>(n->plan().h_system)).name + " CPU " +
                  std::to_string(rack) + " MPI " + std::to_string(st.address);
          st.position = ls->line->attach(n->station(), label);
        }
        break;
      }
      case StationKind::SerialMonitor:
      case StationKind::SerialStation: {
        const auto& sp = m_plan.proto.serial(ps.source);
        bus::PtyStation::Options o;
        const bool station = ps.kind == StationKind::SerialStation;
        o.mode = station ? bus::PtyStation::Mode::Station : bus::PtyStation::Mode::Monitor;
        o.address = ps.address ? int(*ps.address) : -1;
        o.timing = sp.timing() == scenario::Serial::RAW ? bus::PtyStation::Timing::Raw
                                                         : bus::PtyStation::Timing::Interface;
        o.reply_window_bits = pl.params.tsl;
        try {
          st.pty = std::make_unique<bus::PtyStation>(o);
        } catch (const std::exception& e) {
          throw std::runtime_error("cannot open a pseudo-terminal for line " + pl.name + ": " +
                                   e.what());
        }
        label = station ? "serial station " + std::to_string(st.address) : "serial monitor";
        st.position = ls->line->attach(*st.pty, label);
        SerialReport sr;
        sr.line = pl.name;
        sr.mode = station ? "station" : "monitor";
        sr.path = st.pty->path();
        sr.link = sp.link();
        if (station) sr.address = st.address;
        sr.timing = o.timing == bus::PtyStation::Timing::Raw ? "raw" : "interface";
        sr.baud = pl.baud;
        if (!sp.link().empty()) make_link(st.pty->path(), sp.link());
        m_serial.push_back(std::move(sr));
        break;
      }
    }
    ls->stations.push_back(std::move(st));
  }
  if (extra_here && !extra_done) ls->line->attach(*m_opts.extra_device, m_opts.extra_label);
  // An IM 157 link's own master on its lower line, after the planned stations (dp_link_node.hpp).
  if (const int k = link_of_lower_line(m_plan, static_cast<int>(li)); k >= 0) {
    const DpLinkPlan& lp = m_plan.dp_links[static_cast<std::size_t>(k)];
    devices::DpLink* l = m_redundant.at(static_cast<std::size_t>(lp.system))->link(lp.switched);
    if (l != nullptr) l->attach_lower(*ls->line, l->name() + " master " + std::to_string(lp.master));
  }
  m_lines.push_back(std::move(ls));
}

bus::Line& Simulation::line(std::size_t i) { return *m_lines.at(i)->line; }
const LineStats& Simulation::stats(std::size_t i) const { return m_lines.at(i)->stats; }

const devices::FdlPoller* Simulation::poller(std::size_t li, std::uint8_t addr) const {
  for (const auto& s : m_lines.at(li)->stations)
    if (s.kind == StationKind::Master && s.address == addr) return s.poller.get();
  return nullptr;
}

const devices::FdlResponder* Simulation::responder(std::size_t li, std::uint8_t addr) const {
  for (const auto& s : m_lines.at(li)->stations)
    if (s.kind == StationKind::Passive && s.address == addr) return s.responder.get();
  return nullptr;
}

const DpMasterNode* Simulation::dp_master(std::size_t li, std::uint8_t addr) const {
  for (const auto& s : m_lines.at(li)->stations)
    if (s.dp_master && s.address == addr) return s.dp_master.get();
  return nullptr;
}

DpMasterNode* Simulation::dp_master(std::size_t li, std::uint8_t addr) {
  for (auto& s : m_lines.at(li)->stations)
    if (s.dp_master && s.address == addr) return s.dp_master.get();
  return nullptr;
}

const DpSlaveNode* Simulation::dp_slave(std::size_t li, std::uint8_t addr) const {
  for (const auto& s : m_lines.at(li)->stations)
    if (s.dp_slave && s.address == addr) return s.dp_slave.get();
  return nullptr;
}

void Simulation::start() {
  if (m_started) return;
  m_started = true;
  for (auto& ls : m_lines) {
    ls->line->start();
    // Powering up is not a fault: only what happens from now on goes into the report (the
    // capture keeps the power-on events).
    ls->stats.faults.clear();
  }
  // The CPU pairs after the lines are powered (their models unpower the DP masters of the
  // CPUs that are off), before the faults.
  std::vector<RedundantSystemNode*> systems;
  for (auto& node : m_redundant) systems.push_back(node.get());
  for (std::size_t k = 0; k < m_plan.h_systems.size(); ++k) {
    if (!m_plan.h_systems[k].runtime) continue;
    m_h.push_back(std::make_unique<HSystemNode>(m_plan, static_cast<int>(k), m_sched, systems));
    m_h.back()->set_capture(m_opts.capture);
    for (const auto& hm : m_plan.s7.h_memory)
      if (hm.h_system == static_cast<int>(k)) m_h.back()->model().set_s7_memory(hm.memory);
    m_h.back()->start();
    // The CPUs' MPI interfaces are powered with their CPUs.
    const auto& on = m_plan.h_systems[k].runtime->power_on;
    for (int r = 0; r < 2; ++r) {
      const auto when = on[static_cast<std::size_t>(r)];
      if (when && *when <= m_sched.now()) continue;
      set_h_mpi_power(static_cast<int>(k), r, false);
      if (when) {
        const int hk = static_cast<int>(k);
        m_sched.schedule(*when, [this, hk, r] { set_h_mpi_power(hk, r, true); });
      }
    }
  }
  // The Quantum pairs power their racks (and their DP master modules) themselves.
  for (auto& q : m_quantum) q->start();
  // The CPU pairs' DP masters powered with their CPUs at time 0: still powering up.
  for (auto& ls : m_lines) ls->stats.faults.clear();
  for (auto& cpu : m_s7_cpus) cpu->start(m_sched.now());
  for (auto& pg : m_mpi_clients) pg->start(m_sched.now());
  build_gateways();
  schedule_faults();
}

void Simulation::build_gateways() {
  for (const GatewayPlan& gp : m_plan.gateways) {
    dp::Master* master = nullptr;
    devices::RedundantMasterSystemModel* system = nullptr;
    const devices::HSystemModel* h = nullptr;
    if (gp.dp_master >= 0) {
      const DpMasterPlan& mp = m_plan.dp_masters.at(static_cast<std::size_t>(gp.dp_master));
      if (DpMasterNode* n = dp_master(static_cast<std::size_t>(mp.line), mp.params.address))
        master = &n->master();
    } else if (gp.system >= 0) {
      system = &m_redundant.at(static_cast<std::size_t>(gp.system))->model();
      if (gp.h_system >= 0) {
        const int source = m_plan.h_systems.at(static_cast<std::size_t>(gp.h_system)).source;
        for (auto& node : m_h)
          if (node->plan().source == source) h = &node->model();
      }
    }
    m_gateways.push_back(std::make_unique<GatewayNode>(m_plan, gp, m_sched, master, system, h));
    m_gateways.back()->start(m_sched.now());
  }
}

void Simulation::schedule_faults() {
  for (const PlanFault& f : m_plan.faults) {
    if (m_duration && f.at > *m_duration) {
      m_not_reached.push_back(f.description + " at " + bus::format_duration(f.at));
      continue;
    }
    m_sched.schedule(f.at, [this, &f] { apply_fault(f, true); });
    if (f.repair_at) {
      if (m_duration && *f.repair_at > *m_duration) {
        m_not_reached.push_back("repair of " + f.description + " at " +
                                bus::format_duration(*f.repair_at));
      } else {
        m_sched.schedule(*f.repair_at, [this, &f] { apply_fault(f, false); });
      }
    }
  }
}

void Simulation::apply_fault(const PlanFault& f, bool on) {
  if (is_quantum_fault(f.kind)) {
    m_quantum.at(static_cast<std::size_t>(f.quantum))->apply(f, on);
    return;
  }
  if (is_h_fault(f.kind)) {
    for (auto& h : m_h)
      if (h->plan().source == m_plan.h_systems.at(static_cast<std::size_t>(f.h_system)).source)
        h->apply(f, on);
    // The CPU's MPI interface goes with it (after the fault's note: the note comes first).
    if (f.kind == PlanFault::Kind::CpuFailure) set_h_mpi_power(f.h_system, f.rack, !on);
    return;
  }
  LineState& ls = *m_lines.at(static_cast<std::size_t>(f.line));
  bus::Line& l = *ls.line;
  using K = PlanFault::Kind;
  // Every redundant system that the fault concerns notes it first (switchover measurements).
  for (auto& node : m_redundant)
    if (node->index() == f.system || node->line(0) == f.line || node->line(1) == f.line)
      node->note_fault(m_sched.now(), f, on);
  switch (f.kind) {
    case K::CableCut: l.set_cut_between(f.a, f.b, on); break;
    case K::ShortCircuit: l.set_short_circuit(on); break;
    case K::Noise: l.set_noise(on ? f.noise_ppb : 0); break;
    case K::PowerLoss: l.set_power(f.a, !on); break;
    case K::TransceiverFailure: l.set_transceiver_ok(f.a, !on); break;
    case K::Babble: l.set_babbling(f.a, on); break;
    case K::SlaveMute:
    case K::SlaveStop:
    case K::ChannelDiag:
    case K::ModulePull:
    case K::ProcessAlarm: apply_slave_fault(f, on); break;
    case K::ChannelStuck: apply_channel_stuck(f, on); break;
    case K::InterfaceFailure:
    case K::StationPowerLoss:
    case K::MasterFailure:
    case K::MasterStop: {
      std::string text = on ? f.description : "repair of " + f.description;
      if (f.system >= 0) {
        text = m_redundant.at(static_cast<std::size_t>(f.system))->apply(f, on);
      } else if (f.kind == K::MasterFailure) {
        l.set_power(f.a, !on);
      } else if (f.kind == K::MasterStop) {
        for (auto& s : ls.stations)
          if (s.dp_master && s.position == f.a)
            s.dp_master->master().set_mode(on ? dp::MasterMode::Stop : dp::MasterMode::Operate);
      }
      ls.stats.faults.push_back({m_sched.now(), std::move(text)});
      break;
    }
    default: break;  // H-system faults: applied above
  }
}

void Simulation::apply_slave_fault(const PlanFault& f, bool on) {
  LineState& ls = *m_lines.at(static_cast<std::size_t>(f.line));
  if (f.kind == PlanFault::Kind::ModulePull && f.switched >= 0) {  // a switched station's module
    for (auto& r : m_redundant)
      if (devices::SwitchedStationModel* st = r->station(f.switched)) {
        std::string text = on ? f.description : "plugged" + f.description.substr(6);
        if (std::string why = st->set_module_pulled(f.module, on); !why.empty())
          text += " (refused: " + why + ")";
        ls.stats.faults.push_back({m_sched.now(), std::move(text)});
      }
    return;
  }
  DpSlaveNode* node = nullptr;
  for (auto& s : ls.stations)
    if (s.dp_slave && s.address == f.slave) node = s.dp_slave.get();
  if (node == nullptr) return;  // the loader checked it
  using K = PlanFault::Kind;
  using SF = devices::SlaveFault;
  SF sf;
  std::string text;
  switch (f.kind) {
    case K::SlaveMute:
      sf = on ? SF::mute() : SF::unmute();
      text = on ? f.description : "un" + f.description;
      break;
    case K::ChannelDiag:
      sf = SF::channel_diag(f.module, f.channel, static_cast<dp::ChannelError>(f.error_type),
                            f.word_channel ? dp::ChannelType::Word : dp::ChannelType::Bit,
                            f.output_channel ? dp::ChannelDirection::Output
                                             : dp::ChannelDirection::Input,
                            on);
      text = f.description + (on ? " appears" : " disappears");
      break;
    case K::SlaveStop:
      sf = on ? SF::slave_stop() : SF::slave_run();
      text = on ? f.description : "CPU of" + f.description.substr(6, f.description.size() - 6 - 8) +
                                      " back to RUN";  // "CPU of <who> to STOP"
      break;
    case K::ModulePull:
      sf = on ? SF::pulled(f.module) : SF::plugged(f.module);
      text = on ? f.description : "plugged" + f.description.substr(6);  // "pulled ..." -> "plugged ..."
      break;
    default: sf = SF::process_alarm(f.module, {}); text = f.description; break;
  }
  // Slave faults are no line events: the report lists them with the line's faults.
  if (std::string why = node->model().apply(sf); !why.empty()) text += " (refused: " + why + ")";
  ls.stats.faults.push_back({m_sched.now(), std::move(text)});
}

// channel_stuck (docs/h-redundant-io.md): the module's inputs become a constant; the repair
// gives the module the behaviours of its plan again.
void Simulation::apply_channel_stuck(const PlanFault& f, bool on) {
  LineState& ls = *m_lines.at(static_cast<std::size_t>(f.line));
  DpSlaveNode* node = nullptr;
  for (auto& s : ls.stations)
    if (s.dp_slave && s.address == f.slave) node = s.dp_slave.get();
  if (node == nullptr) return;  // the loader checked it
  devices::SlaveModel& model = node->model();
  std::string text = on ? f.description : f.description + ": repaired";
  std::string why;
  if (on) {
    const std::size_t n = model.application().module(f.module).in_len;
    std::vector<std::uint8_t> v(n, 0);
    devices::put_big_endian(static_cast<std::int64_t>(f.stuck_value), v.begin(), n);
    why = model.set_behaviour(f.module, devices::IoBehaviour::constant_value(std::move(v)));
  } else {
    for (const DpSlavePlan& p : m_plan.dp_slaves) {
      if (p.switched >= 0 || p.line != f.line || p.address != f.slave) continue;
      apply_io_plan(
          p, model.application(),
          [&](std::size_t m, devices::IoBehaviour beh) {
            return m == f.module ? model.set_behaviour(m, std::move(beh)) : std::string();
          },
          [&](std::size_t m, std::size_t off, std::size_t w, devices::IoBehaviour beh) {
            return m == f.module ? model.add_channel_behaviour(m, off, w, std::move(beh))
                                 : std::string();
          });
    }
  }
  if (!why.empty()) text += " (refused: " + why + ")";
  ls.stats.faults.push_back({m_sched.now(), std::move(text)});
}

void Simulation::run_until(Ticks t) {
  start();
  m_sched.run_until(t);
}

Report Simulation::report(double wall_seconds) const {
  Report r;
  r.name = m_plan.name;
  r.file = m_plan.file;
  r.seed = m_seed;
  r.duration = m_sched.now();
  r.wall_seconds = wall_seconds;
  r.events = m_sched.events_run();
  r.faults_not_reached = m_not_reached;
  std::size_t serial_index = 0;
  for (std::size_t li = 0; li < m_lines.size(); ++li) {
    const LineState& ls = *m_lines[li];
    const PlanLine& pl = m_plan.lines[li];
    LineReport lr;
    lr.name = pl.name;
    lr.baud = pl.baud;
    lr.params = pl.params;
    lr.traffic = ls.stats;
    lr.probe = ls.stats_probe;
    std::array<int, 128> live;
    live.fill(-1);
    for (const Station& s : ls.stations) {
      if (s.kind == StationKind::Master) {
        const fdl::ActiveStats& as = s.active->stats();
        MasterReport m;
        m.address = s.address;
        m.state = std::string(fdl::to_string(s.active->state()));
        m.in_ring = s.active->in_ring();
        m.las = s.active->las();
        m.tokens_received = as.tokens_received;
        m.tokens_passed = as.tokens_passed;
        m.token_pass_retries = as.token_pass_retries;
        m.stations_dropped = as.stations_dropped;
        m.token_losses = as.token_losses;
        m.admissions = as.admissions;
        m.duplicate_tokens = as.duplicate_token;
        m.gap_polls = as.gap_polls;
        m.rotation = rotation_stats(s.poller->rotation_times());
        m.polls = s.poller->total();
        lr.masters.push_back(std::move(m));
        // Live list: what the masters know from their GAP polls and LAS, merged; the master
        // itself by its own state. Knowledge of a powered-off master is left out (stale).
        if (!ls.line->powered(s.position)) continue;
        live[s.address] = std::max(live[s.address], s.active->in_ring()
                                                        ? int(fdl::StationType::MasterInRing)
                                                        : int(fdl::StationType::MasterNotReady));
        for (const auto& [addr, type] : s.active->live_list())
          if (addr < 128) live[addr] = std::max(live[addr], int(type));
      } else if (s.kind == StationKind::Passive) {
        StationReport sr;
        sr.address = s.address;
        const auto& ps = s.passive->stats();
        sr.requests = ps.requests;
        sr.replies = ps.replies;
        sr.fdl_status = ps.fdl_status;
        sr.cycles = s.responder->cycle();
        sr.tsyn_drops = ps.dropped_tsyn;
        lr.tsyn_drops += ps.dropped_tsyn;
        lr.stations.push_back(sr);
      } else if (s.dp_slave) {
        DpSlaveView v = dp_slave_view(*s.dp_slave, *s.dp_slave_plan, pl.name);
        lr.tsyn_drops += v.fdl.dropped_tsyn;
        r.dp_slaves.push_back(std::move(v));
      }
    }
    // What the wire showed, whoever sent it (a master behind a pty too).
    for (int a = 0; a < 128; ++a) live[a] = std::max<int>(live[a], ls.stats.heard[a]);
    for (const Station& s : ls.stations) {
      const bool red_master = s.red != nullptr && s.switched < 0;
      if (!s.dp_master && !red_master) continue;
      const fdl::ActiveStation& as =
          red_master ? s.red->model().station(s.red_side) : s.dp_master->station();
      const dp::Master& m = red_master ? s.red->model().master(s.red_side) : s.dp_master->master();
      // A DP master is a ring member like any FDL master: its live list counts too.
      if (ls.line->powered(s.position)) {
        live[s.address] = std::max(live[s.address], as.in_ring() ? int(fdl::StationType::MasterInRing)
                                                                 : int(fdl::StationType::MasterNotReady));
        for (const auto& [addr, type] : as.live_list())
          if (addr < 128) live[addr] = std::max(live[addr], int(type));
      }
      std::vector<const dp::SlaveEngine*> engines;
      std::vector<const DpSlavePlan*> plans;
      for (const Station& t : ls.stations) {
        if (t.dp_slave && t.dp_slave_plan->master == s.address) {
          engines.push_back(&t.dp_slave->engine());
          plans.push_back(t.dp_slave_plan);
        } else if (t.switched >= 0 && red_master && t.red == s.red) {
          const SwitchedPlan& swp = m_plan.switched.at(static_cast<std::size_t>(t.switched));
          auto& model = const_cast<RedundantSystemNode*>(t.red)->station(t.switched)->redundant_slave();
          engines.push_back(&model.engine(t.red_side));
          plans.push_back(&m_plan.dp_slaves.at(static_cast<std::size_t>(swp.slave[t.red_side])));
        }
      }
      const std::uint64_t gc =
          red_master ? s.red->model().global_controls(s.red_side) : s.dp_master->global_controls();
      r.dp_masters.push_back(dp_master_report(m, gc, engines, plans, pl.name, pl.baud));
    }
    for (int a = 0; a < 128; ++a)
      if (live[a] >= 0)
        lr.live.push_back({static_cast<std::uint8_t>(a), static_cast<fdl::StationType>(live[a])});
    for (const Station& s : ls.stations) {
      if (!s.pty) continue;
      SerialReport sr = m_serial.at(serial_index++);
      sr.stats = s.pty->stats();
      sr.receivers_tsyn_drops = lr.tsyn_drops;
      r.serial.push_back(std::move(sr));
    }
    r.lines.push_back(std::move(lr));
  }
  for (const auto& node : m_redundant) r.redundancy.push_back(node->report());
  for (const auto& h : m_h) r.h_systems.push_back(h->report());
  for (const auto& g : m_gateways) r.gateways.push_back(g->report());
  for (const auto& q : m_quantum) r.quantum.push_back(q->report());
  r.s7 = s7_report();
  return r;
}

}  // namespace pbvbus::tools

namespace pbvbus::tools {

S7Report Simulation::s7_report() const {
  S7Report r;
  for (const auto& c : m_s7_cpus) {
    S7CpuReport cr;
    cr.name = c->plan().name;
    if (const auto* m = c->mpi()) {
      cr.mpi_address = m->address();
      cr.accepted = m->stats().connects_accepted;
      cr.refused = m->stats().connects_refused;
      cr.open = m->server_connections();
      cr.pdus_received = m->stats().pdus_received;
      cr.pdus_sent = m->stats().pdus_sent;
    }
    cr.dp_exchanges = c->dp_exchanges();
    cr.unmapped_bytes = c->unmapped_bytes();
    r.cpus.push_back(std::move(cr));
  }
  for (const auto& pg : m_mpi_clients) {
    MpiStationReport sr;
    sr.op = pg->plan().op;
    sr.line = m_plan.lines.at(static_cast<std::size_t>(pg->plan().line)).name;
    sr.address = pg->plan().address;
    sr.connects = pg->connects();
    sr.breaks = pg->breaks();
    sr.refused = pg->refusals();
    sr.broken = pg->ends();
    for (std::size_t k = 0; k < pg->reads().size(); ++k) {
      const auto& st = pg->reads()[k];
      const auto& rp = pg->plan().reads[k];
      S7ReadReport rr;
      rr.cpu = rp.cpu;
      rr.item = rp.item.str();
      rr.requests = st.requests;
      rr.ok = st.ok;
      rr.errors = st.errors;
      rr.last_code = st.last_code;
      rr.last_value = st.last_value;
      rr.last_latency = st.last_latency;
      rr.max_latency = st.max_latency;
      sr.reads.push_back(std::move(rr));
    }
    r.stations.push_back(std::move(sr));
  }
  for (const auto& d : m_s7_doors) {
    S7DoorReport dr;
    dr.name = d->plan().name;
    dr.listen = d->plan().listen.str();
    dr.port = d->port();
    if (const auto* s = d->stats()) {
      dr.clients = s->clients_accepted;
      dr.connects = s->connects;
      dr.connects_refused = s->connects_refused;
      dr.routes_closed = s->routes_closed;
      dr.jobs = s->jobs;
      dr.answers = s->answers;
      dr.closed_garbage = s->closed_garbage;
      dr.closed_stalled = s->closed_stalled;
      dr.closed_idle = s->closed_idle;
      dr.closed_queue_full = s->closed_queue_full;
    }
    r.doors.push_back(std::move(dr));
  }
  return r;
}

}  // namespace pbvbus::tools

namespace pbvbus::tools {

void Simulation::attach_s7_capture(S7DoorNode& door) {
  captures::PcapngWriter& w = *m_opts.capture;
  const auto& p = door.plan();
  const std::uint32_t iface =
      w.add_s7_interface("s7door:" + p.name, "S7 PDUs of the ISO-on-TCP door \"" + p.name + "\" at " +
                                                 p.listen.str());
  door.set_capture([&w, iface, this](const iso_on_tcp::PduRecord& r) {
    captures::S7PduInfo info;
    info.direction = r.direction == iso_on_tcp::PduDirection::FromClient
                         ? captures::S7PduInfo::Direction::Inbound
                         : captures::S7PduInfo::Direction::Outbound;
    const std::string comment = "door connection " + std::to_string(r.connection_id);
    info.comment = comment;
    w.write_s7_pdu(iface, m_sched.now(), r.pdu, info);
  });
}

}  // namespace pbvbus::tools

namespace pbvbus::tools {

devices::HSystemModel* Simulation::h_model(int plan_index) {
  if (plan_index < 0) return nullptr;
  const int source = m_plan.h_systems.at(static_cast<std::size_t>(plan_index)).source;
  for (auto& h : m_h)
    if (h->plan().source == source) return &h->model();
  return nullptr;
}

void Simulation::set_h_mpi_power(int plan_index, int rack, bool on) {
  for (auto& n : m_h_mpi) {
    if (n->plan().h_system != plan_index || n->rack() != rack) continue;
    auto& line = *m_lines.at(static_cast<std::size_t>(n->plan().line))->line;
    for (const auto& st : m_lines.at(static_cast<std::size_t>(n->plan().line))->stations)
      if (st.kind == StationKind::HCpuMpi && st.address == n->plan().address[rack])
        line.set_power(st.position, on);
  }
}

}  // namespace pbvbus::tools
