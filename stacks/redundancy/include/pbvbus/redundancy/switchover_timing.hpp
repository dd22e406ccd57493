#pragma once
// Switchover-time planner for a redundant DP master system (design.md "Devices": timing
// planner; seeds-digest.md §2 "switchover time", §3.1; protocol-facts.md §B, §C.2, §G.5).
// A pure function of the bus parameters and the slaves' frame lengths: no I/O, no clock.
//
// The system: two lines A (0) and B (1) with the same bus parameters, one DP master class 1 on
// each (alone in its token ring), switched stations on both lines (the DP cycle runs on both
// channels, seeds §2), one-sided slaves on either line. Every term is derived from what the
// simulated stacks really do (fdl::ActiveStation, dp::Master), not from the Siemens formula,
// which is not public. docs/switchover-timing.md has the derivation and a worked example.
//
// Frame lengths (octets; one octet = 11 bit times on the wire), §B.1 as fdl::encode() picks them,
// n = octets after FC (SAP octets + DU):
//   n = 0 → SD1, 6;   n = 8 → SD3, 14;   otherwise → SD2, 9 + n.   Token SD4 3, SC 1.
//   An SRD reply with n = 0 is an SC (1 octet).
//   Data_Exchange uses the default SAP (no SAP octets): request n = outputs, reply n = inputs.
//   Slave_Diag: request DSAP 60/SSAP 62 and no DU (n = 2, SD2 11 octets); reply n = 2 + diag.
//   Global_Control: SDN broadcast DSAP 58/SSAP 62, DU 2 (n = 4, SD2 13 octets).
//   Pure PrmCmd Set_Prm: DSAP 61/SSAP 62, DU dp::kPrmLenPureCmd = 18 (7 header + 3 DPV1_Status
//   + 8 PrmCmd block): n = 20, SD2 29 octets; the slave answers SC.
//
// Idle times the master really keeps (fdl/src/active_station.cpp):
//   - TID1 after a received reply, SC or token before its next frame (also after a token it
//     passed to itself: the pass is its own token receipt);
//   - TID2 after its own SDN (Global_Control);
//   - none after a slot-time expiry: a repeat, the next request after a NoResponse, and the
//     token after an unanswered GAP poll go out the instant TSL expires.
//   The slave's reply starts after its TSDR; we plan with the largest one the slave may use,
//   max TSDR (PlannedSlave::max_tsdr_bits, bounded by the bus max TSDR as
//   fdl::PassiveStation::response_delay() bounds it).
//
// Terms (bit times, b = 11 bits per octet; TSDR_s = the slave's planned TSDR):
//   DX(s)    = b·req(out_s) + TSDR_s + b·reply(in_s) + TID1            Data_Exchange cycle
//   GC       = b·13 + TID2                                             Global_Control SDN
//   TOKEN    = b·3 + TID1                                              token pass to itself
//   GAP      = b·6 + max(TSL, TSDR_max + b·6 + TID1)                   one GAP poll (FDL Status,
//              SD1); unanswered: the token follows at TSL expiry; answered by a slave that
//              sits in the GAP: reply SD1 and TID1. The larger of the two.
//   DIAG     = max_s (b·11 + TSDR_s + b·reply(2 + diag_s) + TID1)      one Slave_Diag after DH
//   RETRY    = max_s (b·req(out_s)) + TSL                              one repeat
//   T_TR(L)  = Σ_{s on L} DX(s) + GC + TOKEN + GAP + DIAG + RETRY
//   (A line without slaves: no DIAG and no RETRY.)
//   recognition(L) = T_TR(L) + (1 + max_retry)·(max_s b·req(out_s) + TSL)
//     the fault may come just after the station's poll: the next poll starts at most T_TR(L)
//     later; the first attempt and max_retry repeats each end TSL after the request, and the
//     NoResponse (StationFailure) is reported at the last slot expiry. 0 for a line without
//     slaves (nothing to recognise).
//   PRMCMD(s) = b·29 + TSDR_s + b·1 + TID1                             pure PrmCmd cycle
//   T_DP_UM(s, to B) = T_TR(B) + PRMCMD(s) + T_TR(B)
//   T_DP_UM_system(to B) = T_TR(B) + Σ_{switched s} PRMCMD(s) + T_TR(B)
//   bound(s, active on L) = recognition(L) + T_DP_UM(s, to 1-L) + T_SLAVE_UM(s)
//   line-loss recognition(L) = T_TR(L) (definition: a short circuit is noticed at the master's
//     next transmission on L; we take the worst case of one full rotation). A master
//     failure/stop is known at once: 0.
//   system_bound(lost L) = T_TR(L) + T_DP_UM_system(to 1-L) + max_{switched s} T_SLAVE_UM(s)
//   system_bound_master_stop(lost L) = T_DP_UM_system(to 1-L) + max T_SLAVE_UM(s)
//   A station without T_SLAVE_UM counts 0 (and gets a note).
//
// Assumptions (also in notes where they apply): the bus TTR is not below T_TR (else the token
// hold time cuts passes and cycles grow); one fault at a time; no DP-V1 acyclic traffic; no
// start-up traffic of other slaves in the passes concerned; Min_Slave_Interval shorter than a
// pass; the PrmCmd cycle is added on top of T_TR(B) although it replaces the station's
// Data_Exchange in that pass (conservative by one DX cycle per station).

#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "pbvbus/bus/time.hpp"
#include "pbvbus/fdl/bus_params.hpp"

