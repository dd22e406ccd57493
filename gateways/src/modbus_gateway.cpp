#include "pbvbus/gateways/modbus_gateway.hpp"

#include <modbus/modbus.h>

#include <algorithm>
#include <cstdio>
#include <string>

#include "pbvbus/gateways/modbus_device_id.hpp"
#include "pbvbus/gateways/modbus_image.hpp"

namespace pbvbus::gateways {
namespace {

bool in_range(std::uint32_t first, std::uint32_t count, std::uint32_t lo, std::uint32_t n) {
  return first >= lo && first + count <= lo + n;
}

const SourceSlave* find_slave(const ProcessSource& src, std::uint8_t address) {
  for (const auto& s : src.slaves())
    if (s.address == address) return &s;
  return nullptr;
}

void put_u32(std::vector<std::uint16_t>& r, std::size_t at, std::uint64_t v) {
  const auto x = static_cast<std::uint32_t>(v);
  r[at] = static_cast<std::uint16_t>(x >> 16);
  r[at + 1] = static_cast<std::uint16_t>(x & 0xFFFF);
}

}  // namespace

ModbusGateway::ModbusGateway(ProcessSource& source, ModbusGatewayOptions options)
    : m_source(source), m_options(std::move(options)), m_map(source, m_options) {}

ModbusGateway::~ModbusGateway() = default;

std::size_t ModbusGateway::handle(std::uint8_t unit, std::span<const std::uint8_t> pdu,
                                  std::span<std::uint8_t, kModbusMaxPdu> rsp, bool broadcast) {
  ++m_stats.requests;
  ++m_stats.units[unit].requests;
  std::size_t n = answer(unit, pdu, rsp);
  if (n >= 2 && (rsp[0] & 0x80) != 0) {
    ++m_stats.exceptions;
    ++m_stats.units[unit].exceptions;
    if (rsp[1] < m_stats.exceptions_by_code.size()) ++m_stats.exceptions_by_code[rsp[1]];
  }
  return broadcast ? 0 : n;
}

std::size_t ModbusGateway::answer(std::uint8_t unit, std::span<const std::uint8_t> pdu,
                                  std::span<std::uint8_t, kModbusMaxPdu> rsp) {
  if (pdu.empty() || pdu.size() > kModbusMaxPdu) {
    rsp[0] = static_cast<std::uint8_t>((pdu.empty() ? 0 : pdu[0]) | 0x80);
    rsp[1] = pdu.empty() ? kExIllegalFunction : kExIllegalDataValue;
    return 2;
  }
  const bool gw = m_options.gateway_units && (unit == 0 || unit == 255);
  const ModbusUnitMap* u = gw ? nullptr : m_map.unit(unit);
  if (!gw && !u) return m_engine.exception(unit, pdu, kExGatewayPathUnavailable, rsp);
  const ModbusDecoded d = decode_modbus_request(pdu);
  if (!d.ok()) return m_engine.exception(unit, pdu, d.error.exception, rsp);
  if (!engine_ok()) return m_engine.exception(unit, pdu, kExServerDeviceFailure, rsp);
  if (d.request.function == kFcEncapsulatedInterface) return device_id(u, d.request, rsp);
  return gw ? gateway_unit(unit, d.request, pdu, rsp) : slave_unit(*u, d.request, pdu, rsp);
}

std::vector<std::uint16_t> ModbusGateway::status_registers(const ModbusUnitMap& u) const {
  std::vector<std::uint16_t> r(kStatusRegisters, 0);
  SlaveStatus st;
  if (auto s = m_source.status(u.address, u.side)) st = *s;
  const SourceSlave* slave = find_slave(m_source, u.address);
  const std::uint8_t ss1 = st.diag.empty() ? 0 : st.diag[0];  // Station_Status_1
  std::uint16_t flags = 0;
  if (st.data_valid) flags |= kFlagDataValid;
  if (ss1 & 0x08) flags |= kFlagExtDiag;
  if ((ss1 & 0x01) || st.state == dp::SlaveStatusState::NotPresent) flags |= kFlagStationFailure;
  if (ss1 & 0x40) flags |= kFlagPrmFault;
  if (ss1 & 0x04) flags |= kFlagCfgFault;
  if (slave && slave->switched) flags |= kFlagSwitched;
  if (st.redundancy_lost) flags |= kFlagRedundancyLost;
  if (st.active_channel == 1) flags |= kFlagActiveChannelB;
  if (u.side == Side::Standby) flags |= kFlagStandbyView;
  r[0] = modbus_state_code(st.state);
  r[1] = flags;
  r[2] = static_cast<std::uint16_t>(st.data_exchanges & 0xFFFF);
  r[3] = u.ident;
  r[4] = st.active_channel < 0 ? 0xFFFF : static_cast<std::uint16_t>(st.active_channel);
  r[5] = static_cast<std::uint16_t>(st.failures & 0xFFFF);
  r[6] = static_cast<std::uint16_t>(st.returns & 0xFFFF);
  const std::size_t dl = std::min<std::size_t>(st.diag.size(), 2u * kStatusDiagRegisters);
  r[7] = static_cast<std::uint16_t>(dl);
  for (std::size_t i = 0; i < dl; ++i)
    r[8 + i / 2] = static_cast<std::uint16_t>(r[8 + i / 2] | (i % 2 == 0 ? st.diag[i] << 8
                                                                        : st.diag[i]));
  return r;
}

std::vector<std::uint16_t> ModbusGateway::gateway_registers() const {
  std::vector<std::uint16_t> r(kGwInputRegisters, 0);
  for (const auto& s : m_source.slaves()) {
    if (s.address > 127) continue;
    const auto bit = static_cast<std::uint16_t>(1u << (s.address % 16));
    r[kGwConfigured + s.address / 16] |= bit;
    auto st = m_source.status(s.address, Side::Primary);
    if (st && st->state == dp::SlaveStatusState::DataExchange)
      r[kGwLiveList + s.address / 16] |= bit;
  }
  r[kGwMasterMode] = modbus_mode_code(m_source.mode());
  r[kGwMasterAddress] = m_source.master_address();
  const MasterCounters c = m_source.counters();
  put_u32(r, kGwStationFailures, c.station_failures);
  put_u32(r, kGwStationReturns, c.station_returns);
  put_u32(r, kGwDiagnoses, c.diagnoses);
  put_u32(r, kGwAlarms, c.alarms);
  put_u32(r, kGwSwitchovers, c.switchovers);
  put_u32(r, kGwModbusRequests, m_stats.requests);
  put_u32(r, kGwModbusExceptions, m_stats.exceptions);
  r[kGwHMasterRack] = 0xFFFF;
  if (auto h = m_source.h_status()) {
    r[kGwHPresent] = 1;
    r[kGwHCpuState] = h->cpu_state[0];
    r[kGwHCpuState + 1] = h->cpu_state[1];
    r[kGwHCpuRole] = h->cpu_role[0];
    r[kGwHCpuRole + 1] = h->cpu_role[1];
    r[kGwHSystemMode] = h->system_mode;
    r[kGwHMasterRack] = h->master_rack < 0 ? 0xFFFF : static_cast<std::uint16_t>(h->master_rack);
  }
  return r;
}

std::size_t ModbusGateway::gateway_unit(std::uint8_t unit, const ModbusRequest& rq,
                                        std::span<const std::uint8_t> pdu,
                                        std::span<std::uint8_t, kModbusMaxPdu> rsp) {
  switch (rq.function) {
    case kFcReadInputRegisters: {
      if (!in_range(rq.read_address, rq.read_quantity, 0, kGwInputRegisters))
        return m_engine.exception(unit, pdu, kExIllegalDataAddress, rsp);
      const auto regs = gateway_registers();
      for (std::uint16_t i = 0; i < rq.read_quantity; ++i)
        m_engine.mapping().tab_input_registers[rq.read_address + i] = regs[rq.read_address + i];
      return m_engine.reply(unit, pdu, rsp);
    }
    case kFcReadHoldingRegisters:
    case kFcWriteSingleRegister:
    case kFcWriteMultipleRegisters:
    case kFcReadWriteMultipleRegisters: {
      const bool reads = rq.function == kFcReadHoldingRegisters ||
                         rq.function == kFcReadWriteMultipleRegisters;
      const bool writes = rq.function != kFcReadHoldingRegisters;
      if ((reads && !in_range(rq.read_address, rq.read_quantity, 0, kGwHoldingRegisters)) ||
          (writes && !in_range(rq.write_address, rq.write_quantity, 0, kGwHoldingRegisters)))
        return m_engine.exception(unit, pdu, kExIllegalDataAddress, rsp);
      if (writes) {
        const std::uint16_t v = rq.write_value(0);
        if (v < 2 || v > 4) return m_engine.exception(unit, pdu, kExIllegalDataValue, rsp);
        if (!m_source.command(static_cast<dp::MasterMode>(v - 1)))
          return m_engine.exception(unit, pdu, kExServerDeviceFailure, rsp);
      }
      m_engine.mapping().tab_registers[kGwHrMasterMode] = modbus_mode_code(m_source.mode());
      const std::size_t n = m_engine.reply(unit, pdu, rsp);
      // FC23 reads after its write: libmodbus put the written value into the mapping, the
      // answer must show the mode the master is in now.
      if (rq.function == kFcReadWriteMultipleRegisters && n == 4) {
        const std::uint16_t m = modbus_mode_code(m_source.mode());
        rsp[2] = static_cast<std::uint8_t>(m >> 8);
        rsp[3] = static_cast<std::uint8_t>(m & 0xFF);
      }
      return n;
    }
    default:  // the gateway has no bit tables
      return m_engine.exception(unit, pdu, kExIllegalDataAddress, rsp);
  }
}

std::size_t ModbusGateway::slave_unit(const ModbusUnitMap& u, const ModbusRequest& rq,
                                      std::span<const std::uint8_t> pdu,
                                      std::span<std::uint8_t, kModbusMaxPdu> rsp) {
  const std::uint8_t unit = u.unit;
  if (rq.writes() && !u.writable) return m_engine.exception(unit, pdu, kExIllegalFunction, rsp);

  // Where does the request land? Status block (registers only), data area, or nowhere.
  const bool status_read =
      (rq.function == kFcReadInputRegisters || rq.function == kFcReadHoldingRegisters ||
       rq.function == kFcReadWriteMultipleRegisters) &&
      in_range(rq.read_address, rq.read_quantity, kStatusBase, kStatusRegisters);
  bool data_ok = true;
  switch (rq.function) {
    case kFcReadInputRegisters:
      data_ok = status_read || in_range(rq.read_address, rq.read_quantity, 0, u.input_registers);
      break;
    case kFcReadHoldingRegisters:
      data_ok =
          status_read || in_range(rq.read_address, rq.read_quantity, 0, u.holding_registers);
      break;
    case kFcReadDiscreteInputs:
      data_ok = in_range(rq.read_address, rq.read_quantity, 0,
                         static_cast<std::uint32_t>(u.input_len * 8));
      break;
    case kFcReadCoils:
      data_ok = in_range(rq.read_address, rq.read_quantity, 0,
                         static_cast<std::uint32_t>(u.output_len * 8));
      break;
    case kFcWriteSingleCoil:
    case kFcWriteMultipleCoils:
      data_ok = in_range(rq.write_address, rq.write_quantity, 0,
                         static_cast<std::uint32_t>(u.output_len * 8));
      break;
    case kFcWriteSingleRegister:
    case kFcWriteMultipleRegisters:
      data_ok = in_range(rq.write_address, rq.write_quantity, 0, u.holding_registers);
      break;
    case kFcReadWriteMultipleRegisters:
      data_ok = in_range(rq.write_address, rq.write_quantity, 0, u.holding_registers) &&
                (status_read ||
                 in_range(rq.read_address, rq.read_quantity, 0, u.holding_registers));
      break;
    default:
      return m_engine.exception(unit, pdu, kExIllegalFunction, rsp);
  }
  if (!data_ok) return m_engine.exception(unit, pdu, kExIllegalDataAddress, rsp);

  // The status block is always readable (FC03/FC04 only; FC23 writes process data).
  if (status_read && rq.function != kFcReadWriteMultipleRegisters) {
    const auto regs = status_registers(u);
    std::uint16_t* tab = rq.function == kFcReadInputRegisters
                             ? m_engine.mapping().tab_input_registers
                             : m_engine.mapping().tab_registers;
    for (std::uint16_t i = 0; i < rq.read_quantity; ++i)
      tab[rq.read_address + i] = regs[rq.read_address - kStatusBase + i];
    return m_engine.reply(unit, pdu, rsp);
  }

  SlaveStatus st;
  const auto ost = m_source.status(u.address, u.side);
  if (ost) st = *ost;
  const bool stale = !ost || !st.data_valid;
  if (stale && u.stale == StaleReaction::Exception)
    return m_engine.exception(unit, pdu, kExGatewayTargetFailed, rsp);

  switch (rq.function) {
    case kFcReadInputRegisters:
    case kFcReadDiscreteInputs: {
      std::vector<std::uint8_t> in(u.input_len, 0);
      if (!m_source.read_inputs(u.address, u.side, in))
        return m_engine.exception(unit, pdu, kExServerDeviceFailure, rsp);
      if (stale && u.stale == StaleReaction::Zero) std::fill(in.begin(), in.end(), 0);
      const bool value = stale && u.stale == StaleReaction::Value;
      if (rq.function == kFcReadInputRegisters) {
        auto regs = telegram_to_registers(u, in, false);
        if (value) std::fill(regs.begin(), regs.end(), u.stale_value);
        for (std::uint16_t i = 0; i < rq.read_quantity; ++i)
          m_engine.mapping().tab_input_registers[rq.read_address + i] = regs[rq.read_address + i];
      } else {
        for (std::uint16_t i = 0; i < rq.read_quantity; ++i) {
          const std::size_t b = rq.read_address + i;
          m_engine.mapping().tab_input_bits[b] =
              value ? static_cast<std::uint8_t>(u.stale_value & 1u)
                    : static_cast<std::uint8_t>((in[b / 8] >> (b % 8)) & 1u);
        }
      }
      return m_engine.reply(unit, pdu, rsp);
    }
    case kFcReadHoldingRegisters:
    case kFcReadCoils: {
      std::vector<std::uint8_t> out(u.output_len, 0);
      if (!m_source.read_outputs(u.address, u.side, out))
        return m_engine.exception(unit, pdu, kExServerDeviceFailure, rsp);
      if (rq.function == kFcReadHoldingRegisters) {
        const auto regs = telegram_to_registers(u, out, true);
        for (std::uint16_t i = 0; i < rq.read_quantity; ++i)
          m_engine.mapping().tab_registers[rq.read_address + i] = regs[rq.read_address + i];
      } else {
        for (std::uint16_t i = 0; i < rq.read_quantity; ++i) {
          const std::size_t b = rq.read_address + i;
          m_engine.mapping().tab_bits[b] = static_cast<std::uint8_t>((out[b / 8] >> (b % 8)) & 1u);
        }
      }
      return m_engine.reply(unit, pdu, rsp);
    }
    default:
      break;
  }

  // Writes: patch a copy of the whole output telegram, then hand every touched module over
  // whole, in slot order, before anything else runs (one DP cycle).
  std::vector<std::uint8_t> out(u.output_len, 0);
  if (!m_source.read_outputs(u.address, Side::Primary, out))
    return m_engine.exception(unit, pdu, kExServerDeviceFailure, rsp);
  std::vector<bool> touched(u.modules.size(), false);
  const bool coils =
      rq.function == kFcWriteSingleCoil || rq.function == kFcWriteMultipleCoils;
  for (std::uint16_t i = 0; i < rq.write_quantity; ++i) {
    const std::uint16_t v = rq.write_value(i);
    if (coils) {
      const std::size_t b = static_cast<std::size_t>(rq.write_address) + i;
      const auto mask = static_cast<std::uint8_t>(1u << (b % 8));
      out[b / 8] = static_cast<std::uint8_t>(v ? (out[b / 8] | mask) : (out[b / 8] & ~mask));
      for (std::size_t m = 0; m < u.modules.size(); ++m)
        if (b / 8 >= u.modules[m].out_offset && b / 8 < u.modules[m].out_offset + u.modules[m].out_len)
          touched[m] = true;
    } else {
      const int m = patch_output_register(u, static_cast<std::uint16_t>(rq.write_address + i), v, out);
      if (m >= 0) touched[static_cast<std::size_t>(m)] = true;
    }
  }
  for (std::size_t m = 0; m < u.modules.size(); ++m) {
    if (!touched[m]) continue;
    const auto& mm = u.modules[m];
    if (!m_source.write_module_outputs(
            u.address, m, std::span<const std::uint8_t>(out).subspan(mm.out_offset, mm.out_len)))
      return m_engine.exception(unit, pdu, kExServerDeviceFailure, rsp);
  }
  if (rq.function != kFcReadWriteMultipleRegisters) return m_engine.reply(unit, pdu, rsp);

  // FC23: the read part after the write, from the outputs as they are now (or the status
  // block mirror).
  std::vector<std::uint16_t> regs;
  std::uint16_t base = 0;
  if (status_read) {
    regs = status_registers(u);
    base = kStatusBase;
  } else {
    std::vector<std::uint8_t> now(u.output_len, 0);
    if (!m_source.read_outputs(u.address, Side::Primary, now))
      return m_engine.exception(unit, pdu, kExServerDeviceFailure, rsp);
    regs = telegram_to_registers(u, now, true);
  }
  for (std::uint16_t i = 0; i < rq.read_quantity; ++i)
    m_engine.mapping().tab_registers[rq.read_address + i] = regs[rq.read_address - base + i];
  const std::size_t n = m_engine.reply(unit, pdu, rsp);
  // libmodbus copied the written values into its mapping before reading: where the ranges
  // overlap the answer must show the image (e.g. the dropped low byte of an odd module).
  if (n == 2 + 2u * rq.read_quantity && rsp[0] == kFcReadWriteMultipleRegisters) {
    for (std::uint16_t i = 0; i < rq.read_quantity; ++i) {
      const std::uint16_t v = regs[rq.read_address - base + i];
      rsp[2 + 2u * i] = static_cast<std::uint8_t>(v >> 8);
      rsp[3 + 2u * i] = static_cast<std::uint8_t>(v & 0xFF);
    }
  }
  return n;
}

std::size_t ModbusGateway::device_id(const ModbusUnitMap* u, const ModbusRequest& rq,
                                     std::span<std::uint8_t, kModbusMaxPdu> rsp) {
  std::array<std::string, 3> objects;
  objects[0] = "pbvbus";
  if (u) {
    char buf[8];
    std::snprintf(buf, sizeof buf, "%04X", static_cast<unsigned>(u->ident));
    objects[1] = buf;
    objects[2] = u->model;
  } else {
    objects[1] = "gateway";
    objects[2] = m_source.name();
  }
  return modbus_device_id_response(rq, std::move(objects), rsp);
}

}  // namespace pbvbus::gateways
