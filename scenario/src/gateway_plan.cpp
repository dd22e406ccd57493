// The loader's gateway checks (gateway_plan.hpp has the rules).
#include "pbvbus/scenario/gateway_plan.hpp"

#include <arpa/inet.h>

#include <algorithm>
#include <charconv>
#include <map>
#include <set>

#include "pbvbus/scenario/scenario.hpp"

namespace pbvbus::tools {

std::string GwEndpoint::str() const {
  const bool v6 = host.find(':') != std::string::npos;
  return (v6 ? "[" + host + "]" : host) + ":" + std::to_string(port);
}

std::optional<GwEndpoint> parse_endpoint(const std::string& text) {
  const auto colon = text.rfind(':');
  if (colon == std::string::npos || colon == 0 || colon + 1 >= text.size()) return std::nullopt;
  std::string host = text.substr(0, colon);
  const std::string port = text.substr(colon + 1);
  unsigned value = 0;
  auto [p, ec] = std::from_chars(port.data(), port.data() + port.size(), value);
  if (ec != std::errc() || p != port.data() + port.size() || value > 65535) return std::nullopt;
  // Numeric only: a name would need a resolver, which blocks.
  unsigned char buf[16];
  if (host.size() > 2 && host.front() == '[' && host.back() == ']') {
    host = host.substr(1, host.size() - 2);
    if (::inet_pton(AF_INET6, host.c_str(), buf) != 1) return std::nullopt;
  } else if (::inet_pton(AF_INET, host.c_str(), buf) != 1) {
    return std::nullopt;
  }
  return GwEndpoint{host, static_cast<std::uint16_t>(value)};
}

GwRtu plan_modbus_rtu(const scenario::ModbusRtu& m,
                      const std::function<void(const char* field, const std::string& msg)>& error) {
  GwRtu rtu;
  if (m.port_case() == scenario::ModbusRtu::kLink) {
    rtu.link = m.link();
    if (rtu.link.empty()) error("link", "link must not be empty");
  } else if (m.port_case() == scenario::ModbusRtu::kDevice) {
    rtu.device = m.device();
    if (rtu.device.empty()) error("device", "device must not be empty");
  } else {
    error(nullptr, "modbus_rtu needs a link (a pty) or a device");
  }
  if (m.baud() != 0) rtu.baud = m.baud();
  rtu.parity = m.parity() == scenario::ModbusRtu::EVEN ? 'E'
               : m.parity() == scenario::ModbusRtu::ODD ? 'O' : 'N';
  if (m.has_stop_bits()) {
    if (m.stop_bits() != 1 && m.stop_bits() != 2) error("stop_bits", "stop_bits must be 1 or 2");
    rtu.stop_bits = static_cast<int>(m.stop_bits());
  }
  return rtu;
}

namespace {

GwWordOrder word_order(scenario::WordOrder w) {
  switch (w) {
    case scenario::BYTE_SWAP: return GwWordOrder::ByteSwap;
    case scenario::WORD_SWAP: return GwWordOrder::WordSwap;
    case scenario::BYTE_WORD_SWAP: return GwWordOrder::ByteWordSwap;
    default: return GwWordOrder::HighByteFirst;
  }
}

GwStale stale(scenario::ModbusSlaveOptions::Stale s) {
  switch (s) {
    case scenario::ModbusSlaveOptions::KEEP: return GwStale::KeepLast;
    case scenario::ModbusSlaveOptions::ZERO: return GwStale::Zero;
    case scenario::ModbusSlaveOptions::VALUE: return GwStale::Value;
    default: return GwStale::Exception;
  }
}

constexpr const char* kBadListen =
    "(expected HOST:PORT with a numeric IPv4 address or [IPv6] and a port 0..65535, e.g. "
    "127.0.0.1:1502)";

class GwPlanner {
 public:
  GwPlanner(ScenarioPlan& plan, const GwLocator& locate, std::vector<Diagnostic>& errors)
      : m_plan(plan), m_locate(locate), m_errors(errors) {}

