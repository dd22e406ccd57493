#pragma once
// The gateways of a running Simulation (docs/gateway-modbus.md; gateway_plan.hpp has the scenario rules).
// One GatewayNode per `gateway` entry: the ProcessSource adapter over the served master system
// (gateways::DpMasterSource or RedundantSource, with the h_system's model when one drives it),
// the Modbus core (gateways::ModbusGateway, one register map for all its Modbus doors), the
// virtual CAN segment (gateways::CanHub) with the CANopen core (gateways::CanopenGateway), and
// the doors: ModbusTcpServer, ModbusRtuPort per RTU entry, SlcanDoor (pty and/or TCP in one
// door), SocketcandDoor, SocketcanDoor.
//
// Decisions:
//  - Two steps, so that `pbvbus gateway map` needs no I/O: the constructor builds the source and
//    the cores (no socket, no pty); open() opens the doors on the paced runner's io_context.
//    Simulation::start() builds the nodes (after the h_systems, whose models the sources read)
//    and starts the CAN core; Simulation::paced_runner() opens their doors.
//  - A door that cannot open (port in use, no pty) fails the run: open() throws
//    std::runtime_error naming the gateway and the door. Except SocketCAN: a kernel without
//    AF_CAN or a missing interface is common (containers, CI) — the door is reported with its
//    error (report "error") and a warning, and the rest of the gateway runs.
//  - The Modbus core exists for every gateway (it only builds the map); doors and the report's
//    "modbus" part only when the gateway has a Modbus door. The CAN core only with `can`.
//  - Tear-down: the doors go first (they cancel their I/O on the live io_context), then the CAN
//    core (removes its hub port), the hub, the Modbus core, the source. The Simulation destroys
//    its gateway nodes before the paced runner and before the master systems they read.
#include <memory>
#include <string>
#include <vector>

#include "pbvbus/bus/scheduler.hpp"
#include "pbvbus/scenario/gateway_plan.hpp"
#include "pbvbus/simulation/gateway_report.hpp"

namespace pbvbus::bus {
class PacedRunner;
}
namespace pbvbus::dp {
class Master;
}
namespace pbvbus::devices {
class RedundantMasterSystemModel;
class HSystemModel;
}  // namespace pbvbus::devices
namespace pbvbus::gateways {
class ProcessSource;
class ModbusGateway;
class ModbusMap;
class CanHub;
class CanopenGateway;
class ModbusTcpServer;
class ModbusRtuPort;
class SlcanDoor;
class SocketcandDoor;
class SocketcanDoor;
}  // namespace pbvbus::gateways

namespace pbvbus::tools {

struct ScenarioPlan;

class GatewayNode {
 public:
  /// Builds the source and the cores. Exactly one of `master` (a plain master system) and
  /// `system` (a redundant one; `h` its H-system's model or nullptr) is given.
  GatewayNode(const ScenarioPlan& plan, const GatewayPlan& gp, bus::Scheduler& sched,
              dp::Master* master, devices::RedundantMasterSystemModel* system,
              const devices::HSystemModel* h);
  ~GatewayNode();
  GatewayNode(const GatewayNode&) = delete;
  GatewayNode& operator=(const GatewayNode&) = delete;

  const GatewayPlan& plan() const { return m_plan; }
  /// Starts the CAN core at `now` (its first change-detection tick). Idempotent.
  void start(bus::Ticks now);
  /// Opens every door on `runner`'s io_context; throws std::runtime_error (see above).
  void open(bus::PacedRunner& runner);
  /// One line per open door, e.g. "modbus_tcp on 127.0.0.1:1502" (the port it got), for the
  /// run's start-up messages; warnings ("socketcan vcan0: not open: ...") too.
  std::vector<std::string> door_lines() const;

  const gateways::ModbusMap& modbus_map() const;
  /// The CAN node/PDO map as text; empty without `can`.
  std::string can_map_text() const;
  bool has_modbus() const { return m_plan.modbus_tcp.has_value() || !m_plan.modbus_rtu.empty(); }

  GatewayReport report() const;

 private:
  GatewayPlan m_plan;
  bus::Scheduler& m_sched;
  // Cores (declared first: destroyed after the doors).
  std::unique_ptr<gateways::ProcessSource> m_source;
  std::unique_ptr<gateways::ModbusGateway> m_modbus;
  std::unique_ptr<gateways::CanHub> m_hub;
  std::unique_ptr<gateways::CanopenGateway> m_canopen;
  // Doors.
  std::unique_ptr<gateways::ModbusTcpServer> m_tcp;
  std::vector<std::unique_ptr<gateways::ModbusRtuPort>> m_rtu;
  std::unique_ptr<gateways::SlcanDoor> m_slcan;
  std::unique_ptr<gateways::SocketcandDoor> m_socketcand;
  std::unique_ptr<gateways::SocketcanDoor> m_socketcan;
  std::string m_socketcan_error;
  bool m_started = false;
  bool m_open = false;
};

}  // namespace pbvbus::tools
