// The door's bounds over real sockets, built into the ASan+UBSan suite as well: garbage, input
// byte by byte, 10 000 pipelined jobs, too many connections, a client that does not read, a
// half-open socket, a client that half-closes after its jobs. No test measures time; the idle
// timeout is set short only so that the test does not wait a minute for it.
#include <gtest/gtest.h>

#include <atomic>
#include <chrono>

#include "iso_test_support.hpp"

namespace pbvbus::iso_on_tcp::test {
namespace {

bool log_has(DoorFixture& f, const std::string& what) {
  return f.on_io([&] {
    for (const auto& l : f.log)
      if (l.find(what) != std::string::npos) return true;
    return false;
  });
}

TEST(IsoDoorSanitize, GarbageBeforeTheCrClosesTheConnectionAndIsLogged) {
  DoorFixture f;
  Client c(f.port);
  ASSERT_TRUE(c.send({'G', 'E', 'T', ' ', '/', ' ', 'H', 'T', 'T', 'P', '/', '1', '.', '1', '\r',
                      '\n', '\r', '\n'}));
  EXPECT_TRUE(c.closed_by_door());
  EXPECT_EQ(f.stats().closed_garbage, 1u);
  EXPECT_TRUE(log_has(f, "TPKT framing lost"));
  // The door still serves the next client.
  Client d(f.port);
  EXPECT_TRUE(open_s7(d));
}

TEST(IsoDoorSanitize, GarbageInsideADtClosesTheConnection) {
  DoorFixture f;
  Client c(f.port);
  ASSERT_TRUE(open_s7(c));
  ASSERT_TRUE(c.send(tpkt_dt({0xDE, 0xAD, 0xBE, 0xEF, 0x00, 0x01, 0x02, 0x03, 0x04, 0x05})));
  EXPECT_TRUE(c.closed_by_door());
  EXPECT_EQ(f.stats().closed_garbage, 1u);
}

TEST(IsoDoorSanitize, ManyGarbageClientsInARowLeaveTheDoorServing) {
  DoorFixture f;
  std::uint32_t x = 12345;  // a fixed-seed xorshift: the same bytes every run
  for (int i = 0; i < 200; ++i) {
    Client c(f.port);
    Bytes junk(64 + i);
    for (auto& b : junk) {
      x ^= x << 13;
      x ^= x >> 17;
      x ^= x << 5;
      b = static_cast<std::uint8_t>(x);
    }
    if (i % 2) junk[0] = 0x03;  // half of them pass the version octet
    c.send(junk);
    c.shutdown_write();
    EXPECT_TRUE(c.closed_by_door());
  }
  Client good(f.port);
  EXPECT_TRUE(open_s7(good));
  EXPECT_EQ(f.stats().clients_now, 1u);
}

TEST(IsoDoorSanitize, ByteByByteInputIsReassembled) {
  DoorFixture f;
  f.on_io([&] { (*f.memory.db(1))[9] = 0x77; });
  Client c(f.port);
  auto dribble = [&c](const Bytes& b) {
    for (std::uint8_t octet : b)
      if (!c.send({octet})) return false;
    return true;
  };
  ASSERT_TRUE(dribble(kCr));
  ASSERT_EQ(c.recv_tpkt(), kCc);
  ASSERT_TRUE(dribble(kSetupReq));
  ASSERT_EQ(c.recv_tpkt(), kSetupResp);
  ASSERT_TRUE(dribble(read_db1_10(3)));
  const Bytes a = c.recv_tpkt();
  ASSERT_EQ(a.size(), 35u);
  EXPECT_EQ(a[12], 0x03);  // PDU reference
  EXPECT_EQ(a.back(), 0x77);
}

TEST(IsoDoorSanitize, TenThousandPipelinedJobsAreAllAnsweredInOrder) {
  DoorFixture f;
  Client c(f.port);
  ASSERT_TRUE(open_s7(c));
  constexpr int kJobs = 10'000;
  std::atomic<bool> sent_ok{true};
  std::thread writer([&] {
    Bytes all;
    for (int i = 1; i <= kJobs; ++i) {
      const Bytes j = read_db1_10(static_cast<std::uint16_t>(i));
      all.insert(all.end(), j.begin(), j.end());
    }
    sent_ok = c.send(all);  // one burst: the door sees many jobs per read
  });
  int in_order = 0;
  for (int i = 1; i <= kJobs; ++i) {
    const Bytes a = c.recv_tpkt();
    if (a.size() != 35u) break;
    if (((a[11] << 8) | a[12]) == i && a[21] == 0xFF) ++in_order;
  }
  writer.join();
  EXPECT_TRUE(sent_ok);
  EXPECT_EQ(in_order, kJobs);
  const auto st = f.stats();
  EXPECT_EQ(st.jobs, kJobs + 1u);  // and the setup
  EXPECT_EQ(st.answers, kJobs + 1u);
}

TEST(IsoDoorSanitize, TooManyConnectionsAreRefusedAtOnceAndLogged) {
  IsoDoorOptions opt;
  opt.max_clients = 2;
  DoorFixture f(opt);
  Client a(f.port);
  Client b(f.port);
  ASSERT_TRUE(open_s7(a));
  ASSERT_TRUE(open_s7(b));
  Client c(f.port);
  ASSERT_TRUE(c.connected());  // the kernel accepted it; the door closes it
  EXPECT_TRUE(c.closed_by_door());
  EXPECT_EQ(f.stats().clients_refused, 1u);
  EXPECT_TRUE(log_has(f, "max_clients"));
  // Room again once one leaves.
  ASSERT_TRUE(a.send({0x03, 0x00, 0x00, 0x0B, 0x06, 0x80, 0x00, 0x01, 0x00, 0x01, 0x80}));
  EXPECT_TRUE(a.closed_by_door());
  Client d(f.port);
  ASSERT_TRUE(d.send(kCr));
  EXPECT_EQ(d.recv_tpkt(), cc_with_ref(3));  // connection 3: a refused one gets no number
}

TEST(IsoDoorSanitize, AClientThatDoesNotReadIsHeldBackThenClosed) {
  IsoDoorOptions opt;
  opt.max_output = 16 * 1024;
  opt.idle_timeout = std::chrono::milliseconds(200);
  DoorFixture f(opt);
  f.on_io([&] { f.memory.create_db(2, 200); });
  Client c(f.port);
  const int small = 4096;
  ::setsockopt(c.fd(), SOL_SOCKET, SO_RCVBUF, &small, sizeof small);
  ASSERT_TRUE(open_s7(c));
  // Read Var DB2.DBB0, 200 octets: a 12 + 2 + 4 + 200 + 7 = 225-octet answer per 31-octet job.
  Bytes burst;
  for (int i = 0; i < 100; ++i) {
    const Bytes j =
        tpkt_dt({0x32, 0x01, 0x00, 0x00, 0x00, 0x02, 0x00, 0x0E, 0x00, 0x00, 0x04, 0x01,
                 0x12, 0x0A, 0x10, 0x02, 0x00, 0xC8, 0x00, 0x02, 0x84, 0x00, 0x00, 0x00});
    burst.insert(burst.end(), j.begin(), j.end());
  }
  // Never read; keep sending until the door has closed us (at most a million jobs, 31 MB: more
  // than the kernel buffers of both ends). The door stops taking input once 4 KiB of answers
  // wait, so the sends block once the buffers are full, until the idle watch closes it.
  bool gone = false;
  for (int round = 0; round < 10'000 && !gone; ++round) gone = !c.send(burst);
  EXPECT_TRUE(gone);
  const auto st = f.stats();
  EXPECT_EQ(st.closed_stalled, 1u);
  EXPECT_LT(st.jobs, 1000u);  // held back: far fewer jobs taken than sent
  EXPECT_TRUE(log_has(f, "does not read"));
}

TEST(IsoDoorSanitize, AHalfOpenSocketIsClosedAfterTheIdleTimeout) {
  IsoDoorOptions opt;
  opt.idle_timeout = std::chrono::milliseconds(100);
  DoorFixture f(opt);
  Client c(f.port);
  ASSERT_TRUE(c.send({0x03, 0x00, 0x00}));  // a TPKT that never ends
  EXPECT_TRUE(c.closed_by_door());
  EXPECT_EQ(f.stats().closed_idle, 1u);
  EXPECT_EQ(f.stats().clients_now, 0u);
}

TEST(IsoDoorSanitize, AClientThatHalfClosesGetsItsAnswersThenEof) {
  DoorFixture f;
  Client c(f.port);
  ASSERT_TRUE(c.send(kCr));
  ASSERT_TRUE(c.send(kSetupReq));
  ASSERT_TRUE(c.send(read_db1_10(9)));
  c.shutdown_write();
  EXPECT_EQ(c.recv_tpkt(), kCc);
  EXPECT_EQ(c.recv_tpkt(), kSetupResp);
  EXPECT_EQ(c.recv_tpkt().size(), 35u);
  EXPECT_TRUE(c.closed_by_door());
}

TEST(IsoDoorSanitize, ClosingTheDoorWithOpenConnectionsEndsTheirRoutes) {
  DoorFixture f;
  Client a(f.port);
  Client b(f.port);
  ASSERT_TRUE(open_s7(a));
  ASSERT_TRUE(open_s7(b));
  EXPECT_EQ(f.on_io([&] { return f.router.connections(0, 2); }), 2u);
  f.on_io([&] { f.door->close(); });
  EXPECT_TRUE(a.closed_by_door());
  EXPECT_TRUE(b.closed_by_door());
  EXPECT_EQ(f.on_io([&] { return f.router.connections(0, 2); }), 0u);
}

/// Wraps LocalCpuRouter's channels so that every answer comes on a later turn of the io_context,
/// as a CPU across MPI answers later.
class LaterRouter final : public S7Router {
 public:
  LaterRouter(LocalCpuRouter& inner, boost::asio::io_context& io) : inner_(inner), io_(io) {}
  RouteResult open(const RouteRequest& r) override {
    RouteResult res = inner_.open(r);
    if (res.channel) res.channel = std::make_unique<Later>(std::move(res.channel), io_, *this);
    return res;
  }

 private:
  struct Later final : S7Channel {
    Later(std::unique_ptr<S7Channel> c, boost::asio::io_context& i, LaterRouter& r)
        : inner(std::move(c)), io(i), router(r) {}
    ~Later() override { router.closers.clear(); }
    void request(std::vector<std::uint8_t> pdu, Reply reply) override {
      // A one-item Read Var of bit address 0x28 (byte 5) gets "no answer" (an empty one).
      const bool silent = pdu.size() == 24 && pdu[10] == 0x04 && pdu[23] == 0x28;
      inner->request(std::move(pdu), [this, reply, silent](std::vector<std::uint8_t> a) {
        if (silent) a.clear();
        boost::asio::post(io, [reply, a = std::move(a)] { reply(a); });
      });
    }
    void on_closed(Closed c) override { router.closers.push_back(std::move(c)); }
    std::unique_ptr<S7Channel> inner;
    boost::asio::io_context& io;
    LaterRouter& router;
  };
  LocalCpuRouter& inner_;
  boost::asio::io_context& io_;

 public:
  /// The routes' close callbacks (the test breaks a route through them), on the door's thread.
  std::vector<S7Channel::Closed> closers;
};

auto later_router(std::unique_ptr<LaterRouter>& keep) {
  return [&keep](LocalCpuRouter& r, boost::asio::io_context& io) -> S7Router& {
    keep = std::make_unique<LaterRouter>(r, io);
    return *keep;
  };
}

TEST(IsoDoorSanitize, AChannelThatAnswersLaterGetsPipelinedJobsOneAtATimeInOrder) {
  std::unique_ptr<LaterRouter> later;
  DoorFixture f({}, {1, 1, 240}, later_router(later));
  Client c(f.port);
  ASSERT_TRUE(open_s7(c));
  Bytes burst;
  for (std::uint16_t i = 1; i <= 50; ++i) {
    const Bytes j = read_db1_10(i);
    burst.insert(burst.end(), j.begin(), j.end());
  }
  ASSERT_TRUE(c.send(burst));  // AmQ 1: the door queues 49 of them
  for (int i = 1; i <= 50; ++i) {
    const Bytes a = c.recv_tpkt();
    ASSERT_EQ(a.size(), 35u);
    EXPECT_EQ((a[11] << 8) | a[12], i);
  }
}

TEST(IsoDoorSanitize, ARouteThatBreaksSendsDrAndClosesTheConnection) {
  std::unique_ptr<LaterRouter> later;
  DoorFixture f({}, {1, 1, 240}, later_router(later));
  Client c(f.port);
  ASSERT_TRUE(open_s7(c));
  f.on_io([&] {
    ASSERT_EQ(later->closers.size(), 1u);
    auto close = later->closers.front();
    close("MPI connection lost");
  });
  // DR: LI 6, 80, dst-ref = the client's 00 01, src-ref = the door's 00 01, reason 00.
  EXPECT_EQ(c.recv_tpkt(),
            (Bytes{0x03, 0x00, 0x00, 0x0B, 0x06, 0x80, 0x00, 0x01, 0x00, 0x01, 0x00}));
  EXPECT_TRUE(c.closed_by_door());
  EXPECT_EQ(f.stats().routes_closed, 1u);
  EXPECT_TRUE(log_has(f, "MPI connection lost"));
}

TEST(IsoDoorSanitize, ALaterEmptyAnswerClosesTheConnection) {
  std::unique_ptr<LaterRouter> later;
  DoorFixture f({}, {1, 1, 240}, later_router(later));
  Client c(f.port);
  ASSERT_TRUE(open_s7(c));
  // DB1.DBB5, 1 byte: the wrapper turns its answer into "no answer" (see Later::request).
  ASSERT_TRUE(
      c.send(tpkt_dt({0x32, 0x01, 0x00, 0x00, 0x00, 0x01, 0x00, 0x0E, 0x00, 0x00, 0x04, 0x01,
                      0x12, 0x0A, 0x10, 0x02, 0x00, 0x01, 0x00, 0x01, 0x84, 0x00, 0x00, 0x28})));
  EXPECT_TRUE(c.closed_by_door());
  EXPECT_EQ(f.stats().closed_garbage, 1u);
}

TEST(IsoDoorSanitize, AnswersThatComeAfterTheClientLeftAreDropped) {
  std::unique_ptr<LaterRouter> later;
  DoorFixture f({}, {1, 1, 240}, later_router(later));
  for (int round = 0; round < 20; ++round) {
    Client c(f.port);
    Bytes burst = kCr;
    burst.insert(burst.end(), kSetupReq.begin(), kSetupReq.end());
    for (std::uint16_t i = 1; i <= 10; ++i) {
      const Bytes j = read_db1_10(i);
      burst.insert(burst.end(), j.begin(), j.end());
    }
    ASSERT_TRUE(c.send(burst));
    // Leave at once, with a reset: answers are still on their way through the io_context.
    const linger l{1, 0};
    ::setsockopt(c.fd(), SOL_SOCKET, SO_LINGER, &l, sizeof l);
  }
  Client ok(f.port);
  EXPECT_TRUE(open_s7(ok));
  EXPECT_EQ(f.stats().clients_now, 1u);
}

}  // namespace
}  // namespace pbvbus::iso_on_tcp::test