  void run() {
    for (int i = 0; i < m_plan.proto.gateway_size(); ++i) plan_one(i);
  }

 private:
  using Path = std::vector<HPathStep>;

  void error(int i, const Path& path, std::string msg) {
    auto [l, c] = m_locate(i, path);
    m_errors.push_back({m_plan.file, l, c, std::move(msg)});
  }

  /// A TCP listen address; checks it and that its port is used once in the file.
  std::optional<GwEndpoint> endpoint(int i, const Path& path, const std::string& text,
                                     const std::string& what) {
    auto e = parse_endpoint(text);
    if (!e) {
      error(i, path, "bad listen address \"" + text + "\" " + kBadListen);
      return std::nullopt;
    }
    if (e->port != 0) {
      const std::string who = "gateway \"" + m_plan.proto.gateway(i).name() + "\" (" + what + ")";
      auto [it, fresh] = m_ports.emplace(e->port, who);
      if (!fresh) {
        error(i, path, "port " + std::to_string(e->port) + " is already used by " + it->second);
        return std::nullopt;
      }
    }
    return e;
  }

  void link(int i, const Path& path, const std::string& l) {
    if (l.empty()) return;
    auto [it, fresh] = m_links.emplace(l, m_plan.proto.gateway(i).name());
    if (!fresh) error(i, path, "pty link \"" + l + "\" is already used by gateway \"" + it->second + "\"");
  }

  std::optional<bus::Ticks> duration(int i, const Path& path, const std::string& text,
                                     bus::Ticks def) {
    if (text.empty()) return def;
    auto t = bus::parse_duration(text);
    if (!t) {
      error(i, path,
            "bad duration \"" + text + "\" (expected a number and a unit: ns, us, ms, s, min, h)");
      return std::nullopt;
    }
    if (*t <= 0) {
      error(i, path, "must be longer than 0");
      return std::nullopt;
    }
    return t;
  }

  /// The served master system; false with an error.
  bool served(int i, const scenario::Gateway& g, GatewayPlan& gp) {
    const bool by_master = !g.line().empty() || g.has_master();
    const bool by_system = !g.redundant_master_system().empty();
    if (by_master == by_system) {
      error(i, {{by_system ? "redundant_master_system" : "name"}},
            "give the master system: line and master (a dp_master) or redundant_master_system");
      return false;
    }
    if (by_system) {
      for (std::size_t k = 0; k < m_plan.redundant_systems.size(); ++k)
        if (m_plan.redundant_systems[k].name == g.redundant_master_system()) gp.system = static_cast<int>(k);
      if (gp.system < 0) {
        error(i, {{"redundant_master_system"}},
              "unknown redundant_master_system \"" + g.redundant_master_system() + "\"");
        return false;
      }
      gp.served = "redundant_master_system \"" + g.redundant_master_system() + "\"";
      for (std::size_t k = 0; k < m_plan.h_systems.size(); ++k) {
        const auto& rt = m_plan.h_systems[k].runtime;
        if (rt && std::find(rt->systems.begin(), rt->systems.end(), gp.system) != rt->systems.end())
          gp.h_system = static_cast<int>(k);
      }
      const RedundancyPlan& rp = m_plan.redundant_systems[static_cast<std::size_t>(gp.system)];
      std::map<std::uint8_t, int> by_addr;
      for (int side = 0; side < 2; ++side) {
        if (rp.master[side] < 0) continue;
        for (int k : m_plan.dp_masters[static_cast<std::size_t>(rp.master[side])].slaves)
          by_addr.emplace(m_plan.dp_slaves[static_cast<std::size_t>(k)].address, k);
      }
      for (const auto& [a, k] : by_addr) gp.slaves.push_back(k);
      return true;
    }
    if (g.line().empty() || !g.has_master()) {
      error(i, {{g.line().empty() ? "master" : "line"}},
            "a gateway on a dp_master needs both line and master");
      return false;
    }
    const auto li = std::find_if(m_plan.lines.begin(), m_plan.lines.end(),
                                 [&](const PlanLine& l) { return l.name == g.line(); });
    if (li == m_plan.lines.end()) {
      error(i, {{"line"}}, "unknown line \"" + g.line() + "\"");
      return false;
    }
    const int line = static_cast<int>(li - m_plan.lines.begin());
    for (std::size_t k = 0; k < m_plan.dp_masters.size(); ++k)
      if (m_plan.dp_masters[k].line == line && m_plan.dp_masters[k].params.address == g.master())
        gp.dp_master = static_cast<int>(k);
    if (gp.dp_master < 0) {
      error(i, {{"master"}},
            "no dp_master " + std::to_string(g.master()) + " on line \"" + g.line() + "\"");
      return false;
    }
    for (const RedundancyPlan& rp : m_plan.redundant_systems)
      if (rp.master[0] == gp.dp_master || rp.master[1] == gp.dp_master) {
        error(i, {{"master"}},
              "dp_master " + std::to_string(g.master()) + " on line \"" + g.line() +
                  "\" is part of redundant_master_system \"" + rp.name +
                  "\": give redundant_master_system instead");
        return false;
      }
    gp.served = "dp_master " + std::to_string(g.master()) + " on " + g.line();
    std::vector<int> s = m_plan.dp_masters[static_cast<std::size_t>(gp.dp_master)].slaves;
    std::sort(s.begin(), s.end(), [&](int a, int b) {
      return m_plan.dp_slaves[static_cast<std::size_t>(a)].address <
             m_plan.dp_slaves[static_cast<std::size_t>(b)].address;
    });
    gp.slaves = std::move(s);
    return true;
  }

