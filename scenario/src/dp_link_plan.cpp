// IM 157 links in scenarios: y_link and dp_pa_link entries (dp_link_plan.hpp, docs/dp-link.md).
#include "pbvbus/scenario/dp_link_plan.hpp"

#include <algorithm>

#include "pbvbus/dp_link/dp_link.hpp"
#include "pbvbus/gsd/gsd.hpp"
#include "pbvbus/scenario/scenario.hpp"

namespace pbvbus::tools {

namespace {

constexpr std::size_t kPaMaxDevices = 30;    // D5: PA <= 30 nodes
constexpr std::size_t kPaMaxDevicesEx = 10;  // D5: <= 10 nodes / 100 mA in an Ex segment
constexpr std::size_t kMaxFrame = 244;       // the link's frames are the lower stations' frames

class LinkPlanner {
 public:
  LinkPlanner(ScenarioPlan& plan, const DpLocator& locate, std::vector<Diagnostic>& errors,
              const LinkSidePlanner& side)
      : m_plan(plan), m_locate(locate), m_errors(errors), m_side(side) {}

  void run() {
    for (int i = 0; i < m_plan.proto.y_link_size(); ++i)
      plan_link(devices::DpLinkKind::YLink, "y_link", i, m_plan.proto.y_link(i));
    for (int i = 0; i < m_plan.proto.dp_pa_link_size(); ++i)
      plan_link(devices::DpLinkKind::DpPaLink, "dp_pa_link", i, m_plan.proto.dp_pa_link(i));
  }

 private:
  void error(const char* rep, int i, const char* field, std::string msg) {
    auto [l, c] = m_locate(rep, i, field, -1);
    m_errors.push_back({m_plan.file, l, c, std::move(msg)});
  }

  int line_index(const std::string& name) const {
    for (std::size_t k = 0; k < m_plan.lines.size(); ++k)
      if (m_plan.lines[k].name == name) return static_cast<int>(k);
    return -1;
  }

