// The loader's S7 checks (s7_plan.hpp has the rules).
#include "pbvbus/scenario/s7_plan.hpp"

#include <cctype>
#include <charconv>
#include <map>
#include <set>

#include "pbvbus/s7h/h_program.hpp"
#include "pbvbus/scenario/scenario.hpp"

namespace pbvbus::tools {


namespace {

constexpr std::uint32_t kMaxArea = 16 * 1024;  // the largest S7-400 process image
constexpr std::uint32_t kMaxConnections = 64;

/// Parses a decimal number at text[pos..); advances pos. nullopt without digits or on overflow.
std::optional<std::uint32_t> number(const std::string& text, std::size_t& pos) {
  std::uint32_t v = 0;
  const char* b = text.data() + pos;
  auto [p, ec] = std::from_chars(b, text.data() + text.size(), v);
  if (ec != std::errc() || p == b) return std::nullopt;
  pos += static_cast<std::size_t>(p - b);
  return v;
}

std::optional<std::uint8_t> width_of(char c) {
  switch (c) {
    case 'B': return 1;
    case 'W': return 2;
    case 'D': return 4;
    default: return std::nullopt;
  }
}

}  // namespace

std::string S7ItemPlan::str() const {
  const char w = width == 1 ? 'B' : width == 2 ? 'W' : 'D';
  std::string s;
  switch (area) {
    case Area::Db: s = "DB" + std::to_string(db) + ".DB" + w; break;
    case Area::Inputs: s = std::string("I") + w; break;
    case Area::Outputs: s = std::string("Q") + w; break;
    case Area::Flags: s = std::string("M") + w; break;
  }
  s += std::to_string(byte);
  if (count != 1) s += "," + std::to_string(count);
  return s;
}

std::string parse_s7_item(const std::string& raw, S7ItemPlan& out) {
  std::string text;
  for (char c : raw) text += static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
  const std::string syntax =
      " (expected DBn.DBB/DBW/DBDx, MB/MW/MDx, IB/IW/IDx or QB/QW/QDx with an optional \",N\", "
      "e.g. \"DB1.DBW2\" or \"MB0,4\")";
  S7ItemPlan it;
  std::size_t pos = 0;
  if (text.rfind("DB", 0) == 0) {
    pos = 2;
    const auto n = number(text, pos);
    if (!n || *n < 1 || *n > 65535) return "bad DB number in \"" + raw + "\"" + syntax;
    it.area = S7ItemPlan::Area::Db;
    it.db = static_cast<std::uint16_t>(*n);
    if (text.compare(pos, 3, ".DB") != 0) return "bad item \"" + raw + "\"" + syntax;
    pos += 3;
  } else if (!text.empty() && (text[0] == 'M' || text[0] == 'I' || text[0] == 'E' || text[0] == 'Q' ||
                               text[0] == 'A')) {
    // German mnemonics too (E = input, A = output), as STEP 7 users write them.
    it.area = text[0] == 'M'                     ? S7ItemPlan::Area::Flags
              : text[0] == 'I' || text[0] == 'E' ? S7ItemPlan::Area::Inputs
                                                 : S7ItemPlan::Area::Outputs;
    pos = 1;
  } else {
    return "bad item \"" + raw + "\"" + syntax;
  }
  const auto w = pos < text.size() ? width_of(text[pos]) : std::nullopt;
  if (!w) return "bad item \"" + raw + "\": no width B, W or D" + syntax;
  it.width = *w;
  ++pos;
  const auto byte = number(text, pos);
  if (!byte || *byte > 65535) return "bad byte address in \"" + raw + "\"" + syntax;
  it.byte = *byte;
  if (pos < text.size() && text[pos] == ',') {
    ++pos;
    const auto c = number(text, pos);
    if (!c || *c < 1 || *c > 65535) return "bad element count in \"" + raw + "\"" + syntax;
    it.count = static_cast<std::uint16_t>(*c);
  }
  if (pos != text.size()) return "bad item \"" + raw + "\"" + syntax;
  out = it;
  return "";
}

std::vector<std::pair<std::uint8_t, std::string>> S7Plan::cpus_on(int line) const {
  std::vector<std::pair<std::uint8_t, std::string>> out;
  for (const auto& c : cpus)
    if (c.mpi_line == line) out.emplace_back(c.mpi_address, "s7_cpu \"" + c.name + "\"");
  for (const auto& h : h_mpi)
    if (h.line == line)
      for (int r = 0; r < 2; ++r)
        out.emplace_back(h.address[r], "CPU " + std::to_string(r) + " of an h_system");
  return out;
}

namespace {

class S7Planner {
 public:
  S7Planner(ScenarioPlan& plan, const S7Locator& locate, std::vector<Diagnostic>& errors)
      : m_plan(plan), m_proto(plan.proto), m_locate(locate), m_errors(errors) {}

