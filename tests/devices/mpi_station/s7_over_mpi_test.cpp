// S7 communication over MPI on a real line (PG 0, OP 1, CPU 2 at 187.5 kbit/s, HSA 31): the CPU
// serves a s7cpu::CpuMemory through S7CpuSessionFactory. Job and answer bytes are written by hand
// from protocol-facts.md §H.4 and tools-and-formats.md §3.4; frames on the wire with their FCS
// worked out here (sum of DA .. last DU octet mod 256).

#include <gtest/gtest.h>

#include <cstdio>

#include "mpi_line_helpers.hpp"

namespace pbvbus::mpi_station::test {
namespace {

// libnodave's Setup Communication job (§H.4): AmQ 1/1, PDU 960 (03 C0), reference 0.
constexpr const char* kSetup960 = "32 01 00 00 00 00 00 08 00 00 F0 00 00 01 00 01 03 C0";
// The CPU's answer: the lower of each value, PDU 240 (00 F0) (s7::negotiate, docs/s7.md).
constexpr const char* kSetupAnswer240 = "32 03 00 00 00 00 00 08 00 00 00 00 F0 00 00 01 00 01 00 F0";
// §H.4 example job: Read Var DB1.DBB0, 10 bytes, reference 1.
constexpr const char* kReadDb1Dbb0x10 = "32 01 00 00 00 01 00 0E 00 00 04 01 12 0A 10 02 00 0A 00 01 84 00 00 00";

class S7OverMpi : public ::testing::Test {
 protected:
  void SetUp() override {
    pg = &l.add_client(0);
    op = &l.add_client(1);
    cpu = &l.add_cpu(2);
    l.memory.create_db(1, 256);
    for (int i = 0; i < 10; ++i) (*l.memory.db(1))[static_cast<std::size_t>(i)] = static_cast<std::uint8_t>(0x10 + i);
    l.start();
    ASSERT_TRUE(l.run_until([&] { return l.ring_formed(); }, 2000));
    const auto h = pg->open(2);
    ASSERT_TRUE(h.has_value());
    handle = *h;
    ASSERT_TRUE(l.run_until([&] { return pg->state(handle) == mpi::State::Connected; }, 1000));
    (void)pg->take_events();
  }
  /// Submits `job` and runs until the PG's user gets the answer; returns it as hex.
  std::string exchange(const std::string& job) {
    EXPECT_EQ(pg->submit(handle, bytes_from_hex(job)), mpi::RequestError::None);
    std::string answer;
    l.run_until(
        [&] {
          for (const auto& e : pg->take_events())
            if (e.kind == EventKind::Reply) answer = to_hex(e.pdu);
          return !answer.empty();
        },
        1000);
    return answer;
  }

