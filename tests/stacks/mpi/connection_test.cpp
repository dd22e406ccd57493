// The MPI connection state machine, both ends (protocol-facts.md §H.3; decisions in
// docs/mpi.md): set-up, data with message numbers and acks both ways, wrap, disconnect,
// refusal beyond the CPU's resources, broken connections.
#include <gtest/gtest.h>

#include <cstdint>
#include <vector>

#include "mpi_link.hpp"
#include "pbvbus/mpi/connection.hpp"
#include "pbvbus/mpi/connection_pool.hpp"

namespace pbvbus::mpi {
namespace {

using test::Bytes;
using test::MpiLink;
constexpr bus::Ticks kSecond = bus::kTicksPerSecond;

Bytes s7(std::uint8_t tag, std::size_t len = 10) {
  Bytes b(len, tag);
  b[0] = 0x32;
  return b;
}

TEST(MpiConnection, SetUpFollowsTheTraceSequence) {
  MpiLink link;
  ASSERT_EQ(link.pg.connect(0, link.pg_out), RequestError::None);
  EXPECT_EQ(link.pg.state(), State::ConnectSent);
  EXPECT_EQ(link.pg.deadline(), kSecond);
  link.run(0);
  // §H.3 steps 1-4: E0 to DSAP 0, D0 from the CPU's SAP, 05 01 each way.
  ASSERT_EQ(link.wire.size(), 4u);
  EXPECT_TRUE(link.wire[0].from_pg);
  EXPECT_EQ(link.wire[0].dsap, kConnectSap);
  EXPECT_EQ(link.wire[0].ssap, 0x14);
  EXPECT_EQ(link.wire[0].pdu, (Bytes{0xE0, 0x04, 0x00, 0x80, 0x00, 0x02, 0x00, 0x02, 0x01, 0x00, 0x01, 0x00}));
  EXPECT_FALSE(link.wire[1].from_pg);
  EXPECT_EQ(link.wire[1].dsap, 0x14);
  EXPECT_EQ(link.wire[1].ssap, 0x14) << "the CPU answers from SAP 0x14, as in the trace";
  EXPECT_EQ(link.wire[1].pdu, (Bytes{0xD0, 0x04, 0x00, 0x80, 0x00, 0x02, 0x00, 0x02, 0x01, 0x00, 0x01, 0x00}));
  EXPECT_TRUE(link.wire[2].from_pg);
  EXPECT_EQ(link.wire[2].pdu, (Bytes{0x05, 0x01}));
  EXPECT_FALSE(link.wire[3].from_pg);
  EXPECT_EQ(link.wire[3].pdu, (Bytes{0x05, 0x01}));

  EXPECT_EQ(link.pg.state(), State::Connected);
  EXPECT_EQ(link.pg.peer_sap(), 0x14);
  EXPECT_FALSE(link.pg.deadline());
  ASSERT_EQ(link.pg_events.size(), 1u);
  EXPECT_EQ(link.pg_events[0].kind, EventKind::Connected);
  ASSERT_EQ(link.cpu_events.size(), 2u);
  EXPECT_EQ(link.cpu_events[0].kind, EventKind::ConnectIndication);
  EXPECT_EQ(link.cpu_events[0].peer, MpiLink::kPg);
  EXPECT_EQ(link.cpu_events[0].peer_sap, 0x14);
  EXPECT_EQ(link.cpu_events[1].kind, EventKind::Connected);
  EXPECT_EQ(link.cpu.open_connections(), 1u);
  ASSERT_NE(link.cpu.find(0x14), nullptr);
  EXPECT_EQ(link.cpu.find(0x14)->state(), State::Connected);
  EXPECT_FALSE(link.cpu.deadline());
  for (const FdlReply r : link.cpu_replies) EXPECT_EQ(r, FdlReply::Ack);
}

TEST(MpiConnection, DataWithAcksBothWays) {
  MpiLink link;
  link.connect();
  link.wire.clear();
  ASSERT_EQ(link.pg.send_data(10, s7(0xA1), link.pg_out), RequestError::None);
  EXPECT_TRUE(link.pg.awaiting_data_ack());
  EXPECT_EQ(link.pg.deadline(), 10 + kSecond);
  link.run(10);
  ASSERT_EQ(link.wire.size(), 2u);
  EXPECT_EQ(link.wire[0].pdu[0], kData);
  EXPECT_EQ(link.wire[0].pdu[1], 0) << "the first message number is 0 (§H.3)";
  EXPECT_EQ(link.wire[1].pdu, (Bytes{0xB0, 0x01, 0x00})) << "the CPU acks message 0 in its own frame";
  EXPECT_FALSE(link.wire[1].from_pg);
  ASSERT_EQ(link.cpu_events.size(), 3u);
  EXPECT_EQ(link.cpu_events[2].kind, EventKind::DataIndication);
  EXPECT_EQ(link.cpu_events[2].message_number, 0);
  EXPECT_EQ(link.cpu_events[2].data, s7(0xA1));
  ASSERT_EQ(link.pg_events.size(), 2u);
  EXPECT_EQ(link.pg_events[1].kind, EventKind::DataConfirm);
  EXPECT_EQ(link.pg_events[1].message_number, 0);
  EXPECT_FALSE(link.pg.awaiting_data_ack());
  EXPECT_FALSE(link.pg.deadline());

  // The CPU answers with its own data message, numbered from its own counter.
  link.wire.clear();
  ASSERT_EQ(link.cpu.send_data(20, link.cpu_sap(), s7(0xB2, 14), link.cpu_out), RequestError::None);
  link.run(20);
  ASSERT_EQ(link.wire.size(), 2u);
  EXPECT_FALSE(link.wire[0].from_pg);
  EXPECT_EQ(link.wire[0].pdu[1], 0);
  EXPECT_EQ(link.wire[1].pdu, (Bytes{0xB0, 0x01, 0x00}));
  EXPECT_EQ(link.pg_events.back().kind, EventKind::DataIndication);
  EXPECT_EQ(link.pg_events.back().data, s7(0xB2, 14));
  EXPECT_EQ(link.cpu_events.back().kind, EventKind::DataConfirm);

  // Both directions count on: the next PG message is number 1.
  link.wire.clear();
  ASSERT_EQ(link.pg.send_data(30, s7(0xC3), link.pg_out), RequestError::None);
  link.run(30);
  EXPECT_EQ(link.wire[0].pdu[1], 1);
  EXPECT_EQ(link.wire[1].pdu, (Bytes{0xB0, 0x01, 0x01}));
}

TEST(MpiConnection, OneDataMessageOutstandingPerDirection) {
  MpiLink link;
  link.connect();
  ASSERT_EQ(link.pg.send_data(0, s7(1), link.pg_out), RequestError::None);
  EXPECT_EQ(link.pg.send_data(0, s7(2), link.pg_out), RequestError::Busy);
  link.run(0);
  EXPECT_EQ(link.pg.send_data(0, s7(2), link.pg_out), RequestError::None);
}

TEST(MpiConnection, MessageNumbersWrapFrom255To1) {
  MpiLink link;
  link.connect();
  link.wire.clear();
  std::vector<std::uint8_t> sent;
  for (int i = 0; i < 300; ++i) {
    ASSERT_EQ(link.pg.send_data(i, s7(static_cast<std::uint8_t>(i)), link.pg_out), RequestError::None) << i;
    link.run(i);
  }
  for (const auto& f : link.wire) {
    if (f.from_pg) sent.push_back(f.pdu[1]);
  }
  ASSERT_EQ(sent.size(), 300u);
  EXPECT_EQ(sent[0], 0);
  EXPECT_EQ(sent[255], 255);
  EXPECT_EQ(sent[256], 1) << "after 255 comes 1, never 0 (S4 _daveIncMessageNumber)";
  EXPECT_EQ(sent[299], 44);
  int indications = 0;
  for (const Event& e : link.cpu_events) {
    if (e.kind == EventKind::DataIndication) ++indications;
    EXPECT_NE(e.kind, EventKind::Broken);
  }
  EXPECT_EQ(indications, 300);
  EXPECT_EQ(link.pg.next_tx_number(), 45);
}

TEST(MpiConnection, DisconnectByThePg) {
  MpiLink link;
  link.connect();
  link.wire.clear();
  ASSERT_EQ(link.pg.disconnect(5, link.pg_out), RequestError::None);
  EXPECT_EQ(link.pg.state(), State::Disconnecting);
  link.run(5);
  ASSERT_EQ(link.wire.size(), 1u);
  EXPECT_EQ(link.wire[0].pdu, (Bytes{0x80}));
  EXPECT_EQ(link.wire[0].dsap, 0x14);
  EXPECT_EQ(link.pg.state(), State::Closed);
  EXPECT_EQ(link.pg_events.back().kind, EventKind::Disconnected);
  EXPECT_EQ(link.pg_events.back().reason, Reason::Local);
  EXPECT_EQ(link.cpu_events.back().kind, EventKind::Disconnected);
  EXPECT_EQ(link.cpu_events.back().reason, Reason::ByPeer);
  EXPECT_EQ(link.cpu.open_connections(), 0u);
  EXPECT_EQ(link.pg.disconnect(5, link.pg_out), RequestError::WrongState);
}

TEST(MpiConnection, DisconnectByTheCpu) {
  MpiLink link;
  link.connect();
  ASSERT_EQ(link.cpu.disconnect(5, link.cpu_sap(), link.cpu_out), RequestError::None);
  link.run(5);
  EXPECT_EQ(link.pg.state(), State::Closed);
  EXPECT_EQ(link.pg_events.back().reason, Reason::ByPeer);
  EXPECT_EQ(link.cpu_events.back().kind, EventKind::Disconnected);
  EXPECT_EQ(link.cpu_events.back().reason, Reason::Local);
  EXPECT_EQ(link.cpu.open_connections(), 0u);
}

TEST(MpiConnection, ThePgConnectsAgainAfterADisconnect) {
  MpiLink link;
  link.connect();
  link.pg.send_data(0, s7(1), link.pg_out);
  link.run(0);
  link.pg.disconnect(0, link.pg_out);
  link.run(0);
  link.connect(1);
  EXPECT_EQ(link.pg.state(), State::Connected);
  EXPECT_EQ(link.pg.next_tx_number(), 0) << "a new connection counts from 0 again";
  EXPECT_EQ(link.cpu.open_connections(), 1u);
}

TEST(MpiConnection, RefusalBeyondTheCpusConnections) {
  PoolConfig config;
  config.max_connections = 1;
  MpiLink link(config);
  link.connect();
  // A second PG (address 1) asks for a connection: the CPU's FDL answers RR (no resources).
  Connection pg2 = Connection::initiator(MpiLink::kCpu, 0x14);
  Outbox out;
  ASSERT_EQ(pg2.connect(0, out), RequestError::None);
  ASSERT_EQ(out.frames.size(), 1u);
  Outbox cpu_out;
  EXPECT_EQ(link.cpu.on_frame(0, MpiLink::received(1, out.frames[0]), cpu_out), FdlReply::NoResources);
  EXPECT_TRUE(cpu_out.frames.empty());
  EXPECT_TRUE(cpu_out.events.empty());
  pg2.on_fdl_result(0, FdlResult::Refused, out);
  EXPECT_EQ(pg2.state(), State::Closed);
  ASSERT_EQ(out.events.size(), 1u);
  EXPECT_EQ(out.events[0].kind, EventKind::ConnectRefused);
  EXPECT_EQ(out.events[0].reason, Reason::PeerRefused);
  EXPECT_FALSE(pg2.deadline());
  // Once the first PG has gone, the second gets its connection.
  link.pg.disconnect(0, link.pg_out);
  link.run(0);
  out.clear();
  ASSERT_EQ(pg2.connect(1, out), RequestError::None);
  EXPECT_EQ(link.cpu.on_frame(1, MpiLink::received(1, out.frames[0]), cpu_out), FdlReply::Ack);
  EXPECT_EQ(link.cpu.open_connections(), 1u);
}

TEST(MpiConnection, EachConnectionGetsItsOwnCpuSap) {
  MpiLink link;
  link.connect();
  Connection pg2 = Connection::initiator(MpiLink::kCpu, 0x14);
  Outbox out;
  Outbox cpu_out;
  pg2.connect(0, out);
  EXPECT_EQ(link.cpu.on_frame(0, MpiLink::received(1, out.frames[0]), cpu_out), FdlReply::Ack);
  ASSERT_EQ(cpu_out.frames.size(), 1u);
  EXPECT_EQ(cpu_out.frames[0].ssap, 0x15);
  EXPECT_EQ(cpu_out.frames[0].peer, 1);
  EXPECT_EQ(link.cpu.open_connections(), 2u);
}

TEST(MpiConnection, ThePgOpeningAgainFromTheSameSapReleasesItsOldConnection) {
  MpiLink link;
  link.connect();
  Connection again = Connection::initiator(MpiLink::kCpu, 0x14);
  Outbox out;
  Outbox cpu_out;
  again.connect(0, out);
  EXPECT_EQ(link.cpu.on_frame(0, MpiLink::received(MpiLink::kPg, out.frames[0]), cpu_out), FdlReply::Ack);
  ASSERT_GE(cpu_out.events.size(), 2u);
  EXPECT_EQ(cpu_out.events[0].kind, EventKind::Disconnected);
  EXPECT_EQ(cpu_out.events[0].reason, Reason::PeerReconnected);
  EXPECT_EQ(cpu_out.events[1].kind, EventKind::ConnectIndication);
  EXPECT_EQ(link.cpu.open_connections(), 1u);
}

TEST(MpiConnection, AckTimeoutBreaksTheConnection) {
  MpiLink link;
  link.connect();
  link.wire.clear();
  ASSERT_EQ(link.pg.send_data(100, s7(1), link.pg_out), RequestError::None);
  link.pg_out.frames.clear();  // the CPU never sees it (and so never acks)
  link.pg.on_fdl_result(100, FdlResult::Delivered, link.pg_out);
  link.pg.on_timer(100 + kSecond - 1, link.pg_out);
  EXPECT_EQ(link.pg.state(), State::Connected) << "not before the stated time";
  link.pg.on_timer(100 + kSecond, link.pg_out);
  EXPECT_EQ(link.pg.state(), State::Closed);
  ASSERT_EQ(link.pg_out.events.size(), 1u);
  EXPECT_EQ(link.pg_out.events[0].kind, EventKind::Broken);
  EXPECT_EQ(link.pg_out.events[0].reason, Reason::AckTimeout);
  // The CPU may still hold the connection: a disconnect request tells it.
  ASSERT_EQ(link.pg_out.frames.size(), 1u);
  EXPECT_EQ(link.pg_out.frames[0].pdu.bytes()[0], kDisconnectRequest);
  link.pg_out.events.clear();
  link.run(100 + kSecond);
  EXPECT_EQ(link.cpu.open_connections(), 0u);
  EXPECT_EQ(link.cpu_events.back().reason, Reason::ByPeer);
}

TEST(MpiConnection, PeerGoneWhenTheFdlLayerGetsNoAnswer) {
  MpiLink link;
  link.connect();
  link.line_up = false;  // the CPU is gone (power loss, cable cut)
  ASSERT_EQ(link.pg.send_data(0, s7(1), link.pg_out), RequestError::None);
  link.run(0);
  EXPECT_EQ(link.pg.state(), State::Closed);
  EXPECT_EQ(link.pg_events.back().kind, EventKind::Broken);
  EXPECT_EQ(link.pg_events.back().reason, Reason::PeerGone);
  EXPECT_EQ(link.wire.back().pdu[0], kData) << "no disconnect request to a peer that is gone";
}

TEST(MpiConnection, ConnectTimeoutWithoutAConfirm) {
  Connection pg = Connection::initiator(2, 0x14, ConnectionTiming{500, 700});
  Outbox out;
  pg.connect(1000, out);
  pg.on_fdl_result(1000, FdlResult::Delivered, out);
  out.clear();
  EXPECT_EQ(pg.deadline(), 1500);
  pg.on_timer(1499, out);
  EXPECT_EQ(pg.state(), State::ConnectSent);
  pg.on_timer(1500, out);
  EXPECT_EQ(pg.state(), State::Closed);
  ASSERT_EQ(out.events.size(), 1u);
  EXPECT_EQ(out.events[0].reason, Reason::ConnectTimeout);
  EXPECT_TRUE(out.frames.empty()) << "the CPU's SAP is unknown: nothing to release";
}

TEST(MpiConnection, CpuReleasesAConnectionWhoseAckNeverComes) {
  PoolConfig config;
  config.timing = ConnectionTiming{500, 700};
  ConnectionPool cpu(config);
  Connection pg = Connection::initiator(2, 0x14);
  Outbox pg_out;
  Outbox out;
  pg.connect(0, pg_out);
  ASSERT_EQ(cpu.on_frame(0, MpiLink::received(0, pg_out.frames[0]), out), FdlReply::Ack);
  cpu.on_fdl_result(0, 0x14, FdlResult::Delivered, out);  // the confirm reached the PG, no 05 01 follows
  out.clear();
  EXPECT_EQ(cpu.deadline(), 500);
  cpu.on_timer(500, out);
  ASSERT_EQ(out.events.size(), 1u);
  EXPECT_EQ(out.events[0].kind, EventKind::Broken);
  EXPECT_EQ(out.events[0].reason, Reason::ConnectTimeout);
  ASSERT_EQ(out.frames.size(), 1u);
  EXPECT_EQ(out.frames[0].pdu.bytes()[0], kDisconnectRequest);
  EXPECT_EQ(cpu.open_connections(), 0u);
  EXPECT_FALSE(cpu.deadline());
}

TEST(MpiConnection, PdusThatDoNotFitTheStateAreDroppedAndCounted) {
  ConnectionPool cpu;
  Connection pg = Connection::initiator(2, 0x14);
  Outbox pg_out;
  Outbox out;
  pg.connect(0, pg_out);
  ASSERT_EQ(cpu.on_frame(0, MpiLink::received(0, pg_out.frames[0]), out), FdlReply::Ack);
  out.clear();
  // Data before the connection acks: taken by FDL, dropped by MPI, no ack, no indication.
  const Bytes data = {kData, 0x00, 0x32};
  EXPECT_EQ(cpu.on_frame(0, Received{0, 0x14, 0x14, data}, out), FdlReply::Ack);
  EXPECT_TRUE(out.frames.empty());
  EXPECT_TRUE(out.events.empty());
  ASSERT_NE(cpu.find(0x14), nullptr);
  EXPECT_EQ(cpu.find(0x14)->state(), State::ConfirmSent);
  EXPECT_EQ(cpu.find(0x14)->ignored_pdus(), 1u);
  // The PG gets a second confirm after it is connected: dropped too.
  MpiLink link;
  link.connect();
  const Bytes cc = {0xD0, 0x04, 0x00, 0x80, 0x00, 0x02, 0x00, 0x02, 0x01, 0x00, 0x01, 0x00};
  EXPECT_EQ(link.pg.on_frame(0, Received{MpiLink::kCpu, 0x14, link.cpu_sap(), cc}, link.pg_out), FdlReply::Ack);
  EXPECT_EQ(link.pg.state(), State::Connected);
  EXPECT_EQ(link.pg.ignored_pdus(), 1u);
  EXPECT_TRUE(link.pg_out.frames.empty());
}

TEST(MpiConnection, RepeatedDataIsAckedAgainButDeliveredOnce) {
  MpiLink link;
  link.connect();
  const Bytes msg = {kData, 0x00, 0x32, 0x01};
  Outbox out;
  const Received r{MpiLink::kPg, link.cpu_sap(), 0x14, msg};
  EXPECT_EQ(link.cpu.on_frame(0, r, out), FdlReply::Ack);
  EXPECT_EQ(link.cpu.on_frame(0, r, out), FdlReply::Ack);
  ASSERT_EQ(out.frames.size(), 2u);
  EXPECT_EQ(Bytes(out.frames[1].pdu.bytes().begin(), out.frames[1].pdu.bytes().end()), (Bytes{0xB0, 0x01, 0x00}));
  int indications = 0;
  for (const Event& e : out.events) indications += e.kind == EventKind::DataIndication;
  EXPECT_EQ(indications, 1);
}

TEST(MpiConnection, DataOutOfSequenceBreaksTheConnection) {
  MpiLink link;
  link.connect();
  Outbox out;
  const Bytes first = {kData, 0x00, 0x32};
  const Bytes skipped = {kData, 0x02, 0x32};
  EXPECT_EQ(link.cpu.on_frame(0, Received{MpiLink::kPg, link.cpu_sap(), 0x14, first}, out), FdlReply::Ack);
  EXPECT_EQ(link.cpu.on_frame(0, Received{MpiLink::kPg, link.cpu_sap(), 0x14, skipped}, out), FdlReply::Ack);
  EXPECT_EQ(out.events.back().kind, EventKind::Broken);
  EXPECT_EQ(out.events.back().reason, Reason::SequenceError);
  EXPECT_EQ(out.frames.back().pdu.bytes()[0], kDisconnectRequest);
  EXPECT_EQ(link.cpu.open_connections(), 0u);
}

TEST(MpiConnection, TheReceiverTakesThePeersFirstNumber) {
  MpiLink link;
  link.connect();
  Outbox out;
  const Bytes m7 = {kData, 0x07, 0x32};
  const Bytes m8 = {kData, 0x08, 0x32};
  link.cpu.on_frame(0, Received{MpiLink::kPg, link.cpu_sap(), 0x14, m7}, out);
  link.cpu.on_frame(0, Received{MpiLink::kPg, link.cpu_sap(), 0x14, m8}, out);
  int indications = 0;
  for (const Event& e : out.events) {
    indications += e.kind == EventKind::DataIndication;
    EXPECT_NE(e.kind, EventKind::Broken);
  }
  EXPECT_EQ(indications, 2);
}

TEST(MpiConnection, DataAcksOutOfSequence) {
  MpiLink link;
  link.connect();
  link.pg.send_data(0, s7(1), link.pg_out);
  link.run(0);  // message 0 sent and acked
  const Bytes ack0 = {kDataAck, 0x01, 0x00};
  const Received again{MpiLink::kCpu, 0x14, link.cpu_sap(), ack0};
  EXPECT_EQ(link.pg.on_frame(0, again, link.pg_out), FdlReply::Ack);
  EXPECT_EQ(link.pg.state(), State::Connected) << "the same ack twice is dropped";
  EXPECT_EQ(link.pg.ignored_pdus(), 1u);
  const Bytes ack9 = {kDataAck, 0x01, 0x09};
  EXPECT_EQ(link.pg.on_frame(0, Received{MpiLink::kCpu, 0x14, link.cpu_sap(), ack9}, link.pg_out), FdlReply::Ack);
  EXPECT_EQ(link.pg.state(), State::Closed);
  EXPECT_EQ(link.pg_out.events.back().reason, Reason::SequenceError);
}

TEST(MpiConnection, CpuRestartedThePgsDataIsRefused) {
  MpiLink link;
  link.connect();
  link.cpu = ConnectionPool{};  // the CPU lost its connections (restart)
  link.pg.send_data(0, s7(1), link.pg_out);
  link.run(0);
  EXPECT_EQ(link.cpu_replies.back(), FdlReply::SapNotActivated);
  EXPECT_EQ(link.pg.state(), State::Closed);
  EXPECT_EQ(link.pg_events.back().kind, EventKind::Broken);
  EXPECT_EQ(link.pg_events.back().reason, Reason::PeerRefused);
}

TEST(MpiConnection, FdlRepliesOfThePool) {
  ConnectionPool cpu;
  Outbox out;
  const Bytes garbage = {0x42, 0x00};
  const Bytes ack = {0x05, 0x01};
  const Bytes cr = {0xE0, 0x04, 0x00, 0x80, 0x00, 0x02, 0x00, 0x02, 0x01, 0x00, 0x01, 0x00};
  EXPECT_EQ(cpu.on_frame(0, Received{0, kConnectSap, 0x14, garbage}, out), FdlReply::UserError);
  EXPECT_EQ(cpu.on_frame(0, Received{0, kConnectSap, 0x14, ack}, out), FdlReply::SapNotActivated);
  EXPECT_EQ(cpu.on_frame(0, Received{0, 0x14, 0x14, ack}, out), FdlReply::SapNotActivated);
  EXPECT_TRUE(out.frames.empty());
  EXPECT_EQ(cpu.on_frame(0, Received{0, kConnectSap, 0x14, cr}, out), FdlReply::Ack);
  EXPECT_EQ(cpu.on_frame(0, Received{0, 0x14, 0x14, garbage}, out), FdlReply::UserError);
  EXPECT_EQ(cpu.on_frame(0, Received{1, 0x14, 0x14, ack}, out), FdlReply::SapNotActivated) << "other peer";
  EXPECT_EQ(cpu.send_data(0, 0x33, Bytes{1}, out), RequestError::WrongState);
  EXPECT_EQ(cpu.disconnect(0, 0x33, out), RequestError::WrongState);
}

TEST(MpiConnection, ThePoolNeverGivesOutTheConnectSap) {
  PoolConfig config;
  config.first_sap = 0;
  ConnectionPool cpu(config);
  Connection pg = Connection::initiator(2, 0x14);
  Outbox out;
  pg.connect(0, out);
  Outbox cpu_out;
  ASSERT_EQ(cpu.on_frame(0, MpiLink::received(0, out.frames[0]), cpu_out), FdlReply::Ack);
  EXPECT_EQ(cpu_out.frames[0].ssap, 1);
}

TEST(MpiConnection, RequestErrors) {
  Connection pg = Connection::initiator(2, 0x14);
  Outbox out;
  EXPECT_EQ(pg.send_data(0, Bytes{1}, out), RequestError::WrongState);
  EXPECT_EQ(pg.disconnect(0, out), RequestError::WrongState);
  EXPECT_EQ(pg.accept(0, Pdu::connect_request(), out), RequestError::WrongState);
  EXPECT_EQ(pg.connect(0, out), RequestError::None);
  EXPECT_EQ(pg.connect(0, out), RequestError::WrongState);
  // A disconnect before the confirm closes at once: no SAP to send 80 to.
  EXPECT_EQ(pg.disconnect(0, out), RequestError::None);
  EXPECT_EQ(pg.state(), State::Closed);
  EXPECT_EQ(out.events.back().reason, Reason::Local);

  MpiLink link;
  link.connect();
  EXPECT_EQ(link.pg.send_data(0, Bytes{}, link.pg_out), RequestError::EmptyData);
  EXPECT_EQ(link.pg.send_data(0, Bytes(kMaxDataLen + 1, 0), link.pg_out), RequestError::TooLong);
  EXPECT_EQ(link.pg.send_data(0, Bytes(kMaxDataLen, 0), link.pg_out), RequestError::None);
  EXPECT_NE(to_string(RequestError::Busy), "?");
  EXPECT_NE(to_string(State::AckSent), "?");
}

TEST(MpiConnection, LateFdlResultsOfAClosedConnectionNeverReachANewOne) {
  MpiLink link;
  link.connect();
  // The CPU sends data; before its FDL result is back, the PG disconnects.
  ASSERT_EQ(link.cpu.send_data(0, link.cpu_sap(), s7(1), link.cpu_out), RequestError::None);
  const std::vector<Outgoing> held = link.cpu_out.frames;
  link.cpu_out.frames.clear();
  link.pg.disconnect(0, link.pg_out);
  link.run(0);
  EXPECT_EQ(link.cpu.open_connections(), 0u);
  // A new connection meanwhile must not reuse SAP 0x14 while a result for it is outstanding.
  Connection pg2 = Connection::initiator(MpiLink::kCpu, 0x20);
  Outbox out;
  Outbox cpu_out;
  pg2.connect(0, out);
  ASSERT_EQ(link.cpu.on_frame(0, MpiLink::received(5, out.frames[0]), cpu_out), FdlReply::Ack);
  EXPECT_EQ(cpu_out.frames[0].ssap, 0x15);
  // The held frame's result arrives late: the new connection is untouched.
  link.cpu.on_fdl_result(0, held[0].ssap, FdlResult::NoAnswer, cpu_out);
  EXPECT_EQ(link.cpu.open_connections(), 1u);
  ASSERT_NE(link.cpu.find(0x15), nullptr);
  EXPECT_EQ(link.cpu.find(0x15)->state(), State::ConfirmSent);
}

}  // namespace
}  // namespace pbvbus::mpi
