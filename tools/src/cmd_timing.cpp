// `pbvbus timing SCENARIO [--json]`: plans the DP rotation and switchover times of a scenario
// with redundancy::plan_switchover (switchover_timing.hpp; derivation in
// docs/switchover-timing.md). For every redundant_master_system: per line the target rotation
// time T_TR with its parts and the DP error-recognition time; per switched station T_DP_UM,
// T_SLAVE_UM (from the GSD, the scenario, or missing) and the bound for either failing line;
// the system-level switchover (a whole line lost: short circuit, master stop/failure); the
// planner's notes. For every dp_master outside a redundant system: its line's T_TR (its slaves
// planned as one-sided slaves of line A, the system terms left out). The planner's input comes
// from timing_plan.hpp. For every h_system: the update timing (docs/h-timing.md). For every
// quantum_hot_standby: the seed's scan-time model (quantum/scan_time.hpp, docs/quantum-hsby.md
// "Scan time in `pbvbus timing`"): the transfer area, the state RAM sent every scan beyond the
// CPU type's baseline in bytes, the rate, the HSBY cost, the standalone scan and the total.
// Exit 0 on success (also for a scenario without a DP master system), 2 for bad usage or a
// broken scenario (FILE:LINE:COLUMN: reason on stderr).
//
// JSON schema "pbvbus.timing/1" (stable: fields are only ever added; a change of meaning gets a
// new version). All figures are integers: bit times (`_bits`) of the line's baud rate, or
// nanoseconds (`_ns`, rounded down) of the same durations.
//
//   { "schema": "pbvbus.timing/1",
//     "scenario": { "name": str, "file": str },
//     "redundant_systems": [ {
//       "name": str,
//       "bus_params": BUS,          // line A's; the planner uses them for both lines
//       "lines": [ LINE, LINE ],    // [0] = line A, [1] = line B
//       "stations": [ {             // switched stations, in file order
//         "address": int, "model": str,
//         "t_slave_um_ns": int|null,             // the station's own switchover time
//         "t_slave_um_source": "gsd"|"scenario"|"missing",   // missing: counted as 0
//         "prm_cmd": CYCLE,                      // the pure PrmCmd Set_Prm cycle
//         "failing": [ {             // [0]: its active channel on line A fails, [1]: on line B
//           "line": str, "to": str,             // failing line, the line it switches to
//           "recognition_ns": int,              // DP error recognition on the failing line
//           "t_dp_um_bits": int, "t_dp_um_ns": int,   // T_TR(to) + PRMCMD + T_TR(to)
//           "bound_ns": int } ],                // recognition + T_DP_UM + T_SLAVE_UM
//         "worst_ns": int } ],                  // the larger bound
//       "system": [ {               // [0]: line A lost, [1]: line B lost
//         "lost": str, "to": str,
//         "recognition_ns": int,                // line loss noticed: one T_TR of the lost line
//         "t_dp_um_system_bits": int, "t_dp_um_system_ns": int,  // T_TR + Σ PRMCMD + T_TR
//         "max_t_slave_um_ns": int,             // the slowest switched station's (0: none)
//         "slowest_station": int|null,          // its address; null without any T_SLAVE_UM
//         "bound_short_circuit_ns": int,        // recognition + T_DP_UM_system + max T_SLAVE_UM
//         "bound_master_stop_ns": int } ],      // master stop/failure: recognised at once
//       "notes": [ str ] } ],                   // the planner's assumptions and warnings
//     "dp_masters": [ {             // dp_masters outside a redundant system, in file order
//       "address": int,
//       "bus_params": BUS,
//       "line": LINE,
//       "notes": [ str ] } ],
//     "h_systems": [ ... ],         // h_system entries (print_h_json below)
//     "reliability": {              // only with h_systems: their CPU pair as a 1oo2 system
//       "mtbf_1oo1_h": num, "dc": num, "mdt_h": num,  // the inputs (--mtbf-years, --dc, --mdt-hours)
//       "mtbf_1oo2_h": num, "factor": num,             // MTBF_1oo2 and MTBF_1oo2 / MTBF_1oo1
//       "availability_1oo1": num, "availability_1oo2": num },  // fractions
//     "quantum": [ {                // quantum_hot_standby entries, in file order
//       "name": str, "cpu": "x13"|"424 02"|"434 12" (also the 534 14), "iec": bool,
//       "logic_time_ns": int,                   // the standalone scan (logic_time)
//       "transfer": {
//         "mode": "12k"|"user_defined"|"transfer_all"|"iec",
//         "every_scan": REFS4,                  // references sent every scan
//         "additional": [ [ {"first": REF, "count": int} ] ],  // slices, one a scan
//         "non_transfer": {"first": REF, "count": int}|null,
//         "command_register": REF },
//       "model": {                  // quantum::estimate_scan (seed 003 pp. 33-35, 49-50)
//         "every_scan": REFS, "baseline": REFS (IEC-HSBY: 0, not subtracted),
//         "deltas": REFS, "bytes": REFS,        // every_scan − baseline; their bytes (rounded)
//         "total_bytes": int,
//         "rate_us_per_kb": int,                // µs per 1000 B (the seed's "ms/byte")
//         "rate_source": "cpu"|"scenario",      // scenario: transfer_rate_us_per_kb
//         "transfer_ns": int, "transfer_ms": int,   // bytes × rate; rounded to ms as the seed
//         "hsby_ns": int, "standalone_ns": int,
//         "total_ns": int,                      // hsby + standalone + transfer, exact
//         "total_ms": int },                    // the seed's sum of whole ms ("40 + 36 + 28")
//       "scan_time_ns": int,                    // the pair's scan time
//       "scan_time_source": "estimated"|"configured" } ] }
//
//   BUS   = { "baud": int (bit/s), "tsl","min_tsdr","max_tsdr","tqui","tset","ttr","max_retry",
//             "tid1","tid2": int (bit times except max_retry) }
//   LINE  = { "side": "A"|"B", "name": str, "master": int (its DP master's address),
//             "slaves": [ { "address": int, "model": str, "switched": bool,
//                           "dx": CYCLE } ],       // the Data_Exchange cycle, in input order
//             "dx_bits": int, "dx_ns": int,        // Σ Data_Exchange cycles
//             "global_control": CYCLE, "token": CYCLE, "gap": CYCLE,
//             "diag": CYCLE,                       // diagnosis reserve (zero without slaves)
//             "retry": CYCLE,                      // retry reserve (zero without slaves)
//             "t_tr_bits": int, "t_tr_ns": int,
//             "failed_attempt": CYCLE,             // one unanswered attempt: request + TSL
//             "recognition_bits": int, "recognition_ns": int }   // T_TR + (1 + max_retry) · that
//   REF   = a 6-digit Quantum reference, "400001"
//   REFS4 = { "coils", "inputs", "input_registers", "holding_registers": int }
//   REFS  = REFS4 plus "iec_hsby_registers": int for an IEC pair
//   CYCLE = { "request_bits": int, "tsdr_bits": int (responder delay, or TSL when unanswered),
//             "response_bits": int, "idle_bits": int, "bits": int (their sum), "ns": int }