  void run() {
    index_lines();
    for (int i = 0; i < m_proto.s7_cpu_size(); ++i) plan_cpu(i);
    for (int i = 0; i < m_proto.h_system_size(); ++i) plan_h_mpi(i);
    for (int i = 0; i < m_proto.mpi_station_size(); ++i) plan_station(i);
    collect_gateway_ports();
    for (int i = 0; i < m_proto.s7_door_size(); ++i) plan_door(i);
  }

 private:
  using Path = std::vector<std::pair<const char*, int>>;

  void error(const char* rep, int index, const Path& path, std::string msg) {
    const auto [line, col] = m_locate(rep, index, path);
    m_errors.push_back({m_plan.file, line, col, std::move(msg)});
  }

  void index_lines() {
    for (std::size_t i = 0; i < m_plan.lines.size(); ++i)
      m_line.emplace(m_plan.lines[i].name, static_cast<int>(i));
  }
  int line_index(const std::string& name) const {
    auto it = m_line.find(name);
    return it == m_line.end() ? -1 : it->second;
  }

  /// X1 in DP mode or X2: the dp_master entry the interface is.
  std::optional<CpuDpPlan> dp_interface(int i, const char* field, const scenario::CpuInterface& ci) {
    // X2 is DP whatever its `mode` says (the field matters for X1 only).
    const Path at{{field, -1}};
    const int li = line_index(ci.line());
    if (ci.line().empty() || li < 0) {
      error("s7_cpu", i, {{field, -1}, {"line", -1}},
            ci.line().empty() ? "a DP interface needs the line of its dp_master"
                              : "unknown line \"" + ci.line() + "\"");
      return std::nullopt;
    }
    if (!ci.has_address()) {
      error("s7_cpu", i, at, "a DP interface needs `address`: the dp_master entry it is");
      return std::nullopt;
    }
    for (std::size_t m = 0; m < m_plan.dp_masters.size(); ++m) {
      const auto& dm = m_proto.dp_master(static_cast<int>(m));
      if (dm.line() != ci.line() || !dm.has_address() || dm.address() != ci.address()) continue;
      const auto key = static_cast<int>(m);
      if (!m_dp_owner.emplace(key, m_proto.s7_cpu(i).name()).second) {
        error("s7_cpu", i, {{field, -1}, {"address", -1}},
              "dp_master " + std::to_string(ci.address()) + " on line \"" + ci.line() +
                  "\" is already the DP interface of s7_cpu \"" + m_dp_owner[key] + "\"");
        return std::nullopt;
      }
      return CpuDpPlan{li, static_cast<std::uint8_t>(ci.address()), key};
    }
    error("s7_cpu", i, {{field, -1}, {"address", -1}},
          "no dp_master " + std::to_string(ci.address()) + " on line \"" + ci.line() +
              "\" for this DP interface");
    return std::nullopt;
  }

