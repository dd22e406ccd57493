// F3 (I/O module fault), F15 (slave RUN <-> STOP) and OB 122 of the H-system model
// (h_system.hpp block "F3/F15/OB 122"; docs/h-system.md "Interrupts, ...").
//
// Layout: one redundant DP master system at 1.5 Mbit/s; line A: switched station 5 (PBVB0A10:
// 16DI, 16DO), one-sided 20 (PBVB0A02, DP-V0: 8DI, 8DO) and 21 (PBVB0A03, DP-V1 with
// diagnostic/pull/plug alarms: 8DI, 8DO); line B: station 5. I/O map (addresses sorted):
//   5:  16DI IB 0..1, 16DO QB 0..1;  20: 8DI IB 2, 8DO QB 2;  21: 8DI IB 3, 8DO QB 3.
// Program: copy 0 = IB 2 -> QB 2 DIRECT (L PIB 2 / T PQB 2), copy 1 = IB 3 -> QB 3 (image);
// scan time 10 ms. Pair: power_on_both at 12 ms, Redundant at 3.157 s (h_system_fixture.hpp).
// Times of diagnosis OBs: the end of the slave's Slave_Diag response on the wire (the master's
// confirmation), taken from a tap; the alarm OBs the same (the alarm is read in that diagnosis).
#include <gtest/gtest.h>

#include <algorithm>
#include <memory>
#include <string>
#include <vector>

#include "pbvbus/bus/line.hpp"
#include "pbvbus/bus/scheduler.hpp"
#include "pbvbus/bus/tap.hpp"
#include "pbvbus/gsd/gsd.hpp"
#include "pbvbus/s7h/h_system.hpp"
#include "pbvbus/slaves/slave_model.hpp"
#include "pbvbus/switched_io/switched_station.hpp"
#include "pbvbus/dp/prm.hpp"

namespace pbvbus::devices {
namespace {

using Bytes = std::vector<std::uint8_t>;
using Src = HSystemEvent::Source;
constexpr bus::Baud kBaud = bus::Baud::k1_5M;
constexpr bus::Ticks kMs = bus::kTicksPerMs;
constexpr std::uint8_t kSw = 5;
constexpr std::uint8_t kV0 = 20;
constexpr std::uint8_t kV1 = 21;
constexpr bus::Ticks kT0 = 12 * kMs;
constexpr bus::Ticks kRedundant = kT0 + 1000 * kMs + 2000 * kMs + 145 * kMs;  // 3.157 s
constexpr bus::Ticks kUp = kRedundant + 300 * kMs;                             // 3.457 s

GsdFile load(const char* name) {
  auto r = load_gsd(std::string(PBVBUS_SOURCE_DIR) + "/examples/gsd/" + name);
  EXPECT_TRUE(r.ok()) << name;
  return *r.file;
}

/// Slave_Diag responses (SD2, SSAP 60) of the one-sided slaves on line A: time = frame end.
struct DiagTap final : bus::Tap {
  struct Resp {
    bus::Ticks end;
    std::uint8_t station;
    Bytes du;
  };
  std::vector<Resp> seen;
  std::vector<Resp> to_sw;  ///< SD2/SD3 requests to station 5 (DA 0x85): `station` = the DSAP, DU after the SAPs
  std::vector<Resp> from_sw_c1;  ///< SD2 responses of station 5 from SAP 51 to SAP 51 (MSAC_C1 Read/Write): whole frame
  void on_frame(const bus::TapFrame& f) override {
    const auto b = f.bytes;
    if (b.size() >= 11 && b[0] == 0x68 && b[5] == (0x80 | 5) && b[7] == 0x33 && b[8] == 0x33)
      from_sw_c1.push_back({f.end, b[4], Bytes(b.begin(), b.end())});
    if (b.size() >= 11 && b[0] == 0x68 && b[4] == (0x80 | 5) && (b[5] & 0x80) != 0)
      to_sw.push_back({f.end, b[7], Bytes(b.begin() + 9, b.end() - 2)});
    // SD3 (A2 DA SA FC DSAP SSAP DU[6] FCS 16): a request with exactly 6 DU octets, e.g. an
    // MSAC_C1 Write of 2 data octets (5F slot index 02 d0 d1).
    if (b.size() == 14 && b[0] == 0xA2 && b[1] == (0x80 | 5) && (b[2] & 0x80) != 0)
      to_sw.push_back({f.end, b[4], Bytes(b.begin() + 6, b.end() - 2)});
    // SD2 (68 LE LEr 68 DA SA FC DSAP SSAP DU FCS 16), or SD3 for exactly 8 data octets
    // (A2 DA SA FC DSAP SSAP DU[6] FCS 16): a 6-octet diagnosis comes as SD3.
    if (b.size() == 14 && b[0] == 0xA2 && (b[2] & 0x80) != 0 && b[5] == 60) {
      seen.push_back({f.end, static_cast<std::uint8_t>(b[2] & 0x7F), Bytes(b.begin() + 6, b.end() - 2)});
      return;
    }
    if (b.size() < 11 || b[0] != 0x68 || (b[5] & 0x80) == 0 || b[8] != 60) return;
    seen.push_back({f.end, static_cast<std::uint8_t>(b[5] & 0x7F),
                    Bytes(b.begin() + 9, b.end() - 2)});
  }
  /// The first response of `station` after `from` whose DU satisfies `pred`.
  template <class P>
  const Resp* first(std::uint8_t station, bus::Ticks from, P pred) const {
    for (const auto& r : seen)
      if (r.station == station && r.end >= from && pred(r.du)) return &r;
    return nullptr;
  }
};

bool has(const Bytes& du, const Bytes& part) {
  return std::search(du.begin(), du.end(), part.begin(), part.end()) != du.end();
}

struct Fix {
  bus::Scheduler sched;
  bus::Line line[2] = {bus::Line{sched, "A", kBaud}, bus::Line{sched, "B", kBaud}};
  fdl::BusParams bp = fdl::BusParams::defaults(kBaud);
  std::unique_ptr<RedundantMasterSystemModel> sys;
  std::unique_ptr<SwitchedStationModel> sw;
  std::unique_ptr<SlaveModel> v0, v1;
  std::unique_ptr<HSystemModel> h;
  DiagTap tap;

