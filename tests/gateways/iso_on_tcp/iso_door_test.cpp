// The ISO-on-TCP door over a real loopback socket, byte for byte: CR -> the 22-octet CC, Setup
// Communication, Read Var (§H.4's example), Write Var seen in the CPU's memory, DR -> DC, and the
// refusals (unknown rack/slot, connection resources). Octets worked out by hand from
// tools-and-formats.md §3.4 and protocol-facts.md §H.4; the door's code produces none of them.
#include <gtest/gtest.h>

#include "iso_test_support.hpp"

#include "pbvbus/s7cpu/cpu_memory.hpp"

namespace pbvbus::iso_on_tcp::test {
namespace {

TEST(IsoDoor, CrGetsTheTwentyTwoOctetCcThatEchoesTheParameters) {
  DoorFixture f;
  Client c(f.port);
  ASSERT_TRUE(c.connected());
  ASSERT_TRUE(c.send(kCr));
  const Bytes cc = c.recv_tpkt();
  EXPECT_EQ(cc.size(), 22u);  // libnodave insists on exactly 22 octets
  EXPECT_EQ(cc, kCc);
  EXPECT_EQ(f.stats().connects, 1u);
}

TEST(IsoDoor, CcLowersATpduSizeAboveClassZerosMaximum) {
  DoorFixture f;
  Client c(f.port);
  // libnodave's order C1 C2 C0, TPDU size 2^13 = 8192: confirmed as 2^11 = 2048 (class 0), in
  // the encoder's order C0 C1 C2.
  const Bytes cr = {0x03, 0x00, 0x00, 0x16, 0x11, 0xE0, 0x00, 0x00, 0x00, 0x07, 0x00,
                    0xC1, 0x02, 0x01, 0x00, 0xC2, 0x02, 0x01, 0x02, 0xC0, 0x01, 0x0D};
  const Bytes cc = {0x03, 0x00, 0x00, 0x16, 0x11, 0xD0, 0x00, 0x07, 0x00, 0x01, 0x00,
                    0xC0, 0x01, 0x0B, 0xC1, 0x02, 0x01, 0x00, 0xC2, 0x02, 0x01, 0x02};
  ASSERT_TRUE(c.send(cr));
  EXPECT_EQ(c.recv_tpkt(), cc);
}

TEST(IsoDoor, SetupCommunicationAnswersTheLowerPduLength) {
  DoorFixture f;
  Client c(f.port);
  ASSERT_TRUE(c.send(kCr));
  ASSERT_EQ(c.recv_tpkt(), kCc);
  ASSERT_TRUE(c.send(kSetupReq));
  EXPECT_EQ(c.recv_tpkt(), kSetupResp);
}

TEST(IsoDoor, ReadVarOfTheFactSheetsExample) {
  DoorFixture f;
  f.on_io([&] {
    auto db = *f.memory.db(1);
    for (std::size_t i = 0; i < 10; ++i) db[i] = static_cast<std::uint8_t>(0xA0 + i);
  });
  Client c(f.port);
  ASSERT_TRUE(open_s7(c));
  ASSERT_TRUE(c.send(read_db1_10(1)));
  // Ack-Data, param 2, data 14: 04 01 | FF 04 00 50 (80 bits) and the ten octets.
  const Bytes answer = {0x03, 0x00, 0x00, 0x23, 0x02, 0xF0, 0x80, 0x32, 0x03, 0x00, 0x00, 0x00,
                        0x01, 0x00, 0x02, 0x00, 0x0E, 0x00, 0x00, 0x04, 0x01, 0xFF, 0x04, 0x00,
                        0x50, 0xA0, 0xA1, 0xA2, 0xA3, 0xA4, 0xA5, 0xA6, 0xA7, 0xA8, 0xA9};
  EXPECT_EQ(c.recv_tpkt(), answer);
}

TEST(IsoDoor, ReadVarOfSectionThreeFourDeadBeef) {
  DoorFixture f;
  f.on_io([&] {
    auto db = *f.memory.db(1);
    db[0] = 0xDE;
    db[1] = 0xAD;
    db[2] = 0xBE;
    db[3] = 0xEF;
  });
  Client c(f.port);
  ASSERT_TRUE(open_s7(c));
  const Bytes req = {0x03, 0x00, 0x00, 0x1F, 0x02, 0xF0, 0x80, 0x32, 0x01, 0x00, 0x00,
                     0x00, 0x01, 0x00, 0x0E, 0x00, 0x00, 0x04, 0x01, 0x12, 0x0A, 0x10,
                     0x02, 0x00, 0x04, 0x00, 0x01, 0x84, 0x00, 0x00, 0x00};
  const Bytes resp = {0x03, 0x00, 0x00, 0x1D, 0x02, 0xF0, 0x80, 0x32, 0x03, 0x00,
                      0x00, 0x00, 0x01, 0x00, 0x02, 0x00, 0x08, 0x00, 0x00, 0x04,
                      0x01, 0xFF, 0x04, 0x00, 0x20, 0xDE, 0xAD, 0xBE, 0xEF};
  ASSERT_TRUE(c.send(req));
  EXPECT_EQ(c.recv_tpkt(), resp);
}

TEST(IsoDoor, WriteVarLandsInTheCpuMemory) {
  DoorFixture f;
  Client c(f.port);
  ASSERT_TRUE(open_s7(c));
  // Write Var DB1.DBB4, 2 bytes 12 34: address 4 * 8 = 0x20; data 00 04 0010 (16 bits) 12 34.
  const Bytes req = {0x03, 0x00, 0x00, 0x25, 0x02, 0xF0, 0x80, 0x32, 0x01, 0x00, 0x00, 0x00, 0x02,
                     0x00, 0x0E, 0x00, 0x06, 0x05, 0x01, 0x12, 0x0A, 0x10, 0x02, 0x00, 0x02, 0x00,
                     0x01, 0x84, 0x00, 0x00, 0x20, 0x00, 0x04, 0x00, 0x10, 0x12, 0x34};
  // Ack-Data, param 2 (05 01), data 1: return code FF.
  const Bytes resp = {0x03, 0x00, 0x00, 0x16, 0x02, 0xF0, 0x80, 0x32, 0x03, 0x00, 0x00,
                      0x00, 0x02, 0x00, 0x02, 0x00, 0x01, 0x00, 0x00, 0x05, 0x01, 0xFF};
  ASSERT_TRUE(c.send(req));
  EXPECT_EQ(c.recv_tpkt(), resp);
  EXPECT_EQ(f.on_io([&] { return s7cpu::get_word(*f.memory.db(1), 4); }), 0x1234);
}

TEST(IsoDoor, DrIsAnsweredWithDcAndTheConnectionCloses) {
  DoorFixture f;
  Client c(f.port);
  ASSERT_TRUE(open_s7(c));
  // DR: LI 6, 80, dst-ref = the door's 00 01, src-ref = ours 00 01, reason 80 (normal).
  ASSERT_TRUE(c.send({0x03, 0x00, 0x00, 0x0B, 0x06, 0x80, 0x00, 0x01, 0x00, 0x01, 0x80}));
  // DC: LI 5, C0, dst-ref = ours 00 01, src-ref = the door's 00 01; TPKT length 4 + 1 + 5 = 10.
  EXPECT_EQ(c.recv_tpkt(), (Bytes{0x03, 0x00, 0x00, 0x0A, 0x05, 0xC0, 0x00, 0x01, 0x00, 0x01}));
  EXPECT_TRUE(c.closed_by_door());
  const auto st = f.stats();
  EXPECT_EQ(st.disconnects, 1u);
  EXPECT_EQ(st.clients_now, 0u);
  EXPECT_EQ(f.on_io([&] { return f.router.connections(0, 2); }), 0u);
}

TEST(IsoDoor, UnknownRackSlotIsRefusedWithDrAddressUnknown) {
  DoorFixture f;
  Client c(f.port);
  // Called TSAP 01 03: rack 0 slot 3, where there is no CPU.
  Bytes cr = kCr;
  cr[21] = 0x03;
  ASSERT_TRUE(c.send(cr));
  // DR: LI 6, 80, dst-ref 00 01 (the CR's), src-ref 00 01, reason 03 (address unknown).
  EXPECT_EQ(c.recv_tpkt(),
            (Bytes{0x03, 0x00, 0x00, 0x0B, 0x06, 0x80, 0x00, 0x01, 0x00, 0x01, 0x03}));
  EXPECT_TRUE(c.closed_by_door());
  EXPECT_EQ(f.stats().connects_refused, 1u);
}

TEST(IsoDoor, RackInTheTsapSelectsTheCpu) {
  DoorFixture f;
  s7cpu::CpuMemory other;
  other.create_db(1, 4);
  f.on_io([&] {
    LocalCpu cpu;
    cpu.rack = 1;
    cpu.slot = 3;
    cpu.memory = &other;
    cpu.info = &f.info;
    f.router.add(cpu);
    (*other.db(1))[0] = 0x5A;
  });
  Client c(f.port);
  Bytes cr = kCr;
  cr[21] = 1 * 32 + 3;  // rack 1, slot 3
  Bytes cc = kCc;
  cc[21] = 1 * 32 + 3;
  ASSERT_TRUE(c.send(cr));
  ASSERT_EQ(c.recv_tpkt(), cc);
  ASSERT_TRUE(c.send(kSetupReq));
  ASSERT_EQ(c.recv_tpkt(), kSetupResp);
  // DB1.DBB0, 1 byte.
  ASSERT_TRUE(
      c.send(tpkt_dt({0x32, 0x01, 0x00, 0x00, 0x00, 0x05, 0x00, 0x0E, 0x00, 0x00, 0x04, 0x01,
                      0x12, 0x0A, 0x10, 0x02, 0x00, 0x01, 0x00, 0x01, 0x84, 0x00, 0x00, 0x00})));
  const Bytes a = c.recv_tpkt();
  ASSERT_EQ(a.size(), 7u + 12 + 2 + 5);
  EXPECT_EQ(a.back(), 0x5A);
  f.on_io([&] { f.door.reset(); });  // the channel refers to `other`: end it first
}

TEST(IsoDoor, ConnectionResourcesOfTheCpuAreCountedAndRefusedBeyond) {
  DoorFixture f;
  f.on_io([&] {
    LocalCpu cpu;
    cpu.rack = 0;
    cpu.slot = 2;
    cpu.memory = &f.memory;
    cpu.info = &f.info;
    cpu.max_connections = 1;
    f.router.add(cpu);
  });
  Client a(f.port);
  ASSERT_TRUE(a.send(kCr));
  ASSERT_EQ(a.recv_tpkt(), kCc);
  Client b(f.port);
  ASSERT_TRUE(b.send(kCr));
  // DR reason 01, congestion at TSAP; the door's reference of connection 2 is 00 02.
  EXPECT_EQ(b.recv_tpkt(),
            (Bytes{0x03, 0x00, 0x00, 0x0B, 0x06, 0x80, 0x00, 0x01, 0x00, 0x02, 0x01}));
  EXPECT_TRUE(b.closed_by_door());
}

TEST(IsoDoor, LongAnswerGoesOutInSeveralDtsOfTheConfirmedTpduSize) {
  // CR with TPDU size 2^7 = 128. The answer to a read of 120 octets (DB2.DBB0, length 0x78) is
  // 12 + 2 + 4 + 120 = 138 octets of S7 PDU, more than 128 - 3 = 125 per DT: two DTs, 125
  // octets without EOT (02 F0 00), then 13 with EOT (02 F0 80).
  DoorFixture f;
  f.on_io([&] { f.memory.create_db(2, 200); });
  Client c(f.port);
  Bytes cr = kCr;
  cr[13] = 0x07;
  Bytes cc = kCc;
  cc[13] = 0x07;
  ASSERT_TRUE(c.send(cr));
  ASSERT_EQ(c.recv_tpkt(), cc);
  ASSERT_TRUE(c.send(kSetupReq));
  ASSERT_EQ(c.recv_tpkt(), kSetupResp);
  ASSERT_TRUE(
      c.send(tpkt_dt({0x32, 0x01, 0x00, 0x00, 0x00, 0x09, 0x00, 0x0E, 0x00, 0x00, 0x04, 0x01,
                      0x12, 0x0A, 0x10, 0x02, 0x00, 0x78, 0x00, 0x02, 0x84, 0x00, 0x00, 0x00})));
  const Bytes first = c.recv_tpkt();
  ASSERT_EQ(first.size(), 4u + 3 + 125);
  EXPECT_EQ(first[2], 0x00);
  EXPECT_EQ(first[3], 0x84);  // 132
  EXPECT_EQ(first[6], 0x00);  // no EOT
  const Bytes second = c.recv_tpkt();
  ASSERT_EQ(second.size(), 4u + 3 + 13);
  EXPECT_EQ(second[6], 0x80);  // EOT
}

TEST(IsoDoor, EveryPduInAndOutReachesTheCaptureHook) {
  std::vector<std::pair<PduDirection, Bytes>> seen;
  IsoDoorOptions opt;
  opt.capture = [&seen](const PduRecord& r) {
    seen.emplace_back(r.direction, Bytes(r.pdu.begin(), r.pdu.end()));
    EXPECT_EQ(Bytes(r.called_tsap.begin(), r.called_tsap.end()), (Bytes{0x01, 0x02}));
    EXPECT_EQ(Bytes(r.calling_tsap.begin(), r.calling_tsap.end()), (Bytes{0x01, 0x00}));
    EXPECT_EQ(r.connection_id, 1u);
  };
  DoorFixture f(opt);
  Client c(f.port);
  ASSERT_TRUE(open_s7(c));
  const auto n = f.on_io([&] { return seen.size(); });
  ASSERT_EQ(n, 2u);
  f.on_io([&] {
    EXPECT_EQ(seen[0].first, PduDirection::FromClient);
    EXPECT_EQ(seen[0].second, Bytes(kSetupReq.begin() + 7, kSetupReq.end()));
    EXPECT_EQ(seen[1].first, PduDirection::ToClient);
    EXPECT_EQ(seen[1].second, Bytes(kSetupResp.begin() + 7, kSetupResp.end()));
  });
}

}  // namespace
}  // namespace pbvbus::iso_on_tcp::test
