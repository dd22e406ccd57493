#include "pbvbus/gateways/modbus_pdu.hpp"

#include "pbvbus/gateways/modbus_handler.hpp"

namespace pbvbus::gateways {
namespace {

std::uint16_t be16(std::span<const std::uint8_t> p, std::size_t at) {
  return static_cast<std::uint16_t>((p[at] << 8) | p[at + 1]);
}

void put16(std::vector<std::uint8_t>& v, std::uint16_t x) {
  v.push_back(static_cast<std::uint8_t>(x >> 8));
  v.push_back(static_cast<std::uint8_t>(x & 0xFF));
}

ModbusDecoded fail(ModbusRequest r, std::uint8_t ex, std::string_view why) {
  return {r, {ex, why}};
}

/// Address + quantity must stay inside the 64 Ki address space (spec: "Starting Address +
/// Quantity of Outputs" checked, else 0x02).
bool in_space(std::uint16_t address, std::uint16_t quantity) {
  return static_cast<std::uint32_t>(address) + quantity <= 0x10000u;
}

}  // namespace

std::uint16_t ModbusRequest::write_value(std::size_t i) const {
  switch (function) {
    case kFcWriteSingleCoil:
      return values.size() >= 1 && values[0] == 0xFF ? 1 : 0;
    case kFcWriteMultipleCoils:
      if (i / 8 >= values.size()) return 0;
      return static_cast<std::uint16_t>((values[i / 8] >> (i % 8)) & 1u);
    default:
      if (2 * i + 1 >= values.size()) return 0;
      return be16(values, 2 * i);
  }
}

ModbusDecoded decode_modbus_request(std::span<const std::uint8_t> pdu) {
  ModbusRequest r;
  if (pdu.empty()) return fail(r, kExIllegalFunction, "empty PDU");
  r.function = pdu[0];
  const std::size_t n = pdu.size();
  switch (r.function) {
    case kFcReadCoils:
    case kFcReadDiscreteInputs:
    case kFcReadHoldingRegisters:
    case kFcReadInputRegisters: {
      if (n != 5) return fail(r, kExIllegalDataValue, "read request must be 5 octets");
      r.read_address = be16(pdu, 1);
      r.read_quantity = be16(pdu, 3);
      const std::uint16_t max = r.reads_bits() ? kMaxReadBits : kMaxReadRegisters;
      if (r.read_quantity < 1 || r.read_quantity > max)
        return fail(r, kExIllegalDataValue,
                    r.reads_bits() ? "read quantity outside 1..2000"
                                   : "read quantity outside 1..125");
      if (!in_space(r.read_address, r.read_quantity))
        return fail(r, kExIllegalDataAddress, "read range beyond address 65535");
      return {r, {}};
    }
    case kFcWriteSingleCoil:
    case kFcWriteSingleRegister: {
      if (n != 5) return fail(r, kExIllegalDataValue, "single write must be 5 octets");
      r.write_address = be16(pdu, 1);
      r.write_quantity = 1;
      r.values = pdu.subspan(3, 2);
      if (r.function == kFcWriteSingleCoil) {
        const std::uint16_t v = be16(pdu, 3);
        if (v != 0x0000 && v != 0xFF00)
          return fail(r, kExIllegalDataValue, "coil value must be 0x0000 or 0xFF00");
      }
      return {r, {}};
    }
    case kFcWriteMultipleCoils:
    case kFcWriteMultipleRegisters: {
      if (n < 6) return fail(r, kExIllegalDataValue, "multiple write shorter than 6 octets");
      r.write_address = be16(pdu, 1);
      r.write_quantity = be16(pdu, 3);
      const std::size_t byte_count = pdu[5];
      const bool coils = r.function == kFcWriteMultipleCoils;
      const std::uint16_t max = coils ? kMaxWriteCoils : kMaxWriteRegisters;
      if (r.write_quantity < 1 || r.write_quantity > max)
        return fail(r, kExIllegalDataValue,
                    coils ? "coil quantity outside 1..1968" : "register quantity outside 1..123");
      const std::size_t need =
          coils ? (r.write_quantity + 7u) / 8u : 2u * static_cast<std::size_t>(r.write_quantity);
      if (byte_count != need)
        return fail(r, kExIllegalDataValue, "byte count does not match the quantity");
      if (n != 6 + byte_count)
        return fail(r, kExIllegalDataValue, "PDU length does not match the byte count");
      r.values = pdu.subspan(6, byte_count);
      if (!in_space(r.write_address, r.write_quantity))
        return fail(r, kExIllegalDataAddress, "write range beyond address 65535");
      return {r, {}};
    }
    case kFcReadWriteMultipleRegisters: {
      if (n < 10) return fail(r, kExIllegalDataValue, "FC23 request shorter than 10 octets");
      r.read_address = be16(pdu, 1);
      r.read_quantity = be16(pdu, 3);
      r.write_address = be16(pdu, 5);
      r.write_quantity = be16(pdu, 7);
      const std::size_t byte_count = pdu[9];
      if (r.read_quantity < 1 || r.read_quantity > kMaxReadRegisters)
        return fail(r, kExIllegalDataValue, "FC23 read quantity outside 1..125");
      if (r.write_quantity < 1 || r.write_quantity > kMaxRwWriteRegisters)
        return fail(r, kExIllegalDataValue, "FC23 write quantity outside 1..121");
      if (byte_count != 2u * r.write_quantity)
        return fail(r, kExIllegalDataValue, "byte count does not match the quantity");
      if (n != 10 + byte_count)
        return fail(r, kExIllegalDataValue, "PDU length does not match the byte count");
      r.values = pdu.subspan(10, byte_count);
      if (!in_space(r.read_address, r.read_quantity) ||
          !in_space(r.write_address, r.write_quantity))
        return fail(r, kExIllegalDataAddress, "FC23 range beyond address 65535");
      return {r, {}};
    }
    case kFcEncapsulatedInterface: {
      if (n < 2 || pdu[1] != kMeiReadDeviceId)
        return fail(r, kExIllegalFunction, "only MEI type 14 (Read Device Identification)");
      if (n != 4) return fail(r, kExIllegalDataValue, "Read Device ID request must be 4 octets");
      r.read_device_id_code = pdu[2];
      r.object_id = pdu[3];
      if (r.read_device_id_code < 1 || r.read_device_id_code > 4)
        return fail(r, kExIllegalDataValue, "Read Device ID code outside 1..4");
      return {r, {}};
    }
    default:
      return fail(r, kExIllegalFunction, "function code not supported");
  }
}

std::vector<std::uint8_t> encode_modbus_read(std::uint8_t function, std::uint16_t address,
                                             std::uint16_t quantity) {
  std::vector<std::uint8_t> v{function};
  put16(v, address);
  put16(v, quantity);
  return v;
}

std::vector<std::uint8_t> encode_modbus_write_single(std::uint8_t function, std::uint16_t address,
                                                     std::uint16_t value) {
  std::vector<std::uint8_t> v{function};
  put16(v, address);
  put16(v, value);
  return v;
}

std::vector<std::uint8_t> encode_modbus_write_coils(std::uint16_t address,
                                                    const std::vector<bool>& coils) {
  std::vector<std::uint8_t> v{kFcWriteMultipleCoils};
  put16(v, address);
  put16(v, static_cast<std::uint16_t>(coils.size()));
  const std::size_t bytes = (coils.size() + 7) / 8;
  v.push_back(static_cast<std::uint8_t>(bytes));
  for (std::size_t b = 0; b < bytes; ++b) {
    std::uint8_t o = 0;
    for (std::size_t i = 0; i < 8 && b * 8 + i < coils.size(); ++i)
      if (coils[b * 8 + i]) o = static_cast<std::uint8_t>(o | (1u << i));
    v.push_back(o);
  }
  return v;
}

std::vector<std::uint8_t> encode_modbus_write_registers(std::uint16_t address,
                                                        std::span<const std::uint16_t> regs) {
  std::vector<std::uint8_t> v{kFcWriteMultipleRegisters};
  put16(v, address);
  put16(v, static_cast<std::uint16_t>(regs.size()));
  v.push_back(static_cast<std::uint8_t>(regs.size() * 2));
  for (auto r : regs) put16(v, r);
  return v;
}

std::vector<std::uint8_t> encode_modbus_read_write(std::uint16_t read_address,
                                                   std::uint16_t read_quantity,
                                                   std::uint16_t write_address,
                                                   std::span<const std::uint16_t> regs) {
  std::vector<std::uint8_t> v{kFcReadWriteMultipleRegisters};
  put16(v, read_address);
  put16(v, read_quantity);
  put16(v, write_address);
  put16(v, static_cast<std::uint16_t>(regs.size()));
  v.push_back(static_cast<std::uint8_t>(regs.size() * 2));
  for (auto r : regs) put16(v, r);
  return v;
}

std::vector<std::uint8_t> encode_modbus_read_device_id(std::uint8_t code, std::uint8_t object_id) {
  return {kFcEncapsulatedInterface, kMeiReadDeviceId, code, object_id};
}

}  // namespace pbvbus::gateways
