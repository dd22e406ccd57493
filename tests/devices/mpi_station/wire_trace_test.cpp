// MPI stations on a real line: PG 0, OP 1, CPU 2 at 187.5 kbit/s, HSA 31 (mpi_bus_params()),
// forming one token ring. The frames on the wire are compared with the §H.3 trace and the
// docs/mpi.md table; every other frame is worked out by hand here (FCS = sum of DA .. last DU
// octet mod 256, §B.1; FC = the FDL layer's FCB sequence per responder, §C.6: first frame FCV=0
// FCB=1, then FCV=1 with FCB 0, 1, 0, ...; SRD high 0xD from the PG, SRD low 0xC from the CPU).
// Times in bit times: min TSDR 20, TID1 37, TSL 415.

#include <gtest/gtest.h>

#include "mpi_line_helpers.hpp"

namespace pbvbus::mpi_station::test {
namespace {

constexpr const char* kSc = "E5";

/// PG 0, OP 1, CPU 2 in cable order; the ring is formed before the test starts.
class WireTrace : public ::testing::Test {
 protected:
  void SetUp() override {
    pg = &l.add_client(0);
    op = &l.add_client(1);
    cpu = &l.add_cpu(2);
    l.memory.create_db(1, 16);
    for (int i = 0; i < 10; ++i) (*l.memory.db(1))[static_cast<std::size_t>(i)] = static_cast<std::uint8_t>(0x10 + i);
    l.start();
    ASSERT_TRUE(l.run_until([&] { return l.ring_formed(); }, 2000));
  }
  /// Bit time of the start / end of frame i.
  std::int64_t start(std::size_t i) const { return l.rec.start_bits(i); }
  std::int64_t end(std::size_t i) const { return l.rec.end_bits(i); }

