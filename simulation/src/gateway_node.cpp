// The gateways of a running Simulation (gateway_node.hpp has the decisions).
#include "pbvbus/simulation/gateway_node.hpp"

#include <iostream>
#include <stdexcept>

#include "pbvbus/bus/paced_runner.hpp"
#include "pbvbus/gateways/canopen_gateway.hpp"
#include "pbvbus/gateways/dp_master_source.hpp"
#include "pbvbus/gateways/modbus_gateway.hpp"
#include "pbvbus/gateways/modbus_rtu_port.hpp"
#include "pbvbus/gateways/modbus_tcp_server.hpp"
#include "pbvbus/gateways/redundant_source.hpp"
#include "pbvbus/gateways/slcan_door.hpp"
#include "pbvbus/gateways/socketcan_door.hpp"
#include "pbvbus/gateways/socketcand_door.hpp"
#include "pbvbus/scenario/scenario.hpp"

namespace pbvbus::tools {

namespace {

gateways::WordOrder order(GwWordOrder o) {
  switch (o) {
    case GwWordOrder::ByteSwap: return gateways::WordOrder::ByteSwap;
    case GwWordOrder::WordSwap: return gateways::WordOrder::WordSwap;
    case GwWordOrder::ByteWordSwap: return gateways::WordOrder::ByteWordSwap;
    default: return gateways::WordOrder::HighByteFirst;
  }
}

gateways::StaleReaction stale(GwStale s) {
  switch (s) {
    case GwStale::KeepLast: return gateways::StaleReaction::KeepLast;
    case GwStale::Zero: return gateways::StaleReaction::Zero;
    case GwStale::Value: return gateways::StaleReaction::Value;
    default: return gateways::StaleReaction::Exception;
  }
}

gateways::ModbusGatewayOptions modbus_options(const GatewayPlan& gp) {
  gateways::ModbusGatewayOptions o;
  o.standby_units = gp.standby_units;
  for (const GwModbusSlave& s : gp.modbus_slaves) {
    gateways::ModbusSlaveOptions so;
    so.word_order = order(s.order);
    for (const auto& [m, w] : s.modules) so.module_word_order[m] = order(w);
    so.stale = stale(s.stale);
    so.stale_value = s.stale_value;
    o.slaves[s.address] = so;
  }
  return o;
}

gateways::CanopenOptions can_options(const GwCan& c) {
  gateways::CanopenOptions o;
  o.tpdo_cycle = c.tpdo_cycle;
  // The loader keeps the heartbeat in whole milliseconds up to 65535 (object 0x1017 is u16).
  o.heartbeat_ms = static_cast<std::uint16_t>(c.heartbeat / bus::kTicksPerMs);
  for (const auto& [a, n] : c.nodes) o.node_ids[a] = n;
  return o;
}

/// Where the doors' log lines go: stderr, named by the gateway. They report a door under
/// pressure (out of descriptors, clients refused or evicted), so they are not --quiet's to hide.
gateways::DoorLog door_log(const std::string& gateway) {
  return [gateway](const std::string& line) {
    std::cerr << "pbvbus run: gateway \"" << gateway << "\": " << line << std::endl;
  };
}

/// The frame counters every CAN door's stats have (SlcanDoor, SocketcandDoor, SocketcanDoor).
template <class Stats>
void can_door_counts(GatewayDoorReport& d, const Stats& s) {
  d.frames_in = s.frames_in;
  d.frames_out = s.frames_out;
  d.errors = s.errors;
  d.dropped = s.dropped;
}

/// The client counters of the CAN TCP doors (SlcanDoor, SocketcandDoor).
template <class Stats>
void can_door_clients(GatewayDoorReport& d, const Stats& s) {
  d.clients = s.clients;
  d.clients_total = s.clients_total;
  d.clients_refused = s.refused;
  d.accept_pauses = s.accept_pauses;
}

}  // namespace

GatewayNode::GatewayNode(const ScenarioPlan& plan, const GatewayPlan& gp, bus::Scheduler& sched,
                         dp::Master* master, devices::RedundantMasterSystemModel* system,
                         const devices::HSystemModel* h)
    : m_plan(gp), m_sched(sched) {
  std::vector<gateways::SlaveNaming> naming;
  for (int k : gp.slaves) {
    const DpSlavePlan& sp = plan.dp_slaves.at(static_cast<std::size_t>(k));
    naming.push_back({sp.address, sp.model, sp.module_names});
  }
  if (master != nullptr)
    m_source = std::make_unique<gateways::DpMasterSource>(*master, gp.served, std::move(naming));
  else if (system != nullptr)
    m_source = std::make_unique<gateways::RedundantSource>(*system, gp.served, std::move(naming), h);
  else
    throw std::runtime_error("gateway \"" + gp.name + "\": its master system is not running");
  m_modbus = std::make_unique<gateways::ModbusGateway>(*m_source, modbus_options(gp));
  if (gp.can) {
    m_hub = std::make_unique<gateways::CanHub>();
    m_canopen = std::make_unique<gateways::CanopenGateway>(m_sched, *m_source, *m_hub,
                                                           can_options(*gp.can));
  }
}

GatewayNode::~GatewayNode() {
  // Doors first, explicitly (the members would go in this order too; said here for the reader).
  m_socketcan.reset();
  m_socketcand.reset();
  m_slcan.reset();
  m_rtu.clear();
  m_tcp.reset();
}

void GatewayNode::start(bus::Ticks now) {
  if (m_started) return;
  m_started = true;
  if (m_canopen) m_canopen->start(now);
}

void GatewayNode::open(bus::PacedRunner& runner) {
  if (m_open) return;
  m_open = true;
  const std::string who = "gateway \"" + m_plan.name + "\": ";
  if (m_plan.modbus_tcp) {
    gateways::ModbusTcpOptions o;
    o.address = m_plan.modbus_tcp->host;
    o.port = m_plan.modbus_tcp->port;
    if (m_plan.max_clients != 0) o.max_clients = m_plan.max_clients;
    o.log = door_log(m_plan.name);
    try {
      m_tcp = std::make_unique<gateways::ModbusTcpServer>(runner.io_context(), *m_modbus, o);
    } catch (const std::exception& e) {
      throw std::runtime_error(who + "modbus_tcp on " + m_plan.modbus_tcp->str() + ": " + e.what());
    }
  }
  for (const GwRtu& r : m_plan.modbus_rtu) {
    gateways::ModbusRtuOptions o;
    o.device = r.device;
    o.link = r.link;
    o.serial.baud = r.baud;
    o.serial.parity = r.parity;
    o.serial.stop_bits = r.stop_bits;
    try {
      m_rtu.push_back(std::make_unique<gateways::ModbusRtuPort>(runner.io_context(), *m_modbus, o));
    } catch (const std::exception& e) {
      throw std::runtime_error(who + "modbus_rtu " + (r.device.empty() ? "pty" : r.device) + ": " +
                               e.what());
    }
  }
  if (!m_plan.can) return;
  const GwCan& c = *m_plan.can;
  if (c.slcan_pty || c.slcan_tcp) {
    gateways::SlcanDoorOptions o;
    o.pty = c.slcan_pty.has_value();
    o.pty_link = c.slcan_pty.value_or("");
    o.tcp = c.slcan_tcp.has_value();
    if (c.slcan_tcp) {
      o.tcp_address = c.slcan_tcp->host;
      o.tcp_port = c.slcan_tcp->port;
    }
    if (c.slcan_max_clients != 0) o.max_clients = c.slcan_max_clients;
    o.log = door_log(m_plan.name);
    m_slcan = std::make_unique<gateways::SlcanDoor>(runner, *m_hub, o);
    if (std::string why = m_slcan->open(); !why.empty()) throw std::runtime_error(who + "slcan: " + why);
  }
  if (c.socketcand) {
    gateways::SocketcandDoorOptions o;
    o.address = c.socketcand->host;
    o.port = c.socketcand->port;
    if (c.socketcand_max_clients != 0) o.max_clients = c.socketcand_max_clients;
    o.log = door_log(m_plan.name);
    m_socketcand = std::make_unique<gateways::SocketcandDoor>(runner, *m_hub, o);
    if (std::string why = m_socketcand->open(); !why.empty())
      throw std::runtime_error(who + "socketcand on " + c.socketcand->str() + ": " + why);
  }
  if (c.socketcan) {
    gateways::SocketcanDoorOptions o;
    o.interface = *c.socketcan;
    m_socketcan = std::make_unique<gateways::SocketcanDoor>(runner, *m_hub, o);
    m_socketcan_error = m_socketcan->open();
  }
}

std::vector<std::string> GatewayNode::door_lines() const {
  std::vector<std::string> out;
  const std::string who = "gateway " + m_plan.name + ": ";
  if (m_tcp) out.push_back(who + "modbus_tcp on " + GwEndpoint{m_plan.modbus_tcp->host, m_tcp->port()}.str());
  for (std::size_t i = 0; i < m_rtu.size(); ++i) {
    const GwRtu& r = m_plan.modbus_rtu[i];
    std::string l = who + "modbus_rtu on " + m_rtu[i]->path();
    if (!r.link.empty()) l += " (" + r.link + ")";
    out.push_back(l);
  }
  if (m_slcan) {
    if (m_plan.can->slcan_pty) {
      std::string l = who + "slcan on " + m_slcan->pty_path();
      if (!m_plan.can->slcan_pty->empty()) l += " (" + *m_plan.can->slcan_pty + ")";
      out.push_back(l);
    }
    if (m_plan.can->slcan_tcp)
      out.push_back(who + "slcan on " + GwEndpoint{m_plan.can->slcan_tcp->host, m_slcan->port()}.str());
  }
  if (m_socketcand)
    out.push_back(who + "socketcand on " +
                  GwEndpoint{m_plan.can->socketcand->host, m_socketcand->port()}.str());
  if (m_socketcan) {
    if (m_socketcan_error.empty())
      out.push_back(who + "socketcan on " + *m_plan.can->socketcan);
    else
      out.push_back(who + "warning: socketcan on " + *m_plan.can->socketcan + " not open: " +
                    m_socketcan_error);
  }
  return out;
}

const gateways::ModbusMap& GatewayNode::modbus_map() const { return m_modbus->map(); }

std::string GatewayNode::can_map_text() const {
  return m_canopen ? gateways::to_text(m_canopen->map()) : std::string();
}

GatewayReport GatewayNode::report() const {
  GatewayReport r;
  r.name = m_plan.name;
  r.served = m_plan.served;
  if (has_modbus()) {
    GatewayModbusReport m;
    const auto& s = m_modbus->stats();
    m.requests = s.requests;
    m.exceptions = s.exceptions;
    for (std::size_t code = 0; code < s.exceptions_by_code.size(); ++code)
      if (s.exceptions_by_code[code] != 0) m.exceptions_by_code[static_cast<int>(code)] = s.exceptions_by_code[code];
    r.modbus = m;
  }
  if (m_canopen) {
    GatewayCanReport c;
    const auto& s = m_canopen->stats();
    c.frames = m_hub->frames();
    c.tpdo = s.tpdo_sent;
    c.heartbeat = s.heartbeat_sent;
    c.bootup = s.bootup_sent;
    c.emcy = s.emcy_sent;
    c.sdo_sent = s.sdo_sent;
    c.rpdo = s.rpdo_received;
    c.nmt = s.nmt_received;
    c.sdo_received = s.sdo_received;
    c.ignored = s.ignored;
    c.bad = s.bad;
    c.rpdo_refused = s.rpdo_refused;
    c.nmt_refused = s.nmt_refused;
    c.sdo_aborts = s.sdo_aborts;
    r.can = c;
  }
  auto modbus_door = [](std::string kind, std::string where, std::string link,
                        const gateways::ModbusDoorStats& s) {
    GatewayDoorReport d;
    d.kind = std::move(kind);
    d.where = std::move(where);
    d.link = std::move(link);
    d.clients = s.clients_now;
    d.clients_total = s.clients_accepted;
    d.clients_closed_bad = s.clients_closed_bad;
    d.clients_refused = s.clients_refused;
    d.clients_evicted = s.clients_evicted;
    d.accept_pauses = s.accept_pauses;
    d.requests = s.requests;
    d.exceptions = s.exceptions;
    d.bad_frames = s.bad_frames;
    return d;
  };
  if (m_tcp)
    r.doors.push_back(modbus_door("modbus_tcp", GwEndpoint{m_plan.modbus_tcp->host, m_tcp->port()}.str(),
                                  "", m_tcp->stats()));
  for (std::size_t i = 0; i < m_rtu.size(); ++i)
    r.doors.push_back(modbus_door("modbus_rtu", m_rtu[i]->path(), m_plan.modbus_rtu[i].link,
                                  m_rtu[i]->stats()));
  if (m_slcan) {
    GatewayDoorReport d;
    d.kind = "slcan";
    if (m_plan.can->slcan_pty) {
      d.where = m_slcan->pty_path();
      d.link = *m_plan.can->slcan_pty;
    }
    if (m_plan.can->slcan_tcp)
      d.where += (d.where.empty() ? "" : " ") +
                 GwEndpoint{m_plan.can->slcan_tcp->host, m_slcan->port()}.str();
    const auto s = m_slcan->stats();
    can_door_clients(d, s);
    can_door_counts(d, s);
    r.doors.push_back(std::move(d));
  }
  if (m_socketcand) {
    GatewayDoorReport d;
    d.kind = "socketcand";
    d.where = GwEndpoint{m_plan.can->socketcand->host, m_socketcand->port()}.str();
    const auto s = m_socketcand->stats();
    can_door_clients(d, s);
    d.clients_closed_bad = s.closed_bad;
    can_door_counts(d, s);
    r.doors.push_back(std::move(d));
  }
  if (m_socketcan) {
    GatewayDoorReport d;
    d.kind = "socketcan";
    d.where = *m_plan.can->socketcan;
    d.error = m_socketcan_error;
    const auto& s = m_socketcan->stats();
    can_door_counts(d, s);
    r.doors.push_back(std::move(d));
  }
  return r;
}

}  // namespace pbvbus::tools
