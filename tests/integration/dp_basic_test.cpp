// examples/dp-basic.textproto run whole in fast mode: every slave reaches Data_Exch; each
// slave's start-up on the wire carries exactly the Set_Prm / Chk_Cfg octets a configuration
// tool derives from its GSD (worked out by hand below from examples/gsd/*.gsd); and the DP
// cycle time equals the sum of the frame lengths and bus-parameter idle times, in bit times.
#include <gtest/gtest.h>

#include <algorithm>
#include <map>
#include <set>

#include "frame_recorder.hpp"
#include "pbvbus/scenario/scenario.hpp"
#include "pbvbus/simulation/simulation.hpp"

namespace pbvbus::tools {
namespace {

using Bytes = std::vector<std::uint8_t>;

// FDL framing written out in the test (protocol-facts.md §B.1): the FCS is the sum of DA, SA,
// FC and the DU, modulo 256. DP start-up frames carry DAE/SAE: DA and SA with bit 7 set.
Bytes sd2(std::uint8_t da, std::uint8_t sa, std::uint8_t fc, const Bytes& du) {
  const auto le = static_cast<std::uint8_t>(du.size() + 3);
  Bytes f{0x68, le, le, 0x68, da, sa, fc};
  f.insert(f.end(), du.begin(), du.end());
  unsigned sum = da + sa + fc;
  for (auto b : du) sum += b;
  f.push_back(static_cast<std::uint8_t>(sum & 0xFF));
  f.push_back(0x16);
  return f;
}

struct DpRun {
  std::unique_ptr<Simulation> sim;
  test::FrameRecorder rec;
};

std::unique_ptr<DpRun> run_dp_basic() {
  auto r = std::make_unique<DpRun>();
  const auto loaded = load_scenario_file(PBVBUS_SOURCE_DIR "/examples/dp-basic.textproto");
  EXPECT_TRUE(loaded.ok()) << (loaded.errors.empty() ? "" : loaded.errors.front().str());
  if (!loaded.ok()) return nullptr;
  r->sim = std::make_unique<Simulation>(*loaded.plan);
  r->sim->line(0).add_tap(r->rec);
  r->sim->run_until(*r->sim->duration());
  return r;
}

class DpBasic : public ::testing::Test {
 protected:
  static void SetUpTestSuite() { s_run = run_dp_basic().release(); }
  static void TearDownTestSuite() {
    delete s_run;
    s_run = nullptr;
  }
  static DpRun* s_run;
};
DpRun* DpBasic::s_run = nullptr;

TEST_F(DpBasic, EverySlaveReachesDataExchange) {
  ASSERT_NE(s_run, nullptr);
  const DpMasterNode* m = s_run->sim->dp_master(0, 1);
  ASSERT_NE(m, nullptr);
  EXPECT_EQ(m->master().mode(), dp::MasterMode::Operate);
  for (std::uint8_t a : {std::uint8_t{3}, std::uint8_t{4}, std::uint8_t{5}}) {
    const DpSlaveNode* s = s_run->sim->dp_slave(0, a);
    ASSERT_NE(s, nullptr) << int(a);
    EXPECT_EQ(s->engine().state(), dp::SlaveState::DataExch) << int(a);
    EXPECT_EQ(m->master().slave_state(a), dp::SlaveStatusState::DataExchange) << int(a);
    EXPECT_EQ(m->master().slave_stats(a).failures, 0u);
    EXPECT_EQ(m->master().slave_stats(a).startups, 1u);
    EXPECT_GT(m->master().slave_stats(a).data_exchanges, 1000u);
  }
  const Report rep = s_run->sim->report(0.0);
  ASSERT_EQ(rep.dp_masters.size(), 1u);
  ASSERT_EQ(rep.dp_masters[0].slaves.size(), 3u);
  // Master's stored diagnosis of slave 3: Always_1 + WD_On, owner 1, ident 0x0A01.
  EXPECT_EQ(rep.dp_masters[0].slaves[0].diag, (Bytes{0x00, 0x0C, 0x00, 0x01, 0x0A, 0x01}));
  EXPECT_GT(rep.dp_masters[0].global_controls, 30u);  // 2 s / 60 ms
}

// The first four frames the master sends to each slave: Slave_Diag (first frame: FCB=1 FCV=0,
// FC 6D), Set_Prm (5D), Chk_Cfg (7D), Slave_Diag (5D). Set_Prm octets: Station_Status 88
// (Lock_Req, WD_On), WD_Fact 01 0A (watchdog "100ms" = 10 × 10 ms), min TSDR 0B (11), ident,
// Group_Ident 00, then the User_Prm_Data assembled from the GSD defaults.
TEST_F(DpBasic, StartUpFramesMatchTheGsds) {
  ASSERT_NE(s_run, nullptr);
  const std::map<std::uint8_t, Bytes> prm = {
      // PBVB0A01: User_Prm_Data_Len 1, 0x00; ref 1 Bit(1)=1 → 02, ref 2 BitArea(4-5)=1 → 10,
      // ref 3 Bit(0)=0: 0x12.
      {3, {0x88, 0x01, 0x0A, 0x0B, 0x0A, 0x01, 0x00, 0x12}},
      // PBVB0A02: global 1 octet, ref 1 Bit(0)=1 → 01; "8DI": ref 10 BitArea(0-1)=1 → 01;
      // "8DO": ref 11 Bit(0)=0 → 00; "2AO": 2 octets, ref 30 Unsigned8 = 2 at 0 and 1 → 02 02.
      {4, {0x88, 0x01, 0x0A, 0x0B, 0x0A, 0x02, 0x00, 0x01, 0x01, 0x00, 0x02, 0x02}},
      // PBVB0A03 (DP-V1): global 4 octets 80 00 00 00; at 1 ref 1/2/3 Bits 5/6/7 = 1 → E0
      // (diagnostic, process, pull/plug alarm enabled); at 3 ref 4 Bit(0)=1 → 01;
      // "8DI with process alarm": ref 10 BitArea(0-1)=1 → 01; "8DO": nothing;
      // "2AI": ref 11 Unsigned8 = 3, ref 12 Signed16 = 27648 = 6C 00.
      {5, {0x88, 0x01, 0x0A, 0x0B, 0x0A, 0x03, 0x00, 0x80, 0xE0, 0x00, 0x01, 0x01, 0x03, 0x6C,
           0x00}},
  };
  const std::map<std::uint8_t, Bytes> cfg = {
      {3, {0x11, 0x21}},        // "16DI/16DO DC24V"
      {4, {0x10, 0x20, 0x61}},  // 8DI, 8DO, 2AO (2 words out)
      {5, {0x10, 0x20, 0xD1}},  // 8DI, 8DO, 2AI consistent (2 words in)
  };
  for (std::uint8_t a : {std::uint8_t{3}, std::uint8_t{4}, std::uint8_t{5}}) {
    std::vector<Bytes> sent;
    for (const auto& f : s_run->rec.frames()) {
      if (f.bytes.size() < 7 || f.bytes[0] != 0x68) continue;
      if ((f.bytes[4] & 0x7F) != a || (f.bytes[6] & 0x40) == 0) continue;  // requests to a
      sent.push_back(f.bytes);
      if (sent.size() == 4) break;
    }
    ASSERT_EQ(sent.size(), 4u) << int(a);
    const auto da = static_cast<std::uint8_t>(0x80 | a);
    Bytes set_prm{0x3D, 0x3E};
    set_prm.insert(set_prm.end(), prm.at(a).begin(), prm.at(a).end());
    Bytes chk_cfg{0x3E, 0x3E};
    chk_cfg.insert(chk_cfg.end(), cfg.at(a).begin(), cfg.at(a).end());
    EXPECT_EQ(sent[0], sd2(da, 0x81, 0x6D, {0x3C, 0x3E})) << "Slave_Diag to " << int(a);
    EXPECT_EQ(sent[1], sd2(da, 0x81, 0x5D, set_prm)) << "Set_Prm to " << int(a);
    EXPECT_EQ(sent[2], sd2(da, 0x81, 0x7D, chk_cfg)) << "Chk_Cfg to " << int(a);
    EXPECT_EQ(sent[3], sd2(da, 0x81, 0x5D, {0x3C, 0x3E})) << "Slave_Diag to " << int(a);
  }
  // Appendix 1 check of the helper itself: Slave_Diag master 1 → slave 10.
  EXPECT_EQ(sd2(0x8A, 0x81, 0x6D, {0x3C, 0x3E}),
            (Bytes{0x68, 0x05, 0x05, 0x68, 0x8A, 0x81, 0x6D, 0x3C, 0x3E, 0xF2, 0x16}));
}

// DP cycle time of dp-basic in bit times at 1.5 Mbit/s. Bus parameters: min TSDR 11, max TSDR
// 150, TSET 1, TQUI 0 → TID1 = max(33 + 2 + 2·1 + 0, 11) = 37; TID2 = max(37, 150) = 150;
// TSL 300. Data_Exchange uses the default SAP: SD2 = 9 + n octets for n data octets (n ≠ 8),
// 11 bits per octet.
//
//   slave 3: request 2 outputs  11·(9+2) = 121, TSDR 11, response 2 inputs 11·(9+2) = 121,
//            TID1 37                                                           =  290
//   slave 4: request 5 outputs  11·(9+5) = 154, TSDR 30 (tsdr_bits), response 1 input
//            11·(9+1) = 110, TID1 37                                           =  331
//   slave 5: request 1 output   11·(9+1) = 110, TSDR 11, response 5 inputs 11·(9+5) = 154,
//            TID1 37                                                           =  312
//   token to itself (SD4, 3 octets) 11·3 = 33, TID1 37                         =   70
//                                                              plain cycle    = 1003
//   + an unanswered GAP poll (FDL_Status SD1 6 octets, 66, then TSL 300)      =  366
//   + a Global_Control (SDN, SD2 with SAPs 58/62 and 2 octets: 11·13 = 143, then TID2 150)
//                                                                              =  293
//   + a GAP poll that a slave answers: 66 + its TSDR + 66 (SD1 reply) + TID1 37.
// With one master and HSA 126, the GAP (addresses 2..126) takes 125 rotations to walk through
// and a new walk begins every G = 10 rotations at the earliest, so almost every rotation
// carries one GAP poll, and most of them find no station: the median is 1003 + 366 = 1369.
TEST_F(DpBasic, DpCycleTimeIsTheSumOfFramesAndIdleTimes) {
  ASSERT_NE(s_run, nullptr);
  constexpr std::int64_t kPlain = 290 + 331 + 312 + 70;
  static_assert(kPlain == 1003);
  constexpr std::int64_t kGapAbsent = 66 + 300;
  constexpr std::int64_t kGc = 143 + 150;
  constexpr std::int64_t kGapSlave3 = 66 + 11 + 66 + 37;
  constexpr std::int64_t kGapSlave4 = 66 + 30 + 66 + 37;
  constexpr std::int64_t kGapSlave5 = 66 + 11 + 66 + 37;
  const auto bit = bus::ticks_per_bit(bus::Baud::k1_5M);
  const dp::Master& m = s_run->sim->dp_master(0, 1)->master();
  for (std::uint8_t a : {std::uint8_t{3}, std::uint8_t{4}, std::uint8_t{5}}) {
    EXPECT_EQ(m.cycle_median(a), (kPlain + kGapAbsent) * bit) << int(a);
    // Over the whole run: the shortest cycle has neither GAP poll nor Global_Control, the
    // longest has both (an unanswered GAP poll).
    EXPECT_EQ(m.slave_stats(a).cycle_min, kPlain * bit) << int(a);
    EXPECT_EQ(m.slave_stats(a).cycle_max, (kPlain + kGc + kGapAbsent) * bit) << int(a);
  }

  // Every steady-state cycle (after 100 ms) of slave 3, from the wire: the time between the
  // starts of two Data_Exchange requests to it is one of the explained sums.
  const std::set<std::int64_t> allowed = {
      kPlain,          kPlain + kGapAbsent,       kPlain + kGc,
      kPlain + kGc + kGapAbsent, kPlain + kGapSlave3, kPlain + kGapSlave4,
      kPlain + kGapSlave5, kPlain + kGc + kGapSlave3, kPlain + kGc + kGapSlave4,
      kPlain + kGc + kGapSlave5};
  std::map<std::int64_t, int> seen;
  bus::Ticks last = -1;
  const bus::Ticks from = bus::kTicksPerSecond / 10;
  for (const auto& f : s_run->rec.frames()) {
    // Data_Exchange request to 3: SD2, DA 03 (no DAE), SA 01, FC with bit 6 set.
    if (f.bytes.size() != 11 || f.bytes[0] != 0x68 || f.bytes[4] != 0x03 ||
        (f.bytes[6] & 0x40) == 0)
      continue;
    if (last >= from) {
      const auto d = f.start - last;
      EXPECT_EQ(d % bit, 0);
      ++seen[d / bit];
    }
    last = f.start;
  }
  ASSERT_FALSE(seen.empty());
  int total = 0;
  for (const auto& [bits, n] : seen) {
    EXPECT_TRUE(allowed.count(bits)) << "unexplained DP cycle of " << bits << " bit times (" << n
                                     << " times)";
    total += n;
  }
  EXPECT_GT(seen[kPlain + kGapAbsent], total / 2);  // the median
  EXPECT_GT(seen[kPlain], 0);                       // rotations without a GAP poll
  EXPECT_GT(seen[kPlain + kGc + kGapAbsent] + seen[kPlain + kGc], 0);  // Global_Control
}

}  // namespace
}  // namespace pbvbus::tools
