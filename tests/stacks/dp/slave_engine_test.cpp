// DP-V0 slave engine: start-up, faults, locking, watchdog, Global_Control, Set_Slave_Add.
// Expected octets are written by hand from protocol-facts.md (§D, Appendix 1).
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

constexpr std::uint8_t kM1 = 1;   // class-1 master
constexpr std::uint8_t kM2 = 2;   // another master
constexpr std::uint8_t kS = 10;   // the slave
constexpr auto kDx = std::nullopt;

SlaveConfig base_config(std::vector<std::vector<std::uint8_t>> modules) {
  SlaveConfig c;
  c.ident = 0x1234;
  for (auto& m : modules) c.modules.push_back({m, ""});
  return c;
}

// Set_Prm DUs: lock + WD on, 10 x 10 (1 s), min TSDR 11, ident 0x1234, group 0.
const Bytes kPrmLockWd = {0x88, 0x0A, 0x0A, 0x0B, 0x12, 0x34, 0x00};

void start_up(Harness& h, const Bytes& prm, const Bytes& cfg, std::uint8_t master = kM1) {
  ASSERT_EQ(h.req(master, kS, kSapSetPrm, prm), Bytes{0xE5});
  ASSERT_EQ(h.req(master, kS, kSapChkCfg, cfg), Bytes{0xE5});
}

// --- Appendix 1 golden start-up ---------------------------------------------------------------

TEST(SlaveEngine, GoldenStartupAppendix1) {
  SlaveEngine e(base_config({{0x10}, {0x20}}));  // 1 byte in, 1 byte out
  Harness h(e);
  // Slave_Diag, master 1 -> slave 10, answered as SD3 with the unparameterised diagnosis.
  EXPECT_EQ(hex(h.frame({0x68, 0x05, 0x05, 0x68, 0x8A, 0x81, 0x6D, 0x3C, 0x3E, 0xF2, 0x16})),
            "A2 81 8A 08 3E 3C 02 05 00 FF 12 34 D9 16");
  // Set_Prm lock + WD (1 s), min TSDR 11.
  EXPECT_EQ(hex(h.frame({0x68, 0x0C, 0x0C, 0x68, 0x8A, 0x81, 0x5D, 0x3D, 0x3E, 0x88, 0x0A, 0x0A,
                         0x0B, 0x12, 0x34, 0x00, 0xD0, 0x16})),
            "E5");
  EXPECT_EQ(h.last.new_min_tsdr, std::optional<std::uint32_t>(11));
  EXPECT_EQ(e.state(), SlaveState::WaitCfg);
  EXPECT_EQ(e.watchdog_time(), bus::kTicksPerSecond);
  // Chk_Cfg 10 20.
  EXPECT_EQ(hex(h.frame({0x68, 0x07, 0x07, 0x68, 0x8A, 0x81, 0x7D, 0x3E, 0x3E, 0x10, 0x20, 0x34,
                         0x16})),
            "E5");
  EXPECT_EQ(e.state(), SlaveState::DataExch);
  // Diagnosis in data exchange: 00 0C 00 01 12 34 (FCS 81+8A+08+3E+3C+00+0C+00+01+12+34 = E0).
  EXPECT_EQ(hex(h.frame({0x68, 0x05, 0x05, 0x68, 0x8A, 0x81, 0x5D, 0x3C, 0x3E, 0xE2, 0x16})),
            "A2 81 8A 08 3E 3C 00 0C 00 01 12 34 E0 16");
  // Data_Exchange with one output byte 0x42 (FCS 0A+01+5D+42 = AA); the reply carries the
  // input byte 0x3C: the Appendix 1 reply frame.
  ASSERT_TRUE(e.application().write_inputs(0, Bytes{0x3C}));
  EXPECT_EQ(hex(h.frame({0x68, 0x04, 0x04, 0x68, 0x0A, 0x01, 0x5D, 0x42, 0xAA, 0x16})),
            "68 04 04 68 01 0A 08 3C 4F 16");
  Bytes out(1);
  ASSERT_TRUE(e.application().read_outputs(1, out));
  EXPECT_EQ(out, Bytes{0x42});
  // Global_Control Clear broadcast (Appendix 1): no reply, outputs to the safe state.
  EXPECT_EQ(h.frame({0x68, 0x07, 0x07, 0x68, 0xFF, 0x81, 0x46, 0x3A, 0x3E, 0x02, 0x00, 0x40, 0x16}),
            Bytes{});
  ASSERT_TRUE(e.application().read_outputs(1, out));
  EXPECT_EQ(out, Bytes{0x00});
  EXPECT_TRUE(e.application().outputs_safe());
}