  MpiLine l;
  MpiStation* pg = nullptr;
  MpiStation* op = nullptr;
  MpiStation* cpu = nullptr;
};

TEST_F(WireTrace, RingOfThreeMpiStations) {
  // Token order 0 -> 1 -> 2 -> 0 (ascending addresses, §C.4), every station in every LAS.
  const std::size_t from = l.rec.size();
  l.run_ms(20);
  std::vector<std::string> tokens;
  for (std::size_t i = from; i < l.rec.size(); ++i)
    if (l.rec.frame(i).bytes[0] == 0xDC) tokens.push_back(l.rec.hex(i));
  ASSERT_GE(tokens.size(), 9u);
  for (std::size_t i = 0; i + 2 < tokens.size(); ++i) {
    if (tokens[i] == "DC 01 00") {
      EXPECT_EQ(tokens[i + 1], "DC 02 01");
      EXPECT_EQ(tokens[i + 2], "DC 00 02");
    }
  }
  for (const MpiStation* s : {pg, op, cpu}) EXPECT_EQ(s->mac().las(), (std::vector<std::uint8_t>{0, 1, 2}));
}

TEST_F(WireTrace, ConnectAndFirstDataMessageAreTheTraceBytes) {
  const std::size_t from = l.rec.size();
  const auto h = pg->open(2);
  ASSERT_TRUE(h.has_value());
  // The §H.4 example job, DB1.DBB0 x 10, as the first data message (message number 0). The CPU
  // has had no Setup Communication on this connection, so its S7 server answers with the refusal
  // Ack (docs/s7cpu.md "Refusals"): 32 02 00 00 00 01 00 00 00 00 81 04.
  ASSERT_EQ(pg->submit(*h, bytes_from_hex("32 01 00 00 00 01 00 0E 00 00 04 01 12 0A 10 02 00 0A 00 01 84 00 00 00")),
            mpi::RequestError::None);
  l.run_ms(60);
  ASSERT_EQ(pg->state(*h), mpi::State::Connected);

  // 1. Connect request PG -> CPU: the §H.3 trace frame (FC 6D: SRD high, first frame).
  const std::size_t cr = l.find("68 11 11 68 82 80 6D 00 14 E0 04 00 80 00 02 00 02 01 00 01 00 ED 16", from);
  ASSERT_LT(cr, l.rec.size());
  // It goes TID1 after the token the PG received (DC 00 02), and the CPU's FDL answers SC at
  // once: min TSDR (20 bits) after the request's end.
  EXPECT_EQ(l.rec.hex(cr - 1), "DC 00 02");
  EXPECT_EQ(start(cr), end(cr - 1) + 37);
  EXPECT_EQ(l.rec.hex(cr + 1), kSc);
  EXPECT_EQ(start(cr + 1), end(cr) + 20);
  // ... the token goes round: PG -> OP -> CPU ...
  EXPECT_EQ(l.rec.hex(cr + 2), "DC 01 00");
  EXPECT_EQ(start(cr + 2), end(cr + 1) + 37);
  EXPECT_EQ(l.rec.hex(cr + 3), "DC 02 01");
  // 2. ... and the CPU, holding the token, sends the connect confirm (the §H.3 trace frame,
  // FC 6C: SRD low, first frame to the PG) TID1 after the token's end; the PG answers SC.
  EXPECT_EQ(l.rec.hex(cr + 4), "68 11 11 68 80 82 6C 14 14 D0 04 00 80 00 02 00 02 01 00 01 00 F0 16");
  EXPECT_EQ(start(cr + 4), end(cr + 3) + 37);
  EXPECT_EQ(l.rec.hex(cr + 5), kSc);
  EXPECT_EQ(start(cr + 5), end(cr + 4) + 20);

  // The rest of the MPI traffic in order (tokens and GAP polls left out).
  const std::vector<std::string> want = {
      "68 11 11 68 82 80 6D 00 14 E0 04 00 80 00 02 00 02 01 00 01 00 ED 16", kSc,
      "68 11 11 68 80 82 6C 14 14 D0 04 00 80 00 02 00 02 01 00 01 00 F0 16", kSc,
      // 3. connection ack PG (docs/mpi.md step 3): FC 5D (FCV=1, FCB=0);
      //    FCS = 82+80+5D+14+14+05+01 = 0x28D -> 8D.
      "68 07 07 68 82 80 5D 14 14 05 01 8D 16", kSc,
      // 4. connection ack CPU (step 4): FC 5C; FCS = 80+82+5C+14+14+05+01 = 0x28C -> 8C.
      "68 07 07 68 80 82 5C 14 14 05 01 8C 16", kSc,
      // 5. data 0, Read Var DB1.DBB0 x 10 (step 5): FC 7D (FCV=1, FCB=1); FCS 9C.
      "68 1F 1F 68 82 80 7D 14 14 F1 00 32 01 00 00 00 01 00 0E 00 00 04 01 12 0A 10 02 00 0A 00 01 84 00 00 00 9C 16",
      kSc,
      // 6. the CPU's data ack, its own SRD when it next holds the token (step 6): FC 7C; FCS 57.
      "68 08 08 68 80 82 7C 14 14 B0 01 00 57 16", kSc,
      // The CPU's answer, its own data message 0 after the ack: FC 5C; LE = 3 + 2 SAPs + F1 00 +
      // 12 = 0x13; FCS = 80+82+5C+14+14+F1+00+32+02+00+00+00+01+00+00+00+00+81+04 = 0x331 -> 31.
      "68 13 13 68 80 82 5C 14 14 F1 00 32 02 00 00 00 01 00 00 00 00 81 04 31 16", kSc,
      // The PG's data ack of it at its next token: FC 5D; FCS = 82+80+5D+14+14+B0+01+00 = 0x238.
      "68 08 08 68 82 80 5D 14 14 B0 01 00 38 16", kSc,
  };
  const auto got = l.traffic(from);
  ASSERT_GE(got.size(), want.size());
  EXPECT_EQ(std::vector<std::string>(got.begin(), got.begin() + static_cast<long>(want.size())), want);

  // The data ack and the answer leave in the same token visit of the CPU, ack first; the PG's
  // ack of the answer waits for the PG's token.
  const std::size_t ack = l.find("68 08 08 68 80 82 7C 14 14 B0 01 00 57 16", from);
  ASSERT_LT(ack, l.rec.size());
  EXPECT_EQ(l.rec.hex(ack - 1), "DC 02 01");
  EXPECT_EQ(l.rec.hex(ack + 2), "68 13 13 68 80 82 5C 14 14 F1 00 32 02 00 00 00 01 00 00 00 00 81 04 31 16");
  EXPECT_EQ(start(ack + 2), end(ack + 1) + 37);  // TID1 after the PG's SC
  const std::size_t pg_ack = l.find("68 08 08 68 82 80 5D 14 14 B0 01 00 38 16", ack);
  ASSERT_LT(pg_ack, l.rec.size());
  EXPECT_EQ(l.rec.hex(pg_ack - 1), "DC 00 02");

  // The PG's user got Connected and the answer as a Reply; the CPU accepted one connection.
  const auto pe = pg->take_events();
  ASSERT_EQ(of_kind(pe, EventKind::Connected).size(), 1u);
  const auto replies = of_kind(pe, EventKind::Reply);
  ASSERT_EQ(replies.size(), 1u);
  EXPECT_EQ(to_hex(replies[0].pdu), "32 02 00 00 00 01 00 00 00 00 81 04");
  EXPECT_EQ(replies[0].handle, *h);
  EXPECT_EQ(replies[0].peer, 2);
  EXPECT_EQ(cpu->server_connections(), 1u);
  const auto ce = cpu->take_events();
  ASSERT_GE(ce.size(), 2u);
  EXPECT_EQ(ce[0].kind, EventKind::Accepted);
  EXPECT_EQ(ce[0].role, Role::Server);
  EXPECT_EQ(ce[0].local_sap, 0x14);
  EXPECT_EQ(ce[1].kind, EventKind::Connected);
  // The OP said nothing but tokens (and GAP polls).
  for (std::size_t i = from; i < l.rec.size(); ++i) {
    const auto& b = l.rec.frame(i).bytes;
    if (b[0] == 0x68) {
      EXPECT_NE(b[5] & 0x7F, 1) << l.rec.hex(i);
    }
  }

  // Disconnect: 80 from the PG (FC 7D, its fifth frame to the CPU; FCS = 82+80+7D+14+14+80 =
  // 0x227 -> 27), SC, then Closed/Local at the PG and Closed/ByPeer at the CPU.
  const std::size_t before_close = l.rec.size();
  ASSERT_EQ(pg->close(*h), mpi::RequestError::None);
  l.run_ms(20);
  const std::size_t dr = l.find("68 06 06 68 82 80 7D 14 14 80 27 16", before_close);
  ASSERT_LT(dr, l.rec.size());
  EXPECT_EQ(l.rec.hex(dr + 1), kSc);
  const auto closed = of_kind(pg->take_events(), EventKind::Closed);
  ASSERT_EQ(closed.size(), 1u);
  EXPECT_EQ(closed[0].reason, EndReason::Local);
  const auto cpu_closed = of_kind(cpu->take_events(), EventKind::Closed);
  ASSERT_EQ(cpu_closed.size(), 1u);
  EXPECT_EQ(cpu_closed[0].reason, EndReason::ByPeer);
  EXPECT_EQ(cpu->server_connections(), 0u);
  EXPECT_EQ(pg->state(*h), mpi::State::Closed);
}

}  // namespace
}  // namespace pbvbus::mpi_station::test
