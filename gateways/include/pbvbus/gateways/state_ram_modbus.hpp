#pragma once
// A Modbus core serving a Quantum controller's state RAM (seed 003 "State RAM" and "Modbus
// port address swap"; docs/quantum-hsby-modbus.md): what a Quantum CPU's Modbus port answers.
// It sits behind the same doors as the DP gateway (ModbusTcpServer, ModbusRtuPort) and uses the
// same request checks (modbus_pdu.hpp) and libmodbus engine (modbus_engine.hpp): the requested
// ranges of the engine's mapping are filled from the state RAM, modbus_reply answers, written
// ranges are copied back.
//
// Mapping (the Modbus PDU address is the 0-based index within a table, reference 400001 = 4x
// index 0 = PDU address 0):
//   FC01 read / FC05, FC15 write  -> 0x coils
//   FC02 read                     -> 1x discrete inputs (no Modbus function writes them)
//   FC04 read                     -> 3x input registers (no Modbus function writes them)
//   FC03 read / FC06, FC16 write / FC23 -> 4x holding registers (FC23 writes, then reads)
//   FC43/14                       -> VendorName "pbvbus", ProductCode (option), revision
//
// Decisions (docs/quantum-hsby-modbus.md):
// - Unit resolution is the caller's: `resolve(unit)` gives the state RAM of the unit that holds
//   that Modbus address on this port now (it changes at a switchover when the address swap is
//   on), or nullptr. For nullptr the option `unknown_unit` decides: Silent (a multidrop RTU
//   line: nobody answers; handle() returns 0) or GatewayNoResponse (a TCP door in front:
//   exception 0x0B, gateway target device failed to respond).
// - Exception order: unknown unit (silence or 0x0B); 0x01 unsupported FC, 0x03 bad
//   length/quantity/value, 0x02 beyond 65535 (modbus_pdu.hpp); 0x02 a range beyond the
//   table's configured count (reads and writes); 0x04 engine failure.
// - Broadcast (RTU unit 0, broadcast = true): resolve(0) is asked; the write is carried out on
//   the state RAM it gives (the pair gives the primary's: the standby's is overwritten by the
//   next transfer), nothing is answered. Reads in a broadcast do nothing. nullptr: nothing.
// - `on_write(unit, table, first, count)` is called after a write has been applied to the
//   state RAM (FC05/15: 0x; FC06/16/23: 4x), before handle() returns.
// - Stats count every request, per unit too (a silent drop counts in `silent`).

#include <array>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <span>
#include <string>

#include "pbvbus/gateways/modbus_engine.hpp"
#include "pbvbus/gateways/modbus_handler.hpp"
#include "pbvbus/gateways/modbus_pdu.hpp"
#include "pbvbus/quantum/state_ram.hpp"

namespace pbvbus::gateways {

/// What the handler does for a unit the resolver does not know.
enum class UnknownUnit : std::uint8_t {
  Silent,             ///< no answer (RTU multidrop: no station has that address)
  GatewayNoResponse,  ///< exception 0x0B (a gateway in front of the line)
};

struct StateRamModbusOptions {
  UnknownUnit unknown_unit = UnknownUnit::Silent;
  /// FC43/14 ProductCode (object 1): the CPU's model number.
  std::string product_code = "140 CPU 434 12";
  /// FC43/14 MajorMinorRevision (object 2) for a unit, e.g. "HSBY unit A"; empty function:
  /// "HSBY".
  std::function<std::string(std::uint8_t unit)> revision;
};

struct StateRamModbusUnitStats {
  std::uint64_t requests = 0;
  std::uint64_t exceptions = 0;
  std::uint64_t writes = 0;  ///< writes applied to the state RAM
};

struct StateRamModbusStats {
  std::uint64_t requests = 0;
  std::uint64_t exceptions = 0;
  std::uint64_t silent = 0;  ///< requests for an unknown unit left unanswered (Silent)
  std::array<std::uint64_t, 12> exceptions_by_code{};  ///< index = exception code (1..11)
  std::array<StateRamModbusUnitStats, 256> units{};    ///< index = unit id
};

class StateRamModbusHandler final : public ModbusHandler {
 public:
  using UnitResolver = std::function<quantum::StateRam*(std::uint8_t unit)>;
  using WriteHook = std::function<void(std::uint8_t unit, quantum::RefType table,
                                       std::uint32_t first, std::uint32_t count)>;

  explicit StateRamModbusHandler(UnitResolver resolve, StateRamModbusOptions options = {},
                                 WriteHook on_write = {});

  std::size_t handle(std::uint8_t unit, std::span<const std::uint8_t> pdu,
                     std::span<std::uint8_t, kModbusMaxPdu> rsp, bool broadcast) override;

  const StateRamModbusStats& stats() const { return m_stats; }
  const StateRamModbusOptions& options() const { return m_options; }
  bool engine_ok() const { return m_engine.ok(); }

 private:
  std::size_t answer(std::uint8_t unit, std::span<const std::uint8_t> pdu,
                     std::span<std::uint8_t, kModbusMaxPdu> rsp, bool broadcast);
  std::size_t serve(std::uint8_t unit, quantum::StateRam& ram, const ModbusRequest& rq,
                    std::span<const std::uint8_t> pdu, std::span<std::uint8_t, kModbusMaxPdu> rsp);

  UnitResolver m_resolve;
  StateRamModbusOptions m_options;
  WriteHook m_on_write;
  ModbusEngine m_engine;
  StateRamModbusStats m_stats;
};

}  // namespace pbvbus::gateways