#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <exception>
#include <optional>
#include <ostream>
#include <sstream>
#include <string>
#include <vector>

#include "pbvbus/redundancy/switchover_timing.hpp"
#include "pbvbus/tools/commands.hpp"
#include "pbvbus/reports/json_text.hpp"
#include "pbvbus/scenario/scenario.hpp"
#include "pbvbus/scenario/timing_plan.hpp"
#include "pbvbus/scenario/h_plan.hpp"
#include "pbvbus/scenario/quantum_plan.hpp"
#include "pbvbus/quantum/reference.hpp"
#include "timing_reliability.hpp"

namespace pbvbus::tools {

namespace {

using redundancy::CycleBits;
using redundancy::LinePlan;
using redundancy::SwitchoverPlan;

constexpr const char* kTimingUsage =
    "usage: pbvbus timing SCENARIO [--json] [--mtbf-years Y] [--dc F] [--mdt-hours H]\n"
    "\n"
    "Plans the DP rotation and switchover times of a scenario (docs/switchover-timing.md).\n"
    "For every redundant_master_system: per line the target rotation time T_TR with its parts\n"
    "(Data_Exchange cycles, Global_Control, token, GAP poll, diagnosis and retry reserves) and\n"
    "the DP error-recognition time; per switched station T_DP_UM, T_SLAVE_UM (from the GSD or\n"
    "the scenario) and the switchover bound for either failing line; the system switchover\n"
    "when a whole line is lost (short circuit, master stop or failure); the planner's notes.\n"
    "For every other dp_master: its line's T_TR. For every h_system: the update timing. For\n"
    "every quantum_hot_standby: the seed's scan-time model (docs/quantum-hsby.md).\n"
    "\n"
    "  --json    print the same as one JSON object (schema pbvbus.timing/1)\n"
    "For every h_system also its reliability as a 1oo2 system (docs/h-timing.md):\n"
    "  --help    this text\n"
    "\n"
    "Exit status: 0 success, 2 bad usage or a broken scenario (FILE:LINE:COLUMN: reason on\n"
    "stderr).\n";

/// What the command plans, with the names the output uses.
struct SystemTiming {
  const RedundancyPlan* rp = nullptr;
  SwitchoverPlan plan;
  std::string line_name[2];
  int master_address[2] = {0, 0};
  fdl::BusParams params;
};

struct MasterTiming {
  const DpMasterPlan* mp = nullptr;
  SwitchoverPlan plan;
  std::string line_name;
  fdl::BusParams params;
};

std::int64_t bits_ns(std::int64_t bits, bus::Baud baud) {
  return bus::ticks_to_ns(bus::bits_to_ticks(bits, baud));
}

std::string us_of_bits(std::int64_t bits, bus::Baud baud) {
  return format_us(bus::bits_to_ticks(bits, baud));
}

/// Milliseconds with three decimals, rounded down: "36.902 ms".
std::string ms(bus::Ticks t) {
  const std::int64_t us = bus::ticks_to_ns(t) / 1000;
  char buf[40];
  std::snprintf(buf, sizeof buf, "%lld.%03lld ms", static_cast<long long>(us / 1000),
                static_cast<long long>(us % 1000));
  return buf;
}

/// The switched station `address` of system `rp`, or nullptr.
const SwitchedPlan* switched_plan(const ScenarioPlan& plan, const RedundancyPlan& rp,
                                  std::uint8_t address) {
  for (int k : rp.switched) {
    const SwitchedPlan& s = plan.switched.at(static_cast<std::size_t>(k));
    if (s.address == address) return &s;
  }
  return nullptr;
}

const char* t_slave_um_source(const SwitchedPlan* s) {
  if (s == nullptr || !s->t_slave_um) return "missing";
  return s->t_slave_um_from_gsd ? "gsd" : "scenario";
}

/// The slowest switched station (largest given T_SLAVE_UM), or nullptr.
const redundancy::StationBound* slowest(const SwitchoverPlan& p) {
  const redundancy::StationBound* best = nullptr;
  for (const auto& s : p.stations)
    if (s.t_slave_um_given && (best == nullptr || s.t_slave_um > best->t_slave_um)) best = &s;
  return best;
}

bool is_switched(const SwitchoverPlan& p, std::uint8_t address) {
  return std::any_of(p.stations.begin(), p.stations.end(),
                     [&](const redundancy::StationBound& s) { return s.address == address; });
}

// --- text output -------------------------------------------------------------------------------

/// Columns padded to their widest cell; column 0 (and every column in `left`) left-aligned,
/// the others right-aligned.
class Table {
 public:
  explicit Table(std::vector<std::size_t> left = {}) : m_left(std::move(left)) {}
  void add(std::vector<std::string> row) { m_rows.push_back(std::move(row)); }
  void print(std::ostream& out, const std::string& indent) const {
    std::vector<std::size_t> w;
    for (const auto& r : m_rows)
      for (std::size_t c = 0; c < r.size(); ++c) {
        if (w.size() <= c) w.push_back(0);
        w[c] = std::max(w[c], r[c].size());
      }
    for (const auto& r : m_rows) {
      std::string line = indent;
      for (std::size_t c = 0; c < r.size(); ++c) {
        const bool left = c == 0 || std::find(m_left.begin(), m_left.end(), c) != m_left.end();
        const std::string pad(w[c] - r[c].size(), ' ');
        if (c) line += "  ";
        line += left ? r[c] + pad : pad + r[c];
      }
      while (!line.empty() && line.back() == ' ') line.pop_back();
      out << line << "\n";
    }
  }

