// The loader's Quantum Hot Standby checks (quantum_plan.hpp has the rules).
#include "pbvbus/scenario/quantum_plan.hpp"

#include <algorithm>
#include <map>
#include <set>

#include "pbvbus/scenario/scenario.hpp"

namespace pbvbus::tools {

namespace {

using Path = std::vector<std::pair<const char*, int>>;
using quantum::RefType;

constexpr std::uint32_t kMaxRefs = 65535;

std::string ref_name(RefType t) {
  switch (t) {
    case RefType::Coil0x: return "0x";
    case RefType::Input1x: return "1x";
    case RefType::Register3x: return "3x";
    case RefType::Register4x: return "4x";
  }
  return "?";
}

/// References of `t` that `octets` octets of process data take (registers: 2 octets each,
/// bits: 8 each).
std::uint32_t refs_for(RefType t, std::uint32_t octets) {
  return t == RefType::Register3x || t == RefType::Register4x ? (octets + 1) / 2 : octets * 8;
}

class QuantumPlanner {
 public:
  QuantumPlanner(ScenarioPlan& plan, const S7Locator& locate, std::vector<Diagnostic>& errors)
      : m_plan(plan), m_proto(plan.proto), m_locate(locate), m_errors(errors) {}

  void run() {
    for (std::size_t i = 0; i < m_plan.lines.size(); ++i)
      m_line.emplace(m_plan.lines[i].name, static_cast<int>(i));
    for (const auto& g : m_plan.gateways) {
      if (g.modbus_tcp && g.modbus_tcp->port != 0) m_ports.insert(g.modbus_tcp->port);
      if (g.can && g.can->slcan_tcp && g.can->slcan_tcp->port != 0) m_ports.insert(g.can->slcan_tcp->port);
      if (g.can && g.can->socketcand && g.can->socketcand->port != 0)
        m_ports.insert(g.can->socketcand->port);
      for (const auto& r : g.modbus_rtu)
        if (!r.link.empty()) m_links.insert(r.link);
    }
    for (const auto& d : m_plan.s7.doors)
      if (d.listen.port != 0) m_ports.insert(d.listen.port);
    std::set<std::string> names;
    for (int i = 0; i < m_proto.quantum_hot_standby_size(); ++i) {
      const auto& q = m_proto.quantum_hot_standby(i);
      if (q.name().empty())
        error(i, {{"name", -1}}, "quantum_hot_standby needs a name");
      else if (!names.insert(q.name()).second)
        error(i, {{"name", -1}}, "quantum_hot_standby \"" + q.name() + "\" is defined twice");
      plan_one(i, q);
    }
  }

 private:
  void error(int index, const Path& path, std::string msg) {
    const auto [line, col] = m_locate("quantum_hot_standby", index, path);
    m_errors.push_back({m_plan.file, line, col, std::move(msg)});
  }

  std::optional<bus::Ticks> duration(int i, const Path& path, const std::string& text) {
    auto t = bus::parse_duration(text);
    if (!t) error(i, path, "bad duration \"" + text + "\" (e.g. \"20ms\", \"1.5s\")");
    return t;
  }

  std::optional<quantum::Reference> reference(int i, const Path& path, const std::string& text,
                                              std::initializer_list<RefType> allowed) {
    auto r = quantum::parse_reference(text);
    if (!r) {
      error(i, path, "bad reference \"" + text + "\" (expected e.g. \"400001\" or \"40001\")");
      return std::nullopt;
    }
    if (std::find(allowed.begin(), allowed.end(), r->type) == allowed.end()) {
      std::string list;
      for (RefType t : allowed) list += (list.empty() ? "" : " or ") + ref_name(t);
      error(i, path, "reference " + text + " is a " + ref_name(r->type) + " reference; " + list +
                         " expected here");
      return std::nullopt;
    }
    return r;
  }

