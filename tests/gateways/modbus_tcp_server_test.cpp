// The Modbus TCP door with raw-socket clients: golden ADUs worked out by hand, pipelining, and
// every robustness case of docs/gateway-modbus.md (slow, stalled, half-open, flooding, garbage, wrong MBAP
// length, no client allowed). The bus is a Scheduler + PacedRunner driven on the test thread;
// each client runs on its own thread with blocking sockets.
//
// MBAP arithmetic used below: TID(2) PID(2)=0 LEN(2) UNIT(1); LEN = 1 (unit) + PDU octets.
//   FC03 request PDU  03 addr(2) qty(2)          = 5 octets -> LEN 00 06
//   FC03 response PDU 03 bc regs(2*qty)          = 2 + 2*qty -> qty 2: LEN 00 07
//   exception PDU     FC|80 code                 = 2 octets -> LEN 00 03

#include "pbvbus/gateways/modbus_tcp_server.hpp"

#include <gtest/gtest.h>

#include <atomic>
#include <thread>

#include "hex.hpp"
#include "modbus_test_handler.hpp"

namespace pbvbus::gateways {
namespace {

using namespace std::chrono_literals;
using pbvbus::test::bytes_from_hex;
using pbvbus::test::to_hex;
using test::recv_n;
using test::send_all;
using test::tcp_connect;
using test::wait_closed;
using test::with_client;

/// A scheduler event every 100 us of virtual time: proof that the bus kept running.
class Periodic final : public bus::EventTarget {
 public:
  explicit Periodic(bus::Scheduler& s) : m_s(s) { m_s.schedule(m_s.now() + kPeriod, *this); }
  void on_event(bus::Ticks now, std::uint64_t) override {
    ++count;
    m_s.schedule(now + kPeriod, *this);
  }
  static constexpr bus::Ticks kPeriod = 100 * bus::kTicksPerUs;
  std::uint64_t count = 0;

 private:
  bus::Scheduler& m_s;
};

class ModbusTcpDoor : public ::testing::Test {
 protected:
  void open(ModbusTcpOptions o = {}) {
    o.port = 0;
    srv = std::make_unique<ModbusTcpServer>(runner.io_context(), handler, o);
    port = srv->port();
    ASSERT_NE(port, 0);
  }
  /// One request, one response of `rsp_len` octets, on a fresh connection.
  std::string round_trip(const std::string& req, std::size_t rsp_len) {
    return with_client(runner, [p = port, req, rsp_len] {
      const int fd = tcp_connect(p);
      if (fd < 0) return std::string("connect failed");
      send_all(fd, bytes_from_hex(req));
      const auto r = recv_n(fd, rsp_len);
      ::close(fd);
      return to_hex(r);
    });
  }
  bool drive_until(const std::function<bool()>& done) { return test::drive_until(runner, done); }