  void plan_cpu(int i) {
    const auto& c = m_proto.s7_cpu(i);
    S7CpuPlan p;
    p.source = i;
    p.name = c.name();
    p.order_number = c.order_number().empty() ? "6ES7 315-2AG10-0AB0" : c.order_number();
    if (c.name().empty()) error("s7_cpu", i, {}, "s7_cpu needs a name");
    else if (!m_cpu_names.insert(c.name()).second)
      error("s7_cpu", i, {{"name", -1}}, "s7_cpu \"" + c.name() + "\" is defined twice");
    if (p.order_number.size() > 20)
      error("s7_cpu", i, {{"order_number", -1}},
            "order_number has " + std::to_string(p.order_number.size()) +
                " characters; SZL W#16#0011 holds 20");
    if (!c.has_mpi_dp() && !c.has_dp())
      error("s7_cpu", i, {}, "s7_cpu \"" + c.name() + "\" has no interface (mpi_dp or dp)");
    if (c.has_mpi_dp()) {
      if (c.mpi_dp().mode() == scenario::CpuInterface::MPI) {
        p.mpi_line = line_index(c.mpi_dp().line());  // the station check reported a bad line
        p.mpi_address = static_cast<std::uint8_t>(c.mpi_dp().has_address() ? c.mpi_dp().address() : 2);
      } else {
        p.x1_dp = dp_interface(i, "mpi_dp", c.mpi_dp());
      }
    }
    if (c.has_dp()) p.x2_dp = dp_interface(i, "dp", c.dp());
    std::set<std::uint32_t> numbers;
    for (int k = 0; k < c.db_size(); ++k) {
      const auto& db = c.db(k);
      if (!db.has_number() || db.number() < 1 || db.number() > 65535) {
        error("s7_cpu", i, {{"db", k}, {"number", -1}}, "a DB needs a number 1..65535");
        continue;
      }
      if (!numbers.insert(db.number()).second) {
        error("s7_cpu", i, {{"db", k}, {"number", -1}},
              "DB " + std::to_string(db.number()) + " is defined twice");
        continue;
      }
      if (!db.has_size() || db.size() < 1 || db.size() > 65534) {
        error("s7_cpu", i, {{"db", k}, {"size", -1}},
              "DB " + std::to_string(db.number()) + " needs a size 1..65534 bytes");
        continue;
      }
      p.dbs.push_back({static_cast<std::uint16_t>(db.number()), db.size()});
    }
    const auto area = [&](const char* field, bool has, std::uint32_t v, std::uint32_t& out) {
      if (!has) return;
      if (v > kMaxArea)
        error("s7_cpu", i, {{field, -1}},
              std::string(field) + " " + std::to_string(v) + " is over 16384");
      else
        out = v;
    };
    area("input_bytes", c.has_input_bytes(), c.input_bytes(), p.input_bytes);
    area("output_bytes", c.has_output_bytes(), c.output_bytes(), p.output_bytes);
    area("flag_bytes", c.has_flag_bytes(), c.flag_bytes(), p.flag_bytes);
    if (c.has_max_connections()) {
      if (c.max_connections() < 1 || c.max_connections() > kMaxConnections)
        error("s7_cpu", i, {{"max_connections", -1}}, "max_connections must be 1..64");
      else
        p.max_connections = c.max_connections();
    }
    p.run = c.mode() == scenario::S7Cpu::RUN;
    if (c.has_program()) {
      devices::ProgramSpec spec;
      bool good = true;
      plan_program_spec(c.program(), spec, [&](std::vector<HPathStep> path, std::string msg) {
        Path at{{"program", -1}};
        for (const auto& st : path) at.emplace_back(st.field, st.index);
        error("s7_cpu", i, at, std::move(msg));
        good = false;
      });
      // SFC 11/12 name one of this CPU's DP interfaces by its line (docs/h-dp-sfc.md).
      auto dp_line = [&](const std::string& l) {
        return (c.has_mpi_dp() && c.mpi_dp().mode() == scenario::CpuInterface::DP && c.mpi_dp().line() == l) ||
               (c.has_dp() && c.dp().line() == l);
      };
      auto check_line = [&](const char* list, int k, const std::string& l, const char* sfc) {
        if (dp_line(l)) return;
        error("s7_cpu", i, {{"program", -1}, {list, k}, {"line", -1}},
              std::string(sfc) + ": line \"" + l + "\" is not a DP interface of s7_cpu \"" + c.name() + "\"");
        good = false;
      };
      for (int k = 0; k < c.program().dpsyc_fr_size(); ++k)
        check_line("dpsyc_fr", k, c.program().dpsyc_fr(k).line(), "SFC 11");
      for (int k = 0; k < c.program().d_act_dp_size(); ++k)
        check_line("d_act_dp", k, c.program().d_act_dp(k).line(), "SFC 12");
      if (good) {
        const auto why = devices::validate(spec, p.input_bytes, p.output_bytes);
        if (!why.empty()) error("s7_cpu", i, {{"program", -1}}, "program: " + why.front());
        else p.program = std::move(spec);
      }
    }
    m_plan.s7.cpus.push_back(std::move(p));
  }