  const DpSlavePlan* slave(const GatewayPlan& gp, std::uint32_t address) const {
    for (int k : gp.slaves)
      if (m_plan.dp_slaves[static_cast<std::size_t>(k)].address == address)
        return &m_plan.dp_slaves[static_cast<std::size_t>(k)];
    return nullptr;
  }

  void plan_modbus(int i, const scenario::Gateway& g, GatewayPlan& gp) {
    if (g.has_modbus_tcp()) {
      const std::string l = g.modbus_tcp().listen().empty() ? "127.0.0.1:1502" : g.modbus_tcp().listen();
      gp.modbus_tcp = endpoint(i, {{"modbus_tcp"}, {"listen"}}, l, "modbus_tcp");
      gp.max_clients = g.modbus_tcp().max_clients();
    }
    for (int r = 0; r < g.modbus_rtu_size(); ++r) {
      GwRtu rtu = plan_modbus_rtu(g.modbus_rtu(r), [&](const char* field, const std::string& msg) {
        if (field != nullptr)
          error(i, {{"modbus_rtu", r}, {field}}, msg);
        else
          error(i, {{"modbus_rtu", r}}, msg);
      });
      if (!rtu.link.empty()) link(i, {{"modbus_rtu", r}, {"link"}}, rtu.link);
      gp.modbus_rtu.push_back(std::move(rtu));
    }
    const auto& o = g.modbus();
    gp.standby_units = o.standby_units();
    if (o.standby_units() && gp.system < 0)
      error(i, {{"modbus"}, {"standby_units"}}, "standby_units needs a redundant_master_system");
    std::set<std::uint32_t> seen;
    for (int s = 0; s < o.slave_size(); ++s) {
      const auto& so = o.slave(s);
      const Path at = {{"modbus"}, {"slave", s}};
      if (!so.has_address()) {
        error(i, at, "a slave option needs its address");
        continue;
      }
      const DpSlavePlan* sp = slave(gp, so.address());
      if (sp == nullptr) {
        error(i, {{"modbus"}, {"slave", s}, {"address"}},
              "address " + std::to_string(so.address()) + " is not a slave of " + gp.served);
        continue;
      }
      if (!seen.insert(so.address()).second) {
        error(i, {{"modbus"}, {"slave", s}, {"address"}},
              "options for slave " + std::to_string(so.address()) + " are given twice");
        continue;
      }
      GwModbusSlave ms;
      ms.address = sp->address;
      ms.order = word_order(so.word_order());
      ms.stale = stale(so.stale());
      if (so.stale_value() > 0xFFFF)
        error(i, {{"modbus"}, {"slave", s}, {"stale_value"}},
              "stale_value " + std::to_string(so.stale_value()) + " is out of range 0..65535");
      ms.stale_value = static_cast<std::uint16_t>(so.stale_value() & 0xFFFF);
      std::set<std::uint32_t> mods;
      for (int m = 0; m < so.module_size(); ++m) {
        const auto& mo = so.module(m);
        const Path mat = {{"modbus"}, {"slave", s}, {"module", m}, {"module_index"}};
        if (!mo.has_module_index()) {
          error(i, {{"modbus"}, {"slave", s}, {"module", m}}, "a module option needs its module_index");
          continue;
        }
        const std::size_t n = sp->module_names.size();
        if (mo.module_index() >= n) {
          error(i, mat,
                "module_index " + std::to_string(mo.module_index()) + " is out of range: slave " +
                    std::to_string(sp->address) + " has " + std::to_string(n) + " module" +
                    (n == 1 ? "" : "s") + (n == 0 ? "" : " (0.." + std::to_string(n - 1) + ")"));
          continue;
        }
        if (!mods.insert(mo.module_index()).second) {
          error(i, mat, "options for module_index " + std::to_string(mo.module_index()) +
                            " are given twice");
          continue;
        }
        if (mo.has_word_order()) ms.modules.emplace_back(mo.module_index(), word_order(mo.word_order()));
      }
      gp.modbus_slaves.push_back(std::move(ms));
    }
  }

