#pragma once
// The Modbus gateway core (docs/gateway-modbus.md): answers request PDUs for one ProcessSource
// following the register layout of modbus_map.hpp. The doors (TCP/RTU) frame; this class only sees
// PDUs.
//
// libmodbus is the PDU engine (modbus_engine.hpp): for each request the gateway pre-checks the
// PDU (modbus_pdu.hpp) and the unit's map, fills only the requested ranges of the engine's
// full-size `modbus_mapping_t` from the image and lets `modbus_reply()` (or
// `modbus_reply_exception()`) write the answer. libmodbus therefore never sees a request that is
// not well-formed and inside the map.
//
// Decisions (docs/gateway-modbus.md):
// - Exception order: 0x0A unknown unit; 0x01 unsupported FC (PDU check) ; 0x03 bad
//   length/quantity/value; 0x02 beyond 65535; 0x01 write to a read-only unit (standby unit, or
//   outputs_writable false); 0x02 outside the unit's map (status block writes included);
//   0x0B slave not in data exchange with stale reaction Exception (process data only — the
//   status block and FC43 always answer); 0x04 the source refused.
// - Stale reactions apply to reads of inputs (FC02/FC04). Holding registers and coils read back
//   the outputs as last written (they are the gateway's own data, not stale); with reaction
//   Exception every process-data access is 0x0B. With KeepLast/Zero/Value writes go through
//   (the master sends them when the slave is back).
// - A read copies the whole telegram once (one DP cycle's image); a write patches every touched
//   module in a copy of the outputs and then calls write_module_outputs for each touched module
//   in slot order, all within handle() (one DP cycle). FC23 writes before it reads.
// - Broadcast (RTU unit 0): the request is carried out for the gateway unit, nothing answered.
// - Gateway unit counters include the request that reads them.
// - FC43/14 (basic device identification): VendorName "pbvbus", ProductCode = ident as 4 hex
//   digits ("gateway" for the gateway unit), MajorMinorRevision = GSD model name (the source's
//   name for the gateway unit). Conformity level 0x81; codes 2/3 answer the basic objects; an
//   unknown object id restarts at 0 for stream access and is 0x02 for individual access (4).

#include <array>
#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

#include "pbvbus/gateways/modbus_engine.hpp"
#include "pbvbus/gateways/modbus_handler.hpp"
#include "pbvbus/gateways/modbus_map.hpp"
#include "pbvbus/gateways/modbus_options.hpp"
#include "pbvbus/gateways/modbus_pdu.hpp"
#include "pbvbus/gateways/process_source.hpp"

namespace pbvbus::gateways {

struct ModbusUnitStats {
  std::uint64_t requests = 0;
  std::uint64_t exceptions = 0;
};

struct ModbusGatewayStats {
  std::uint64_t requests = 0;
  std::uint64_t exceptions = 0;
  std::array<std::uint64_t, 12> exceptions_by_code{};  ///< index = exception code (1..11)
  std::array<ModbusUnitStats, 256> units{};             ///< index = unit id
};

class ModbusGateway final : public ModbusHandler {
 public:
  /// `source` must outlive the gateway. Never throws for resource failures: if libmodbus or
  /// the socketpair cannot be set up, engine_ok() is false and every request gets 0x04.
  explicit ModbusGateway(ProcessSource& source, ModbusGatewayOptions options = {});
  ~ModbusGateway() override;
  ModbusGateway(const ModbusGateway&) = delete;
  ModbusGateway& operator=(const ModbusGateway&) = delete;

  std::size_t handle(std::uint8_t unit, std::span<const std::uint8_t> pdu,
                     std::span<std::uint8_t, kModbusMaxPdu> rsp, bool broadcast) override;

  const ModbusMap& map() const { return m_map; }
  const ModbusGatewayOptions& options() const { return m_options; }
  const ModbusGatewayStats& stats() const { return m_stats; }
  bool engine_ok() const { return m_engine.ok(); }

 private:
  struct Answer;
  std::size_t answer(std::uint8_t unit, std::span<const std::uint8_t> pdu,
                     std::span<std::uint8_t, kModbusMaxPdu> rsp);
  std::size_t gateway_unit(std::uint8_t unit, const ModbusRequest& rq,
                           std::span<const std::uint8_t> pdu,
                           std::span<std::uint8_t, kModbusMaxPdu> rsp);
  std::size_t slave_unit(const ModbusUnitMap& u, const ModbusRequest& rq,
                         std::span<const std::uint8_t> pdu,
                         std::span<std::uint8_t, kModbusMaxPdu> rsp);
  std::size_t device_id(const ModbusUnitMap* u, const ModbusRequest& rq,
                        std::span<std::uint8_t, kModbusMaxPdu> rsp);
  std::vector<std::uint16_t> status_registers(const ModbusUnitMap& u) const;
  std::vector<std::uint16_t> gateway_registers() const;

  ProcessSource& m_source;
  ModbusGatewayOptions m_options;
  ModbusMap m_map;
  ModbusGatewayStats m_stats;
  ModbusEngine m_engine;
};

}  // namespace pbvbus::gateways