  void plan_one(int i, const scenario::QuantumHotStandby& q) {
    QuantumPlan p;
    p.source = i;
    p.name = q.name();
    p.iec = q.iec();
    switch (q.cpu()) {
      case scenario::QuantumHotStandby::CPU_434_12:
      case scenario::QuantumHotStandby::CPU_534_14: p.cpu = quantum::CpuType::Cpu43412; break;
      case scenario::QuantumHotStandby::CPU_424_02: p.cpu = quantum::CpuType::Cpu42402; break;
      case scenario::QuantumHotStandby::CPU_X13: p.cpu = quantum::CpuType::X13; break;
      default: break;
    }
    plan_sizes(i, q, p);
    plan_transfer(i, q, p);
    p.keyswitch_override = q.keyswitch_override();
    p.standby_stays_on_logic_mismatch = q.standby_stays_on_logic_mismatch();
    p.allow_different_firmware = q.allow_different_firmware();
    p.exec_upgrade_while_running = q.exec_upgrade_while_running();
    plan_racks(i, q, p);
    plan_dp(i, q, p);
    plan_modbus(i, q, p);
    plan_logic(i, q, p);
    plan_scan(i, q, p);
    m_plan.quantum.push_back(std::move(p));
  }

  void plan_sizes(int i, const scenario::QuantumHotStandby& q, QuantumPlan& p) {
    const quantum::RefCounts b = quantum::baseline(p.cpu);
    p.sizes = {static_cast<std::uint32_t>(b.coils), static_cast<std::uint32_t>(b.inputs),
               static_cast<std::uint32_t>(b.input_regs), static_cast<std::uint32_t>(b.holding)};
    const auto& s = q.state_ram();
    auto take = [&](bool has, std::uint32_t v, std::uint32_t& out, const char* field, bool bits) {
      if (!has) return;
      if (v > kMaxRefs)
        error(i, {{"state_ram", -1}, {field, -1}}, std::string(field) + " " + std::to_string(v) +
                                                       " is above 65535");
      else if (bits && v % 16 != 0)
        error(i, {{"state_ram", -1}, {field, -1}},
              std::string(field) + " " + std::to_string(v) + " is not a multiple of 16");
      else
        out = v;
    };
    take(s.has_coils(), s.coils(), p.sizes.coils, "coils", true);
    take(s.has_inputs(), s.inputs(), p.sizes.inputs, "inputs", true);
    take(s.has_input_registers(), s.input_registers(), p.sizes.input_regs, "input_registers", false);
    take(s.has_holding_registers(), s.holding_registers(), p.sizes.holding, "holding_registers", false);
  }

  void plan_transfer(int i, const scenario::QuantumHotStandby& q, QuantumPlan& p) {
    quantum::TransferConfig& c = p.transfer;
    const auto& t = q.transfer();
    c.mode = t.mode() == scenario::QuantumTransfer::USER_DEFINED ? quantum::TransferConfig::Mode::UserDefined
             : t.mode() == scenario::QuantumTransfer::TRANSFER_ALL ? quantum::TransferConfig::Mode::TransferAll
                                                                  : quantum::TransferConfig::Mode::Default12K;
    c.coils = t.coils();
    c.inputs = t.inputs();
    c.input_regs = t.input_registers();
    c.holding = t.holding_registers();
    if (t.has_additional()) {
      const auto& a = t.additional();
      c.additional.enabled = true;
      c.additional.coils = a.coils();
      c.additional.inputs = a.inputs();
      c.additional.input_regs = a.input_registers();
      c.additional.holding = a.holding_registers();
      c.additional.scans = static_cast<int>(a.scans());
    }
    c.iec = p.iec;
    c.iec_heap_bytes = static_cast<std::uint32_t>(std::min<std::uint64_t>(q.iec_heap_bytes(), 0xFFFFFFFFu));
    bool refs_ok = true;
    c.command_register = 0;
    if (!q.command_register().empty()) {
      if (auto r = reference(i, {{"command_register", -1}}, q.command_register(), {RefType::Register4x}))
        c.command_register = r->index;
      else
        refs_ok = false;
    }
    p.command_register = c.command_register;
    if (q.has_non_transfer()) {
      const auto& n = q.non_transfer();
      if (auto r = reference(i, {{"non_transfer", -1}, {"start", -1}}, n.start(), {RefType::Register4x})) {
        c.non_transfer.first = r->index;
        c.non_transfer.count = n.length();
      } else {
        refs_ok = false;
      }
    }
    if (!refs_ok) return;
    const quantum::TransferPlanResult r = quantum::plan_transfer(c, p.sizes);
    if (!r.plan) {
      // The rule's own sentence, at the field it concerns.
      const std::string& e = r.error;
      Path at = {{"transfer", -1}};
      if (e.find("command register") != std::string::npos) at = {{"command_register", -1}};
      else if (e.find("non-transfer") != std::string::npos || e.find("nontransfer") != std::string::npos)
        at = {{"non_transfer", -1}};
      else if (e.find("IEC") != std::string::npos || e.find("128") != std::string::npos)
        at = {{"iec", -1}};
      error(i, at, e);
      return;
    }
    p.plan = *r.plan;
  }