TEST(SlaveEngine, CompactTwoInTwoOutStartup) {
  SlaveEngine e(base_config({{0x31}}));  // 2 bytes in + 2 bytes out
  Harness h(e);
  EXPECT_EQ(h.du(kM1, kS, kSapSlaveDiag, {}), (Bytes{0x02, 0x05, 0x00, 0xFF, 0x12, 0x34}));
  EXPECT_EQ(h.du(kM1, kS, kSapGetCfg, {}), Bytes{0x31});
  start_up(h, kPrmLockWd, {0x31});
  EXPECT_EQ(h.du(kM1, kS, kSapSlaveDiag, {}), (Bytes{0x00, 0x0C, 0x00, 0x01, 0x12, 0x34}));
  ASSERT_TRUE(e.application().write_inputs(0, Bytes{0x11, 0x22}));
  // Appendix 1: Data_Exchange with 2 output bytes AA 55; reply 01+0A+08+11+22 = 0x46.
  EXPECT_EQ(hex(h.frame({0x68, 0x05, 0x05, 0x68, 0x0A, 0x01, 0x5D, 0xAA, 0x55, 0x67, 0x16})),
            "68 05 05 68 01 0A 08 11 22 46 16");
  Bytes out(2);
  ASSERT_TRUE(e.application().read_outputs(0, out));
  EXPECT_EQ(out, (Bytes{0xAA, 0x55}));
  EXPECT_FALSE(e.application().outputs_safe());
  // Another master may read inputs and outputs.
  EXPECT_EQ(h.du(kM2, kS, kSapRdInp, {}), (Bytes{0x11, 0x22}));
  EXPECT_EQ(h.du(kM2, kS, kSapRdOutp, {}), (Bytes{0xAA, 0x55}));
  EXPECT_EQ(h.du(kM2, kS, kSapGetCfg, {}), Bytes{0x31});
}

TEST(SlaveEngine, ModularStartupWithSd3DataExchange) {
  // 4 bytes in; 8 bytes out; 4 bytes in consistent (special format).
  SlaveEngine e(base_config({{0x13}, {0x27}, {0x40, 0x83}}));
  Harness h(e);
  EXPECT_EQ(e.layout().inputs, 8u);
  EXPECT_EQ(e.layout().outputs, 8u);
  EXPECT_TRUE(e.layout().modules[2].consistent);
  EXPECT_EQ(e.layout().modules[2].in_offset, 4u);
  EXPECT_EQ(h.du(kM1, kS, kSapGetCfg, {}), (Bytes{0x13, 0x27, 0x40, 0x83}));
  // The master describes module 2 with the equivalent general identifier 0x93.
  start_up(h, kPrmLockWd, {0x13, 0x27, 0x93});
  EXPECT_EQ(e.state(), SlaveState::DataExch);
  ASSERT_TRUE(e.application().write_inputs(0, Bytes{0xA0, 0xA1, 0xA2, 0xA3}));
  ASSERT_TRUE(e.application().write_inputs(2, Bytes{0xB0, 0xB1, 0xB2, 0xB3}));
  EXPECT_FALSE(e.application().write_inputs(2, Bytes{0xB0}));  // wrong length refused
  // Appendix 1: Data_Exchange with 8 output bytes goes as SD3. The 8-byte reply is SD3 too:
  // FCS = 01+0A+08+A0+A1+A2+A3+B0+B1+B2+B3 = 0x55F -> 5F.
  EXPECT_EQ(hex(h.frame({0xA2, 0x0A, 0x01, 0x7D, 0x01, 0x02, 0x03, 0x04, 0x05, 0x06, 0x07, 0x08,
                         0xAC, 0x16})),
            "A2 01 0A 08 A0 A1 A2 A3 B0 B1 B2 B3 5F 16");
  Bytes out(8);
  ASSERT_TRUE(e.application().read_outputs(1, out));
  EXPECT_EQ(out, (Bytes{1, 2, 3, 4, 5, 6, 7, 8}));
}

// --- Set_Prm faults ---------------------------------------------------------------------------

TEST(SlaveEngine, WrongIdentGivesPrmFault) {
  SlaveEngine e(base_config({{0x31}}));
  Harness h(e);
  EXPECT_EQ(h.req(kM1, kS, kSapSetPrm, {0x88, 0x0A, 0x0A, 0x0B, 0x43, 0x21, 0x00}), Bytes{0xE5});
  EXPECT_EQ(e.state(), SlaveState::WaitPrm);
  EXPECT_EQ(h.du(kM1, kS, kSapSlaveDiag, {}), (Bytes{0x42, 0x05, 0x00, 0xFF, 0x12, 0x34}));
  // Chk_Cfg and Data_Exchange are not accepted in Wait_Prm: RS.
  h.req(kM1, kS, kSapChkCfg, {0x31});
  EXPECT_EQ(h.last.kind, K::Status);
  EXPECT_EQ(h.last.status, ResponseStatus::RS);
  h.req(kM1, kS, kDx, {0x00, 0x00});
  EXPECT_EQ(h.last.status, ResponseStatus::RS);
  // A good Set_Prm clears the fault.
  start_up(h, kPrmLockWd, {0x31});
  EXPECT_EQ(h.du(kM1, kS, kSapSlaveDiag, {}), (Bytes{0x00, 0x0C, 0x00, 0x01, 0x12, 0x34}));
}

