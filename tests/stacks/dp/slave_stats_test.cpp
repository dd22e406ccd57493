// The slave engine's own view for reports (SlaveStats, last_inputs, last_outputs): what it was
// asked, by whom, and what became of it — independent of any master's bookkeeping.
#include <gtest/gtest.h>

#include "pbvbus/dp/slave_engine.hpp"
#include "slave_harness.hpp"

namespace pbvbus::dp {
namespace {

using test::Bytes;
using test::Harness;
using fdl::ResponseStatus;

constexpr std::uint8_t kM1 = 1;
constexpr std::uint8_t kM2 = 2;
constexpr std::uint8_t kS = 10;
constexpr auto kDx = std::nullopt;
const Bytes kPrmLockWd = {0x88, 0x0A, 0x0A, 0x0B, 0x12, 0x34, 0x00};  // 1 s watchdog

SlaveConfig config_2in_2out() {
  SlaveConfig c;
  c.ident = 0x1234;
  c.modules.push_back({{0x31}, "2 in / 2 out"});
  return c;
}

std::vector<std::uint8_t> vec(std::span<const std::uint8_t> s) { return {s.begin(), s.end()}; }

TEST(SlaveStats, CountsEveryServiceOfAStartUpAndTheCycles) {
  SlaveEngine e(config_2in_2out());
  Harness h(e);
  EXPECT_EQ(vec(e.last_inputs()), (Bytes{0, 0}));
  EXPECT_EQ(vec(e.last_outputs()), (Bytes{0, 0}));
  h.req(kM1, kS, kSapSlaveDiag, {});
  h.req(kM1, kS, kSapSetPrm, kPrmLockWd);
  h.req(kM1, kS, kSapChkCfg, {0x31});
  h.req(kM1, kS, kSapSlaveDiag, {});
  ASSERT_EQ(e.state(), SlaveState::DataExch);
  for (std::uint8_t i = 0; i < 5; ++i) {
    ASSERT_TRUE(e.application().write_inputs(0, Bytes{0x02, static_cast<std::uint8_t>(0x20 + i)}));
    h.req(kM1, kS, kDx, {0xA0, i});
    ASSERT_EQ(h.last.status, ResponseStatus::DL);
  }
  h.req(kM1, 127, kSapGlobalControl, {0x00, 0x00}, fdl::RequestFn::SdnHigh);
  h.req(kM1, kS, kSapGetCfg, {});
  h.req(kM1, kS, kSapRdInp, {});
  h.req(kM1, kS, kSapRdOutp, {});
  const SlaveStats& s = e.stats();
  EXPECT_EQ(s.slave_diag, 2u);
  EXPECT_EQ(s.set_prm, 1u);
  EXPECT_EQ(s.chk_cfg, 1u);
  EXPECT_EQ(s.data_exchange, 5u);
  EXPECT_EQ(s.global_control, 1u);
  EXPECT_EQ(s.get_cfg, 1u);
  EXPECT_EQ(s.rd_inp, 1u);
  EXPECT_EQ(s.rd_outp, 1u);
  EXPECT_EQ(s.refused, 0u);
  EXPECT_EQ(s.prm_faults, 0u);
  EXPECT_EQ(s.cfg_faults, 0u);
  EXPECT_EQ(s.data_exch_entries, 1u);
  EXPECT_EQ(s.watchdog_expiries, 0u);
  // What it sent last and what it received last.
  EXPECT_EQ(vec(e.last_inputs()), (Bytes{0x02, 0x24}));
  EXPECT_EQ(vec(e.last_outputs()), (Bytes{0xA0, 0x04}));
}

TEST(SlaveStats, RefusalsAndFaultsAreCounted) {
  SlaveEngine e(config_2in_2out());
  Harness h(e);
  h.req(kM1, kS, kDx, {0x00, 0x00});                // not parameterised: RS
  h.req(kM1, kS, kSapChkCfg, {0x31});               // Wait_Prm: RS
  h.req(kM1, kS, kSapSetPrm, {0x88, 0x0A, 0x0A, 0x0B, 0x43, 0x21, 0x00});  // wrong ident
  h.req(kM1, kS, kSapSetPrm, kPrmLockWd);
  h.req(kM1, kS, kSapChkCfg, {0x10});               // wrong configuration
  h.req(kM1, kS, kSapSetPrm, kPrmLockWd);
  h.req(kM1, kS, kSapChkCfg, {0x31});
  h.req(kM2, kS, kDx, {0x00, 0x00});                // not the owner: RS
  h.req(kM1, kS, std::uint8_t{53}, {});             // no such service: RS
  const SlaveStats& s = e.stats();
  EXPECT_EQ(s.set_prm, 3u);
  EXPECT_EQ(s.chk_cfg, 3u);
  EXPECT_EQ(s.data_exchange, 2u);
  EXPECT_EQ(s.other, 1u);
  EXPECT_EQ(s.refused, 4u);
  EXPECT_EQ(s.prm_faults, 1u);
  EXPECT_EQ(s.cfg_faults, 1u);
  EXPECT_EQ(s.data_exch_entries, 1u);
  EXPECT_EQ(e.master_address(), kM1);
}

TEST(SlaveStats, WatchdogExpiriesAreCountedAndTheLastOutputsKept) {
  SlaveEngine e(config_2in_2out());
  Harness h(e);
  h.req(kM1, kS, kSapSetPrm, kPrmLockWd);
  h.req(kM1, kS, kSapChkCfg, {0x31});
  h.req(kM1, kS, kDx, {0x12, 0x34});
  h.advance(bus::kTicksPerSecond);
  EXPECT_EQ(e.state(), SlaveState::WaitPrm);
  EXPECT_EQ(e.stats().watchdog_expiries, 1u);
  // The device's outputs are safe (zero), but the report still knows what arrived last.
  Bytes out(2);
  e.application().read_outputs(0, out);
  EXPECT_EQ(out, (Bytes{0, 0}));
  EXPECT_EQ(vec(e.last_outputs()), (Bytes{0x12, 0x34}));
  // A second start-up and expiry: two.
  h.req(kM1, kS, kSapSetPrm, kPrmLockWd);
  h.req(kM1, kS, kSapChkCfg, {0x31});
  h.advance(bus::kTicksPerSecond);
  EXPECT_EQ(e.stats().watchdog_expiries, 2u);
  EXPECT_EQ(e.stats().data_exch_entries, 2u);
  // A power cycle does not reset the counters.
  e.on_power_on(h.now);
  EXPECT_EQ(e.stats().set_prm, 2u);
}

}  // namespace
}  // namespace pbvbus::dp
