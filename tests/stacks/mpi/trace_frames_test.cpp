// The §H.3 wire trace as whole FDL frames (protocol-facts.md §B.1 framing and FCS, §H.2 SRD with
// SAP extensions): our PDUs wrapped by pbvbus::fdl's encoder give the trace's bytes, and the
// trace's frames decode to the same PDUs. Frames the trace does not show are worked out by hand
// below (FCS = sum of DA..last DU octet mod 256, §B.1).
#include <gtest/gtest.h>

#include <cstdint>
#include <vector>

#include "pbvbus/fdl/telegram.hpp"
#include "pbvbus/mpi/connection.hpp"
#include "pbvbus/mpi/connection_pool.hpp"
#include "pbvbus/mpi/pdu.hpp"

namespace pbvbus::mpi {
namespace {

using Bytes = std::vector<std::uint8_t>;

// PG address 0, PLC address 2 (§H.3). libnodave's SAP 0x14, the PLC's connection SAP 0x14.
constexpr std::uint8_t kPg = 0;
constexpr std::uint8_t kPlc = 2;

Bytes wrap(std::uint8_t da, std::uint8_t sa, std::uint8_t fc, std::uint8_t dsap, std::uint8_t ssap,
           const Pdu& pdu) {
  PduBuffer b;
  EXPECT_EQ(encode(pdu, b), EncodeError::None);
  fdl::FrameSpec spec;
  spec.da = da;
  spec.sa = sa;
  spec.fc = fc;
  spec.dsap = dsap;
  spec.ssap = ssap;
  spec.data = b.bytes();
  fdl::Frame f;
  EXPECT_EQ(fdl::encode(spec, f), fdl::EncodeError::None);
  return Bytes(f.bytes().begin(), f.bytes().end());
}

Pdu unwrap(const Bytes& frame, fdl::Telegram& t) {
  EXPECT_EQ(fdl::decode(frame, t), fdl::DecodeError::None);
  Pdu p;
  EXPECT_EQ(decode(t.data, p), DecodeError::None);
  return p;
}

const Bytes kTraceConnectRequest = {0x68, 0x11, 0x11, 0x68, 0x82, 0x80, 0x6D, 0x00, 0x14, 0xE0, 0x04, 0x00,
                                    0x80, 0x00, 0x02, 0x00, 0x02, 0x01, 0x00, 0x01, 0x00, 0xED, 0x16};
const Bytes kTraceConnectConfirm = {0x68, 0x11, 0x11, 0x68, 0x80, 0x82, 0x6C, 0x14, 0x14, 0xD0, 0x04, 0x00,
                                    0x80, 0x00, 0x02, 0x00, 0x02, 0x01, 0x00, 0x01, 0x00, 0xF0, 0x16};

TEST(MpiTraceFrames, ConnectRequestIsTheTraceFrame) {
  // FC 6D: SRD high, first frame (FCB=1, FCV=0). DSAP 0x00, SSAP 0x14.
  // FCS by hand: 82+80+6D+00+14 = 0x183; E0+04+00+80+00+02+00+02+01+00+01+00 = 0x16A;
  // 0x183 + 0x16A = 0x2ED -> ED (§H.3 trace).
  EXPECT_EQ(wrap(kPlc, kPg, 0x6D, kConnectSap, kFirstConnectionSap, Pdu::connect_request()),
            kTraceConnectRequest);
}

TEST(MpiTraceFrames, ConnectConfirmIsTheTraceFrame) {
  // FC 6C: SRD low, first frame. DSAP 0x14 (PG's SAP), SSAP 0x14 (the PLC's connection SAP).
  // FCS by hand: 80+82+6C+14+14 = 0x196; D0+04+00+80+00+02+00+02+01+00+01+00 = 0x15A;
  // 0x196 + 0x15A = 0x2F0 -> F0 (§H.3 trace).
  EXPECT_EQ(wrap(kPg, kPlc, 0x6C, 0x14, 0x14, Pdu::connect_confirm()), kTraceConnectConfirm);
}

TEST(MpiTraceFrames, TraceFramesDecodeToThePdus) {
  fdl::Telegram t;
  Pdu cr = unwrap(kTraceConnectRequest, t);
  EXPECT_EQ(t.type, fdl::FrameType::SD2);
  EXPECT_EQ(t.da, kPlc);
  EXPECT_EQ(t.sa, kPg);
  EXPECT_EQ(t.dsap, kConnectSap);
  EXPECT_EQ(t.ssap, 0x14);
  EXPECT_EQ(cr.type, PduType::ConnectRequest);
  EXPECT_EQ(cr.connect_params, kTraceConnectParams);
  Pdu cc = unwrap(kTraceConnectConfirm, t);
  EXPECT_EQ(t.da, kPg);
  EXPECT_EQ(t.sa, kPlc);
  EXPECT_EQ(t.ssap, 0x14) << "the PLC-side SAP used from now on";
  EXPECT_EQ(cc.type, PduType::ConnectConfirm);
  EXPECT_EQ(cc.connect_params, kTraceConnectParams);
}

TEST(MpiTraceFrames, ConnectionAcksWorkedByHand) {
  // Step 3, PG -> PLC, the PG's second SRD high: FCV=1, FCB toggled to 0 -> FC 5D (§C.6).
  // LE = DA SA FC DSAP SSAP + 2 = 7. FCS: 82+80+5D+14+14+05+01 = 0x18D -> 8D.
  EXPECT_EQ(wrap(kPlc, kPg, 0x5D, 0x14, 0x14, Pdu::connection_ack()),
            (Bytes{0x68, 0x07, 0x07, 0x68, 0x82, 0x80, 0x5D, 0x14, 0x14, 0x05, 0x01, 0x8D, 0x16}));
  // Step 4, PLC -> PG, its second SRD low: FC 5C. FCS: 80+82+5C+14+14+05+01 = 0x18C -> 8C.
  EXPECT_EQ(wrap(kPg, kPlc, 0x5C, 0x14, 0x14, Pdu::connection_ack()),
            (Bytes{0x68, 0x07, 0x07, 0x68, 0x80, 0x82, 0x5C, 0x14, 0x14, 0x05, 0x01, 0x8C, 0x16}));
}

TEST(MpiTraceFrames, DataMessageAndItsAckWorkedByHand) {
  // Step 5: message 0 carrying the §H.4 Read Var job for DB1.DBB0, 10 bytes (24 octets).
  const Bytes read_var = {0x32, 0x01, 0x00, 0x00, 0x00, 0x01, 0x00, 0x0E, 0x00, 0x00, 0x04, 0x01,
                          0x12, 0x0A, 0x10, 0x02, 0x00, 0x0A, 0x00, 0x01, 0x84, 0x00, 0x00, 0x00};
  // PG's third SRD high: FC 7D. LE = 5 + 2 + 24 = 31 = 0x1F.
  // FCS: 82+80+7D+14+14+F1+00 = 0x298; the S7 PDU's octets sum to 0x104; 0x39C -> 9C.
  Bytes expected = {0x68, 0x1F, 0x1F, 0x68, 0x82, 0x80, 0x7D, 0x14, 0x14, 0xF1, 0x00};
  expected.insert(expected.end(), read_var.begin(), read_var.end());
  expected.push_back(0x9C);
  expected.push_back(0x16);
  EXPECT_EQ(wrap(kPlc, kPg, 0x7D, 0x14, 0x14, Pdu::data_message(0, read_var)), expected);
  // Step 6: the PLC's MPI-layer ack of message 0, its own SRD frame (third SRD low: 7C).
  // LE = 5 + 3 = 8 (DU incl. SAPs = 5, not 8, so SD2). FCS: 80+82+7C+14+14+B0+01+00 = 0x257 -> 57.
  EXPECT_EQ(wrap(kPg, kPlc, 0x7C, 0x14, 0x14, Pdu::data_ack(0)),
            (Bytes{0x68, 0x08, 0x08, 0x68, 0x80, 0x82, 0x7C, 0x14, 0x14, 0xB0, 0x01, 0x00, 0x57, 0x16}));
}

TEST(MpiTraceFrames, DisconnectRequestWorkedByHand) {
  // Step 7, PG -> PLC, FC 5D. LE = 6. FCS: 82+80+5D+14+14+80 = 0x207 -> 07.
  EXPECT_EQ(wrap(kPlc, kPg, 0x5D, 0x14, 0x14, Pdu::disconnect_request()),
            (Bytes{0x68, 0x06, 0x06, 0x68, 0x82, 0x80, 0x5D, 0x14, 0x14, 0x80, 0x07, 0x16}));
}

TEST(MpiTraceFrames, SixOctetDataMessageTravelsAsSd3) {
  // §B.1: a DU of exactly 8 octets incl. the SAPs goes out as SD3: F1 nr + 4 S7 octets.
  // FCS: 82+80+7D+14+14+F1+05+32+01+00+00 = 0x2D0 -> D0.
  const Bytes s7 = {0x32, 0x01, 0x00, 0x00};
  const Bytes frame = wrap(kPlc, kPg, 0x7D, 0x14, 0x14, Pdu::data_message(5, s7));
  EXPECT_EQ(frame, (Bytes{0xA2, 0x82, 0x80, 0x7D, 0x14, 0x14, 0xF1, 0x05, 0x32, 0x01, 0x00, 0x00, 0xD0, 0x16}));
  fdl::Telegram t;
  const Pdu p = unwrap(frame, t);
  EXPECT_EQ(t.type, fdl::FrameType::SD3);
  EXPECT_EQ(p.message_number, 5);
}

Bytes wrap_outgoing(std::uint8_t sa, std::uint8_t fc, const Outgoing& f) {
  fdl::FrameSpec spec;
  spec.da = f.peer;
  spec.sa = sa;
  spec.fc = fc;
  spec.dsap = f.dsap;
  spec.ssap = f.ssap;
  spec.data = f.pdu.bytes();
  fdl::Frame frame;
  EXPECT_EQ(fdl::encode(spec, frame), fdl::EncodeError::None);
  return Bytes(frame.bytes().begin(), frame.bytes().end());
}

TEST(MpiTraceFrames, TheCpuSideAnswersTheTracesRequestWithTheTracesConfirm) {
  // The trace's connect request, as the CPU's FDL layer receives it, goes into a pool; the
  // confirm it sends, wrapped with the trace's FC 6C, is the trace's confirm byte for byte.
  fdl::Telegram t;
  ASSERT_EQ(fdl::decode(kTraceConnectRequest, t), fdl::DecodeError::None);
  ConnectionPool cpu;
  Outbox out;
  EXPECT_EQ(cpu.on_frame(0, Received{t.sa, *t.dsap, *t.ssap, t.data}, out), FdlReply::Ack);
  ASSERT_EQ(out.frames.size(), 1u);
  EXPECT_EQ(wrap_outgoing(kPlc, 0x6C, out.frames[0]), kTraceConnectConfirm);
}

TEST(MpiTraceFrames, ThePgSideSendsTheTracesRequestAndTakesTheTracesConfirm) {
  Connection pg = Connection::initiator(kPlc, 0x14);
  Outbox out;
  ASSERT_EQ(pg.connect(0, out), RequestError::None);
  ASSERT_EQ(out.frames.size(), 1u);
  EXPECT_EQ(wrap_outgoing(kPg, 0x6D, out.frames[0]), kTraceConnectRequest);
  pg.on_fdl_result(0, FdlResult::Delivered, out);
  out.clear();
  fdl::Telegram t;
  ASSERT_EQ(fdl::decode(kTraceConnectConfirm, t), fdl::DecodeError::None);
  EXPECT_EQ(pg.on_frame(0, Received{t.sa, *t.dsap, *t.ssap, t.data}, out), FdlReply::Ack);
  EXPECT_EQ(pg.state(), State::AckSent);
  ASSERT_EQ(out.frames.size(), 1u);
  // Step 3 with the PG's next FC (5D), as worked out above.
  EXPECT_EQ(wrap_outgoing(kPg, 0x5D, out.frames[0]),
            (Bytes{0x68, 0x07, 0x07, 0x68, 0x82, 0x80, 0x5D, 0x14, 0x14, 0x05, 0x01, 0x8D, 0x16}));
}

}  // namespace
}  // namespace pbvbus::mpi
