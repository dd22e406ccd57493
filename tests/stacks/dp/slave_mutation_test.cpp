// Mutant slaves at the DP level (SlaveConfig::mutation, devices/slave_mutant.hpp): each test runs
// the same sequence on the conformant engine and on the mutant, and shows that the mutant breaks
// exactly its rule (so a test cannot pass vacuously: the conformant half must behave correctly).
// Expected octets are written by hand from protocol-facts.md §D, §E and Appendix 1.
#include <gtest/gtest.h>

#include "pbvbus/dp/slave_engine.hpp"
#include "slave_harness.hpp"

namespace pbvbus::dp {
namespace {

using test::Bytes;
using test::Harness;
using test::hex;
using K = fdl::Reply::Kind;
using fdl::ResponseStatus;
using Mu = EngineMutation;

constexpr std::uint8_t kM1 = 1;  // class-1 master
constexpr std::uint8_t kM2 = 2;  // another master
constexpr std::uint8_t kS = 10;  // the slave
constexpr auto kDx = std::nullopt;

SlaveConfig config(std::vector<std::vector<std::uint8_t>> modules, Mu m) {
  SlaveConfig c;
  c.ident = 0x1234;
  for (auto& mod : modules) c.modules.push_back({mod, ""});
  c.mutation = m;
  return c;
}

// Set_Prm DU: Lock_Req + WD_On (0x88), WD 10 x 10 x 10 ms = 1 s, min TSDR 11, ident 0x1234,
// group 0.
const Bytes kPrmLockWd = {0x88, 0x0A, 0x0A, 0x0B, 0x12, 0x34, 0x00};

void start_up(Harness& h, const Bytes& prm, const Bytes& cfg, std::uint8_t master = kM1) {
  ASSERT_EQ(h.req(master, kS, kSapSetPrm, prm), Bytes{0xE5});
  ASSERT_EQ(h.req(master, kS, kSapChkCfg, cfg), Bytes{0xE5});
}

// Slave_Diag request master 1 -> slave 10 (Appendix 1): 68 05 05 68 8A 81 6D 3C 3E FCS 16 with
// FCS = 8A+81+6D+3C+3E = 0x1F2 -> F2.
const Bytes kDiagReq = {0x68, 0x05, 0x05, 0x68, 0x8A, 0x81, 0x6D, 0x3C, 0x3E, 0xF2, 0x16};

// --- no_prm_req_bit -------------------------------------------------------------------------

TEST(SlaveMutation, NoPrmReqBit) {
  // Conformant: SD3 (8 = 2 SAPs + 6 octets) A2 DA=81 SA=8A FC=08 (DL) 3E 3C, DU 02 05 00 FF 12 34:
  // Station_Not_Ready; Prm_Req | bit 2 (always 1); Master_Add FF; ident. FCS = 81+8A+08+3E+3C
  // +02+05+00+FF+12+34 = 0x2D9 -> D9.
  SlaveEngine good(config({{0x31}}, Mu::None));
  Harness hg(good);
  EXPECT_EQ(hex(hg.frame(kDiagReq)), "A2 81 8A 08 3E 3C 02 05 00 FF 12 34 D9 16");
  // Mutant: octet 2 lacks Prm_Req: 04, FCS 0x2D8 -> D8.
  SlaveEngine bad(config({{0x31}}, Mu::NoPrmReqBit));
  Harness hb(bad);
  EXPECT_EQ(hex(hb.frame(kDiagReq)), "A2 81 8A 08 3E 3C 02 04 00 FF 12 34 D8 16");
  // Everything else is unchanged: it can still be parameterised, and in Data_Exch the
  // diagnosis is the conformant 00 0C 00 01 12 34.
  start_up(hb, kPrmLockWd, {0x31});
  EXPECT_EQ(bad.state(), SlaveState::DataExch);
  EXPECT_EQ(hb.du(kM1, kS, kSapSlaveDiag, {}), (Bytes{0x00, 0x0C, 0x00, 0x01, 0x12, 0x34}));
}

// --- wrong_diag_ident -----------------------------------------------------------------------

TEST(SlaveMutation, WrongDiagIdent) {
  SlaveEngine good(config({{0x31}}, Mu::None));
  Harness hg(good);
  EXPECT_EQ(hex(hg.frame(kDiagReq)), "A2 81 8A 08 3E 3C 02 05 00 FF 12 34 D9 16");
  // Mutant: octets 5..6 = 0x1235; FCS 0x2D9 + 1 = 0x2DA -> DA.
  SlaveEngine bad(config({{0x31}}, Mu::WrongDiagIdent));
  Harness hb(bad);
  EXPECT_EQ(hex(hb.frame(kDiagReq)), "A2 81 8A 08 3E 3C 02 05 00 FF 12 35 DA 16");
  // Set_Prm still checks against the real ident 0x1234.
  start_up(hb, kPrmLockWd, {0x31});
  EXPECT_EQ(bad.state(), SlaveState::DataExch);
}

// --- wrong_get_cfg ----------------------------------------------------------------------------

TEST(SlaveMutation, WrongGetCfg) {
  // Get_Cfg (DSAP 59 = 3B) master 1 -> slave 10: FCS = 8A+81+6D+3B+3E = 0x1F1 -> F1.
  const Bytes req = {0x68, 0x05, 0x05, 0x68, 0x8A, 0x81, 0x6D, 0x3B, 0x3E, 0xF1, 0x16};
  // Real configuration 10 20 (8DI, 8DO). Reply SD2, LE = DA SA FC (3) + 2 SAPs + 2 octets = 7:
  // 68 07 07 68 81 8A 08 3E 3B 10 20, FCS = 81+8A+08+3E+3B+10+20 = 0x1BC -> BC.
  SlaveEngine good(config({{0x10}, {0x20}}, Mu::None));
  Harness hg(good);
  EXPECT_EQ(hex(hg.frame(req)), "68 07 07 68 81 8A 08 3E 3B 10 20 BC 16");
  // Mutant: last octet + 1 = 0x21 (16DO): FCS BD.
  SlaveEngine bad(config({{0x10}, {0x20}}, Mu::WrongGetCfg));
  Harness hb(bad);
  EXPECT_EQ(hex(hb.frame(req)), "68 07 07 68 81 8A 08 3E 3B 10 21 BD 16");
  // Chk_Cfg is still compared with the real configuration: 10 21 is refused, 10 20 accepted.
  hb.req(kM1, kS, kSapSetPrm, kPrmLockWd);
  hb.req(kM1, kS, kSapChkCfg, {0x10, 0x21});
  EXPECT_EQ(bad.state(), SlaveState::WaitPrm);
  start_up(hb, kPrmLockWd, {0x10, 0x20});
  EXPECT_EQ(bad.state(), SlaveState::DataExch);
}

// --- accept_wrong_ident -----------------------------------------------------------------------

TEST(SlaveMutation, AcceptWrongIdent) {
  const Bytes wrong = {0x88, 0x0A, 0x0A, 0x0B, 0x43, 0x21, 0x00};  // ident 0x4321
  SlaveEngine good(config({{0x31}}, Mu::None));
  Harness hg(good);
  EXPECT_EQ(hg.req(kM1, kS, kSapSetPrm, wrong), Bytes{0xE5});
  EXPECT_EQ(good.state(), SlaveState::WaitPrm);
  // Prm_Fault (0x40) | Station_Not_Ready (0x02); Prm_Req; no master.
  EXPECT_EQ(hg.du(kM1, kS, kSapSlaveDiag, {}), (Bytes{0x42, 0x05, 0x00, 0xFF, 0x12, 0x34}));

  SlaveEngine bad(config({{0x31}}, Mu::AcceptWrongIdent));
  Harness hb(bad);
  EXPECT_EQ(hb.req(kM1, kS, kSapSetPrm, wrong), Bytes{0xE5});
  EXPECT_EQ(bad.state(), SlaveState::WaitCfg);
  // Wait_Cfg: Station_Not_Ready, WD_On | bit 2, owner 1, its own ident in the diagnosis.
  EXPECT_EQ(hb.du(kM1, kS, kSapSlaveDiag, {}), (Bytes{0x02, 0x0C, 0x00, 0x01, 0x12, 0x34}));
  // Other Set_Prm checks still apply: WD_On with factor 0 is a Prm_Fault.
  hb.req(kM1, kS, kSapSetPrm, {0x88, 0x00, 0x0A, 0x0B, 0x43, 0x21, 0x00});
  EXPECT_EQ(hb.du(kM1, kS, kSapSlaveDiag, {}), (Bytes{0x42, 0x05, 0x00, 0xFF, 0x12, 0x34}));
}

// --- ignore_watchdog --------------------------------------------------------------------------

TEST(SlaveMutation, IgnoreWatchdog) {
  for (const Mu m : {Mu::None, Mu::IgnoreWatchdog}) {
    SCOPED_TRACE(m == Mu::None ? "conformant" : "mutant");
    SlaveEngine e(config({{0x31}}, m));
    Harness h(e);
    start_up(h, kPrmLockWd, {0x31});
    h.req(kM1, kS, kDx, {0x12, 0x34});
    EXPECT_EQ(e.watchdog_time(), bus::kTicksPerSecond);  // 10 x 10 x 10 ms
    h.advance(bus::kTicksPerSecond);                      // 1 s without a frame
    Bytes out(2);
    e.application().read_outputs(0, out);
    if (m == Mu::None) {
      EXPECT_EQ(e.state(), SlaveState::WaitPrm);
      EXPECT_EQ(out, (Bytes{0x00, 0x00}));
      EXPECT_EQ(h.du(kM1, kS, kSapSlaveDiag, {}), (Bytes{0x02, 0x05, 0x00, 0xFF, 0x12, 0x34}));
    } else {
      // Still in Data_Exch with the outputs applied; WD_On still reported, no timer wanted.
      EXPECT_EQ(e.state(), SlaveState::DataExch);
      EXPECT_EQ(out, (Bytes{0x12, 0x34}));
      EXPECT_EQ(e.next_deadline(), bus::kNever);
      EXPECT_EQ(h.du(kM1, kS, kSapSlaveDiag, {}), (Bytes{0x00, 0x0C, 0x00, 0x01, 0x12, 0x34}));
    }
  }
}

// --- ignore_clear_data ------------------------------------------------------------------------

void gc(Harness& h, std::uint8_t cmd, std::uint8_t groups) {
  h.req(kM1, 127, kSapGlobalControl, {cmd, groups}, fdl::RequestFn::SdnHigh);
}
Bytes outputs(SlaveEngine& e, std::size_t module = 0, std::size_t n = 2) {
  Bytes o(n);
  e.application().read_outputs(module, o);
  return o;
}

TEST(SlaveMutation, IgnoreClearData) {
  for (const Mu m : {Mu::None, Mu::IgnoreClearData}) {
    SCOPED_TRACE(m == Mu::None ? "conformant" : "mutant");
    SlaveEngine e(config({{0x31}}, m));
    Harness h(e);
    start_up(h, kPrmLockWd, {0x31});
    h.req(kM1, kS, kDx, {0x01, 0x02});
    gc(h, 0x02, 0x00);  // Clear_Data, all groups
    const Bytes after_clear = outputs(e);
    h.req(kM1, kS, kDx, {0x03, 0x04});
    if (m == Mu::None) {
      EXPECT_EQ(after_clear, (Bytes{0x00, 0x00}));
      EXPECT_EQ(outputs(e), (Bytes{0x00, 0x00}));  // held safe while Clear lasts
      EXPECT_TRUE(e.application().outputs_safe());
    } else {
      EXPECT_EQ(after_clear, (Bytes{0x01, 0x02}));
      EXPECT_EQ(outputs(e), (Bytes{0x03, 0x04}));
      EXPECT_FALSE(e.application().outputs_safe());
    }
    // The received outputs are stored either way (Rd_Outp).
    EXPECT_EQ(h.du(kM1, kS, kSapRdOutp, {}), (Bytes{0x03, 0x04}));
  }
}

// --- ignore_lock ------------------------------------------------------------------------------

TEST(SlaveMutation, IgnoreLock) {
  for (const Mu m : {Mu::None, Mu::IgnoreLock}) {
    SCOPED_TRACE(m == Mu::None ? "conformant" : "mutant");
    SlaveEngine e(config({{0x31}}, m));
    Harness h(e);
    start_up(h, kPrmLockWd, {0x31});
    h.req(kM1, kS, kDx, {0x01, 0x02});
    // Master 2 sends a locking Set_Prm: acknowledged (SC) in both cases.
    EXPECT_EQ(h.req(kM2, kS, kSapSetPrm, kPrmLockWd), Bytes{0xE5});
    if (m == Mu::None) {
      EXPECT_EQ(e.state(), SlaveState::DataExch);
      EXPECT_EQ(e.master_address(), kM1);
      // Master 2 reads the diagnosis and sees master 1 as owner (octet 4 = 01).
      EXPECT_EQ(h.du(kM2, kS, kSapSlaveDiag, {}), (Bytes{0x00, 0x0C, 0x00, 0x01, 0x12, 0x34}));
    } else {
      EXPECT_EQ(e.state(), SlaveState::WaitCfg);
      EXPECT_EQ(e.master_address(), kM2);
      EXPECT_EQ(outputs(e), (Bytes{0x00, 0x00}));  // left Data_Exch: outputs safe
      EXPECT_EQ(h.du(kM2, kS, kSapSlaveDiag, {}), (Bytes{0x02, 0x0C, 0x00, 0x02, 0x12, 0x34}));
    }
  }
}

// --- accept_wrong_cfg -------------------------------------------------------------------------

TEST(SlaveMutation, AcceptWrongCfg) {
  for (const Mu m : {Mu::None, Mu::AcceptWrongCfg}) {
    SCOPED_TRACE(m == Mu::None ? "conformant" : "mutant");
    SlaveEngine e(config({{0x31}}, m));  // 2 bytes in + out
    Harness h(e);
    ASSERT_EQ(h.req(kM1, kS, kSapSetPrm, kPrmLockWd), Bytes{0xE5});
    EXPECT_EQ(h.req(kM1, kS, kSapChkCfg, {0x21}), Bytes{0xE5});  // 2 bytes out only
    if (m == Mu::None) {
      EXPECT_EQ(e.state(), SlaveState::WaitPrm);
      // Cfg_Fault (0x04) | Station_Not_Ready, Ext_Diag (0x08) with the identifier block
      // 41 01 (header 0x40 | 2 octets incl. header, module 0 faulty).
      EXPECT_EQ(h.du(kM1, kS, kSapSlaveDiag, {}),
                (Bytes{0x0E, 0x05, 0x00, 0xFF, 0x12, 0x34, 0x42, 0x01}));
    } else {
      EXPECT_EQ(e.state(), SlaveState::DataExch);
      EXPECT_EQ(h.du(kM1, kS, kSapSlaveDiag, {}), (Bytes{0x00, 0x0C, 0x00, 0x01, 0x12, 0x34}));
    }
  }
}

// --- ignore_freeze / ignore_sync --------------------------------------------------------------

SlaveConfig sync_freeze_config(Mu m) {
  auto c = config({{0x31}}, m);
  c.features.sync = c.features.freeze = true;
  return c;
}
// Lock + WD + Sync_Req (0x20) + Freeze_Req (0x10), group 1.
const Bytes kPrmSyncFreeze = {0xB8, 0x0A, 0x0A, 0x0B, 0x12, 0x34, 0x01};

TEST(SlaveMutation, IgnoreFreeze) {
  for (const Mu m : {Mu::None, Mu::IgnoreFreeze}) {
    SCOPED_TRACE(m == Mu::None ? "conformant" : "mutant");
    SlaveEngine e(sync_freeze_config(m));
    Harness h(e);
    start_up(h, kPrmSyncFreeze, {0x31});
    e.application().write_inputs(0, Bytes{0x11, 0x22});
    gc(h, 0x08, 0x01);  // Freeze, group 1
    e.application().write_inputs(0, Bytes{0x33, 0x44});
    // Both report Freeze_Mode (octet 2 bit 4): 0x1C.
    EXPECT_EQ(h.du(kM1, kS, kSapSlaveDiag, {}), (Bytes{0x00, 0x1C, 0x00, 0x01, 0x12, 0x34}));
    EXPECT_EQ(h.du(kM1, kS, kDx, {0, 0}),
              m == Mu::None ? (Bytes{0x11, 0x22}) : (Bytes{0x33, 0x44}));
  }
}

TEST(SlaveMutation, IgnoreSync) {
  for (const Mu m : {Mu::None, Mu::IgnoreSync}) {
    SCOPED_TRACE(m == Mu::None ? "conformant" : "mutant");
    SlaveEngine e(sync_freeze_config(m));
    Harness h(e);
    start_up(h, kPrmSyncFreeze, {0x31});
    h.req(kM1, kS, kDx, {0x01, 0x02});
    gc(h, 0x20, 0x00);  // Sync
    EXPECT_EQ(h.du(kM1, kS, kSapSlaveDiag, {}), (Bytes{0x00, 0x2C, 0x00, 0x01, 0x12, 0x34}));
    h.req(kM1, kS, kDx, {0x03, 0x04});
    EXPECT_EQ(outputs(e), m == Mu::None ? (Bytes{0x01, 0x02}) : (Bytes{0x03, 0x04}));
    gc(h, 0x20, 0x00);  // the next Sync applies them in both
    EXPECT_EQ(outputs(e), (Bytes{0x03, 0x04}));
  }
}

// --- slow_slave_interval ----------------------------------------------------------------------

TEST(SlaveMutation, SlowSlaveInterval) {
  // Min_Slave_Interval 1 (100 us): the mutant needs 10 x 100 us = 1 ms between polls.
  constexpr bus::Ticks kMs = bus::kTicksPerMs;
  for (const Mu m : {Mu::None, Mu::SlowSlaveInterval}) {
    SCOPED_TRACE(m == Mu::None ? "conformant" : "mutant");
    SlaveEngine e(config({{0x31}}, m));
    Harness h(e);
    start_up(h, {0x80, 0x01, 0x01, 0x0B, 0x12, 0x34, 0x00}, {0x31});  // Lock_Req, no WD_On
    e.application().write_inputs(0, Bytes{0x11, 0x22});
    // Data_Exchange 0A 01 5D AA 55 (FCS 0A+01+5D+AA+55 = 0x167 -> 67); reply DU 11 22:
    // 68 05 05 68 01 0A 08 11 22, FCS 01+0A+08+11+22 = 0x46.
    const Bytes dx = {0x68, 0x05, 0x05, 0x68, 0x0A, 0x01, 0x5D, 0xAA, 0x55, 0x67, 0x16};
    const std::string answer = "68 05 05 68 01 0A 08 11 22 46 16";
    EXPECT_EQ(hex(h.frame(dx)), answer);  // t = 0
    h.now += kMs / 2;                     // 0.5 ms later: too soon for the mutant
    EXPECT_EQ(hex(h.frame(dx)), m == Mu::None ? answer : "");
    h.now += kMs / 2 - 1;  // 1 ms - 1 tick after the answered one: still too soon
    EXPECT_EQ(hex(h.frame(dx)), m == Mu::None ? answer : "");
    h.now += 1;  // exactly 1 ms after the last answered request: answered again
    EXPECT_EQ(hex(h.frame(dx)), answer);
    EXPECT_EQ(e.state(), SlaveState::DataExch);
    // Other services are not affected.
    EXPECT_EQ(h.du(kM1, kS, kSapRdInp, {}), (Bytes{0x11, 0x22}));
  }
}

// --- keep_state_on_power_cycle ----------------------------------------------------------------

TEST(SlaveMutation, KeepStateOnPowerCycle) {
  for (const Mu m : {Mu::None, Mu::KeepStateOnPowerCycle}) {
    SCOPED_TRACE(m == Mu::None ? "conformant" : "mutant");
    SlaveEngine e(config({{0x31}}, m));
    Harness h(e);
    start_up(h, kPrmLockWd, {0x31});
    h.req(kM1, kS, kDx, {0x01, 0x02});
    h.now += 5 * bus::kTicksPerSecond;  // off for 5 s (longer than the 1 s watchdog)
    e.on_power_on(h.now);
    if (m == Mu::None) {
      EXPECT_EQ(e.state(), SlaveState::WaitPrm);
      EXPECT_EQ(h.du(kM1, kS, kSapSlaveDiag, {}), (Bytes{0x02, 0x05, 0x00, 0xFF, 0x12, 0x34}));
      h.req(kM1, kS, kDx, {0x01, 0x02});
      EXPECT_EQ(h.last.status, ResponseStatus::RS);
    } else {
      EXPECT_EQ(e.state(), SlaveState::DataExch);
      EXPECT_EQ(h.du(kM1, kS, kSapSlaveDiag, {}), (Bytes{0x00, 0x0C, 0x00, 0x01, 0x12, 0x34}));
      h.req(kM1, kS, kDx, {0x01, 0x02});
      EXPECT_EQ(h.last.kind, K::Data);
      // The watchdog still runs (restarted at power-on): 1 s of silence ends it.
      h.advance(bus::kTicksPerSecond);
      EXPECT_EQ(e.state(), SlaveState::WaitPrm);
    }
  }
}

// --- reject_fail_safe -------------------------------------------------------------------------

TEST(SlaveMutation, RejectFailSafe) {
  for (const Mu m : {Mu::None, Mu::RejectFailSafe}) {
    SCOPED_TRACE(m == Mu::None ? "conformant" : "mutant");
    auto c = config({{0x31}}, m);
    c.features.fail_safe = true;
    SlaveEngine e(c);
    Harness h(e);
    start_up(h, kPrmLockWd, {0x31});
    e.application().write_inputs(0, Bytes{0x11, 0x22});
    h.req(kM1, kS, kDx, {0x0F, 0xF0});
    // Data_Exchange without output data: 10 0A 01 5D FCS 16 (FCS 0A+01+5D = 0x68).
    const std::string r = hex(h.frame({0x10, 0x0A, 0x01, 0x5D, 0x68, 0x16}));
    if (m == Mu::None) {
      EXPECT_EQ(r, "68 05 05 68 01 0A 08 11 22 46 16");
      EXPECT_EQ(e.state(), SlaveState::DataExch);
      EXPECT_TRUE(e.application().outputs_safe());
    } else {
      // RS as SD1: 10 01 0A 03 (slave, RS), FCS 01+0A+03 = 0x0E.
      EXPECT_EQ(r, "10 01 0A 03 0E 16");
      EXPECT_EQ(e.state(), SlaveState::WaitPrm);
    }
    // Wrong non-zero length is refused by both.
  }
  SlaveEngine e(config({{0x31}}, Mu::RejectFailSafe));
  Harness h(e);
  start_up(h, kPrmLockWd, {0x31});
  h.req(kM1, kS, kDx, {0x01});
  EXPECT_EQ(h.last.status, ResponseStatus::RS);
}

// --- dpv1_bad_index_accepted ------------------------------------------------------------------

SlaveConfig dpv1_config(Mu m) {
  auto c = config({{0x10}, {0x20}}, m);
  c.features.dpv1 = true;
  c.features.c1_read_write = true;
  c.min_user_prm_len = 3;
  c.max_user_prm_len = 3;
  return c;
}

TEST(SlaveMutation, Dpv1BadIndexAccepted) {
  // MSAC_C1 Read slot 0 index 0 length 4: 68 09 09 68 8A 81 7D 33 33 5E 00 00 04 FCS 16,
  // FCS = 8A+81+7D+33+33+5E+00+00+04 = 0x250 -> 50.
  const Bytes read = {0x68, 0x09, 0x09, 0x68, 0x8A, 0x81, 0x7D, 0x33, 0x33,
                      0x5E, 0x00, 0x00, 0x04, 0x50, 0x16};
  // Read slot 5 (beyond the 2 modules) index 0 length 4: FCS 0x255 -> 55.
  const Bytes read_slot5 = {0x68, 0x09, 0x09, 0x68, 0x8A, 0x81, 0x7D, 0x33, 0x33,
                            0x5E, 0x05, 0x00, 0x04, 0x55, 0x16};
  for (const Mu m : {Mu::None, Mu::Dpv1BadIndexAccepted}) {
    SCOPED_TRACE(m == Mu::None ? "conformant" : "mutant");
    SlaveEngine e(dpv1_config(m));
    Harness h(e);
    start_up(h, {0x88, 0x0A, 0x0A, 0x0B, 0x12, 0x34, 0x00, 0x80, 0x00, 0x00}, {0x10, 0x20});
    if (m == Mu::None) {
      // Error: DE 80 B0 00 (invalid index). 68 09 09 68 81 8A 08 33 33 DE 80 B0 00,
      // FCS = 81+8A+08+33+33+DE+80+B0+00 = 0x387 -> 87 (Appendix 1).
      EXPECT_EQ(hex(h.frame(read)), "68 09 09 68 81 8A 08 33 33 DE 80 B0 00 87 16");
    } else {
      // Read.res with 4 zero octets: DU 5E 00 00 04 00 00 00 00 (8) + 2 SAPs = 10, LE 13 = 0D;
      // FCS = 81+8A+08+33+33+5E+00+00+04 = 0x1DB -> DB.
      EXPECT_EQ(hex(h.frame(read)),
                "68 0D 0D 68 81 8A 08 33 33 5E 00 00 04 00 00 00 00 DB 16");
    }
    // An unknown slot keeps its error in both: DE 80 B2 00, FCS 0x387 + 2 = 0x389 -> 89.
    EXPECT_EQ(hex(h.frame(read_slot5)), "68 09 09 68 81 8A 08 33 33 DE 80 B2 00 89 16");
  }
}

// --- tear_consistent --------------------------------------------------------------------------

TEST(SlaveMutation, TearConsistent) {
  // Module 0: 0xD1 = consistent, word format, inputs, 2 words (4 octets). Module 1: 0x13 =
  // 4 input octets without consistency. No outputs: Data_Exchange carries no data.
  for (const Mu m : {Mu::None, Mu::TearConsistent}) {
    SCOPED_TRACE(m == Mu::None ? "conformant" : "mutant");
    SlaveEngine e(config({{0xD1}, {0x13}}, m));
    Harness h(e);
    ASSERT_TRUE(e.layout().modules[0].consistent);
    ASSERT_FALSE(e.layout().modules[1].consistent);
    start_up(h, {0x80, 0x01, 0x01, 0x0B, 0x12, 0x34, 0x00}, {0xD1, 0x13});  // Lock_Req, no WD_On
    auto& app = e.application();
    // The device writes one value into every word of the module.
    app.write_inputs(0, Bytes{0x11, 0x11, 0x11, 0x11});
    app.write_inputs(1, Bytes{0xA1, 0xA1, 0xA1, 0xA1});
    const Bytes first = h.du(kM1, kS, kDx, {});
    app.write_inputs(0, Bytes{0x22, 0x22, 0x22, 0x22});
    app.write_inputs(1, Bytes{0xA2, 0xA2, 0xA2, 0xA2});
    const Bytes second = h.du(kM1, kS, kDx, {});
    if (m == Mu::None) {
      EXPECT_EQ(first, (Bytes{0x11, 0x11, 0x11, 0x11, 0xA1, 0xA1, 0xA1, 0xA1}));
      EXPECT_EQ(second, (Bytes{0x22, 0x22, 0x22, 0x22, 0xA2, 0xA2, 0xA2, 0xA2}));
    } else {
      // First half (2 octets) from the previous image (zeros before the first exchange), the
      // second half current; the non-consistent module is untouched.
      EXPECT_EQ(first, (Bytes{0x00, 0x00, 0x11, 0x11, 0xA1, 0xA1, 0xA1, 0xA1}));
      EXPECT_EQ(second, (Bytes{0x11, 0x11, 0x22, 0x22, 0xA2, 0xA2, 0xA2, 0xA2}));
    }
    // Rd_Inp is not torn.
    EXPECT_EQ(h.du(kM1, kS, kSapRdInp, {}),
              (Bytes{0x22, 0x22, 0x22, 0x22, 0xA2, 0xA2, 0xA2, 0xA2}));
  }
}

}  // namespace
}  // namespace pbvbus::dp