  void plan_racks(int i, const scenario::QuantumHotStandby& q, QuantumPlan& p) {
    p.racks[0].power_on_at = 0;
    p.racks[1].power_on_at = 100 * bus::kTicksPerMs;
    p.racks[1].designation_b = true;
    if (q.rack_size() > 2) error(i, {{"rack", 2}}, "a Hot Standby pair has two racks (rack 0, rack 1)");
    for (int r = 0; r < std::min(q.rack_size(), 2); ++r) {
      const auto& e = q.rack(r);
      QuantumRackPlan& rp = p.racks[static_cast<std::size_t>(r)];
      if (e.has_designation()) rp.designation_b = e.designation() == scenario::QuantumRack::B;
      rp.key = e.key() == scenario::QuantumRack::OFF_LINE ? QuantumRackPlan::Key::OffLine
               : e.key() == scenario::QuantumRack::XFER ? QuantumRackPlan::Key::Xfer
                                                        : QuantumRackPlan::Key::Run;
      if (!e.power_on_at().empty())
        if (auto t = duration(i, {{"rack", r}, {"power_on_at", -1}}, e.power_on_at())) rp.power_on_at = *t;
      if (e.has_logic_checksum()) rp.logic_checksum = e.logic_checksum();
      if (e.has_firmware()) rp.firmware = e.firmware();
      if (e.local_io_size() > 0)
        error(i, {{"rack", r}, {"local_io", 0}},
              "local I/O \"" + e.local_io(0) + "\" in a Hot Standby rack: only remote I/O is supported, "
              "local I/O is not carried across a switchover (seed 003 p. 17); put it on the DP line");
    }
  }

  /// The inclusive 4x range [a, b) the non-transfer area and the command register take.
  bool reserved_4x(const QuantumPlan& p, std::uint32_t first, std::uint32_t count) const {
    const auto& n = p.transfer.non_transfer;
    const std::uint32_t end = first + count;
    if (n.count > 0 && first < n.first + n.count && n.first < end) return true;
    return p.command_register >= first && p.command_register < end;
  }

  bool in_per_scan(const QuantumPlan& p, RefType t, std::uint32_t first, std::uint32_t count) const {
    for (const auto& r : p.plan.every_scan)
      if (r.type == t && first >= r.first && first + count <= r.first + r.count) return true;
    return false;
  }

