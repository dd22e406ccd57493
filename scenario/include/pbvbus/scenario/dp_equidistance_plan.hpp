#pragma once
// Equidistance of a dp_master in scenarios (`equidistant_cycle`, docs/dp-equidistance.md):
// plan_dp() calls plan_dp_equidistance() after the lines' bus parameters are derived. For each
// dp_master with `equidistant_cycle` it sets dp::MasterParams::equidistant_cycle (T_DP) and
// refuses, at the field, a T_DP that is
//  - not a positive duration;
//  - shorter than the planned DP cycle + a margin: per slave of the master a Data_Exchange at
//    max TSDR (11·request + max TSDR + 11·response + TID1), a Global_Control (11·13 + TID2),
//    one unanswered GAP poll (11·6 + TSL + TID1) and the token to itself (11·3 + TID1); the
//    margin is one repeat of the longest Data_Exchange request (11·request + TSL), so that a
//    single retry per cycle does not overrun;
//  - shorter than the longest Min_Slave_Interval of its slaves (the slave would sit every
//    other pass out);
//  - longer than a line's TTR given in `bus_params` minus the planned cycle (the pass would be
//    cut by the token hold time). Unless `bus_params` gives TTR, the line's derived TTR is
//    raised by T_DP: the token then comes back after one equidistant cycle with the pass's
//    hold time intact.

#include <vector>

#include "pbvbus/scenario/dp_plan.hpp"

namespace pbvbus::tools {

struct ScenarioPlan;
struct Diagnostic;

/// Octets on the wire of a DP request / response with `n` data octets (SD1 for a request
/// without data, SD3 for exactly 8, else SD2; a response without data is the short
/// acknowledgement E5), as the planners count them (11 bit times per octet).
inline std::uint64_t dp_request_octets(std::uint64_t n) { return n == 0 ? 6 : n == 8 ? 14 : 9 + n; }
inline std::uint64_t dp_response_octets(std::uint64_t n) { return n == 0 ? 1 : dp_request_octets(n); }

/// The planned DP cycle of master `mp` in bit times (see the header comment), without margin.
std::uint64_t dp_planned_cycle_bits(const ScenarioPlan& plan, const DpMasterPlan& mp);

void plan_dp_equidistance(ScenarioPlan& plan, const DpLocator& locate,
                          std::vector<Diagnostic>& errors);

}  // namespace pbvbus::tools