namespace pbvbus::redundancy {

/// Octets on the wire of a frame with an FC carrying `after_fc` octets (SAP octets + DU):
/// SD1 (6) for none, SD3 (14) for exactly 8, SD2 (9 + n) otherwise (§B.1, fdl::encode()).
constexpr std::int64_t fc_frame_octets(std::size_t after_fc) {
  return after_fc == 0 ? 6 : after_fc == 8 ? 14 : 9 + static_cast<std::int64_t>(after_fc);
}
/// Octets of an SRD reply carrying `after_fc` octets: an SC (1) when there is nothing.
constexpr std::int64_t reply_frame_octets(std::size_t after_fc) {
  return after_fc == 0 ? 1 : fc_frame_octets(after_fc);
}
inline constexpr std::int64_t kTokenOctets = 3;
inline constexpr std::int64_t kFdlStatusOctets = 6;  ///< SD1 request and SD1 reply
inline constexpr std::size_t kSapOctets = 2;         ///< DSAP + SSAP
inline constexpr std::size_t kGlobalControlDu = 2;
inline constexpr std::size_t kMaxDpData = 244;  ///< DP payload with SAPs (§B.1)

/// One slave as the planner sees it.
struct PlannedSlave {
  std::uint8_t address = 0;
  std::string name;
  std::size_t in_len = 0;           ///< Data_Exchange input octets (slave → master)
  std::size_t out_len = 0;          ///< Data_Exchange output octets (master → slave)
  std::uint32_t max_tsdr_bits = 0;  ///< the slave's max TSDR (GSD MaxTsdr_<baud>); 0 = bus max TSDR
  std::size_t max_diag_len = 6;     ///< the longest Slave_Diag DU it may send (6..244)
  bool switched = false;            ///< on both lines (a switched station)
  int line = 0;                     ///< 0 = A, 1 = B; ignored when switched
  std::optional<bus::Ticks> t_slave_um;  ///< the station's own switchover time (switched only)
};

/// A message cycle split into its parts (bit times).
struct CycleBits {
  std::int64_t request = 0;   ///< 11 · request octets
  std::int64_t tsdr = 0;      ///< responder delay, or TSL for an unanswered poll
  std::int64_t response = 0;  ///< 11 · reply octets (0 when none)
  std::int64_t idle = 0;      ///< TID1/TID2 after it, 0 when the next frame follows TSL expiry
  std::int64_t total() const { return request + tsdr + response + idle; }
};

struct SlaveCycle {
  std::uint8_t address = 0;
  std::string name;
  CycleBits dx;  ///< its Data_Exchange cycle
};

/// One line's terms. Bit times are exact; ticks = bits · ticks per bit.
struct LinePlan {
  std::vector<SlaveCycle> slaves;  ///< the slaves this line's master polls, in input order
  std::int64_t dx_bits = 0;        ///< Σ DX(s)
  CycleBits gc;                    ///< Global_Control SDN + TID2
  CycleBits token;                 ///< token pass to itself + TID1
  CycleBits gap;                   ///< one GAP poll (the worse of unanswered / answered)
  CycleBits diag;                  ///< one Slave_Diag read after DH (largest)
  CycleBits retry;                 ///< one repeat: largest request + TSL
  std::int64_t t_tr_bits = 0;
  CycleBits failed_attempt;  ///< one unanswered attempt: largest request + TSL
  std::int64_t recognition_bits = 0;
  std::int64_t line_loss_recognition_bits = 0;
  bus::Ticks t_tr = 0;
  bus::Ticks recognition = 0;
  bus::Ticks line_loss_recognition = 0;
};

/// A switched station's station-level switchover, for each line its active channel may be on.
struct StationBound {
  std::uint8_t address = 0;
  std::string name;
  CycleBits prm_cmd[2];  ///< the PrmCmd cycle on line i (same on both lines)
  /// Index = the line of the failing active channel; the new one is on the other line.
  std::int64_t t_dp_um_bits[2] = {0, 0};
  bus::Ticks recognition[2] = {0, 0};
  bus::Ticks t_dp_um[2] = {0, 0};
  bus::Ticks t_slave_um = 0;  ///< 0 when not given (see notes)
  bool t_slave_um_given = false;
  bus::Ticks bound[2] = {0, 0};
  bus::Ticks worst() const { return bound[0] > bound[1] ? bound[0] : bound[1]; }
};

struct SwitchoverPlan {
  bus::Baud baud = bus::Baud::k1_5M;
  std::int64_t tid1_bits = 0, tid2_bits = 0, tsl_bits = 0;
  LinePlan line[2];
  std::vector<StationBound> stations;  ///< switched stations, in input order
  /// Index = the line that is lost; the switched stations go to the other one.
  std::int64_t system_t_dp_um_bits[2] = {0, 0};
  bus::Ticks system_t_dp_um[2] = {0, 0};
  bus::Ticks max_t_slave_um = 0;  ///< the slowest switched station's T_SLAVE_UM (0: none given)
  bus::Ticks system_bound[2] = {0, 0};              ///< line lost (short circuit)
  bus::Ticks system_bound_master_stop[2] = {0, 0};  ///< master failure/stop: recognised at once
  std::vector<std::string> notes;
};

/// Plans T_TR, recognition, T_DP_UM and the bounds. Throws std::invalid_argument for a slave
/// with more than 244 input, output or diagnosis octets, or a one-sided slave whose line is
/// neither 0 nor 1.
SwitchoverPlan plan_switchover(const fdl::BusParams& bp, const std::vector<PlannedSlave>& slaves);

}  // namespace pbvbus::redundancy
