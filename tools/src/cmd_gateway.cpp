// `pbvbus gateway map SCENARIO [--json|--csv] [--gateway NAME]` (docs/gateway-modbus.md): the register map of
// each gateway of a scenario, something an HMI engineer can import, and the CAN node/PDO map.
//
// Decisions:
//  - The Simulation is built and started (stations powered, gateways' cores built) but not run
//    and no door is opened: no port is bound, no pty made — a map can be printed while the
//    scenario runs elsewhere.
//  - Text (default): per gateway a heading, the Modbus map (gateways::ModbusMap::to_text) when
//    the gateway has a Modbus door, the CAN map (gateways::to_text(CanopenMap)) when it has `can`.
//  - --json: {"schema":"pbvbus.gateway.map/1","gateways":[{"name","served","modbus": the
//    ModbusMap's JSON | null,"can": the CAN map as text | null}]}.
//  - --csv: the Modbus map's CSV alone (one header line, then rows) so that it imports as is;
//    it needs exactly one gateway with a Modbus door, or --gateway NAME to choose one.
//  - Exit codes: 0 printed, 2 bad usage, a bad scenario, no (such) gateway, 1 the Simulation
//    could not be built.
#include <iostream>
#include <memory>
#include <optional>
#include <string>

#include "pbvbus/gateways/modbus_map.hpp"
#include "pbvbus/tools/commands.hpp"
#include "pbvbus/simulation/gateway_node.hpp"
#include "pbvbus/reports/json_text.hpp"
#include "pbvbus/scenario/scenario.hpp"
#include "pbvbus/simulation/simulation.hpp"

namespace pbvbus::tools {

namespace {

constexpr const char* kGatewayUsage =
    "usage: pbvbus gateway map SCENARIO [--json | --csv] [--gateway NAME]\n"
    "\n"
    "Prints the register map of each gateway of SCENARIO (Modbus units, tables, addresses,\n"
    "word order, status block) and its CAN node/PDO map. Nothing is run or opened.\n"
    "\n"
    "options:\n"
    "  --json            the maps as JSON (schema pbvbus.gateway.map/1)\n"
    "  --csv             the Modbus map as CSV (one gateway: the only one, or --gateway)\n"
    "  --gateway NAME    only this gateway\n"
    "  -h, --help        this text\n";

}  // namespace

int cmd_gateway(const Args& args, std::ostream& out, std::ostream& err) {
  auto usage_error = [&](const std::string& msg) {
    err << "pbvbus gateway: " << msg << "\nTry 'pbvbus gateway --help'.\n";
    return 2;
  };
  if (args.empty()) return usage_error("missing subcommand (map)");
  if (args[0] == "-h" || args[0] == "--help") {
    out << kGatewayUsage;
    return 0;
  }
  if (args[0] != "map") return usage_error("unknown subcommand '" + args[0] + "' (expected map)");
  std::optional<std::string> scenario, only;
  bool json = false, csv = false;
  for (std::size_t i = 1; i < args.size(); ++i) {
    const std::string& a = args[i];
    if (a == "-h" || a == "--help") {
      out << kGatewayUsage;
      return 0;
    } else if (a == "--json") {
      json = true;
    } else if (a == "--csv") {
      csv = true;
    } else if (a == "--gateway") {
      if (i + 1 >= args.size()) return usage_error("--gateway needs a name");
      only = args[++i];
    } else if (a.size() > 1 && a[0] == '-') {
      return usage_error("unknown option '" + a + "'");
    } else if (!scenario) {
      scenario = a;
    } else {
      return usage_error("more than one scenario given ('" + *scenario + "' and '" + a + "')");
    }
  }
  if (!scenario) return usage_error("missing SCENARIO");
  if (json && csv) return usage_error("--json and --csv exclude each other");

  const LoadResult loaded = load_scenario_file(*scenario);
  if (!loaded.ok()) {
    for (const auto& d : loaded.errors) err << d.str() << "\n";
    return 2;
  }
  const ScenarioPlan& plan = *loaded.plan;
  if (plan.gateways.empty()) {
    err << "pbvbus gateway: " << plan.file << " has no gateway\n";
    return 2;
  }
  if (only) {
    bool found = false;
    for (const auto& g : plan.gateways) found |= g.name == *only;
    if (!found) {
      err << "pbvbus gateway: " << plan.file << " has no gateway \"" << *only << "\"\n";
      return 2;
    }
  }
  std::unique_ptr<Simulation> sim;
  try {
    sim = std::make_unique<Simulation>(plan);
    sim->start();
  } catch (const std::exception& e) {
    err << "pbvbus gateway: " << e.what() << "\n";
    return 1;
  }
  std::vector<const GatewayNode*> nodes;
  for (std::size_t i = 0; i < sim->gateway_count(); ++i)
    if (!only || sim->gateway(i).plan().name == *only) nodes.push_back(&sim->gateway(i));

  if (csv) {
    std::vector<const GatewayNode*> modbus;
    for (const GatewayNode* n : nodes)
      if (n->has_modbus()) modbus.push_back(n);
    if (modbus.size() != 1) {
      err << "pbvbus gateway: --csv prints one gateway's Modbus map: "
          << (modbus.empty() ? "no gateway has a Modbus door" : "choose one with --gateway NAME")
          << "\n";
      return 2;
    }
    out << modbus[0]->modbus_map().to_csv();
    return 0;
  }
  if (json) {
    out << "{\"schema\":\"pbvbus.gateway.map/1\",\"gateways\":[";
    for (std::size_t i = 0; i < nodes.size(); ++i) {
      const GatewayNode& n = *nodes[i];
      out << (i ? "," : "") << "{\"name\":" << json_quote(n.plan().name)
          << ",\"served\":" << json_quote(n.plan().served) << ",\"modbus\":"
          << (n.has_modbus() ? n.modbus_map().to_json() : std::string("null")) << ",\"can\":"
          << (n.plan().can ? json_quote(n.can_map_text()) : std::string("null")) << "}";
    }
    out << "]}\n";
    return 0;
  }
  for (std::size_t i = 0; i < nodes.size(); ++i) {
    const GatewayNode& n = *nodes[i];
    if (i != 0) out << "\n";
    out << "gateway " << n.plan().name << " (" << n.plan().served << ")\n";
    if (n.has_modbus()) out << "\nModbus\n" << n.modbus_map().to_text();
    if (n.plan().can) out << "\nCAN\n" << n.can_map_text();
  }
  return 0;
}

}  // namespace pbvbus::tools
