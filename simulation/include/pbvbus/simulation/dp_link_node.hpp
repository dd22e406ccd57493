#pragma once
// A scenario's IM 157 link at run time (docs/dp-link.md; scenario dp_link_plan.hpp): the
// devices::DpLink of a y_link / dp_pa_link entry. Its RedundantSystemNode owns it as one of the
// system's switched stations (station(k) is the link's upper side, so the switched-I/O faults,
// the switchover measurement and the report treat it like any switched station); the
// Simulation attaches the coupler's master to the lower line after the line's planned stations
// (so the planned cable positions, and the capture probes placed by them, stay as planned).
//
// Decisions:
// - Upper bus parameters: the system's line A parameters (as for switched stations); lower:
//   the lower line's effective parameters, the coupler's master at the entry's `master`.
// - The lower stations are the dp_slave entries of the lower line, built by the Simulation like
//   any masterless dp_slave; the coupler's master holds their planned SlaveParams (what a
//   configuration tool gives a master, dp_plan.hpp).
#include <memory>

#include "pbvbus/dp_link/dp_link.hpp"
#include "pbvbus/scenario/scenario.hpp"

namespace pbvbus::tools {

/// Builds the link whose upper side is ScenarioPlan::switched[k] (SwitchedPlan::link >= 0).
/// Throws std::runtime_error if the model cannot be built (the loader checks the same).
std::unique_ptr<devices::DpLink> build_dp_link(const ScenarioPlan& plan, int k,
                                               const fdl::BusParams& upper);

}  // namespace pbvbus::tools