TEST(SlaveEngine, PrmFaultCases) {
  auto cfg = base_config({{0x31}});
  cfg.min_user_prm_len = 2;
  cfg.max_user_prm_len = 2;
  cfg.check_user_prm = [](std::span<const std::uint8_t> u) { return u[0] <= 10; };
  SlaveEngine e(cfg);
  Harness h(e);
  const Bytes prm_fault_diag{0x42, 0x05, 0x00, 0xFF, 0x12, 0x34};
  // Too short (6 octets).
  h.req(kM1, kS, kSapSetPrm, {0x88, 0x0A, 0x0A, 0x0B, 0x12, 0x34});
  EXPECT_EQ(h.du(kM1, kS, kSapSlaveDiag, {}), prm_fault_diag);
  // User prm length 1 (limits 2..2).
  h.req(kM1, kS, kSapSetPrm, {0x88, 0x0A, 0x0A, 0x0B, 0x12, 0x34, 0x00, 0x05});
  EXPECT_EQ(h.du(kM1, kS, kSapSlaveDiag, {}), prm_fault_diag);
  // Content refused by the check callback.
  h.req(kM1, kS, kSapSetPrm, {0x88, 0x0A, 0x0A, 0x0B, 0x12, 0x34, 0x00, 0x0B, 0x00});
  EXPECT_EQ(h.du(kM1, kS, kSapSlaveDiag, {}), prm_fault_diag);
  // Watchdog factor 0 with WD_On.
  h.req(kM1, kS, kSapSetPrm, {0x88, 0x00, 0x0A, 0x0B, 0x12, 0x34, 0x00, 0x05, 0x00});
  EXPECT_EQ(h.du(kM1, kS, kSapSlaveDiag, {}), prm_fault_diag);
  // Good.
  h.req(kM1, kS, kSapSetPrm, {0x88, 0x0A, 0x0A, 0x0B, 0x12, 0x34, 0x00, 0x05, 0x00});
  EXPECT_EQ(e.state(), SlaveState::WaitCfg);
  EXPECT_EQ(h.du(kM1, kS, kSapSlaveDiag, {}), (Bytes{0x02, 0x0C, 0x00, 0x01, 0x12, 0x34}));
  // A faulty Set_Prm in Data_Exch drops the slave to Wait_Prm with outputs safe.
  h.req(kM1, kS, kSapChkCfg, {0x31});
  h.req(kM1, kS, kDx, {0x12, 0x34});
  h.req(kM1, kS, kSapSetPrm, {0x88, 0x0A, 0x0A, 0x0B, 0x12, 0x35, 0x00, 0x05, 0x00});
  EXPECT_EQ(e.state(), SlaveState::WaitPrm);
  Bytes out(2);
  e.application().read_outputs(0, out);
  EXPECT_EQ(out, (Bytes{0, 0}));
}

TEST(SlaveEngine, SyncFreezeWithoutSupportIsNotSupported) {
  SlaveEngine e(base_config({{0x31}}));
  Harness h(e);
  h.req(kM1, kS, kSapSetPrm, {0xB8, 0x0A, 0x0A, 0x0B, 0x12, 0x34, 0x00});  // Sync_Req + Freeze_Req
  EXPECT_EQ(h.last.kind, K::ShortAck);
  EXPECT_EQ(e.state(), SlaveState::WaitPrm);
  EXPECT_EQ(h.du(kM1, kS, kSapSlaveDiag, {}), (Bytes{0x12, 0x05, 0x00, 0xFF, 0x12, 0x34}));
}

TEST(SlaveEngine, MinTsdrOnlyWithoutLock) {
  SlaveEngine e(base_config({{0x31}}));
  Harness h(e);
  start_up(h, kPrmLockWd, {0x31});
  // Lock = Unlock = 0: only min TSDR changes.
  h.req(kM1, kS, kSapSetPrm, {0x00, 0x01, 0x01, 0x2A, 0x00, 0x00, 0x00});
  EXPECT_EQ(h.last.kind, K::ShortAck);
  EXPECT_EQ(h.last.new_min_tsdr, std::optional<std::uint32_t>(42));
  EXPECT_EQ(e.state(), SlaveState::DataExch);
  EXPECT_EQ(e.watchdog_time(), bus::kTicksPerSecond);
}

// --- Chk_Cfg ------------------------------------------------------------------------------------