  void plan_link(devices::DpLinkKind kind, const char* rep, int i, const scenario::DpLink& w) {
    const bool pa = kind == devices::DpLinkKind::DpPaLink;
    const std::string what = rep;
    DpLinkPlan lp;
    lp.kind = kind;
    lp.source = i;
    lp.repeated = rep;
    for (std::size_t k = 0; k < m_plan.redundant_systems.size(); ++k)
      if (!w.system().empty() && m_plan.redundant_systems[k].name == w.system())
        lp.system = static_cast<int>(k);
    if (lp.system < 0) {
      error(rep, i, "system",
            w.system().empty() ? what + " needs a system (a redundant_master_system's name)"
                               : "no redundant_master_system \"" + w.system() + "\"");
      return;
    }
    const RedundancyPlan& rp = m_plan.redundant_systems[static_cast<std::size_t>(lp.system)];
    if (rp.line[0] < 0) return;  // the system itself is broken (reported)
    bool ok = true;
    // D5, 001 L8128: DP/PA link or Y-link only up to 1.5 MBd on the redundant system.
    for (int side = 0; side < 2; ++side) {
      const PlanLine& ul = m_plan.lines[static_cast<std::size_t>(rp.line[side])];
      if (ul.baud > bus::Baud::k1_5M) {
        error(rep, i, "system",
              "redundant_master_system \"" + rp.name + "\" with a " +
                  devices::to_string(kind) + " runs at 1.5 Mbit/s at most (001 L8128), line \"" +
                  ul.name + "\" runs at " + std::string(bus::baud_name(ul.baud)) + "bit/s");
        ok = false;
      }
    }
    if (!w.has_address()) {
      error(rep, i, nullptr, what + " needs an address");
      return;
    }
    if (w.address() > dp::kMaxSlaveAddress) {
      error(rep, i, "address", what + " address " + std::to_string(w.address()) +
                                   " is out of range 0..125");
      return;
    }
    lp.address = static_cast<std::uint8_t>(w.address());
    if (w.has_master()) lp.master = static_cast<std::uint8_t>(w.master() & 0x7F);
    lp.ex = w.ex();
    if (lp.ex && !pa) {
      error(rep, i, "ex", "ex applies to a dp_pa_link's PA segment, not to a y_link");
      ok = false;
    }
    if (!w.switchover_time().empty()) {
      auto t = bus::parse_duration(w.switchover_time());
      if (!t || *t == 0) {
        error(rep, i, "switchover_time",
              "bad switchover_time \"" + w.switchover_time() + "\" (e.g. \"100ms\")");
        ok = false;
      } else {
        lp.switchover = *t;
      }
    }
    // The lower line.
    if (w.lower_line().empty()) {
      error(rep, i, nullptr, what + " needs a lower_line (the line below the coupler)");
      return;
    }
    lp.lower_line = line_index(w.lower_line());
    if (lp.lower_line < 0) {
      error(rep, i, "lower_line", "unknown line \"" + w.lower_line() + "\"");
      return;
    }
    const PlanLine& ll = m_plan.lines[static_cast<std::size_t>(lp.lower_line)];
    if (std::string why = devices::check_lower_baud(kind, ll.baud); !why.empty()) {
      error(rep, i, "lower_line", why + ", not " + std::string(bus::baud_name(ll.baud)) +
                                      "bit/s (line \"" + ll.name + "\")");
      ok = false;
    }
    if (ll.mpi) {
      error(rep, i, "lower_line", "lower_line \"" + ll.name + "\" is an MPI line");
      ok = false;
    }
    for (const auto& r : m_plan.redundant_systems)
      if (r.line[0] == lp.lower_line || r.line[1] == lp.lower_line) {
        error(rep, i, "lower_line", "lower_line \"" + ll.name + "\" is a line of redundant_master_system \"" +
                                        r.name + "\"");
        ok = false;
      }
    for (const auto& m : m_plan.dp_masters)
      if (m.line == lp.lower_line) {
        error(rep, i, "lower_line", "lower_line \"" + ll.name + "\" carries a dp_master (" +
                                        std::to_string(m.params.address) +
                                        "): the coupler is the lower line's DP master");
        ok = false;
      }
    for (const auto& other : m_plan.dp_links)
      if (other.lower_line == lp.lower_line) {
        error(rep, i, "lower_line", "lower_line \"" + ll.name + "\" is already below another link");
        ok = false;
      }
    if (lp.master >= ll.params.hsa) {
      error(rep, i, "master", "the coupler's master address " + std::to_string(lp.master) +
                                  " is not below HSA " + std::to_string(ll.params.hsa) +
                                  " of line \"" + ll.name + "\"");
      ok = false;
    }
    // The lower stations: the dp_slave entries on the lower line, file order.
    std::size_t in = 0, out = 0;
    for (std::size_t k = 0; k < m_plan.dp_slaves.size(); ++k) {
      const DpSlavePlan& sp = m_plan.dp_slaves[k];
      if (sp.line != lp.lower_line || sp.switched >= 0) continue;
      if (sp.master != dp::kNoMaster) {
        auto [l, c] = m_locate("dp_slave", sp.source, "master", -1);
        m_errors.push_back({m_plan.file, l, c,
                            "dp_slave " + std::to_string(sp.address) + " on \"" + ll.name +
                                "\" (below " + what + " " + std::to_string(lp.address) +
                                ") names a master: the coupler is its master"});
        ok = false;
      }
      if (sp.address == lp.master) {
        error(rep, i, "master", "the coupler's master address " + std::to_string(lp.master) +
                                    " is dp_slave " + std::to_string(sp.address) + "'s on \"" +
                                    ll.name + "\"");
        ok = false;
      }
      lp.lower.push_back(static_cast<int>(k));
      in += sp.inputs;
      out += sp.outputs;
    }
    const std::size_t n = lp.lower.size();
    if (n == 0) {
      error(rep, i, "lower_line", what + " without lower stations: no dp_slave on \"" + ll.name + "\"");
      return;
    }
    if (pa && n > (lp.ex ? kPaMaxDevicesEx : kPaMaxDevices)) {
      error(rep, i, lp.ex ? "ex" : "lower_line",
            std::to_string(n) + " PA devices on \"" + ll.name + "\": a PA segment takes at most " +
                (lp.ex ? "10 in an Ex area (100 mA)" : std::string("30")) + " (D5)");
      ok = false;
    } else if (n > devices::kLinkMaxLowerStations) {
      error(rep, i, "lower_line", std::to_string(n) + " lower stations on \"" + ll.name +
                                      "\", a link takes at most 64");
      ok = false;
    }
    if (in > kMaxFrame || out > kMaxFrame) {
      error(rep, i, "lower_line", "the lower stations on \"" + ll.name + "\" have " +
                                      std::to_string(in) + " octets of inputs and " +
                                      std::to_string(out) + " of outputs: the link's frames "
                                      "carry at most 244 each way");
      ok = false;
    }
    if (!ok) return;
    plan_upper(lp, rp, rep, i);
  }

