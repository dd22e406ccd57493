// DpMasterSource over a real dp::Master on a bus::Line with a PBVB0A01 slave model (one module
// "16DI/16DO DC24V": 2 octets in, 2 out): the adapter's view before and in data exchange, a
// module write that then appears in the slave's received outputs, the mode command — and the
// same through ModbusGateway (FC04/FC06 golden PDUs).
#include "pbvbus/gateways/dp_master_source.hpp"

#include <gtest/gtest.h>

#include <array>
#include <memory>
#include <string>
#include <vector>

#include "pbvbus/bus/line.hpp"
#include "pbvbus/bus/scheduler.hpp"
#include "pbvbus/gsd/gsd.hpp"
#include "pbvbus/slaves/slave_model.hpp"
#include "pbvbus/fdl/active_station.hpp"
#include "pbvbus/gateways/modbus_gateway.hpp"

namespace pbvbus::gateways {
namespace {

using Bytes = std::vector<std::uint8_t>;
constexpr bus::Baud kBaud = bus::Baud::k1_5M;
constexpr bus::Ticks kMs = bus::kTicksPerMs;
constexpr std::uint8_t kSlave = 4;

struct Bench {
  bus::Scheduler sched;
  bus::Line line{sched, "dp", kBaud};
  fdl::BusParams bp = fdl::BusParams::defaults(kBaud);
  std::unique_ptr<dp::Master> master;
  std::unique_ptr<fdl::ActiveStation> station;
  std::unique_ptr<devices::SlaveModel> slave;

