// RedundantSource over a RedundantMasterSystemModel on two bus::Lines at 1.5 Mbit/s: a switched
// station PBVB0A10 at 5 ("16DI DC24V" 2 in, "16DO DC24V/0.5A" 2 out) on both lines and a
// one-sided PBVB0A01 at 10 on line A. Asserts the adapter's sides (Primary = the active
// channel's line, Standby = the other; one-sided: Primary only), inputs in data exchange, a
// write through the system that reaches the station's backplane, the swap of the sides after
// the active line's master fails, and the Modbus standby unit on top.
#include "pbvbus/gateways/redundant_source.hpp"

#include <gtest/gtest.h>

#include <array>
#include <memory>
#include <string>
#include <vector>

#include "pbvbus/bus/line.hpp"
#include "pbvbus/bus/scheduler.hpp"
#include "pbvbus/gsd/gsd.hpp"
#include "pbvbus/s7h/h_system.hpp"
#include "pbvbus/slaves/slave_model.hpp"
#include "pbvbus/switched_io/switched_station.hpp"
#include "pbvbus/gateways/modbus_gateway.hpp"

namespace pbvbus::gateways {
namespace {

using Bytes = std::vector<std::uint8_t>;
constexpr bus::Baud kBaud = bus::Baud::k1_5M;
constexpr bus::Ticks kMs = bus::kTicksPerMs;
constexpr std::uint8_t kSw = 5;
constexpr std::uint8_t kOne = 10;

devices::GsdFile load(const char* name) {
  auto r = devices::load_gsd(std::string(PBVBUS_SOURCE_DIR) + "/examples/gsd/" + name);
  EXPECT_TRUE(r.ok()) << name;
  return *r.file;
}

struct System {
  bus::Scheduler sched;
  bus::Line line[2] = {bus::Line{sched, "A", kBaud}, bus::Line{sched, "B", kBaud}};
  fdl::BusParams bp = fdl::BusParams::defaults(kBaud);
  std::unique_ptr<devices::RedundantMasterSystemModel> sys;
  std::unique_ptr<devices::SwitchedStationModel> st;
  std::unique_ptr<devices::SlaveModel> one;

