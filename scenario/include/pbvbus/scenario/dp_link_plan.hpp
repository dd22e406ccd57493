#pragma once
// IM 157 links in scenarios (docs/dp-link.md): `y_link` and `dp_pa_link` entries. plan_dp()
// calls plan_dp_links() after the switched stations and before it derives the lines' bus
// parameters. A link is planned as a switched station of its redundant_master_system
// (SwitchedPlan with `link` set, one DpSlavePlan per upper line, built from the generated link
// GSD, devices::link_gsd_text) whose modules are the lower stations: the dp_slave entries on
// `lower_line` (without a `master` of their own), in file order. The H CPUs and the redundant
// master system therefore see the lower stations as data of a switched station.
//
// Refusals (FILE:LINE:COLUMN, at the field concerned):
// - the system's upper lines above 1.5 Mbit/s (D5; 001 L8128: a CP 443-5 Extended with a
//   DP/PA link or Y-link only up to 1.5 MBd; decision: refused for every master, the
//   integrated interface included, as the manual gives no other limit);
// - the lower line's baud rate (devices::check_lower_baud: PA 31.25 kbit/s only, Y-link
//   187.5 kbit/s .. 1.5 Mbit/s), a lower line that is a redundant system's line, an MPI line, or
//   one that carries a dp_master or another link;
// - more than 30 PA devices, or more than 10 with `ex: true` (D5: PA <= 10 nodes / 100 mA Ex,
//   <= 30 nodes); `ex` on a y_link; more than 64 lower stations; more than 244 octets of inputs
//   or outputs in all (the link's frames are the lower stations' frames);
// - a lower dp_slave naming a master; the coupler's master address used by a lower station or
//   not below the lower line's HSA; no lower station at all.

#include <cstdint>
#include <functional>
#include <vector>

#include "pbvbus/bus/time.hpp"
#include "pbvbus/dp_link/link_gsd.hpp"
#include "pbvbus/scenario/dp_plan.hpp"

namespace pbvbus::tools {

struct DpLinkPlan {
  devices::DpLinkKind kind = devices::DpLinkKind::YLink;
  int source = 0;                   ///< index into Scenario.y_link / dp_pa_link
  const char* repeated = "y_link";  ///< the Scenario field `source` indexes
  int system = -1;                  ///< index into ScenarioPlan::redundant_systems
  int switched = -1;                ///< index into ScenarioPlan::switched (the upper side)
  std::uint8_t address = 0;
  int lower_line = -1;              ///< index into ScenarioPlan::lines
  std::uint8_t master = 1;          ///< the coupler's master on the lower line
  std::vector<int> lower;           ///< indices into ScenarioPlan::dp_slaves, file order
  bus::Ticks switchover = 100 * bus::kTicksPerMs;  ///< the coupler's T_SLAVE_UM
  bool ex = false;
};

/// Plans one upper interface (side 0 = line A, 1 = line B) of a link from the synthesised
/// dp_slave entry `d` and the link's GSD `g`; returns its index in ScenarioPlan::dp_slaves or -1
/// (errors reported at Scenario.`rep`[i]).
using LinkSidePlanner = std::function<int(const scenario::DpSlave& d, const devices::GsdFile& g,
                                          const char* rep, int i, int switched, int side)>;

void plan_dp_links(ScenarioPlan& plan, const DpLocator& locate, std::vector<Diagnostic>& errors,
                   const LinkSidePlanner& plan_side);

/// Whether the line (index into ScenarioPlan::lines) is some link's lower line; the link or -1.
int link_of_lower_line(const ScenarioPlan& plan, int line);

}  // namespace pbvbus::tools