  void plan_dp(int i, const scenario::QuantumHotStandby& q, QuantumPlan& p) {
    if (!q.has_dp()) return;
    const auto& d = q.dp();
    const auto it = m_line.find(d.line());
    if (d.line().empty()) {
      error(i, {{"dp", -1}, {"line", -1}}, "dp needs the line of the DP master module");
      return;
    }
    if (it == m_line.end()) {
      error(i, {{"dp", -1}, {"line", -1}}, "no line named \"" + d.line() + "\"");
      return;
    }
    if (m_plan.lines[static_cast<std::size_t>(it->second)].mpi) {
      error(i, {{"dp", -1}, {"line", -1}}, "line \"" + d.line() + "\" is an MPI line; the DP master modules need a PROFIBUS-DP line");
      return;
    }
    if (!d.has_address()) {
      error(i, {{"dp", -1}}, "dp needs the address of the dp_master that is both racks' DP master module");
      return;
    }
    for (std::size_t m = 0; m < m_plan.dp_masters.size(); ++m) {
      const auto& mp = m_plan.dp_masters[m];
      if (mp.line == it->second && mp.params.address == d.address()) p.dp_master = static_cast<int>(m);
    }
    if (p.dp_master < 0) {
      error(i, {{"dp", -1}, {"address", -1}}, "no dp_master with address " + std::to_string(d.address()) +
                                                 " on line \"" + d.line() + "\"");
      return;
    }
    for (const auto& other : m_plan.quantum)
      if (other.dp_master == p.dp_master)
        error(i, {{"dp", -1}, {"address", -1}}, "that dp_master is already the DP master module of \"" + other.name + "\"");
    for (const auto& g : m_plan.gateways)
      if (g.dp_master == p.dp_master)
        error(i, {{"dp", -1}, {"address", -1}}, "gateway \"" + g.name + "\" serves that dp_master; the pair's state RAM owns its outputs (use the pair's modbus_port instead)");
    for (const auto& c : m_plan.s7.cpus)
      if ((c.x1_dp && c.x1_dp->dp_master == p.dp_master) || (c.x2_dp && c.x2_dp->dp_master == p.dp_master))
        error(i, {{"dp", -1}, {"address", -1}}, "that dp_master is the DP interface of s7_cpu \"" + c.name + "\"");
    p.dp_line = it->second;
    p.dp_address = static_cast<std::uint8_t>(d.address());

    // The master's slaves, by address.
    std::map<std::uint8_t, int> slaves;
    for (std::size_t s = 0; s < m_plan.dp_slaves.size(); ++s) {
      const auto& sp = m_plan.dp_slaves[s];
      if (sp.line == p.dp_line && sp.master == p.dp_address && sp.switched < 0)
        slaves.emplace(sp.address, static_cast<int>(s));
    }
    std::map<std::uint8_t, int> entry;  // slave address -> map entry
    for (int k = 0; k < d.map_size(); ++k) {
      const auto& e = d.map(k);
      if (!e.has_slave()) {
        error(i, {{"dp", -1}, {"map", k}}, "map needs the slave's address");
        continue;
      }
      if (!slaves.count(static_cast<std::uint8_t>(e.slave())) || e.slave() > 125) {
        error(i, {{"dp", -1}, {"map", k}, {"slave", -1}},
              "no dp_slave " + std::to_string(e.slave()) + " of dp_master " + std::to_string(p.dp_address) +
                  " on line \"" + d.line() + "\"");
        continue;
      }
      if (!entry.emplace(static_cast<std::uint8_t>(e.slave()), k).second)
        error(i, {{"dp", -1}, {"map", k}, {"slave", -1}}, "slave " + std::to_string(e.slave()) + " is mapped twice");
    }
    // Allocation: explicit entries first, then the rest at the next free registers.
    std::uint32_t next_3x = 0;
    std::uint32_t next_4x = 0;
    const auto& n = p.transfer.non_transfer;
    next_4x = std::max(p.command_register + 1, n.count > 0 ? n.first + n.count : 0);
    struct Used { RefType t; std::uint32_t a, b; std::uint8_t slave; };
    std::vector<Used> used;
    for (const auto& [addr, si] : slaves) {
      const DpSlavePlan& sp = m_plan.dp_slaves[static_cast<std::size_t>(si)];
      QuantumIoMapPlan io;
      io.slave = si;
      io.address = addr;
      io.input_octets = static_cast<std::uint32_t>(sp.inputs);
      io.output_octets = static_cast<std::uint32_t>(sp.outputs);
      io.inputs = {RefType::Register3x, next_3x};
      io.outputs = {RefType::Register4x, next_4x};
      const auto e = entry.find(addr);
      Path at = {{"dp", -1}};
      if (e != entry.end()) {
        const auto& m = d.map(e->second);
        at = {{"dp", -1}, {"map", e->second}};
        if (!m.inputs().empty()) {
          Path f = at; f.push_back({"inputs", -1});
          if (auto r = reference(i, f, m.inputs(), {RefType::Register3x, RefType::Input1x})) io.inputs = *r; else continue;
        }
        if (!m.outputs().empty()) {
          Path f = at; f.push_back({"outputs", -1});
          if (auto r = reference(i, f, m.outputs(), {RefType::Register4x, RefType::Coil0x})) io.outputs = *r; else continue;
        }
      }
      const std::uint32_t nin = refs_for(io.inputs.type, io.input_octets);
      const std::uint32_t nout = refs_for(io.outputs.type, io.output_octets);
      const std::string who = "slave " + std::to_string(addr);
      bool ok = true;
      if (nin > 0 && io.inputs.index + nin > (io.inputs.type == RefType::Input1x ? p.sizes.inputs : p.sizes.input_regs)) {
        error(i, at, who + "'s " + std::to_string(io.input_octets) + " input octets from " +
                         quantum::format_reference(io.inputs) + " do not fit the configured " + ref_name(io.inputs.type) + " state RAM");
        ok = false;
      }
      if (nout > 0 && io.outputs.index + nout > (io.outputs.type == RefType::Coil0x ? p.sizes.coils : p.sizes.holding)) {
        error(i, at, who + "'s " + std::to_string(io.output_octets) + " output octets from " +
                         quantum::format_reference(io.outputs) + " do not fit the configured " + ref_name(io.outputs.type) + " state RAM");
        ok = false;
      }
      if (ok && nout > 0 && io.outputs.type == RefType::Register4x && reserved_4x(p, io.outputs.index, nout)) {
        error(i, at, who + "'s outputs from " + quantum::format_reference(io.outputs) +
                         " overlap the command register or the non-transfer area");
        ok = false;
      }
      if (ok && nout > 0 && m_transfer_ok(p) && !in_per_scan(p, io.outputs.type, io.outputs.index, nout)) {
        error(i, at, who + "'s outputs from " + quantum::format_reference(io.outputs) +
                         " are not transferred every scan: after a takeover they would be older than one scan");
        ok = false;
      }
      for (const Used& u : used) {
        if (!ok) break;
        auto overlap = [&](RefType t, std::uint32_t a, std::uint32_t c) {
          return c > 0 && u.t == t && a < u.b && u.a < a + c;
        };
        if (overlap(io.inputs.type, io.inputs.index, nin) || overlap(io.outputs.type, io.outputs.index, nout)) {
          error(i, at, who + "'s data overlaps slave " + std::to_string(u.slave) + "'s");
          ok = false;
        }
      }
      if (!ok) continue;
      if (nin > 0) used.push_back({io.inputs.type, io.inputs.index, io.inputs.index + nin, addr});
      if (nout > 0) used.push_back({io.outputs.type, io.outputs.index, io.outputs.index + nout, addr});
      if (io.inputs.type == RefType::Register3x) next_3x = std::max(next_3x, io.inputs.index + nin);
      if (io.outputs.type == RefType::Register4x) next_4x = std::max(next_4x, io.outputs.index + nout);
      p.io.push_back(io);
    }
  }

