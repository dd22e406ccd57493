// Late answers of a CPU's MPI station (mpi_station.hpp "Late answers"; s7_session.hpp): a
// session that holds a job (as an H CPU does during an update, 000 L1673-1680) answers nothing
// from handle() and hands the answer over later through the station's sink. PG 0 and CPU 2 at
// 187.5 kbit/s, HSA 31, on a real line. The job and answer bytes are written by hand from
// protocol-facts.md §H.3/§H.4; FCS = sum of DA .. last DU octet mod 256 (§B.1); the CPU's FC
// runs 6C (confirm, FCB 1 FCV 0), then FCV 1 with FCB 0, 1, 0, ... (§C.6): 5C connection ack,
// 7C ack of the setup job, 5C setup answer, 7C ack of the next job, 5C its answer, 7C, ...

#include <gtest/gtest.h>

#include <deque>
#include <memory>

#include "mpi_line_helpers.hpp"

namespace pbvbus::mpi_station::test {
namespace {

// libnodave's Setup Communication (§H.4), reference 0, and the CPU's answer (PDU 240).
constexpr const char* kSetup960 = "32 01 00 00 00 00 00 08 00 00 F0 00 00 01 00 01 03 C0";
constexpr const char* kSetupAnswer240 = "32 03 00 00 00 00 00 08 00 00 00 00 F0 00 00 01 00 01 00 F0";
// Read Var DB1.DBB0 x 10 (§H.4 example job) with PDU reference 00 07, and with 00 08.
constexpr const char* kRead7 = "32 01 00 00 00 07 00 0E 00 00 04 01 12 0A 10 02 00 0A 00 01 84 00 00 00";
constexpr const char* kRead8 = "32 01 00 00 00 08 00 0E 00 00 04 01 12 0A 10 02 00 0A 00 01 84 00 00 00";

/// A session on the line's CPU memory that holds every job while `hold` is set: it keeps the
/// job and answers it (on the memory as it is then) when the test calls release().
class HoldingSession final : public S7Session {
 public:
  HoldingSession(std::unique_ptr<S7Session> inner, const bool& hold) : inner_(std::move(inner)), hold_(hold) {}
  std::vector<std::uint8_t> handle(std::span<const std::uint8_t> pdu) override {
    if (ended_) return {};
    if (!hold_) return inner_->handle(pdu);
    held_.emplace_back(pdu.begin(), pdu.end());
    return {};
  }
  bool holds_jobs_now() const override { return hold_; }
  bool ended() const override { return ended_; }
  /// From now on every job gets no answer (as an H CPU's session lost with its CPU).
  void end() {
    ended_ = true;
    inner_.reset();
  }
  void on_late_answer(LateAnswerSink sink) override { sink_ = std::move(sink); }
  /// Answers the held jobs in arrival order through the station's sink.
  void release() {
    while (!held_.empty()) {
      auto job = std::move(held_.front());
      held_.pop_front();
      sink_(ended_ ? std::vector<std::uint8_t>{} : inner_->handle(job));
    }
  }
  const LateAnswerSink& sink() const { return sink_; }

 private:
  std::unique_ptr<S7Session> inner_;
  const bool& hold_;
  bool ended_ = false;
  std::deque<std::vector<std::uint8_t>> held_;
  LateAnswerSink sink_;
};

class HoldingFactory final : public S7SessionFactory {
 public:
  explicit HoldingFactory(S7SessionFactory& inner) : inner_(inner) {}
  std::unique_ptr<S7Session> open(std::uint8_t peer) override {
    auto s = std::make_unique<HoldingSession>(inner_.open(peer), hold);
    last = s.get();
    return s;
  }
  bool hold = false;
  HoldingSession* last = nullptr;  // owned by the station (gone with its connection)

 private:
  S7SessionFactory& inner_;
};

class MpiLateAnswer : public ::testing::Test {
 protected:
  void SetUp() override {
    pg = &l.add_client(0);
    MpiStationConfig c;
    c.address = 2;
    c.bus = l.params;
    cpu = &l.attach(c, &factory);
    l.memory.create_db(1, 16);
    for (int i = 0; i < 10; ++i) (*l.memory.db(1))[static_cast<std::size_t>(i)] = static_cast<std::uint8_t>(0x10 + i);
    l.start();
    ASSERT_TRUE(l.run_until([&] { return l.ring_formed(); }, 2000));
    connect();
    ASSERT_EQ(exchange(kSetup960), kSetupAnswer240);  // answered at once (not held)
  }
  void connect() {
    const auto h = pg->open(2);
    ASSERT_TRUE(h.has_value());
    handle = *h;
    ASSERT_TRUE(l.run_until([&] { return pg->state(handle) == mpi::State::Connected; }, 1000));
    (void)pg->take_events();
  }
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
  /// The PG's Reply events so far, with their times.
  void collect() {
    for (auto& e : pg->take_events())
      if (e.kind == EventKind::Reply) replies.push_back(std::move(e));
  }

