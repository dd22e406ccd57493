#include "pbvbus/gateways/modbus_map.hpp"

#include <cstdio>

namespace pbvbus::gateways {
namespace {

struct Field {
  std::uint16_t address;
  std::uint16_t count;
  const char* type;
  const char* description;
};

// The status block and the gateway unit's registers, for the printed map (one source of truth
// for to_text/to_json/to_csv).
constexpr Field kStatusFields[] = {
    {kStatusState, 1, "UINT16",
     "DP state: 1 Inactive 2 Diag 3 Prm 4 Cfg 5 CheckDiag 6 DataExchange 7 NotPresent 8 Locked"},
    {kStatusFlags, 1, "UINT16 bits",
     "flags: b0 data valid, b1 ext diag, b2 station failure, b3 prm fault, b4 cfg fault, "
     "b5 switched, b6 redundancy lost, b7 active channel B, b8 standby view"},
    {kStatusLifeCounter, 1, "UINT16", "life counter (Data_Exchange cycles mod 65536)"},
    {kStatusIdent, 1, "UINT16", "Ident_Number"},
    {kStatusActiveChannel, 1, "UINT16", "active channel: 0 A, 1 B, 65535 none"},
    {kStatusFailures, 1, "UINT16", "station failures (mod 65536)"},
    {kStatusReturns, 1, "UINT16", "station returns (mod 65536)"},
    {kStatusDiagLength, 1, "UINT16", "diagnosis length in octets"},
    {kStatusDiag, kStatusDiagRegisters, "BYTES AB CD", "raw Slave_Diag, high byte first"},
};

constexpr Field kGatewayFields[] = {
    {kGwLiveList, 8, "UINT16 bits", "live list: stations in data exchange (reg r bit n = 16r+n)"},
    {kGwConfigured, 8, "UINT16 bits", "configured stations (reg r bit n = station 16r+n)"},
    {kGwMasterMode, 1, "UINT16", "master mode: 1 Offline 2 Stop 3 Clear 4 Operate"},
    {kGwMasterAddress, 1, "UINT16", "master address"},
    {kGwStationFailures, 2, "UINT32 AB CD", "station failures"},
    {kGwStationReturns, 2, "UINT32 AB CD", "station returns"},
    {kGwDiagnoses, 2, "UINT32 AB CD", "diagnoses read"},
    {kGwAlarms, 2, "UINT32 AB CD", "alarms"},
    {kGwSwitchovers, 2, "UINT32 AB CD", "channel switchovers"},
    {kGwModbusRequests, 2, "UINT32 AB CD", "Modbus requests"},
    {kGwModbusExceptions, 2, "UINT32 AB CD", "Modbus exception responses"},
    {kGwHPresent, 1, "UINT16", "H-system present (1) or not (0)"},
    {kGwHCpuState, 2, "UINT16", "CPU state rack 0, rack 1"},
    {kGwHCpuRole, 2, "UINT16", "CPU role rack 0, rack 1"},
    {kGwHSystemMode, 1, "UINT16", "H system mode"},
    {kGwHMasterRack, 1, "UINT16", "master rack (0/1, 65535 none)"},
};

std::string csv_quote(std::string_view s) {
  bool need = s.find_first_of(",\"\n\r") != std::string_view::npos;
  if (!need) return std::string(s);
  std::string r = "\"";
  for (char c : s) {
    if (c == '"') r += '"';
    r += c;
  }
  return r + '"';
}

std::string json_quote(std::string_view s) {
  std::string r = "\"";
  for (char c : s) {
    const auto u = static_cast<unsigned char>(c);
    if (c == '"' || c == '\\') {
      r += '\\';
      r += c;
    } else if (u < 0x20) {
      char buf[8];
      std::snprintf(buf, sizeof buf, "\\u%04x", u);
      r += buf;
    } else {
      r += c;
    }
  }
  return r + '"';
}

std::string data_type(WordOrder o) { return std::string("BYTES ") + std::string(to_string(o)); }

}  // namespace

std::string_view to_string(ModbusTable t) {
  switch (t) {
    case ModbusTable::InputRegister: return "input_register";
    case ModbusTable::HoldingRegister: return "holding_register";
    case ModbusTable::DiscreteInput: return "discrete_input";
    case ModbusTable::Coil: return "coil";
  }
  return "?";
}

std::string_view to_string(WordOrder o) {
  switch (o) {
    case WordOrder::HighByteFirst: return "AB CD";
    case WordOrder::ByteSwap: return "BA DC";
    case WordOrder::WordSwap: return "CD AB";
    case WordOrder::ByteWordSwap: return "DC BA";
  }
  return "?";
}

std::string_view to_string(StaleReaction r) {
  switch (r) {
    case StaleReaction::Exception: return "exception";
    case StaleReaction::KeepLast: return "keep_last";
    case StaleReaction::Zero: return "zero";
    case StaleReaction::Value: return "value";
  }
  return "?";
}

std::uint16_t modbus_state_code(dp::SlaveStatusState s) {
  return static_cast<std::uint16_t>(static_cast<unsigned>(s) + 1u);
}

std::uint16_t modbus_mode_code(dp::MasterMode m) {
  return static_cast<std::uint16_t>(static_cast<unsigned>(m) + 1u);
}

ModbusMap::ModbusMap(const ProcessSource& source, const ModbusGatewayOptions& options)
    : m_source_name(source.name()), m_gateway_units(options.gateway_units) {
  m_index.fill(-1);
  const bool standby = options.standby_units && source.redundant();
  for (int pass = 0; pass < (standby ? 2 : 1); ++pass) {
    for (const SourceSlave& s : source.slaves()) {
      if (s.address == 0 || s.address > 125) {
        if (pass == 0)
          m_warnings.push_back("slave at address " + std::to_string(s.address) +
                               " not mapped: unit 0 is the gateway, units above 125 are not "
                               "slave addresses");
        continue;
      }
      if (pass == 1 && !s.switched) continue;  // a one-sided slave has no standby side
      if (pass == 1 && s.address > kMaxStandbyAddress) {
        // Seed 003 p. 93 (Swap Address at Switchover): primary addresses 1..119, the standby at
        // address + 128 <= 247; 248..255 are reserved by Modbus over Serial Line §2.2.
        m_warnings.push_back("slave at address " + std::to_string(s.address) +
                             " has no standby unit: address + 128 would be a reserved Modbus "
                             "address (standby units only for addresses 1..119)");
        continue;
      }
      const ModbusSlaveOptions& so = options.slave(s.address);
      ModbusUnitMap u;
      u.address = s.address;
      u.side = pass == 0 ? Side::Primary : Side::Standby;
      u.unit = static_cast<std::uint8_t>(pass == 0 ? s.address : s.address + 128);
      u.model = s.name;
      u.ident = s.ident;
      u.writable = pass == 0 && s.outputs_writable;
      u.stale = so.stale;
      u.stale_value = so.stale_value;
      u.input_len = s.input_len;
      u.output_len = s.output_len;
      for (std::size_t i = 0; i < s.modules.size(); ++i) {
        const SourceModule& sm = s.modules[i];
        ModbusModuleMap m;
        m.module = i;
        m.name = sm.name;
        m.in_offset = sm.in_offset;
        m.in_len = sm.in_len;
        m.out_offset = sm.out_offset;
        m.out_len = sm.out_len;
        auto it = so.module_word_order.find(i);
        m.order = it == so.module_word_order.end() ? so.word_order : it->second;
        m.input_register = u.input_registers;
        m.input_registers = static_cast<std::uint16_t>((sm.in_len + 1) / 2);
        m.holding_register = u.holding_registers;
        m.holding_registers = static_cast<std::uint16_t>((sm.out_len + 1) / 2);
        u.input_registers = static_cast<std::uint16_t>(u.input_registers + m.input_registers);
        u.holding_registers =
            static_cast<std::uint16_t>(u.holding_registers + m.holding_registers);
        for (std::uint16_t r = 0; r < m.input_registers; ++r)
          u.input_register_module.push_back(static_cast<std::uint16_t>(i));
        for (std::uint16_t r = 0; r < m.holding_registers; ++r)
          u.holding_register_module.push_back(static_cast<std::uint16_t>(i));
        u.modules.push_back(std::move(m));
      }
      // A DP telegram is at most 244 octets (≤ 244 registers with padding), far below the
      // status block: the data area can never reach 4096.
      m_index[u.unit] = static_cast<int>(m_units.size());
      m_units.push_back(std::move(u));
    }
  }
}

const ModbusUnitMap* ModbusMap::unit(std::uint8_t unit) const {
  const int i = m_index[unit];
  return i < 0 ? nullptr : &m_units[static_cast<std::size_t>(i)];
}

std::string ModbusMap::to_text() const {
  std::string t = "Modbus register map of " + m_source_name + "\n";
  char buf[256];
  for (const auto& w : m_warnings) t += "warning: " + w + "\n";
  if (m_gateway_units) {
    t += "unit 0 / 255: the gateway\n  input registers:\n";
    for (const Field& f : kGatewayFields) {
      std::snprintf(buf, sizeof buf, "    %5u..%-5u %-13s %s\n", f.address,
                    f.address + f.count - 1u, f.type, f.description);
      t += buf;
    }
    t += "  holding register 0: master mode (write 2 Stop, 3 Clear, 4 Operate)\n";
  }
  for (const ModbusUnitMap& u : m_units) {
    std::snprintf(buf, sizeof buf, "unit %u: slave %u %s (ident 0x%04X)%s%s, stale data: %s\n",
                  u.unit, u.address, u.model.c_str(), u.ident,
                  u.side == Side::Standby ? ", standby side" : "",
                  u.writable ? "" : ", read-only", std::string(to_string(u.stale)).c_str());
    t += buf;
    for (const ModbusModuleMap& m : u.modules) {
      std::snprintf(buf, sizeof buf, "  module %zu %s [%s]:", m.module, m.name.c_str(),
                    std::string(to_string(m.order)).c_str());
      t += buf;
      if (m.in_len > 0) {
        std::snprintf(buf, sizeof buf, " IR %u..%u (%zu octets), DI %zu..%zu",
                      m.input_register, m.input_register + m.input_registers - 1u, m.in_len,
                      m.in_offset * 8, (m.in_offset + m.in_len) * 8 - 1);
        t += buf;
      }
      if (m.out_len > 0) {
        std::snprintf(buf, sizeof buf, " HR %u..%u (%zu octets), coils %zu..%zu",
                      m.holding_register, m.holding_register + m.holding_registers - 1u,
                      m.out_len, m.out_offset * 8, (m.out_offset + m.out_len) * 8 - 1);
        t += buf;
      }
      if (m.in_len == 0 && m.out_len == 0) t += " no data";
      t += "\n";
    }
    std::snprintf(buf, sizeof buf, "  status: IR %u..%u, mirrored read-only in HR\n",
                  kStatusBase, kStatusBase + kStatusRegisters - 1u);
    t += buf;
  }
  return t;
}

std::string ModbusMap::to_json() const {
  std::string j = "{\"source\":" + json_quote(m_source_name) +
                  ",\"gateway_units\":" + (m_gateway_units ? "true" : "false") + ",\"units\":[";
  bool first_u = true;
  for (const ModbusUnitMap& u : m_units) {
    if (!first_u) j += ",";
    first_u = false;
    j += "{\"unit\":" + std::to_string(u.unit) + ",\"slave\":" + std::to_string(u.address) +
         ",\"side\":" + (u.side == Side::Primary ? "\"primary\"" : "\"standby\"") +
         ",\"model\":" + json_quote(u.model) + ",\"ident\":" + std::to_string(u.ident) +
         ",\"writable\":" + (u.writable ? "true" : "false") +
         ",\"stale\":" + json_quote(to_string(u.stale)) +
         ",\"input_registers\":" + std::to_string(u.input_registers) +
         ",\"holding_registers\":" + std::to_string(u.holding_registers) +
         ",\"discrete_inputs\":" + std::to_string(u.input_len * 8) +
         ",\"coils\":" + std::to_string(u.output_len * 8) +
         ",\"status_block\":" + std::to_string(kStatusBase) + ",\"modules\":[";
    bool first_m = true;
    for (const ModbusModuleMap& m : u.modules) {
      if (!first_m) j += ",";
      first_m = false;
      j += "{\"slot\":" + std::to_string(m.module) + ",\"name\":" + json_quote(m.name) +
           ",\"word_order\":" + json_quote(to_string(m.order)) +
           ",\"in_octets\":" + std::to_string(m.in_len) +
           ",\"out_octets\":" + std::to_string(m.out_len);
      if (m.in_len > 0)
        j += ",\"input_register\":" + std::to_string(m.input_register) +
             ",\"input_register_count\":" + std::to_string(m.input_registers) +
             ",\"discrete_input\":" + std::to_string(m.in_offset * 8);
      if (m.out_len > 0)
        j += ",\"holding_register\":" + std::to_string(m.holding_register) +
             ",\"holding_register_count\":" + std::to_string(m.holding_registers) +
             ",\"coil\":" + std::to_string(m.out_offset * 8);
      j += "}";
    }
    j += "]}";
  }
  j += "],\"warnings\":[";
  for (std::size_t i = 0; i < m_warnings.size(); ++i)
    j += (i ? "," : "") + json_quote(m_warnings[i]);
  return j + "]}";
}

std::string ModbusMap::to_csv() const {
  std::string c = "unit,table,first_address,count,slave,slot,module,data_type,description\n";
  auto row = [&c](unsigned unit, ModbusTable t, std::size_t first, std::size_t count,
                  const std::string& slave, const std::string& slot, std::string_view module,
                  std::string_view type, std::string_view desc) {
    c += std::to_string(unit) + "," + std::string(to_string(t)) + "," + std::to_string(first) +
         "," + std::to_string(count) + "," + slave + "," + slot + "," + csv_quote(module) + "," +
         csv_quote(type) + "," + csv_quote(desc) + "\n";
  };
  if (m_gateway_units) {
    for (unsigned gu : {0u, 255u}) {
      for (const Field& f : kGatewayFields)
        row(gu, ModbusTable::InputRegister, f.address, f.count, "", "", "gateway", f.type,
            f.description);
      row(gu, ModbusTable::HoldingRegister, kGwHrMasterMode, 1, "", "", "gateway", "UINT16",
          "master mode: read current, write 2 Stop 3 Clear 4 Operate");
    }
  }
  for (const ModbusUnitMap& u : m_units) {
    const std::string slave = std::to_string(u.address);
    const std::string side = u.side == Side::Standby ? " (standby side, read-only)" : "";
    for (const ModbusModuleMap& m : u.modules) {
      const std::string slot = std::to_string(m.module);
      if (m.in_len > 0) {
        row(u.unit, ModbusTable::InputRegister, m.input_register, m.input_registers, slave, slot,
            m.name, data_type(m.order),
            std::to_string(m.in_len) + " input octets from octet " +
                std::to_string(m.in_offset) + side);
        row(u.unit, ModbusTable::DiscreteInput, m.in_offset * 8, m.in_len * 8, slave, slot,
            m.name, "BIT", "input bits, octet x 8 + bit" + side);
      }
      if (m.out_len > 0) {
        row(u.unit, ModbusTable::HoldingRegister, m.holding_register, m.holding_registers, slave,
            slot, m.name, data_type(m.order),
            std::to_string(m.out_len) + " output octets from octet " +
                std::to_string(m.out_offset) + side);
        row(u.unit, ModbusTable::Coil, m.out_offset * 8, m.out_len * 8, slave, slot, m.name,
            "BIT", "output bits, octet x 8 + bit" + side);
      }
    }
    for (const Field& f : kStatusFields)
      row(u.unit, ModbusTable::InputRegister, f.address, f.count, slave, "", "status", f.type,
          f.description);
    row(u.unit, ModbusTable::HoldingRegister, kStatusBase, kStatusRegisters, slave, "", "status",
        "UINT16", "read-only mirror of the status block");
  }
  return c;
}

}  // namespace pbvbus::gateways
