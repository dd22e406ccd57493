// The IM 157 links (devices/dp_link): a Y-link at address 5 on a redundant DP master system of
// two 1.5 Mbit/s lines (masters at 1), its coupler's master (1) on a lower line at 1.5 Mbit/s
// with two PBVB0A01 slaves (16DI/16DO, 0x11,0x21) at 3 and 4; and a DP/PA link with its PA line
// at 31.25 kbit/s. Facts and decisions: docs/dp-link.md (000 L1773-L1832, 001 L5558-L5566,
// L8128).
#include <gtest/gtest.h>

#include <algorithm>
#include <memory>
#include <string>
#include <vector>

#include "pbvbus/bus/line.hpp"
#include "pbvbus/bus/scheduler.hpp"
#include "pbvbus/bus/tap.hpp"
#include "pbvbus/dp_link/dp_link.hpp"
#include "pbvbus/fdl/telegram.hpp"
#include "pbvbus/gsd/gsd.hpp"
#include "pbvbus/slaves/slave_model.hpp"
#include "pbvbus/switched_io/redundant_master_system.hpp"

namespace pbvbus::devices {
namespace {

using Bytes = std::vector<std::uint8_t>;
using K = redundancy::SystemEvent::Kind;
constexpr bus::Ticks kMs = bus::kTicksPerMs;
constexpr std::uint8_t kLink = 5;
constexpr std::uint8_t kLowA = 3;  // constant inputs 12 34
constexpr std::uint8_t kLowB = 4;  // echo: inputs = its outputs

GsdFile load(const char* name) {
  auto r = load_gsd(std::string(PBVBUS_SOURCE_DIR) + "/examples/gsd/" + name);
  EXPECT_TRUE(r.ok()) << name;
  return *r.file;
}
std::vector<ModuleChoice> plain() { return {ModuleChoice::named("16DI/16DO DC24V")}; }
/// The PA device (PBVB0A5A): one AI (0x94, 5 in) and one AO (0xA4, 5 out) block.
std::vector<ModuleChoice> pa() {
  return {ModuleChoice::named("AI short"), ModuleChoice::named("AO short")};
}

/// Times of the Data_Exchange requests (SD2, DA = `to`, no SAPs) the lower line carries.
struct DxTimes final : bus::Tap {
  explicit DxTimes(std::uint8_t d) : dst(d) {}
  void on_frame(const bus::TapFrame& f) override {
    const auto& b = f.bytes;
    // SD2 LE LEr SD2 DA SA FC ...: a request to `to` without SAP extension (DA bit 7 clear).
    if (b.size() >= 9 && b[0] == 0x68 && b[4] == dst && (b[6] & 0x40) != 0) at.push_back(f.start);
  }
  std::uint8_t dst;
  std::vector<bus::Ticks> at;
  bus::Ticks max_gap(bus::Ticks from, bus::Ticks until) const {
    bus::Ticks g = 0;
    for (std::size_t i = 1; i < at.size(); ++i)
      if (at[i] > from && at[i - 1] < until) g = std::max(g, at[i] - at[i - 1]);
    return g;
  }
};

struct Rig {
  bus::Scheduler sched;
  bus::Baud upper_baud = bus::Baud::k1_5M;
  bus::Line line[2] = {bus::Line{sched, "A", bus::Baud::k1_5M},
                       bus::Line{sched, "B", bus::Baud::k1_5M}};
  std::unique_ptr<bus::Line> lower;
  std::unique_ptr<DpLink> link;
  std::unique_ptr<RedundantMasterSystemModel> sys;
  std::unique_ptr<SlaveModel> low[2];
  bus::AttachmentId low_att[2] = {-1, -1};
  std::uint16_t counter = 0;
  std::vector<dp::MasterEvent> lower_events;

  std::size_t io = 2;  ///< octets each way per lower station (PA: 5)

  Bytes value(std::uint8_t a, std::uint8_t b) const {
    Bytes v(io, 0);
    v[0] = a;
    v[1] = b;
    return v;
  }

