// MPI connection-layer PDU codec (protocol-facts.md §H.3): the PDUs of the §H.3 table byte for
// byte, round trips, and every decode error.
#include <gtest/gtest.h>

#include <cstdint>
#include <vector>

#include "pbvbus/mpi/pdu.hpp"

namespace pbvbus::mpi {
namespace {

using Bytes = std::vector<std::uint8_t>;

Bytes encoded(const Pdu& p) {
  PduBuffer b;
  EXPECT_EQ(encode(p, b), EncodeError::None);
  return Bytes(b.bytes().begin(), b.bytes().end());
}

DecodeError decoded(const Bytes& b, Pdu& p) { return decode(b, p); }

// §H.3 table, steps 1..7, as the trace and libnodave write them.
TEST(MpiPdu, ConnectRequestIsTheTraceOctets) {
  EXPECT_EQ(encoded(Pdu::connect_request()),
            (Bytes{0xE0, 0x04, 0x00, 0x80, 0x00, 0x02, 0x00, 0x02, 0x01, 0x00, 0x01, 0x00}));
}

TEST(MpiPdu, ConnectConfirmIsTheTraceOctets) {
  EXPECT_EQ(encoded(Pdu::connect_confirm()),
            (Bytes{0xD0, 0x04, 0x00, 0x80, 0x00, 0x02, 0x00, 0x02, 0x01, 0x00, 0x01, 0x00}));
}

TEST(MpiPdu, ConnectionAckDataAckDisconnect) {
  EXPECT_EQ(encoded(Pdu::connection_ack()), (Bytes{0x05, 0x01}));
  EXPECT_EQ(encoded(Pdu::data_ack(0x2A)), (Bytes{0xB0, 0x01, 0x2A}));
  EXPECT_EQ(encoded(Pdu::disconnect_request()), (Bytes{0x80}));
  const Bytes s7{0x32, 0x01, 0x00, 0x00};
  EXPECT_EQ(encoded(Pdu::data_message(7, s7)), (Bytes{0xF1, 0x07, 0x32, 0x01, 0x00, 0x00}));
}

TEST(MpiPdu, DecodesEachTypeWithItsFields) {
  Pdu p;
  ASSERT_EQ(decoded({0xE0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11}, p), DecodeError::None);
  EXPECT_EQ(p.type, PduType::ConnectRequest);
  EXPECT_EQ(p.connect_params, (ConnectParams{1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11}));
  ASSERT_EQ(decoded({0xD0, 0x04, 0x00, 0x80, 0x00, 0x02, 0x00, 0x02, 0x01, 0x00, 0x01, 0x00}, p),
            DecodeError::None);
  EXPECT_EQ(p.type, PduType::ConnectConfirm);
  EXPECT_EQ(p.connect_params, kTraceConnectParams);
  ASSERT_EQ(decoded({0x05, 0x01}, p), DecodeError::None);
  EXPECT_EQ(p.type, PduType::ConnectionAck);
  ASSERT_EQ(decoded({0xB0, 0x01, 0xFF}, p), DecodeError::None);
  EXPECT_EQ(p.type, PduType::DataAck);
  EXPECT_EQ(p.message_number, 0xFF);
  ASSERT_EQ(decoded({0x80}, p), DecodeError::None);
  EXPECT_EQ(p.type, PduType::DisconnectRequest);
  const Bytes data{0xF1, 0x03, 0x32, 0x07};
  ASSERT_EQ(decode(data, p), DecodeError::None);
  EXPECT_EQ(p.type, PduType::Data);
  EXPECT_EQ(p.message_number, 3);
  ASSERT_EQ(p.data.size(), 2u);
  EXPECT_EQ(p.data.data(), data.data() + 2);  // points into the input
}

TEST(MpiPdu, RoundTripsEveryTypeAndLength) {
  std::vector<Pdu> pdus = {Pdu::connect_request(), Pdu::connect_confirm({9, 8, 7, 6, 5, 4, 3, 2, 1, 0, 0xFF}),
                           Pdu::connection_ack(), Pdu::disconnect_request()};
  for (unsigned nr = 0; nr < 256; ++nr) pdus.push_back(Pdu::data_ack(static_cast<std::uint8_t>(nr)));
  std::vector<Bytes> payloads;
  for (std::size_t len = 1; len <= kMaxDataLen; ++len) {
    Bytes b(len);
    for (std::size_t i = 0; i < len; ++i) b[i] = static_cast<std::uint8_t>(i * 37 + len);
    payloads.push_back(b);
  }
  for (std::size_t i = 0; i < payloads.size(); ++i) {
    pdus.push_back(Pdu::data_message(static_cast<std::uint8_t>(i), payloads[i]));
  }
  for (const Pdu& p : pdus) {
    PduBuffer b;
    ASSERT_EQ(encode(p, b), EncodeError::None) << to_string(p.type);
    Pdu q;
    ASSERT_EQ(decode(b.bytes(), q), DecodeError::None) << to_string(p.type);
    EXPECT_EQ(q.type, p.type);
    if (p.type == PduType::ConnectRequest || p.type == PduType::ConnectConfirm) {
      EXPECT_EQ(q.connect_params, p.connect_params);
    }
    if (p.type == PduType::Data || p.type == PduType::DataAck) {
      EXPECT_EQ(q.message_number, p.message_number);
    }
    EXPECT_EQ(Bytes(q.data.begin(), q.data.end()), Bytes(p.data.begin(), p.data.end()));
    // and back: decode∘encode∘decode gives the same bytes
    PduBuffer again;
    ASSERT_EQ(encode(q, again), EncodeError::None);
    EXPECT_EQ(Bytes(again.bytes().begin(), again.bytes().end()), Bytes(b.bytes().begin(), b.bytes().end()));
  }
}

TEST(MpiPdu, LongestDataMessageFillsAnFdlFrame) {
  const Bytes s7(kMaxDataLen, 0xAA);
  PduBuffer b;
  ASSERT_EQ(encode(Pdu::data_message(1, s7), b), EncodeError::None);
  EXPECT_EQ(b.len, 244);  // §B.1: 246 DU octets incl. DSAP and SSAP
}

TEST(MpiPdu, EncodeErrors) {
  PduBuffer b;
  EXPECT_EQ(encode(Pdu::data_message(0, {}), b), EncodeError::EmptyData);
  const Bytes too_long(kMaxDataLen + 1, 0);
  EXPECT_EQ(encode(Pdu::data_message(0, too_long), b), EncodeError::TooLong);
  EXPECT_EQ(to_string(EncodeError::TooLong), "S7 PDU longer than one data message carries");
}

struct BadCase {
  Bytes bytes;
  DecodeError error;
};

TEST(MpiPdu, EveryDecodeError) {
  const std::vector<BadCase> cases = {
      {{}, DecodeError::Empty},
      {{0x00}, DecodeError::UnknownType},
      {{0xF0, 0x00, 0x32}, DecodeError::UnknownType},  // F0 is the S7 setup function, not an MPI PDU
      {{0xC0}, DecodeError::UnknownType},
      {{0xE0}, DecodeError::BadLength},
      {{0xE0, 0x04, 0x00, 0x80, 0x00, 0x02, 0x00, 0x02, 0x01, 0x00, 0x01}, DecodeError::BadLength},
      {{0xE0, 0x04, 0x00, 0x80, 0x00, 0x02, 0x00, 0x02, 0x01, 0x00, 0x01, 0x00, 0x00}, DecodeError::BadLength},
      {{0xD0, 0x04}, DecodeError::BadLength},
      {{0x05}, DecodeError::BadLength},
      {{0x05, 0x01, 0x00}, DecodeError::BadLength},
      {{0x05, 0x02}, DecodeError::BadAckSubcode},
      {{0xB0, 0x01}, DecodeError::BadLength},
      {{0xB0, 0x01, 0x00, 0x00}, DecodeError::BadLength},
      {{0xB0, 0x00, 0x05}, DecodeError::BadAckSubcode},
      {{0x80, 0x00}, DecodeError::BadLength},
      {{0xF1}, DecodeError::BadLength},
      {{0xF1, 0x00}, DecodeError::EmptyData},
      {Bytes(kMaxPduLen + 1, 0xF1), DecodeError::TooLong},
  };
  for (const BadCase& c : cases) {
    Pdu p = Pdu::data_ack(0x77);
    EXPECT_EQ(decode(c.bytes, p), c.error) << "case of " << c.bytes.size() << " octets";
    EXPECT_EQ(p.type, PduType::DataAck) << "the output is untouched on error";
    EXPECT_NE(to_string(c.error), "?");
  }
}

TEST(MpiPdu, MessageNumbersCountFromZeroAndSkipZeroOnWrap) {
  // §H.3 / S4 _daveIncMessageNumber: 0, 1, ..., 255, 1, 2, ...
  EXPECT_EQ(next_message_number(0), 1);
  EXPECT_EQ(next_message_number(1), 2);
  EXPECT_EQ(next_message_number(254), 255);
  EXPECT_EQ(next_message_number(255), 1);
  std::uint8_t n = 0;
  for (int i = 0; i < 255; ++i) n = next_message_number(n);
  EXPECT_EQ(n, 255);
  for (int i = 0; i < 255; ++i) n = next_message_number(n);
  EXPECT_EQ(n, 255) << "the cycle after the first pass is 255 long (1..255)";
}

}  // namespace
}  // namespace pbvbus::mpi