  static bool m_transfer_ok(const QuantumPlan& p) { return !p.plan.every_scan.empty(); }

  void plan_modbus(int i, const scenario::QuantumHotStandby& q, QuantumPlan& p) {
    std::set<int> ports;
    for (int k = 0; k < q.modbus_port_size(); ++k) {
      const auto& m = q.modbus_port(k);
      QuantumModbusPortPlan mp;
      const Path at = {{"modbus_port", k}};
      if (!m.has_port() || m.port() < 1 || m.port() > 3) {
        error(i, at, "modbus_port needs a port 1..3 (the CPU's Modbus ports)");
        continue;
      }
      mp.port = static_cast<int>(m.port());
      if (!ports.insert(mp.port).second) error(i, {{"modbus_port", k}, {"port", -1}}, "Modbus port " + std::to_string(mp.port) + " is configured twice");
      mp.no_swap = m.no_swap();
      const std::uint32_t addr = m.has_address() ? m.address() : 1;
      const std::uint32_t top = mp.no_swap ? 247 : 119;
      if (addr < 1 || addr > top) {
        error(i, {{"modbus_port", k}, {"address", -1}},
              "Modbus address " + std::to_string(addr) + " is out of range 1.." + std::to_string(top) +
                  (mp.no_swap ? "" : " (the standby answers at the address + 128, at most 247; seed 003 p. 93)"));
        continue;
      }
      mp.address = static_cast<std::uint8_t>(addr);
      mp.wiring = m.wiring() == scenario::QuantumModbusPort::RACK_0   ? QuantumModbusPortPlan::Wiring::Rack0
                  : m.wiring() == scenario::QuantumModbusPort::RACK_1 ? QuantumModbusPortPlan::Wiring::Rack1
                                                                      : QuantumModbusPortPlan::Wiring::Shared;
      if (m.has_tcp()) {
        const std::string l = m.tcp().listen().empty() ? "127.0.0.1:1502" : m.tcp().listen();
        if (auto ep = parse_endpoint(l)) {
          mp.tcp = *ep;
          if (ep->port != 0 && !m_ports.insert(ep->port).second)
            error(i, {{"modbus_port", k}, {"tcp", -1}, {"listen", -1}}, "port " + std::to_string(ep->port) + " is used twice in the file");
        } else {
          error(i, {{"modbus_port", k}, {"tcp", -1}, {"listen", -1}},
                "bad listen \"" + l + "\" (expected HOST:PORT with a numeric IPv4 address or [IPv6], e.g. \"127.0.0.1:1502\")");
        }
        mp.max_clients = m.tcp().max_clients();
      }
      if (m.has_rtu()) {
        mp.rtu = plan_modbus_rtu(m.rtu(), [&](const char* field, const std::string& msg) {
          Path f = {{"modbus_port", k}, {"rtu", -1}};
          if (field != nullptr) f.push_back({field, -1});
          error(i, f, msg);
        });
        if (!mp.rtu->link.empty() && !m_links.insert(mp.rtu->link).second)
          error(i, {{"modbus_port", k}, {"rtu", -1}, {"link", -1}}, "link \"" + mp.rtu->link + "\" is used twice in the file");
      }
      if (!m.has_tcp() && !m.has_rtu())
        error(i, at, "modbus_port needs a door: tcp (a Modbus TCP server) or rtu (a pty)");
      p.modbus.push_back(mp);
    }
  }

