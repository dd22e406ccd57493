// MPI connection-layer PDU codec (protocol-facts.md §H.3).
#include "pbvbus/mpi/pdu.hpp"

#include <algorithm>

namespace pbvbus::mpi {

std::string_view to_string(PduType t) {
  switch (t) {
    case PduType::ConnectRequest: return "connect request";
    case PduType::ConnectConfirm: return "connect confirm";
    case PduType::ConnectionAck: return "connection ack";
    case PduType::Data: return "data";
    case PduType::DataAck: return "data ack";
    case PduType::DisconnectRequest: return "disconnect request";
  }
  return "?";
}

std::string_view to_string(DecodeError e) {
  switch (e) {
    case DecodeError::None: return "ok";
    case DecodeError::Empty: return "empty PDU";
    case DecodeError::UnknownType: return "unknown PDU type octet";
    case DecodeError::BadLength: return "wrong length for the PDU type";
    case DecodeError::BadAckSubcode: return "second octet of an ack is not 0x01";
    case DecodeError::EmptyData: return "data message without an S7 PDU";
    case DecodeError::TooLong: return "PDU longer than an FDL frame carries";
  }
  return "?";
}

std::string_view to_string(EncodeError e) {
  switch (e) {
    case EncodeError::None: return "ok";
    case EncodeError::EmptyData: return "data message without an S7 PDU";
    case EncodeError::TooLong: return "S7 PDU longer than one data message carries";
  }
  return "?";
}

Pdu Pdu::connect_request(const ConnectParams& p) {
  Pdu r;
  r.type = PduType::ConnectRequest;
  r.connect_params = p;
  return r;
}
Pdu Pdu::connect_confirm(const ConnectParams& p) {
  Pdu r;
  r.type = PduType::ConnectConfirm;
  r.connect_params = p;
  return r;
}
Pdu Pdu::connection_ack() {
  Pdu r;
  r.type = PduType::ConnectionAck;
  return r;
}
Pdu Pdu::data_message(std::uint8_t msg_nr, std::span<const std::uint8_t> s7_pdu) {
  Pdu r;
  r.type = PduType::Data;
  r.message_number = msg_nr;
  r.data = s7_pdu;
  return r;
}
Pdu Pdu::data_ack(std::uint8_t msg_nr) {
  Pdu r;
  r.type = PduType::DataAck;
  r.message_number = msg_nr;
  return r;
}
Pdu Pdu::disconnect_request() { return Pdu{}; }

namespace {
DecodeError decode_connect(PduType type, std::span<const std::uint8_t> b, Pdu& out) {
  if (b.size() != 1 + kConnectParamsLen) return DecodeError::BadLength;
  out.type = type;
  std::copy(b.begin() + 1, b.end(), out.connect_params.begin());
  return DecodeError::None;
}
}  // namespace

DecodeError decode(std::span<const std::uint8_t> b, Pdu& out) {
  if (b.empty()) return DecodeError::Empty;
  if (b.size() > kMaxPduLen) return DecodeError::TooLong;
  Pdu p;
  switch (b[0]) {
    case kConnectRequest: {
      const DecodeError e = decode_connect(PduType::ConnectRequest, b, p);
      if (e != DecodeError::None) return e;
      break;
    }
    case kConnectConfirm: {
      const DecodeError e = decode_connect(PduType::ConnectConfirm, b, p);
      if (e != DecodeError::None) return e;
      break;
    }
    case kConnectionAck:
      if (b.size() != 2) return DecodeError::BadLength;
      if (b[1] != kAckSubcode) return DecodeError::BadAckSubcode;
      p.type = PduType::ConnectionAck;
      break;
    case kData:
      if (b.size() < 2) return DecodeError::BadLength;
      if (b.size() == 2) return DecodeError::EmptyData;
      p.type = PduType::Data;
      p.message_number = b[1];
      p.data = b.subspan(2);
      break;
    case kDataAck:
      if (b.size() != 3) return DecodeError::BadLength;
      if (b[1] != kAckSubcode) return DecodeError::BadAckSubcode;
      p.type = PduType::DataAck;
      p.message_number = b[2];
      break;
    case kDisconnectRequest:
      if (b.size() != 1) return DecodeError::BadLength;
      p.type = PduType::DisconnectRequest;
      break;
    default:
      return DecodeError::UnknownType;
  }
  out = p;
  return DecodeError::None;
}

EncodeError encode(const Pdu& p, PduBuffer& out) {
  std::size_t n = 0;
  auto put = [&](std::uint8_t v) { out.buf[n++] = v; };
  switch (p.type) {
    case PduType::ConnectRequest:
    case PduType::ConnectConfirm:
      put(p.type == PduType::ConnectRequest ? kConnectRequest : kConnectConfirm);
      for (const std::uint8_t v : p.connect_params) put(v);
      break;
    case PduType::ConnectionAck:
      put(kConnectionAck);
      put(kAckSubcode);
      break;
    case PduType::Data:
      if (p.data.empty()) return EncodeError::EmptyData;
      if (p.data.size() > kMaxDataLen) return EncodeError::TooLong;
      put(kData);
      put(p.message_number);
      for (const std::uint8_t v : p.data) put(v);
      break;
    case PduType::DataAck:
      put(kDataAck);
      put(kAckSubcode);
      put(p.message_number);
      break;
    case PduType::DisconnectRequest:
      put(kDisconnectRequest);
      break;
  }
  out.len = static_cast<std::uint8_t>(n);
  return EncodeError::None;
}

}  // namespace pbvbus::mpi