  bus::Scheduler sched;
  bus::PacedRunner runner{sched};
  test::RegisterFileHandler handler;
  std::unique_ptr<ModbusTcpServer> srv;
  std::uint16_t port = 0;
};

TEST_F(ModbusTcpDoor, GoldenFc03ReadOfTwoRegisters) {
  open();
  handler.regs[0] = 0x1234;
  handler.regs[1] = 0x0007;
  // TID 0001, PID 0, LEN 6, unit 1, FC03 addr 0000 qty 0002 ->
  // TID 0001, PID 0, LEN 7 (unit + 03 + bc 04 + 4 octets), unit 1, 03 04 12 34 00 07.
  EXPECT_EQ(round_trip("00 01 00 00 00 06 01 03 00 00 00 02", 13),
            "00 01 00 00 00 07 01 03 04 12 34 00 07");
  ASSERT_EQ(handler.calls.size(), 1u);
  EXPECT_EQ(handler.calls[0].unit, 1);
  EXPECT_EQ(to_hex(handler.calls[0].pdu), "03 00 00 00 02");  // the PDU, MBAP stripped
  EXPECT_FALSE(handler.calls[0].broadcast);
  EXPECT_EQ(srv->stats().requests, 1u);
  EXPECT_EQ(srv->stats().exceptions, 0u);
  EXPECT_EQ(srv->stats().clients_accepted, 1u);
}

TEST_F(ModbusTcpDoor, GoldenWritesAndExceptions) {
  open();
  // FC06 register 5 = 04D2 (1234): the response echoes the request PDU, LEN 6.
  EXPECT_EQ(round_trip("12 34 00 00 00 06 01 06 00 05 04 D2", 12),
            "12 34 00 00 00 06 01 06 00 05 04 D2");
  EXPECT_EQ(handler.regs[5], 1234);
  // FC16 registers 2..3 = 0007 0008: request LEN = 1 + 1 + 2 + 2 + 1 + 4 = 11 (0B); the
  // response is 10 addr qty, LEN 6.
  EXPECT_EQ(round_trip("00 02 00 00 00 0B 01 10 00 02 00 02 04 00 07 00 08", 12),
            "00 02 00 00 00 06 01 10 00 02 00 02");
  EXPECT_EQ(handler.regs[2], 7);
  EXPECT_EQ(handler.regs[3], 8);
  // Unit 9 is not configured: 83 0A (gateway path unavailable), LEN 3, unit echoed.
  EXPECT_EQ(round_trip("00 03 00 00 00 06 09 03 00 00 00 01", 9), "00 03 00 00 00 03 09 83 0A");
  // Unit 2 is not in data exchange: 83 0B.
  EXPECT_EQ(round_trip("00 04 00 00 00 06 02 03 00 00 00 01", 9), "00 04 00 00 00 03 02 83 0B");
  // Address 15 + 2 registers runs past register 15: 83 02.
  EXPECT_EQ(round_trip("00 05 00 00 00 06 01 03 00 0F 00 02", 9), "00 05 00 00 00 03 01 83 02");
  // FC 2B is not implemented by the test handler: AB 01.
  EXPECT_EQ(round_trip("00 06 00 00 00 05 01 2B 0E 01 00", 9), "00 06 00 00 00 03 01 AB 01");
  EXPECT_EQ(srv->stats().requests, 6u);
  EXPECT_EQ(srv->stats().exceptions, 4u);
  EXPECT_EQ(srv->stats().clients_accepted, 6u);
  EXPECT_EQ(srv->stats().clients_closed_bad, 0u);
}

TEST_F(ModbusTcpDoor, PipelinedRequestsInOneSegmentAreAnsweredInOrder) {
  open();
  handler.regs[0] = 0x0102;
  // Three requests in one send(): FC06 reg 0 = 0A0B, then FC03 reg 0, then unit 9.
  const std::string req =
      "00 0A 00 00 00 06 01 06 00 00 0A 0B"
      "00 0B 00 00 00 06 01 03 00 00 00 01"
      "00 0C 00 00 00 06 09 03 00 00 00 01";
  // FC06 echo (12) + FC03 of 1 register: LEN 5, 03 02 0A 0B (11) + exception (9) = 32 octets.
  EXPECT_EQ(round_trip(req, 32),
            "00 0A 00 00 00 06 01 06 00 00 0A 0B "
            "00 0B 00 00 00 05 01 03 02 0A 0B "
            "00 0C 00 00 00 03 09 83 0A");
}

TEST_F(ModbusTcpDoor, AClientThatHalfClosesAfterItsRequestsGetsEveryResponse) {
  open();
  handler.record = false;
  // 500 pipelined FC03 of 16 registers (41-octet responses: 20 500 octets), then shutdown(WR).
  const auto req = bytes_from_hex("00 01 00 00 00 06 01 03 00 00 00 10");
  std::vector<std::uint8_t> all;
  for (int i = 0; i < 500; ++i) all.insert(all.end(), req.begin(), req.end());
  const auto [octets, closed] = with_client(runner, [&, p = port] {
    const int fd = tcp_connect(p);
    send_all(fd, all);
    ::shutdown(fd, SHUT_WR);
    const auto r = recv_n(fd, 500 * 41);
    const bool c = wait_closed(fd);
    ::close(fd);
    return std::pair{r.size(), c};
  });
  EXPECT_EQ(octets, 500u * 41u);
  EXPECT_TRUE(closed);
  EXPECT_EQ(srv->stats().requests, 500u);
  EXPECT_EQ(srv->stats().clients_closed_bad, 0u);
}

TEST_F(ModbusTcpDoor, SlowClientSendingByteByByteIsServed) {
  open();
  handler.regs[3] = 0xCAFE;
  const auto got = with_client(runner, [p = port] {
    const int fd = tcp_connect(p);
    int one = 1;
    ::setsockopt(fd, IPPROTO_TCP, TCP_NODELAY, &one, sizeof one);
    for (auto b : bytes_from_hex("00 07 00 00 00 06 01 03 00 03 00 01")) {
      send_all(fd, std::span(&b, 1));
      std::this_thread::sleep_for(15ms);  // each octet its own segment
    }
    const auto r = recv_n(fd, 11);
    ::close(fd);
    return to_hex(r);
  });
  EXPECT_EQ(got, "00 07 00 00 00 05 01 03 02 CA FE");
  EXPECT_EQ(srv->stats().clients_closed_bad, 0u);
}

TEST_F(ModbusTcpDoor, HalfOpenClientIsClosedAfterTheIdleTimeout) {
  ModbusTcpOptions o;
  o.idle_timeout = 300ms;
  open(o);
  std::atomic<bool> closed{false};
  auto client = std::async(std::launch::async, [&, p = port] {
    const int fd = tcp_connect(p);
    send_all(fd, bytes_from_hex("00 01 00"));  // three octets of a header, then nothing
    closed = wait_closed(fd);                  // the door must end it (10 s receive timeout)
    ::close(fd);
    return true;
  });
  EXPECT_TRUE(drive_until([&] { return srv->stats().clients_closed_bad == 1; }));
  drive_until([&] { return client.wait_for(0s) == std::future_status::ready; });
  client.get();
  EXPECT_TRUE(closed);
  EXPECT_EQ(srv->stats().clients_now, 0u);
  EXPECT_TRUE(handler.calls.empty());
}

TEST_F(ModbusTcpDoor, StalledClientThatNeverReadsIsClosed) {
  open();
  handler.record = false;
  // Each FC03 of 16 registers: a 12-octet request, a 7 + 2 + 32 = 41-octet response. The client
  // sends up to 400 000 of them (4.8 MB of requests, 16 MB of responses) and reads none: after
  // the kernel buffers, more than 64 KiB queue in the door, which closes the connection and
  // the client's send fails.
  const auto req = bytes_from_hex("00 01 00 00 00 06 01 03 00 00 00 10");
  std::vector<std::uint8_t> block;
  for (int i = 0; i < 1000; ++i) block.insert(block.end(), req.begin(), req.end());
  const bool send_failed = with_client(
      runner,
      [&, p = port] {
        const int fd = tcp_connect(p, 4096);
        bool failed = false;
        for (int i = 0; i < 400 && !failed; ++i) failed = !send_all(fd, block);
        if (!failed) failed = wait_closed(fd);
        ::close(fd);
        return failed;
      },
      60s);
  EXPECT_TRUE(send_failed);
  EXPECT_EQ(srv->stats().clients_closed_bad, 1u);
  EXPECT_EQ(srv->stats().clients_now, 0u);
}

TEST_F(ModbusTcpDoor, FloodOf10000PipelinedRequestsDoesNotStopTheBus) {
  Periodic tick(sched);
  // The handler notes the periodic count at each request: if the door served the flood in one
  // go, every request would see the same count.
  struct Probe final : ModbusHandler {
    test::RegisterFileHandler* inner;
    Periodic* tick;
    bus::Scheduler* sched;
    std::uint64_t first_tick = 0, last_tick = 0, n = 0;
    bus::Ticks first_time = 0, last_time = 0;
    std::size_t handle(std::uint8_t u, std::span<const std::uint8_t> p,
                       std::span<std::uint8_t, kModbusMaxPdu> r, bool b) override {
      if (n++ == 0) {
        first_tick = tick->count;
        first_time = sched->now();
      }
      last_tick = tick->count;
      last_time = sched->now();
      return inner->handle(u, p, r, b);
    }
  } probe;
  handler.record = false;
  probe.inner = &handler;
  probe.tick = &tick;
  probe.sched = &sched;
  srv = std::make_unique<ModbusTcpServer>(runner.io_context(), probe,
                                          ModbusTcpOptions{"127.0.0.1", 0});
  port = srv->port();
  handler.regs[0] = 42;

  constexpr int kN = 10'000;
  std::vector<std::uint8_t> all;
  for (int i = 0; i < kN; ++i) {
    // TID = i; FC03 of register 0.
    const std::uint8_t t[12] = {static_cast<std::uint8_t>(i >> 8),
                                static_cast<std::uint8_t>(i),
                                0,
                                0,
                                0,
                                6,
                                1,
                                3,
                                0,
                                0,
                                0,
                                1};
    all.insert(all.end(), t, t + 12);
  }
  const auto [answers, in_order] = with_client(
      runner,
      [&, p = port] {
        const int fd = tcp_connect(p);
        std::thread writer([&] { send_all(fd, all); });
        int got = 0;
        bool ordered = true;
        // Each response: TID, 00 00 00 05 01 03 02 00 2A (11 octets).
        for (; got < kN; ++got) {
          const auto r = recv_n(fd, 11);
          if (r.size() != 11) break;
          ordered &= r[0] == static_cast<std::uint8_t>(got >> 8) &&
                     r[1] == static_cast<std::uint8_t>(got) && r[9] == 0 && r[10] == 42;
        }
        writer.join();
        ::close(fd);
        return std::pair{got, ordered};
      },
      60s);
  EXPECT_EQ(answers, kN);
  EXPECT_TRUE(in_order);
  EXPECT_EQ(srv->stats().requests, static_cast<std::uint64_t>(kN));
  EXPECT_EQ(probe.n, static_cast<std::uint64_t>(kN));
  // The bus kept running while the door served the flood: periodic events ran between the
  // first and the last request, and virtual time advanced over the flood.
  EXPECT_GT(probe.last_tick, probe.first_tick);
  EXPECT_GT(probe.last_time, probe.first_time);
  // And every 100 us event up to the current virtual time ran (no event was starved).
  EXPECT_EQ(tick.count, static_cast<std::uint64_t>(sched.now() / Periodic::kPeriod));
  srv.reset();  // before the probe it refers to
}

TEST_F(ModbusTcpDoor, GarbageBytesCloseTheConnection) {
  open();
  // "GET / HTTP/1.1": TID 'GE', PID 'T ' = 5420 != 0 -> not Modbus, closed.
  const bool closed = with_client(runner, [p = port] {
    const int fd = tcp_connect(p);
    const std::string http = "GET / HTTP/1.1\r\n\r\n";
    send_all(fd, std::span(reinterpret_cast<const std::uint8_t*>(http.data()), http.size()));
    const bool c = wait_closed(fd);
    ::close(fd);
    return c;
  });
  EXPECT_TRUE(closed);
  EXPECT_EQ(srv->stats().bad_frames, 1u);
  EXPECT_EQ(srv->stats().clients_closed_bad, 1u);
  EXPECT_EQ(srv->stats().requests, 0u);
}

TEST_F(ModbusTcpDoor, WrongMbapLengthClosesAfterAnsweringWhatCameBefore) {
  open();
  handler.regs[0] = 0x00AA;
  for (const char* bad :
       {"00 02 00 00 00 FF 01 03", "00 02 00 00 00 01 01", "00 02 00 00 00 00 01"}) {
    const auto [first, closed] = with_client(runner, [p = port, bad] {
      const int fd = tcp_connect(p);
      // A good FC03 (LEN 6) and, in the same segment, a header with a bad LEN.
      auto b = bytes_from_hex(std::string("00 01 00 00 00 06 01 03 00 00 00 01") + bad);
      send_all(fd, b);
      const auto r = recv_n(fd, 11);
      const bool c = wait_closed(fd);
      ::close(fd);
      return std::pair{to_hex(r), c};
    });
    EXPECT_EQ(first, "00 01 00 00 00 05 01 03 02 00 AA") << bad;
    EXPECT_TRUE(closed) << bad;
  }
  EXPECT_EQ(srv->stats().bad_frames, 3u);
  EXPECT_EQ(srv->stats().clients_closed_bad, 3u);
  EXPECT_EQ(srv->stats().requests, 3u);
}

TEST_F(ModbusTcpDoor, WithMaxClientsZeroEveryClientIsAcceptedAndClosedAtOnce) {
  // (A full door with a limit evicts the longest-idle connection: modbus_tcp_limits_test.cpp.)
  ModbusTcpOptions o;
  o.max_clients = 0;
  open(o);
  const bool closed = with_client(runner, [p = port] {
    const int fd = tcp_connect(p);
    const bool c = fd >= 0 && wait_closed(fd);
    ::close(fd);
    return c;
  });
  EXPECT_TRUE(closed);
  EXPECT_EQ(srv->rejected(), 1u);
  EXPECT_EQ(srv->stats().clients_refused, 1u);
  EXPECT_EQ(srv->stats().clients_accepted, 0u);
  EXPECT_EQ(srv->stats().clients_closed_bad, 0u);  // counted apart from bad frames and stalls
  EXPECT_EQ(srv->stats().clients_now, 0u);
}

TEST_F(ModbusTcpDoor, CloseEndsEveryConnectionAndTheDoorCanBeDestroyedBeforeTheIoContext) {
  open();
  int fd = -1;
  with_client(runner, [&, p = port] {
    fd = tcp_connect(p);
    return 0;
  });
  drive_until([&] { return srv->stats().clients_now == 1; });
  srv->close();
  srv->close();  // idempotent
  EXPECT_EQ(srv->stats().clients_now, 0u);
  const bool closed = with_client(runner, [&] { return wait_closed(fd); });
  EXPECT_TRUE(closed);
  ::close(fd);
  srv.reset();
  runner.run_for(5 * bus::kTicksPerMs);  // queued handlers find the door gone
  // A new connection is refused: nobody listens any more.
  EXPECT_LT(tcp_connect(port), 0);
}

}  // namespace
}  // namespace pbvbus::gateways
