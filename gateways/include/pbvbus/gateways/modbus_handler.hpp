#pragma once
// The seam between the Modbus doors (TCP with MBAP framing, RTU with CRC framing) and the
// Modbus gateway core (docs/gateway-modbus.md). The doors frame, the core answers PDUs: a door strips its
// framing, hands the unit id and the request PDU (function code + data) to handle(), and frames
// whatever PDU comes back. Everything runs on the bus thread (process_source.hpp).

#include <array>
#include <cstddef>
#include <cstdint>
#include <span>

namespace pbvbus::gateways {

/// Longest Modbus PDU (function code + 252 octets of data).
inline constexpr std::size_t kModbusMaxPdu = 253;

/// Modbus exception codes the gateway uses (Modbus Application Protocol V1.1b3, §7).
inline constexpr std::uint8_t kExIllegalFunction = 0x01;
inline constexpr std::uint8_t kExIllegalDataAddress = 0x02;
inline constexpr std::uint8_t kExIllegalDataValue = 0x03;
inline constexpr std::uint8_t kExServerDeviceFailure = 0x04;
inline constexpr std::uint8_t kExGatewayPathUnavailable = 0x0A;
inline constexpr std::uint8_t kExGatewayTargetFailed = 0x0B;

/// Counters a door keeps per gateway (report: clients, requests, exceptions).
struct ModbusDoorStats {
  std::uint64_t clients_accepted = 0;   ///< TCP connections accepted (RTU: 0)
  std::uint64_t clients_now = 0;        ///< open TCP connections
  std::uint64_t clients_closed_bad = 0; ///< closed for a protocol violation, flood or stall
  std::uint64_t clients_evicted = 0;    ///< closed to make room for a new one (max_clients)
  std::uint64_t clients_refused = 0;    ///< accepted and closed at once (max_clients is 0)
  std::uint64_t accept_pauses = 0;      ///< accept() failed (e.g. out of descriptors): paused
  std::uint64_t requests = 0;           ///< well-framed requests handed to the core
  std::uint64_t exceptions = 0;         ///< of their answers, exception responses
  std::uint64_t bad_frames = 0;         ///< dropped: bad MBAP header, bad RTU CRC, overlong
  std::uint64_t no_reply = 0;           ///< requests answered by nothing (RTU broadcast)
};

class ModbusHandler {
 public:
  virtual ~ModbusHandler() = default;
  /// Answers one request. `pdu` = function code + data as received (1..253 octets). Writes the
  /// response PDU into `rsp` (a normal response, or FC|0x80 + exception code) and returns its
  /// length; returns 0 when no response must be sent (`broadcast`: RTU unit 0 — the request is
  /// carried out, nothing is answered). Never throws, whatever the bytes.
  virtual std::size_t handle(std::uint8_t unit, std::span<const std::uint8_t> pdu,
                             std::span<std::uint8_t, kModbusMaxPdu> rsp, bool broadcast) = 0;
};

}  // namespace pbvbus::gateways