  explicit Rig(DpLinkKind kind = DpLinkKind::YLink) {
    const bool y = kind == DpLinkKind::YLink;
    io = y ? 2 : 5;
    const bus::Baud lb = kind == DpLinkKind::YLink ? bus::Baud::k1_5M : bus::Baud::k31_25;
    lower = std::make_unique<bus::Line>(sched, kind == DpLinkKind::YLink ? "Y" : "PA", lb);
    fdl::BusParams up = fdl::BusParams::defaults(upper_baud);
    up.hsa = 12;
    fdl::BusParams lo = fdl::BusParams::defaults(lb);
    lo.hsa = 6;
    const GsdFile g = load(y ? "PBVB0A01.gsd" : "PBVB0A5A.gsd");
    const std::vector<ModuleChoice> mods = y ? plain() : pa();
    std::vector<dp::SlaveParams> lp;
    for (std::uint8_t a : {kLowA, kLowB}) {
      auto sp = master_slave_params(g, mods, a);
      EXPECT_TRUE(sp.ok());
      lp.push_back(*sp.value);
    }
    DpLinkOptions o;
    o.kind = kind;
    o.address = kLink;
    o.upper_bus_params = up;
    o.lower_bus_params = lo;
    auto b = DpLink::build(o, lp);
    EXPECT_TRUE(b.ok()) << (b.errors.empty() ? "" : b.errors[0]);
    link = std::move(b.link);
    link->set_lower_event_handler([this](const dp::MasterEvent& e) { lower_events.push_back(e); });
    RedundantMasterSystemOptions ro;
    ro.bus_params = up;
    std::vector<dp::SlaveParams> cfg{link->upper_slave_params()};
    sys = std::make_unique<RedundantMasterSystemModel>(
        ro, cfg, cfg,
        std::vector<redundancy::SwitchedStationRef>{{kLink, link->switchover_time(), false}});
    // The program: module 0 (station 3) gets A5 5A, module 1 (station 4) a 16-bit counter.
    sys->set_cycle_hook([this](RedundantMasterSystemModel& m, int, bus::Ticks) {
      ++counter;
      m.system().write_outputs(kLink, 0, value(0xA5, 0x5A));
      m.system().write_outputs(kLink, 1, value(static_cast<std::uint8_t>(counter >> 8),
                                               static_cast<std::uint8_t>(counter)));
    });
    for (int l = 0; l < 2; ++l) sys->attach(l, line[l], "master 1");
    for (int l = 0; l < 2; ++l) link->attach_upper(l, line[l]);
    link->attach_lower(*lower);
    for (int k = 0; k < 2; ++k) {
      SlaveModelOptions so;
      so.address = k == 0 ? kLowA : kLowB;
      so.bus_params = lo;
      auto sb = SlaveModel::build(g, mods, so);
      EXPECT_TRUE(sb.ok());
      low[k] = std::move(sb.model);
      EXPECT_EQ(low[k]->set_behaviour(0, k == 0 ? IoBehaviour::constant_value(value(0x12, 0x34))
                                                : IoBehaviour::echo(y ? 0 : 1)),
                "");
      low_att[k] = lower->attach(*low[k], k == 0 ? "low 3" : "low 4");
    }
    line[0].start();
    line[1].start();
    lower->start();
  }
  void run_until(bus::Ticks t) { sched.run_until(t); }
  redundancy::MasterSystem& ms() { return sys->system(); }
  /// What lower station k's module has received as outputs.
  Bytes low_out(int k) {
    Bytes b(io);
    low[k]->application().read_outputs(io == 2 ? 0 : 1, b);
    return b;
  }
  Bytes upper_inputs() {
    const dp::MasterImage* img = ms().active_image(kLink);
    if (img == nullptr) return {};
    Bytes b(img->input_length());
    img->read_all_inputs(b);
    return b;
  }
};

TEST(DpLinkGsd, ModulesAreTheLowerStationsAndTheSwitchoverTimeIsInTenMs) {
  const std::string t = link_gsd_text(DpLinkKind::YLink,
                                      {{"a @3", {0x11, 0x21}}, {"b @4", {0xD3}}}, 95 * kMs);
  auto g = parse_gsd(t, "y.gsd");
  ASSERT_TRUE(g.ok()) << g.errors[0].to_string();
  EXPECT_EQ(g.file->ident_number(), kYLinkIdent);
  ASSERT_EQ(g.file->modules().size(), 2u);
  EXPECT_EQ(g.file->modules()[0].config, (GsdBytes{0x11, 0x21}));
  EXPECT_EQ(g.file->modules()[1].config, (GsdBytes{0xD3}));
  // 95 ms rounded up to the 10 ms unit: 10 (= 100 ms).
  EXPECT_EQ(g.file->redundancy().slave_max_switch_over_time, 10u);
  EXPECT_TRUE(g.file->redundancy().system_redundancy());
  EXPECT_TRUE(g.file->redundancy().prm_cmd_supp);
}

TEST(DpLinkGsd, LowerBaudRatesByKind) {
  // Y-link: 187.5 kbit/s .. 1.5 Mbit/s (product note 6847578); DP/PA link: 31.25 kbit/s (MBP).
  EXPECT_EQ(check_lower_baud(DpLinkKind::YLink, bus::Baud::k187_5), "");
  EXPECT_EQ(check_lower_baud(DpLinkKind::YLink, bus::Baud::k1_5M), "");
  EXPECT_NE(check_lower_baud(DpLinkKind::YLink, bus::Baud::k93_75), "");
  EXPECT_NE(check_lower_baud(DpLinkKind::YLink, bus::Baud::k3M), "");
  EXPECT_EQ(check_lower_baud(DpLinkKind::DpPaLink, bus::Baud::k31_25), "");
  EXPECT_NE(check_lower_baud(DpLinkKind::DpPaLink, bus::Baud::k45_45), "");
}

TEST(DpLink, BuildRefusesAWrongLowerBaudAndNoStations) {
  DpLinkOptions o;
  o.upper_bus_params = fdl::BusParams::defaults(bus::Baud::k1_5M);
  o.lower_bus_params = fdl::BusParams::defaults(bus::Baud::k12M);
  EXPECT_FALSE(DpLink::build(o, {}).ok());
  EXPECT_EQ(DpLink::build(o, {}).errors.size(), 2u);
}

TEST(DpLink, UpperConfigurationIsTheLowerStationsInOrder) {
  Rig r;
  const dp::SlaveParams p = r.link->upper_slave_params();
  // Chk_Cfg = station 3's 11 21, then station 4's 11 21; Set_Prm carries the 8-octet PrmCmd.
  EXPECT_EQ(p.chk_cfg_du(), (Bytes{0x11, 0x21, 0x11, 0x21}));
  EXPECT_EQ(p.ident, kYLinkIdent);
  EXPECT_EQ(p.prm_cmd.size(), 8u);
  EXPECT_EQ(r.link->module_of(kLowB), std::optional<std::size_t>(1));
  EXPECT_EQ(r.link->module_of(7), std::nullopt);
}

TEST(DpLink, DataPassesBothWays) {
  Rig r;
  r.run_until(400 * kMs);
  // Lower station 3 got A5 5A from module 0; station 4 echoes its outputs (the counter).
  EXPECT_EQ(r.low_out(0), (Bytes{0xA5, 0x5A}));
  const Bytes in = r.upper_inputs();
  ASSERT_EQ(in.size(), 4u);
  EXPECT_EQ(in[0], 0x12);
  EXPECT_EQ(in[1], 0x34);
  const unsigned echoed = (in[2] << 8) | in[3];
  EXPECT_GT(echoed, 0u);
  EXPECT_LE(echoed, r.counter);
  EXPECT_EQ(r.ms().active(kLink), 0);
  EXPECT_EQ(r.link->upper().primary(), 0);
}

TEST(DpLink, UpperSwitchoverLeavesTheLowerLineRunning) {
  Rig r;
  DxTimes dx(kLowA);
  r.lower->add_tap(dx);
  r.run_until(400 * kMs);
  ASSERT_EQ(r.link->upper().primary(), 0);
  const bus::Ticks t0 = r.sched.now();
  r.sys->stop_master(0);  // F14 master system stopped: every station switches to B
  r.run_until(t0 + 600 * kMs);
  EXPECT_EQ(r.ms().active(kLink), 1);
  EXPECT_EQ(r.link->upper().primary(), 1);
  bool switched = false;
  for (const auto& e : r.ms().events())
    if (e.kind == K::Switchover && e.station == kLink && e.time >= t0) switched = true;
  EXPECT_TRUE(switched);
  // The lower line never noticed: no station failure, and the gap between two Data_Exchange
  // requests to station 3 stays within one lower cycle + margin (1.5 Mbit/s, t_bit by hand):
  //   a DX of 2 octets each way: request SD2 9 + 2 = 11 octets x 11 = 121, TSDR <= max_tsdr
  //   150, response 121, Tid1 = 33 + Tsm 4 = 37 -> 429 per slave, 2 slaves 858;
  //   token to itself (SD4, 3 octets) 33 + Tid 37 = 70 -> cycle 928;
  //   margin: one GAP poll (FDL Status SD1 6 octets 66 + TSL 300 + Tid1 37 = 403) and one
  //   Global_Control (SD2 with SAPs, 2 data: 13 octets 143 + Tid2 = max TSDR 150 after an SDN:
  //   293) = 696. Bound 928 + 696 = 1624 t_bit.
  const bus::Ticks tbit = bus::ticks_per_bit(bus::Baud::k1_5M);
  EXPECT_LE(dx.max_gap(t0, t0 + 600 * kMs), 1624 * tbit);
  // ... and the requests were there all along (not a vacuous bound): at least 600 ms / bound.
  const auto n = std::count_if(dx.at.begin(), dx.at.end(), [&](bus::Ticks t) {
    return t >= t0 && t < t0 + 600 * kMs;
  });
  EXPECT_GE(static_cast<bus::Ticks>(n), 600 * kMs / (1624 * tbit));
  for (const auto& e : r.lower_events)
    EXPECT_NE(e.kind, dp::MasterEvent::Kind::StationFailure) << "at " << e.time;
  // Outputs held across the switchover ("no pulses"): station 3 still has A5 5A.
  EXPECT_EQ(r.low_out(0)[0], 0xA5);
}

TEST(DpLink, LowerStationFailureIsTheLinksModuleMissing) {
  Rig r;
  r.run_until(400 * kMs);
  ASSERT_EQ(r.upper_inputs()[0], 0x12);
  r.lower->set_power(r.low_att[0], false);  // station 3 fails
  r.run_until(700 * kMs);
  EXPECT_TRUE(r.link->lower_failed(kLowA));
  EXPECT_FALSE(r.link->lower_failed(kLowB));
  // The link stays in data exchange; its diagnosis shows module 0 (slot 1) missing: the
  // identifier-related block bit 0 and Module_Status 11B for slot 1.
  EXPECT_FALSE(r.ms().station_failed(kLink));
  const auto diag = r.ms().master(0).slave_diag(kLink);
  std::vector<dp::ExtDiagBlock> blocks;
  ASSERT_GT(diag.size(), dp::kStdDiagLen);
  ASSERT_TRUE(dp::split_ext_diag(diag.subspan(dp::kStdDiagLen), blocks));
  bool ident = false, status = false;
  for (const auto& b : blocks) {
    if (b.kind == dp::kBlockIdentifier && b.bytes.size() >= 2) ident = (b.bytes[1] & 0x01) != 0;
    if (b.kind == dp::kBlockDevice && b.bytes.size() >= 5 && b.bytes[1] == dp::kModuleStatus)
      status = (b.bytes[4] & 0x03) == 0x03;
  }
  EXPECT_TRUE(ident);
  EXPECT_TRUE(status);
  const Bytes in = r.upper_inputs();
  EXPECT_EQ(in[0], 0);  // a missing station's inputs read 0
  EXPECT_EQ(in[1], 0);
  r.lower->set_power(r.low_att[0], true);
  r.run_until(1200 * kMs);
  EXPECT_FALSE(r.link->lower_failed(kLowA));
  EXPECT_EQ(r.upper_inputs()[0], 0x12);
}

TEST(DpLink, DpPaLinkPollsItsPaLineAt31k25) {
  Rig r(DpLinkKind::DpPaLink);
  EXPECT_EQ(r.lower->baud(), bus::Baud::k31_25);
  r.run_until(1500 * kMs);
  // Module 0 = PA device 3 (5 in, 5 out), module 1 = device 4: 10 octets each way.
  const Bytes in = r.upper_inputs();
  ASSERT_EQ(in.size(), 10u);
  EXPECT_EQ(in[0], 0x12);
  EXPECT_EQ(in[1], 0x34);
  EXPECT_EQ(r.low_out(0), (Bytes{0xA5, 0x5A, 0, 0, 0}));
  EXPECT_EQ(r.link->upper_slave_params().chk_cfg_du(), (Bytes{0x94, 0xA4, 0x94, 0xA4}));
  EXPECT_EQ(r.link->upper_slave_params().ident, kDpPaLinkIdent);
}

}  // namespace
}  // namespace pbvbus::devices