  Bench() {
    bp.hsa = 12;
    auto gsd = devices::load_gsd(std::string(PBVBUS_SOURCE_DIR) + "/examples/gsd/PBVB0A01.gsd");
    EXPECT_TRUE(gsd.ok());
    const std::vector<devices::ModuleChoice> mods{devices::ModuleChoice::named("16DI/16DO DC24V")};
    auto sp = devices::master_slave_params(*gsd.file, mods, kSlave);
    EXPECT_TRUE(sp.ok());
    dp::MasterParams mp;
    mp.address = 1;
    master = std::make_unique<dp::Master>(mp, std::vector<dp::SlaveParams>{*sp.value});
    station = std::make_unique<fdl::ActiveStation>(mp.address, bp, *master);
    line.attach(*station, "master 1");
    devices::SlaveModelOptions so;
    so.address = kSlave;
    so.bus_params = bp;
    auto b = devices::SlaveModel::build(*gsd.file, mods, so);
    EXPECT_TRUE(b.ok());
    slave = std::move(b.model);
    EXPECT_EQ(slave->set_behaviour(0, devices::IoBehaviour::constant_value({0x12, 0x34})), "");
    line.attach(*slave, "slave 4");
  }
  Bytes slave_outputs() {
    Bytes o(2);
    EXPECT_TRUE(slave->application().read_outputs(0, o));
    return o;
  }
};

TEST(DpMasterSource, LayoutNamesAndSides) {
  Bench b;
  DpMasterSource src(*b.master, "dp_master 1 on dp", {{kSlave, "PBVB IO", {"DIO16"}}});
  EXPECT_EQ(src.name(), "dp_master 1 on dp");
  EXPECT_FALSE(src.redundant());
  ASSERT_EQ(src.slaves().size(), 1u);
  const SourceSlave& s = src.slaves()[0];
  EXPECT_EQ(s.address, kSlave);
  EXPECT_EQ(s.name, "PBVB IO");
  EXPECT_EQ(s.ident, b.master->slave_params(kSlave).ident);
  ASSERT_EQ(s.modules.size(), 1u);
  EXPECT_EQ(s.modules[0].name, "DIO16");
  EXPECT_EQ(s.modules[0].in_len, 2u);
  EXPECT_EQ(s.modules[0].out_len, 2u);
  EXPECT_EQ(s.input_len, 2u);
  EXPECT_EQ(s.output_len, 2u);
  EXPECT_FALSE(s.switched);
  EXPECT_EQ(src.status(kSlave, Side::Standby), std::nullopt);
  EXPECT_EQ(src.status(9, Side::Primary), std::nullopt);
  std::array<std::uint8_t, 2> buf{};
  EXPECT_FALSE(src.read_inputs(kSlave, Side::Standby, buf));
  std::array<std::uint8_t, 3> wrong{};
  EXPECT_FALSE(src.read_inputs(kSlave, Side::Primary, wrong));
  EXPECT_EQ(src.master_address(), 1);
  // Unnamed: SlaveParams::name and "module N".
  DpMasterSource plain(*b.master, "x");
  EXPECT_EQ(plain.slaves()[0].name, b.master->slave_params(kSlave).name);
  EXPECT_EQ(plain.slaves()[0].modules[0].name, "module 0");
}

TEST(DpMasterSource, DataExchangeInputsAndAWriteThatReachesTheSlave) {
  Bench b;
  DpMasterSource src(*b.master, "m");
  auto st = src.status(kSlave, Side::Primary);
  ASSERT_TRUE(st.has_value());
  EXPECT_FALSE(st->data_valid);
  EXPECT_NE(st->state, dp::SlaveStatusState::DataExchange);
  b.line.start();
  b.sched.run_until(300 * kMs);
  st = src.status(kSlave, Side::Primary);
  ASSERT_TRUE(st.has_value());
  EXPECT_EQ(st->state, dp::SlaveStatusState::DataExchange);
  EXPECT_TRUE(st->data_valid);
  EXPECT_GT(st->data_exchanges, 0u);
  EXPECT_FALSE(st->diag.empty());
  std::array<std::uint8_t, 2> in{};
  ASSERT_TRUE(src.read_inputs(kSlave, Side::Primary, in));
  EXPECT_EQ(in, (std::array<std::uint8_t, 2>{0x12, 0x34}));
  const Bytes out{0xAB, 0xCD};
  ASSERT_TRUE(src.write_module_outputs(kSlave, 0, out));
  EXPECT_FALSE(src.write_module_outputs(kSlave, 0, Bytes{1}));  // wrong length
  EXPECT_FALSE(src.write_module_outputs(kSlave, 1, out));       // no module 1
  std::array<std::uint8_t, 2> back{};
  ASSERT_TRUE(src.read_outputs(kSlave, Side::Primary, back));
  EXPECT_EQ(back, (std::array<std::uint8_t, 2>{0xAB, 0xCD}));
  b.sched.run_until(350 * kMs);
  EXPECT_EQ(b.slave_outputs(), out);
  EXPECT_EQ(src.counters().station_failures, 0u);
  EXPECT_GT(src.counters().diagnoses, 0u);
}

TEST(DpMasterSource, ModeCommand) {
  Bench b;
  DpMasterSource src(*b.master, "m");
  EXPECT_EQ(src.mode(), dp::MasterMode::Operate);
  EXPECT_FALSE(src.command(dp::MasterMode::Offline));
  EXPECT_EQ(src.mode(), dp::MasterMode::Operate);
  EXPECT_TRUE(src.command(dp::MasterMode::Stop));
  EXPECT_EQ(src.mode(), dp::MasterMode::Stop);
  EXPECT_EQ(b.master->mode(), dp::MasterMode::Stop);
}

TEST(DpMasterSource, ThroughTheModbusGateway) {
  Bench b;
  DpMasterSource src(*b.master, "m");
  ModbusGateway gw(src);
  std::array<std::uint8_t, kModbusMaxPdu> rsp{};
  auto ask = [&](std::uint8_t unit, const Bytes& pdu) {
    const std::size_t n = gw.handle(unit, pdu, rsp, false);
    return Bytes(rsp.begin(), rsp.begin() + static_cast<std::ptrdiff_t>(n));
  };
  // Before the start-up: not in data exchange, stale reaction Exception -> 0x0B.
  EXPECT_EQ(ask(kSlave, Bytes{0x04, 0, 0, 0, 1}), (Bytes{0x84, 0x0B}));
  b.line.start();
  b.sched.run_until(300 * kMs);
  // IR 0 = inputs 12 34, high byte first.
  EXPECT_EQ(ask(kSlave, Bytes{0x04, 0, 0, 0, 1}), (Bytes{0x04, 0x02, 0x12, 0x34}));
  // Status: 4096 state 6 (DataExchange), 4097 flags data valid = 1.
  EXPECT_EQ(ask(kSlave, Bytes{0x04, 0x10, 0x00, 0, 2}), (Bytes{0x04, 0x04, 0, 6, 0, 1}));
  // HR 0 := 0x5566 -> the slave's outputs 55 66 after the next cycles.
  EXPECT_EQ(ask(kSlave, Bytes{0x06, 0, 0, 0x55, 0x66}), (Bytes{0x06, 0, 0, 0x55, 0x66}));
  b.sched.run_until(350 * kMs);
  EXPECT_EQ(b.slave_outputs(), (Bytes{0x55, 0x66}));
  // Gateway unit: live list register 0 has station 4 -> 0x0010; mode Operate = 4.
  EXPECT_EQ(ask(0, Bytes{0x04, 0, 0, 0, 1}), (Bytes{0x04, 0x02, 0x00, 0x10}));
  EXPECT_EQ(ask(0, Bytes{0x06, 0, 0, 0, 2}), (Bytes{0x06, 0, 0, 0, 2}));
  EXPECT_EQ(b.master->mode(), dp::MasterMode::Stop);
}

}  // namespace
}  // namespace pbvbus::gateways