  void plan_h_memory(int i) {
    const auto& h = m_proto.h_system(i);
    if (!h.has_cpu()) return;
    HS7Plan p;
    for (std::size_t k = 0; k < m_plan.h_systems.size(); ++k)
      if (m_plan.h_systems[k].source == i) p.h_system = static_cast<int>(k);
    const auto& m = h.cpu().s7_memory();
    if (m.has_flag_bytes()) {
      if (m.flag_bytes() > kMaxArea)
        error("h_system", i, {{"cpu", -1}, {"s7_memory", -1}, {"flag_bytes", -1}},
              "flag_bytes " + std::to_string(m.flag_bytes()) + " is over 16384");
      else
        p.memory.flags = m.flag_bytes();
    }
    std::set<std::uint32_t> numbers;
    for (int k = 0; k < m.db_size(); ++k) {
      const auto& db = m.db(k);
      const Path at{{"cpu", -1}, {"s7_memory", -1}, {"db", k}};
      if (!db.has_number() || db.number() < 1 || db.number() > 65535 || !numbers.insert(db.number()).second) {
        Path f = at;
        f.push_back({"number", -1});
        error("h_system", i, f,
              db.has_number() && db.number() >= 1 && db.number() <= 65535
                  ? "DB " + std::to_string(db.number()) + " is defined twice"
                  : "a DB needs a number 1..65535");
        continue;
      }
      if (!db.has_size() || db.size() < 1 || db.size() > 65534) {
        Path f = at;
        f.push_back({"size", -1});
        error("h_system", i, f, "DB " + std::to_string(db.number()) + " needs a size 1..65534 bytes");
        continue;
      }
      p.memory.dbs.push_back({static_cast<std::uint16_t>(db.number()), db.size()});
    }
    m_plan.s7.h_memory.push_back(std::move(p));
  }

  void plan_h_mpi(int i) {
    const auto& h = m_proto.h_system(i);
    plan_h_memory(i);
    if (!h.has_cpu() || !h.cpu().has_mpi()) return;
    const auto& m = h.cpu().mpi();
    HMpiPlan p;
    for (std::size_t k = 0; k < m_plan.h_systems.size(); ++k)
      if (m_plan.h_systems[k].source == i) p.h_system = static_cast<int>(k);
    p.line = line_index(m.line());
    p.address[0] = static_cast<std::uint8_t>(m.has_address_cpu0() ? m.address_cpu0() : 2);
    p.address[1] = static_cast<std::uint8_t>(m.has_address_cpu1() ? m.address_cpu1() : 3);
    if (p.address[0] == p.address[1])
      error("h_system", i, {{"cpu", -1}, {"mpi", -1}, {"address_cpu1", -1}},
            "both CPUs have MPI address " + std::to_string(p.address[0]) +
                ": CPU 1 differs from CPU 0 in its MPI address");
    if (m.has_max_connections()) {
      if (m.max_connections() < 1 || m.max_connections() > kMaxConnections)
        error("h_system", i, {{"cpu", -1}, {"mpi", -1}, {"max_connections", -1}},
              "max_connections must be 1..64");
      else
        p.max_connections = m.max_connections();
    }
    // The pair counts its ad-hoc connections against this (HCpuPair::connect).
    if (p.h_system >= 0 && m_plan.h_systems[static_cast<std::size_t>(p.h_system)].runtime)
      m_plan.h_systems[static_cast<std::size_t>(p.h_system)].runtime->pair.max_connections =
          static_cast<int>(p.max_connections);
    m_plan.s7.h_mpi.push_back(p);
  }

  /// Whether MPI address `a` on line `li` is an S7 CPU's.
  bool cpu_at(int li, std::uint32_t a) const {
    for (const auto& [addr, who] : m_plan.s7.cpus_on(li))
      if (addr == a) return true;
    return false;
  }