TEST(SlaveEngine, WrongConfigGivesCfgFaultWithIdentifierBlock) {
  SlaveEngine e(base_config({{0x13}, {0x27}, {0x40, 0x83}}));
  Harness h(e);
  // Module 2 configured without consistency.
  start_up(h, kPrmLockWd, {0x13, 0x27, 0x40, 0x03});
  EXPECT_EQ(e.state(), SlaveState::WaitPrm);
  // Not_Ready + Cfg_Fault + Ext_Diag; Prm_Req; identifier block, 1 octet, bit 2.
  EXPECT_EQ(h.du(kM1, kS, kSapSlaveDiag, {}),
            (Bytes{0x0E, 0x05, 0x00, 0xFF, 0x12, 0x34, 0x42, 0x04}));
  // One identifier too many: module index 3 (beyond the real ones) is flagged.
  start_up(h, kPrmLockWd, {0x13, 0x27, 0x40, 0x83, 0x10});
  EXPECT_EQ(h.du(kM1, kS, kSapSlaveDiag, {}),
            (Bytes{0x0E, 0x05, 0x00, 0xFF, 0x12, 0x34, 0x42, 0x08}));
  // A correct configuration clears it.
  start_up(h, kPrmLockWd, {0x13, 0x27, 0x40, 0x83});
  EXPECT_EQ(h.du(kM1, kS, kSapSlaveDiag, {}), (Bytes{0x00, 0x0C, 0x00, 0x01, 0x12, 0x34}));
  // A different Chk_Cfg in Data_Exch: back to Wait_Prm with Cfg_Fault; modules 0 and 1 swapped.
  h.req(kM1, kS, kSapChkCfg, {0x27, 0x13, 0x40, 0x83});
  EXPECT_EQ(e.state(), SlaveState::WaitPrm);
  EXPECT_EQ(h.du(kM1, kS, kSapSlaveDiag, {}),
            (Bytes{0x0E, 0x05, 0x00, 0xFF, 0x12, 0x34, 0x42, 0x03}));
}

TEST(SlaveEngine, ManufacturerDataChecked) {
  // Special format, input 4 bytes, one manufacturer octet AB.
  SlaveEngine e(base_config({{0x41, 0x03, 0xAB}}));
  Harness h(e);
  start_up(h, kPrmLockWd, {0x41, 0x03, 0xCD});
  EXPECT_EQ(e.state(), SlaveState::WaitPrm);
  start_up(h, kPrmLockWd, {0x4F, 0x03});  // count 15: do not check
  EXPECT_EQ(e.state(), SlaveState::DataExch);
  start_up(h, kPrmLockWd, {0x41, 0x03, 0xAB});
  EXPECT_EQ(e.state(), SlaveState::DataExch);
  start_up(h, kPrmLockWd, {0x41, 0x03});  // truncated
  EXPECT_EQ(e.state(), SlaveState::WaitPrm);
}

// --- watchdog -----------------------------------------------------------------------------------

TEST(SlaveEngine, WatchdogExpiryReturnsToWaitPrmWithSafeOutputs) {
  SlaveEngine e(base_config({{0x31}}));
  Harness h(e);
  start_up(h, kPrmLockWd, {0x31});
  h.req(kM1, kS, kDx, {0x12, 0x34});
  EXPECT_EQ(e.next_deadline(), bus::kTicksPerSecond);
  h.advance(bus::kTicksPerSecond - 1);
  EXPECT_EQ(e.state(), SlaveState::DataExch);
  h.req(kM1, kS, kDx, {0x12, 0x34});  // restarts the watchdog
  EXPECT_EQ(e.next_deadline(), 2 * bus::kTicksPerSecond - 1);
  // Frames from another master do not restart it.
  h.advance(bus::kTicksPerSecond / 2);
  h.req(kM2, kS, kSapSlaveDiag, {});
  EXPECT_EQ(e.next_deadline(), 2 * bus::kTicksPerSecond - 1);
  h.advance(bus::kTicksPerSecond / 2);
  EXPECT_EQ(e.state(), SlaveState::WaitPrm);
  EXPECT_EQ(e.next_deadline(), bus::kNever);
  Bytes out(2);
  e.application().read_outputs(0, out);
  EXPECT_EQ(out, (Bytes{0, 0}));
  EXPECT_TRUE(e.application().outputs_safe());
  EXPECT_EQ(h.du(kM1, kS, kSapSlaveDiag, {}), (Bytes{0x02, 0x05, 0x00, 0xFF, 0x12, 0x34}));
  h.req(kM1, kS, kDx, {0x12, 0x34});
  EXPECT_EQ(h.last.status, ResponseStatus::RS);
}

TEST(SlaveEngine, WatchdogExpiryDetectedOnLateRequest) {
  // Without on_time() calls, a request after the deadline still sees the expiry first.
  SlaveEngine e(base_config({{0x31}}));
  Harness h(e);
  start_up(h, kPrmLockWd, {0x31});
  h.now = bus::kTicksPerSecond;
  h.req(kM1, kS, kDx, {0x12, 0x34});
  EXPECT_EQ(h.last.status, ResponseStatus::RS);
  EXPECT_EQ(e.state(), SlaveState::WaitPrm);
}

TEST(SlaveEngine, WatchdogOffWithoutWdOn) {
  SlaveEngine e(base_config({{0x31}}));
  Harness h(e);
  ASSERT_EQ(h.req(kM1, kS, kSapSetPrm, {0x80, 0x0A, 0x0A, 0x00, 0x12, 0x34, 0x00}), Bytes{0xE5});
  EXPECT_FALSE(h.last.new_min_tsdr.has_value());  // min TSDR 0 = unchanged
  ASSERT_EQ(h.req(kM1, kS, kSapChkCfg, {0x31}), Bytes{0xE5});
  EXPECT_EQ(e.next_deadline(), bus::kNever);
  EXPECT_EQ(h.du(kM1, kS, kSapSlaveDiag, {}), (Bytes{0x00, 0x04, 0x00, 0x01, 0x12, 0x34}));
}

