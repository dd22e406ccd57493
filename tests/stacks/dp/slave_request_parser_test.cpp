// Garbage in, no crash out: seeded random requests (any SAP, any length, any source, broadcast,
// address 126) to DP-V1 slaves with C1, C2 and alarms, in every state. Every reply must be a
// legal FDL reply for the request, and the diagnosis must stay well-formed. Also built into
// sanitize_dp (ASan + UBSan).
#include <gtest/gtest.h>

#include <random>

#include "pbvbus/dp/slave_engine.hpp"

namespace pbvbus::dp {
namespace {

SlaveConfig fuzz_config() {
  SlaveConfig c;
  c.ident = 0x1234;
  c.modules = {{{0x13}, ""}, {{0x27}, ""}, {{0xC1, 0x81, 0x83, 0x99}, ""}};
  c.features = {true, true, true, true, true, true, true, 3, 0xFC, 7, true, true};
  c.min_user_prm_len = 3;
  c.max_user_prm_len = 20;
  c.max_diag_len = 40;
  return c;
}

TEST(SlaveRequestParser, RandomRequestsNeverBreakTheEngine) {
  std::mt19937 rng(12345);
  auto byte = [&] { return static_cast<std::uint8_t>(rng() & 0xFF); };
  const fdl::RequestFn fns[] = {fdl::RequestFn::SrdHigh, fdl::RequestFn::SrdLow,
                                fdl::RequestFn::SdaHigh, fdl::RequestFn::SdnHigh,
                                fdl::RequestFn::SdnLow};
  long in_data_exchange = 0;
  long record_replies = 0;
  for (int round = 0; round < 40; ++round) {
    SlaveEngine e(fuzz_config());
    auto& app = e.application();
    app.on_read(0, 1, [](const RecordCall&, std::span<std::uint8_t> out) {
      for (auto& b : out) b = 0x77;
      return RecordResult::ok(out.size() + 5);  // claims more than it may: must be clipped
    });
    app.on_write(1, 1, [](const RecordCall&, std::span<const std::uint8_t>) {
      return RecordResult::pending();
    });
    bus::Ticks now = 0;
    fdl::Reply reply;
    std::vector<std::uint8_t> data;
    for (int i = 0; i < 3000; ++i) {
      now += static_cast<bus::Ticks>(rng() % 50'000'000);
      while (e.next_deadline() <= now) {
        const auto d = e.next_deadline();
        e.on_time(d);
        ASSERT_NE(e.next_deadline(), d);
      }
      fdl::Indication ind;
      ind.now = now;
      ind.sa = static_cast<std::uint8_t>(rng() % 4);
      const auto r = rng() % 16;
      ind.da = r == 0 ? 127 : r == 1 ? 126 : 10;
      ind.fn = ind.da == 127 ? fdl::RequestFn::SdnHigh : fns[rng() % 5];
      // Bias towards the DP SAPs and plausible PDUs so that deep states are reached.
      const auto s = rng() % 20;
      if (s < 3) ind.dsap = std::nullopt;
      else if (s < 16) ind.dsap = static_cast<std::uint8_t>(45 + rng() % 19);
      else ind.dsap = static_cast<std::uint8_t>(rng() % 64);
      if (ind.dsap) ind.ssap = static_cast<std::uint8_t>(rng() % 64);
      data.resize(rng() % 4 == 0 ? rng() % 245 : rng() % 24);
      for (auto& b : data) b = byte();
      if (ind.dsap == kSapSetPrm && rng() % 2) {
        // A plausible locking Set_Prm with random options.
        data.resize(10 + rng() % 8);
        data[0] = static_cast<std::uint8_t>(0x80 | (byte() & 0x38));
        data[1] = static_cast<std::uint8_t>(1 + rng() % 255);
        data[2] = static_cast<std::uint8_t>(1 + rng() % 255);
        data[4] = 0x12;
        data[5] = 0x34;
        data[7] = static_cast<std::uint8_t>(0x80 | (byte() & 0x44));
        data[8] = static_cast<std::uint8_t>(byte() & 0xFD);
        data[9] = static_cast<std::uint8_t>(byte() & 0x07);
      }
      if (ind.dsap == kSapChkCfg && rng() % 2) data = e.layout().cfg;
      if (ind.dsap && (*ind.dsap == kSapC1ReadWrite || *ind.dsap == 48 || *ind.dsap == 47) &&
          rng() % 2) {
        const auto slot = static_cast<std::uint8_t>(rng() % 3);
        const auto index = static_cast<std::uint8_t>(rng() % 3);
        if (rng() % 2) {
          data = {kFnRead, slot, index, static_cast<std::uint8_t>(1 + rng() % 240)};
        } else {
          const auto n = static_cast<std::uint8_t>(rng() % 30);
          data = {kFnWrite, slot, index, n};
          for (int k = 0; k < n; ++k) data.push_back(byte());
        }
      }
      if (ind.dsap && (*ind.dsap == kSapC2ResourceManager || *ind.dsap == 48 || *ind.dsap == 47) &&
          rng() % 3 == 0)
        data = {0x57, 0, 0, 0, 0, static_cast<std::uint8_t>(rng() % 3), 1, 0, 0, 0, 0, 0, 0, 2, 0,
                2, 1, 2, 3, 4};
      if (ind.dsap == kSapC1Alarm && rng() % 2)
        data = {kFnAlarmAck, static_cast<std::uint8_t>(byte() & 3), static_cast<std::uint8_t>(rng() % 7),
                static_cast<std::uint8_t>(byte() & 0x1F)};
      if (!ind.dsap && rng() % 2) data.assign(e.layout().outputs, byte());
      ind.data = data;
      if (rng() % 10 == 0)
        app.raise_alarm(static_cast<std::uint8_t>(rng() % 8), byte(), AlarmSpec::Appears, rng() % 2);
      if (rng() % 20 == 0)
        app.add_channel_diag({static_cast<std::uint8_t>(rng() % 64), byte(),
                              ChannelDirection::Input, ChannelType::Bit, 1});
      reply = fdl::Reply{};
      e.on_request(ind, reply);
      if (e.state() == SlaveState::DataExch) ++in_data_exchange;
      if (reply.kind == fdl::Reply::Kind::Data && !reply.data.empty() &&
          (reply.data[0] == kFnRead || reply.data[0] == kFnWrite || reply.data[0] == 0xDE ||
           reply.data[0] == 0xDF))
        ++record_replies;
      if (!fdl::fn_expects_reply(ind.fn)) {
        ASSERT_EQ(reply.kind, fdl::Reply::Kind::None);
      }
      if (reply.kind == fdl::Reply::Kind::Data) {
        ASSERT_LE(reply.data.size(), 244u);
        ASSERT_TRUE(reply.status == fdl::ResponseStatus::DL || reply.status == fdl::ResponseStatus::DH);
      }
      if (reply.kind == fdl::Reply::Kind::Status) {
        ASSERT_EQ(reply.status, fdl::ResponseStatus::RS);
      }
      if (ind.dsap == kSapSlaveDiag && fdl::fn_expects_reply(ind.fn) && ind.da != 127) {
        ASSERT_EQ(reply.kind, fdl::Reply::Kind::Data);
        ASSERT_GE(reply.data.size(), 6u);
        ASSERT_LE(reply.data.size(), 40u);
        EXPECT_EQ(reply.data[1] & kDiagAlways1, kDiagAlways1);
        EXPECT_EQ(reply.data[4], 0x12);
        EXPECT_EQ(reply.data[5], 0x34);
        std::vector<ExtDiagBlock> blocks;
        EXPECT_TRUE(split_ext_diag(std::span(reply.data).subspan(6), blocks));
      }
    }
  }
  // The random walk must get deep: data exchange and DP-V1 record services were exercised.
  EXPECT_GT(in_data_exchange, 1000);
  EXPECT_GT(record_replies, 10);
}

}  // namespace
}  // namespace pbvbus::dp
