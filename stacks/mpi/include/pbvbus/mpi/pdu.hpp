#pragma once
// MPI connection-layer PDUs: the octets an MPI station puts in the FDL DU after DA SA FC DSAP
// SSAP (protocol-facts.md §H.3; source S4, libnodave nodave.c `_daveConnectPLCMPI1`,
// `_daveSendAck`, `_daveSendWithPrefix2`, `_daveDisconnectPLCMPI`).
//
//   Connect request      E0 <11 connect parameters>     PG -> PLC, DSAP 0x00, SSAP = PG's SAP
//   Connect confirm      D0 <11 connect parameters>     PLC -> PG; its SSAP is the PLC's SAP
//   Connection ack       05 01                          both ways after the confirm
//   Data                 F1 <msgNr> <S7 PDU...>         either way
//   Data ack             B0 01 <msgNr>                  receiver -> sender, its own SRD frame
//   Disconnect request   80                             PG -> PLC
//
// decode() takes the whole MPI PDU (the FDL telegram's `data` after the SAP octets) and never
// reads outside it; errors are values with a reason. encode() produces exactly what decode()
// accepts: decode(encode(p)) == p for every p encode() accepts.
//
// Uncertain octets (§H.3 [U]): the 11 connect parameters are opaque — carried as they are, the
// trace's values (kTraceConnectParams) used when we originate a connection; the second octet
// 0x01 of the connection ack and of the data ack is not explained by the source, so it is
// required to be 0x01 (the only value the traces and libnodave show). §H.3 documents no
// disconnect reply ("the PLC's reply is not decoded"), so there is no PDU for one here; see
// docs/mpi.md for how a disconnect completes.

#include <array>
#include <cstddef>
#include <cstdint>
#include <span>
#include <string_view>

#include "pbvbus/fdl/telegram.hpp"

namespace pbvbus::mpi {

// First octet of each PDU (§H.3).
inline constexpr std::uint8_t kConnectRequest = 0xE0;
inline constexpr std::uint8_t kConnectConfirm = 0xD0;
inline constexpr std::uint8_t kConnectionAck = 0x05;
inline constexpr std::uint8_t kData = 0xF1;
inline constexpr std::uint8_t kDataAck = 0xB0;
inline constexpr std::uint8_t kDisconnectRequest = 0x80;
/// Second octet of the connection ack and of the data ack: always 0x01 in S4 [U: meaning unknown].
inline constexpr std::uint8_t kAckSubcode = 0x01;

/// DSAP of a connect request: the PLC's connection-management SAP (§H.3 trace: DSAP 0x00).
inline constexpr std::uint8_t kConnectSap = 0x00;
/// libnodave's first own SAP (`nextConnection = 0x14`); the PLC in the trace also answers
/// from 0x14 (§H.3).
inline constexpr std::uint8_t kFirstConnectionSap = 0x14;

inline constexpr std::size_t kConnectParamsLen = 11;
using ConnectParams = std::array<std::uint8_t, kConnectParamsLen>;
/// The connect parameters of the §H.3 trace (request and confirm carry the same octets).
/// Not decoded [U]; S4 sends them as they are.
inline constexpr ConnectParams kTraceConnectParams = {0x04, 0x00, 0x80, 0x00, 0x02, 0x00,
                                                      0x02, 0x01, 0x00, 0x01, 0x00};

/// Largest MPI PDU: the FDL DU limit (§B.1: 246 octets incl. the two SAP octets).
inline constexpr std::size_t kMaxPduLen = fdl::kMaxDu - 2;
/// Largest S7 PDU in one data message (after F1 and the message number).
inline constexpr std::size_t kMaxDataLen = kMaxPduLen - 2;

enum class PduType : std::uint8_t {
  ConnectRequest,
  ConnectConfirm,
  ConnectionAck,
  Data,
  DataAck,
  DisconnectRequest,
};
std::string_view to_string(PduType t);

/// One decoded (or to-be-encoded) MPI PDU. Only the fields of its type are meaningful.
struct Pdu {
  PduType type = PduType::DisconnectRequest;
  ConnectParams connect_params = kTraceConnectParams;  ///< ConnectRequest/ConnectConfirm
  std::uint8_t message_number = 0;                     ///< Data, DataAck
  std::span<const std::uint8_t> data;                  ///< Data: the S7 PDU (points into the input)

  static Pdu connect_request(const ConnectParams& p = kTraceConnectParams);
  static Pdu connect_confirm(const ConnectParams& p = kTraceConnectParams);
  static Pdu connection_ack();
  static Pdu data_message(std::uint8_t msg_nr, std::span<const std::uint8_t> s7_pdu);
  static Pdu data_ack(std::uint8_t msg_nr);
  static Pdu disconnect_request();
};

enum class DecodeError : std::uint8_t {
  None = 0,
  Empty,            ///< no octets at all
  UnknownType,      ///< first octet is none of E0 D0 05 F1 B0 80
  BadLength,        ///< a fixed-length PDU with too few or too many octets
  BadAckSubcode,    ///< 05 xx or B0 xx with xx != 01
  EmptyData,        ///< F1 msgNr with no S7 PDU after it
  TooLong,          ///< more octets than an FDL frame can carry (kMaxPduLen)
};
std::string_view to_string(DecodeError e);

/// Decodes one whole MPI PDU. On success `out.data` points into `bytes`.
DecodeError decode(std::span<const std::uint8_t> bytes, Pdu& out);

/// An encoded PDU; fixed storage, no allocation.
struct PduBuffer {
  std::array<std::uint8_t, kMaxPduLen> buf{};
  std::uint8_t len = 0;
  std::span<const std::uint8_t> bytes() const { return {buf.data(), len}; }
};

enum class EncodeError : std::uint8_t {
  None = 0,
  EmptyData,  ///< a data message without an S7 PDU
  TooLong,    ///< a data message longer than kMaxDataLen
};
std::string_view to_string(EncodeError e);

EncodeError encode(const Pdu& pdu, PduBuffer& out);

/// The sender's next message number (§H.3, S4 `_daveIncMessageNumber`): 8 bits, counting from
/// 0; after 255 comes 1, never 0 again.
constexpr std::uint8_t next_message_number(std::uint8_t n) {
  return n == 0xFF ? std::uint8_t{1} : static_cast<std::uint8_t>(n + 1);
}

}  // namespace pbvbus::mpi