// --- locking ------------------------------------------------------------------------------------

TEST(SlaveEngine, LockedByAnotherMaster) {
  SlaveEngine e(base_config({{0x31}}));
  Harness h(e);
  start_up(h, kPrmLockWd, {0x31});
  e.application().write_inputs(0, Bytes{0x11, 0x22});
  h.req(kM1, kS, kDx, {0xAA, 0x55});
  // Master 2 tries to take over: SC, but nothing changes.
  EXPECT_EQ(h.req(kM2, kS, kSapSetPrm, {0x88, 0x05, 0x05, 0x0B, 0x12, 0x34, 0x00}), Bytes{0xE5});
  EXPECT_FALSE(h.last.new_min_tsdr.has_value());
  EXPECT_EQ(h.req(kM2, kS, kSapChkCfg, {0x10}), Bytes{0xE5});
  EXPECT_EQ(e.state(), SlaveState::DataExch);
  EXPECT_EQ(e.master_address(), kM1);
  // Its diagnosis shows the owner (1), from which master 2 derives Master_Lock.
  EXPECT_EQ(h.du(kM2, kS, kSapSlaveDiag, {}), (Bytes{0x00, 0x0C, 0x00, 0x01, 0x12, 0x34}));
  // Its Data_Exchange and unicast Global_Control are refused; its broadcast is ignored.
  h.req(kM2, kS, kDx, {0x00, 0x00});
  EXPECT_EQ(h.last.status, ResponseStatus::RS);
  h.req(kM2, kS, kSapGlobalControl, {0x02, 0x00}, fdl::RequestFn::SdaHigh);
  EXPECT_EQ(h.last.status, ResponseStatus::RS);
  h.req(kM2, 127, kSapGlobalControl, {0x02, 0x00}, fdl::RequestFn::SdnHigh);
  EXPECT_EQ(h.last.kind, K::None);
  Bytes out(2);
  e.application().read_outputs(0, out);
  EXPECT_EQ(out, (Bytes{0xAA, 0x55}));
  // It may still read.
  EXPECT_EQ(h.du(kM2, kS, kSapRdInp, {}), (Bytes{0x11, 0x22}));
  EXPECT_EQ(h.du(kM2, kS, kSapRdOutp, {}), (Bytes{0xAA, 0x55}));
  // The owner unlocks; then master 2 can parameterise.
  EXPECT_EQ(h.req(kM1, kS, kSapSetPrm, {0x40, 0x0A, 0x0A, 0x00, 0x12, 0x34, 0x00}), Bytes{0xE5});
  EXPECT_EQ(e.state(), SlaveState::WaitPrm);
  EXPECT_EQ(h.du(kM2, kS, kSapSlaveDiag, {}), (Bytes{0x02, 0x05, 0x00, 0xFF, 0x12, 0x34}));
  start_up(h, kPrmLockWd, {0x31}, kM2);
  EXPECT_EQ(h.du(kM1, kS, kSapSlaveDiag, {}), (Bytes{0x00, 0x0C, 0x00, 0x02, 0x12, 0x34}));
}

// --- services and states ----------------------------------------------------------------------

TEST(SlaveEngine, UnsupportedServicesAnswerRs) {
  SlaveEngine e(base_config({{0x31}}));
  Harness h(e);
  for (std::uint8_t sap : {std::uint8_t{53}, kSapSetSlaveAdd, kSapC1ReadWrite, kSapC1Alarm,
                           kSapC2ResourceManager, std::uint8_t{48}, std::uint8_t{0}}) {
    h.req(kM1, kS, sap, {0x5E, 0x00, 0x00, 0x04});
    EXPECT_EQ(h.last.kind, K::Status) << int(sap);
    EXPECT_EQ(h.last.status, ResponseStatus::RS) << int(sap);
  }
  // Rd_Inp / Rd_Outp / Data_Exchange outside Data_Exch.
  for (auto sap : {std::optional<std::uint8_t>(kSapRdInp), std::optional<std::uint8_t>(kSapRdOutp),
                   std::optional<std::uint8_t>()}) {
    h.req(kM1, kS, sap, {});
    EXPECT_EQ(h.last.status, ResponseStatus::RS);
  }
  // Unsupported in Data_Exch as well.
  start_up(h, kPrmLockWd, {0x31});
  h.req(kM1, kS, kSapC1ReadWrite, {0x5E, 0x00, 0x00, 0x04});
  EXPECT_EQ(h.last.status, ResponseStatus::RS);
  // SDN to a reply-less service gives no reply.
  h.req(kM1, kS, kSapSlaveDiag, {}, fdl::RequestFn::SdnHigh);
  EXPECT_EQ(h.last.kind, K::None);
}