  void plan_logic(int i, const scenario::QuantumHotStandby& q, QuantumPlan& p) {
    const auto& l = q.logic();
    if (!l.counter().empty()) {
      if (auto r = reference(i, {{"logic", -1}, {"counter", -1}}, l.counter(), {RefType::Register4x})) {
        if (r->index >= p.sizes.holding)
          error(i, {{"logic", -1}, {"counter", -1}}, "counter " + l.counter() + " is beyond the configured 4x state RAM");
        else
          p.counter = *r;
      }
    }
    for (int k = 0; k < l.copy_size(); ++k) {
      const auto& c = l.copy(k);
      QuantumCopyPlan cp;
      auto f = reference(i, {{"logic", -1}, {"copy", k}, {"from", -1}}, c.from(), {RefType::Register3x, RefType::Register4x});
      auto t = reference(i, {{"logic", -1}, {"copy", k}, {"to", -1}}, c.to(), {RefType::Register4x});
      if (!f || !t) continue;
      if (c.count() < 1) {
        error(i, {{"logic", -1}, {"copy", k}, {"count", -1}}, "count must be at least 1");
        continue;
      }
      const std::uint32_t from_size = f->type == RefType::Register3x ? p.sizes.input_regs : p.sizes.holding;
      if (f->index + c.count() > from_size || t->index + c.count() > p.sizes.holding) {
        error(i, {{"logic", -1}, {"copy", k}}, "copy of " + std::to_string(c.count()) + " registers from " + c.from() +
                                                  " to " + c.to() + " goes beyond the configured state RAM");
        continue;
      }
      cp.from = *f;
      cp.to = *t;
      cp.count = c.count();
      p.copies.push_back(cp);
    }
  }

