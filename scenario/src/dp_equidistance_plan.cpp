// Equidistance of a dp_master in scenarios (dp_equidistance_plan.hpp; docs/dp-equidistance.md).
#include "pbvbus/scenario/dp_equidistance_plan.hpp"

#include <algorithm>
#include <string>

#include "pbvbus/scenario/scenario.hpp"

namespace pbvbus::tools {

namespace {

std::string us(bus::Ticks t) {
  // Microseconds with up to three decimals (1 bit at 12 Mbit/s is 0.083 µs).
  const std::int64_t ns = t * 1000 / bus::kTicksPerUs;
  std::string s = std::to_string(ns / 1000);
  if (ns % 1000 != 0) {
    std::string frac = std::to_string(1000 + ns % 1000).substr(1);
    while (!frac.empty() && frac.back() == '0') frac.pop_back();
    s += "." + frac;
  }
  return s + " us";
}

}  // namespace

std::uint64_t dp_planned_cycle_bits(const ScenarioPlan& plan, const DpMasterPlan& mp) {
  if (mp.line < 0) return 0;
  const fdl::BusParams& p = plan.lines[static_cast<std::size_t>(mp.line)].params;
  std::uint64_t cycle = 0;
  for (int si : mp.slaves) {
    const DpSlavePlan& s = plan.dp_slaves[static_cast<std::size_t>(si)];
    cycle += 11 * dp_request_octets(s.outputs) + p.max_tsdr + 11 * dp_response_octets(s.inputs) + p.tid1();
  }
  cycle += 11 * 13 + p.tid2();          // Global_Control (SD2, SAPs 58/62, 2 octets), then TID2
  cycle += 11 * 6 + p.tsl + p.tid1();   // one unanswered GAP poll
  cycle += 11 * 3 + p.tid1();           // the token to itself
  return cycle;
}

void plan_dp_equidistance(ScenarioPlan& plan, const DpLocator& locate,
                          std::vector<Diagnostic>& errors) {
  for (auto& mp : plan.dp_masters) {
    const auto& m = plan.proto.dp_master(mp.source);
    if (m.equidistant_cycle().empty()) continue;
    auto err = [&](std::string msg) {
      auto [l, c] = locate("dp_master", mp.source, "equidistant_cycle", -1);
      errors.push_back({plan.file, l, c, std::move(msg)});
    };
    const std::string who = "dp_master " + std::to_string(mp.params.address) + ": equidistant_cycle \"" +
                            m.equidistant_cycle() + "\"";
    const auto t = bus::parse_duration(m.equidistant_cycle());
    if (!t || *t <= 0) {
      err(who + " is not a positive duration (e.g. \"2ms\")");
      continue;
    }
    if (mp.line < 0) continue;  // the unknown line is reported elsewhere
    PlanLine& line = plan.lines[static_cast<std::size_t>(mp.line)];
    const bus::Ticks bit = bus::ticks_per_bit(line.baud);
    const std::uint64_t cycle = dp_planned_cycle_bits(plan, mp);
    std::uint64_t longest = 0;
    bus::Ticks min_interval = 0;
    int min_interval_slave = -1;
    for (int si : mp.slaves) {
      const DpSlavePlan& s = plan.dp_slaves[static_cast<std::size_t>(si)];
      longest = std::max<std::uint64_t>(longest, 11 * dp_request_octets(s.outputs));
      const bus::Ticks iv = static_cast<bus::Ticks>(s.params.min_slave_interval) * 100 * bus::kTicksPerUs;
      if (iv > min_interval) {
        min_interval = iv;
        min_interval_slave = s.address;
      }
    }
    const std::uint64_t margin = longest + line.params.tsl;
    const std::uint64_t need = cycle + margin;
    const std::int64_t tdp_bits = *t / bit;
    const std::string tdp = who + " (" + std::to_string(tdp_bits) + " bit times at line \"" + line.name + "\")";
    if (static_cast<std::uint64_t>(tdp_bits) < need) {
      err(tdp + " is shorter than the planned DP cycle of " + std::to_string(cycle) + " bit times (" +
          std::to_string(mp.slaves.size()) + (mp.slaves.size() == 1 ? " slave" : " slaves") +
          ", Global_Control, GAP poll, token) + a margin of " +
          std::to_string(margin) + " (one repeat) = " + std::to_string(need) + " bit times (" +
          us(static_cast<bus::Ticks>(need) * bit) + ")");
      continue;
    }
    if (*t < min_interval) {
      err(tdp + " is shorter than the Min_Slave_Interval of dp_slave " + std::to_string(min_interval_slave) +
          " (" + us(min_interval) + ")");
      continue;
    }
    const auto& given = plan.proto.line(mp.line).bus_params();
    if (given.has_ttr()) {
      if (static_cast<std::uint64_t>(line.params.ttr) < static_cast<std::uint64_t>(tdp_bits) + cycle) {
        err(tdp + " + the planned DP cycle of " + std::to_string(cycle) + " bit times is more than the TTR " +
            std::to_string(line.params.ttr) + " given for the line: the pass would be cut by the token hold time");
        continue;
      }
    } else {
      line.params.ttr = static_cast<std::uint32_t>(std::clamp<std::uint64_t>(
          std::uint64_t{line.params.ttr} + static_cast<std::uint64_t>(tdp_bits),
          fdl::BusParams::kTtrMin, fdl::BusParams::kTtrMax));
    }
    mp.params.equidistant_cycle = *t;
  }
}

}  // namespace pbvbus::tools