  /// The link towards its system: a switched station built from the link GSD.
  void plan_upper(DpLinkPlan& lp, const RedundancyPlan& rp, const char* rep, int i) {
    std::vector<devices::LinkGsdModule> mods;
    std::vector<std::string> names;
    for (int k : lp.lower) {
      const DpSlavePlan& sp = m_plan.dp_slaves[static_cast<std::size_t>(k)];
      devices::LinkGsdModule m;
      m.name = sp.model + " @" + std::to_string(sp.address);
      m.cfg = sp.params.chk_cfg_du();
      names.push_back(m.name);
      mods.push_back(std::move(m));
    }
    const std::string gsd_name = std::string(rep) + " " + std::to_string(lp.address) + " (IM 157)";
    auto g = devices::parse_gsd(devices::link_gsd_text(lp.kind, mods, lp.switchover), gsd_name);
    if (!g.ok()) {
      error(rep, i, nullptr, "the link's configuration: " + g.errors.front().to_string());
      return;
    }
    SwitchedPlan swp;
    swp.source = i;
    swp.system = lp.system;
    swp.address = lp.address;
    swp.t_slave_um = lp.switchover;
    swp.link = static_cast<int>(m_plan.dp_links.size());
    const int index = static_cast<int>(m_plan.switched.size());
    for (int side = 0; side < 2; ++side) {
      scenario::DpSlave d;
      d.set_address(lp.address);
      d.set_line(m_plan.lines[static_cast<std::size_t>(rp.line[side])].name);
      d.set_master(m_plan.proto.dp_master(m_plan.dp_masters[static_cast<std::size_t>(rp.master[side])].source).address());
      d.set_gsd(gsd_name);
      for (const auto& nm : names) d.add_modules(nm);
      d.set_inputs(scenario::DpSlave::ZERO);
      const int s = m_side(d, *g.file, rep, i, index, side);
      if (s < 0) return;  // reported
      swp.slave[side] = s;
    }
    lp.switched = index;
    m_plan.redundant_systems[static_cast<std::size_t>(lp.system)].switched.push_back(index);
    m_plan.switched.push_back(swp);
    m_plan.dp_links.push_back(lp);
  }

  ScenarioPlan& m_plan;
  const DpLocator& m_locate;
  std::vector<Diagnostic>& m_errors;
  const LinkSidePlanner& m_side;
};

}  // namespace

void plan_dp_links(ScenarioPlan& plan, const DpLocator& locate, std::vector<Diagnostic>& errors,
                   const LinkSidePlanner& plan_side) {
  LinkPlanner(plan, locate, errors, plan_side).run();
}

int link_of_lower_line(const ScenarioPlan& plan, int line) {
  for (std::size_t k = 0; k < plan.dp_links.size(); ++k)
    if (plan.dp_links[k].lower_line == line) return static_cast<int>(k);
  return -1;
}

}  // namespace pbvbus::tools
