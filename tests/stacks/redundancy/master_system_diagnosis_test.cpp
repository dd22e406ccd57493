// redundancy::MasterSystem::on_diagnosis (master_system.hpp "Diagnosis changes"): the content of
// a station's diagnosis on its ACTIVE channel, without the per-line Red_Status, for the
// H-system's OB 82 of DP-V0 slaves (F3) and of slaves in STOP (F15). Driven by hand-made master
// events (no bus); the Slave_Diag octets are written out in the test.
#include <gtest/gtest.h>

#include <vector>

#include "pbvbus/dp/master.hpp"
#include "pbvbus/redundancy/master_system.hpp"

namespace pbvbus::redundancy {
namespace {

constexpr bus::Ticks kMs = bus::kTicksPerMs;

dp::SlaveParams slave(std::uint8_t a, bool switched) {
  dp::SlaveParams p;
  p.address = a;
  p.ident = 0x0A10;
  p.user_prm = {0x80, 0x00, 0x00};
  p.modules = {{{0x11}, "2 byte in"}};
  if (switched) p.prm_cmd.assign(8, 0);
  return p;
}

struct Fix {
  dp::Master a{dp::MasterParams{}, {slave(5, true), slave(10, false)}};
  dp::Master b{dp::MasterParams{}, {slave(5, true)}};
  MasterSystem ms{a, b, {{5, 30 * kMs, false}}};
  std::vector<SystemDiagnosis> got;
  Fix() {
    ms.on_diagnosis([this](const SystemDiagnosis& d) { got.push_back(d); });
  }
  void event(int line, dp::MasterEvent::Kind k, std::uint8_t slave, bus::Ticks t,
             std::vector<std::uint8_t> diag = {}) {
    dp::MasterEvent e;
    e.kind = k;
    e.slave = slave;
    e.time = t;
    e.diag = diag;
    ms.on_master_event(line, e);
  }
};

// Standard octets of a slave in data exchange with master 2 (WD_On + always-1), ident 0A10.
std::vector<std::uint8_t> diag(std::vector<std::uint8_t> ext, std::uint8_t st1 = 0x00) {
  std::vector<std::uint8_t> d;
  d.reserve(6 + ext.size());  // (GCC 12's -Warray-bounds misfires on insert into a 6-octet one)
  for (std::uint8_t b : {st1, std::uint8_t{0x0C}, std::uint8_t{0x00}, std::uint8_t{0x02},
                         std::uint8_t{0x0A}, std::uint8_t{0x10}})
    d.push_back(b);
  for (std::uint8_t b : ext) d.push_back(b);
  return d;
}
// Red_Status (0x9F), Red_State_1 = Primary | Data_Exchange (0x0A) or Backup | DX (0x09).
std::vector<std::uint8_t> red(bool primary) {
  return {0x08, 0x9F, 0x00, 0x00, 0x00, static_cast<std::uint8_t>(primary ? 0x0A : 0x09), 0x00,
          0x00};
}

TEST(MasterSystemDiagnosis, OneSidedSlaveChangeIsDeliveredOnceWithContent) {
  Fix f;
  using K = dp::MasterEvent::Kind;
  f.event(0, K::DataExchangeEntered, 10, 1 * kMs, diag({}));
  // Channel block: module 0, channel 1, input, bit, short circuit (88 41 21).
  const auto d1 = diag({0x88, 0x41, 0x21}, 0x08);
  f.event(0, K::Diagnosis, 10, 5 * kMs, d1);
  ASSERT_EQ(f.got.size(), 1u);
  EXPECT_EQ(f.got[0].time, 5 * kMs);
  EXPECT_EQ(f.got[0].station, 10);
  EXPECT_EQ(f.got[0].line, 0);
  EXPECT_EQ(f.got[0].diag, d1);
  EXPECT_TRUE(f.got[0].previous.empty());
  EXPECT_EQ(diagnosis_content(d1), (std::vector<std::uint8_t>{0x88, 0x41, 0x21}));
  // The same content again (a DH read, another standard octet): nothing.
  f.event(0, K::Diagnosis, 10, 6 * kMs, diag({0x88, 0x41, 0x21}, 0x08 | 0x02));
  EXPECT_EQ(f.got.size(), 1u);
  // Gone.
  f.event(0, K::Diagnosis, 10, 9 * kMs, diag({}));
  ASSERT_EQ(f.got.size(), 2u);
  EXPECT_EQ(f.got[1].time, 9 * kMs);
  EXPECT_EQ(f.got[1].previous, d1);
  EXPECT_EQ(f.ms.diagnosis_changes(), 2u);
}

TEST(MasterSystemDiagnosis, SwitchedStationOnlyActiveChannelAndRedStatusIgnored) {
  Fix f;
  using K = dp::MasterEvent::Kind;
  // Both channels up; line A's diagnosis says Primary: A is active.
  f.event(0, K::DataExchangeEntered, 5, 1 * kMs, diag(red(true)));
  f.event(1, K::DataExchangeEntered, 5, 1 * kMs, diag(red(false)));
  ASSERT_EQ(f.ms.active(5), 0);
  // The passive channel's (B) diagnosis with a channel fault: not the program's.
  auto fault = red(false);
  for (int b : {0x88, 0x41, 0x21}) fault.push_back(static_cast<std::uint8_t>(b));
  f.event(1, K::Diagnosis, 5, 3 * kMs, diag(fault, 0x08));
  EXPECT_TRUE(f.got.empty());
  // Line A: Red_Status only (a new Seq_Nr): no content change.
  auto a2 = red(true);
  a2[3] = 0x08;  // Seq_Nr 1
  f.event(0, K::Diagnosis, 5, 4 * kMs, diag(a2));
  EXPECT_TRUE(f.got.empty());
  // Line A with the channel fault: delivered, line 0.
  auto a3 = red(true);
  for (int b : {0x88, 0x41, 0x21}) a3.push_back(static_cast<std::uint8_t>(b));
  f.event(0, K::Diagnosis, 5, 7 * kMs, diag(a3, 0x08));
  ASSERT_EQ(f.got.size(), 1u);
  EXPECT_EQ(f.got[0].line, 0);
  EXPECT_EQ(f.got[0].time, 7 * kMs);
  EXPECT_EQ(diagnosis_content(f.got[0].diag), (std::vector<std::uint8_t>{0x88, 0x41, 0x21}));
}

TEST(MasterSystemDiagnosis, BrokenBlockLengthIsNoContent) {
  // 0x0A says 10 octets, only 3 follow: no blocks (no crash).
  EXPECT_TRUE(diagnosis_content(diag({0x0A, 0x01, 0x02})).empty());
  EXPECT_TRUE(diagnosis_content(std::vector<std::uint8_t>{0x00, 0x0C}).empty());
}

}  // namespace
}  // namespace pbvbus::redundancy