  System() {
    bp.hsa = 12;
    const devices::GsdFile sw = load("PBVB0A10.gsd");
    const devices::GsdFile plain = load("PBVB0A01.gsd");
    const std::vector<devices::ModuleChoice> sw_mods{
        devices::ModuleChoice::named("16DI DC24V"),
        devices::ModuleChoice::named("16DO DC24V/0.5A")};
    const std::vector<devices::ModuleChoice> plain_mods{
        devices::ModuleChoice::named("16DI/16DO DC24V")};
    std::vector<dp::SlaveParams> cfg[2];
    for (int l = 0; l < 2; ++l) {
      auto sp = devices::master_slave_params(sw, sw_mods, kSw);
      EXPECT_TRUE(sp.ok());
      dp::SlaveParams p = *sp.value;
      p.prm_cmd.assign(8, 0);  // the MasterSystem writes the block
      cfg[l].push_back(p);
    }
    auto op = devices::master_slave_params(plain, plain_mods, kOne);
    EXPECT_TRUE(op.ok());
    cfg[0].push_back(*op.value);
    devices::RedundantMasterSystemOptions o;
    o.bus_params = bp;
    sys = std::make_unique<devices::RedundantMasterSystemModel>(
        o, cfg[0], cfg[1], std::vector<redundancy::SwitchedStationRef>{{kSw, 30 * kMs, false}});
    for (int l = 0; l < 2; ++l) sys->attach(l, line[l], "master 1");
    devices::SwitchedStationOptions so;
    so.address = kSw;
    so.bus_params = bp;
    auto b = devices::SwitchedStationModel::build(sw, sw_mods, so);
    EXPECT_TRUE(b.ok());
    st = std::move(b.model);
    EXPECT_EQ(st->set_behaviour(0, devices::IoBehaviour::constant_value({0x5A, 0xA5})), "");
    for (int l = 0; l < 2; ++l) st->attach(l, line[l]);
    devices::SlaveModelOptions po;
    po.address = kOne;
    po.bus_params = bp;
    auto pb = devices::SlaveModel::build(plain, plain_mods, po);
    EXPECT_TRUE(pb.ok());
    one = std::move(pb.model);
    line[0].attach(*one, "one-sided");
  }
  void start() {
    line[0].start();
    line[1].start();
  }
};

TEST(RedundantSource, SlavesAndSidesBeforeTheStart) {
  System s;
  RedundantSource src(*s.sys, "redundant 1", {{kSw, "PBVB0A10", {"DI16", "DO16"}}});
  EXPECT_TRUE(src.redundant());
  ASSERT_EQ(src.slaves().size(), 2u);
  EXPECT_EQ(src.slaves()[0].address, kSw);
  EXPECT_TRUE(src.slaves()[0].switched);
  EXPECT_TRUE(src.slaves()[0].outputs_writable);
  EXPECT_EQ(src.slaves()[0].modules[1].name, "DO16");
  EXPECT_EQ(src.slaves()[0].input_len, 2u);
  EXPECT_EQ(src.slaves()[0].output_len, 2u);
  EXPECT_EQ(src.slaves()[1].address, kOne);
  EXPECT_FALSE(src.slaves()[1].switched);
  EXPECT_EQ(src.line_of(kOne, Side::Primary), 0);
  EXPECT_EQ(src.line_of(kOne, Side::Standby), -1);
  EXPECT_EQ(src.status(kOne, Side::Standby), std::nullopt);
  EXPECT_EQ(src.h_status(), std::nullopt);
  EXPECT_EQ(src.master_address(), 1);
}

TEST(RedundantSource, PrimaryIsTheActiveChannelAndSwapsWhenItsMasterFails) {
  System s;
  RedundantSource src(*s.sys, "redundant 1");
  s.start();
  s.sched.run_until(1000 * kMs);
  const int active = s.sys->system().active(kSw);
  ASSERT_GE(active, 0);
  EXPECT_EQ(src.line_of(kSw, Side::Primary), active);
  EXPECT_EQ(src.line_of(kSw, Side::Standby), 1 - active);
  auto p = src.status(kSw, Side::Primary);
  auto sb = src.status(kSw, Side::Standby);
  ASSERT_TRUE(p && sb);
  EXPECT_EQ(p->state, dp::SlaveStatusState::DataExchange);
  EXPECT_TRUE(p->data_valid);
  EXPECT_EQ(p->side_line, active);
  EXPECT_EQ(sb->side_line, 1 - active);
  EXPECT_EQ(p->active_channel, active);
  std::array<std::uint8_t, 2> in{};
  ASSERT_TRUE(src.read_inputs(kSw, Side::Primary, in));
  EXPECT_EQ(in, (std::array<std::uint8_t, 2>{0x5A, 0xA5}));
  auto one = src.status(kOne, Side::Primary);
  ASSERT_TRUE(one);
  EXPECT_EQ(one->state, dp::SlaveStatusState::DataExchange);
  EXPECT_EQ(one->active_channel, -1);

  // A write through the system reaches the station's backplane (module 1 = "16DO").
  ASSERT_TRUE(src.write_module_outputs(kSw, 1, Bytes{0xC3, 0x3C}));
  s.sched.run_until(1100 * kMs);
  const auto bp = s.st->outputs();
  EXPECT_EQ(Bytes(bp.begin(), bp.end()), (Bytes{0xC3, 0x3C}));

  // The active line's master fails: the station switches over, the sides follow.
  s.sys->fail_master(active);
  s.sched.run_until(2500 * kMs);
  EXPECT_EQ(s.sys->system().active(kSw), 1 - active);
  EXPECT_EQ(src.line_of(kSw, Side::Primary), 1 - active);
  p = src.status(kSw, Side::Primary);
  ASSERT_TRUE(p);
  EXPECT_EQ(p->side_line, 1 - active);
  EXPECT_TRUE(p->data_valid);
  EXPECT_TRUE(p->redundancy_lost);
  EXPECT_GE(src.counters().switchovers, 1u);
}

TEST(RedundantSource, CommandGoesToBothMasters) {
  System s;
  RedundantSource src(*s.sys, "redundant 1");
  EXPECT_FALSE(src.command(dp::MasterMode::Offline));
  EXPECT_TRUE(src.command(dp::MasterMode::Clear));
  EXPECT_EQ(s.sys->master(0).mode(), dp::MasterMode::Clear);
  EXPECT_EQ(s.sys->master(1).mode(), dp::MasterMode::Clear);
  EXPECT_EQ(src.mode(), dp::MasterMode::Clear);
}

TEST(RedundantSource, StandbyUnitThroughTheModbusGateway) {
  System s;
  RedundantSource src(*s.sys, "redundant 1");
  ModbusGatewayOptions opt;
  opt.standby_units = true;
  ModbusGateway gw(src, opt);
  std::array<std::uint8_t, kModbusMaxPdu> rsp{};
  auto ask = [&](std::uint8_t unit, const Bytes& pdu) {
    const std::size_t n = gw.handle(unit, pdu, rsp, false);
    return Bytes(rsp.begin(), rsp.begin() + static_cast<std::ptrdiff_t>(n));
  };
  s.start();
  s.sched.run_until(1000 * kMs);
  // Unit 5: inputs 5A A5 in IR 0. Unit 5 + 128 = 133: the standby view, flags with bit 8.
  EXPECT_EQ(ask(kSw, Bytes{0x04, 0, 0, 0, 1}), (Bytes{0x04, 0x02, 0x5A, 0xA5}));
  const auto flags = ask(133, Bytes{0x04, 0x10, 0x01, 0, 1});
  ASSERT_EQ(flags.size(), 4u);
  EXPECT_EQ(flags[2] & 0x01, 0x01);  // bit 8 standby view (high byte bit 0)
  EXPECT_EQ(flags[3] & 0x20, 0x20);  // bit 5 switched
  // Standby is read-only; the one-sided slave has no standby unit.
  EXPECT_EQ(ask(133, Bytes{0x06, 0, 0, 0, 1}), (Bytes{0x86, 0x01}));
  EXPECT_EQ(ask(138, Bytes{0x04, 0, 0, 0, 1}), (Bytes{0x84, 0x0A}));
}

TEST(RedundantSource, DrivenByAnHSystemIsReadOnlyAndReportsTheCpuPair) {
  System s;
  devices::HSystemModel h(s.sched, devices::HCpuPairParams{},
                          std::vector<devices::RedundantMasterSystemModel*>{s.sys.get()});
  RedundantSource src(*s.sys, "H system", {}, &h);
  for (const auto& sl : src.slaves()) EXPECT_FALSE(sl.outputs_writable);
  EXPECT_FALSE(src.write_module_outputs(kSw, 1, Bytes{1, 2}));
  EXPECT_FALSE(src.command(dp::MasterMode::Stop));
  auto hs = src.h_status();
  ASSERT_TRUE(hs.has_value());
  EXPECT_EQ(hs->master_rack, -1);  // both CPUs off
  h.power_on_both();
  s.start();
  s.sched.run_until(6000 * kMs);
  hs = src.h_status();
  ASSERT_TRUE(hs.has_value());
  ASSERT_GE(hs->master_rack, 0);
  EXPECT_EQ(hs->master_rack, h.pair().master());
  EXPECT_EQ(hs->cpu_role[static_cast<std::size_t>(hs->master_rack)],
            static_cast<std::uint8_t>(devices::CpuRole::Master));
  EXPECT_EQ(hs->system_mode, static_cast<std::uint8_t>(h.pair().system_mode()));
  EXPECT_EQ(src.master_address(), s.sys->master(hs->master_rack).address());
  // Through the gateway: unit 0 IR 32 = 1 (H present), IR 38 = the master rack; a write to a
  // slave is 0x01 (read-only), the mode command 0x04 (refused).
  ModbusGateway gw(src);
  std::array<std::uint8_t, kModbusMaxPdu> rsp{};
  auto ask = [&](std::uint8_t unit, const Bytes& pdu) {
    const std::size_t n = gw.handle(unit, pdu, rsp, false);
    return Bytes(rsp.begin(), rsp.begin() + static_cast<std::ptrdiff_t>(n));
  };
  EXPECT_EQ(ask(0, Bytes{0x04, 0, 32, 0, 1}), (Bytes{0x04, 0x02, 0x00, 0x01}));
  EXPECT_EQ(ask(0, Bytes{0x04, 0, 38, 0, 1}),
            (Bytes{0x04, 0x02, 0x00, static_cast<std::uint8_t>(hs->master_rack)}));
  EXPECT_EQ(ask(kSw, Bytes{0x06, 0, 0, 0, 1}), (Bytes{0x86, 0x01}));
  EXPECT_EQ(ask(0, Bytes{0x06, 0, 0, 0, 2}), (Bytes{0x86, 0x04}));
}

}  // namespace
}  // namespace pbvbus::gateways