TEST(SlaveEngine, WrongOutputLengthLeavesDataExchange) {
  SlaveEngine e(base_config({{0x31}}));
  Harness h(e);
  start_up(h, kPrmLockWd, {0x31});
  h.req(kM1, kS, kDx, {0x01, 0x02});
  EXPECT_EQ(h.last.kind, K::Data);
  h.req(kM1, kS, kDx, {0x01, 0x02, 0x03});
  EXPECT_EQ(h.last.status, ResponseStatus::RS);
  EXPECT_EQ(e.state(), SlaveState::WaitPrm);
  Bytes out(2);
  e.application().read_outputs(0, out);
  EXPECT_EQ(out, (Bytes{0, 0}));
  EXPECT_EQ(h.du(kM1, kS, kSapSlaveDiag, {}), (Bytes{0x02, 0x05, 0x00, 0xFF, 0x12, 0x34}));
  // Zero-length outputs without Fail_Safe are wrong as well.
  start_up(h, kPrmLockWd, {0x31});
  h.req(kM1, kS, kDx, {});
  EXPECT_EQ(h.last.status, ResponseStatus::RS);
}

TEST(SlaveEngine, FailSafeAcceptsZeroLengthOutputs) {
  auto cfg = base_config({{0x31}});
  cfg.features.fail_safe = true;
  SlaveEngine e(cfg);
  Harness h(e);
  start_up(h, kPrmLockWd, {0x31});
  e.application().write_inputs(0, Bytes{0x11, 0x22});
  h.req(kM1, kS, kDx, {0x0F, 0xF0});
  Bytes out(2);
  e.application().read_outputs(0, out);
  EXPECT_EQ(out, (Bytes{0x0F, 0xF0}));
  EXPECT_EQ(h.du(kM1, kS, kDx, {}), (Bytes{0x11, 0x22}));
  e.application().read_outputs(0, out);
  EXPECT_EQ(out, (Bytes{0, 0}));
  EXPECT_TRUE(e.application().outputs_safe());
  EXPECT_EQ(e.state(), SlaveState::DataExch);
}

TEST(SlaveEngine, SlaveWithoutInputsAnswersSc) {
  SlaveEngine e(base_config({{0x21}}));  // 2 bytes out only
  Harness h(e);
  start_up(h, kPrmLockWd, {0x21});
  EXPECT_EQ(h.req(kM1, kS, kDx, {0x01, 0x02}), Bytes{0xE5});
  // With a diagnosis pending it must say DH: a no-data response frame (SD1).
  e.application().set_ext_diag(true);
  EXPECT_EQ(hex(h.req(kM1, kS, kDx, {0x01, 0x02})), "10 01 0A 0A 15 16");
}

TEST(SlaveEngine, NewDiagnosisAnswersDhUntilOwnerReads) {
  SlaveEngine e(base_config({{0x31}, {0x10}}));
  Harness h(e);
  start_up(h, kPrmLockWd, {0x31, 0x10});
  h.req(kM1, kS, kDx, {0, 0});
  EXPECT_EQ(h.last.status, ResponseStatus::DL);
  auto& app = e.application();
  app.add_channel_diag({1, 1, ChannelDirection::Input, ChannelType::Bit, 1});
  app.set_device_diag(Bytes{0x20, 0x30});
  h.req(kM1, kS, kDx, {0, 0});
  EXPECT_EQ(h.last.status, ResponseStatus::DH);
  // Another master reading the diagnosis does not clear DH.
  const Bytes diag{0x08, 0x0C, 0x00, 0x01, 0x12, 0x34, 0x81, 0x41, 0x21, 0x03, 0x20, 0x30};
  EXPECT_EQ(h.du(kM2, kS, kSapSlaveDiag, {}), diag);
  h.req(kM1, kS, kDx, {0, 0});
  EXPECT_EQ(h.last.status, ResponseStatus::DH);
  EXPECT_EQ(h.du(kM1, kS, kSapSlaveDiag, {}), diag);
  h.req(kM1, kS, kDx, {0, 0});
  EXPECT_EQ(h.last.status, ResponseStatus::DL);
  // Module fault: identifier-related block (module 1), Stat_Diag.
  app.clear_channel_diags();
  app.set_device_diag({});
  app.set_module_state(1, ModuleState::Fault);
  app.set_stat_diag(true);
  h.req(kM1, kS, kDx, {0, 0});
  EXPECT_EQ(h.last.status, ResponseStatus::DH);
  EXPECT_EQ(h.du(kM1, kS, kSapSlaveDiag, {}),
            (Bytes{0x08, 0x0E, 0x00, 0x01, 0x12, 0x34, 0x42, 0x02}));
  app.set_module_state(1, ModuleState::Ok);
  app.set_stat_diag(false);
  app.set_ext_diag(true);
  EXPECT_EQ(h.du(kM1, kS, kSapSlaveDiag, {}), (Bytes{0x08, 0x0C, 0x00, 0x01, 0x12, 0x34}));
}