  MpiLine l;
  MpiStation* pg = nullptr;
  MpiStation* op = nullptr;
  MpiStation* cpu = nullptr;
  Handle handle = 0;
};

TEST_F(S7OverMpi, SetupCommunicationNegotiates240ThroughMpi) {
  EXPECT_EQ(exchange(kSetup960), kSetupAnswer240);
}

TEST_F(S7OverMpi, ReadsDb1Dbb0TenBytesAsH4Shows) {
  ASSERT_EQ(exchange(kSetup960), kSetupAnswer240);
  const std::size_t from = l.rec.size();
  // §H.4 answer: 32 03 00 00 00 01 00 02 00 0E 00 00 | 04 01 | FF 04 00 50 <10 bytes>.
  EXPECT_EQ(exchange(kReadDb1Dbb0x10),
            "32 03 00 00 00 01 00 02 00 0E 00 00 04 01 FF 04 00 50 10 11 12 13 14 15 16 17 18 19");
  // On the wire: the job as the PG's data message 1 (its frames to the CPU so far: 6D connect,
  // 5D connection ack, 7D setup, 5D ack of the setup answer, so FC 7D), FCS = the §H.3/§H.4
  // step-5 frame's 9C + 1 for the message number = 9D.
  const std::size_t job =
      l.find("68 1F 1F 68 82 80 7D 14 14 F1 01 32 01 00 00 00 01 00 0E 00 00 04 01 12 0A 10 02 00 0A 00 01 84 00 00 00 9D 16",
             from);
  ASSERT_LT(job, l.rec.size());
  EXPECT_EQ(l.rec.hex(job + 1), "E5");
  // The CPU's data ack (FC 7C; FCS = 80+82+7C+14+14+B0+01+01 = 0x258) and its answer, data
  // message 1 (FC 5C; LE = 3 + 2 + 2 + 28 = 0x23; FCS = 80+82+5C+14+14+F1+01 = 0x278, plus the
  // PDU: header 0x46, 04 01 = 0x05, FF 04 00 50 = 0x153, data 10..19 = 0xCD: 0x4E3 -> E3).
  const std::size_t ack = l.find("68 08 08 68 80 82 7C 14 14 B0 01 01 58 16", job);
  ASSERT_LT(ack, l.rec.size());
  EXPECT_EQ(l.rec.hex(ack + 2),
            "68 23 23 68 80 82 5C 14 14 F1 01 32 03 00 00 00 01 00 02 00 0E 00 00 04 01 FF 04 00 50 "
            "10 11 12 13 14 15 16 17 18 19 E3 16");

  // Nine more reads of the same job: each answer is what the memory holds at that moment (the
  // owner changes DBB0 between reads, as a user program would between two cycles).
  for (int i = 1; i < 10; ++i) {
    (*l.memory.db(1))[0] = static_cast<std::uint8_t>(0x80 + i);
    char b0[3];
    std::snprintf(b0, sizeof b0, "%02X", 0x80 + i);
    EXPECT_EQ(exchange(kReadDb1Dbb0x10), std::string("32 03 00 00 00 01 00 02 00 0E 00 00 04 01 FF 04 00 50 ") + b0 +
                                             " 11 12 13 14 15 16 17 18 19")
        << i;
  }
  EXPECT_EQ(pg->stats().pdus_sent, 11u);
  EXPECT_EQ(pg->stats().pdus_received, 11u);
  EXPECT_EQ(cpu->stats().pdus_received, 11u);
  EXPECT_EQ(cpu->stats().pdus_sent, 11u);
  EXPECT_EQ(pg->stats().frames_refused + pg->stats().frames_unanswered, 0u);
}

TEST_F(S7OverMpi, WriteVarThenReadShowsTheWrittenBytes) {
  ASSERT_EQ(exchange(kSetup960), kSetupAnswer240);
  // Write Var DB1.DBB2, 4 bytes AA BB CC DD (§H.4): parameters 05 01 + item (address 2 x 8 =
  // 0x10), 14 octets; data 00 04 00 20 AA BB CC DD (transport 04, 32 bits), 8 octets.
  EXPECT_EQ(exchange("32 01 00 00 00 02 00 0E 00 08 05 01 12 0A 10 02 00 04 00 01 84 00 00 10 00 04 00 20 AA BB CC DD"),
            "32 03 00 00 00 02 00 02 00 01 00 00 05 01 FF");
  const auto db = *l.memory.db(1);
  EXPECT_EQ(to_hex(db.subspan(0, 8)), "10 11 AA BB CC DD 16 17");
  EXPECT_EQ(exchange(kReadDb1Dbb0x10),
            "32 03 00 00 00 01 00 02 00 0E 00 00 04 01 FF 04 00 50 10 11 AA BB CC DD 16 17 18 19");
}

TEST_F(S7OverMpi, TheLargestAnswerFitsOneDataMessage) {
  ASSERT_EQ(exchange(kSetup960), kSetupAnswer240);
  for (std::size_t i = 0; i < 256; ++i) (*l.memory.db(1))[i] = static_cast<std::uint8_t>(i);
  // 222 bytes (0xDE): answer = 12 + 2 + 4 + 222 = 240 octets, the negotiated PDU size; data
  // length 4 + 222 = 0xE2, 222 x 8 = 1776 = 0x06F0 bits.
  const std::size_t from = l.rec.size();
  const std::string answer = exchange("32 01 00 00 00 03 00 0E 00 00 04 01 12 0A 10 02 00 DE 00 01 84 00 00 00");
  ASSERT_EQ(answer.size(), 240u * 3 - 1);
  EXPECT_EQ(answer.substr(0, 18 * 3), "32 03 00 00 00 03 00 02 00 E2 00 00 04 01 FF 04 06 F0 ");
  // On the wire: SD2 with LE = 3 + 2 SAPs + F1 nr + 240 = 247 (0xF7): 4 + 247 + 2 = 253 octets.
  const std::size_t big = l.find_prefix("68 F7 F7 68 80 82", from);
  ASSERT_LT(big, l.rec.size());
  EXPECT_EQ(l.rec.frame(big).bytes.size(), 253u);
  EXPECT_EQ(l.rec.hex(big + 1), "E5");
  // One more byte does not fit the PDU: item return code 85 (docs/s7cpu.md "PDU size").
  EXPECT_EQ(exchange("32 01 00 00 00 04 00 0E 00 00 04 01 12 0A 10 02 00 DF 00 01 84 00 00 00"),
            "32 03 00 00 00 04 00 02 00 04 00 00 04 01 85 00 00 00");
  // A PDU longer than one data message carries (242 octets) is refused at submit().
  EXPECT_EQ(pg->submit(handle, Bytes(243, 0x32)), mpi::RequestError::TooLong);
  EXPECT_EQ(pg->submit(handle, Bytes{}), mpi::RequestError::EmptyData);
}

TEST(S7CpuSessions, OfferAtMost240OverMpi) {
  s7cpu::CpuMemory memory;
  s7cpu::CpuInfo info;
  S7CpuSessionFactory big(memory, info, s7::SetupCommunication{8, 8, 960});
  EXPECT_EQ(big.own().pdu_length, 240);
  EXPECT_EQ(big.own().max_amq_calling, 8);
  S7CpuSessionFactory small(memory, info, s7::SetupCommunication{1, 1, 120});
  EXPECT_EQ(small.own().pdu_length, 120);
  auto session = big.open(0);
  ASSERT_NE(session, nullptr);
  // AmQ: the lower of the client's 1 and the factory's 8; PDU: the lower of 960 and 240.
  EXPECT_EQ(to_hex(session->handle(bytes_from_hex(kSetup960))), kSetupAnswer240);
  // Not an S7 PDU: no answer.
  EXPECT_TRUE(session->handle(bytes_from_hex("01 02 03")).empty());
  EXPECT_EQ(big.sessions_opened(), 1u);
}

}  // namespace
}  // namespace pbvbus::mpi_station::test
