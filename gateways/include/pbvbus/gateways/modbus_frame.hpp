#pragma once
// Modbus framing for the doors (docs/gateway-modbus.md): the MBAP header of Modbus TCP and the RTU frame with
// its CRC. Pure functions and one small state machine, no I/O, fuzzed (fuzz_modbus_frame).
//
// MBAP (Modbus Messaging on TCP/IP Implementation Guide V1.0b §3.1.3): TID(2) PID(2) LEN(2)
// UNIT(1), big-endian. LEN counts UNIT + PDU, so a PDU of 1..253 octets gives LEN 2..254 and a
// whole ADU of at most 7 + 253 = 260 octets. A header with PID != 0 or LEN outside 2..254 is
// not Modbus: the TCP door closes the connection (there is no way to find the next header).
//
// RTU (Modbus over Serial Line V1.02 §2.5.1): UNIT(1) PDU CRC(2), at most 256 octets. The CRC is
// CRC-16/MODBUS: polynomial 0x8005 reflected (0xA001), initial value 0xFFFF, no final XOR, sent
// low byte first.
//
// RtuFramer: a serial line carries no length, and on a pty there is no reliable inter-character
// timing either, so requests are framed by their function code, the way libmodbus does it:
//   FC 01..06            8 octets (unit fc addr(2) qty/value(2) crc(2))
//   FC 08                8 octets (sub-function(2) data(2))
//   FC 07, 11, 12, 17    4 octets (no data)
//   FC 15, 16            7 + byte count (octet 6) + 2
//   FC 22                10 octets (mask write: addr(2) and(2) or(2))
//   FC 23                11 + write byte count (octet 10) + 2
//   FC 24                6 octets (FIFO pointer address(2))
//   FC 43                7 octets (MEI type, code, object id)
//   anything else        unknown length: the frame ends at t3.5 silence (silence()).
// Decisions (also in docs/gateway-modbus-doors.md):
//  - Resync after a bad CRC (or a length rule that gives more than 256 octets, or an unknown-FC
//    frame that grows beyond 256 octets): the candidate's FIRST octet is dropped and framing
//    starts again at the next buffered octet. So a frame that follows garbage, or that follows a
//    frame damaged in its head, is still found without waiting for silence, and one bad octet
//    costs at most one lost request. Each bad candidate counts once in bad_crc / overlong; the
//    octets given up count in dropped_octets.
//  - Silence (t3.5 with no octet) ends everything: an unknown-FC frame is checked (CRC) and
//    delivered; an incomplete fixed-length frame is dropped (octets counted, `incomplete`).
//  - A frame with a good CRC is delivered whatever its unit; filtering (unit 0 = broadcast) is
//    the port's job.

#include <array>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <optional>
#include <span>
#include <string_view>
#include <vector>

#include "pbvbus/gateways/modbus_handler.hpp"

namespace pbvbus::gateways {

inline constexpr std::size_t kMbapHeaderLen = 7;
inline constexpr std::size_t kModbusTcpMaxAdu = kMbapHeaderLen + kModbusMaxPdu;  // 260
inline constexpr std::size_t kModbusRtuMaxAdu = 256;

struct MbapHeader {
  std::uint16_t transaction_id = 0;
  std::uint16_t protocol_id = 0;
  std::uint16_t length = 0;  ///< octets following LEN: unit + PDU
  std::uint8_t unit = 0;
  friend bool operator==(const MbapHeader&, const MbapHeader&) = default;
};

enum class MbapError : std::uint8_t { None, Short, ProtocolId, LengthTooSmall, LengthTooLarge };
/// "ok", "short header", "protocol id not 0", "length below 2", "length above 254".
std::string_view to_string(MbapError e);

struct MbapDecoded {
  MbapHeader header;
  MbapError error = MbapError::Short;
  bool ok() const { return error == MbapError::None; }
  /// Octets of the PDU that follow the 7-octet header (valid when ok()).
  std::size_t pdu_len() const { return header.length - 1u; }
  /// Octets of the whole ADU, header included (valid when ok()).
  std::size_t adu_len() const { return 6u + header.length; }
};

/// Decodes the first 7 octets of `bytes` (more may follow; they are not looked at).
MbapDecoded decode_mbap(std::span<const std::uint8_t> bytes);
/// Writes the 7-octet header.
void encode_mbap(const MbapHeader& h, std::span<std::uint8_t, kMbapHeaderLen> out);
/// A whole TCP ADU: header (PID 0, LEN = 1 + pdu.size()) + PDU into `out`. Returns its length,
/// or 0 (nothing written) when the PDU is empty or longer than 253 octets or `out` too small.
std::size_t encode_tcp_adu(std::uint16_t transaction_id, std::uint8_t unit,
                           std::span<const std::uint8_t> pdu, std::span<std::uint8_t> out);

/// CRC-16/MODBUS over `bytes` (the value; its low byte goes first on the wire).
std::uint16_t crc16_modbus(std::span<const std::uint8_t> bytes);
/// A whole RTU ADU: unit + PDU + CRC (low, high). Returns its length, or 0 when the PDU is empty
/// or longer than 253 octets or `out` too small.
std::size_t encode_rtu_adu(std::uint8_t unit, std::span<const std::uint8_t> pdu,
                           std::span<std::uint8_t> out);
/// The RTU request length the function code defines, given the first octets of a frame:
/// a length, 0 when more octets are needed to tell (byte count not yet here), nullopt when the
/// function code has no length rule (unknown FC: framed by silence). `head` must hold at least
/// 2 octets (unit, FC), else 0.
std::optional<std::size_t> rtu_request_length(std::span<const std::uint8_t> head);

/// One good RTU frame (the spans point into the framer's buffer; valid during the callback).
struct RtuFrame {
  std::uint8_t unit = 0;
  std::span<const std::uint8_t> pdu;  ///< function code + data, without unit and CRC
  std::span<const std::uint8_t> adu;  ///< the whole frame, CRC included
};

class RtuFramer {
 public:
  using Sink = std::function<void(const RtuFrame&)>;
  struct Stats {
    std::uint64_t frames = 0;          ///< good frames delivered
    std::uint64_t bad_crc = 0;         ///< candidates whose CRC did not match
    std::uint64_t overlong = 0;        ///< candidates longer than 256 octets
    std::uint64_t incomplete = 0;      ///< partial frames ended by silence
    std::uint64_t dropped_octets = 0;  ///< octets given up while resynchronising
  };

  /// Takes received octets; calls `sink` for every complete frame with a good CRC, in order.
  void feed(std::span<const std::uint8_t> bytes, const Sink& sink);
  /// The line has been silent for t3.5: ends a frame of unknown length (delivered if its CRC
  /// is good) and drops whatever else is pending.
  void silence(const Sink& sink);
  /// Octets buffered (a frame in progress).
  std::size_t pending() const { return m_len; }
  const Stats& stats() const { return m_stats; }

 private:
  void scan(const Sink& sink);
  void drop_front(std::size_t n);
  bool deliver_if_good(std::size_t len, const Sink& sink);

  std::array<std::uint8_t, 2 * kModbusRtuMaxAdu> m_buf{};
  std::size_t m_len = 0;
  Stats m_stats;
};

}  // namespace pbvbus::gateways
