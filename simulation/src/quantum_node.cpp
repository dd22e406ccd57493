// A Quantum Hot Standby pair at run time (quantum_node.hpp).
#include "pbvbus/simulation/quantum_node.hpp"

#include <algorithm>
#include <iostream>
#include <stdexcept>

#include "pbvbus/captures/event_record.hpp"
#include "pbvbus/captures/hsby_event.hpp"
#include "pbvbus/captures/pcapng_writer.hpp"
#include "pbvbus/gateways/modbus_rtu_port.hpp"
#include "pbvbus/gateways/modbus_tcp_server.hpp"
#include "pbvbus/gateways/state_ram_modbus.hpp"
#include "pbvbus/quantum/command_register.hpp"
#include "pbvbus/quantum/reference.hpp"
#include "pbvbus/quantum/transfer_area.hpp"

namespace pbvbus::tools {

namespace {

std::string qn_led(quantum::Led l) { return std::string(quantum::to_string(l)); }

std::string qn_ref_type(quantum::RefType t) {
  switch (t) {
    case quantum::RefType::Coil0x: return "0x";
    case quantum::RefType::Input1x: return "1x";
    case quantum::RefType::Register3x: return "3x";
    case quantum::RefType::Register4x: return "4x";
  }
  return "?";
}

std::string qn_cpu_name(quantum::CpuType c) {
  switch (c) {
    case quantum::CpuType::X13: return "140 CPU x13";
    case quantum::CpuType::Cpu42402: return "140 CPU 424 02";
    case quantum::CpuType::Cpu43412: return "140 CPU 434 12";
  }
  return "?";
}

}  // namespace

/// One Modbus port: its addressing and its doors.
struct QuantumNode::Port {
  QuantumModbusPortPlan plan;
  std::unique_ptr<quantum::HsbyModbusPort> addressing;
  std::unique_ptr<gateways::StateRamModbusHandler> tcp_handler, rtu_handler;
  std::unique_ptr<gateways::ModbusTcpServer> tcp;
  std::unique_ptr<gateways::ModbusRtuPort> rtu;
};

QuantumNode::QuantumNode(const ScenarioPlan& plan, int index, bus::Scheduler& sched)
    : m_plan(plan), m_index(index), m_sched(sched) {
  const QuantumPlan& q = this->plan();
  quantum::HsbyPairParams p;
  p.sizes = q.sizes;
  p.plan = q.plan;
  p.command_register = q.command_register;
  p.keyswitch_override = q.keyswitch_override;
  p.standby_stays_on_logic_mismatch = q.standby_stays_on_logic_mismatch;
  p.allow_different_firmware = q.allow_different_firmware;
  p.scan_time = q.scan_time;
  // The CHS → CHS copy over the fibre while the primary solves its logic (scan_time.hpp): the
  // state RAM sent every scan (0x/1x one bit each, 3x/4x two octets) at 10 Mbit/s, within the
  // scan.
  const std::int64_t bits = quantum::per_scan_count(q.plan, quantum::RefType::Coil0x) +
                            quantum::per_scan_count(q.plan, quantum::RefType::Input1x);
  const std::int64_t regs = quantum::per_scan_count(q.plan, quantum::RefType::Register3x) +
                            quantum::per_scan_count(q.plan, quantum::RefType::Register4x);
  p.transfer_time = std::clamp<bus::Ticks>(quantum::fibre_transfer_time((bits + 7) / 8 + 2 * regs),
                                           bus::kTicksPerUs, q.scan_time);
  for (int r = 0; r < 2; ++r) {
    const QuantumRackPlan& rp = q.racks[static_cast<std::size_t>(r)];
    auto& rk = p.racks[static_cast<std::size_t>(r)];
    rk.designation = rp.designation_b ? quantum::Designation::B : quantum::Designation::A;
    rk.key = rp.key == QuantumRackPlan::Key::OffLine ? quantum::KeySwitch::OffLine
             : rp.key == QuantumRackPlan::Key::Xfer  ? quantum::KeySwitch::Xfer
                                                     : quantum::KeySwitch::Run;
    rk.logic_checksum = rp.logic_checksum;
    rk.firmware = rp.firmware;
  }
  std::array<quantum::IoHead*, 2> heads{nullptr, nullptr};
  if (q.dp_master >= 0) {
    const DpMasterPlan& mp = m_plan.dp_masters.at(static_cast<std::size_t>(q.dp_master));
    const fdl::BusParams& bp = m_plan.lines.at(static_cast<std::size_t>(q.dp_line)).params;
    std::vector<dp::SlaveParams> slaves;
    for (int si : mp.slaves) slaves.push_back(m_plan.dp_slaves.at(static_cast<std::size_t>(si)).params);
    std::vector<quantum::DpIoMap> map;
    for (const QuantumIoMapPlan& io : q.io) map.push_back({io.address, io.inputs, io.outputs});
    const bus::Ticks bound = std::min(quantum::token_timeout(bp, q.dp_address), q.scan_time / 2);
    p.line_check_delay = bound;
    for (int r = 0; r < 2; ++r) {
      m_heads[static_cast<std::size_t>(r)] =
          std::make_unique<quantum::DpHead>(mp.params, slaves, bp, map, bound);
      heads[static_cast<std::size_t>(r)] = m_heads[static_cast<std::size_t>(r)].get();
    }
  }
  m_pair = std::make_unique<quantum::HsbyPair>(m_sched, p, heads);
  // The Hot Standby dialog's settings are the command register's start value in both units
  // (seed 003 pp. 88-93): override, both run modes Run, the logic-mismatch option, each port's
  // swap setting.
  quantum::CommandRegister c;
  c.keyswitch_override = q.keyswitch_override;
  c.run_a = c.run_b = true;
  c.standby_stays_on_logic_mismatch = q.standby_stays_on_logic_mismatch;
  c.exec_upgrade_while_running = q.exec_upgrade_while_running;
  for (const QuantumModbusPortPlan& mp : q.modbus)
    c.swap_disabled[static_cast<std::size_t>(mp.port - 1)] = mp.no_swap;
  for (int r = 0; r < 2; ++r) m_pair->ram(r).set_holding(q.command_register, quantum::encode_command(c));
  m_pair->set_logic([this](quantum::StateRam& ram, bus::Ticks) { logic(ram); });
  m_pair->set_event_handler([this](const quantum::PairEvent& e) { on_event(e); });
  for (const QuantumModbusPortPlan& mp : q.modbus) {
    auto port = std::make_unique<Port>();
    port->plan = mp;
    port->addressing = std::make_unique<quantum::HsbyModbusPort>(*m_pair, mp.port, mp.address, mp.address, !mp.no_swap);
    Port* raw = port.get();
    auto resolve = [this, raw](std::uint8_t unit) -> quantum::StateRam* {
      if (unit == 0) {  // broadcast: what the primary holds is what the next transfer carries
        const int pr = m_pair->primary();
        return pr >= 0 ? &m_pair->ram(pr) : nullptr;
      }
      const int r = raw->plan.wiring == QuantumModbusPortPlan::Wiring::Rack0   ? raw->addressing->rack_only(0, unit)
                    : raw->plan.wiring == QuantumModbusPortPlan::Wiring::Rack1 ? raw->addressing->rack_only(1, unit)
                                                                               : raw->addressing->rack_for(unit);
      return r >= 0 ? &m_pair->ram(r) : nullptr;
    };
    gateways::StateRamModbusOptions o;
    o.product_code = qn_cpu_name(q.cpu);
    o.revision = [this, raw](std::uint8_t unit) {
      const int r = raw->plan.wiring == QuantumModbusPortPlan::Wiring::Shared ? raw->addressing->rack_for(unit)
                    : raw->plan.wiring == QuantumModbusPortPlan::Wiring::Rack0 ? 0 : 1;
      if (r < 0) return std::string("HSBY");
      return std::string("HSBY unit ") + std::string(quantum::to_string(m_pair->designation(r)));
    };
    o.unknown_unit = gateways::UnknownUnit::GatewayNoResponse;
    port->tcp_handler = std::make_unique<gateways::StateRamModbusHandler>(resolve, o);
    o.unknown_unit = gateways::UnknownUnit::Silent;
    port->rtu_handler = std::make_unique<gateways::StateRamModbusHandler>(resolve, o);
    m_ports.push_back(std::move(port));
  }
  refresh_addresses();
}

QuantumNode::~QuantumNode() {
  // Doors first: they hold handlers that point at the pair.
  for (auto& p : m_ports) {
    if (p->tcp) p->tcp->close();
    if (p->rtu) p->rtu->close();
  }
}

const QuantumPlan& QuantumNode::plan() const { return m_plan.quantum.at(static_cast<std::size_t>(m_index)); }

bus::AttachmentId QuantumNode::attach_dp(bus::Line& line) {
  m_dp_line = &line;
  const std::string base = plan().name + " rack ";
  m_heads[0]->attach(line, base + "0 DP master " + std::to_string(plan().dp_address));
  m_heads[1]->attach(line, base + "1 DP master " + std::to_string(plan().dp_address));
  return m_heads[0]->attachment();
}

void QuantumNode::start() {
  if (m_started) return;
  m_started = true;
  for (auto& h : m_heads)
    if (h && m_dp_line != nullptr) m_dp_line->set_power(h->attachment(), false);
  for (int r = 0; r < 2; ++r) {
    const bus::Ticks at = plan().racks[static_cast<std::size_t>(r)].power_on_at;
    if (at <= m_sched.now())
      m_pair->power_on(r);
    else
      m_sched.schedule(at, [this, r] { m_pair->power_on(r); });
  }
}

// The capture's Hsby records (captures/hsby_event.hpp) carry quantum's numbers.
static_assert(static_cast<int>(quantum::PairEventKind::Power) == static_cast<int>(captures::HsbyEventKind::Power));
static_assert(static_cast<int>(quantum::PairEventKind::Switchover) ==
              static_cast<int>(captures::HsbyEventKind::Switchover));
static_assert(static_cast<int>(quantum::PairEventKind::Fibre) == static_cast<int>(captures::HsbyEventKind::Fibre));
static_assert(static_cast<int>(quantum::PairEventKind::Ignored) == static_cast<int>(captures::HsbyEventKind::Ignored));
static_assert(static_cast<int>(quantum::CpuState::Off) == static_cast<int>(captures::HsbyRackState::Off));
static_assert(static_cast<int>(quantum::CpuState::Offline) == static_cast<int>(captures::HsbyRackState::Offline));
static_assert(static_cast<int>(quantum::CpuState::Primary) == static_cast<int>(captures::HsbyRackState::Primary));
static_assert(static_cast<int>(quantum::CpuState::Standby) == static_cast<int>(captures::HsbyRackState::Standby));

void QuantumNode::on_event(const quantum::PairEvent& e) {
  captures::HsbyEventFields f;
  f.kind = static_cast<captures::HsbyEventKind>(e.kind);
  f.rack = e.rack;
  f.state = e.rack >= 0 ? static_cast<int>(e.state) : -1;
  f.text = plan().name + ": " + (e.rack >= 0 ? "rack " + std::to_string(e.rack) + ": " : "") + e.text;
  captures::EventRecord r = captures::hsby_event_record(f);
  if (e.kind != quantum::PairEventKind::Switchover) {
    if (m_capture != nullptr) m_capture->write_event(e.time, r);
    return;
  }
  // The pair logs a switchover before it files its record: the takeover time and the Modbus
  // addresses after it are read once the operation is over, at the same virtual time.
  QuantumSwitchoverReport sw;
  for (std::size_t k = 0; k < m_ports.size(); ++k)
    sw.modbus.push_back({m_ports[k]->plan.port, m_port_addr.at(k), {}});
  const std::size_t n = m_pair->switchovers().size();
  m_sched.schedule(e.time, [this, r, sw, n, t = e.time]() mutable {
    if (m_pair->switchovers().size() > n)
      r.value = static_cast<std::uint64_t>(bus::ticks_to_ns(m_pair->switchovers()[n].takeover_ticks));
    for (std::size_t k = 0; k < m_ports.size(); ++k)
      sw.modbus[k].after = {m_ports[k]->addressing->address(0), m_ports[k]->addressing->address(1)};
    m_switchovers.push_back(std::move(sw));
    if (m_capture != nullptr) m_capture->write_event(t, r);
  });
}

void QuantumNode::refresh_addresses() {
  m_port_addr.resize(m_ports.size());
  for (std::size_t k = 0; k < m_ports.size(); ++k)
    m_port_addr[k] = {m_ports[k]->addressing->address(0), m_ports[k]->addressing->address(1)};
}

void QuantumNode::logic(quantum::StateRam& ram) {
  refresh_addresses();
  const QuantumPlan& q = plan();
  if (q.counter) {
    auto v = static_cast<std::uint16_t>(ram.holding(q.counter->index) + 1);
    if (v == 0) v = 1;
    ram.set_holding(q.counter->index, v);
  }
  for (const QuantumCopyPlan& c : q.copies)
    for (std::uint32_t k = 0; k < c.count; ++k) {
      const std::uint16_t v = c.from.type == quantum::RefType::Register3x ? ram.input_reg(c.from.index + k)
                                                                          : ram.holding(c.from.index + k);
      ram.set_holding(c.to.index + k, v);
    }
}

void QuantumNode::open(bus::PacedRunner& runner) {
  const std::string who = "quantum_hot_standby \"" + plan().name + "\": ";
  auto log = [name = plan().name](const std::string& line) {
    std::cerr << "pbvbus run: quantum_hot_standby \"" << name << "\": " << line << std::endl;
  };
  for (auto& p : m_ports) {
    const std::string port = "modbus port " + std::to_string(p->plan.port);
    if (p->plan.tcp && !p->tcp) {
      gateways::ModbusTcpOptions o;
      o.address = p->plan.tcp->host;
      o.port = p->plan.tcp->port;
      if (p->plan.max_clients != 0) o.max_clients = p->plan.max_clients;
      o.log = log;
      try {
        p->tcp = std::make_unique<gateways::ModbusTcpServer>(runner.io_context(), *p->tcp_handler, o);
      } catch (const std::exception& e) {
        throw std::runtime_error(who + port + " tcp on " + p->plan.tcp->str() + ": " + e.what());
      }
    }
    if (p->plan.rtu && !p->rtu) {
      gateways::ModbusRtuOptions o;
      o.device = p->plan.rtu->device;
      o.link = p->plan.rtu->link;
      o.serial.baud = p->plan.rtu->baud;
      o.serial.parity = p->plan.rtu->parity;
      o.serial.stop_bits = p->plan.rtu->stop_bits;
      try {
        p->rtu = std::make_unique<gateways::ModbusRtuPort>(runner.io_context(), *p->rtu_handler, o);
      } catch (const std::exception& e) {
        throw std::runtime_error(who + port + " rtu " + (o.device.empty() ? "pty" : o.device) + ": " + e.what());
      }
    }
  }
}

std::vector<std::string> QuantumNode::door_lines() const {
  std::vector<std::string> out;
  const std::string who = "quantum " + plan().name + " modbus port ";
  for (const auto& p : m_ports) {
    const std::string port = who + std::to_string(p->plan.port) + ": ";
    if (p->tcp) out.push_back(port + "modbus_tcp on " + GwEndpoint{p->plan.tcp->host, p->tcp->port()}.str());
    if (p->rtu) {
      std::string l = port + "modbus_rtu on " + p->rtu->path();
      if (!p->plan.rtu->link.empty()) l += " (" + p->plan.rtu->link + ")";
      out.push_back(l);
    }
  }
  return out;
}

void QuantumNode::note(const std::string& text) {
  m_faults.emplace_back(m_sched.now(), text);
  if (m_capture == nullptr) return;
  captures::EventRecord r;
  r.category = captures::EventCategory::Note;
  r.text = plan().name + ": " + text;
  m_capture->write_event(m_sched.now(), r);
}

void QuantumNode::apply(const PlanFault& f, bool on) {
  using K = PlanFault::Kind;
  note((on ? "" : "repair: ") + f.description);
  refresh_addresses();  // the Modbus addresses before what the fault causes
  quantum::HsbyPair& q = *m_pair;
  switch (f.kind) {
    case K::QuantumPowerLoss: on ? q.power_off(f.rack) : q.power_on(f.rack); break;
    case K::QuantumCpuStop: on ? q.stop_cpu(f.rack) : q.start_cpu(f.rack); break;
    case K::QuantumKey:
      q.set_key(f.rack, !on ? quantum::KeySwitch::Run : f.key == 2 ? quantum::KeySwitch::Xfer : quantum::KeySwitch::OffLine);
      break;
    case K::QuantumUpdate:
      // Seed 003 pp. 21-22: hold the update button, key to Xfer, key to the mode wanted after
      // the update (Run), release the button.
      q.press_update(f.rack);
      q.set_key(f.rack, quantum::KeySwitch::Xfer);
      q.set_key(f.rack, quantum::KeySwitch::Run);
      q.release_update(f.rack);
      break;
    case K::QuantumFibre:
      q.set_fibre(!on ? quantum::FibreState::Ok
                      : f.fibre == 1 ? quantum::FibreState::TxRxNotCrossed : quantum::FibreState::Cut);
      break;
    case K::QuantumCommand: {
      const int p = q.primary();
      for (int r = 0; r < 2; ++r) {
        // A host writes unit 1 (the primary); with no primary, both units' own copies.
        if (p >= 0 && r != p) continue;
        quantum::StateRam& ram = q.ram(r);
        quantum::CommandRegister c = quantum::decode_command(ram.holding(plan().command_register));
        c.run_a = f.run_a;
        c.run_b = f.run_b;
        c.keyswitch_override = f.keyswitch_override;
        ram.set_holding(plan().command_register, quantum::encode_command(c));
      }
      // The override bit acts at once (seed p. 90: the primary then reads bits 14 and 15).
      q.set_keyswitch_override(f.keyswitch_override);
      break;
    }
    case K::QuantumLogicChange:
      q.load_program(f.rack, f.checksum, [this](quantum::StateRam& ram, bus::Ticks) { logic(ram); });
      break;
    case K::QuantumExecUpgrade:
      if (std::string why = q.upgrade_executive(f.rack, f.checksum); !why.empty())
        m_faults.back().second += " — refused: " + why;
      break;
    default: break;
  }
}

QuantumReport QuantumNode::report() const {
  const QuantumPlan& qp = plan();
  const quantum::HsbyPair& q = *m_pair;
  QuantumReport r;
  r.name = qp.name;
  r.cpu = qn_cpu_name(qp.cpu);
  r.iec = qp.iec;
  r.scan_time = qp.scan_time;
  r.scan_time_estimated = qp.scan_time_estimated;
  r.transfer_time = q.transfer_time();
  for (const auto& t : qp.plan.every_scan)
    r.every_scan.push_back({qn_ref_type(t.type), quantum::format_reference(t.type, t.first), t.count});
  r.additional_slices = qp.plan.additional_slices.size();
  if (qp.plan.non_transfer.count > 0)
    r.non_transfer = QuantumTransferRange{"4x", quantum::format_reference(quantum::RefType::Register4x, qp.plan.non_transfer.first),
                                          qp.plan.non_transfer.count};
  r.command_register = quantum::format_reference(quantum::RefType::Register4x, qp.command_register);
  for (int k = 0; k < 2; ++k) {
    QuantumRackReport& rr = r.racks[static_cast<std::size_t>(k)];
    rr.rack = k;
    rr.designation = std::string(quantum::to_string(q.designation(k)));
    rr.state = std::string(quantum::to_string(q.state(k)));
    rr.key = std::string(quantum::to_string(q.key(k)));
    rr.logic_checksum = q.logic_checksum(k);
    rr.scans = q.scans(k);
    const quantum::ChsLeds l = q.leds(k);
    rr.ready = qn_led(l.ready);
    rr.com_act = qn_led(l.com_act);
    rr.primary = qn_led(l.primary);
    rr.com_err = qn_led(l.com_err);
    rr.standby = qn_led(l.standby);
    const quantum::HeadRole h = q.head_role(k);
    // Without `dp` the pair has no DP master modules: the role it would give them means nothing.
    rr.dp_head = !m_heads[0]                     ? "none"
                 : h == quantum::HeadRole::Active  ? "active"
                 : h == quantum::HeadRole::Passive ? "passive"
                                                   : "off";
  }
  r.fibre = std::string(quantum::to_string(q.fibre()));
  r.transfers_completed = q.transfers_completed();
  r.transfers_lost = q.transfers_lost();
  for (const auto& s : q.switchovers()) {
    QuantumSwitchoverReport sr;
    sr.at = s.time;
    sr.cause_at = s.cause_time;
    sr.cause = std::string(quantum::to_string(s.cause));
    sr.from = s.old_rack;
    sr.to = s.new_rack;
    sr.takeover = s.takeover_ticks;
    sr.takeover_scans = s.takeover_scans;
    r.switchovers.push_back(sr);
  }
  // m_switchovers[k] belongs to the k-th switchover (both in order of occurrence).
  for (std::size_t k = 0; k < m_switchovers.size() && k < r.switchovers.size(); ++k)
    r.switchovers[k].modbus = m_switchovers[k].modbus;
  for (const auto& p : m_ports) {
    QuantumPortReport pr;
    pr.port = p->plan.port;
    pr.address = p->plan.address;
    pr.swap = p->addressing->swap_enabled();
    pr.wiring = p->plan.wiring == QuantumModbusPortPlan::Wiring::Rack0   ? "rack 0"
                : p->plan.wiring == QuantumModbusPortPlan::Wiring::Rack1 ? "rack 1"
                                                                         : "shared";
    pr.addresses = {p->addressing->address(0), p->addressing->address(1)};
    for (const std::string& l : door_lines())
      if (l.find("modbus port " + std::to_string(p->plan.port) + ":") != std::string::npos) pr.doors.push_back(l);
    for (const auto* h : {p->tcp_handler.get(), p->rtu_handler.get()}) {
      pr.requests += h->stats().requests;
      pr.exceptions += h->stats().exceptions;
      pr.no_reply += h->stats().silent;
    }
    pr.conflicts = p->addressing->conflicts();
    r.modbus.push_back(pr);
  }
  if (m_heads[0]) {
    QuantumDpReport d;
    d.line = m_plan.lines.at(static_cast<std::size_t>(qp.dp_line)).name;
    d.address = qp.dp_address;
    for (const auto& h : m_heads) {
      d.takeovers += h->master().hsby_stats().takeovers;
      d.resumed += h->master().hsby_stats().resumed;
      d.restarted += h->master().hsby_stats().restarted;
    }
    r.dp = d;
  }
  for (const auto& e : q.events())
    r.events.push_back({e.time, e.rack, std::string(quantum::to_string(e.kind)), e.text});
  r.faults = m_faults;
  return r;
}

}  // namespace pbvbus::tools