  void plan_station(int i) {
    const auto& s = m_proto.mpi_station(i);
    MpiStationPlan p;
    p.source = i;
    p.op = s.role() == scenario::MpiStation::OP;
    p.line = line_index(s.line());
    p.address = static_cast<std::uint8_t>(s.has_address() ? s.address() : (p.op ? 1 : 0));
    for (int k = 0; k < s.read_size(); ++k) {
      const auto& r = s.read(k);
      S7PollPlan rp;
      if (!r.has_cpu()) {
        error("mpi_station", i, {{"read", k}}, "a read needs `cpu`: the CPU's MPI address");
        continue;
      }
      if (p.line >= 0 && !cpu_at(p.line, r.cpu())) {
        error("mpi_station", i, {{"read", k}, {"cpu", -1}},
              "no S7 CPU at MPI address " + std::to_string(r.cpu()) + " on line \"" + s.line() + "\"");
        continue;
      }
      rp.cpu = static_cast<std::uint8_t>(r.cpu());
      if (std::string why = parse_s7_item(r.item(), rp.item); !why.empty()) {
        error("mpi_station", i, {{"read", k}, {"item", -1}}, why);
        continue;
      }
      if (!r.period().empty()) {
        const auto t = bus::parse_duration(r.period());
        if (!t || *t <= 0) {
          error("mpi_station", i, {{"read", k}, {"period", -1}},
                "bad period \"" + r.period() + "\" (a duration > 0, e.g. \"100ms\")");
          continue;
        }
        rp.period = *t;
      }
      p.reads.push_back(rp);
    }
    m_plan.s7.stations.push_back(std::move(p));
  }

  void collect_gateway_ports() {
    for (const auto& g : m_plan.gateways) {
      for (const auto* e : {&g.modbus_tcp}) if (*e && (*e)->port != 0) m_ports.insert((*e)->port);
      if (g.can) {
        if (g.can->slcan_tcp && g.can->slcan_tcp->port != 0) m_ports.insert(g.can->slcan_tcp->port);
        if (g.can->socketcand && g.can->socketcand->port != 0) m_ports.insert(g.can->socketcand->port);
      }
    }
  }

  void plan_door(int i) {
    const auto& d = m_proto.s7_door(i);
    S7DoorPlan p;
    p.source = i;
    p.name = d.name();
    if (d.name().empty()) error("s7_door", i, {}, "s7_door needs a name");
    else if (!m_door_names.insert(d.name()).second)
      error("s7_door", i, {{"name", -1}}, "s7_door \"" + d.name() + "\" is defined twice");
    if (!d.listen().empty()) {
      if (auto ep = parse_endpoint(d.listen())) {
        p.listen = *ep;
      } else {
        p.listen.port = 0;  // no second message about the default port
        error("s7_door", i, {{"listen", -1}},
              "bad listen \"" + d.listen() + "\" (expected HOST:PORT with a numeric IPv4 "
              "address or [IPv6] and a port 0..65535, e.g. \"127.0.0.1:10102\")");
      }
    }
    if (p.listen.port != 0 && !m_ports.insert(p.listen.port).second)
      error("s7_door", i, {{"listen", -1}},
            "port " + std::to_string(p.listen.port) + " is used twice in the file");
    p.max_connections = d.max_connections();
    if (!d.idle_timeout().empty()) {
      const auto t = bus::parse_duration(d.idle_timeout());
      if (!t || *t <= 0)
        error("s7_door", i, {{"idle_timeout", -1}},
              "bad idle_timeout \"" + d.idle_timeout() + "\" (a duration > 0, e.g. \"60s\")");
      else
        p.idle_timeout = *t;
    }
    if (!d.mpi_line().empty()) {
      p.mpi_line = line_index(d.mpi_line());
      if (p.mpi_line >= 0) {
        const auto& line = m_plan.lines[static_cast<std::size_t>(p.mpi_line)];
        for (const auto& st : line.stations)
          if (st.kind == StationKind::S7DoorMpi && st.source == i && st.address)
            p.mpi_address = *st.address;
      }
    }
    if (d.route_size() == 0) error("s7_door", i, {}, "s7_door \"" + d.name() + "\" has no route");
    std::set<std::pair<std::uint32_t, std::uint32_t>> seen;
    for (int k = 0; k < d.route_size(); ++k) plan_route(i, k, d, p, seen);
    m_plan.s7.doors.push_back(std::move(p));
  }