  void plan_scan(int i, const scenario::QuantumHotStandby& q, QuantumPlan& p) {
    // The seed's scan-time model (scan_time.hpp): the standalone scan, the Hot Standby cost and
    // the transfer of what goes every scan beyond the CPU type's baseline. Computed whether or
    // not scan_time is configured (`pbvbus timing` shows it either way).
    quantum::ScanInputs in;
    if (q.has_transfer_rate_us_per_kb()) {
      const std::uint32_t r = q.transfer_rate_us_per_kb();
      if (r < 1 || r > 100000)
        error(i, {{"transfer_rate_us_per_kb", -1}},
              "transfer_rate_us_per_kb " + std::to_string(r) + " is outside 1..100000");
      else
        in.rate_override = r;
    }
    if (q.iec_hsby_registers() != 0) {
      if (!p.iec)
        error(i, {{"iec_hsby_registers", -1}},
              "iec_hsby_registers needs iec: true (IEC-HSBY registers exist in IEC Hot Standby only)");
      else
        in.transferred.iec_regs = q.iec_hsby_registers();
    }
    if (!q.logic_time().empty())
      if (auto t = duration(i, {{"logic_time", -1}}, q.logic_time())) p.logic_time = *t;
    if (p.logic_time <= 0) {
      error(i, {{"logic_time", -1}}, "logic_time must be longer than 0");
      return;
    }
    in.standalone = p.logic_time;
    in.transferred.coils = quantum::per_scan_count(p.plan, RefType::Coil0x);
    in.transferred.inputs = quantum::per_scan_count(p.plan, RefType::Input1x);
    in.transferred.input_regs = quantum::per_scan_count(p.plan, RefType::Register3x);
    in.transferred.holding = quantum::per_scan_count(p.plan, RefType::Register4x);
    p.estimate = quantum::estimate_scan(p.cpu, in);
    if (!q.scan_time().empty()) {
      if (auto t = duration(i, {{"scan_time", -1}}, q.scan_time())) {
        if (*t < p.logic_time)
          error(i, {{"scan_time", -1}}, "scan_time is shorter than logic_time (the scan solves the logic)");
        p.scan_time = *t;
      }
      return;
    }
    p.scan_time = std::max(p.estimate.total, p.logic_time);
    p.scan_time_estimated = true;
  }

  ScenarioPlan& m_plan;
  const scenario::Scenario& m_proto;
  const S7Locator& m_locate;
  std::vector<Diagnostic>& m_errors;
  std::map<std::string, int> m_line;
  std::set<std::uint16_t> m_ports;
  std::set<std::string> m_links;
};

}  // namespace

void plan_quantum(ScenarioPlan& plan, const S7Locator& locate, std::vector<Diagnostic>& errors) {
  QuantumPlanner(plan, locate, errors).run();
}

}  // namespace pbvbus::tools