  MpiLine l;
  HoldingFactory factory{l.factory};
  MpiStation* pg = nullptr;
  MpiStation* cpu = nullptr;
  Handle handle = 0;
  std::vector<StationEvent> replies;
};

TEST_F(MpiLateAnswer, HeldJobIsAckedAtOnceAndAnsweredWhenTheSessionHandsItOver) {
  factory.hold = true;
  const std::size_t from = l.rec.size();
  ASSERT_EQ(pg->submit(handle, bytes_from_hex(kRead7)), mpi::RequestError::None);
  ASSERT_EQ(pg->submit(handle, bytes_from_hex(kRead8)), mpi::RequestError::None);
  l.run_ms(100);
  // Both data messages are acknowledged by the MPI layer at once (B0 01 nr, §H.3 step 6): the
  // CPU's acks of the PG's messages 1 and 2. FC 7C, then 5C; FCS = 80+82+7C+14+14+B0+01+01 =
  // 0x258 -> 58 and 80+82+5C+14+14+B0+01+02 = 0x239 -> 39.
  const std::size_t ack1 = l.find("68 08 08 68 80 82 7C 14 14 B0 01 01 58 16", from);
  ASSERT_LT(ack1, l.rec.size());
  EXPECT_LT(l.find("68 08 08 68 80 82 5C 14 14 B0 01 02 39 16", ack1), l.rec.size());
  collect();
  EXPECT_TRUE(replies.empty());
  EXPECT_EQ(cpu->held_jobs(), 2u);
  EXPECT_EQ(cpu->stats().answers_held, 2u);
  EXPECT_EQ(cpu->stats().answers_none, 0u);

  // Held longer than the data ack timeout (1 s, mpi::ConnectionTiming): the connection stays:
  // the MPI layer waits for the ack of a message, not for the answer to a job.
  l.run_ms(1500);
  EXPECT_EQ(pg->state(handle), mpi::State::Connected);
  EXPECT_EQ(cpu->server_connections(), 1u);
  collect();
  EXPECT_TRUE(replies.empty());

  // The session answers now, on the memory as it is now (DBB0 changed meanwhile).
  (*l.memory.db(1))[0] = 0x55;
  const std::size_t before = l.rec.size();
  const bus::Ticks released = l.sched.now();
  factory.hold = false;
  ASSERT_NE(factory.last, nullptr);
  factory.last->release();
  EXPECT_EQ(cpu->held_jobs(), 0u);
  EXPECT_EQ(cpu->stats().answers_late, 2u);
  ASSERT_TRUE(l.run_until([&] {
    collect();
    return replies.size() == 2;
  }, 1000));
  // The answers in arrival order, each with its job's PDU reference (§H.4: octets 4-5):
  // 32 03 00 00 | 00 07 | 00 02 00 0E 00 00 | 04 01 | FF 04 00 50 <55 11 .. 19>.
  EXPECT_EQ(to_hex(replies[0].pdu),
            "32 03 00 00 00 07 00 02 00 0E 00 00 04 01 FF 04 00 50 55 11 12 13 14 15 16 17 18 19");
  EXPECT_EQ(to_hex(replies[1].pdu),
            "32 03 00 00 00 08 00 02 00 0E 00 00 04 01 FF 04 00 50 55 11 12 13 14 15 16 17 18 19");
  EXPECT_GE(replies[0].at, released);
  // On the wire: the first answer as the CPU's data message 1 (its second data message, after
  // the setup answer 0). FC 7C (its frames: 6C 5C 7C 5C, the two acks 7C 5C, so 7C); LE = 5 +
  // F1 nr + 28 = 0x23; FCS = 80+82+7C+14+14+F1+01 = 0x298, PDU header 32+03+07+02+0E = 0x4C,
  // 04 01 = 05, FF 04 00 50 = 0x153, data 55 + (11..19 = 9 x 10 + 45 = 0xBD) = 0x112: 0x54E
  // -> 4E.
  const std::size_t a1 = l.find(
      "68 23 23 68 80 82 7C 14 14 F1 01 32 03 00 00 00 07 00 02 00 0E 00 00 04 01 FF 04 00 50 "
      "55 11 12 13 14 15 16 17 18 19 4E 16",
      before);
  ASSERT_LT(a1, l.rec.size());
  EXPECT_GE(l.rec.frame(a1).start, released);
  EXPECT_EQ(l.rec.hex(a1 + 1), "E5");
  // The second waits for the PG's ack of the first (stop and wait), then goes as message 2:
  // FC 5C, FCS = 0x54E - 0x20 (7C -> 5C) + 1 (07 -> 08) + 1 (nr 01 -> 02) = 0x530 -> 30.
  const std::size_t a2 = l.find(
      "68 23 23 68 80 82 5C 14 14 F1 02 32 03 00 00 00 08 00 02 00 0E 00 00 04 01 FF 04 00 50 "
      "55 11 12 13 14 15 16 17 18 19 30 16",
      a1);
  ASSERT_LT(a2, l.rec.size());
  EXPECT_LT(l.find_prefix("68 08 08 68 82 80", a1), a2);  // the PG's data ack comes between
  EXPECT_EQ(cpu->stats().late_answers_dropped, 0u);

  // Not held any more: the next job is answered at once.
  EXPECT_EQ(exchange(kRead7),
            "32 03 00 00 00 07 00 02 00 0E 00 00 04 01 FF 04 00 50 55 11 12 13 14 15 16 17 18 19");
}

TEST_F(MpiLateAnswer, HeldJobOfAConnectionReleasedMeanwhileIsDropped) {
  factory.hold = true;
  ASSERT_EQ(pg->submit(handle, bytes_from_hex(kRead7)), mpi::RequestError::None);
  l.run_ms(50);
  ASSERT_EQ(cpu->held_jobs(), 1u);
  // Keep the old connection's sink (the session dies with its connection; its sink stays
  // callable, as a model's would be until it unregisters).
  const LateAnswerSink old_sink = factory.last->sink();
  const std::vector<std::uint8_t> answer =
      bytes_from_hex("32 03 00 00 00 07 00 02 00 0E 00 00 04 01 FF 04 00 50 10 11 12 13 14 15 16 17 18 19");
  ASSERT_EQ(pg->close(handle), mpi::RequestError::None);
  ASSERT_TRUE(l.run_until([&] { return cpu->server_connections() == 0; }, 1000));
  EXPECT_EQ(cpu->held_jobs(), 0u);

  // A new connection gets the same CPU SAP (0x14); the old sink must not reach it.
  factory.hold = false;
  connect();
  ASSERT_EQ(exchange(kSetup960), kSetupAnswer240);
  const std::uint64_t sent = cpu->stats().pdus_sent;
  const std::size_t before = l.rec.size();
  old_sink(answer);
  EXPECT_EQ(cpu->stats().late_answers_dropped, 1u);
  EXPECT_EQ(cpu->stats().answers_late, 0u);
  l.run_ms(100);
  collect();
  EXPECT_TRUE(replies.empty());
  EXPECT_EQ(cpu->stats().pdus_sent, sent);
  EXPECT_EQ(l.find_prefix("68 23 23 68 80 82", before), l.rec.size());  // no answer on the wire
}

TEST_F(MpiLateAnswer, HeldJobOfASessionThatEndedReleasesTheConnection) {
  // The session ends while it holds a job (an H CPU's connection lost): its late answer is
  // empty, the station releases the connection (80) instead of leaving the client waiting.
  factory.hold = true;
  ASSERT_EQ(pg->submit(handle, bytes_from_hex(kRead7)), mpi::RequestError::None);
  l.run_ms(50);
  ASSERT_EQ(cpu->held_jobs(), 1u);
  (void)cpu->take_events();
  factory.last->end();
  factory.last->release();
  EXPECT_EQ(cpu->held_jobs(), 0u);
  const auto cpu_broken = of_kind(cpu->take_events(), EventKind::Broken);
  ASSERT_EQ(cpu_broken.size(), 1u);
  EXPECT_EQ(cpu_broken[0].reason, EndReason::SessionEnded);
  EXPECT_EQ(cpu->stats().broken[static_cast<std::size_t>(EndReason::SessionEnded)], 1u);
  ASSERT_TRUE(l.run_until([&] { return pg->state(handle) == mpi::State::Closed; }, 1000));
  const auto pg_ends = of_kind(pg->take_events(), EventKind::Closed);
  ASSERT_EQ(pg_ends.size(), 1u);
  EXPECT_EQ(pg_ends[0].reason, EndReason::ByPeer);
  EXPECT_TRUE(of_kind(cpu->take_events(), EventKind::Closed).empty());  // reported once
  EXPECT_EQ(cpu->server_connections(), 0u);
}

TEST_F(MpiLateAnswer, JobOfASessionThatEndedGetsTheDisconnect) {
  // The same without holding: a job answered by nothing from an ended session.
  factory.last->end();
  ASSERT_EQ(pg->submit(handle, bytes_from_hex(kRead7)), mpi::RequestError::None);
  ASSERT_TRUE(l.run_until([&] { return pg->state(handle) == mpi::State::Closed; }, 1000));
  const auto pg_ends = of_kind(pg->take_events(), EventKind::Closed);
  ASSERT_EQ(pg_ends.size(), 1u);
  EXPECT_EQ(pg_ends[0].reason, EndReason::ByPeer);
  EXPECT_EQ(cpu->stats().broken[static_cast<std::size_t>(EndReason::SessionEnded)], 1u);
  EXPECT_EQ(cpu->stats().answers_none, 1u);
}

}  // namespace
}  // namespace pbvbus::mpi_station::test
