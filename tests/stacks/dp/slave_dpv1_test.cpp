// DP-V1 slave: DPV1_Status checks, MSAC_C1 read/write (direct and polled), alarms, module
// status, MSAC_C2 connections. Expected octets by hand from protocol-facts.md §D.2, §D.5, §E.
#include <gtest/gtest.h>

#include <utility>
#include <vector>

#include "pbvbus/dp/slave_engine.hpp"
#include "slave_harness.hpp"

namespace pbvbus::dp {
namespace {

using test::Bytes;
using test::Harness;
using test::hex;
using K = fdl::Reply::Kind;
using fdl::ResponseStatus;

constexpr std::uint8_t kM1 = 1;
constexpr std::uint8_t kM2 = 2;
constexpr std::uint8_t kS = 10;

SlaveConfig dpv1_config() {
  SlaveConfig c;
  c.ident = 0x1234;
  c.modules = {{{0x10}, "in"}, {{0x20}, "out"}};
  c.features.dpv1 = true;
  c.features.c1_read_write = true;
  c.features.alarms_supported = kEnableDiagnosticAlarm | kEnableProcessAlarm;
  c.features.max_alarm_mode = 2;
  c.features.wd_base_1ms = true;
  c.min_user_prm_len = 3;
  c.max_user_prm_len = 3;
  return c;
}

Bytes prm(std::uint8_t s1, std::uint8_t s2, std::uint8_t s3) {
  return {0x88, 0x0A, 0x0A, 0x0B, 0x12, 0x34, 0x00, s1, s2, s3};
}

void start(Harness& h, const Bytes& p) {
  ASSERT_EQ(h.req(kM1, kS, kSapSetPrm, p), Bytes{0xE5});
  ASSERT_EQ(h.req(kM1, kS, kSapChkCfg, {0x10, 0x20}), Bytes{0xE5});
}

TEST(SlaveDpv1, GoldenSetPrmAndC1Read) {
  SlaveEngine e(dpv1_config());
  e.application().on_read(0, 0, [](const RecordCall& call, std::span<std::uint8_t> out) {
    EXPECT_EQ(call.master, kM1);
    EXPECT_FALSE(call.c2);
    EXPECT_EQ(out.size(), 64u);
    out[0] = 0xAB;
    out[1] = 0xCD;
    return RecordResult::ok(2);
  });
  Harness h(e);
  // Appendix 1: Set_Prm DP-V1 (DPV1_Status 80 00 00), then Chk_Cfg 10 20.
  EXPECT_EQ(hex(h.frame({0x68, 0x0F, 0x0F, 0x68, 0x8A, 0x81, 0x5D, 0x3D, 0x3E, 0x88, 0x0A, 0x0A,
                         0x0B, 0x12, 0x34, 0x00, 0x80, 0x00, 0x00, 0x50, 0x16})),
            "E5");
  EXPECT_TRUE(e.dpv1_status().dpv1_enable());
  EXPECT_EQ(hex(h.frame({0x68, 0x07, 0x07, 0x68, 0x8A, 0x81, 0x7D, 0x3E, 0x3E, 0x10, 0x20, 0x34,
                         0x16})),
            "E5");
  // Appendix 1: C1 Read slot 0 index 0 length 64; reply with 2 bytes AB CD as SD3.
  EXPECT_EQ(hex(h.frame({0x68, 0x09, 0x09, 0x68, 0x8A, 0x81, 0x7D, 0x33, 0x33, 0x5E, 0x00, 0x00,
                         0x40, 0x8C, 0x16})),
            "A2 81 8A 08 33 33 5E 00 00 02 AB CD 51 16");
}

TEST(SlaveDpv1, GoldenInvalidIndex) {
  SlaveEngine e(dpv1_config());
  Harness h(e);
  start(h, prm(0x80, 0x00, 0x00));
  EXPECT_EQ(hex(h.frame({0x68, 0x09, 0x09, 0x68, 0x8A, 0x81, 0x7D, 0x33, 0x33, 0x5E, 0x00, 0x00,
                         0x40, 0x8C, 0x16})),
            "68 09 09 68 81 8A 08 33 33 DE 80 B0 00 87 16");
}

TEST(SlaveDpv1, C1WriteAndErrors) {
  SlaveEngine e(dpv1_config());
  Bytes written;
  e.application().on_write(1, 2, [&](const RecordCall&, std::span<const std::uint8_t> d) {
    if (d.size() != 2) return RecordResult::fail(dpv1_err::kWriteLengthError);
    written.assign(d.begin(), d.end());
    return RecordResult::ok();
  });
  Harness h(e);
  start(h, prm(0x80, 0x00, 0x00));
  EXPECT_EQ(h.du(kM1, kS, kSapC1ReadWrite, {0x5F, 0x01, 0x02, 0x02, 0x11, 0x22}),
            (Bytes{0x5F, 0x01, 0x02, 0x02}));
  EXPECT_EQ(written, (Bytes{0x11, 0x22}));
  // The handler refuses the length.
  EXPECT_EQ(h.du(kM1, kS, kSapC1ReadWrite, {0x5F, 0x01, 0x02, 0x01, 0x33}),
            (Bytes{0xDF, 0x80, 0xB1, 0x00}));
  // Length octet does not match the data.
  EXPECT_EQ(h.du(kM1, kS, kSapC1ReadWrite, {0x5F, 0x01, 0x02, 0x03, 0x11, 0x22}),
            (Bytes{0xDF, 0x80, 0xB1, 0x00}));
  // Slot 5 does not exist (2 modules): invalid slot.
  EXPECT_EQ(h.du(kM1, kS, kSapC1ReadWrite, {0x5E, 0x05, 0x00, 0x04}),
            (Bytes{0xDE, 0x80, 0xB2, 0x00}));
  // Read of length 0 is an invalid parameter.
  EXPECT_EQ(h.du(kM1, kS, kSapC1ReadWrite, {0x5E, 0x01, 0x02, 0x00}),
            (Bytes{0xDE, 0x80, 0xB8, 0x00}));
  // Unknown function number.
  EXPECT_EQ(h.du(kM1, kS, kSapC1ReadWrite, {0x5A, 0x00, 0x00, 0x00}),
            (Bytes{0xDA, 0x80, 0xA9, 0x00}));
  // Another master may not use MSAC_C1.
  h.req(kM2, kS, kSapC1ReadWrite, {0x5E, 0x01, 0x02, 0x04});
  EXPECT_EQ(h.last.status, ResponseStatus::RS);
}

TEST(SlaveDpv1, C1WriteAnyTakesWritesWithoutAHandlerOfTheirOwn) {
  SlaveEngine e(dpv1_config());
  std::vector<std::pair<int, int>> any;  // (slot, index) the fallback saw
  e.application().on_write(1, 2, [&](const RecordCall&, std::span<const std::uint8_t>) {
    return RecordResult::ok();
  });
  e.application().on_write_any([&](const RecordCall& c, std::span<const std::uint8_t>) {
    any.emplace_back(c.slot, c.index);
    return c.slot == 2 ? RecordResult::ok() : RecordResult::fail(dpv1_err::kInvalidSlot);
  });
  Harness h(e);
  start(h, prm(0x80, 0x00, 0x00));
  // (1, 2) has its own handler; (2, 7) and (9, 1) go to the fallback.
  EXPECT_EQ(h.du(kM1, kS, kSapC1ReadWrite, {0x5F, 0x01, 0x02, 0x01, 0x11}),
            (Bytes{0x5F, 0x01, 0x02, 0x01}));
  EXPECT_EQ(h.du(kM1, kS, kSapC1ReadWrite, {0x5F, 0x02, 0x07, 0x01, 0x11}),
            (Bytes{0x5F, 0x02, 0x07, 0x01}));
  EXPECT_EQ(h.du(kM1, kS, kSapC1ReadWrite, {0x5F, 0x09, 0x01, 0x01, 0x11}),
            (Bytes{0xDF, 0x80, 0xB2, 0x00}));
  EXPECT_EQ(any, (std::vector<std::pair<int, int>>{{2, 7}, {9, 1}}));
  // Reads never reach it: still "invalid index".
  EXPECT_EQ(h.du(kM1, kS, kSapC1ReadWrite, {0x5E, 0x02, 0x07, 0x04}),
            (Bytes{0xDE, 0x80, 0xB0, 0x00}));
}

TEST(SlaveDpv1, C1PendingAnswerGoesOutOnPoll) {
  SlaveEngine e(dpv1_config());
  std::uint32_t id = 0;
  e.application().on_read(0, 5, [&](const RecordCall& call, std::span<std::uint8_t>) {
    id = call.id;
    return RecordResult::pending();
  });
  Harness h(e);
  start(h, prm(0x80, 0x00, 0x00));
  EXPECT_EQ(h.req(kM1, kS, kSapC1ReadWrite, {0x5E, 0x00, 0x05, 0x10}), Bytes{0xE5});
  ASSERT_NE(id, 0u);
  EXPECT_EQ(h.req(kM1, kS, kSapC1ReadWrite, {}), Bytes{0xE5});  // poll: not ready
  e.application().complete_read(id, Bytes{0x01, 0x02, 0x03});
  // Poll frame (LE 5: SAPs only); the reply carries the Read.res.
  EXPECT_EQ(h.du(kM1, kS, kSapC1ReadWrite, {}), (Bytes{0x5E, 0x00, 0x05, 0x03, 0x01, 0x02, 0x03}));
  EXPECT_EQ(h.req(kM1, kS, kSapC1ReadWrite, {}), Bytes{0xE5});  // nothing more
  // A failing deferred write.
  e.application().on_write(0, 6, [&](const RecordCall& call, std::span<const std::uint8_t>) {
    id = call.id;
    return RecordResult::pending();
  });
  EXPECT_EQ(h.req(kM1, kS, kSapC1ReadWrite, {0x5F, 0x00, 0x06, 0x01, 0x07}), Bytes{0xE5});
  e.application().complete_error(id, {0x80, dpv1_err::kResourceBusy, 0x01});
  EXPECT_EQ(h.du(kM1, kS, kSapC1ReadWrite, {}), (Bytes{0xDF, 0x80, 0xC2, 0x01}));
}

TEST(SlaveDpv1, C1NeedsDpv1Enable) {
  SlaveEngine e(dpv1_config());
  Harness h(e);
  start(h, prm(0x00, 0x00, 0x00));  // DP-V0 compatibility mode
  EXPECT_EQ(e.state(), SlaveState::DataExch);
  h.req(kM1, kS, kSapC1ReadWrite, {0x5E, 0x00, 0x00, 0x04});
  EXPECT_EQ(h.last.status, ResponseStatus::RS);
  h.req(kM1, kS, kSapC1Alarm, {0x5C, 0x00, 0x01, 0x00});
  EXPECT_EQ(h.last.status, ResponseStatus::RS);
}

TEST(SlaveDpv1, Dpv1StatusChecks) {
  SlaveEngine e(dpv1_config());
  Harness h(e);
  const Bytes prm_fault{0x42, 0x05, 0x00, 0xFF, 0x12, 0x34};
  struct Case {
    Bytes status;
    const char* why;
  } cases[] = {
      {{0xC0, 0x00, 0x00}, "Fail_Safe not supported"},
      {{0xA0, 0x00, 0x00}, "Publisher_Enable"},
      {{0x80, 0x80, 0x00}, "pull/plug alarm not supported"},
      {{0x80, 0x20, 0x03}, "Alarm_Mode 3 > 2"},
      {{0x80, 0x01, 0x00}, "Check_Cfg_Mode not supported"},
      {{0x80, 0x00, 0x80}, "PrmCmd"},
      {{0x80, 0x00, 0x08}, "Prm_Structure"},
      {{0x00, 0x20, 0x00}, "alarm enabled without DPV1_Enable"},
  };
  for (const auto& c : cases) {
    h.req(kM1, kS, kSapSetPrm, prm(c.status[0], c.status[1], c.status[2]));
    EXPECT_EQ(e.state(), SlaveState::WaitPrm) << c.why;
    EXPECT_EQ(h.du(kM1, kS, kSapSlaveDiag, {}), prm_fault) << c.why;
  }
  // A DP-V0 Set_Prm (no DPV1_Status) is too short for this slave's 3..3 user prm octets.
  h.req(kM1, kS, kSapSetPrm, {0x88, 0x0A, 0x0A, 0x0B, 0x12, 0x34, 0x00});
  EXPECT_EQ(h.du(kM1, kS, kSapSlaveDiag, {}), prm_fault);
  // WD_Base_1ms: 10 x 10 x 1 ms.
  start(h, prm(0x84, 0x60, 0x02));
  EXPECT_EQ(e.state(), SlaveState::DataExch);
  EXPECT_EQ(e.watchdog_time(), 100 * bus::kTicksPerMs);
}

TEST(SlaveDpv1, AlarmRoundTrip) {
  SlaveEngine e(dpv1_config());
  auto& app = e.application();
  std::vector<int> acked;
  app.on_alarm_ack([&](std::uint8_t type, std::uint8_t slot, std::uint8_t seq) {
    acked.push_back(type * 10000 + slot * 100 + seq);
  });
  Harness h(e);
  EXPECT_EQ(app.raise_alarm(1, 1, AlarmSpec::Appears, false), AlarmResult::Closed);
  start(h, prm(0x80, 0x60, 0x00));  // diagnostic + process alarms, Alarm_Mode 0
  h.req(kM1, kS, std::nullopt, {0x00});
  EXPECT_EQ(h.last.status, ResponseStatus::DL);

  std::uint8_t seq = 99;
  EXPECT_EQ(app.raise_alarm(1, 1, AlarmSpec::Appears, false, Bytes{0x01}, &seq), AlarmResult::Ok);
  EXPECT_EQ(seq, 0);
  // Alarm_Mode 0: one of each type outstanding.
  EXPECT_EQ(app.raise_alarm(1, 2, AlarmSpec::Appears, false), AlarmResult::LimitExpired);
  EXPECT_EQ(app.raise_alarm(3, 1, AlarmSpec::None, false), AlarmResult::TypeNotEnabled);
  EXPECT_EQ(app.raise_alarm(0, 1, AlarmSpec::None, false), AlarmResult::BadArgument);
  EXPECT_EQ(app.raise_alarm(2, 2, AlarmSpec::None, true, {}, &seq), AlarmResult::Ok);
  EXPECT_EQ(seq, 1);
  h.req(kM1, kS, std::nullopt, {0x00});
  EXPECT_EQ(h.last.status, ResponseStatus::DH);
  // Alarm PDUs: 05 01 01 01 01 (diagnostic, slot 1, Seq 0 appears, data 01) and
  // 04 02 02 0C (process, slot 2, Seq 1, Add_Ack).
  EXPECT_EQ(h.du(kM1, kS, kSapSlaveDiag, {}),
            (Bytes{0x00, 0x0C, 0x00, 0x01, 0x12, 0x34, 0x05, 0x01, 0x01, 0x01, 0x01, 0x04, 0x02,
                   0x02, 0x0C}));
  // Wrong Seq_Nr, wrong slot, malformed.
  EXPECT_EQ(h.du(kM1, kS, kSapC1Alarm, {0x5C, 0x01, 0x01, 0x09}), (Bytes{0xDC, 0x80, 0xB5, 0x00}));
  EXPECT_EQ(h.du(kM1, kS, kSapC1Alarm, {0x5C, 0x02, 0x01, 0x01}), (Bytes{0xDC, 0x80, 0xB5, 0x00}));
  EXPECT_EQ(h.du(kM1, kS, kSapC1Alarm, {0x5C, 0x01, 0x01}), (Bytes{0xDC, 0x80, 0xB8, 0x00}));
  // Right one: echoed; the alarm leaves the diagnosis.
  EXPECT_EQ(h.du(kM1, kS, kSapC1Alarm, {0x5C, 0x01, 0x01, 0x01}), (Bytes{0x5C, 0x01, 0x01, 0x01}));
  EXPECT_EQ(acked, std::vector<int>{10100});
  EXPECT_EQ(h.du(kM1, kS, kSapSlaveDiag, {}),
            (Bytes{0x00, 0x0C, 0x00, 0x01, 0x12, 0x34, 0x04, 0x02, 0x02, 0x0C}));
  EXPECT_EQ(app.alarms_outstanding(), 1u);
  // Now another diagnostic alarm may go: it gets Seq_Nr 2.
  EXPECT_EQ(app.raise_alarm(1, 1, AlarmSpec::Disappears, false, {}, &seq), AlarmResult::Ok);
  EXPECT_EQ(seq, 2);
  EXPECT_EQ(h.du(kM1, kS, kSapC1Alarm, {0x5C, 0x02, 0x02, 0x0C}), (Bytes{0x5C, 0x02, 0x02, 0x0C}));
  // Leaving data exchange drops outstanding alarms.
  h.req(kM1, kS, kSapSetPrm, prm(0x80, 0x60, 0x00));
  EXPECT_EQ(app.alarms_outstanding(), 0u);
  EXPECT_EQ(app.raise_alarm(1, 1, AlarmSpec::Appears, false), AlarmResult::Closed);
}

TEST(SlaveDpv1, AlarmModeLimitsTotal) {
  SlaveEngine e(dpv1_config());
  auto& app = e.application();
  Harness h(e);
  start(h, prm(0x80, 0x20, 0x02));  // Alarm_Mode 2: 4 alarms in total
  for (int i = 0; i < 4; ++i)
    EXPECT_EQ(app.raise_alarm(1, static_cast<std::uint8_t>(i), AlarmSpec::Appears, false),
              AlarmResult::Ok);
  EXPECT_EQ(app.raise_alarm(1, 9, AlarmSpec::Appears, false), AlarmResult::LimitExpired);
  EXPECT_EQ(app.raise_alarm(2, 9, AlarmSpec::Appears, false), AlarmResult::TypeNotEnabled);
}

TEST(SlaveDpv1, ModuleStatusBlock) {
  SlaveEngine e(dpv1_config());
  Harness h(e);
  start(h, prm(0x80, 0x00, 0x00));
  e.application().set_module_state(1, ModuleState::WrongModule);
  // Ext_Diag; identifier block (module 1); Module_Status 05 82 00 00 08 (module 1 = 10b).
  EXPECT_EQ(h.du(kM1, kS, kSapSlaveDiag, {}),
            (Bytes{0x08, 0x0C, 0x00, 0x01, 0x12, 0x34, 0x42, 0x02, 0x05, 0x82, 0x00, 0x00, 0x08}));
}

TEST(SlaveDpv1, CheckCfgModeLetsTheUserDecide) {
  auto c = dpv1_config();
  c.features.check_cfg_mode = true;
  std::vector<Bytes> asked;
  // This device also accepts its output byte declared consistent (A0): same layout.
  c.check_cfg_user = [&](std::span<const std::uint8_t> cfg) {
    asked.emplace_back(cfg.begin(), cfg.end());
    return cfg.size() == 2 && cfg[0] == 0x10 && (cfg[1] == 0x20 || cfg[1] == 0xA0);
  };
  SlaveEngine e(c);
  Harness h(e);
  // Without Check_Cfg_Mode the strict check applies and the callback is not asked.
  h.req(kM1, kS, kSapSetPrm, prm(0x80, 0x00, 0x00));
  h.req(kM1, kS, kSapChkCfg, {0x10, 0xA0});
  EXPECT_EQ(e.state(), SlaveState::WaitPrm);
  EXPECT_TRUE(asked.empty());
  // With Check_Cfg_Mode (DPV1_Status_2 bit 0) the callback decides.
  h.req(kM1, kS, kSapSetPrm, prm(0x80, 0x01, 0x00));
  h.req(kM1, kS, kSapChkCfg, {0x10, 0x50});
  EXPECT_EQ(e.state(), SlaveState::WaitPrm);
  EXPECT_EQ(h.du(kM1, kS, kSapSlaveDiag, {}), (Bytes{0x06, 0x05, 0x00, 0xFF, 0x12, 0x34}));
  h.req(kM1, kS, kSapSetPrm, prm(0x80, 0x01, 0x00));
  h.req(kM1, kS, kSapChkCfg, {0x10, 0xA0});
  EXPECT_EQ(e.state(), SlaveState::DataExch);
  EXPECT_EQ(asked, (std::vector<Bytes>{{0x10, 0x50}, {0x10, 0xA0}}));
}

TEST(SlaveDpv1, StructuredPrmAndPrmCmdWhereSupported) {
  // DPV1_Status_3 = PrmCmd | Prm_Structure; one PrmCmd block (§G.2): 08 02 00 00 02 0C 00 0A.
  const Bytes with_block{0x88, 0x0A, 0x0A, 0x0B, 0x12, 0x34, 0x00, 0x80, 0x00, 0x88,
                         0x08, 0x02, 0x00, 0x00, 0x02, 0x0C, 0x00, 0x0A};
  auto c = dpv1_config();
  c.max_user_prm_len = 11;
  {
    SlaveEngine plain(c);  // without PrmCmd/Prm_Structure support: Prm_Fault
    Harness h(plain);
    h.req(kM1, kS, kSapSetPrm, with_block);
    EXPECT_EQ(h.du(kM1, kS, kSapSlaveDiag, {}), (Bytes{0x42, 0x05, 0x00, 0xFF, 0x12, 0x34}));
  }
  c.features.prm_structure = c.features.prm_cmd = true;
  Bytes seen;
  c.check_user_prm = [&](std::span<const std::uint8_t> u) {
    seen.assign(u.begin(), u.end());
    return true;
  };
  SlaveEngine e(c);
  Harness h(e);
  h.req(kM1, kS, kSapSetPrm, with_block);
  EXPECT_EQ(e.state(), SlaveState::WaitCfg);
  EXPECT_EQ(seen, Bytes(with_block.begin() + 7, with_block.end()));
  EXPECT_TRUE(e.dpv1_status().prm_cmd());
  // A block whose length runs past the end is a Prm_Fault.
  Bytes broken = with_block;
  broken[10] = 0x09;
  h.req(kM1, kS, kSapSetPrm, broken);
  EXPECT_EQ(e.state(), SlaveState::WaitPrm);
  EXPECT_EQ(h.du(kM1, kS, kSapSlaveDiag, {}), (Bytes{0x42, 0x05, 0x00, 0xFF, 0x12, 0x34}));
}

TEST(SlaveDpv1, StatusPdusFromTheApplication) {
  SlaveEngine e(dpv1_config());
  auto& app = e.application();
  Harness h(e);
  // Red_State (AUMA layout, §G.3): visible even before parameterisation.
  EXPECT_TRUE(app.set_status(kRedState, 0, 0x01, Bytes{0x02, 0x01, 0x00, 0x00}));
  EXPECT_EQ(h.du(kM1, kS, kSapSlaveDiag, {}),
            (Bytes{0x02, 0x05, 0x00, 0xFF, 0x12, 0x34, 0x08, 0x9F, 0x00, 0x01, 0x02, 0x01, 0x00,
                   0x00}));
  EXPECT_FALSE(app.set_status(0x10, 0, 0));          // not a status type
  EXPECT_FALSE(app.set_status(kModuleStatus, 0, 0));  // built by the engine
  start(h, prm(0x80, 0x00, 0x00));
  h.req(kM1, kS, std::nullopt, {0x00});
  // Set before the master owned the slave: DH until the owner has read the diagnosis.
  EXPECT_EQ(h.last.status, ResponseStatus::DH);
  h.req(kM1, kS, kSapSlaveDiag, {});
  h.req(kM1, kS, std::nullopt, {0x00});
  EXPECT_EQ(h.last.status, ResponseStatus::DL);
  // Replacing it is new diagnosis: DH.
  EXPECT_TRUE(app.set_status(kRedState, 0, 0x01, Bytes{0x0A, 0x01, 0x00, 0x00}));
  h.req(kM1, kS, std::nullopt, {0x00});
  EXPECT_EQ(h.last.status, ResponseStatus::DH);
  EXPECT_EQ(h.du(kM1, kS, kSapSlaveDiag, {}),
            (Bytes{0x00, 0x0C, 0x00, 0x01, 0x12, 0x34, 0x08, 0x9F, 0x00, 0x01, 0x0A, 0x01, 0x00,
                   0x00}));
  app.clear_status(kRedState, 0);
  EXPECT_EQ(h.du(kM1, kS, kSapSlaveDiag, {}), (Bytes{0x00, 0x0C, 0x00, 0x01, 0x12, 0x34}));
}

// --- MSAC_C2 ------------------------------------------------------------------------------------

SlaveConfig c2_config() {
  auto c = dpv1_config();
  c.features.c2 = true;
  c.features.c2_connections = 1;
  return c;
}

// Initiate.req: Send_Timeout 100 (1 s), features 01 00, profile 00 00, ident 0x0000,
// S_Type 00 S_Len 2, D_Type 01 D_Len 2, S address AA BB, D address CC DD.
const Bytes kInitiate{0x57, 0x00, 0x00, 0x00, 0x00, 0x64, 0x01, 0x00, 0x00, 0x00,
                      0x00, 0x00, 0x00, 0x02, 0x01, 0x02, 0xAA, 0xBB, 0xCC, 0xDD};

TEST(SlaveDpv1, C2InitiateReadAbort) {
  SlaveEngine e(c2_config());
  bool via_c2 = false;
  e.application().on_read(0, 0, [&](const RecordCall& call, std::span<std::uint8_t> out) {
    via_c2 = call.c2;
    EXPECT_EQ(call.master, kM2);
    out[0] = 0xAB;
    out[1] = 0xCD;
    return RecordResult::ok(2);
  });
  Harness h(e);
  // A class-2 master needs no Set_Prm. Resource manager: connection SAP 48 (0x30), timeout 100.
  EXPECT_EQ(h.du(kM2, kS, kSapC2ResourceManager, kInitiate), (Bytes{0x56, 0x30, 0x00, 0x64}));
  // Only one connection: a second master is turned away.
  EXPECT_EQ(h.du(kM1, kS, kSapC2ResourceManager, kInitiate), (Bytes{0xD7, 0x80, 0xC3, 0x00}));
  EXPECT_EQ(h.du(kM2, kS, 48, kInitiate),
            (Bytes{0x57, 0xF0, 0x01, 0x00, 0x00, 0x00, 0x00, 0x00, 0x01, 0x02, 0x00, 0x02, 0xCC,
                   0xDD, 0xAA, 0xBB}));
  EXPECT_EQ(h.du(kM2, kS, 48, {0x5E, 0x00, 0x00, 0x10}), (Bytes{0x5E, 0x00, 0x00, 0x02, 0xAB, 0xCD}));
  EXPECT_TRUE(via_c2);
  EXPECT_EQ(h.du(kM2, kS, 48, {0x51, 0x00, 0x00, 0x00}), (Bytes{0xD1, 0x80, 0xA9, 0x00}));
  EXPECT_EQ(h.du(kM2, kS, 48, {0x57}), (Bytes{0xD7, 0x80, 0xB5, 0x00}));
  EXPECT_EQ(h.req(kM2, kS, 48, {0x48}), Bytes{0xE5});  // Idle
  // Another master on that SAP: RS.
  h.req(kM1, kS, 48, {0x5E, 0x00, 0x00, 0x10});
  EXPECT_EQ(h.last.status, ResponseStatus::RS);
  // Abort closes it.
  EXPECT_EQ(h.req(kM2, kS, 48, {0x58, 0x00, 0x25, 0x00}), Bytes{0xE5});
  h.req(kM2, kS, 48, {0x5E, 0x00, 0x00, 0x10});
  EXPECT_EQ(h.last.status, ResponseStatus::RS);
  EXPECT_EQ(h.du(kM1, kS, kSapC2ResourceManager, kInitiate), (Bytes{0x56, 0x30, 0x00, 0x64}));
}

TEST(SlaveDpv1, C2TimesOutAfterTwiceSendTimeout) {
  SlaveEngine e(c2_config());
  Harness h(e);
  h.du(kM2, kS, kSapC2ResourceManager, kInitiate);
  h.du(kM2, kS, 48, kInitiate);
  EXPECT_EQ(e.next_deadline(), 2 * bus::kTicksPerSecond);
  h.advance(2 * bus::kTicksPerSecond - 1);
  EXPECT_EQ(h.req(kM2, kS, 48, {0x48}), Bytes{0xE5});  // keeps it alive
  EXPECT_EQ(e.next_deadline(), 4 * bus::kTicksPerSecond - 1);
  h.advance(2 * bus::kTicksPerSecond);
  EXPECT_EQ(e.next_deadline(), bus::kNever);
  h.req(kM2, kS, 48, {0x48});
  EXPECT_EQ(h.last.status, ResponseStatus::RS);
  // Malformed Initiate to the resource manager.
  EXPECT_EQ(h.du(kM2, kS, kSapC2ResourceManager, {0x57, 0x00}), (Bytes{0xD7, 0x80, 0xB8, 0x00}));
}

TEST(SlaveDpv1, C2Write) {
  SlaveEngine e(c2_config());
  Bytes written;
  e.application().on_write(2, 7, [&](const RecordCall& call, std::span<const std::uint8_t> d) {
    EXPECT_TRUE(call.c2);
    written.assign(d.begin(), d.end());
    return RecordResult::ok();
  });
  Harness h(e);
  h.du(kM2, kS, kSapC2ResourceManager, kInitiate);
  h.du(kM2, kS, 48, kInitiate);
  EXPECT_EQ(h.du(kM2, kS, 48, {0x5F, 0x02, 0x07, 0x03, 0x01, 0x02, 0x03}),
            (Bytes{0x5F, 0x02, 0x07, 0x03}));
  EXPECT_EQ(written, (Bytes{0x01, 0x02, 0x03}));
  EXPECT_EQ(h.du(kM2, kS, 48, {0x5F, 0x02, 0x08, 0x01, 0x01}), (Bytes{0xDF, 0x80, 0xB0, 0x00}));
}

}  // namespace
}  // namespace pbvbus::dp