  Fix() {
    bp.hsa = 22;
    const GsdFile swg = load("PBVB0A10.gsd");
    const GsdFile g0 = load("PBVB0A02.gsd");
    const GsdFile g1 = load("PBVB0A03.gsd");
    const std::vector<ModuleChoice> swm{ModuleChoice::named("16DI DC24V"),
                                        ModuleChoice::named("16DO DC24V/0.5A")};
    const std::vector<ModuleChoice> m0{ModuleChoice::named("8DI DC24V"),
                                       ModuleChoice::named("8DO DC24V/0.5A")};
    const std::vector<ModuleChoice> m1{ModuleChoice::named("8DI with process alarm"),
                                       ModuleChoice::named("8DO DC24V/0.5A")};
    std::vector<dp::SlaveParams> cfg[2];
    for (int l = 0; l < 2; ++l) {
      auto sp = master_slave_params(swg, swm, kSw);
      EXPECT_TRUE(sp.ok());
      dp::SlaveParams q = *sp.value;
      q.prm_cmd.assign(8, 0);
      q.user_prm[1] |= dp::kEnablePullPlugAlarm;  // DPV1_Status_2: pull/plug alarms too
      cfg[l].push_back(q);
    }
    for (auto [g, m, a] : {std::tuple{&g0, &m0, kV0}, std::tuple{&g1, &m1, kV1}}) {
      auto sp = master_slave_params(*g, *m, a);
      EXPECT_TRUE(sp.ok()) << int(a);
      dp::SlaveParams q = *sp.value;
      // 21: DPV1_Status_2 enables the diagnostic and pull/plug alarms its GSD supports (the
      // GSD's constant leaves them off).
      if (a == kV1) q.user_prm[1] |= dp::kEnableDiagnosticAlarm | dp::kEnablePullPlugAlarm;
      cfg[0].push_back(q);
    }
    RedundantMasterSystemOptions o;
    o.bus_params = bp;
    sys = std::make_unique<RedundantMasterSystemModel>(
        o, cfg[0], cfg[1], std::vector<redundancy::SwitchedStationRef>{{kSw, 30 * kMs, false}});
    for (int l = 0; l < 2; ++l) sys->attach(l, line[l], "master");
    SwitchedStationOptions so;
    so.address = kSw;
    so.bus_params = bp;
    auto b = SwitchedStationModel::build(swg, swm, so);
    EXPECT_TRUE(b.ok());
    sw = std::move(b.model);
    for (int l = 0; l < 2; ++l) sw->attach(l, line[l]);
    for (auto [g, m, a, out] : {std::tuple{&g0, &m0, kV0, &v0}, std::tuple{&g1, &m1, kV1, &v1}}) {
      SlaveModelOptions s;
      s.address = a;
      s.bus_params = bp;
      auto sb = SlaveModel::build(*g, *m, s);
      EXPECT_TRUE(sb.ok()) << int(a);
      *out = std::move(sb.model);
      line[0].attach(**out, "one-sided");
    }
    EXPECT_EQ(v0->set_behaviour(0, IoBehaviour::constant_value({0x5A})), "");
    EXPECT_EQ(v1->set_behaviour(0, IoBehaviour::constant_value({0x3C})), "");
    line[0].add_tap(tap);
    line[1].add_tap(tap);  // station 5's record write goes over its active channel
    line[0].start();
    line[1].start();
    h = std::make_unique<HSystemModel>(sched, HCpuPairParams{},
                                       std::vector<RedundantMasterSystemModel*>{sys.get()});
    ProgramSpec spec;
    spec.scan_time = 10 * kMs;
    spec.copies = {CopyNetwork{2, 2, 1, true}, CopyNetwork{3, 3, 1, false}};
    h->set_program(spec);
  }
  void at(bus::Ticks t) { sched.run_until(t); }
  void bring_up() {
    at(kT0);
    h->power_on_both();
    at(kUp);
  }
  std::vector<HSystemEvent> obs(int ob, bus::Ticks from = 0) const {
    std::vector<HSystemEvent> out;
    for (const auto& e : h->events())
      if (e.ob == ob && e.time >= from) out.push_back(e);
    return out;
  }
  std::size_t diag_count(int rack, std::uint16_t code) const {
    const auto d = h->diag_buffer(rack);
    return static_cast<std::size_t>(
        std::count_if(d.begin(), d.end(), [&](const DiagEntry& e) { return e.code == code; }));
  }
};

TEST(HF3Model, IoMapAndProgramAsDocumented) {
  Fix f;
  f.bring_up();
  ASSERT_EQ(f.h->pair().system_mode(), SystemMode::Redundant);
  const auto* e20 = f.h->io_map().find(0, kV0, 0);
  ASSERT_NE(e20, nullptr);
  EXPECT_EQ(e20->in_addr, 2u);
  EXPECT_EQ(f.h->io_map().find(0, kV1, 1)->out_addr, 3u);
  // The direct copy moved 20's 0x5A, the image copy 21's 0x3C.
  EXPECT_EQ(f.h->piq()[2], 0x5A);
  EXPECT_EQ(f.h->piq()[3], 0x3C);
  EXPECT_TRUE(f.obs(82).empty());
  EXPECT_TRUE(f.obs(122).empty());
}

TEST(HF3Model, DpV0ChannelDiagnosisIsOb82OnBothCpus) {
  Fix f;
  f.bring_up();
  const bus::Ticks t1 = kUp + 5 * kMs;
  f.at(t1);
  // Module 0 (identifier 0), channel 3, input, bit, line break (6): 80 43 26.
  ASSERT_EQ(f.v0->apply(SlaveFault::channel_diag(0, 3, dp::ChannelError::LineBreak)), "");
  f.at(t1 + 100 * kMs);
  const auto* r = f.tap.first(kV0, t1, [](const Bytes& du) { return has(du, {0x80, 0x43, 0x26}); });
  ASSERT_NE(r, nullptr);
  EXPECT_EQ(r->du[0] & 0x08, 0x08);  // Ext_Diag
  auto ob = f.obs(82);
  ASSERT_EQ(ob.size(), 1u);
  EXPECT_EQ(ob[0].code, 0x3942);
  EXPECT_EQ(ob[0].rack, -1);  // Redundant: both CPUs, synchronously
  EXPECT_EQ(ob[0].time, r->end);
  EXPECT_EQ(ob[0].mdl_addr, 2);  // 20's 8DI: IB 2
  EXPECT_EQ(ob[0].module, 0);
  EXPECT_FALSE(ob[0].mdl_stop);
  EXPECT_TRUE(ob[0].incoming);
  EXPECT_EQ(ob[0].source, Src::Diagnosis);
  EXPECT_EQ(ob[0].station, kV0);
  EXPECT_EQ(f.diag_count(0, 0x3942), 1u);
  EXPECT_EQ(f.diag_count(1, 0x3942), 1u);

  const bus::Ticks t2 = t1 + 200 * kMs;
  f.at(t2);
  ASSERT_EQ(f.v0->apply(SlaveFault::channel_diag(0, 3, dp::ChannelError::LineBreak,
                                                 dp::ChannelType::Bit, dp::ChannelDirection::Input,
                                                 false)),
            "");
  f.at(t2 + 100 * kMs);
  const auto* r2 = f.tap.first(kV0, t2, [](const Bytes& du) { return du.size() == 6; });
  ASSERT_NE(r2, nullptr);
  ob = f.obs(82);
  ASSERT_EQ(ob.size(), 2u);
  EXPECT_EQ(ob[1].code, 0x3842);
  EXPECT_FALSE(ob[1].incoming);
  EXPECT_EQ(ob[1].time, r2->end);
  EXPECT_EQ(ob[1].mdl_addr, 2);
  EXPECT_EQ(f.diag_count(0, 0x3842), 1u);
  EXPECT_EQ(f.diag_count(1, 0x3842), 1u);
}

TEST(HF3Model, DpV1DiagnosticAlarmIsOneOb82NotTwo) {
  Fix f;
  f.bring_up();
  const bus::Ticks t1 = kUp + 5 * kMs;
  f.at(t1);
  SlaveFault c = SlaveFault::channel_diag(0, 1, dp::ChannelError::ShortCircuit);
  c.alarm = true;
  ASSERT_EQ(f.v1->apply(c), "");
  f.at(t1 + 100 * kMs);
  // The diagnosis with the alarm PDU (type 1, slot 1) and the channel block 88 41 21.
  const auto* r = f.tap.first(kV1, t1, [](const Bytes& du) { return has(du, {0x80, 0x41, 0x21}); });
  ASSERT_NE(r, nullptr);
  auto ob = f.obs(82);
  ASSERT_EQ(ob.size(), 1u);  // the alarm's; the diagnosis change adds none
  EXPECT_EQ(ob[0].source, Src::Alarm);
  EXPECT_EQ(ob[0].code, 0x3942);
  EXPECT_EQ(ob[0].rack, -1);
  EXPECT_EQ(ob[0].mdl_addr, 3);  // 21's 8DI: IB 3
  EXPECT_EQ(ob[0].module, 0);
  EXPECT_EQ(ob[0].time, r->end);
  // Both CPUs log it.
  EXPECT_EQ(f.diag_count(0, 0x3942), 1u);
  EXPECT_EQ(f.diag_count(1, 0x3942), 1u);
  c.kind = SlaveFault::Kind::ChannelDiagDisappears;
  ASSERT_EQ(f.v1->apply(c), "");
  f.at(t1 + 300 * kMs);
  ob = f.obs(82);
  ASSERT_EQ(ob.size(), 2u);
  EXPECT_EQ(ob[1].code, 0x3842);
  EXPECT_EQ(ob[1].source, Src::Alarm);
  EXPECT_EQ(ob[1].mdl_addr, 3);
}

TEST(HF15Model, DpV0SlaveStopRunIsOb82WithMdlStop) {
  Fix f;
  f.bring_up();
  const bus::Ticks t1 = kUp + 5 * kMs;
  f.at(t1);
  ASSERT_EQ(f.v0->apply(SlaveFault::slave_stop()), "");
  EXPECT_TRUE(f.v0->stopped());
  f.at(t1 + 100 * kMs);
  // DP-V0: the free-format device block 05 | record 0 = 01 00 04 00 (MDL_STOP: octet 2, bit 2).
  const auto* r = f.tap.first(kV0, t1, [](const Bytes& du) { return du.size() > 6; });
  ASSERT_NE(r, nullptr);
  ASSERT_EQ(r->du.size(), 11u);
  EXPECT_EQ(r->du[0], 0x08);  // Ext_Diag, nothing else
  EXPECT_EQ(Bytes(r->du.begin() + 6, r->du.end()), (Bytes{0x05, 0x01, 0x00, 0x04, 0x00}));
  auto ob = f.obs(82);
  ASSERT_EQ(ob.size(), 1u);
  EXPECT_EQ(ob[0].code, 0x3942);  // EV_CLASS 39
  EXPECT_TRUE(ob[0].mdl_stop);
  EXPECT_EQ(ob[0].module, -1);
  // The slave's diagnostic address (D1/D2, 001 Table 4-8): 16383 the master system, 5 16382,
  // 20 16381.
  EXPECT_EQ(ob[0].mdl_addr, 16381);
  EXPECT_EQ(ob[0].rack, -1);
  EXPECT_EQ(ob[0].time, r->end);
  // The slave stays in data exchange (no OB 86), its inputs read 0: the direct copy sends 0.
  EXPECT_TRUE(f.obs(86).empty());
  EXPECT_EQ(f.h->pii()[2], 0x00);
  EXPECT_EQ(f.h->piq()[2], 0x00);

  const bus::Ticks t2 = t1 + 200 * kMs;
  f.at(t2);
  ASSERT_EQ(f.v0->apply(SlaveFault::slave_run()), "");
  f.at(t2 + 100 * kMs);
  const auto* r2 = f.tap.first(kV0, t2, [](const Bytes& du) { return du.size() == 6; });
  ASSERT_NE(r2, nullptr);
  EXPECT_EQ(r2->du[0], 0x00);
  ob = f.obs(82);
  ASSERT_EQ(ob.size(), 2u);
  EXPECT_EQ(ob[1].code, 0x3842);
  EXPECT_FALSE(ob[1].mdl_stop);
  EXPECT_EQ(ob[1].time, r2->end);
  EXPECT_EQ(f.h->pii()[2], 0x5A);
  EXPECT_EQ(f.diag_count(0, 0x3942), 1u);
  EXPECT_EQ(f.diag_count(1, 0x3842), 1u);
}

TEST(HF15Model, DpV1SlaveStopIsStatusPduWithMdlStop) {
  Fix f;
  f.bring_up();
  const bus::Ticks t1 = kUp + 5 * kMs;
  f.at(t1);
  ASSERT_EQ(f.v1->apply(SlaveFault::slave_stop()), "");
  f.at(t1 + 100 * kMs);
  // Status_Message PDU: 08 81 00 01 (slot 0, "appears") + record 0 = 01 00 04 00.
  const Bytes pdu{0x08, 0x81, 0x00, 0x01, 0x01, 0x00, 0x04, 0x00};
  const auto* r = f.tap.first(kV1, t1, [&](const Bytes& du) { return has(du, pdu); });
  ASSERT_NE(r, nullptr);
  auto ob = f.obs(82);
  ASSERT_EQ(ob.size(), 1u);
  EXPECT_EQ(ob[0].code, 0x3942);
  EXPECT_TRUE(ob[0].mdl_stop);
  EXPECT_EQ(ob[0].mdl_addr, 16380);  // 21's diagnostic address (5 16382, 20 16381, 21 16380)
  EXPECT_EQ(ob[0].time, r->end);
  ASSERT_EQ(f.v1->apply(SlaveFault::slave_run()), "");
  f.at(t1 + 300 * kMs);
  ob = f.obs(82);
  ASSERT_EQ(ob.size(), 2u);
  EXPECT_EQ(ob[1].code, 0x3842);
  EXPECT_FALSE(ob[1].mdl_stop);
}

TEST(HF3Model, SwitchedStationAlarmsOb82AndPullPlugOb83Synchronously) {
  Fix f;
  f.bring_up();
  const bus::Ticks t1 = kUp + 5 * kMs;
  f.at(t1);
  const Bytes ch{0x80, 0x41, 0x21};  // module 0, channel 1, input, bit, short circuit
  ASSERT_EQ(f.sw->raise_alarm(1, 1, dp::AlarmSpec::Appears, false, ch), dp::AlarmResult::Ok);
  f.at(t1 + 100 * kMs);
  auto ob = f.obs(82);
  ASSERT_EQ(ob.size(), 1u);
  EXPECT_EQ(ob[0].code, 0x3942);
  EXPECT_EQ(ob[0].rack, -1);
  EXPECT_EQ(ob[0].mdl_addr, 0);  // station 5's 16DI: IB 0
  EXPECT_EQ(ob[0].station, kSw);

  const bus::Ticks t2 = t1 + 200 * kMs;
  // The configuration's parameter record of the 16DO (record 1, two octets).
  ASSERT_TRUE(f.h->set_module_parameters(0, kSw, 1, 1, {0x12, 0x34}));
  EXPECT_FALSE(f.h->set_module_parameters(0, kSw, 2, 1, {0x12}));  // no module 2
  f.at(t2);
  // Pull of the output module (slot 2): OB 83 W#16#3961 on both CPUs, MDL_ADDR = QB 0 (it has
  // no inputs: its output address).
  ASSERT_EQ(f.sw->raise_alarm(3, 2, dp::AlarmSpec::Appears, false), dp::AlarmResult::Ok);
  f.at(t2 + 100 * kMs);
  auto o83 = f.obs(83);
  ASSERT_EQ(o83.size(), 1u);
  EXPECT_EQ(o83[0].code, 0x3961);
  EXPECT_EQ(o83[0].rack, -1);
  EXPECT_EQ(o83[0].role, CpuRole::Master);
  EXPECT_EQ(o83[0].mdl_addr, 0);
  EXPECT_EQ(o83[0].module, 1);
  EXPECT_EQ(f.diag_count(0, 0x3961), 1u);
  EXPECT_EQ(f.diag_count(1, 0x3961), 1u);
  ASSERT_EQ(f.sw->raise_alarm(4, 2, dp::AlarmSpec::Disappears, false), dp::AlarmResult::Ok);
  f.at(t2 + 300 * kMs);
  o83 = f.obs(83);
  ASSERT_EQ(o83.size(), 2u);
  EXPECT_EQ(o83[1].code, 0x3861);
  EXPECT_FALSE(o83[1].incoming);
  EXPECT_EQ(o83[1].rack, -1);
  // The alarms' acknowledgements (their PDUs leave the diagnosis) raise nothing more.
  f.at(t2 + 1000 * kMs);
  // Re-parameterisation after the plug: the MSAC_C1 Write (slot 2, index 1, 12 34) on the active
  // channel, once (after the plug, not after the pull). On the wire it is an SD3 frame (six DU
  // octets): DSAP 51 (0x33, MSAC_C1), DU = Function_Num 5F, Slot_Number 02, Index 01, Length 02,
  // data 12 34. The station (module_records.hpp) takes it: the positive response `5F 02 01 02`
  // from station 5 to master 1 (SD2: 68 09 09 68 DA=81 SA=85 FC=08 DSAP=33 SSAP=33 DU; FCS =
  // 81+85+08+33+33+5F+02+01+02 = 0x1D8 -> D8) and the record is the module's.
  EXPECT_EQ(f.h->reparameterisations(), 1u);
  std::vector<DiagTap::Resp> writes;
  for (const auto& r : f.tap.to_sw)
    if (r.station == 0x33 && !r.du.empty() && r.du[0] == 0x5F) writes.push_back(r);
  ASSERT_EQ(writes.size(), 1u);
  EXPECT_EQ(writes[0].du, (Bytes{0x5F, 0x02, 0x01, 0x02, 0x12, 0x34}));
  EXPECT_GT(writes[0].end, o83[1].time);  // after the plug's OB 83
  EXPECT_LT(writes[0].end, o83[1].time + 10 * kMs);
  ASSERT_EQ(f.tap.from_sw_c1.size(), 1u);
  EXPECT_EQ(f.tap.from_sw_c1[0].du,
            (Bytes{0x68, 0x09, 0x09, 0x68, 0x81, 0x85, 0x08, 0x33, 0x33, 0x5F, 0x02, 0x01, 0x02,
                   0xD8, 0x16}));
  EXPECT_GT(f.tap.from_sw_c1[0].end, writes[0].end);
  ASSERT_NE(f.sw->module_records(), nullptr);
  EXPECT_EQ(f.sw->module_records()->record(1, 1), (Bytes{0x12, 0x34}));
  EXPECT_EQ(f.sw->module_records()->writes_accepted(), 1u);

  EXPECT_EQ(f.obs(82).size(), 1u);
  EXPECT_EQ(f.obs(83).size(), 2u);
}

TEST(HOb122Model, DirectAccessToFailedStationOncePerNetworkAndScan) {
  Fix f;
  f.bring_up();
  ASSERT_EQ(f.h->piq()[2], 0x5A);
  const bus::Ticks t1 = kUp + 5 * kMs;
  f.at(t1);
  ASSERT_EQ(f.v0->apply(SlaveFault::mute()), "");
  f.at(t1 + 500 * kMs);
  const auto o86 = f.obs(86);
  ASSERT_EQ(o86.size(), 1u);
  EXPECT_EQ(o86[0].code, 0x39C4);
  // D1: the slave's diagnostic address (h_diag_address.hpp): from 16383 (417-4H, 001 Table 4-5)
  // down: the master system 16383, then its slaves by address: 5 -> 16382, 20 -> 16381,
  // 21 -> 16380.
  EXPECT_EQ(o86[0].mdl_addr, 16381);
  EXPECT_EQ(f.h->diag_addresses().master(0), std::optional<std::uint16_t>(16383));
  EXPECT_EQ(f.h->diag_addresses().slave(0, kSw), std::optional<std::uint16_t>(16382));
  EXPECT_EQ(f.h->diag_addresses().slave(0, kV1), std::optional<std::uint16_t>(16380));
  EXPECT_EQ(f.h->diag_addresses().slave(0, 22), std::nullopt);
  f.h->set_diag_address_top(8191);  // a 414-4H
  EXPECT_EQ(f.h->diag_addresses().slave(0, kV0), std::optional<std::uint16_t>(8189));
  f.h->set_diag_address_top(16383);
  const auto o122 = f.obs(122);
  ASSERT_GE(o122.size(), 4u);
  // From the first scan after the failure: one read (2942) and one write (2943) per scan, the
  // scans 10 ms apart (scan_time), never before the 39C4.
  EXPECT_GE(o122[0].time, o86[0].time);
  EXPECT_EQ(o122[0].code, 0x2942);
  EXPECT_EQ(o122[0].mdl_addr, 2);  // PIB 2
  EXPECT_EQ(o122[1].code, 0x2943);
  EXPECT_EQ(o122[1].mdl_addr, 2);  // PQB 2
  EXPECT_EQ(o122[1].time, o122[0].time);
  EXPECT_EQ(o122[2].time, o122[0].time + 10 * kMs);
  EXPECT_EQ(o122[0].rack, -1);
  EXPECT_EQ(o122[0].station, kV0);
  EXPECT_EQ(o122.size() % 2, 0u);
  EXPECT_EQ(f.h->access_errors(), o122.size());
  // The value read is 0 (the image keeps the last value 0x5A for OB 85's sake).
  EXPECT_EQ(f.h->piq()[2], 0x00);
  EXPECT_EQ(f.h->pii()[2], 0x5A);
  // Copy 1 (image access to 21) raises nothing.
  for (const auto& e : o122) EXPECT_EQ(e.station, kV0);
  EXPECT_GE(f.diag_count(0, 0x2942), 2u);
  EXPECT_EQ(f.diag_count(0, 0x2942), f.diag_count(1, 0x2942));
  // Back: no more OB 122.
  ASSERT_EQ(f.v0->apply(SlaveFault::unmute()), "");
  f.at(t1 + 2000 * kMs);
  bool back = false;
  for (const auto& e : f.obs(86))
    if (e.code == 0x38C4) {
      back = true;
      EXPECT_EQ(e.mdl_addr, 16381);  // the return names the same diagnostic address
    }
  EXPECT_TRUE(back);
  const auto n = f.obs(122).size();
  f.at(t1 + 2500 * kMs);
  EXPECT_EQ(f.obs(122).size(), n);
  EXPECT_EQ(f.h->piq()[2], 0x5A);
}

}  // namespace
}  // namespace pbvbus::devices
