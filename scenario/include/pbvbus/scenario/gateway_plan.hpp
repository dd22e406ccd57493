#pragma once
// Gateways in scenarios (docs/gateway-modbus.md; scenario/proto/scenario.proto message Gateway): the loader's
// checked form of each `gateway` entry, planned after the DP systems and the h_systems.
// GatewayNode (gateway_node.hpp) builds the running gateways from it.
//
// Decisions (the loader reports each violation with FILE:LINE:COLUMN):
//  - A gateway serves exactly ONE master system: `line` + `master` naming a dp_master on that
//    line, or `redundant_master_system` naming one. A dp_master that is one side of a
//    redundant_master_system is served through the system's name (an error otherwise: the
//    gateway would see one line of a system whose outputs the system writes).
//  - A gateway on a redundant system driven by an h_system is planned like any other; it is
//    read-only because its source (RedundantSource with the HSystemModel) says so — the CPU
//    program owns the outputs (`h_system` is set here only so the node can pass the model).
//  - Outputs ownership: the served master system runs no master-side test program (the
//    dp_master's `outputs` is ignored; DpMasterPlan::gateway_outputs), outputs start at 0 and
//    are what clients write — except behind an h_system (the CPUs write them).
//  - Names unique and not empty. At least one door (modbus_tcp, modbus_rtu or can); can needs
//    at least one transport.
//  - Listen addresses "HOST:PORT": HOST a numeric IPv4 address or "[IPv6]" (no name lookup on
//    the bus thread), PORT 0..65535, 0 = ephemeral. A port other than 0 may be used only once in
//    the file (all gateways, all TCP doors), since two listeners on one port cannot both bind.
//  - modbus_rtu: `link` or `device` (not both, not neither); baud > 0 (default 19200);
//    stop_bits 1 or 2 (default 1); a pty link used twice in the file (RTU or SLCAN) is an error.
//  - modbus options: a slave option's address must be a slave of the served system, once; a
//    module option's module_index below that slave's module count, once; stale_value 0..65535;
//    standby_units only on a redundant_master_system.
//  - can: node map entries name a slave of the system (once) and a node id 1..127; every served
//    slave's node id (mapped, else its address) is unique; tpdo_cycle and heartbeat > 0, the
//    heartbeat in whole milliseconds up to 65535 ms (CiA 301 object 0x1017 is u16 ms).
#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "pbvbus/bus/time.hpp"
#include "pbvbus/scenario/h_plan.hpp"
#include "scenario.pb.h"

namespace pbvbus::tools {

struct Diagnostic;
struct ScenarioPlan;

/// A TCP listen address, split and checked.
struct GwEndpoint {
  std::string host;  ///< "127.0.0.1", "::1" (without brackets)
  std::uint16_t port = 0;
  /// "127.0.0.1:1502", "[::1]:1502".
  std::string str() const;
};
/// Parses "HOST:PORT" (see above); nullopt if it is not one.
std::optional<GwEndpoint> parse_endpoint(const std::string& text);

enum class GwWordOrder : std::uint8_t { HighByteFirst, ByteSwap, WordSwap, ByteWordSwap };
enum class GwStale : std::uint8_t { Exception, KeepLast, Zero, Value };

struct GwModbusSlave {
  std::uint8_t address = 0;
  GwWordOrder order = GwWordOrder::HighByteFirst;
  GwStale stale = GwStale::Exception;
  std::uint16_t stale_value = 0;
  std::vector<std::pair<std::size_t, GwWordOrder>> modules;  ///< module index, its order
};

struct GwRtu {
  std::string link;    ///< a pty with this symlink (empty: device)
  std::string device;  ///< a serial device path (empty: pty)
  std::uint32_t baud = 19200;
  char parity = 'N';   ///< 'N', 'E', 'O'
  int stop_bits = 1;
};

/// A `modbus_rtu` entry checked (link or device, stop bits); `error(field, message)` for each
/// problem (field nullptr: the entry itself). The link's uniqueness is the caller's check.
GwRtu plan_modbus_rtu(const scenario::ModbusRtu& m,
                      const std::function<void(const char* field, const std::string& msg)>& error);

struct GwCan {
  std::vector<std::pair<std::uint8_t, std::uint8_t>> nodes;  ///< explicit: address -> node id
  bus::Ticks tpdo_cycle = 100 * bus::kTicksPerMs;
  bus::Ticks heartbeat = 1000 * bus::kTicksPerMs;
  std::optional<std::string> slcan_pty;  ///< present: an SLCAN pty; the string is its link ("" none)
  std::optional<GwEndpoint> slcan_tcp;
  std::uint32_t slcan_max_clients = 0;  ///< 0 = the door's default
  std::optional<GwEndpoint> socketcand;
  std::uint32_t socketcand_max_clients = 0;  ///< 0 = the door's default
  std::optional<std::string> socketcan;  ///< interface name
};

struct GatewayPlan {
  int source = 0;  ///< index into Scenario.gateway
  std::string name;
  int dp_master = -1;  ///< index into ScenarioPlan::dp_masters (a plain master system), or -1
  int system = -1;     ///< index into ScenarioPlan::redundant_systems, or -1
  int h_system = -1;   ///< index into ScenarioPlan::h_systems driving `system` (read-only), or -1
  /// The served slaves, ascending by address: indices into ScenarioPlan::dp_slaves (a switched
  /// station once, by its line-A interface).
  std::vector<int> slaves;
  std::optional<GwEndpoint> modbus_tcp;
  std::uint32_t max_clients = 0;  ///< 0 = the door's default
  std::vector<GwRtu> modbus_rtu;
  bool standby_units = false;
  std::vector<GwModbusSlave> modbus_slaves;  ///< options given, in file order
  std::optional<GwCan> can;
  /// "dp_master 1 on PROFIBUS_DP_1" / "redundant_master_system \"R\"".
  std::string served;
};

/// 1-based line and column of the field at the end of `path` inside gateway[index].
using GwLocator = std::function<std::pair<int, int>(int index, const std::vector<HPathStep>& path)>;

/// Plans the gateway entries (after plan_dp and plan_h). Errors are appended to `errors`;
/// marks the served dp_masters' `gateway_outputs`.
void plan_gateways(ScenarioPlan& plan, const GwLocator& locate, std::vector<Diagnostic>& errors);

}  // namespace pbvbus::tools
