// The battery's times (conformance/src/timing_plan.cpp; docs/conformance.md "Timing"), worked
// out by hand for PBVB0A01 (one module 0x11 0x21: 2 octets in, 2 out; Set_Prm DU 7 + 1 octet
// of User_Prm_Data = 8; Max_Diag_Data_Len 8; Min_Slave_Intervall 1 = 100 us, so the battery's
// Data_Exchange spacing is 10 x 100 us = 1 ms).

#include <gtest/gtest.h>

#include "../../conformance/src/timing_plan.hpp"
#include "pbvbus/gsd/gsd.hpp"
#include "pbvbus/slaves/slave_model.hpp"

namespace pbvbus::conformance {
namespace {

DutSpec spec_0a01() {
  auto r = devices::load_gsd(std::string(PBVBUS_SOURCE_DIR) + "/examples/gsd/PBVB0A01.gsd");
  EXPECT_TRUE(r.ok());
  DutSpec s;
  s.gsd = std::make_shared<const devices::GsdFile>(*r.file);
  s.address = 5;
  return s;
}

dp::SlaveParams params_of(const DutSpec& s) {
  auto p = devices::master_slave_params(*s.gsd, {devices::ModuleChoice::at(0)}, s.address);
  EXPECT_TRUE(p.ok());
  return *p.value;
}

constexpr bus::Ticks kDx = bus::kTicksPerMs;  // 10 x Min_Slave_Intervall (100 us)

TEST(TimingPlan, AutoSpeedGivesAProgramItsReplyTimeWithinTheLongestSlotTime) {
  // TSL bits = 0.1 s x speed x baud must stay <= 16 383.
  const auto sp = [](bus::Baud b) {
    const bus::Speed s = auto_speed(b, std::chrono::milliseconds(100));
    return std::to_string(s.num) + "/" + std::to_string(s.den);
  };
  EXPECT_EQ(sp(bus::Baud::k9_6), "1/1");      // 960 bits
  EXPECT_EQ(sp(bus::Baud::k93_75), "1/1");    // 9 375
  EXPECT_EQ(sp(bus::Baud::k187_5), "1/2");    // 18 750 at 1/1 is too long; 9 375
  EXPECT_EQ(sp(bus::Baud::k1_5M), "1/10");    // 30 000 at 1/5; 15 000
  EXPECT_EQ(sp(bus::Baud::k12M), "1/100");    // 24 000 at 1/50; 12 000
}

TEST(TimingPlan, ModelAt1M5KeepsTheProfileSlotTimeAndTheFloorWatchdog) {
  const DutSpec s = spec_0a01();
  const auto t = detail::plan_timing(s, params_of(s), 2, 2, bus::Baud::k1_5M, 300, kDx);
  EXPECT_EQ(t.tsl_bits, 300u);
  // Longest request and reply: 11 + 8 octets = 19 characters = 209 bit times each.
  EXPECT_EQ(t.longest_request, bus::bits_to_ticks(209, bus::Baud::k1_5M));
  EXPECT_EQ(t.longest_reply, bus::bits_to_ticks(209, bus::Baud::k1_5M));
  // 33 + 300 + 209 + 209 = 751 bit times + 1 ms.
  EXPECT_EQ(t.exchange_span, bus::bits_to_ticks(751, bus::Baud::k1_5M) + kDx);
  EXPECT_EQ(t.twd, 100 * bus::kTicksPerMs);  // the floor: 4 x 1.5 ms is less
  EXPECT_EQ(t.wd_margin, bus::kTicksPerMs);  // 1 % of 100 ms
  EXPECT_EQ(t.pace_jitter, 0);
}

TEST(TimingPlan, ProgramAt9k6GetsASlotTimeAndWatchdogItCanKeep) {
  DutSpec s = spec_0a01();
  s.pty_path = "/tmp/unused";
  s.speed = {1, 1};
  const auto t = detail::plan_timing(s, params_of(s), 2, 2, bus::Baud::k9_6, 100, kDx);
  EXPECT_EQ(t.tsl_bits, 960u);  // 100 ms x 9 600 bit/s
  EXPECT_EQ(t.reply_wall, std::chrono::milliseconds(100));
  // Span: 33 + 960 + 209 + 209 = 1 411 bit times + 1 ms.
  EXPECT_EQ(t.exchange_span, bus::bits_to_ticks(1411, bus::Baud::k9_6) + kDx);
  EXPECT_EQ(t.pace_jitter, 30 * bus::kTicksPerMs);
  // Extra margin: 209 + 960 + 209 = 1 378 bit times (143.54 ms) + 2 x 30 ms = 203.54 ms.
  // TWD: max(100 ms, 4 x 147.98, 4 x 203.54 = 814.2) -> 820 ms; margin 8.2 + 203.54 = 211.74,
  // 4 x that = 847 > 820 -> TWD 850 ms, margin 8.5 + 203.54 ms (4 x = 848.2 <= 850).
  const bus::Ticks extra = bus::bits_to_ticks(1378, bus::Baud::k9_6) + 60 * bus::kTicksPerMs;
  EXPECT_EQ(t.twd, 850 * bus::kTicksPerMs);
  EXPECT_EQ(t.wd_margin, t.twd / 100 + extra);
  EXPECT_GE(t.twd, 4 * t.wd_margin);
}

TEST(TimingPlan, SlotTimeNeverExceedsTheStandardsMaximum) {
  DutSpec s = spec_0a01();
  s.pty_path = "/tmp/unused";
  s.speed = {1, 1};  // at 1.5 Mbit/s 100 ms would be 150 000 bit times
  const auto t = detail::plan_timing(s, params_of(s), 2, 2, bus::Baud::k1_5M, 300, kDx);
  EXPECT_EQ(t.tsl_bits, 16383u);
  EXPECT_EQ(t.reply_wall, std::chrono::milliseconds(10));  // 16 383 / 1.5 Mbit/s, rounded down
}

}  // namespace
}  // namespace pbvbus::conformance
