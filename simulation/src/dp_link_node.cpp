// A scenario's IM 157 link at run time (dp_link_node.hpp).
#include "pbvbus/simulation/dp_link_node.hpp"

#include <stdexcept>

namespace pbvbus::tools {

std::unique_ptr<devices::DpLink> build_dp_link(const ScenarioPlan& plan, int k,
                                               const fdl::BusParams& upper) {
  const SwitchedPlan& swp = plan.switched.at(static_cast<std::size_t>(k));
  const DpLinkPlan& lp = plan.dp_links.at(static_cast<std::size_t>(swp.link));
  devices::DpLinkOptions o;
  o.kind = lp.kind;
  o.address = lp.address;
  o.upper_bus_params = upper;
  o.lower_bus_params = plan.lines.at(static_cast<std::size_t>(lp.lower_line)).params;
  o.lower_master_address = lp.master;
  o.switchover = lp.switchover;
  std::vector<dp::SlaveParams> lower;
  for (int s : lp.lower) lower.push_back(plan.dp_slaves.at(static_cast<std::size_t>(s)).params);
  auto b = devices::DpLink::build(o, std::move(lower));
  if (!b.ok())
    throw std::runtime_error(std::string(devices::to_string(lp.kind)) + " " +
                             std::to_string(lp.address) + ": " +
                             (b.errors.empty() ? std::string("cannot be built") : b.errors.front()));
  return std::move(b.link);
}

}  // namespace pbvbus::tools
