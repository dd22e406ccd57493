// Slave engine hooks for PI 2.212 slave redundancy (protocol-facts.md §G.2, §G.3, §D.2, §D.5):
// the PrmCmd block in Set_Prm handed to SlaveConfig::on_prm_cmd, the "pure PrmCmd" Set_Prm that
// keeps data exchange, status blocks in the diagnosis and the DH reply that makes the master
// fetch them. Octets written out by hand from the reference tables.
#include <gtest/gtest.h>

#include "pbvbus/dp/slave_engine.hpp"
#include "slave_harness.hpp"

namespace pbvbus::dp {
namespace {

using test::Bytes;
using test::Harness;
using test::hex;

constexpr std::uint8_t kM1 = 1;
constexpr std::uint8_t kM2 = 2;
constexpr std::uint8_t kS = 10;

// Set_Prm DU, octet by octet (§D.2, §G.2):
//   88        Station_Status: Lock_Req 0x80 | WD_On 0x08
//   0A 0A     WD_Fact_1, WD_Fact_2 (TWD = 10 ms × 10 × 10 = 1 s)
//   0B        min TSDR 11
//   12 34     Ident_Number
//   00        Group_Ident
//   80        DPV1_Status_1: DPV1_Enable
//   00        DPV1_Status_2
//   88        DPV1_Status_3: PrmCmd 0x80 | Prm_Structure 0x08
//   08 02 00  PrmCmd block: Structure_Length 8, Structure_Type 2, slot 0
//   <seq>     Seq_Nr << 3
//   <fn>      Function (Primary_Request = 0x02)
//   04        Properties: Address_Change (system redundancy)
//   00 1E     Output_Hold_Time 30 × 10 ms = 300 ms
Bytes set_prm(std::uint8_t seq_octet, std::uint8_t function) {
  return {0x88, 0x0A, 0x0A, 0x0B, 0x12, 0x34, 0x00, 0x80, 0x00, 0x88,
          0x08, 0x02, 0x00, seq_octet, function, 0x04, 0x00, 0x1E};
}

struct Seen {
  std::vector<Bytes> blocks;
  std::vector<bool> pure;
  std::vector<std::uint8_t> masters;
  PrmCmdResult answer = PrmCmdResult::Accept;
};

SlaveConfig config(Seen& seen) {
  SlaveConfig c;
  c.ident = 0x1234;
  c.modules = {{{0x10}, "in"}, {{0x20}, "out"}};
  c.features.dpv1 = true;
  c.features.prm_cmd = c.features.prm_structure = true;
  c.min_user_prm_len = 3;
  c.max_user_prm_len = 3 + 8 + 4;
  c.on_prm_cmd = [&seen](const PrmCmdView& v) {
    seen.blocks.emplace_back(v.block.begin(), v.block.end());
    seen.pure.push_back(v.pure);
    seen.masters.push_back(v.master);
    return seen.answer;
  };
  return c;
}

TEST(SlavePrmCmd, BlockHandedOverAndPurePrmCmdKeepsDataExchange) {
  Seen seen;
  SlaveEngine e(config(seen));
  Harness h(e);
  e.application().write_inputs(0, Bytes{0x3C});
  // Full parameterisation with a PrmCmd block (Seq_Nr 1 → 0x08, Primary_Request): SC.
  EXPECT_EQ(h.req(kM1, kS, kSapSetPrm, set_prm(0x08, 0x02)), Bytes{0xE5});
  ASSERT_EQ(seen.blocks.size(), 1u);
  EXPECT_EQ(hex(seen.blocks[0]), "08 02 00 08 02 04 00 1E");
  EXPECT_FALSE(seen.pure[0]);
  EXPECT_EQ(seen.masters[0], kM1);
  EXPECT_EQ(e.state(), SlaveState::WaitCfg);
  EXPECT_EQ(h.req(kM1, kS, kSapChkCfg, {0x10, 0x20}), Bytes{0xE5});
  ASSERT_EQ(e.state(), SlaveState::DataExch);
  // Data_Exchange, outputs 55: reply SD2 DA 01 SA 0A FC 08 (DL) data 3C,
  // FCS = 01 + 0A + 08 + 3C = 0x4F.
  EXPECT_EQ(hex(h.req(kM1, kS, std::nullopt, {0x55})), "68 04 04 68 01 0A 08 3C 4F 16");
  Bytes out(1);
  ASSERT_TRUE(e.application().read_outputs(1, out));
  EXPECT_EQ(out[0], 0x55);

  // Pure PrmCmd (18 octets) in Data_Exch, Seq_Nr 2 → 0x10, Master_State_Clear 0x40: SC, the
  // block reaches the hook as pure, the slave stays in Data_Exch with its outputs.
  EXPECT_EQ(h.req(kM1, kS, kSapSetPrm, set_prm(0x10, 0x40)), Bytes{0xE5});
  ASSERT_EQ(seen.blocks.size(), 2u);
  EXPECT_EQ(hex(seen.blocks[1]), "08 02 00 10 40 04 00 1E");
  EXPECT_TRUE(seen.pure[1]);
  EXPECT_EQ(e.state(), SlaveState::DataExch);
  ASSERT_TRUE(e.application().read_outputs(1, out));
  EXPECT_EQ(out[0], 0x55);
  EXPECT_FALSE(e.application().outputs_safe());

  // The redundancy layer answers with a Prm_Cmd_Ack status block (§G.3):
  // 08 9E 00 <Seq_Nr 2 = 0x10> <Function 0x40> <Red_State_1: Primary 0x02 | Data_Exchange 0x08
  // = 0x0A> <Red_State_2: Backup 0x01 | Data_Exchange 0x08 = 0x09> 00.
  ASSERT_TRUE(e.application().set_status(0x9E, 0, 0x10, Bytes{0x40, 0x0A, 0x09, 0x00}));
  // The next Data_Exchange answers DH: FC 0x0A, FCS = 01 + 0A + 0A + 3C = 0x51.
  EXPECT_EQ(hex(h.req(kM1, kS, std::nullopt, {0x55})), "68 04 04 68 01 0A 0A 3C 51 16");
  // Slave_Diag: 00 (ready; status PDUs alone do not set Ext_Diag), 0C (WD_On 0x08 | 0x04),
  // 00, master 01, ident 12 34, then the block.
  EXPECT_EQ(hex(h.du(kM1, kS, kSapSlaveDiag, {})), "00 0C 00 01 12 34 08 9E 00 10 40 0A 09 00");
  // Read by the owner: DL again.
  EXPECT_EQ(hex(h.req(kM1, kS, std::nullopt, {0x55})), "68 04 04 68 01 0A 08 3C 4F 16");
  // request_diag_read(): DH without a diagnosis change, until the owner reads.
  e.application().request_diag_read();
  EXPECT_EQ(hex(h.req(kM1, kS, std::nullopt, {0x55})), "68 04 04 68 01 0A 0A 3C 51 16");
  EXPECT_EQ(hex(h.du(kM2, kS, kSapSlaveDiag, {})), "00 0C 00 01 12 34 08 9E 00 10 40 0A 09 00");
  EXPECT_EQ(hex(h.req(kM1, kS, std::nullopt, {0x55})), "68 04 04 68 01 0A 0A 3C 51 16");
  h.du(kM1, kS, kSapSlaveDiag, {});
  EXPECT_EQ(hex(h.req(kM1, kS, std::nullopt, {0x55})), "68 04 04 68 01 0A 08 3C 4F 16");

  // A pure PrmCmd from another master: SC, ignored (locked).
  EXPECT_EQ(h.req(kM2, kS, kSapSetPrm, set_prm(0x18, 0x02)), Bytes{0xE5});
  EXPECT_EQ(seen.blocks.size(), 2u);
  // A rejected pure PrmCmd is a Prm_Fault: Wait_Prm, outputs safe.
  seen.answer = PrmCmdResult::Reject;
  EXPECT_EQ(h.req(kM1, kS, kSapSetPrm, set_prm(0x18, 0x02)), Bytes{0xE5});
  EXPECT_EQ(e.state(), SlaveState::WaitPrm);
  EXPECT_TRUE(e.application().outputs_safe());
  EXPECT_EQ(hex(h.du(kM1, kS, kSapSlaveDiag, {})), "42 05 00 FF 12 34 08 9E 00 10 40 0A 09 00");
}

TEST(SlavePrmCmd, PurePrmCmdToAnUnparameterisedSlaveIsAFullSetPrm) {
  Seen seen;
  SlaveEngine e(config(seen));
  Harness h(e);
  h.req(kM1, kS, kSapSetPrm, set_prm(0x08, 0x02));
  EXPECT_EQ(e.state(), SlaveState::WaitCfg);
  ASSERT_EQ(seen.pure.size(), 1u);
  EXPECT_FALSE(seen.pure[0]);
  EXPECT_EQ(e.watchdog_time(), 1000 * bus::kTicksPerMs);
  // In Wait_Cfg the same length from the owner is pure: the watchdog factors are not re-read.
  Bytes p = set_prm(0x10, 0x02);
  p[1] = 0x01;
  h.req(kM1, kS, kSapSetPrm, p);
  EXPECT_TRUE(seen.pure.back());
  EXPECT_EQ(e.watchdog_time(), 1000 * bus::kTicksPerMs);
  EXPECT_EQ(e.state(), SlaveState::WaitCfg);
}

TEST(SlavePrmCmd, MalformedPrmCmdBlocksArePrmFaults) {
  Seen seen;
  const auto fault = [&](const Bytes& du) {
    SlaveEngine e(config(seen));
    Harness h(e);
    h.req(kM1, kS, kSapSetPrm, du);
    return hex(h.du(kM1, kS, kSapSlaveDiag, {}));
  };
  const std::string prm_fault = "42 05 00 FF 12 34";
  // PrmCmd block without the PrmCmd bit (DPV1_Status_3 = Prm_Structure 0x08 only).
  Bytes b = set_prm(0x08, 0x02);
  b[9] = 0x08;
  EXPECT_EQ(fault(b), prm_fault);
  // A 12-octet block of type 2 (chains correctly, but PrmCmd is 8 octets).
  b = set_prm(0x08, 0x02);
  b[10] = 0x0C;
  b.insert(b.end(), {0, 0, 0, 0});
  EXPECT_EQ(fault(b), prm_fault);
  // Two PrmCmd blocks.
  b = set_prm(0x08, 0x02);
  b.insert(b.end(), {0x04, 0x02, 0x00, 0x00});
  EXPECT_EQ(fault(b), prm_fault);
  EXPECT_TRUE(seen.blocks.empty());  // never handed over
  // The hook's Reject on a full Set_Prm.
  seen.answer = PrmCmdResult::Reject;
  EXPECT_EQ(fault(set_prm(0x08, 0x02)), prm_fault);
  EXPECT_EQ(seen.blocks.size(), 1u);
  // Without the hook a valid block is accepted and ignored.
  SlaveConfig c = config(seen);
  c.on_prm_cmd = nullptr;
  SlaveEngine e(c);
  Harness h(e);
  h.req(kM1, kS, kSapSetPrm, set_prm(0x08, 0x02));
  EXPECT_EQ(e.state(), SlaveState::WaitCfg);
}

}  // namespace
}  // namespace pbvbus::dp
