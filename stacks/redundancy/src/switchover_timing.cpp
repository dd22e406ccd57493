// Switchover-time planner: the arithmetic of switchover_timing.hpp (derivation in
// docs/switchover-timing.md).
#include "pbvbus/redundancy/switchover_timing.hpp"

#include <algorithm>
#include <stdexcept>

#include "pbvbus/dp/prm.hpp"

namespace pbvbus::redundancy {

namespace {

constexpr std::int64_t kBits = bus::kBitsPerChar;

std::string who(const PlannedSlave& s) {
  std::string w = "slave " + std::to_string(s.address);
  if (!s.name.empty()) w += " (" + s.name + ")";
  return w;
}

struct Ctx {
  const fdl::BusParams& bp;
  std::int64_t tid1, tid2, tsl;
  std::vector<std::string>& notes;

  /// The TSDR we plan with: the slave's max TSDR within [min TSDR, bus max TSDR], as
  /// fdl::PassiveStation::response_delay() bounds it.
  std::int64_t tsdr(const PlannedSlave& s) const {
    std::uint32_t t = s.max_tsdr_bits == 0 ? bp.max_tsdr : std::min(s.max_tsdr_bits, bp.max_tsdr);
    t = std::max(t, bp.min_tsdr);
    return t;
  }
  std::int64_t dx_request(const PlannedSlave& s) const {
    return kBits * fc_frame_octets(s.out_len);
  }
  CycleBits dx(const PlannedSlave& s) const {
    return {dx_request(s), tsdr(s), kBits * reply_frame_octets(s.in_len), tid1};
  }
  CycleBits diag(const PlannedSlave& s) const {
    return {kBits * fc_frame_octets(kSapOctets), tsdr(s),
            kBits * reply_frame_octets(kSapOctets + s.max_diag_len), tid1};
  }
  CycleBits prm_cmd(const PlannedSlave& s) const {
    return {kBits * fc_frame_octets(kSapOctets + dp::kPrmLenPureCmd), tsdr(s),
            kBits * reply_frame_octets(0), tid1};
  }
  bus::Ticks ticks(std::int64_t bits) const { return bp.ticks(bits); }
};

void plan_line(const Ctx& c, const std::vector<const PlannedSlave*>& on_line, int index,
               LinePlan& lp) {
  const char* name = index == 0 ? "A" : "B";
  std::int64_t max_tsdr = 0;
  std::int64_t max_req = 0;
  for (const PlannedSlave* s : on_line) {
    SlaveCycle sc;
    sc.address = s->address;
    sc.name = s->name;
    sc.dx = c.dx(*s);
    lp.dx_bits += sc.dx.total();
    lp.slaves.push_back(std::move(sc));
    max_tsdr = std::max(max_tsdr, c.tsdr(*s));
    max_req = std::max(max_req, c.dx_request(*s));
    const CycleBits d = c.diag(*s);
    if (d.total() > lp.diag.total()) lp.diag = d;
  }
  lp.gc = {kBits * fc_frame_octets(kSapOctets + kGlobalControlDu), 0, 0, c.tid2};
  lp.token = {kBits * kTokenOctets, 0, 0, c.tid1};
  // GAP poll: unanswered (the token follows at TSL expiry), or answered by a slave in the GAP.
  const CycleBits unanswered{kBits * kFdlStatusOctets, c.tsl, 0, 0};
  const CycleBits answered{kBits * kFdlStatusOctets, max_tsdr, kBits * kFdlStatusOctets, c.tid1};
  lp.gap = (!on_line.empty() && answered.total() > unanswered.total()) ? answered : unanswered;
  if (!on_line.empty()) {
    lp.retry = {max_req, c.tsl, 0, 0};
    lp.failed_attempt = lp.retry;
  }
  lp.t_tr_bits = lp.dx_bits + lp.gc.total() + lp.token.total() + lp.gap.total() + lp.diag.total() +
                 lp.retry.total();
  lp.recognition_bits = on_line.empty() ? 0
                                        : lp.t_tr_bits + (1 + std::int64_t{c.bp.max_retry}) *
                                                             lp.failed_attempt.total();
  lp.line_loss_recognition_bits = lp.t_tr_bits;
  lp.t_tr = c.ticks(lp.t_tr_bits);
  lp.recognition = c.ticks(lp.recognition_bits);
  lp.line_loss_recognition = c.ticks(lp.line_loss_recognition_bits);
  if (on_line.empty())
    c.notes.push_back(std::string("line ") + name +
                      ": no slaves; T_TR is Global_Control + token + GAP poll only, and there is "
                      "no station failure to recognise (recognition 0)");
  if (std::int64_t{c.bp.ttr} < lp.t_tr_bits)
    c.notes.push_back(std::string("line ") + name + ": the bus TTR " + std::to_string(c.bp.ttr) +
                      " t_bit is below the planned T_TR " + std::to_string(lp.t_tr_bits) +
                      " t_bit: the token hold time cuts passes and DP cycles can exceed the plan");
}

}  // namespace

SwitchoverPlan plan_switchover(const fdl::BusParams& bp, const std::vector<PlannedSlave>& slaves) {
  SwitchoverPlan plan;
  plan.baud = bp.baud;
  plan.tid1_bits = bp.tid1();
  plan.tid2_bits = bp.tid2();
  plan.tsl_bits = bp.tsl;
  const Ctx c{bp, plan.tid1_bits, plan.tid2_bits, plan.tsl_bits, plan.notes};

  std::vector<const PlannedSlave*> on_line[2];
  std::vector<const PlannedSlave*> switched;
  for (const PlannedSlave& s : slaves) {
    if (s.in_len > kMaxDpData || s.out_len > kMaxDpData || s.max_diag_len > kMaxDpData)
      throw std::invalid_argument(who(s) + ": more than 244 input, output or diagnosis octets");
    if (!s.switched && s.line != 0 && s.line != 1)
      throw std::invalid_argument(who(s) + ": line " + std::to_string(s.line) +
                                  " is neither 0 (A) nor 1 (B)");
    if (s.max_tsdr_bits > bp.max_tsdr)
      plan.notes.push_back(who(s) + ": max TSDR " + std::to_string(s.max_tsdr_bits) +
                           " t_bit exceeds the bus max TSDR " + std::to_string(bp.max_tsdr) +
                           " t_bit; planned with the bus max TSDR (the slave must answer "
                           "within it, else the master sees no response)");
    if (s.max_diag_len < 6)
      plan.notes.push_back(who(s) + ": max diagnosis length " + std::to_string(s.max_diag_len) +
                           " is below the 6 standard octets; planned as given");
    if (s.switched) {
      on_line[0].push_back(&s);
      on_line[1].push_back(&s);
      switched.push_back(&s);
    } else {
      on_line[s.line].push_back(&s);
      if (s.t_slave_um) plan.notes.push_back(who(s) + ": one-sided; its T_SLAVE_UM is not used");
    }
  }
  for (int i = 0; i < 2; ++i) {
    std::vector<std::uint8_t> seen;
    for (const PlannedSlave* s : on_line[i]) {
      if (std::find(seen.begin(), seen.end(), s->address) != seen.end())
        plan.notes.push_back(std::string("line ") + (i == 0 ? "A" : "B") + ": address " +
                             std::to_string(s->address) + " appears twice");
      seen.push_back(s->address);
    }
    plan_line(c, on_line[i], i, plan.line[i]);
  }

  std::int64_t prm_sum[2] = {0, 0};
  for (const PlannedSlave* s : switched) {
    StationBound sb;
    sb.address = s->address;
    sb.name = s->name;
    if (s->t_slave_um) {
      sb.t_slave_um = *s->t_slave_um;
      sb.t_slave_um_given = true;
    } else {
      plan.notes.push_back(who(*s) +
                           ": no T_SLAVE_UM given; its bound leaves the station's own "
                           "switchover time out (counted as 0)");
    }
    plan.max_t_slave_um = std::max(plan.max_t_slave_um, sb.t_slave_um);
    for (int to = 0; to < 2; ++to) {
      sb.prm_cmd[to] = c.prm_cmd(*s);
      prm_sum[to] += sb.prm_cmd[to].total();
    }
    for (int from = 0; from < 2; ++from) {
      const int to = 1 - from;
      sb.t_dp_um_bits[from] = 2 * plan.line[to].t_tr_bits + sb.prm_cmd[to].total();
      sb.recognition[from] = plan.line[from].recognition;
      sb.t_dp_um[from] = c.ticks(sb.t_dp_um_bits[from]);
      sb.bound[from] = sb.recognition[from] + sb.t_dp_um[from] + sb.t_slave_um;
    }
    plan.stations.push_back(std::move(sb));
  }
  if (switched.empty())
    plan.notes.push_back("no switched stations: the system-level terms cover no station");
  for (int lost = 0; lost < 2; ++lost) {
    const int to = 1 - lost;
    plan.system_t_dp_um_bits[lost] = 2 * plan.line[to].t_tr_bits + prm_sum[to];
    plan.system_t_dp_um[lost] = c.ticks(plan.system_t_dp_um_bits[lost]);
    plan.system_bound_master_stop[lost] = plan.system_t_dp_um[lost] + plan.max_t_slave_um;
    plan.system_bound[lost] =
        plan.line[lost].line_loss_recognition + plan.system_bound_master_stop[lost];
  }
  return plan;
}

}  // namespace pbvbus::redundancy
