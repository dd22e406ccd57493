// IsoSession without sockets, against a router whose channel answers only when the test says:
// AmQ from the Setup Communication answer, jobs queued in order beyond it and the bound that
// closes the connection, DT segments joined until EOT, the route closing (DR reason 0), a CPU
// that answers nothing, and what is refused before the CR. Octets by hand (§3.4, ISO 8073).
#include <gtest/gtest.h>

#include <deque>
#include <optional>

#include "iso_test_support.hpp"

#include "pbvbus/iso_on_tcp/iso_session.hpp"

namespace pbvbus::iso_on_tcp::test {
namespace {

struct Pending {
  Bytes pdu;
  S7Channel::Reply reply;
};

/// A channel that keeps every request until the test answers it.
class LaterChannel final : public S7Channel {
 public:
  explicit LaterChannel(std::deque<Pending>& q, S7Channel::Closed& closed)
      : q_(q), closed_(closed) {}
  void request(std::vector<std::uint8_t> pdu, Reply reply) override {
    q_.push_back({std::move(pdu), std::move(reply)});
  }
  void on_closed(Closed c) override { closed_ = std::move(c); }

 private:
  std::deque<Pending>& q_;
  S7Channel::Closed& closed_;
};

class LaterRouter final : public S7Router {
 public:
  RouteResult open(const RouteRequest& r) override {
    last = r;
    RouteResult res;
    res.channel = std::make_unique<LaterChannel>(pending, closed);
    return res;
  }
  std::deque<Pending> pending;
  S7Channel::Closed closed;
  std::optional<RouteRequest> last;
};

struct SessionRig {
  explicit SessionRig(SessionLimits limits = {}) {
    IsoSession::Hooks h;
    h.send = [this](std::span<const std::uint8_t> o) { sent.emplace_back(o.begin(), o.end()); };
    h.finish = [this](SessionEnd e, const std::string& why) {
      ended = e;
      reason = why;
    };
    session = std::make_unique<IsoSession>(router, limits, std::move(h), 1, 1);
  }
  void feed(const Bytes& b) { session->feed(b); }
  LaterRouter router;
  std::unique_ptr<IsoSession> session;
  std::vector<Bytes> sent;
  std::optional<SessionEnd> ended;
  std::string reason;
};

/// A Read Var job (DB1.DBB0, 1 byte) with PDU reference `ref`, in TPKT + DT.
Bytes job(std::uint16_t ref) {
  return read_db1(ref, 1);
}
std::uint16_t ref_of(const Bytes& pdu) {
  return static_cast<std::uint16_t>((pdu[4] << 8) | pdu[5]);
}
/// Setup Communication Ack-Data with max AmQ called `amq`, PDU 240 (S7 PDU only).
Bytes setup_answer(std::uint8_t amq) {
  return {0x32, 0x03, 0x00, 0x00, 0x00, 0x00, 0x00, 0x08, 0x00, 0x00,
          0x00, 0x00, 0xF0, 0x00, 0x00, amq,  0x00, amq,  0x00, 0xF0};
}

TEST(IsoSession, RouterSeesBothTsapsAsRackAndSlot) {
  SessionRig r;
  r.feed(kCr);
  ASSERT_TRUE(r.router.last);
  EXPECT_EQ(r.router.last->called_tsap, (Bytes{0x01, 0x02}));
  ASSERT_TRUE(r.router.last->called);
  EXPECT_EQ(r.router.last->called->rack, 0);
  EXPECT_EQ(r.router.last->called->slot, 2);
  EXPECT_EQ(r.router.last->calling->connection_type, s7::kTsapPg);
  ASSERT_EQ(r.sent.size(), 1u);
  EXPECT_EQ(r.sent[0], kCc);
}

TEST(IsoSession, AmqFromTheSetupAnswerBoundsOutstandingJobsTheRestWaitInOrder) {
  SessionRig r;
  r.feed(kCr);
  r.feed(kSetupReq);
  ASSERT_EQ(r.router.pending.size(), 1u);
  EXPECT_EQ(r.session->amq(), 1u);
  r.router.pending.front().reply(setup_answer(2));
  r.router.pending.pop_front();
  EXPECT_EQ(r.session->amq(), 2u);
  Bytes five;
  for (std::uint16_t i = 1; i <= 5; ++i) {
    const Bytes j = job(i);
    five.insert(five.end(), j.begin(), j.end());
  }
  r.feed(five);
  ASSERT_EQ(r.router.pending.size(), 2u);
  EXPECT_EQ(r.session->queued(), 3u);
  std::vector<std::uint16_t> order;
  while (!r.router.pending.empty()) {
    Pending p = std::move(r.router.pending.front());
    r.router.pending.pop_front();
    order.push_back(ref_of(p.pdu));
    Bytes answer = {0x32, 0x03, 0x00, 0x00, p.pdu[4], p.pdu[5], 0x00, 0x02, 0x00, 0x05,
                    0x00, 0x00, 0x04, 0x01, 0xFF,     0x04,     0x00, 0x08, 0x00};
    p.reply(answer);
  }
  EXPECT_EQ(order, (std::vector<std::uint16_t>{1, 2, 3, 4, 5}));
  EXPECT_EQ(r.session->answers(), 6u);
  EXPECT_FALSE(r.ended);
}

TEST(IsoSession, OneJobBeyondTheQueueBoundEndsTheSession) {
  SessionLimits lim;
  lim.max_queued_jobs = 3;
  SessionRig r(lim);
  r.feed(kCr);
  for (std::uint16_t i = 1; i <= 4; ++i) r.feed(job(i));  // 1 outstanding (AmQ 1), 3 waiting
  EXPECT_FALSE(r.ended);
  r.feed(job(5));
  ASSERT_TRUE(r.ended);
  EXPECT_EQ(*r.ended, SessionEnd::QueueFull);
  EXPECT_NE(r.reason.find("max_queued_jobs"), std::string::npos);
}

TEST(IsoSession, DtSegmentsAreJoinedUntilEot) {
  SessionRig r;
  r.feed(kCr);
  const Bytes whole = job(7);
  // The same S7 PDU as two DTs: the first 10 octets without EOT (02 F0 00), the rest with EOT.
  const Bytes pdu(whole.begin() + 7, whole.end());
  Bytes a = {0x03, 0x00, 0x00, 0x11, 0x02, 0xF0, 0x00};
  a.insert(a.end(), pdu.begin(), pdu.begin() + 10);
  const std::size_t rest = pdu.size() - 10;
  Bytes b = {0x03, 0x00, 0x00, static_cast<std::uint8_t>(7 + rest), 0x02, 0xF0, 0x80};
  b.insert(b.end(), pdu.begin() + 10, pdu.end());
  r.feed(a);
  EXPECT_TRUE(r.router.pending.empty());
  r.feed(b);
  ASSERT_EQ(r.router.pending.size(), 1u);
  EXPECT_EQ(r.router.pending.front().pdu, pdu);
}

TEST(IsoSession, ADtLargerThanTheConfirmedTpduSizeIsTaken) {
  // libnodave's CR order and TPDU size 2^9 = 512 (tools-and-formats §3.2), then one DT of
  // 3 + 600 octets: taken (class 0 allows 2048), handed on as one PDU.
  SessionRig r;
  r.feed({0x03, 0x00, 0x00, 0x16, 0x11, 0xE0, 0x00, 0x00, 0x00, 0x01, 0x00,
          0xC1, 0x02, 0x01, 0x00, 0xC2, 0x02, 0x01, 0x02, 0xC0, 0x01, 0x09});
  ASSERT_EQ(r.sent.size(), 1u);
  EXPECT_EQ(r.sent[0][13], 0x09);  // CC: C0 01 09
  // A Write Var job of DB1.DBB0, 572 octets: 10 + 14 + 4 + 572 = 600 octets of S7 PDU.
  Bytes pdu = {0x32, 0x01, 0x00, 0x00, 0x00, 0x01, 0x00, 0x0E, 0x02, 0x40, 0x05, 0x01, 0x12, 0x0A,
               0x10, 0x02, 0x02, 0x3C, 0x00, 0x01, 0x84, 0x00, 0x00, 0x00, 0x00, 0x04, 0x11, 0xE0};
  pdu.resize(600, 0x55);
  r.feed(tpkt_dt(pdu));
  EXPECT_FALSE(r.ended);
  ASSERT_EQ(r.router.pending.size(), 1u);
  EXPECT_EQ(r.router.pending.front().pdu.size(), 600u);
}

TEST(IsoSession, RouteClosingSendsDrReasonZeroAndEnds) {
  SessionRig r;
  r.feed(kCr);
  ASSERT_TRUE(r.router.closed);
  r.router.closed("MPI connection lost");
  ASSERT_TRUE(r.ended);
  EXPECT_EQ(*r.ended, SessionEnd::ChannelClosed);
  // DR: LI 6, 80, dst-ref = the client's 00 01, src-ref = ours 00 01, reason 00.
  EXPECT_EQ(r.sent.back(),
            (Bytes{0x03, 0x00, 0x00, 0x0B, 0x06, 0x80, 0x00, 0x01, 0x00, 0x01, 0x00}));
}

TEST(IsoSession, AnAnswerAfterTheSessionIsGoneIsDropped) {
  SessionRig r;
  r.feed(kCr);
  r.feed(job(1));
  ASSERT_EQ(r.router.pending.size(), 1u);
  r.session.reset();
  r.router.pending.front().reply({0x32, 0x03});  // must not touch the destroyed session
  r.router.closed("late");
  SUCCEED();
}

TEST(IsoSession, EmptyAnswerEndsTheSession) {
  SessionRig r;
  r.feed(kCr);
  r.feed(job(1));
  r.router.pending.front().reply({});
  ASSERT_TRUE(r.ended);
  EXPECT_EQ(*r.ended, SessionEnd::NoAnswer);
}

TEST(IsoSession, DataBeforeTheCrEndsTheSessionWithoutAnswer) {
  SessionRig r;
  r.feed(job(1));
  ASSERT_TRUE(r.ended);
  EXPECT_EQ(*r.ended, SessionEnd::Garbage);
  EXPECT_TRUE(r.sent.empty());
  EXPECT_FALSE(r.router.last);
}

TEST(IsoSession, ASecondCrOnAnOpenConnectionGetsAnEr) {
  SessionRig r;
  r.feed(kCr);
  r.feed(kCr);
  ASSERT_TRUE(r.ended);
  EXPECT_EQ(*r.ended, SessionEnd::Garbage);
  // ER: LI, 70, dst-ref 00 01, cause 02 (invalid TPDU type), then C1 with the rejected TPDU.
  const Bytes& er = r.sent.back();
  ASSERT_GE(er.size(), 9u);
  EXPECT_EQ(er[5], 0x70);
  EXPECT_EQ(er[6], 0x00);
  EXPECT_EQ(er[7], 0x01);
  EXPECT_EQ(er[8], 0x02);
}

TEST(IsoSession, AnAckFromTheClientIsRefused) {
  SessionRig r;
  r.feed(kCr);
  r.feed(tpkt_dt({0x32, 0x02, 0x00, 0x00, 0x00, 0x01, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00}));
  ASSERT_TRUE(r.ended);
  EXPECT_EQ(*r.ended, SessionEnd::Garbage);
  EXPECT_TRUE(r.router.pending.empty());
}

}  // namespace
}  // namespace pbvbus::iso_on_tcp::test
