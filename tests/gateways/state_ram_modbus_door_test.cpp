// The state-RAM Modbus core behind the real doors with libmodbus as the client: a Modbus TCP
// door on an ephemeral port (answering 0x0B for an unknown unit, as a gateway in front of the
// line does) and the RTU door on its pty (a multidrop line: an unknown unit gets no answer).
// Unit 1 and unit 129 are served from two different racks' state RAMs, and the resolver swaps
// them as a switchover with the address swap does (seed 003: primary 1, standby 129).
// The client runs on its own thread while the test thread drives the paced runner; the handler
// and the state RAMs are only touched on the test thread.

#include <gtest/gtest.h>
#include <modbus/modbus.h>

#include <cerrno>
#include <map>
#include <string>
#include <vector>

#include "modbus_test_handler.hpp"

#include "pbvbus/gateways/modbus_rtu_port.hpp"
#include "pbvbus/gateways/modbus_tcp_server.hpp"
#include "pbvbus/gateways/state_ram_modbus.hpp"

namespace pbvbus::gateways {
namespace {

using quantum::StateRam;
using quantum::StateRamSizes;

constexpr StateRamSizes kSizes{32, 16, 8, 16};

/// What one client session saw: the values read, or the first error.
struct Seen {
  std::vector<int> values;
  std::string error;
};

/// Reads `count` holding registers at 0 from each unit in turn, then (if `write_unit`) writes
/// register 3 = 0x0777 to that unit. `ctx` is connected here and freed at the end.
Seen session(modbus_t* ctx, const std::vector<int>& units, int count, int write_unit = 0) {
  Seen s;
  if (ctx == nullptr) return {{}, "modbus_new failed"};
  modbus_set_response_timeout(ctx, 5, 0);
  if (modbus_connect(ctx) != 0) {
    s.error = std::string("connect: ") + modbus_strerror(errno);
    modbus_free(ctx);
    return s;
  }
  for (int u : units) {
    std::uint16_t r[8]{};
    modbus_set_slave(ctx, u);
    const int n = modbus_read_registers(ctx, 0, count, r);
    if (n != count) {
      s.values.push_back(-errno);
      continue;
    }
    for (int i = 0; i < n; ++i) s.values.push_back(r[i]);
  }
  if (write_unit != 0) {
    modbus_set_slave(ctx, write_unit);
    if (modbus_write_register(ctx, 3, 0x0777) != 1)
      s.error = std::string("write: ") + modbus_strerror(errno);
  }
  modbus_close(ctx);
  modbus_free(ctx);
  return s;
}

class StateRamModbusDoor : public ::testing::Test {
 protected:
  StateRamModbusDoor() {
    a.set_holding(0, 0x0A00);
    a.set_holding(1, 0x0A01);
    b.set_holding(0, 0x0B00);
    b.set_holding(1, 0x0B01);
    units[1] = &a;  // rack A primary
    units[129] = &b;
  }
  StateRamModbusHandler make(UnknownUnit unknown) {
    StateRamModbusOptions o;
    o.unknown_unit = unknown;
    return StateRamModbusHandler(
        [this](std::uint8_t u) -> StateRam* {
          auto it = units.find(u);
          return it == units.end() ? nullptr : it->second;
        },
        o);
  }
  void switchover() {
    units[1] = &b;
    units[129] = &a;
  }

  bus::Scheduler sched;
  bus::PacedRunner runner{sched};
  StateRam a{kSizes};
  StateRam b{kSizes};
  std::map<std::uint8_t, StateRam*> units;
};

TEST_F(StateRamModbusDoor, TcpUnits1And129AcrossASwitchover) {
  auto h = make(UnknownUnit::GatewayNoResponse);
  ModbusTcpServer srv(runner.io_context(), h, {"127.0.0.1", 0});
  const int port = srv.port();
  ASSERT_NE(port, 0);
  auto s = test::with_client(runner, [port] {
    return session(modbus_new_tcp("127.0.0.1", port), {1, 129}, 2, 1);
  });
  EXPECT_EQ(s.error, "");
  EXPECT_EQ(s.values, (std::vector<int>{0x0A00, 0x0A01, 0x0B00, 0x0B01}));
  EXPECT_EQ(a.holding(3), 0x0777);  // written to unit 1 = rack A
  EXPECT_EQ(b.holding(3), 0);

  switchover();
  s = test::with_client(runner, [port] {
    return session(modbus_new_tcp("127.0.0.1", port), {1, 129, 9}, 2, 1);
  });
  EXPECT_EQ(s.error, "");
  // Unit 9: nobody -> exception 0x0B, which libmodbus reports as EMBXGTAR.
  EXPECT_EQ(s.values, (std::vector<int>{0x0B00, 0x0B01, 0x0A00, 0x0A01, -EMBXGTAR}));
  EXPECT_EQ(b.holding(3), 0x0777);  // unit 1 is rack B now
  EXPECT_EQ(h.stats().units[1].requests, 4u);
  EXPECT_EQ(h.stats().units[129].requests, 2u);
  EXPECT_EQ(h.stats().exceptions_by_code[0x0B], 1u);
}

TEST_F(StateRamModbusDoor, RtuOnThePtyUnits1And129AcrossASwitchover) {
  auto h = make(UnknownUnit::Silent);
  ModbusRtuPort rtu(runner.io_context(), h);
  const std::string path = rtu.path();
  auto s = test::with_client(runner, [path] {
    return session(modbus_new_rtu(path.c_str(), 115200, 'N', 8, 1), {1, 129}, 2);
  });
  EXPECT_EQ(s.error, "");
  EXPECT_EQ(s.values, (std::vector<int>{0x0A00, 0x0A01, 0x0B00, 0x0B01}));

  switchover();
  s = test::with_client(runner, [path] {
    return session(modbus_new_rtu(path.c_str(), 115200, 'N', 8, 1), {1, 129}, 2, 129);
  });
  EXPECT_EQ(s.error, "");
  EXPECT_EQ(s.values, (std::vector<int>{0x0B00, 0x0B01, 0x0A00, 0x0A01}));
  EXPECT_EQ(a.holding(3), 0x0777);  // written to unit 129 = rack A, now the standby
  EXPECT_EQ(rtu.stats().bad_frames, 0u);
  EXPECT_EQ(rtu.stats().no_reply, 0u);
}

TEST_F(StateRamModbusDoor, RtuUnknownUnitIsNotAnswered) {
  auto h = make(UnknownUnit::Silent);
  ModbusRtuPort rtu(runner.io_context(), h);
  const std::string path = rtu.path();
  // libmodbus waits for an answer that never comes: its error is a time-out (nothing is
  // measured; the 300 ms only bound the wait).
  const int err = test::with_client(runner, [path] {
    modbus_t* ctx = modbus_new_rtu(path.c_str(), 115200, 'N', 8, 1);
    if (ctx == nullptr || modbus_connect(ctx) != 0) return -1;
    modbus_set_response_timeout(ctx, 0, 300000);
    modbus_set_slave(ctx, 9);
    std::uint16_t r[1];
    const int n = modbus_read_registers(ctx, 0, 1, r);
    const int e = n < 0 ? errno : 0;
    modbus_close(ctx);
    modbus_free(ctx);
    return e;
  });
  EXPECT_EQ(err, ETIMEDOUT);
  EXPECT_EQ(h.stats().silent, 1u);
  EXPECT_EQ(rtu.stats().no_reply, 1u);
}

}  // namespace
}  // namespace pbvbus::gateways
