// DP master class 1 on a real line at 1.5 Mbit/s: fdl::ActiveStation + dp::Master, and DP
// slaves made of fdl::PassiveStation + dp::SlaveEngine. Checks the whole start-up on the wire
// against protocol-facts.md Appendix 1, that data exchange carries outputs and inputs within
// one DP cycle, DP-V1 read and alarm acknowledgement end to end, and station failure and return
// after a power cycle.
#include <gtest/gtest.h>

#include <memory>
#include <string>
#include <vector>

#include "frame_recorder.hpp"
#include "pbvbus/bus/line.hpp"
#include "pbvbus/bus/scheduler.hpp"
#include "pbvbus/dp/class2_master.hpp"
#include "pbvbus/dp/master.hpp"
#include "pbvbus/dp/slave_engine.hpp"
#include "pbvbus/fdl/active_station.hpp"
#include "pbvbus/fdl/passive_station.hpp"
#include "pbvbus/fdl/telegram.hpp"

namespace pbvbus::dp {
namespace {

using pbvbus::test::FrameRecorder;
using Bytes = std::vector<std::uint8_t>;

constexpr bus::Baud kBaud = bus::Baud::k1_5M;
constexpr bus::Ticks kBit = bus::ticks_per_bit(kBaud);

/// The frames of the message cycles between master 1 and `slave` (requests to it other than
/// FDL Status, and the replies or SCs that follow them), in order.
std::vector<std::string> dialogue(const FrameRecorder& rec, std::uint8_t slave) {
  std::vector<std::string> out;
  bool ours = false;
  for (std::size_t i = 0; i < rec.size(); ++i) {
    fdl::Telegram t;
    if (fdl::decode(rec.frame(i).bytes, t) != fdl::DecodeError::None) {
      ours = false;
      continue;
    }
    if (t.type == fdl::FrameType::SD4) {
      ours = false;
    } else if (t.is_request()) {
      ours = t.da == slave && t.sa == 1 && fdl::fc_request_fn(t.fc) != fdl::RequestFn::FdlStatus;
      if (ours) out.push_back(rec.hex(i));
    } else {
      if (ours) out.push_back(rec.hex(i));
      ours = false;
    }
  }
  return out;
}

struct Bench {
  bus::Scheduler sched;
  bus::Line line{sched, "dp", kBaud};
  FrameRecorder rec;
  fdl::BusParams bp;
  std::unique_ptr<Master> master;
  std::unique_ptr<fdl::ActiveStation> station;
  std::vector<std::unique_ptr<SlaveEngine>> engines;
  std::vector<std::unique_ptr<fdl::PassiveStation>> slaves;
  std::vector<bus::AttachmentId> slave_att;
  std::vector<MasterEvent> events;

