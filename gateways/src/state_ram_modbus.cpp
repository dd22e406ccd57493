#include "pbvbus/gateways/state_ram_modbus.hpp"

#include <modbus/modbus.h>

#include <utility>

#include "pbvbus/gateways/modbus_device_id.hpp"

namespace pbvbus::gateways {
namespace {

using quantum::RefType;
using quantum::StateRam;

bool in_table(std::uint32_t first, std::uint32_t count, std::uint32_t size) {
  return first + count <= size;
}

/// The table a function code reads (FC01..04, FC23's read part).
RefType read_table(std::uint8_t fc) {
  switch (fc) {
    case kFcReadCoils:
      return RefType::Coil0x;
    case kFcReadDiscreteInputs:
      return RefType::Input1x;
    case kFcReadInputRegisters:
      return RefType::Register3x;
    default:
      return RefType::Register4x;
  }
}

bool is_read(std::uint8_t fc) {
  return fc == kFcReadCoils || fc == kFcReadDiscreteInputs || fc == kFcReadHoldingRegisters ||
         fc == kFcReadInputRegisters || fc == kFcReadWriteMultipleRegisters;
}

}  // namespace

StateRamModbusHandler::StateRamModbusHandler(UnitResolver resolve, StateRamModbusOptions options,
                                             WriteHook on_write)
    : m_resolve(std::move(resolve)),
      m_options(std::move(options)),
      m_on_write(std::move(on_write)) {}

std::size_t StateRamModbusHandler::handle(std::uint8_t unit, std::span<const std::uint8_t> pdu,
                                          std::span<std::uint8_t, kModbusMaxPdu> rsp,
                                          bool broadcast) {
  ++m_stats.requests;
  ++m_stats.units[unit].requests;
  const std::size_t n = answer(unit, pdu, rsp, broadcast);
  if (n >= 2 && (rsp[0] & 0x80) != 0) {
    ++m_stats.exceptions;
    ++m_stats.units[unit].exceptions;
    if (rsp[1] < m_stats.exceptions_by_code.size()) ++m_stats.exceptions_by_code[rsp[1]];
  }
  return broadcast ? 0 : n;
}

std::size_t StateRamModbusHandler::answer(std::uint8_t unit, std::span<const std::uint8_t> pdu,
                                          std::span<std::uint8_t, kModbusMaxPdu> rsp,
                                          bool broadcast) {
  StateRam* ram = m_resolve ? m_resolve(unit) : nullptr;
  if (!ram) {
    // Nobody holds this address: on a multidrop line nobody answers; a gateway in front of
    // the line answers that the target did not respond (Modbus Application Protocol §7).
    if (broadcast) return 0;
    if (m_options.unknown_unit == UnknownUnit::Silent || pdu.empty()) {
      ++m_stats.silent;
      return 0;
    }
    rsp[0] = static_cast<std::uint8_t>(pdu[0] | 0x80);
    rsp[1] = kExGatewayTargetFailed;
    return 2;
  }
  if (pdu.empty() || pdu.size() > kModbusMaxPdu) {
    rsp[0] = static_cast<std::uint8_t>((pdu.empty() ? 0 : pdu[0]) | 0x80);
    rsp[1] = pdu.empty() ? kExIllegalFunction : kExIllegalDataValue;
    return 2;
  }
  const ModbusDecoded d = decode_modbus_request(pdu);
  if (!d.ok()) return m_engine.exception(unit, pdu, d.error.exception, rsp);
  if (!m_engine.ok()) return m_engine.exception(unit, pdu, kExServerDeviceFailure, rsp);
  if (d.request.function == kFcEncapsulatedInterface) {
    std::array<std::string, 3> objects{"pbvbus", m_options.product_code,
                                       m_options.revision ? m_options.revision(unit) : "HSBY"};
    return modbus_device_id_response(d.request, std::move(objects), rsp);
  }
  return serve(unit, *ram, d.request, pdu, rsp);
}

std::size_t StateRamModbusHandler::serve(std::uint8_t unit, StateRam& ram, const ModbusRequest& rq,
                                         std::span<const std::uint8_t> pdu,
                                         std::span<std::uint8_t, kModbusMaxPdu> rsp) {
  const bool reads = is_read(rq.function);
  const bool writes = rq.writes();
  const RefType rt = read_table(rq.function);
  // Writes go to 0x (FC05/15) or 4x (FC06/16/23): 1x and 3x have no Modbus write function.
  const bool coil_write = rq.function == kFcWriteSingleCoil || rq.function == kFcWriteMultipleCoils;
  const RefType wt = coil_write ? RefType::Coil0x : RefType::Register4x;
  if ((reads && !in_table(rq.read_address, rq.read_quantity, ram.count(rt))) ||
      (writes && !in_table(rq.write_address, rq.write_quantity, ram.count(wt))))
    return m_engine.exception(unit, pdu, kExIllegalDataAddress, rsp);

  _modbus_mapping_t& m = m_engine.mapping();
  if (reads) {
    for (std::uint32_t i = rq.read_address; i < rq.read_address + rq.read_quantity; ++i) {
      switch (rt) {
        case RefType::Coil0x:
          m.tab_bits[i] = ram.coil(i) ? 1 : 0;
          break;
        case RefType::Input1x:
          m.tab_input_bits[i] = ram.input(i) ? 1 : 0;
          break;
        case RefType::Register3x:
          m.tab_input_registers[i] = ram.input_reg(i);
          break;
        case RefType::Register4x:
          m.tab_registers[i] = ram.holding(i);
          break;
      }
    }
  }
  const std::size_t n = m_engine.reply(unit, pdu, rsp);
  if (!writes || n == 0 || (rsp[0] & 0x80) != 0) return n;

  // libmodbus put the written values into its mapping: copy the written range back.
  for (std::uint32_t i = rq.write_address; i < rq.write_address + rq.write_quantity; ++i) {
    if (wt == RefType::Coil0x)
      ram.set_coil(i, m.tab_bits[i] != 0);
    else
      ram.set_holding(i, m.tab_registers[i]);
  }
  ++m_stats.units[unit].writes;
  if (m_on_write) m_on_write(unit, wt, rq.write_address, rq.write_quantity);
  return n;
}

}  // namespace pbvbus::gateways