TEST(SlaveEngine, ExtDiagOverflow) {
  auto cfg = base_config({{0x31}});
  cfg.max_diag_len = 10;
  SlaveEngine e(cfg);
  Harness h(e);
  start_up(h, kPrmLockWd, {0x31});
  e.application().add_channel_diag({0, 0, ChannelDirection::Input, ChannelType::Bit, 1});
  e.application().add_channel_diag({0, 1, ChannelDirection::Input, ChannelType::Bit, 6});
  // Only the first channel block fits into 10 octets.
  EXPECT_EQ(h.du(kM1, kS, kSapSlaveDiag, {}),
            (Bytes{0x08, 0x0C, 0x80, 0x01, 0x12, 0x34, 0x80, 0x40, 0x21}));
}

// --- Global_Control -----------------------------------------------------------------------------

class SyncFreeze : public ::testing::Test {
 protected:
  SyncFreeze() : e(make()), h(e) {
    // Lock + WD + Sync_Req + Freeze_Req, group 1 (bit 0).
    start_up(h, {0xB8, 0x0A, 0x0A, 0x0B, 0x12, 0x34, 0x01}, {0x31});
  }
  static SlaveConfig make() {
    auto c = base_config({{0x31}});
    c.features.sync = c.features.freeze = true;
    return c;
  }
  Bytes outputs() {
    Bytes o(2);
    e.application().read_outputs(0, o);
    return o;
  }
  void gc(std::uint8_t cmd, std::uint8_t groups) {
    h.req(kM1, 127, kSapGlobalControl, {cmd, groups}, fdl::RequestFn::SdnHigh);
  }
  SlaveEngine e;
  Harness h;
};

TEST_F(SyncFreeze, SyncLatchesOutputs) {
  h.req(kM1, kS, kDx, {0x01, 0x02});
  EXPECT_EQ(outputs(), (Bytes{0x01, 0x02}));
  gc(0x20, 0x00);  // Sync, all groups
  EXPECT_TRUE(e.sync_mode());
  EXPECT_EQ(h.du(kM1, kS, kSapSlaveDiag, {}), (Bytes{0x00, 0x2C, 0x00, 0x01, 0x12, 0x34}));
  h.req(kM1, kS, kDx, {0x03, 0x04});
  EXPECT_EQ(outputs(), (Bytes{0x01, 0x02}));  // held
  EXPECT_EQ(h.du(kM1, kS, kSapRdOutp, {}), (Bytes{0x03, 0x04}));
  gc(0x20, 0x01);  // next Sync (our group) applies them
  EXPECT_EQ(outputs(), (Bytes{0x03, 0x04}));
  h.req(kM1, kS, kDx, {0x05, 0x06});
  gc(0x20, 0x02);  // Sync to group 2 only: not for us
  EXPECT_EQ(outputs(), (Bytes{0x03, 0x04}));
  gc(0x30, 0x00);  // Sync and Unsync together: Unsync wins
  EXPECT_FALSE(e.sync_mode());
  EXPECT_EQ(outputs(), (Bytes{0x05, 0x06}));
  h.req(kM1, kS, kDx, {0x07, 0x08});
  EXPECT_EQ(outputs(), (Bytes{0x07, 0x08}));
}

TEST_F(SyncFreeze, FreezeHoldsInputs) {
  auto& app = e.application();
  app.write_inputs(0, Bytes{0x11, 0x22});
  gc(0x08, 0x01);  // Freeze
  EXPECT_TRUE(e.freeze_mode());
  app.write_inputs(0, Bytes{0x33, 0x44});
  EXPECT_EQ(h.du(kM1, kS, kDx, {0, 0}), (Bytes{0x11, 0x22}));
  EXPECT_EQ(h.du(kM1, kS, kSapSlaveDiag, {}), (Bytes{0x00, 0x1C, 0x00, 0x01, 0x12, 0x34}));
  gc(0x08, 0x00);  // Freeze again: re-sample
  app.write_inputs(0, Bytes{0x55, 0x66});
  EXPECT_EQ(h.du(kM1, kS, kDx, {0, 0}), (Bytes{0x33, 0x44}));
  gc(0x08, 0x80);  // group 8 only: not for us
  EXPECT_EQ(h.du(kM1, kS, kDx, {0, 0}), (Bytes{0x33, 0x44}));
  gc(0x0C, 0x00);  // Freeze + Unfreeze: Unfreeze wins
  EXPECT_FALSE(e.freeze_mode());
  EXPECT_EQ(h.du(kM1, kS, kDx, {0, 0}), (Bytes{0x55, 0x66}));
}

