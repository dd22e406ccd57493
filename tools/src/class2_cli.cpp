// `pbvbus run --dp2 SPEC`: class-2 master services against a running scenario
// (class2_cli.hpp documents the command line and the decisions).

#include "pbvbus/reports/json_text.hpp"
#include "pbvbus/tools/class2_cli.hpp"

#include <cstdio>
#include <set>
#include <stdexcept>

#include "pbvbus/bus/line.hpp"
#include "pbvbus/dp/class2_master.hpp"
#include "pbvbus/dp/master_acyclic.hpp"
#include "pbvbus/dp/master_report.hpp"
#include "pbvbus/fdl/active_station.hpp"
#include "pbvbus/fdl/telegram.hpp"
#include "pbvbus/simulation/simulation.hpp"

namespace pbvbus::tools {

namespace {

std::vector<std::string_view> split(std::string_view s, char sep) {
  std::vector<std::string_view> parts;
  std::size_t start = 0;
  for (;;) {
    const std::size_t p = s.find(sep, start);
    parts.push_back(s.substr(start, p == std::string_view::npos ? std::string_view::npos : p - start));
    if (p == std::string_view::npos) return parts;
    start = p + 1;
  }
}

/// Decimal, or hex with 0x. nullopt if not a number or above `max`.
std::optional<std::uint32_t> parse_uint(std::string_view s, std::uint32_t max) {
  if (s.empty()) return std::nullopt;
  unsigned base = 10;
  if (s.size() > 2 && s[0] == '0' && (s[1] == 'x' || s[1] == 'X')) {
    base = 16;
    s.remove_prefix(2);
  }
  std::uint64_t v = 0;
  for (char c : s) {
    unsigned d;
    if (c >= '0' && c <= '9') d = static_cast<unsigned>(c - '0');
    else if (base == 16 && c >= 'a' && c <= 'f') d = static_cast<unsigned>(c - 'a' + 10);
    else if (base == 16 && c >= 'A' && c <= 'F') d = static_cast<unsigned>(c - 'A' + 10);
    else return std::nullopt;
    v = v * base + d;
    if (v > max) return std::nullopt;
  }
  return static_cast<std::uint32_t>(v);
}

std::optional<std::vector<std::uint8_t>> parse_hex(std::string_view s) {
  if (s.size() >= 2 && s[0] == '0' && (s[1] == 'x' || s[1] == 'X')) s.remove_prefix(2);
  if (s.empty() || s.size() % 2 != 0) return std::nullopt;
  std::vector<std::uint8_t> out;
  for (std::size_t i = 0; i < s.size(); i += 2) {
    auto v = parse_uint(std::string("0x") + std::string(s.substr(i, 2)), 0xFF);
    if (!v) return std::nullopt;
    out.push_back(static_cast<std::uint8_t>(*v));
  }
  return out;
}

std::string hex_spaced(const std::vector<std::uint8_t>& b) {
  std::string s;
  char buf[4];
  for (std::size_t i = 0; i < b.size(); ++i) {
    std::snprintf(buf, sizeof buf, "%02X", b[i]);
    if (i) s += ' ';
    s += buf;
  }
  return s;
}

std::string hex_plain(const std::vector<std::uint8_t>& b) {
  std::string s;
  char buf[4];
  for (std::uint8_t x : b) {
    std::snprintf(buf, sizeof buf, "%02X", x);
    s += buf;
  }
  return s;
}

std::string format_time(bus::Ticks t) {
  const auto ms = static_cast<unsigned long long>(t / bus::kTicksPerMs);
  char buf[40];
  std::snprintf(buf, sizeof buf, "%llu.%03llu s", ms / 1000, ms % 1000);
  return buf;
}

/// How often a read/write waiting for another one's MSAC_C2 connection to the same slave looks again.
constexpr bus::Ticks kC2RetryDelay = 10 * bus::kTicksPerMs;

struct OpName {
  Class2Op op;
  std::string_view name;
};
constexpr OpName kOps[] = {
    {Class2Op::GetCfg, "get_cfg"},   {Class2Op::SlaveDiag, "slave_diag"},
    {Class2Op::RdInp, "rd_inp"},     {Class2Op::RdOutp, "rd_outp"},
    {Class2Op::SetSlaveAdd, "set_slave_add"}, {Class2Op::Read, "read"},
    {Class2Op::Write, "write"},
};

}  // namespace

std::string_view to_string(Class2Op op) {
  for (const auto& o : kOps)
    if (o.op == op) return o.name;
  return "?";
}

std::optional<Class2Request> parse_class2_spec(std::string_view spec, std::string& error) {
  const std::string quoted = "--dp2 '" + std::string(spec) + "': ";
  const auto parts = split(spec, ':');
  if (parts.size() < 3 || parts.size() > 4) {
    error = quoted + "expected TIME:SERVICE:STATION[:KEY=VALUE,...], e.g. 1s:get_cfg:5";
    return std::nullopt;
  }
  Class2Request r;
  const auto t = bus::parse_duration(std::string(parts[0]));
  if (!t) {
    error = quoted + "bad time '" + std::string(parts[0]) + "' (expected e.g. 1s, 250ms)";
    return std::nullopt;
  }
  r.at = *t;
  bool known = false;
  for (const auto& o : kOps)
    if (o.name == parts[1]) {
      r.op = o.op;
      known = true;
    }
  if (!known) {
    error = quoted + "unknown service '" + std::string(parts[1]) +
            "' (get_cfg, slave_diag, rd_inp, rd_outp, set_slave_add, read, write)";
    return std::nullopt;
  }
  const auto st = parse_uint(parts[2], 126);
  if (!st) {
    error = quoted + "bad station '" + std::string(parts[2]) + "' (expected an address 0..126)";
    return std::nullopt;
  }
  r.station = static_cast<std::uint8_t>(*st);

  std::set<std::string, std::less<>> seen;
  if (parts.size() == 4) {
    for (std::string_view kv : split(parts[3], ',')) {
      const std::size_t eq = kv.find('=');
      if (eq == std::string_view::npos || eq == 0) {
        error = quoted + "bad argument '" + std::string(kv) + "' (expected KEY=VALUE)";
        return std::nullopt;
      }
      const std::string key(kv.substr(0, eq));
      const std::string_view val = kv.substr(eq + 1);
      auto bad_value = [&](const char* what) {
        error = quoted + "bad value '" + std::string(val) + "' of " + key + " (expected " + what + ")";
        return std::nullopt;
      };
      auto num = [&](std::uint32_t max) { return parse_uint(val, max); };
      if (!seen.insert(key).second) {
        error = quoted + "'" + key + "' given twice";
        return std::nullopt;
      }
      const bool sa = r.op == Class2Op::SetSlaveAdd;
      const bool rw = r.op == Class2Op::Read || r.op == Class2Op::Write;
      if (sa && key == "new") {
        auto v = num(125);
        if (!v) return bad_value("an address 0..125");
        r.new_address = static_cast<std::uint8_t>(*v);
      } else if (sa && key == "ident") {
        auto v = num(0xFFFF);
        if (!v) return bad_value("an ident number 0..0xFFFF");
        r.ident = static_cast<std::uint16_t>(*v);
      } else if (sa && key == "no_add_chg") {
        if (val != "0" && val != "1") return bad_value("0 or 1");
        r.no_add_chg = val == "1";
      } else if (rw && key == "slot") {
        auto v = num(254);
        if (!v) return bad_value("a slot 0..254");
        r.slot = static_cast<std::uint8_t>(*v);
      } else if (rw && key == "index") {
        auto v = num(255);
        if (!v) return bad_value("an index 0..255");
        r.index = static_cast<std::uint8_t>(*v);
      } else if (r.op == Class2Op::Read && key == "len") {
        auto v = num(240);
        if (!v || *v == 0) return bad_value("a length 1..240");
        r.length = static_cast<std::uint8_t>(*v);
      } else if (r.op == Class2Op::Write && key == "data") {
        auto v = parse_hex(val);
        if (!v || v->size() > 240) return bad_value("1..240 octets in hex, e.g. 0102A0");
        r.data = std::move(*v);
      } else {
        error = quoted + "unknown argument '" + key + "' for " + std::string(parts[1]);
        return std::nullopt;
      }
    }
  }
  auto need = [&](std::initializer_list<const char*> keys) {
    for (const char* k : keys)
      if (!seen.count(k)) {
        error = quoted + std::string(parts[1]) + " needs " + k + "=";
        return false;
      }
    return true;
  };
  switch (r.op) {
    case Class2Op::SetSlaveAdd:
      if (!need({"new", "ident"})) return std::nullopt;
      break;
    case Class2Op::Read:
      if (!need({"slot", "index", "len"})) return std::nullopt;
      break;
    case Class2Op::Write:
      if (!need({"slot", "index", "data"})) return std::nullopt;
      break;
    default:
      break;
  }
  return r;
}

const char* const kClass2Usage =
    "  --dp2 SPEC        (repeatable) a DP class-2 master request at a virtual time:\n"
    "                    TIME:SERVICE:STATION[:KEY=VALUE,...], SERVICE one of get_cfg,\n"
    "                    slave_diag, rd_inp, rd_outp, set_slave_add (new=N,ident=0xNNNN\n"
    "                    [,no_add_chg=1]), read (slot=N,index=N,len=N), write\n"
    "                    (slot=N,index=N,data=HEX); e.g. --dp2 1s:get_cfg:5. Results go\n"
    "                    into the report (JSON: array \"class2\")\n"
    "  --dp2-line NAME   line of the class-2 master (default: the first line)\n"
    "  --dp2-address N   its FDL address (default: the lowest one free on the line)\n";

Class2ArgResult parse_class2_arg(const Args& args, std::size_t& i, Class2Options& opts,
                                 std::string& error) {
  const std::string& a = args[i];
  if (a != "--dp2" && a != "--dp2-line" && a != "--dp2-address") return Class2ArgResult::NotMine;
  if (i + 1 >= args.size()) {
    error = a + " needs a value";
    return Class2ArgResult::Error;
  }
  const std::string& v = args[++i];
  if (a == "--dp2") {
    auto r = parse_class2_spec(v, error);
    if (!r) return Class2ArgResult::Error;
    opts.requests.push_back(std::move(*r));
  } else if (a == "--dp2-line") {
    opts.line = v;
  } else {
    auto n = parse_uint(v, 126);
    if (!n) {
      error = "bad --dp2-address '" + v + "' (expected 0..126)";
      return Class2ArgResult::Error;
    }
    opts.address = static_cast<std::uint8_t>(*n);
  }
  return Class2ArgResult::Taken;
}

struct Class2Cli::Impl {
  Impl(std::uint8_t addr, const fdl::BusParams& params)
      : master(dp::Class2Params{addr, 100}), station(addr, params, master) {}
  dp::Class2Master master;
  fdl::ActiveStation station;
  bus::Scheduler* sched = nullptr;
  std::set<std::uint8_t> c2_busy;  ///< slaves with a read/write session (initiate .. abort)
};

Class2Cli::Class2Cli(std::unique_ptr<Impl> impl) : m_impl(std::move(impl)) {}
Class2Cli::~Class2Cli() = default;

std::uint8_t Class2Cli::address() const { return m_impl->master.address(); }

std::unique_ptr<Class2Cli> Class2Cli::attach(Simulation& sim, const Class2Options& opts,
                                             std::string& error) {
  const ScenarioPlan& plan = sim.plan();
  if (plan.lines.empty()) {
    error = "--dp2: the scenario has no line";
    return nullptr;
  }
  std::size_t li = 0;
  if (opts.line) {
    li = plan.lines.size();
    for (std::size_t k = 0; k < plan.lines.size(); ++k)
      if (plan.lines[k].name == *opts.line) li = k;
    if (li == plan.lines.size()) {
      error = "--dp2-line: no line named '" + *opts.line + "' in the scenario";
      return nullptr;
    }
  }
  const PlanLine& pl = plan.lines[li];
  std::set<std::uint8_t> used;
  for (const PlanStation& ps : pl.stations)
    if (ps.address) used.insert(*ps.address);
  std::uint8_t addr = 0;
  if (opts.address) {
    addr = *opts.address;
    if (used.count(addr)) {
      error = "--dp2-address " + std::to_string(addr) + " is in use on line '" + pl.name + "'";
      return nullptr;
    }
    if (addr > pl.params.hsa) {
      error = "--dp2-address " + std::to_string(addr) + " is above the line's HSA " +
              std::to_string(pl.params.hsa) + " (a master there never gets the token)";
      return nullptr;
    }
  } else {
    while (addr <= pl.params.hsa && used.count(addr)) ++addr;
    if (addr > pl.params.hsa) {
      error = "--dp2: no free address up to HSA " + std::to_string(pl.params.hsa) + " on line '" +
              pl.name + "'";
      return nullptr;
    }
  }
  auto impl = std::make_unique<Impl>(addr, pl.params);
  impl->sched = &sim.scheduler();
  sim.line(li).attach(impl->station, "class-2 master " + std::to_string(addr));
  std::unique_ptr<Class2Cli> c(new Class2Cli(std::move(impl)));
  c->m_line_name = pl.name;
  c->m_requests = opts.requests;
  c->m_outcomes.resize(c->m_requests.size());
  for (std::size_t k = 0; k < c->m_requests.size(); ++k) {
    const Class2Request& r = c->m_requests[k];
    Class2Outcome& o = c->m_outcomes[k];
    o.at = r.at;
    o.op = r.op;
    o.station = r.station;
    o.status = "pending";
    Class2Cli* self = c.get();
    sim.scheduler().schedule(r.at, [self, k] { self->submit(k); });
  }
  return c;
}

void Class2Cli::record(std::size_t k, const void* result, const char* prefix) {
  const auto& r = *static_cast<const dp::Class2Result*>(result);
  Class2Outcome& o = m_outcomes[k];
  o.done = m_impl->sched->now();
  o.status = std::string(prefix) + (r.ok() ? std::string("OK") : std::string(dp::to_string(r.status)));
  const bool reads_data = o.op == Class2Op::GetCfg || o.op == Class2Op::SlaveDiag ||
                          o.op == Class2Op::RdInp || o.op == Class2Op::RdOutp || o.op == Class2Op::Read;
  if (r.ok() && reads_data && r.data.empty()) {
    o.status = std::string(prefix) + (r.short_ack ? "no data (SC)" : "no data");
    return;
  }
  if (r.status == dp::AcyclicStatus::NotAvailable || r.status == dp::AcyclicStatus::InvalidResponse)
    o.status += " (" + std::string(fdl::to_string(r.fdl_status)) + ")";
  if (r.status == dp::AcyclicStatus::Negative) {
    o.text = dp::describe(r.error);
    return;
  }
  if (!r.ok()) return;
  o.bytes = r.data;
  switch (o.op) {
    case Class2Op::GetCfg:
      o.text = std::to_string(r.inputs) + " B in, " + std::to_string(r.outputs) + " B out";
      break;
    case Class2Op::SlaveDiag:
      o.text = dp::describe_diag(r.data);
      break;
    case Class2Op::RdInp:
    case Class2Op::RdOutp:
    case Class2Op::Read:
      o.text = std::to_string(r.data.size()) + " B";
      break;
    case Class2Op::SetSlaveAdd:
    case Class2Op::Write:
      o.bytes.clear();  // the response PDU of a write echoes the request; the status says it all
      break;
  }
}

void Class2Cli::submit(std::size_t k) {
  const Class2Request& r = m_requests[k];
  dp::Class2Master& m = m_impl->master;
  auto done = [this, k](const dp::Class2Result& res) { record(k, &res, ""); };
  std::uint32_t id = 0;
  switch (r.op) {
    case Class2Op::GetCfg: id = m.get_cfg(r.station, done); break;
    case Class2Op::SlaveDiag: id = m.slave_diag(r.station, done); break;
    case Class2Op::RdInp: id = m.rd_inp(r.station, done); break;
    case Class2Op::RdOutp: id = m.rd_outp(r.station, done); break;
    case Class2Op::SetSlaveAdd:
      id = m.set_slave_add(r.station, r.new_address, r.ident, r.no_add_chg, done);
      break;
    case Class2Op::Read:
    case Class2Op::Write:
      if (m_impl->c2_busy.count(r.station) || m.c2_open(r.station)) {
        // An earlier read/write to this slave still holds the connection: try again later.
        m_impl->sched->schedule(m_impl->sched->now() + kC2RetryDelay, [this, k] { submit(k); });
        return;
      }
      m_impl->c2_busy.insert(r.station);
      id = m.c2_initiate(r.station, [this, k](const dp::Class2Result& ini) {
        if (!ini.ok()) {
          record(k, &ini, "initiate: ");
          m_impl->c2_busy.erase(m_requests[k].station);
          return;
        }
        const Class2Request& rq = m_requests[k];
        dp::Class2Master& mm = m_impl->master;
        auto then_abort = [this, k](const dp::Class2Result& res) {
          record(k, &res, "");
          const std::uint8_t st = m_requests[k].station;
          if (!m_impl->master.c2_open(st) ||
              m_impl->master.c2_abort(st, [this, st](const dp::Class2Result&) { m_impl->c2_busy.erase(st); }) == 0)
            m_impl->c2_busy.erase(st);
        };
        const std::uint32_t rid =
            rq.op == Class2Op::Read ? mm.c2_read(rq.station, rq.slot, rq.index, rq.length, then_abort)
                                    : mm.c2_write(rq.station, rq.slot, rq.index, rq.data, then_abort);
        if (rid == 0) {
          m_outcomes[k].status = "rejected by the class-2 master";
          m_impl->c2_busy.erase(rq.station);
        }
      });
      break;
  }
  if (id == 0 && (r.op == Class2Op::Read || r.op == Class2Op::Write)) m_impl->c2_busy.erase(r.station);
  if (id == 0) m_outcomes[k].status = "rejected by the class-2 master (own address or open connection)";
}

std::string format_class2_line(const Class2Outcome& o) {
  std::string s = format_time(o.at) + " " + std::string(to_string(o.op)) + " " + std::to_string(o.station) +
                  ": " + o.status;
  if (!o.bytes.empty()) s += " " + hex_spaced(o.bytes);
  if (!o.text.empty()) s += " (" + o.text + ")";
  if (o.done) s += " at " + format_time(o.done);
  return s;
}

void Class2Cli::write_text(std::ostream& os) const {
  os << "class-2 master " << static_cast<int>(address()) << " on " << m_line_name << ":\n";
  for (const Class2Outcome& o : m_outcomes) os << "  " << format_class2_line(o) << "\n";
}

std::string Class2Cli::json() const {
  std::string j = "[";
  for (std::size_t k = 0; k < m_outcomes.size(); ++k) {
    const Class2Outcome& o = m_outcomes[k];
    if (k) j += ",";
    j += "{\"time_ns\":" + std::to_string(bus::ticks_to_ns(o.at)) + ",\"done_ns\":" +
         (o.done ? std::to_string(bus::ticks_to_ns(o.done)) : std::string("null")) + ",\"service\":\"" +
         std::string(to_string(o.op)) + "\",\"station\":" + std::to_string(o.station) +
         ",\"master\":" + std::to_string(address()) + ",\"status\":" + json_quote(o.status) +
         ",\"bytes\":\"" + hex_plain(o.bytes) + "\",\"text\":" + json_quote(o.text) + "}";
  }
  return j + "]";
}

void Class2Cli::add_to_json(std::string& report_json) const {
  const std::size_t p = report_json.rfind('}');
  if (p == std::string::npos) return;
  report_json.insert(p, ",\"class2\":" + json());
}

}  // namespace pbvbus::tools
