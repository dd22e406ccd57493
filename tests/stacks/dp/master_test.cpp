// DP master class 1: start-up and cyclic frames against protocol-facts.md Appendix 1, the
// diagnosis evaluation table, Global_Control cadence, failure/return, Min_Slave_Interval, DH,
// DP-V1 read/write/alarm acknowledgement. Expected frames are written by hand; FCS values are
// worked out in the comments (sum of DA..DU mod 256).
#include <gtest/gtest.h>

#include <algorithm>

#include "master_harness.hpp"
#include "pbvbus/dp/master.hpp"

namespace pbvbus::dp {
namespace {

using test::Bytes;
using test::hex;
using test::MasterDriver;
using fdl::ResponseStatus;
using St = SlaveStatusState;

constexpr std::uint8_t kS = 10;

SlaveParams slave10(std::vector<std::vector<std::uint8_t>> modules = {{0x10}, {0x20}}) {
  SlaveParams p;
  p.address = kS;
  p.ident = 0x1234;
  for (auto& m : modules) p.modules.push_back({m, ""});
  return p;
}

MasterParams master1(MasterMode mode = MasterMode::Operate) {
  MasterParams p;
  p.address = 1;
  p.initial_mode = mode;
  return p;
}

struct Events {
  std::vector<MasterEvent> all;
  std::vector<Bytes> diags;
  void attach(Master& m) {
    m.set_event_handler([this](const MasterEvent& e) {
      all.push_back(e);
      diags.emplace_back(e.diag.begin(), e.diag.end());
    });
  }
  int count(MasterEvent::Kind k) const {
    return static_cast<int>(std::count_if(all.begin(), all.end(),
                                          [k](const MasterEvent& e) { return e.kind == k; }));
  }
};

// Global_Control frames from master 1 (FCS FF+81+46+3A+3E = 0x23E → 3E, plus the two octets).
const std::string kGcOperate = "68 07 07 68 FF 81 46 3A 3E 00 00 3E 16";
const std::string kGcClear = "68 07 07 68 FF 81 46 3A 3E 02 00 40 16";  // Appendix 1

/// Takes the Global_Control that opens a visit when one is due.
void take_gc(MasterDriver& d, const std::string& expected) {
  EXPECT_EQ(d.next(), expected);
  d.confirm_sent();
}

/// Start-up with hand-made answers, one step per token visit; leaves the slave in data exchange.
void bring_up(MasterDriver& d, Master& m) {
  d.token();
  std::string f = d.next();
  if (f.find(" FF 81 46 ") != std::string::npos) {
    d.confirm_sent();
    f = d.next();
  }
  ASSERT_EQ(f, "68 05 05 68 8A 81 6D 3C 3E F2 16");  // Slave_Diag, first frame
  d.confirm_data(ResponseStatus::DL, {0x02, 0x05, 0x00, 0xFF, 0x12, 0x34});
  EXPECT_EQ(d.next(), "");
  d.token();
  ASSERT_NE(d.next().find(" 8A 81 5D 3D 3E "), std::string::npos);  // Set_Prm
  d.confirm_sc();
  EXPECT_EQ(d.next(), "");
  d.token();
  ASSERT_NE(d.next().find(" 8A 81 7D 3E 3E "), std::string::npos);  // Chk_Cfg
  d.confirm_sc();
  EXPECT_EQ(d.next(), "");
  d.token();
  ASSERT_EQ(d.next(), "68 05 05 68 8A 81 5D 3C 3E E2 16");  // Slave_Diag (8A+81+5D+3C+3E = E2)
  d.confirm_data(ResponseStatus::DL, {0x00, 0x0C, 0x00, 0x01, 0x12, 0x34});
  EXPECT_EQ(d.next(), "");
  EXPECT_EQ(m.slave_state(kS), St::DataExchange);
}

// --- Appendix 1 goldens -------------------------------------------------------------------------

TEST(DpMaster, GoldenStartupInClearThenOperate) {
  Master m(master1(MasterMode::Clear), {slave10()});
  Events ev;
  ev.attach(m);
  MasterDriver d(m);
  m.on_power_on(0);
  EXPECT_EQ(m.slave_state(kS), St::Diag);

  d.token();
  EXPECT_EQ(d.next(), kGcClear);
  d.confirm_sent();
  EXPECT_EQ(d.next(), "68 05 05 68 8A 81 6D 3C 3E F2 16");
  d.confirm_data(ResponseStatus::DL, {0x02, 0x05, 0x00, 0xFF, 0x12, 0x34});
  EXPECT_EQ(d.next(), "");  // one start-up step per pass
  EXPECT_EQ(m.slave_state(kS), St::Prm);
  EXPECT_EQ(hex(m.slave_diag(kS)), "02 05 00 FF 12 34");

  d.token();
  EXPECT_EQ(d.next(), "68 0C 0C 68 8A 81 5D 3D 3E 88 0A 0A 0B 12 34 00 D0 16");
  d.confirm_sc();
  EXPECT_EQ(m.slave_state(kS), St::Cfg);
  EXPECT_EQ(d.next(), "");

  d.token();
  EXPECT_EQ(d.next(), "68 07 07 68 8A 81 7D 3E 3E 10 20 34 16");
  d.confirm_sc();
  EXPECT_EQ(m.slave_state(kS), St::CheckDiag);
  EXPECT_EQ(d.next(), "");

  d.token();
  EXPECT_EQ(d.next(), "68 05 05 68 8A 81 5D 3C 3E E2 16");
  d.confirm_data(ResponseStatus::DL, {0x00, 0x0C, 0x00, 0x01, 0x12, 0x34});
  EXPECT_EQ(m.slave_state(kS), St::DataExchange);
  EXPECT_TRUE(m.image(kS).data_valid());
  EXPECT_EQ(d.next(), "");

  // Clear: the output byte goes out as zero even though the user wrote 0x42
  // (FCS 0A+01+7D+00 = 88). The golden reply carries input 0x3C.
  const Bytes out{0x42};
  ASSERT_EQ(m.image(kS).write_outputs(1, out), ImageAccess::Ok);
  d.token();
  EXPECT_EQ(d.next(), "68 04 04 68 0A 01 7D 00 88 16");
  d.confirm_data(ResponseStatus::DL, {0x3C});
  Bytes in(1);
  EXPECT_EQ(m.image(kS).read_inputs(0, in), ImageAccess::Ok);
  EXPECT_EQ(in, Bytes{0x3C});
  EXPECT_EQ(m.image(kS).inputs_generation(), 1u);
  EXPECT_EQ(d.next(), "");

  // Operate: Global_Control 00 00 at once, then the real outputs (0A+01+5D+42 = AA).
  m.set_mode(MasterMode::Operate);
  d.token();
  EXPECT_EQ(d.next(), kGcOperate);
  d.confirm_sent();
  EXPECT_EQ(d.next(), "68 04 04 68 0A 01 5D 42 AA 16");
  d.confirm_data(ResponseStatus::DL, {0x3D});
  EXPECT_EQ(d.next(), "");
  EXPECT_EQ(m.slave_stats(kS).data_exchanges, 2u);
  EXPECT_EQ(m.slave_stats(kS).startups, 1u);
  EXPECT_EQ(ev.count(MasterEvent::Kind::StationFailure), 0);
  EXPECT_EQ(ev.count(MasterEvent::Kind::ModeChange), 1);
  EXPECT_EQ(ev.count(MasterEvent::Kind::Diagnosis), 0);  // start-up reads raise no events
}

TEST(DpMaster, GoldenDataExchangeTwoAndEightOutputBytes) {
  {
    Master m(master1(), {slave10({{0x21}})});  // 2 bytes out
    MasterDriver d(m);
    m.on_power_on(0);
    bring_up(d, m);
    const Bytes out{0xAA, 0x55};
    ASSERT_EQ(m.image(kS).write_outputs(0, out), ImageAccess::Ok);
    d.token();
    EXPECT_EQ(d.next(), "68 05 05 68 0A 01 7D AA 55 87 16");
    d.confirm_sc();  // no inputs: SC
    d.token();
    EXPECT_EQ(d.next(), "68 05 05 68 0A 01 5D AA 55 67 16");  // Appendix 1
    d.confirm_sc();
    EXPECT_EQ(m.slave_state(kS), St::DataExchange);
  }
  {
    Master m(master1(), {slave10({{0x27}})});  // 8 bytes out
    MasterDriver d(m);
    m.on_power_on(0);
    bring_up(d, m);
    const Bytes out{1, 2, 3, 4, 5, 6, 7, 8};
    ASSERT_EQ(m.image(kS).write_outputs(0, out), ImageAccess::Ok);
    d.token();
    EXPECT_EQ(d.next(), "A2 0A 01 7D 01 02 03 04 05 06 07 08 AC 16");  // Appendix 1, SD3
    d.confirm_sc();
  }
}

TEST(DpMaster, SetPrmDpv1Golden) {
  SlaveParams p = slave10();
  p.user_prm = {0x80, 0x00, 0x00};
  EXPECT_TRUE(p.dpv1());
  Master m(master1(), {p});
  MasterDriver d(m);
  m.on_power_on(0);
  d.token();
  take_gc(d, kGcOperate);
  EXPECT_EQ(d.next(), "68 05 05 68 8A 81 6D 3C 3E F2 16");
  d.confirm_data(ResponseStatus::DL, {0x02, 0x05, 0x00, 0xFF, 0x12, 0x34});
  d.token();
  EXPECT_EQ(d.next(), "68 0F 0F 68 8A 81 5D 3D 3E 88 0A 0A 0B 12 34 00 80 00 00 50 16");
}

// --- diagnosis evaluation ------------------------------------------------------------------------

struct DiagCase {
  const char* name;
  Bytes diag;
  St after;
  const char* stored;  ///< stored diagnosis
};

class DiagAfterChkCfg : public ::testing::TestWithParam<DiagCase> {};

TEST_P(DiagAfterChkCfg, Reaction) {
  const DiagCase& c = GetParam();
  Master m(master1(), {slave10()});
  MasterDriver d(m);
  m.on_power_on(0);
  d.token();
  take_gc(d, kGcOperate);
  ASSERT_FALSE(d.next().empty());  // Slave_Diag
  d.confirm_data(ResponseStatus::DL, {0x02, 0x05, 0x00, 0xFF, 0x12, 0x34});
  d.token();
  ASSERT_FALSE(d.next().empty());  // Set_Prm
  d.confirm_sc();
  d.token();
  ASSERT_FALSE(d.next().empty());  // Chk_Cfg
  d.confirm_sc();
  d.token();
  ASSERT_EQ(d.next(), "68 05 05 68 8A 81 5D 3C 3E E2 16");
  d.confirm_data(ResponseStatus::DL, c.diag);
  EXPECT_EQ(m.slave_state(kS), c.after) << c.name;
  EXPECT_EQ(hex(m.slave_diag(kS)), c.stored) << c.name;
  // What the next pass sends follows from the state.
  d.token();
  const std::string f = d.next();
  switch (c.after) {
    case St::DataExchange: EXPECT_EQ(f.substr(0, 14), "68 04 04 68 0A") << c.name; break;
    case St::CheckDiag:
    case St::Diag:
    case St::Locked: EXPECT_EQ(f, "68 05 05 68 8A 81 7D 3C 3E 02 16") << c.name; break;
    default: ADD_FAILURE() << c.name;
  }
}

INSTANTIATE_TEST_SUITE_P(
    Table, DiagAfterChkCfg,
    ::testing::Values(
        DiagCase{"clean", {0x00, 0x0C, 0x00, 0x01, 0x12, 0x34}, St::DataExchange, "00 0C 00 01 12 34"},
        DiagCase{"ext_diag", {0x08, 0x0C, 0x00, 0x01, 0x12, 0x34, 0x03, 0xAA, 0xBB}, St::DataExchange,
                 "08 0C 00 01 12 34 03 AA BB"},
        DiagCase{"not_ready", {0x02, 0x0C, 0x00, 0x01, 0x12, 0x34}, St::CheckDiag, "02 0C 00 01 12 34"},
        DiagCase{"stat_diag", {0x00, 0x0E, 0x00, 0x01, 0x12, 0x34}, St::CheckDiag, "00 0E 00 01 12 34"},
        DiagCase{"cfg_fault", {0x04, 0x05, 0x00, 0xFF, 0x12, 0x34}, St::Diag, "04 05 00 FF 12 34"},
        DiagCase{"prm_fault", {0x40, 0x05, 0x00, 0xFF, 0x12, 0x34}, St::Diag, "40 05 00 FF 12 34"},
        DiagCase{"prm_req", {0x02, 0x05, 0x00, 0xFF, 0x12, 0x34}, St::Diag, "02 05 00 FF 12 34"},
        DiagCase{"not_supported", {0x10, 0x0C, 0x00, 0x01, 0x12, 0x34}, St::Diag, "10 0C 00 01 12 34"},
        DiagCase{"not_ours", {0x00, 0x04, 0x00, 0xFF, 0x12, 0x34}, St::Diag, "00 04 00 FF 12 34"},
        DiagCase{"master_lock", {0x00, 0x0C, 0x00, 0x02, 0x12, 0x34}, St::Locked, "80 0C 00 02 12 34"},
        DiagCase{"always1_missing", {0x00, 0x08, 0x00, 0x01, 0x12, 0x34}, St::Diag,
                 "20 08 00 01 12 34"},
        DiagCase{"too_short", {0x00, 0x0C, 0x00, 0x01, 0x12}, St::Diag, "20 00 00 FF 12 34"}),
    [](const ::testing::TestParamInfo<DiagCase>& i) { return std::string(i.param.name); });

TEST(DpMaster, FirstDiagShowingAnotherMasterLocksAndRetries) {
  Master m(master1(), {slave10()});
  MasterDriver d(m);
  m.on_power_on(0);
  d.token();
  take_gc(d, kGcOperate);
  ASSERT_EQ(d.next(), "68 05 05 68 8A 81 6D 3C 3E F2 16");
  d.confirm_data(ResponseStatus::DL, {0x00, 0x0C, 0x00, 0x05, 0x12, 0x34});
  EXPECT_EQ(m.slave_state(kS), St::Locked);
  EXPECT_EQ(hex(m.slave_diag(kS)), "80 0C 00 05 12 34");
  // Next pass: Slave_Diag again, never Set_Prm while another master owns it.
  d.token();
  ASSERT_EQ(d.next(), "68 05 05 68 8A 81 5D 3C 3E E2 16");
  d.confirm_data(ResponseStatus::DL, {0x02, 0x05, 0x00, 0xFF, 0x12, 0x34});  // released
  EXPECT_EQ(m.slave_state(kS), St::Prm);
}

TEST(DpMaster, SetPrmAnsweredRsRestartsStartup) {
  Master m(master1(), {slave10()});
  MasterDriver d(m);
  m.on_power_on(0);
  d.token();
  take_gc(d, kGcOperate);
  d.next();
  d.confirm_data(ResponseStatus::DL, {0x02, 0x05, 0x00, 0xFF, 0x12, 0x34});
  d.token();
  d.next();
  d.confirm_data(ResponseStatus::RS, {});
  EXPECT_EQ(m.slave_state(kS), St::Diag);
  EXPECT_EQ(m.slave_stats(kS).invalid_responses, 1u);
}

// --- cyclic operation ---------------------------------------------------------------------------

TEST(DpMaster, DhInsertsSlaveDiagAndReportsIt) {
  Master m(master1(), {slave10()});
  Events ev;
  ev.attach(m);
  MasterDriver d(m);
  m.on_power_on(0);
  bring_up(d, m);
  const int diag_events = ev.count(MasterEvent::Kind::Diagnosis);
  d.token();
  EXPECT_EQ(d.next(), "68 04 04 68 0A 01 7D 00 88 16");
  d.confirm_data(ResponseStatus::DH, {0x11});
  // The diagnosis follows in the same visit (FCS 8A+81+5D+3C+3E = E2).
  EXPECT_EQ(d.next(), "68 05 05 68 8A 81 5D 3C 3E E2 16");
  d.confirm_data(ResponseStatus::DL, {0x08, 0x0C, 0x00, 0x01, 0x12, 0x34, 0x03, 0x01, 0x02});
  EXPECT_EQ(d.next(), "");
  EXPECT_EQ(m.slave_state(kS), St::DataExchange);
  EXPECT_EQ(m.slave_stats(kS).dh, 1u);
  ASSERT_EQ(ev.count(MasterEvent::Kind::Diagnosis), diag_events + 1);
  EXPECT_EQ(hex(ev.diags.back()), "08 0C 00 01 12 34 03 01 02");
  Bytes in(1);
  m.image(kS).read_inputs(0, in);
  EXPECT_EQ(in, Bytes{0x11});
}

TEST(DpMaster, DhDiagShowingPrmReqRestartsAndFails) {
  Master m(master1(), {slave10()});
  Events ev;
  ev.attach(m);
  MasterDriver d(m);
  m.on_power_on(0);
  bring_up(d, m);
  d.token();
  d.next();
  d.confirm_data(ResponseStatus::DH, {0x11});
  d.next();
  d.confirm_data(ResponseStatus::DL, {0x02, 0x05, 0x00, 0xFF, 0x12, 0x34});  // watchdog expired
  EXPECT_EQ(m.slave_state(kS), St::Diag);
  EXPECT_FALSE(m.image(kS).data_valid());
  ASSERT_EQ(ev.count(MasterEvent::Kind::StationFailure), 1);
  EXPECT_EQ(ev.all.back().cause, MasterEvent::Cause::LeftDataExchange);
}

TEST(DpMaster, RsInDataExchangeRestartsStartup) {
  Master m(master1(), {slave10()});
  Events ev;
  ev.attach(m);
  MasterDriver d(m);
  m.on_power_on(0);
  bring_up(d, m);
  d.token();
  d.next();
  d.confirm_data(ResponseStatus::RS, {});
  EXPECT_EQ(m.slave_state(kS), St::Diag);
  EXPECT_EQ(ev.count(MasterEvent::Kind::StationFailure), 1);
  // RS is a valid reply, so the FCB toggles: 5D (8A+81+5D+3C+3E = 1E2).
  d.token();
  EXPECT_EQ(d.next(), "68 05 05 68 8A 81 5D 3C 3E E2 16");
}

TEST(DpMaster, WrongInputLengthIsInvalidSlaveResponse) {
  Master m(master1(), {slave10()});
  Events ev;
  ev.attach(m);
  MasterDriver d(m);
  m.on_power_on(0);
  bring_up(d, m);
  d.token();
  d.next();
  d.confirm_data(ResponseStatus::DL, {0x11, 0x22});
  EXPECT_EQ(m.slave_state(kS), St::Diag);
  EXPECT_EQ(m.slave_stats(kS).invalid_responses, 1u);
  EXPECT_EQ(hex(m.slave_diag(kS)), "20 0C 00 01 12 34");
  ASSERT_EQ(ev.count(MasterEvent::Kind::StationFailure), 1);
}

TEST(DpMaster, NoResponseIsStationFailureThenReturnWithReparameterisation) {
  Master m(master1(), {slave10()});
  Events ev;
  ev.attach(m);
  MasterDriver d(m);
  m.on_power_on(0);
  bring_up(d, m);
  d.token();
  d.next();
  d.confirm_none(1);
  EXPECT_EQ(m.slave_state(kS), St::NotPresent);
  EXPECT_EQ(hex(m.slave_diag(kS)), "01 00 00 FF 12 34");
  ASSERT_EQ(ev.count(MasterEvent::Kind::StationFailure), 1);
  EXPECT_EQ(ev.all.back().cause, MasterEvent::Cause::NoResponse);
  EXPECT_EQ(ev.all.back().slave, kS);
  EXPECT_FALSE(m.image(kS).data_valid());
  // Retried with Slave_Diag each pass; the FDL station restarts the FCB (first frame).
  for (int i = 0; i < 3; ++i) {
    d.token();
    ASSERT_EQ(d.next(), "68 05 05 68 8A 81 6D 3C 3E F2 16");
    d.confirm_none(0);
    EXPECT_EQ(d.next(), "");
  }
  EXPECT_EQ(ev.count(MasterEvent::Kind::StationFailure), 1);
  // It is back (after a power cycle): full start-up, then StationReturn.
  d.token();
  ASSERT_EQ(d.next(), "68 05 05 68 8A 81 6D 3C 3E F2 16");
  d.confirm_data(ResponseStatus::DL, {0x02, 0x05, 0x00, 0xFF, 0x12, 0x34});
  d.token();
  EXPECT_EQ(d.next(), "68 0C 0C 68 8A 81 5D 3D 3E 88 0A 0A 0B 12 34 00 D0 16");
  d.confirm_sc();
  d.token();
  EXPECT_EQ(d.next(), "68 07 07 68 8A 81 7D 3E 3E 10 20 34 16");
  d.confirm_sc();
  d.token();
  d.next();
  d.confirm_data(ResponseStatus::DL, {0x00, 0x0C, 0x00, 0x01, 0x12, 0x34});
  EXPECT_EQ(m.slave_state(kS), St::DataExchange);
  ASSERT_EQ(ev.count(MasterEvent::Kind::StationReturn), 1);
  EXPECT_EQ(m.slave_stats(kS).failures, 1u);
  EXPECT_EQ(m.slave_stats(kS).returns, 1u);
  EXPECT_EQ(m.slave_stats(kS).retries, 1u);
  EXPECT_EQ(m.slave_stats(kS).no_response, 4u);
  EXPECT_EQ(to_string(m.slave_state(kS)), "data exchange");
}

TEST(DpMaster, AbsentAtStartIsAFailureOnce) {
  Master m(master1(), {slave10()});
  Events ev;
  ev.attach(m);
  MasterDriver d(m);
  m.on_power_on(0);
  d.token();
  take_gc(d, kGcOperate);
  d.next();
  d.confirm_none();
  EXPECT_EQ(m.slave_state(kS), St::NotPresent);
  EXPECT_EQ(ev.count(MasterEvent::Kind::StationFailure), 1);
}

TEST(DpMaster, FailedRetryInterval) {
  MasterParams mp = master1();
  mp.failed_retry_interval = 10 * bus::kTicksPerMs;
  Master m(mp, {slave10()});
  MasterDriver d(m);
  m.on_power_on(0);
  d.token();
  take_gc(d, kGcOperate);
  d.next();
  d.confirm_none();
  d.now += 5 * bus::kTicksPerMs;
  d.token();
  EXPECT_EQ(d.next(), "");  // not yet
  d.now += 5 * bus::kTicksPerMs;
  d.token();
  EXPECT_EQ(d.next(), "68 05 05 68 8A 81 6D 3C 3E F2 16");
}

TEST(DpMaster, AutoClearOnStationFailure) {
  MasterParams mp = master1();
  mp.auto_clear = true;
  Master m(mp, {slave10()});
  Events ev;
  ev.attach(m);
  MasterDriver d(m);
  m.on_power_on(0);
  bring_up(d, m);
  d.token();
  d.next();
  d.confirm_none();
  EXPECT_EQ(m.mode(), MasterMode::Clear);
  ASSERT_GE(ev.all.size(), 2u);
  EXPECT_EQ(ev.all.back().kind, MasterEvent::Kind::ModeChange);
  EXPECT_EQ(ev.all.back().mode, MasterMode::Clear);
  EXPECT_EQ(d.next(), kGcClear);  // announced at once, still in this token visit
}

TEST(DpMaster, StopSendsNothingAndRestartsStartup) {
  Master m(master1(), {slave10()});
  MasterDriver d(m);
  m.on_power_on(0);
  bring_up(d, m);
  m.set_mode(MasterMode::Stop);
  EXPECT_EQ(m.slave_state(kS), St::Inactive);
  d.token();
  EXPECT_EQ(d.next(), "");
  m.set_mode(MasterMode::Operate);
  d.token();
  EXPECT_EQ(d.next(), kGcOperate);
  d.confirm_sent();
  EXPECT_EQ(d.next(), "68 05 05 68 8A 81 7D 3C 3E 02 16");
}

TEST(DpMaster, FailSafeSlaveGetsNoOutputDataInClear) {
  SlaveParams p = slave10();
  p.fail_safe = true;
  Master m(master1(MasterMode::Clear), {p});
  MasterDriver d(m);
  m.on_power_on(0);
  bring_up(d, m);
  d.token();
  EXPECT_EQ(d.next(), "10 0A 01 7D 88 16");  // SD1: 0A+01+7D = 88
}

TEST(DpMaster, GlobalControlCadenceWithinDataControlTime) {
  MasterParams mp = master1();
  mp.data_control_time = 10;  // 100 ms → announced every 50 ms
  Master m(mp, {slave10()});
  MasterDriver d(m);
  d.step = bus::kTicksPerMs;  // each message cycle (and token pass) 1 ms
  SlaveConfig sc;
  sc.ident = 0x1234;
  sc.modules = {{{0x10}, ""}, {{0x20}, ""}};
  SlaveEngine e(sc);
  d.attach(kS, e);
  m.on_power_on(0);
  std::vector<bus::Ticks> gc_times;
  for (int i = 0; i < 400; ++i) {
    d.token();
    for (;;) {
      const std::string f = d.next();
      if (f.empty()) break;
      if (f == kGcOperate) gc_times.push_back(d.now);
      d.deliver();
      d.now += d.step;
    }
    d.now += d.step;
  }
  ASSERT_GE(gc_times.size(), 5u);
  EXPECT_LE(gc_times.front(), d.step);
  for (std::size_t i = 1; i < gc_times.size(); ++i) {
    const bus::Ticks gap = gc_times[i] - gc_times[i - 1];
    EXPECT_GE(gap, 50 * bus::kTicksPerMs);
    EXPECT_LE(gap, 100 * bus::kTicksPerMs);
  }
  EXPECT_EQ(m.slave_state(kS), St::DataExchange);
  EXPECT_EQ(e.state(), SlaveState::DataExch);  // the watchdog (1 s) never expired
}

TEST(DpMaster, MinSlaveIntervalIsRespected) {
  SlaveParams p = slave10();
  p.min_slave_interval = 50;  // 5 ms
  Master m(master1(), {p});
  MasterDriver d(m);
  d.step = bus::kTicksPerMs / 2;
  SlaveConfig sc;
  sc.ident = 0x1234;
  sc.modules = {{{0x10}, ""}, {{0x20}, ""}};
  SlaveEngine e(sc);
  d.attach(kS, e);
  m.on_power_on(0);
  std::vector<bus::Ticks> times;
  for (int i = 0; i < 300; ++i) {
    d.token();
    for (;;) {
      const std::string f = d.next();
      if (f.empty()) break;
      if (d.req.da == kS && !d.req.dsap.has_value()) times.push_back(d.now);
      d.deliver();
      d.now += d.step;
    }
    d.now += d.step;
  }
  ASSERT_GE(times.size(), 10u);
  for (std::size_t i = 1; i < times.size(); ++i)
    EXPECT_GE(times[i] - times[i - 1], 5 * bus::kTicksPerMs);
  const auto& st = m.slave_stats(kS);
  EXPECT_EQ(st.cycle_count, times.size() - 1);
  EXPECT_GE(st.cycle_min, 5 * bus::kTicksPerMs);
  EXPECT_LE(st.cycle_min, 6 * bus::kTicksPerMs);
  EXPECT_GE(m.cycle_median(kS), st.cycle_min);
  EXPECT_LE(m.cycle_median(kS), st.cycle_max);
}

TEST(DpMaster, SyncFreezeGlobalControlAtPassStart) {
  SlaveParams p = slave10();
  p.station_status |= kPrmSyncReq | kPrmFreezeReq;
  p.group_ident = 0x01;
  Master m(master1(), {p});
  MasterDriver d(m);
  m.on_power_on(0);
  bring_up(d, m);
  m.global_control(kGcSync, 0x01);
  m.global_control(kGcFreeze, 0x01);
  d.token();
  // FF+81+46+3A+3E = 23E; + 20 + 01 = 25F; + 08 + 01 = 247.
  EXPECT_EQ(d.next(), "68 07 07 68 FF 81 46 3A 3E 20 01 5F 16");
  d.confirm_sent();
  EXPECT_EQ(d.next(), "68 07 07 68 FF 81 46 3A 3E 08 01 47 16");
  d.confirm_sent();
  EXPECT_EQ(d.next().substr(0, 14), "68 04 04 68 0A");
  d.confirm_data(ResponseStatus::DL, {0x00});
  EXPECT_EQ(d.next(), "");
  // In Clear the command keeps Clear_Data: 32 01 → 23E + 32 + 01 = 271. Sync and Unsync
  // together are passed as given; the slave lets Unsync win.
  m.set_mode(MasterMode::Clear);
  m.global_control(kGcUnsync | kGcSync, 0x01);
  d.token();
  EXPECT_EQ(d.next(), kGcClear);
  d.confirm_sent();
  EXPECT_EQ(d.next(), "68 07 07 68 FF 81 46 3A 3E 32 01 71 16");
}

// --- DP-V1 ----------------------------------------------------------------------------------------

SlaveParams dpv1_slave() {
  SlaveParams p = slave10();
  p.user_prm = {0x80, 0x20, 0x00};  // DPV1_Enable, diagnostic alarms
  return p;
}

/// Brings a DP-V1 slave up and runs one Data_Exchange (FC 7D), so the next frame to the slave
/// goes with FCB 0 (5D) and the one after with FCB 1 (7D).
void dpv1_up(MasterDriver& d, Master& m) {
  bring_up(d, m);
  d.token();
  ASSERT_EQ(d.next(), "68 04 04 68 0A 01 7D 00 88 16");
  d.confirm_data(ResponseStatus::DL, {0x00});
  EXPECT_EQ(d.next(), "");
}

TEST(DpMaster, Dpv1ReadGoldenAndPositiveResponse) {
  Master m(master1(), {dpv1_slave()});
  MasterDriver d(m);
  m.on_power_on(0);
  dpv1_up(d, m);
  std::vector<AcyclicResult> results;
  const auto id = m.read(kS, 0, 0, 64, [&](const AcyclicResult& r) { results.push_back(r); });
  ASSERT_NE(id, 0u);
  d.token();
  EXPECT_EQ(d.next(), "68 04 04 68 0A 01 5D 00 68 16");  // DX first
  d.confirm_data(ResponseStatus::DL, {0x00});
  EXPECT_EQ(d.next(), "68 09 09 68 8A 81 7D 33 33 5E 00 00 40 8C 16");  // Appendix 1
  d.confirm_data(ResponseStatus::DL, {0x5E, 0x00, 0x00, 0x02, 0xAB, 0xCD});
  ASSERT_EQ(results.size(), 1u);
  EXPECT_EQ(results[0].id, id);
  EXPECT_EQ(results[0].status, AcyclicStatus::Ok);
  EXPECT_EQ(results[0].data, (Bytes{0xAB, 0xCD}));
  EXPECT_EQ(d.next(), "");
}

TEST(DpMaster, Dpv1NegativeReadDecoded) {
  Master m(master1(), {dpv1_slave()});
  MasterDriver d(m);
  m.on_power_on(0);
  dpv1_up(d, m);
  std::vector<AcyclicResult> results;
  m.read(kS, 0, 7, 4, [&](const AcyclicResult& r) { results.push_back(r); });
  d.token();
  d.next();
  d.confirm_data(ResponseStatus::DL, {0x00});
  // 8A+81+7D+33+33+5E+00+07+04 = 257.
  EXPECT_EQ(d.next(), "68 09 09 68 8A 81 7D 33 33 5E 00 07 04 57 16");
  d.confirm_data(ResponseStatus::DL, {0xDE, 0x80, 0xB0, 0x00});
  ASSERT_EQ(results.size(), 1u);
  EXPECT_EQ(results[0].status, AcyclicStatus::Negative);
  EXPECT_EQ(results[0].error, (Dpv1Error{0x80, 0xB0, 0x00}));
  EXPECT_EQ(describe(results[0].error), "DP-V1 access: invalid index (B0), code 2 00");
}

TEST(DpMaster, Dpv1WriteWithPollingAndTimeout) {
  SlaveParams p = dpv1_slave();
  p.c1_response_timeout = 1;  // 10 ms
  Master m(master1(), {p});
  MasterDriver d(m);
  m.on_power_on(0);
  dpv1_up(d, m);
  std::vector<AcyclicResult> results;
  const Bytes rec{0xAA, 0xBB, 0xCC};
  ASSERT_NE(m.write(kS, 1, 2, rec, [&](const AcyclicResult& r) { results.push_back(r); }), 0u);
  d.token();
  d.next();
  d.confirm_data(ResponseStatus::DL, {0x00});
  // 8A+81+7D+33+33+5F+01+02+03+AA+BB+CC = 484.
  EXPECT_EQ(d.next(), "68 0C 0C 68 8A 81 7D 33 33 5F 01 02 03 AA BB CC 84 16");
  d.confirm_sc();  // not ready yet
  EXPECT_EQ(d.next(), "");
  d.now += bus::kTicksPerMs;
  d.token();
  d.next();
  d.confirm_data(ResponseStatus::DL, {0x00});
  // Poll without data: 8A+81+7D+33+33 = 1EE.
  EXPECT_EQ(d.next(), "68 05 05 68 8A 81 7D 33 33 EE 16");
  d.confirm_data(ResponseStatus::DL, {0x5F, 0x01, 0x02, 0x03});
  ASSERT_EQ(results.size(), 1u);
  EXPECT_EQ(results[0].status, AcyclicStatus::Ok);
  EXPECT_EQ(results[0].data, (Bytes{0x5F, 0x01, 0x02, 0x03}));

  // A second write that never completes times out after 10 ms.
  ASSERT_NE(m.write(kS, 1, 2, rec, [&](const AcyclicResult& r) { results.push_back(r); }), 0u);
  for (int i = 0; i < 4; ++i) {
    d.token();
    d.next();
    d.confirm_data(ResponseStatus::DL, {0x00});
    if (d.next().empty()) break;
    d.confirm_sc();
    d.now += 4 * bus::kTicksPerMs;
  }
  ASSERT_EQ(results.size(), 2u);
  EXPECT_EQ(results[1].status, AcyclicStatus::Timeout);
}

TEST(DpMaster, Dpv1RequestsRefusedAndFailedWhenNotInDataExchange) {
  Master m(master1(), {dpv1_slave()});
  MasterDriver d(m);
  m.on_power_on(0);
  EXPECT_EQ(m.read(kS, 0, 0, 4, nullptr), 0u);  // still in start-up
  dpv1_up(d, m);
  EXPECT_EQ(m.read(kS, 0, 0, 0, nullptr), 0u);    // length 0
  EXPECT_EQ(m.read(kS, 0, 0, 241, nullptr), 0u);  // too long
  EXPECT_EQ(m.read(99, 0, 0, 4, nullptr), 0u);    // unknown
  std::vector<AcyclicResult> results;
  ASSERT_NE(m.read(kS, 0, 0, 4, [&](const AcyclicResult& r) { results.push_back(r); }), 0u);
  d.token();
  d.next();
  d.confirm_none();  // the slave is gone
  ASSERT_EQ(results.size(), 1u);
  EXPECT_EQ(results[0].status, AcyclicStatus::NotAvailable);

  Master v0(master1(), {slave10()});
  MasterDriver d0(v0);
  v0.on_power_on(0);
  bring_up(d0, v0);
  EXPECT_EQ(v0.read(kS, 0, 0, 4, nullptr), 0u);  // not a DP-V1 slave
}

TEST(DpMaster, AlarmInDiagnosisIsReportedAndAcknowledged) {
  Master m(master1(), {dpv1_slave()});
  Events ev;
  ev.attach(m);
  MasterDriver d(m);
  m.on_power_on(0);
  dpv1_up(d, m);
  d.token();
  d.next();
  d.confirm_data(ResponseStatus::DH, {0x00});
  ASSERT_EQ(d.next(), "68 05 05 68 8A 81 7D 3C 3E 02 16");
  // Diagnostic alarm, slot 2, Seq_Nr 1, error appears: specifier 0x09; one data octet 0x55.
  d.confirm_data(ResponseStatus::DL, {0x00, 0x0C, 0x00, 0x01, 0x12, 0x34, 0x05, 0x01, 0x02, 0x09, 0x55});
  ASSERT_EQ(ev.count(MasterEvent::Kind::Alarm), 1);
  const auto it = std::find_if(ev.all.begin(), ev.all.end(),
                               [](const MasterEvent& e) { return e.kind == MasterEvent::Kind::Alarm; });
  EXPECT_EQ(it->alarm_type, 1);
  EXPECT_EQ(it->alarm_slot, 2);
  EXPECT_EQ(it->alarm_specifier, 0x09);
  // Alarm_Ack to SAP 50 from SAP 51 in the same visit: 8A+81+5D+32+33+5C+02+01+09 = 235.
  EXPECT_EQ(d.next(), "68 09 09 68 8A 81 5D 32 33 5C 02 01 09 35 16");
  d.confirm_data(ResponseStatus::DL, {0x5C, 0x02, 0x01, 0x09});
  EXPECT_EQ(m.slave_stats(kS).alarm_acks, 1u);
  EXPECT_EQ(m.slave_stats(kS).alarms, 1u);
  // The same alarm seen again (diag read before the ack took effect) is not reported twice.
  d.token();
  d.next();
  d.confirm_data(ResponseStatus::DH, {0x00});
  d.next();
  d.confirm_data(ResponseStatus::DL, {0x00, 0x0C, 0x00, 0x01, 0x12, 0x34, 0x05, 0x01, 0x02, 0x09, 0x55});
  EXPECT_EQ(ev.count(MasterEvent::Kind::Alarm), 1);
}

TEST(DpMaster, ManualAlarmAckNegativeResponse) {
  MasterParams mp = master1();
  mp.auto_alarm_ack = false;
  Master m(mp, {dpv1_slave()});
  MasterDriver d(m);
  m.on_power_on(0);
  dpv1_up(d, m);
  std::vector<AcyclicResult> results;
  ASSERT_NE(m.alarm_ack(kS, 2, 1, 0x09, [&](const AcyclicResult& r) { results.push_back(r); }), 0u);
  d.token();
  d.next();
  d.confirm_data(ResponseStatus::DL, {0x00});
  EXPECT_EQ(d.next(), "68 09 09 68 8A 81 7D 32 33 5C 02 01 09 55 16");  // ... + 20 = 255
  d.confirm_data(ResponseStatus::DL, {0xDC, 0x80, 0xB5, 0x00});
  ASSERT_EQ(results.size(), 1u);
  EXPECT_EQ(results[0].status, AcyclicStatus::Negative);
  EXPECT_EQ(describe(results[0].error), "DP-V1 access: state conflict (B5), code 2 00");
}

// --- configuration checks ----------------------------------------------------------------------

TEST(DpMaster, RejectsBadConfiguration) {
  EXPECT_THROW(Master(master1(), {slave10(), slave10()}), std::invalid_argument);
  SlaveParams p = slave10();
  p.address = 1;
  EXPECT_THROW(Master(master1(), {p}), std::invalid_argument);
  p = slave10();
  p.address = 126;
  EXPECT_THROW(Master(master1(), {p}), std::invalid_argument);
  p = slave10({{0x40}});  // special identifier without its length octet
  EXPECT_THROW(Master(master1(), {p}), std::invalid_argument);
  p = slave10();
  p.wd_fact_1 = 0;
  EXPECT_THROW(Master(master1(), {p}), std::invalid_argument);
  MasterParams mp = master1();
  mp.data_control_time = 0;
  EXPECT_THROW(Master(mp, {slave10()}), std::invalid_argument);
}

TEST(DpMaster, DeactivatedSlaveIsNeverAddressed) {
  SlaveParams p = slave10();
  p.active = false;
  Master m(master1(), {p});
  MasterDriver d(m);
  m.on_power_on(0);
  d.token();
  take_gc(d, kGcOperate);
  EXPECT_EQ(d.next(), "");
  EXPECT_EQ(hex(m.slave_diag(kS)), "00 80 00 FF 12 34");
}

// S7 SFC 12 D_ACT_DP (docs/h-dp-sfc.md): deactivated in data exchange, the slave is no longer
// addressed (only Global_Control goes out), its diagnosis shows Deactivated (octet 2 bit 7,
// "00 80 00 FF 12 34" as for a slave configured inactive), no StationFailure; activated again,
// it runs the whole start-up: Slave_Diag (DSAP 3C), Set_Prm (3D), Chk_Cfg (3E), Slave_Diag.
TEST(DpMaster, SlaveDeactivatedAndActivatedAtRunTime) {
  Master m(master1(), {slave10()});
  Events ev;
  ev.attach(m);
  MasterDriver d(m);
  m.on_power_on(0);
  bring_up(d, m);
  ASSERT_FALSE(m.set_slave_active(11, false));  // no such slave
  ASSERT_TRUE(m.set_slave_active(kS, false));
  EXPECT_EQ(m.slave_state(kS), St::Inactive);
  EXPECT_EQ(hex(m.slave_diag(kS)), "00 80 00 FF 12 34");
  EXPECT_FALSE(m.image(kS).data_valid());
  for (int i = 0; i < 20; ++i) {
    d.token();
    for (std::string f = d.next(); !f.empty(); f = d.next()) {
      EXPECT_NE(f.find(" FF 81 46 3A 3E "), std::string::npos) << f;  // Global_Control only
      d.confirm_sent();
    }
  }
  EXPECT_EQ(ev.count(MasterEvent::Kind::StationFailure), 0);
  const auto startups = m.slave_stats(kS).startups;
  ASSERT_TRUE(m.set_slave_active(kS, true));
  EXPECT_EQ(m.slave_state(kS), St::Diag);
  auto step = [&](const std::string& part) {
    d.token();
    std::string f = d.next();
    if (f.find(" FF 81 46 ") != std::string::npos) {
      d.confirm_sent();
      f = d.next();
    }
    EXPECT_NE(f.find(part), std::string::npos) << f;
  };
  step(" 3C 3E ");  // Slave_Diag
  d.confirm_data(ResponseStatus::DL, {0x02, 0x05, 0x00, 0xFF, 0x12, 0x34});
  step(" 3D 3E 88 ");  // Set_Prm
  d.confirm_sc();
  step(" 3E 3E ");  // Chk_Cfg
  d.confirm_sc();
  step(" 3C 3E ");  // Slave_Diag
  d.confirm_data(ResponseStatus::DL, {0x00, 0x0C, 0x00, 0x01, 0x12, 0x34});
  EXPECT_EQ(m.slave_state(kS), St::DataExchange);
  EXPECT_EQ(m.slave_stats(kS).startups, startups + 1);
  EXPECT_EQ(ev.count(MasterEvent::Kind::StationFailure), 0);
  EXPECT_EQ(ev.count(MasterEvent::Kind::StationReturn), 0);
}

TEST(DpMaster, PollsInConfigurationOrderAndContinuesACutPass) {
  // Configuration order 12, 10, 11 (not address order); no inputs or outputs: SD1 frames.
  std::vector<SlaveParams> ps;
  for (std::uint8_t a : {std::uint8_t{12}, std::uint8_t{10}, std::uint8_t{11}}) {
    SlaveParams p = slave10({{0x00}});  // an empty slot: no data either way
    p.address = a;
    ps.push_back(p);
  }
  Master m(master1(), ps);
  MasterDriver d(m);
  m.on_power_on(0);
  d.token();
  take_gc(d, kGcOperate);
  // Slave_Diag to each, in configuration order: 8C+81+6D+3C+3E = 1F4, 8A.. = 1F2, 8B.. = 1F3.
  EXPECT_EQ(d.next(), "68 05 05 68 8C 81 6D 3C 3E F4 16");
  d.confirm_none(0);
  EXPECT_EQ(d.next(), "68 05 05 68 8A 81 6D 3C 3E F2 16");
  d.confirm_none(0);
  // The token hold time runs out here: the next visit goes on with slave 11, then the pass
  // ends and the following visit starts again with 12.
  d.token_keep();
  EXPECT_EQ(d.next(), "68 05 05 68 8B 81 6D 3C 3E F3 16");
  d.confirm_none(0);
  EXPECT_EQ(d.next(), "");
  d.token();
  EXPECT_EQ(d.next(), "68 05 05 68 8C 81 6D 3C 3E F4 16");
}

}  // namespace
}  // namespace pbvbus::dp
