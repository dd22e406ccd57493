#pragma once
// A request-PDU decoder for the function codes the Modbus gateway serves (docs/gateway-modbus.md): 01, 02,
// 03, 04, 05, 06, 15, 16, 23 and 43/14. It does every length and quantity check of the Modbus
// Application Protocol V1.1b3 (§6) so the gateway can pre-check a request against a slave's map
// before libmodbus sees it; libmodbus then only ever gets well-formed requests.
//
// Decisions (docs/gateway-modbus.md "Request checks"):
// - Errors are values (the exception code and a fixed reason text); nothing throws.
// - Order of the checks: function code (0x01), then PDU length and quantity/byte count/value
//   (0x03), then the address range against the 64 Ki address space (0x02) — the order of the
//   spec's state diagrams. The gateway checks the slave's map (0x02) afterwards.
// - A PDU whose length does not match its function code (too short, trailing octets) is 0x03:
//   the spec has no code of its own for it and 0x03 is what its diagrams give for a byte count
//   that does not fit.
// - Quantity limits from the spec: reads 1..2000 bits (FC01/02) and 1..125 registers (FC03/04,
//   FC23 read part); writes 1..1968 coils (FC15), 1..123 registers (FC16), 1..121 (FC23 write).
// - FC05 value must be 0x0000 or 0xFF00 (else 0x03). FC43 only with MEI type 14 (else 0x01),
//   Read Device ID code 1..4 (else 0x03).
// - `values` points into the caller's PDU (no copy): keep the PDU alive while using it.

#include <cstddef>
#include <cstdint>
#include <span>
#include <string_view>
#include <vector>

namespace pbvbus::gateways {

/// Function codes the gateway knows (Modbus Application Protocol V1.1b3 §6).
inline constexpr std::uint8_t kFcReadCoils = 0x01;
inline constexpr std::uint8_t kFcReadDiscreteInputs = 0x02;
inline constexpr std::uint8_t kFcReadHoldingRegisters = 0x03;
inline constexpr std::uint8_t kFcReadInputRegisters = 0x04;
inline constexpr std::uint8_t kFcWriteSingleCoil = 0x05;
inline constexpr std::uint8_t kFcWriteSingleRegister = 0x06;
inline constexpr std::uint8_t kFcWriteMultipleCoils = 0x0F;
inline constexpr std::uint8_t kFcWriteMultipleRegisters = 0x10;
inline constexpr std::uint8_t kFcReadWriteMultipleRegisters = 0x17;
inline constexpr std::uint8_t kFcEncapsulatedInterface = 0x2B;
inline constexpr std::uint8_t kMeiReadDeviceId = 0x0E;

/// Spec quantity limits.
inline constexpr std::uint16_t kMaxReadBits = 2000;
inline constexpr std::uint16_t kMaxReadRegisters = 125;
inline constexpr std::uint16_t kMaxWriteCoils = 1968;
inline constexpr std::uint16_t kMaxWriteRegisters = 123;
inline constexpr std::uint16_t kMaxRwWriteRegisters = 121;

/// A decoded request. Which fields mean something depends on the function code:
/// - FC01..04: read_address/read_quantity.
/// - FC05: write_address, write_quantity = 1, values = the 2 value octets (FF 00 / 00 00).
/// - FC06: write_address, write_quantity = 1, values = the 2 register octets.
/// - FC15: write_address/write_quantity (coils), values = the packed coil octets (LSB first).
/// - FC16: write_address/write_quantity, values = 2 octets per register, high byte first.
/// - FC23: both; the write part is done before the read part.
/// - FC43/14: read_device_id_code (1..4) and object_id.
struct ModbusRequest {
  std::uint8_t function = 0;
  std::uint16_t read_address = 0;
  std::uint16_t read_quantity = 0;
  std::uint16_t write_address = 0;
  std::uint16_t write_quantity = 0;
  std::span<const std::uint8_t> values;
  std::uint8_t read_device_id_code = 0;
  std::uint8_t object_id = 0;

  bool reads_bits() const { return function == kFcReadCoils || function == kFcReadDiscreteInputs; }
  bool writes() const {
    return function == kFcWriteSingleCoil || function == kFcWriteSingleRegister ||
           function == kFcWriteMultipleCoils || function == kFcWriteMultipleRegisters ||
           function == kFcReadWriteMultipleRegisters;
  }
  /// The write part's value for register/coil `i` (0-based within the write range): a register
  /// value, or 0/1 for a coil.
  std::uint16_t write_value(std::size_t i) const;
};

/// Why a request was refused: the exception code to answer and a fixed text for logs/tests.
struct ModbusPduError {
  std::uint8_t exception = 0;
  std::string_view reason;
};

struct ModbusDecoded {
  ModbusRequest request;
  ModbusPduError error;  ///< exception == 0: decoded fine
  bool ok() const { return error.exception == 0; }
};

/// Decodes a request PDU (function code + data). Never throws, whatever the bytes.
ModbusDecoded decode_modbus_request(std::span<const std::uint8_t> pdu);

/// Encoders for tests and tools (they do not check limits: tests build bad requests with them).
std::vector<std::uint8_t> encode_modbus_read(std::uint8_t function, std::uint16_t address,
                                             std::uint16_t quantity);
std::vector<std::uint8_t> encode_modbus_write_single(std::uint8_t function, std::uint16_t address,
                                                     std::uint16_t value);
/// FC15: coil values 0/1, packed LSB first.
std::vector<std::uint8_t> encode_modbus_write_coils(std::uint16_t address,
                                                    const std::vector<bool>& coils);
/// FC16.
std::vector<std::uint8_t> encode_modbus_write_registers(std::uint16_t address,
                                                        std::span<const std::uint16_t> regs);
/// FC23.
std::vector<std::uint8_t> encode_modbus_read_write(std::uint16_t read_address,
                                                   std::uint16_t read_quantity,
                                                   std::uint16_t write_address,
                                                   std::span<const std::uint16_t> regs);
/// FC43/14.
std::vector<std::uint8_t> encode_modbus_read_device_id(std::uint8_t code, std::uint8_t object_id);

}  // namespace pbvbus::gateways