  void plan_route(int i, int k, const scenario::S7Door& d, S7DoorPlan& p,
                  std::set<std::pair<std::uint32_t, std::uint32_t>>& seen) {
    const auto& r = d.route(k);
    S7RoutePlan rp;
    if (!r.has_rack() || r.rack() > 7) {
      error("s7_door", i, {{"route", k}, {"rack", -1}}, "a route needs a rack 0..7");
      return;
    }
    if (!r.has_slot() || r.slot() > 31) {
      error("s7_door", i, {{"route", k}, {"slot", -1}}, "a route needs a slot 0..31");
      return;
    }
    if (!seen.insert({r.rack(), r.slot()}).second) {
      error("s7_door", i, {{"route", k}},
            "rack " + std::to_string(r.rack()) + " slot " + std::to_string(r.slot()) +
                " is routed twice in s7_door \"" + d.name() + "\"");
      return;
    }
    rp.rack = static_cast<std::uint8_t>(r.rack());
    rp.slot = static_cast<std::uint8_t>(r.slot());
    switch (r.target_case()) {
      case scenario::S7Route::kCpu: {
        rp.kind = S7RoutePlan::Kind::Cpu;
        for (std::size_t c = 0; c < m_plan.s7.cpus.size(); ++c)
          if (m_plan.s7.cpus[c].name == r.cpu()) rp.target = static_cast<int>(c);
        if (rp.target < 0) {
          error("s7_door", i, {{"route", k}, {"cpu", -1}}, "unknown s7_cpu \"" + r.cpu() + "\"");
          return;
        }
        break;
      }
      case scenario::S7Route::kHSystem: {
        rp.kind = S7RoutePlan::Kind::HSystem;
        for (std::size_t h = 0; h < m_plan.h_systems.size(); ++h)
          if (m_plan.h_systems[h].name == r.h_system()) rp.target = static_cast<int>(h);
        if (rp.target < 0) {
          error("s7_door", i, {{"route", k}, {"h_system", -1}},
                "unknown h_system \"" + r.h_system() + "\"");
          return;
        }
        const auto& hs = m_plan.h_systems[static_cast<std::size_t>(rp.target)];
        if (!hs.runtime) {
          error("s7_door", i, {{"route", k}, {"h_system", -1}},
                "h_system \"" + r.h_system() + "\" has no `cpu` part: nothing answers S7");
          return;
        }
        if (!r.connection().empty()) {
          const auto& cs = hs.runtime->connections;
          for (std::size_t c = 0; c < cs.size(); ++c)
            if (cs[c].name == r.connection()) rp.connection = static_cast<int>(c);
          if (rp.connection < 0) {
            error("s7_door", i, {{"route", k}, {"connection", -1}},
                  "h_system \"" + r.h_system() + "\" has no connection \"" + r.connection() + "\"");
            return;
          }
        }
        break;
      }
      case scenario::S7Route::kMpiAddress: {
        rp.kind = S7RoutePlan::Kind::Mpi;
        if (p.mpi_line < 0) {
          error("s7_door", i, {{"route", k}, {"mpi_address", -1}},
                "a route over MPI needs the door's `mpi_line` (a line of kind MPI)");
          return;
        }
        if (!cpu_at(p.mpi_line, r.mpi_address())) {
          error("s7_door", i, {{"route", k}, {"mpi_address", -1}},
                "no S7 CPU at MPI address " + std::to_string(r.mpi_address()) + " on line \"" +
                    d.mpi_line() + "\"");
          return;
        }
        rp.mpi_address = static_cast<std::uint8_t>(r.mpi_address());
        break;
      }
      default:
        error("s7_door", i, {{"route", k}}, "a route needs a target: cpu, h_system or mpi_address");
        return;
    }
    if (!r.connection().empty() && rp.kind != S7RoutePlan::Kind::HSystem)
      error("s7_door", i, {{"route", k}, {"connection", -1}},
            "`connection` is for h_system routes only");
    p.routes.push_back(rp);
  }

  ScenarioPlan& m_plan;
  const scenario::Scenario& m_proto;
  const S7Locator& m_locate;
  std::vector<Diagnostic>& m_errors;
  std::map<std::string, int> m_line;
  std::set<std::string> m_cpu_names, m_door_names;
  std::map<int, std::string> m_dp_owner;
  std::set<std::uint16_t> m_ports;
};

}  // namespace

void plan_s7(ScenarioPlan& plan, const S7Locator& locate, std::vector<Diagnostic>& errors) {
  S7Planner(plan, locate, errors).run();
}

}  // namespace pbvbus::tools