  Bench(MasterParams mp, std::vector<SlaveParams> sp, std::vector<SlaveConfig> sc) {
    bp = fdl::BusParams::defaults(kBaud);
    bp.hsa = 12;
    line.add_tap(rec);
    std::vector<std::uint8_t> addrs;
    for (const auto& p : sp) addrs.push_back(p.address);
    master = std::make_unique<Master>(mp, std::move(sp));
    master->set_event_handler([this](const MasterEvent& e) { events.push_back(e); });
    station = std::make_unique<fdl::ActiveStation>(mp.address, bp, *master);
    line.attach(*station, "master 1");
    for (std::size_t i = 0; i < sc.size(); ++i) {
      engines.push_back(std::make_unique<SlaveEngine>(sc[i]));
      slaves.push_back(std::make_unique<fdl::PassiveStation>(addrs[i], bp, *engines.back()));
      slave_att.push_back(line.attach(*slaves.back(), "slave " + std::to_string(addrs[i])));
    }
    line.start();
  }
  void run_for(bus::Ticks t) { sched.run_until(sched.now() + t); }
  int count(MasterEvent::Kind k) const {
    int n = 0;
    for (const auto& e : events) n += e.kind == k ? 1 : 0;
    return n;
  }
};

SlaveParams params10() {
  SlaveParams p;
  p.address = 10;
  p.ident = 0x1234;
  p.modules = {{{0x10}, "DI 8"}, {{0x20}, "DO 8"}};
  return p;
}
SlaveConfig config10() {
  SlaveConfig c;
  c.ident = 0x1234;
  c.modules = {{{0x10}, "DI 8"}, {{0x20}, "DO 8"}};
  return c;
}
SlaveParams params11() {
  SlaveParams p;
  p.address = 11;
  p.ident = 0x4711;
  p.user_prm = {0x80, 0x20, 0x00};  // DPV1_Enable, diagnostic alarms
  p.modules = {{{0xD1}, "AI 2 words consistent"}, {{0xE1}, "AO 2 words consistent"}};
  return p;
}
SlaveConfig config11() {
  SlaveConfig c;
  c.ident = 0x4711;
  c.features.dpv1 = true;
  c.features.c1_read_write = true;
  c.features.alarms_supported = kEnableDiagnosticAlarm;
  c.min_user_prm_len = 3;
  c.max_user_prm_len = 3;
  c.modules = {{{0xD1}, "AI 2 words consistent"}, {{0xE1}, "AO 2 words consistent"}};
  return c;
}

TEST(DpMasterLine, StartupFramesOnTheWireAndDataExchange) {
  Bench b(MasterParams{}, {params10()}, {config10()});
  b.run_for(20 * bus::kTicksPerMs);
  ASSERT_EQ(b.master->slave_state(10), SlaveStatusState::DataExchange);
  ASSERT_EQ(b.engines[0]->state(), SlaveState::DataExch);

  const auto d = dialogue(b.rec, 10);
  ASSERT_GE(d.size(), 12u);
  // Appendix 1: Slave_Diag (first frame), its SD3 reply, Set_Prm, Chk_Cfg.
  EXPECT_EQ(d[0], "68 05 05 68 8A 81 6D 3C 3E F2 16");
  EXPECT_EQ(d[1], "A2 81 8A 08 3E 3C 02 05 00 FF 12 34 D9 16");
  EXPECT_EQ(d[2], "68 0C 0C 68 8A 81 5D 3D 3E 88 0A 0A 0B 12 34 00 D0 16");
  EXPECT_EQ(d[3], "E5");
  EXPECT_EQ(d[4], "68 07 07 68 8A 81 7D 3E 3E 10 20 34 16");
  EXPECT_EQ(d[5], "E5");
  // Diagnosis after Chk_Cfg: in data exchange with master 1, WD on (81+8A+08+3E+3C+00+0C+00+01
  // +12+34 = 1E0).
  EXPECT_EQ(d[6], "68 05 05 68 8A 81 5D 3C 3E E2 16");
  EXPECT_EQ(d[7], "A2 81 8A 08 3E 3C 00 0C 00 01 12 34 E0 16");
  // Data_Exchange: output 00 (0A+01+7D+00 = 88), input 00 (01+0A+08+00 = 13); then FCB 0.
  EXPECT_EQ(d[8], "68 04 04 68 0A 01 7D 00 88 16");
  EXPECT_EQ(d[9], "68 04 04 68 01 0A 08 00 13 16");
  EXPECT_EQ(d[10], "68 04 04 68 0A 01 5D 00 68 16");
  EXPECT_EQ(d[11], "68 04 04 68 01 0A 08 00 13 16");

  // Global_Control 00 00 from master 1 is on the wire.
  bool gc = false;
  for (std::size_t i = 0; i < b.rec.size(); ++i)
    gc = gc || b.rec.hex(i) == "68 07 07 68 FF 81 46 3A 3E 00 00 3E 16";
  EXPECT_TRUE(gc);

  // Outputs written on the master side reach the slave within one DP cycle, and inputs the
  // other way (plus the telegram's own duration).
  const auto& st = b.master->slave_stats(10);
  ASSERT_GT(st.cycle_count, 5u);
  const bus::Ticks cycle = st.cycle_max;
  const Bytes out{0x42};
  ASSERT_EQ(b.master->image(10).write_outputs(1, out), ImageAccess::Ok);
  const Bytes in{0x99};
  ASSERT_TRUE(b.engines[0]->application().write_inputs(0, in));
  b.run_for(cycle + 200 * kBit);
  Bytes got(1);
  ASSERT_TRUE(b.engines[0]->application().read_outputs(1, got));
  EXPECT_EQ(got, out);
  ASSERT_EQ(b.master->image(10).read_inputs(0, got), ImageAccess::Ok);
  EXPECT_EQ(got, in);
  EXPECT_TRUE(b.master->image(10).data_valid());
  EXPECT_GT(b.master->cycle_median(10), 0);
  EXPECT_EQ(b.count(MasterEvent::Kind::StationFailure), 0);
}

TEST(DpMasterLine, StationFailureAndReturnAfterPowerCycle) {
  Bench b(MasterParams{}, {params10(), params11()}, {config10(), config11()});
  b.run_for(30 * bus::kTicksPerMs);
  ASSERT_EQ(b.master->slave_state(10), SlaveStatusState::DataExchange);
  ASSERT_EQ(b.master->slave_state(11), SlaveStatusState::DataExchange);

  b.line.set_power(b.slave_att[0], false);
  b.run_for(10 * bus::kTicksPerMs);
  EXPECT_EQ(b.master->slave_state(10), SlaveStatusState::NotPresent);
  ASSERT_EQ(b.count(MasterEvent::Kind::StationFailure), 1);
  EXPECT_EQ(b.events.back().slave, 10);
  EXPECT_EQ(b.master->slave_state(11), SlaveStatusState::DataExchange);  // the other one runs on
  Bytes diag(b.master->slave_diag(10).begin(), b.master->slave_diag(10).end());
  EXPECT_EQ(diag, (Bytes{0x01, 0x00, 0x00, 0xFF, 0x12, 0x34}));

  b.line.set_power(b.slave_att[0], true);
  b.run_for(20 * bus::kTicksPerMs);
  EXPECT_EQ(b.master->slave_state(10), SlaveStatusState::DataExchange);
  EXPECT_EQ(b.engines[0]->state(), SlaveState::DataExch);
  EXPECT_EQ(b.count(MasterEvent::Kind::StationReturn), 1);
  EXPECT_EQ(b.master->slave_stats(10).startups, 2u);
}

TEST(DpMasterLine, Dpv1ReadAndAlarmAcknowledgement) {
  Bench b(MasterParams{}, {params11()}, {config11()});
  auto& app = b.engines[0]->application();
  app.on_read(1, 7, [](const RecordCall&, std::span<std::uint8_t> out) {
    out[0] = 0xAB;
    out[1] = 0xCD;
    return RecordResult::ok(2);
  });
  b.run_for(20 * bus::kTicksPerMs);
  ASSERT_EQ(b.master->slave_state(11), SlaveStatusState::DataExchange);

  std::vector<AcyclicResult> results;
  ASSERT_NE(b.master->read(11, 1, 7, 16, [&](const AcyclicResult& r) { results.push_back(r); }), 0u);
  ASSERT_NE(b.master->read(11, 1, 8, 16, [&](const AcyclicResult& r) { results.push_back(r); }), 0u);
  b.run_for(5 * bus::kTicksPerMs);
  ASSERT_EQ(results.size(), 2u);
  EXPECT_EQ(results[0].status, AcyclicStatus::Ok);
  EXPECT_EQ(results[0].data, (Bytes{0xAB, 0xCD}));
  EXPECT_EQ(results[1].status, AcyclicStatus::Negative);
  EXPECT_EQ(results[1].error, (Dpv1Error{0x80, 0xB0, 0x00}));

  std::uint8_t seq = 0xFF;
  ASSERT_EQ(app.raise_alarm(1, 2, AlarmSpec::Appears, false, {}, &seq), AlarmResult::Ok);
  EXPECT_EQ(app.alarms_outstanding(), 1u);
  b.run_for(5 * bus::kTicksPerMs);
  ASSERT_EQ(b.count(MasterEvent::Kind::Alarm), 1);
  EXPECT_EQ(app.alarms_outstanding(), 0u);  // acknowledged by the master
  EXPECT_EQ(b.master->slave_stats(11).alarm_acks, 1u);
  EXPECT_EQ(b.master->slave_stats(11).dh, 1u);
  EXPECT_EQ(b.master->slave_state(11), SlaveStatusState::DataExchange);
}

TEST(DpMasterLine, SyncAndFreezeGroups) {
  SlaveParams p = params10();
  p.station_status |= kPrmSyncReq | kPrmFreezeReq;
  p.group_ident = 0x01;
  SlaveConfig c = config10();
  c.features.sync = true;
  c.features.freeze = true;
  Bench b(MasterParams{}, {p}, {c});
  b.run_for(20 * bus::kTicksPerMs);
  ASSERT_EQ(b.master->slave_state(10), SlaveStatusState::DataExchange);
  auto& app = b.engines[0]->application();
  Bytes got(1);

  // Freeze: the inputs sampled at the command are what the master keeps getting.
  const Bytes in1{0x11}, in2{0x22};
  app.write_inputs(0, in1);
  b.run_for(2 * bus::kTicksPerMs);
  b.master->global_control(kGcFreeze, 0x01);
  b.run_for(2 * bus::kTicksPerMs);
  EXPECT_TRUE(b.engines[0]->freeze_mode());
  app.write_inputs(0, in2);
  b.run_for(2 * bus::kTicksPerMs);
  b.master->image(10).read_inputs(0, got);
  EXPECT_EQ(got, in1);
  b.master->global_control(kGcUnfreeze, 0x01);
  b.run_for(2 * bus::kTicksPerMs);
  b.master->image(10).read_inputs(0, got);
  EXPECT_EQ(got, in2);

  // Sync: outputs are latched at the command and held until the next one.
  const Bytes out1{0x0F}, out2{0xF0};
  b.master->image(10).write_outputs(1, out1);
  b.run_for(2 * bus::kTicksPerMs);
  b.master->global_control(kGcSync, 0x01);
  b.run_for(2 * bus::kTicksPerMs);
  EXPECT_TRUE(b.engines[0]->sync_mode());
  b.master->image(10).write_outputs(1, out2);
  b.run_for(2 * bus::kTicksPerMs);
  app.read_outputs(1, got);
  EXPECT_EQ(got, out1);
  b.master->global_control(kGcSync, 0x01);
  b.run_for(2 * bus::kTicksPerMs);
  app.read_outputs(1, got);
  EXPECT_EQ(got, out2);
  // A command for another group does not reach it.
  b.master->global_control(kGcUnsync, 0x02);
  b.run_for(2 * bus::kTicksPerMs);
  EXPECT_TRUE(b.engines[0]->sync_mode());
  // Sync/Unsync at the start of a pass: "68 07 07 68 FF 81 46 3A 3E 10 02 50 16" went out.
  bool seen = false;
  for (std::size_t i = 0; i < b.rec.size(); ++i)
    seen = seen || b.rec.hex(i) == "68 07 07 68 FF 81 46 3A 3E 10 02 50 16";
  EXPECT_TRUE(seen);
}

TEST(DpMasterLine, Class2MasterNextToAClass1Master) {
  Bench b(MasterParams{}, {params10()}, {config10()});
  Class2Master c2({2, 100});
  fdl::ActiveStation st2(2, b.bp, c2);
  b.line.attach(st2, "master 2 (class 2)");
  b.line.start();
  b.run_for(50 * bus::kTicksPerMs);
  ASSERT_EQ(b.master->slave_state(10), SlaveStatusState::DataExchange);
  ASSERT_TRUE(st2.in_ring());
  const Bytes in{0x5A}, out{0xA5};
  b.engines[0]->application().write_inputs(0, in);
  b.master->image(10).write_outputs(1, out);
  b.run_for(2 * bus::kTicksPerMs);

  std::vector<Class2Result> res;
  auto cb = [&](const Class2Result& r) { res.push_back(r); };
  c2.slave_diag(10, cb);
  c2.get_cfg(10, cb);
  c2.rd_inp(10, cb);
  c2.rd_outp(10, cb);
  b.run_for(10 * bus::kTicksPerMs);
  ASSERT_EQ(res.size(), 4u);
  for (const auto& r : res) EXPECT_EQ(r.status, AcyclicStatus::Ok) << to_string(r.service);
  EXPECT_EQ(res[0].diag.master_add, 1);  // parameterised by master 1
  EXPECT_EQ(res[0].diag.status_1 & kDiagMasterLock, 0);  // Master_Lock is for masters to set
  EXPECT_EQ(res[1].data, (Bytes{0x10, 0x20}));
  EXPECT_EQ(res[2].data, in);
  EXPECT_EQ(res[3].data, out);
  // The class-2 requests disturbed nothing.
  EXPECT_EQ(b.master->slave_state(10), SlaveStatusState::DataExchange);
  EXPECT_EQ(b.count(MasterEvent::Kind::StationFailure), 0);
}

TEST(DpMasterLine, WrongConfigurationShowsCfgFaultAndNeverExchangesData) {
  SlaveParams p = params10();
  p.modules = {{{0x10}, "DI 8"}, {{0x21}, "DO 16 (wrong)"}};
  Bench b(MasterParams{}, {p}, {config10()});
  b.run_for(20 * bus::kTicksPerMs);
  EXPECT_NE(b.master->slave_state(10), SlaveStatusState::DataExchange);
  EXPECT_EQ(b.engines[0]->state(), SlaveState::WaitPrm);
  const auto diag = b.master->slave_diag(10);
  ASSERT_GE(diag.size(), 6u);
  // The last diagnosis read after a Chk_Cfg: Cfg_Fault (plus the identifier block naming
  // module 1), not parameterised.
  EXPECT_NE(diag[0] & kDiagCfgFault, 0);
  EXPECT_EQ(diag[3], 0xFF);
  EXPECT_GT(b.master->slave_stats(10).startups, 3u);  // it keeps trying
  EXPECT_EQ(b.master->slave_stats(10).data_exchanges, 0u);
  EXPECT_EQ(b.count(MasterEvent::Kind::StationFailure), 0);
}

TEST(DpMasterLine, SecondClass1MasterSeesTheSlaveLocked) {
  Bench b(MasterParams{}, {params10()}, {config10()});
  b.run_for(20 * bus::kTicksPerMs);
  ASSERT_EQ(b.master->slave_state(10), SlaveStatusState::DataExchange);
  MasterParams mp2;
  mp2.address = 3;
  Master m3(mp2, {params10()});
  fdl::ActiveStation st3(3, b.bp, m3);
  b.line.attach(st3, "master 3");
  b.line.start();
  b.run_for(60 * bus::kTicksPerMs);
  ASSERT_TRUE(st3.in_ring());
  EXPECT_EQ(m3.slave_state(10), SlaveStatusState::Locked);
  const auto diag = m3.slave_diag(10);
  ASSERT_EQ(diag.size(), 6u);
  EXPECT_EQ(diag[0], kDiagMasterLock);  // set by master 3 itself
  EXPECT_EQ(diag[3], 1);                // owned by master 1
  EXPECT_EQ(m3.slave_stats(10).startups, 0u);  // never tried to parameterise it
  EXPECT_EQ(b.master->slave_state(10), SlaveStatusState::DataExchange);
  EXPECT_EQ(b.engines[0]->master_address(), 1);
}

}  // namespace
}  // namespace pbvbus::dp