  void plan_can(int i, const scenario::Gateway& g, GatewayPlan& gp) {
    if (!g.has_can()) return;
    const auto& c = g.can();
    GwCan can;
    std::map<std::uint32_t, std::uint32_t> node_of;  // address -> node
    for (int n = 0; n < c.node_size(); ++n) {
      const auto& e = c.node(n);
      if (!e.has_address() || !e.has_node()) {
        error(i, {{"can"}, {"node", n}}, "a node map entry needs address and node");
        continue;
      }
      if (slave(gp, e.address()) == nullptr) {
        error(i, {{"can"}, {"node", n}, {"address"}},
              "address " + std::to_string(e.address()) + " is not a slave of " + gp.served);
        continue;
      }
      if (e.node() < 1 || e.node() > 127) {
        error(i, {{"can"}, {"node", n}, {"node"}},
              "node " + std::to_string(e.node()) + " is out of range 1..127");
        continue;
      }
      if (!node_of.emplace(e.address(), e.node()).second) {
        error(i, {{"can"}, {"node", n}, {"address"}},
              "slave " + std::to_string(e.address()) + " is mapped twice");
        continue;
      }
      can.nodes.emplace_back(static_cast<std::uint8_t>(e.address()), static_cast<std::uint8_t>(e.node()));
    }
    // Every served slave's node id: mapped, else its address (1..127; 0 is not mapped).
    std::map<std::uint32_t, std::uint32_t> owner;  // node -> address
    for (int k : gp.slaves) {
      const std::uint32_t a = m_plan.dp_slaves[static_cast<std::size_t>(k)].address;
      const auto it = node_of.find(a);
      const std::uint32_t node = it != node_of.end() ? it->second : a;
      if (node < 1 || node > 127) continue;
      auto [o, fresh] = owner.emplace(node, a);
      if (!fresh) {
        int at = 0;
        for (int n = 0; n < c.node_size(); ++n)
          if (c.node(n).node() == node) at = n;
        error(i, {{"can"}, {"node", at}, {"node"}},
              "node " + std::to_string(node) + " is used twice (slave " + std::to_string(o->second) +
                  " and slave " + std::to_string(a) + ")");
      }
    }
    if (auto t = duration(i, {{"can"}, {"tpdo_cycle"}}, c.tpdo_cycle(), can.tpdo_cycle)) can.tpdo_cycle = *t;
    if (auto t = duration(i, {{"can"}, {"heartbeat"}}, c.heartbeat(), can.heartbeat)) {
      // Object 0x1017 holds it as u16 milliseconds.
      if (*t % bus::kTicksPerMs != 0 || *t > 65535 * bus::kTicksPerMs)
        error(i, {{"can"}, {"heartbeat"}},
              "heartbeat must be whole milliseconds up to 65535ms (object 0x1017 is 16 bits)");
      else
        can.heartbeat = *t;
    }
    if (c.has_slcan_pty()) {
      can.slcan_pty = c.slcan_pty().link();
      link(i, {{"can"}, {"slcan_pty"}, {"link"}}, c.slcan_pty().link());
    }
    if (c.has_slcan_tcp()) {
      if (c.slcan_tcp().listen().empty())
        error(i, {{"can"}, {"slcan_tcp"}}, "slcan_tcp needs listen (HOST:PORT)");
      else
        can.slcan_tcp = endpoint(i, {{"can"}, {"slcan_tcp"}, {"listen"}}, c.slcan_tcp().listen(), "slcan_tcp");
      can.slcan_max_clients = c.slcan_tcp().max_clients();
    }
    if (c.has_socketcand()) {
      const std::string l = c.socketcand().listen().empty() ? "127.0.0.1:29536" : c.socketcand().listen();
      can.socketcand = endpoint(i, {{"can"}, {"socketcand"}, {"listen"}}, l, "socketcand");
      can.socketcand_max_clients = c.socketcand().max_clients();
    }
    if (c.has_socketcan()) {
      if (c.socketcan().interface().empty())
        error(i, {{"can"}, {"socketcan"}}, "socketcan needs an interface, e.g. \"vcan0\"");
      can.socketcan = c.socketcan().interface();
    }
    if (!c.has_slcan_pty() && !c.has_slcan_tcp() && !c.has_socketcand() && !c.has_socketcan())
      error(i, {{"can"}}, "can needs a transport: slcan_pty, slcan_tcp, socketcand or socketcan");
    gp.can = std::move(can);
  }