TEST_F(SyncFreeze, ClearDataHoldsSafeOutputs) {
  h.req(kM1, kS, kDx, {0x01, 0x02});
  gc(0x02, 0x00);
  EXPECT_EQ(outputs(), (Bytes{0x00, 0x00}));
  h.req(kM1, kS, kDx, {0x03, 0x04});
  EXPECT_EQ(outputs(), (Bytes{0x00, 0x00}));
  EXPECT_TRUE(e.application().outputs_safe());
  EXPECT_EQ(h.du(kM1, kS, kSapRdOutp, {}), (Bytes{0x03, 0x04}));
  gc(0x00, 0x00);  // Operate
  h.req(kM1, kS, kDx, {0x05, 0x06});
  EXPECT_EQ(outputs(), (Bytes{0x05, 0x06}));
}

TEST(SlaveEngine, SyncWithoutEnablingIsIgnored) {
  auto c = base_config({{0x31}});
  c.features.sync = true;
  SlaveEngine e(c);
  Harness h(e);
  start_up(h, kPrmLockWd, {0x31});  // no Sync_Req
  h.req(kM1, 127, kSapGlobalControl, {0x20, 0x00}, fdl::RequestFn::SdnHigh);
  EXPECT_FALSE(e.sync_mode());
  h.req(kM1, kS, kDx, {0x03, 0x04});
  Bytes o(2);
  e.application().read_outputs(0, o);
  EXPECT_EQ(o, (Bytes{0x03, 0x04}));
}

// --- Set_Slave_Add ------------------------------------------------------------------------------

TEST(SlaveEngine, SetSlaveAddFrom126) {
  auto c = base_config({{0x31}});
  c.features.set_slave_add = true;
  SlaveEngine e(c);
  Harness h(e);
  // Diagnosis works at 126; Set_Prm does not.
  EXPECT_EQ(h.du(kM1, 126, kSapSlaveDiag, {}), (Bytes{0x02, 0x05, 0x00, 0xFF, 0x12, 0x34}));
  EXPECT_EQ(e.state(), SlaveState::PowerOn);
  h.req(kM1, 126, kSapSetPrm, kPrmLockWd);
  EXPECT_EQ(h.last.status, ResponseStatus::RS);
  // Wrong ident: refused.
  h.req(kM1, 126, kSapSetSlaveAdd, {0x05, 0x12, 0x35, 0x00});
  EXPECT_EQ(h.last.status, ResponseStatus::RS);
  // Appendix 1 frame: Set_Slave_Add 126 -> 5, ident 0x1234.
  EXPECT_EQ(hex(h.frame({0x68, 0x09, 0x09, 0x68, 0xFE, 0x81, 0x6D, 0x37, 0x3E, 0x05, 0x12, 0x34,
                         0x00, 0xAC, 0x16})),
            "E5");
  EXPECT_EQ(h.last.new_address, std::optional<std::uint8_t>(5));
  EXPECT_EQ(e.state(), SlaveState::WaitPrm);
  // From its new address it can be parameterised, and No_Add_Chg = 0 allows another change.
  h.req(kM1, 5, kSapSetSlaveAdd, {0x06, 0x12, 0x34, 0x01});
  EXPECT_EQ(h.last.kind, K::ShortAck);
  EXPECT_EQ(h.last.new_address, std::optional<std::uint8_t>(6));
  // No_Add_Chg = 1: no further change until a factory reset.
  h.req(kM1, 6, kSapSetSlaveAdd, {0x07, 0x12, 0x34, 0x00});
  EXPECT_EQ(h.last.status, ResponseStatus::RS);
  e.factory_reset();
  h.req(kM1, 6, kSapSetSlaveAdd, {0x80, 0x12, 0x34, 0x00});  // address 128: invalid
  EXPECT_EQ(h.last.status, ResponseStatus::RS);
  h.req(kM1, 6, kSapSetSlaveAdd, {0x07, 0x12, 0x34, 0x00});
  EXPECT_EQ(h.last.new_address, std::optional<std::uint8_t>(7));
  // Not in Data_Exch.
  ASSERT_EQ(h.req(kM1, 7, kSapSetPrm, kPrmLockWd), Bytes{0xE5});
  ASSERT_EQ(h.req(kM1, 7, kSapChkCfg, {0x31}), Bytes{0xE5});
  h.req(kM1, 7, kSapSetSlaveAdd, {0x08, 0x12, 0x34, 0x00});
  EXPECT_EQ(h.last.status, ResponseStatus::RS);
}

TEST(SlaveEngine, BadConfigurationIsRejected) {
  SlaveConfig c = base_config({{0x41}});  // special format, length octet missing
  EXPECT_THROW(SlaveEngine{c}, std::invalid_argument);
  c = base_config({{0x1F}, {0x1F}, {0x1F}, {0x1F}, {0x1F}, {0x1F}, {0x1F}, {0x1F}, {0x1F},
                   {0x1F}, {0x1F}, {0x1F}, {0x1F}, {0x1F}, {0x1F}, {0x1F}});  // 256 bytes in
  EXPECT_THROW(SlaveEngine{c}, std::invalid_argument);
  c = base_config({{0x10}});
  c.features.dpv1 = true;  // needs 3 user prm octets
  EXPECT_THROW(SlaveEngine{c}, std::invalid_argument);
}

}  // namespace
}  // namespace pbvbus::dp