 private:
  std::vector<std::size_t> m_left;
  std::vector<std::vector<std::string>> m_rows;
};

std::string num(std::int64_t v) {
  return std::to_string(v);
}

void print_bus_params(const std::string& line, const fdl::BusParams& p, std::ostream& out) {
  out << "  bus parameters (line " << line << ", " << bus::baud_name(p.baud) << "): TSL " << p.tsl
      << ", min TSDR " << p.min_tsdr << ", max TSDR " << p.max_tsdr << ", TID1 " << p.tid1()
      << ", TID2 " << p.tid2() << ", TTR " << p.ttr << " bit, max_retry " << int(p.max_retry)
      << "; 1 bit = " << format_us(bus::bits_to_ticks(1, p.baud)) << " us\n";
}

/// T_TR and its parts, the DP error recognition.
void print_line(const std::string& title, const LinePlan& lp, const SwitchoverPlan& p,
                std::int64_t max_retry, std::ostream& out) {
  out << "\n  " << title << "\n";
  Table t({1});
  t.add({"term", "", "request", "TSDR/TSL", "reply", "idle", "bits", "us"});
  for (const auto& s : lp.slaves) {
    const CycleBits& c = s.dx;
    t.add({"Data_Exchange " + std::to_string(s.address),
           s.name + (is_switched(p, s.address) ? " (switched)" : ""), num(c.request), num(c.tsdr),
           num(c.response), num(c.idle), num(c.total()), us_of_bits(c.total(), p.baud)});
  }
  t.add({"sum of Data_Exchange cycles", "", "", "", "", "", num(lp.dx_bits),
         us_of_bits(lp.dx_bits, p.baud)});
  auto row = [&](const std::string& what, const std::string& detail, const CycleBits& c) {
    t.add({what, detail, num(c.request), num(c.tsdr), num(c.response), num(c.idle), num(c.total()),
           us_of_bits(c.total(), p.baud)});
  };
  row("Global_Control", "SDN + TID2", lp.gc);
  row("token", "to itself + TID1", lp.token);
  row("GAP poll", lp.gap.response == 0 ? "unanswered: TSL" : "answered", lp.gap);
  row("diag reserve", "largest Slave_Diag", lp.diag);
  row("retry reserve", "largest request + TSL", lp.retry);
  t.add({"T_TR", "", "", "", "", "", num(lp.t_tr_bits), us_of_bits(lp.t_tr_bits, p.baud)});
  t.add({"DP error recognition",
         "T_TR + " + std::to_string(1 + max_retry) + " x " +
             std::to_string(lp.failed_attempt.total()),
         "", "", "", "", num(lp.recognition_bits), us_of_bits(lp.recognition_bits, p.baud)});
  t.print(out, "    ");
}

void print_notes(const std::vector<std::string>& notes, std::ostream& out) {
  if (notes.empty()) return;
  out << "\n  notes:\n";
  for (const auto& n : notes) out << "    - " << n << "\n";
}

void print_system_text(const ScenarioPlan& plan, const SystemTiming& s, std::ostream& out) {
  const SwitchoverPlan& p = s.plan;
  out << "\nRedundant DP master system \"" << s.rp->name << "\": line A " << s.line_name[0]
      << " (DP master " << s.master_address[0] << "), line B " << s.line_name[1] << " (DP master "
      << s.master_address[1] << ")\n";
  print_bus_params(s.line_name[0], s.params, out);
  for (int side = 0; side < 2; ++side)
    print_line("line " + s.line_name[side] + " (" + (side == 0 ? "A" : "B") +
                   "): target rotation time T_TR",
               p.line[side], p, s.params.max_retry, out);

  out << "\n  switched stations: bound = recognition (failing line) + T_DP_UM (to the other) + "
         "T_SLAVE_UM\n";
  if (p.stations.empty()) {
    out << "    (none)\n";
  } else {
    Table t({1, 3, 4});
    t.add({"station", "model", "T_SLAVE_UM", "from", "failing", "recognition", "T_DP_UM bits",
           "T_DP_UM", "bound", "worst"});
    for (const auto& st : p.stations) {
      const SwitchedPlan* sw = switched_plan(plan, *s.rp, st.address);
      for (int from = 0; from < 2; ++from)
        t.add({from == 0 ? std::to_string(st.address) : "", from == 0 ? st.name : "",
               from == 0 ? (st.t_slave_um_given ? ms(st.t_slave_um) : "-") : "",
               from == 0 ? t_slave_um_source(sw) : "", s.line_name[from], ms(st.recognition[from]),
               num(st.t_dp_um_bits[from]), ms(st.t_dp_um[from]), ms(st.bound[from]),
               from == 0 ? ms(st.worst()) : ""});
    }
    t.print(out, "    ");
  }

  const redundancy::StationBound* slow = slowest(p);
  out << "\n  system switchover (a whole line lost); slowest station: ";
  if (slow != nullptr)
    out << int(slow->address) << ", T_SLAVE_UM " << ms(slow->t_slave_um) << "\n";
  else
    out << "none with a T_SLAVE_UM\n";
  Table t({1});
  t.add({"lost", "to", "recognition", "T_DP_UM_system bits", "T_DP_UM_system", "T_SLAVE_UM",
         "short circuit", "master stop/failure"});
  for (int lost = 0; lost < 2; ++lost)
    t.add({s.line_name[lost], s.line_name[1 - lost], ms(p.line[lost].line_loss_recognition),
           num(p.system_t_dp_um_bits[lost]), ms(p.system_t_dp_um[lost]), ms(p.max_t_slave_um),
           ms(p.system_bound[lost]), ms(p.system_bound_master_stop[lost])});
  t.print(out, "    ");
  out << "    (short circuit: recognition + T_DP_UM_system + T_SLAVE_UM; master stop/failure is "
         "known at once)\n";
  print_notes(p.notes, out);
}

void print_master_text(const MasterTiming& m, std::ostream& out) {
  out << "\nDP master " << int(m.mp->params.address) << " on line " << m.line_name
      << " (not redundant)\n";
  print_bus_params(m.line_name, m.params, out);
  print_line("line " + m.line_name + ": target rotation time T_TR", m.plan.line[0], m.plan,
             m.params.max_retry, out);
  print_notes(m.plan.notes, out);
}

// --- JSON output -------------------------------------------------------------------------------

std::string jcycle(const CycleBits& c, bus::Baud baud) {
  return "{\"request_bits\": " + num(c.request) + ", \"tsdr_bits\": " + num(c.tsdr) +
         ", \"response_bits\": " + num(c.response) + ", \"idle_bits\": " + num(c.idle) +
         ", \"bits\": " + num(c.total()) + ", \"ns\": " + num(bits_ns(c.total(), baud)) + "}";
}

std::string jopt_ns(std::optional<bus::Ticks> t) {
  return t ? num(bus::ticks_to_ns(*t)) : "null";
}

std::string jbus(const fdl::BusParams& p) {
  return "{\"baud\": " + num(static_cast<std::uint32_t>(p.baud)) + ", \"tsl\": " + num(p.tsl) +
         ", \"min_tsdr\": " + num(p.min_tsdr) + ", \"max_tsdr\": " + num(p.max_tsdr) +
         ", \"tqui\": " + num(p.tqui) + ", \"tset\": " + num(p.tset) + ", \"ttr\": " + num(p.ttr) +
         ", \"max_retry\": " + num(p.max_retry) + ", \"tid1\": " + num(p.tid1()) +
         ", \"tid2\": " + num(p.tid2()) + "}";
}

std::string jline(const LinePlan& lp, const SwitchoverPlan& p, int side, const std::string& name,
                  int master, const std::string& ind) {
  const bus::Baud b = p.baud;
  std::ostringstream o;
  o << "{\"side\": \"" << (side == 0 ? "A" : "B") << "\", \"name\": " << json_quote(name)
    << ", \"master\": " << master << ",\n"
    << ind << " \"slaves\": [";
  for (std::size_t i = 0; i < lp.slaves.size(); ++i) {
    const auto& s = lp.slaves[i];
    o << (i ? "," : "") << "\n"
      << ind << "   {\"address\": " << int(s.address) << ", \"model\": " << json_quote(s.name)
      << ", \"switched\": " << (is_switched(p, s.address) ? "true" : "false")
      << ", \"dx\": " << jcycle(s.dx, b) << "}";
  }
  o << (lp.slaves.empty() ? "],\n" : "\n" + ind + " ],\n");
  o << ind << " \"dx_bits\": " << lp.dx_bits << ", \"dx_ns\": " << bits_ns(lp.dx_bits, b) << ",\n";
  o << ind << " \"global_control\": " << jcycle(lp.gc, b) << ",\n";
  o << ind << " \"token\": " << jcycle(lp.token, b) << ",\n";
  o << ind << " \"gap\": " << jcycle(lp.gap, b) << ",\n";
  o << ind << " \"diag\": " << jcycle(lp.diag, b) << ",\n";
  o << ind << " \"retry\": " << jcycle(lp.retry, b) << ",\n";
  o << ind << " \"t_tr_bits\": " << lp.t_tr_bits << ", \"t_tr_ns\": " << bus::ticks_to_ns(lp.t_tr)
    << ",\n";
  o << ind << " \"failed_attempt\": " << jcycle(lp.failed_attempt, b) << ",\n";
  o << ind << " \"recognition_bits\": " << lp.recognition_bits
    << ", \"recognition_ns\": " << bus::ticks_to_ns(lp.recognition) << "}";
  return o.str();
}

std::string jnotes(const std::vector<std::string>& notes) {
  std::string s = "[";
  for (std::size_t i = 0; i < notes.size(); ++i) s += (i ? ", " : "") + json_quote(notes[i]);
  return s + "]";
}

/// Everything but the h_systems and the closing brace (cmd_timing adds those).
void print_json(const ScenarioPlan& plan, const std::vector<SystemTiming>& systems,
                const std::vector<MasterTiming>& masters, std::ostream& out) {
  out << "{\"schema\": \"pbvbus.timing/1\",\n";
  out << " \"scenario\": {\"name\": " << json_quote(plan.name)
      << ", \"file\": " << json_quote(plan.file) << "},\n";
  out << " \"redundant_systems\": [";
  for (std::size_t n = 0; n < systems.size(); ++n) {
    const SystemTiming& s = systems[n];
    const SwitchoverPlan& p = s.plan;
    out << (n ? "," : "") << "\n  {\"name\": " << json_quote(s.rp->name) << ",\n";
    out << "   \"bus_params\": " << jbus(s.params) << ",\n";
    out << "   \"lines\": [";
    for (int side = 0; side < 2; ++side)
      out << (side ? ",\n    " : "\n    ")
          << jline(p.line[side], p, side, s.line_name[side], s.master_address[side], "    ");
    out << "],\n   \"stations\": [";
    for (std::size_t k = 0; k < p.stations.size(); ++k) {
      const auto& st = p.stations[k];
      const SwitchedPlan* sw = switched_plan(plan, *s.rp, st.address);
      out << (k ? "," : "") << "\n    {\"address\": " << int(st.address)
          << ", \"model\": " << json_quote(st.name) << ", \"t_slave_um_ns\": "
          << jopt_ns(st.t_slave_um_given ? std::optional<bus::Ticks>(st.t_slave_um) : std::nullopt)
          << ", \"t_slave_um_source\": \"" << t_slave_um_source(sw)
          << "\",\n     \"prm_cmd\": " << jcycle(st.prm_cmd[0], p.baud) << ",\n     \"failing\": [";
      for (int from = 0; from < 2; ++from)
        out << (from ? ",\n       " : "") << "{\"line\": " << json_quote(s.line_name[from])
            << ", \"to\": " << json_quote(s.line_name[1 - from])
            << ", \"recognition_ns\": " << bus::ticks_to_ns(st.recognition[from])
            << ", \"t_dp_um_bits\": " << st.t_dp_um_bits[from]
            << ", \"t_dp_um_ns\": " << bus::ticks_to_ns(st.t_dp_um[from])
            << ", \"bound_ns\": " << bus::ticks_to_ns(st.bound[from]) << "}";
      out << "],\n     \"worst_ns\": " << bus::ticks_to_ns(st.worst()) << "}";
    }
    out << (p.stations.empty() ? "],\n" : "\n   ],\n");
    const redundancy::StationBound* slow = slowest(p);
    out << "   \"system\": [";
    for (int lost = 0; lost < 2; ++lost)
      out << (lost ? ",\n    " : "\n    ") << "{\"lost\": " << json_quote(s.line_name[lost])
          << ", \"to\": " << json_quote(s.line_name[1 - lost])
          << ", \"recognition_ns\": " << bus::ticks_to_ns(p.line[lost].line_loss_recognition)
          << ", \"t_dp_um_system_bits\": " << p.system_t_dp_um_bits[lost]
          << ", \"t_dp_um_system_ns\": " << bus::ticks_to_ns(p.system_t_dp_um[lost])
          << ", \"max_t_slave_um_ns\": " << bus::ticks_to_ns(p.max_t_slave_um)
          << ", \"slowest_station\": "
          << (slow != nullptr ? std::to_string(slow->address) : std::string("null"))
          << ", \"bound_short_circuit_ns\": " << bus::ticks_to_ns(p.system_bound[lost])
          << ", \"bound_master_stop_ns\": " << bus::ticks_to_ns(p.system_bound_master_stop[lost])
          << "}";
    out << "],\n   \"notes\": " << jnotes(p.notes) << "}";
  }
  out << (systems.empty() ? "],\n" : "\n ],\n");
  out << " \"dp_masters\": [";
  for (std::size_t n = 0; n < masters.size(); ++n) {
    const MasterTiming& m = masters[n];
    out << (n ? "," : "") << "\n  {\"address\": " << int(m.mp->params.address) << ",\n";
    out << "   \"bus_params\": " << jbus(m.params) << ",\n";
    out << "   \"line\": "
        << jline(m.plan.line[0], m.plan, 0, m.line_name, m.mp->params.address, "    ") << ",\n";
    out << "   \"notes\": " << jnotes(m.plan.notes) << "}";
  }
  out << (masters.empty() ? "]" : "\n ]");
}


// --- the H-system's update timing (h_system entries) -----------------------------------------

struct HTiming {
  const HSystemPlan* hp = nullptr;
  devices::UpdatePlan plan;
  devices::HCheckResult checks;
  bool configured = false;  ///< any of the four H parameters given
};

std::string hms(devices::Us v) { return devices::format_ms(v); }

void print_h_text(const HTiming& h, std::ostream& out) {
  const devices::UpdatePlan& p = h.plan;
  out << "\nH-system \"" << h.hp->name << "\": update timing (T_P15 procedure, docs/h-timing.md)\n";
  out << "  T_WA " << hms(p.input.t_wa) << ", T_PROG " << hms(p.input.t_prog)
      << ", DBs in work memory " << p.input.db_kb << " KB\n";
  for (const auto& s : p.systems) {
    out << "  [1] " << s.in.name << ": T_PTO " << hms(s.in.t_pto) << " - (2 x T_TR " << hms(s.in.t_tr)
        << " + T_WA + T_PROG + T_DP_UM " << hms(s.in.t_dp_um) << " + T_SLAVE_UM "
        << hms(s.in.t_slave_um) << " = " << hms(s.subtracted) << ") = " << hms(s.t_p15) << "\n";
  }
  if (p.t_p15_hw)
    out << "  T_P15_HW = " << hms(*p.t_p15_hw) << " (" << p.systems.at(*p.hw_system).in.name << ")\n";
  else
    out << "  T_P15_HW: none (no DP master system)\n";
  out << "  T_PH = MAX(30 ms, 3 x T_TRmax " << hms(p.t_tr_max) << ") = " << hms(p.t_ph) << "\n";
  out << "  [2] T_P15_OD = 50 ms + T_PH = " << hms(p.t_p15_od) << "; T_P15_AWP = 75 ms + 0.7 ms x "
      << p.input.db_kb << " KB = " << hms(p.t_p15_awp) << "\n";
  if (p.t_p15) {
    out << "  [3] T_P15 = MAX(T_P15_AWP, T_P15_OD) = " << hms(*p.t_p15) << "\n";
    out << "  recommended: max communication delay 4 x T_P15 = " << hms(*p.recommended_comm_delay)
        << ", max cycle extension 10 x T_P15 = " << hms(*p.recommended_cycle_extension) << "\n";
    if (p.settable_t_p15) out << "  smallest settable T_P15: " << hms(*p.settable_t_p15) << "\n";
  } else {
    out << "  no recommendation: the procedure aborts (" << devices::to_string(p.abort) << ")\n";
  }
  for (const auto& m : p.messages) out << "    " << m << "\n";
  for (const auto& n : p.notes) out << "  note: " << n << "\n";
  if (h.configured) {
    out << "  configured H parameters: " << (h.checks.ok() ? "ok" : "NOT OK") << "\n";
  }
  for (const auto& v : h.checks.violations)
    out << "    " << (v.severity == devices::Severity::Error ? "error" : "warning") << ": "
        << v.message << "\n";
}

std::string jus(std::optional<devices::Us> v) { return v ? std::to_string(*v) : "null"; }

void print_h_json(const std::vector<HTiming>& hs, std::ostream& out) {
  out << ",\n \"h_systems\": [";
  for (std::size_t n = 0; n < hs.size(); ++n) {
    const HTiming& h = hs[n];
    const devices::UpdatePlan& p = h.plan;
    out << (n ? "," : "") << "\n  {\"name\": " << json_quote(h.hp->name) << ", \"t_wa_us\": "
        << p.input.t_wa << ", \"t_prog_us\": " << p.input.t_prog << ", \"db_kb\": " << p.input.db_kb
        << ",\n   \"dp_systems\": [";
    for (std::size_t k = 0; k < p.systems.size(); ++k) {
      const auto& s = p.systems[k];
      out << (k ? ", " : "") << "{\"name\": " << json_quote(s.in.name) << ", \"t_tr_us\": "
          << s.in.t_tr << ", \"t_dp_um_us\": " << s.in.t_dp_um << ", \"t_slave_um_us\": "
          << s.in.t_slave_um << ", \"t_pto_us\": " << s.in.t_pto << ", \"subtracted_us\": "
          << s.subtracted << ", \"t_p15_us\": " << s.t_p15 << "}";
    }
    out << "],\n   \"t_p15_hw_us\": " << jus(p.t_p15_hw) << ", \"t_ph_us\": " << p.t_ph
        << ", \"t_p15_od_us\": " << p.t_p15_od << ", \"t_p15_awp_us\": " << p.t_p15_awp
        << ", \"t_p15_us\": " << jus(p.t_p15) << ", \"recommended_comm_delay_us\": "
        << jus(p.recommended_comm_delay) << ", \"recommended_cycle_extension_us\": "
        << jus(p.recommended_cycle_extension) << ", \"abort\": "
        << json_quote(devices::to_string(p.abort)) << ",\n   \"messages\": " << jnotes(p.messages)
        << ", \"notes\": " << jnotes(p.notes) << ",\n   \"configured\": "
        << (h.configured ? "true" : "false") << ", \"checks_ok\": " << (h.checks.ok() ? "true" : "false")
        << ", \"checks\": [";
    for (std::size_t k = 0; k < h.checks.violations.size(); ++k) {
      const auto& v = h.checks.violations[k];
      out << (k ? ", " : "") << "{\"check\": " << json_quote(devices::to_string(v.check))
          << ", \"severity\": " << (v.severity == devices::Severity::Error ? "\"error\"" : "\"warning\"")
          << ", \"message\": " << json_quote(v.message) << "}";
    }
    out << "]}";
  }
  out << (hs.empty() ? "]" : "\n ]");
}

// --- Quantum Hot Standby scan time (quantum_hot_standby entries) ---------------------------

const char* cpu_name(quantum::CpuType c) {
  switch (c) {
    case quantum::CpuType::X13: return "x13";
    case quantum::CpuType::Cpu42402: return "424 02";
    case quantum::CpuType::Cpu43412: return "434 12";
  }
  return "?";
}

const char* transfer_mode(const QuantumPlan& q) {
  if (q.iec) return "iec";
  switch (q.transfer.mode) {
    case quantum::TransferConfig::Mode::Default12K: return "12k";
    case quantum::TransferConfig::Mode::UserDefined: return "user_defined";
    case quantum::TransferConfig::Mode::TransferAll: return "transfer_all";
  }
  return "?";
}

const char* transfer_mode_text(const QuantumPlan& q) {
  if (q.iec) return "IEC: all state RAM";
  switch (q.transfer.mode) {
    case quantum::TransferConfig::Mode::Default12K: return "12K (default)";
    case quantum::TransferConfig::Mode::UserDefined: return "user defined";
    case quantum::TransferConfig::Mode::TransferAll: return "transfer all";
  }
  return "?";
}

/// The rate the model used (µs per 1000 B) and whether the scenario set it.
std::pair<std::int64_t, bool> quantum_rate(const ScenarioPlan& plan, const QuantumPlan& q) {
  const auto& e = plan.proto.quantum_hot_standby(q.source);
  if (e.has_transfer_rate_us_per_kb()) return {e.transfer_rate_us_per_kb(), true};
  return {quantum::rate_us_per_1000_bytes(q.cpu), false};
}

/// References of one type sent every scan, the baseline, the delta and its bytes.
struct QuantumRow {
  const char* type;  ///< "0x", "1x", "3x", "4x", "IEC-HSBY 3x"
  const char* key;   ///< the JSON name
  std::int64_t transferred, baseline, delta, bytes;
};

std::vector<QuantumRow> quantum_rows(const QuantumPlan& q) {
  const quantum::RefCounts b = quantum::baseline(q.cpu);
  const quantum::ScanEstimate& e = q.estimate;
  auto sent = [&](quantum::RefType t) {
    return static_cast<std::int64_t>(quantum::per_scan_count(q.plan, t));
  };
  std::vector<QuantumRow> rows = {
      {"0x", "coils", sent(quantum::RefType::Coil0x), b.coils, e.deltas.coils, e.coil_bytes},
      {"1x", "inputs", sent(quantum::RefType::Input1x), b.inputs, e.deltas.inputs, e.input_bytes},
      {"3x", "input_registers", sent(quantum::RefType::Register3x), b.input_regs,
       e.deltas.input_regs, e.input_reg_bytes},
      {"4x", "holding_registers", sent(quantum::RefType::Register4x), b.holding, e.deltas.holding,
       e.holding_bytes}};
  // The seed's IEC example counts every IEC-HSBY register (its baseline's 700 not taken off).
  if (q.iec)
    rows.push_back({"IEC-HSBY 3x", "iec_hsby_registers", e.deltas.iec_regs, 0, e.deltas.iec_regs,
                    e.iec_bytes});
  return rows;
}

std::string range_text(const quantum::TransferRange& r) {
  return quantum::format_reference(r.type, r.first) + ".." + quantum::format_reference(r.type, r.first + r.count - 1);
}

/// "40 + 36 + 28 = 104 ms" (a negative transfer as "- 44").
std::string seed_sum(const quantum::ScanEstimate& e) {
  const std::int64_t standalone = (e.standalone + bus::kTicksPerMs / 2) / bus::kTicksPerMs;
  std::string s = num(e.hsby / bus::kTicksPerMs) + " + " + num(standalone) +
                  (e.transfer_ms < 0 ? " - " + num(-e.transfer_ms) : " + " + num(e.transfer_ms));
  return s + " = " + num(e.total_ms) + " ms";
}

void print_quantum_text(const ScenarioPlan& plan, const QuantumPlan& q, std::ostream& out) {
  const quantum::ScanEstimate& e = q.estimate;
  out << "\nQuantum Hot Standby \"" << q.name << "\": scan time (seed 003 pp. 33-35, 49-50; "
      << "docs/quantum-hsby.md)\n";
  out << "  CPU " << cpu_name(q.cpu) << ", " << (q.iec ? "IEC" : "984") << " Hot Standby; logic "
      << "(standalone scan) " << ms(q.logic_time) << "\n";
  out << "  transfer area: " << transfer_mode_text(q) << "\n";
  out << "    every scan: 0x " << quantum::per_scan_count(q.plan, quantum::RefType::Coil0x)
      << ", 1x " << quantum::per_scan_count(q.plan, quantum::RefType::Input1x) << ", 3x "
      << quantum::per_scan_count(q.plan, quantum::RefType::Register3x) << ", 4x "
      << quantum::per_scan_count(q.plan, quantum::RefType::Register4x) << "\n";
  if (q.plan.additional_slices.empty()) {
    out << "    additional: none\n";
  } else {
    out << "    additional: " << q.plan.additional_slices.size() << " slices, one a scan\n";
    for (std::size_t k = 0; k < q.plan.additional_slices.size(); ++k) {
      out << "      slice " << k << ":";
      for (const auto& r : q.plan.additional_slices[k]) out << " " << range_text(r);
      out << "\n";
    }
  }
  const quantum::NonTransferArea& n = q.plan.non_transfer;
  if (n.count == 0)
    out << "    non-transfer area: none\n";
  else
    out << "    non-transfer area: "
        << range_text({quantum::RefType::Register4x, n.first, n.count}) << " (" << n.count
        << " registers)\n";
  out << "    command register: "
      << quantum::format_reference(quantum::RefType::Register4x, q.command_register) << "\n";

  out << "  scan-time model (every scan's state RAM beyond the CPU type's baseline)\n";
  Table t;
  t.add({"type", "every scan", "baseline", "delta", "bytes"});
  for (const QuantumRow& r : quantum_rows(q))
    t.add({r.type, num(r.transferred), std::string(r.key) == "iec_hsby_registers" ? "-" : num(r.baseline),
           num(r.delta), num(r.bytes)});
  t.add({"total", "", "", "", num(e.bytes) + " B"});
  t.print(out, "    ");
  const auto [rate, set] = quantum_rate(plan, q);
  out << "  rate " << rate << " us per 1000 B ("
      << (set ? std::string("transfer_rate_us_per_kb; the CPU's is ") +
                    num(quantum::rate_us_per_1000_bytes(q.cpu))
              : std::string("the CPU's"))
      << "; the seed's \"ms/byte\" read as ms per ~1000 B)\n";
  out << "  transfer " << num(e.bytes) << " B x " << rate << " us / 1000 B = " << ms(e.transfer)
      << " ~ " << e.transfer_ms << " ms\n";
  out << "  HSBY cost " << ms(e.hsby) << ", standalone " << ms(e.standalone) << "\n";
  out << "  total " << seed_sum(e) << " (exact " << ms(e.total) << ")\n";
  out << "  scan time " << ms(q.scan_time)
      << (q.scan_time_estimated ? " (estimated: the model's total)" : " (configured)") << "\n";
  out << "  note: the per-scan transfer adds scan time only when the logic is shorter than the "
         "transfer (seed p. 33); it never causes a watchdog timeout (pp. 35, 51)\n";
}

void print_quantum_json(const ScenarioPlan& plan, std::ostream& out) {
  out << ",\n \"quantum\": [";
  for (std::size_t n = 0; n < plan.quantum.size(); ++n) {
    const QuantumPlan& q = plan.quantum[n];
    const quantum::ScanEstimate& e = q.estimate;
    out << (n ? "," : "") << "\n  {\"name\": " << json_quote(q.name) << ", \"cpu\": \""
        << cpu_name(q.cpu) << "\", \"iec\": " << (q.iec ? "true" : "false")
        << ", \"logic_time_ns\": " << bus::ticks_to_ns(q.logic_time) << ",\n   \"transfer\": {\"mode\": \""
        << transfer_mode(q) << "\", \"every_scan\": {";
    const auto rows = quantum_rows(q);
    for (std::size_t k = 0; k < 4; ++k)
      out << (k ? ", " : "") << "\"" << rows[k].key << "\": " << rows[k].transferred;
    out << "},\n    \"additional\": [";
    for (std::size_t k = 0; k < q.plan.additional_slices.size(); ++k) {
      out << (k ? ", " : "") << "[";
      const auto& slice = q.plan.additional_slices[k];
      for (std::size_t r = 0; r < slice.size(); ++r)
        out << (r ? ", " : "") << "{\"first\": \"" << quantum::format_reference(slice[r].type, slice[r].first)
            << "\", \"count\": " << slice[r].count << "}";
      out << "]";
    }
    out << "], \"non_transfer\": ";
    const quantum::NonTransferArea& nt = q.plan.non_transfer;
    if (nt.count == 0)
      out << "null";
    else
      out << "{\"first\": \"" << quantum::format_reference(quantum::RefType::Register4x, nt.first)
          << "\", \"count\": " << nt.count << "}";
    out << ", \"command_register\": \""
        << quantum::format_reference(quantum::RefType::Register4x, q.command_register) << "\"},\n";
    auto obj = [&](auto field) {
      std::string s = "{";
      for (std::size_t k = 0; k < rows.size(); ++k)
        s += std::string(k ? ", " : "") + "\"" + rows[k].key + "\": " + num(field(rows[k]));
      return s + "}";
    };
    const auto [rate, set] = quantum_rate(plan, q);
    out << "   \"model\": {\"every_scan\": " << obj([](const QuantumRow& r) { return r.transferred; })
        << ",\n    \"baseline\": " << obj([](const QuantumRow& r) { return r.baseline; })
        << ",\n    \"deltas\": " << obj([](const QuantumRow& r) { return r.delta; })
        << ",\n    \"bytes\": " << obj([](const QuantumRow& r) { return r.bytes; })
        << ",\n    \"total_bytes\": " << e.bytes << ", \"rate_us_per_kb\": " << rate
        << ", \"rate_source\": \"" << (set ? "scenario" : "cpu") << "\", \"transfer_ns\": "
        << bus::ticks_to_ns(e.transfer) << ", \"transfer_ms\": " << e.transfer_ms
        << ",\n    \"hsby_ns\": " << bus::ticks_to_ns(e.hsby) << ", \"standalone_ns\": "
        << bus::ticks_to_ns(e.standalone) << ", \"total_ns\": " << bus::ticks_to_ns(e.total)
        << ", \"total_ms\": " << e.total_ms << "},\n";
    out << "   \"scan_time_ns\": " << bus::ticks_to_ns(q.scan_time) << ", \"scan_time_source\": \""
        << (q.scan_time_estimated ? "estimated" : "configured") << "\"}";
  }
  out << (plan.quantum.empty() ? "]" : "\n ]");
}

}  // namespace

int cmd_timing(const Args& args, std::ostream& out, std::ostream& err) {
  bool json = false;
  std::string file;
  ReliabilityOptions rel;
  for (std::size_t k = 0; k < args.size(); ++k) {
    const std::string& a = args[k];
    bool matched = false;
    std::string rel_error;
    if (!parse_reliability_option(args, k, rel, matched, rel_error)) {
      err << "pbvbus timing: " << rel_error << "\n" << kTimingUsage << kReliabilityUsage;
      return 2;
    }
    if (matched) continue;
    if (a == "--help" || a == "-h") {
      out << kTimingUsage << kReliabilityUsage;
      return 0;
    }
    if (a == "--json") {
      json = true;
    } else if (!a.empty() && a[0] == '-') {
      err << "pbvbus timing: unknown option '" << a << "'\n" << kTimingUsage;
      return 2;
    } else if (!file.empty()) {
      err << "pbvbus timing: only one SCENARIO, got '" << file << "' and '" << a << "'\n";
      return 2;
    } else {
      file = a;
    }
  }
  if (file.empty()) {
    err << "pbvbus timing: no SCENARIO given\n" << kTimingUsage;
    return 2;
  }
  const LoadResult loaded = load_scenario_file(file);
  if (!loaded.ok()) {
    for (const auto& d : loaded.errors) err << d.str() << "\n";
    return 2;
  }
  const ScenarioPlan& plan = *loaded.plan;

  std::vector<SystemTiming> systems;
  std::vector<MasterTiming> masters;
  std::vector<bool> in_system(plan.dp_masters.size(), false);
  try {
    for (std::size_t k = 0; k < plan.redundant_systems.size(); ++k) {
      const RedundancyPlan& rp = plan.redundant_systems[k];
      SystemTiming s;
      s.rp = &rp;
      s.plan = plan_system_timing(plan, static_cast<int>(k));
      s.params = plan.lines.at(static_cast<std::size_t>(rp.line[0])).params;
      for (int side = 0; side < 2; ++side) {
        s.line_name[side] = plan.lines.at(static_cast<std::size_t>(rp.line[side])).name;
        const auto mi = static_cast<std::size_t>(rp.master[side]);
        s.master_address[side] = plan.dp_masters.at(mi).params.address;
        in_system.at(mi) = true;
      }
      systems.push_back(std::move(s));
    }
    for (std::size_t k = 0; k < plan.dp_masters.size(); ++k) {
      if (in_system[k]) continue;
      const DpMasterPlan& mp = plan.dp_masters[k];
      MasterTiming m;
      m.mp = &mp;
      m.plan = plan_master_timing(plan, static_cast<int>(k));
      m.line_name = plan.lines.at(static_cast<std::size_t>(mp.line)).name;
      m.params = plan.lines.at(static_cast<std::size_t>(mp.line)).params;
      masters.push_back(std::move(m));
    }
  } catch (const std::exception& e) {
    err << "pbvbus timing: " << plan.file << ": " << e.what() << "\n";
    return 2;
  }
  const devices::ReliabilityInput rel_in{rel.mtbf_years * devices::kHoursPerYear, rel.dc,
                                         rel.mdt_hours};
  if (const std::string why = devices::check_reliability_input(rel_in); !why.empty()) {
    err << "pbvbus timing: " << why << "\n";
    return 2;
  }
  const devices::ReliabilityResult reliability = *devices::plan_reliability(rel_in);
  std::vector<HTiming> hs;
  try {
    for (const auto& hp : plan.h_systems) {
      HTiming h;
      h.hp = &hp;
      h.plan = devices::plan_update(h_update_input(plan, hp));
      const auto& c = hp.params;
      h.configured = c.max_cycle_extension || c.max_comm_delay || c.t_p15 || c.t_ph;
      if (h.configured) h.checks = devices::check_h_parameters(c, &h.plan);
      hs.push_back(std::move(h));
    }
  } catch (const std::exception& e) {
    err << "pbvbus timing: " << plan.file << ": " << e.what() << "\n";
    return 2;
  }

  if (json) {
    print_json(plan, systems, masters, out);
    print_h_json(hs, out);
    if (!hs.empty()) {
      out << ",\n ";
      print_reliability_json(reliability, out);  // the same for every h_system (its CPU pair)
    }
    print_quantum_json(plan, out);
    out << "}\n";
    return 0;
  }
  out << "Scenario \"" << plan.name << "\" (" << plan.file
      << "): planned DP rotation and switchover times\n";
  if (systems.empty() && masters.empty() && hs.empty() && plan.quantum.empty()) {
    out << "no DP master system in this scenario: nothing to plan\n";
    return 0;
  }
  for (const auto& s : systems) print_system_text(plan, s, out);
  for (const auto& m : masters) print_master_text(m, out);
  for (const auto& h : hs) {
    print_h_text(h, out);
    print_reliability_text(reliability, out);
  }
  for (const auto& q : plan.quantum) print_quantum_text(plan, q, out);
  return 0;
}

}  // namespace pbvbus::tools