  void plan_one(int i) {
    const scenario::Gateway& g = m_plan.proto.gateway(i);
    GatewayPlan gp;
    gp.source = i;
    gp.name = g.name();
    if (g.name().empty()) {
      error(i, {}, "a gateway needs a name");
    } else if (!m_names.insert(g.name()).second) {
      error(i, {{"name"}}, "gateway \"" + g.name() + "\" is defined twice");
    }
    if (!g.has_modbus_tcp() && g.modbus_rtu_size() == 0 && !g.has_can())
      error(i, {}, "gateway \"" + g.name() + "\" has no door: add modbus_tcp, modbus_rtu or can");
    if (!served(i, g, gp)) return;
    plan_modbus(i, g, gp);
    plan_can(i, g, gp);
    // Outputs ownership (scenario.proto, DpMaster.outputs): the clients own them, unless an
    // h_system's CPUs do.
    if (gp.h_system < 0) {
      if (gp.dp_master >= 0) m_plan.dp_masters[static_cast<std::size_t>(gp.dp_master)].gateway_outputs = true;
      if (gp.system >= 0)
        for (int m : m_plan.redundant_systems[static_cast<std::size_t>(gp.system)].master)
          if (m >= 0) m_plan.dp_masters[static_cast<std::size_t>(m)].gateway_outputs = true;
    }
    m_plan.gateways.push_back(std::move(gp));
  }

  ScenarioPlan& m_plan;
  const GwLocator& m_locate;
  std::vector<Diagnostic>& m_errors;
  std::set<std::string> m_names;
  std::map<std::uint16_t, std::string> m_ports;
  std::map<std::string, std::string> m_links;
};

}  // namespace

void plan_gateways(ScenarioPlan& plan, const GwLocator& locate, std::vector<Diagnostic>& errors) {
  GwPlanner(plan, locate, errors).run();
}

}  // namespace pbvbus::tools
