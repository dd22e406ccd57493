// Consistent process data (design.md "Consistent data", protocol-facts.md §F): writer and reader
// threads hammer modules; every value is written whole with all bytes equal (a counter), so a
// torn read shows up as a module whose bytes differ. Runs under ThreadSanitizer in CI
// (sanitize_dp).
#include <gtest/gtest.h>

#include <atomic>
#include <thread>
#include <vector>

#include "pbvbus/dp/process_image.hpp"
#include "pbvbus/dp/slave_engine.hpp"

namespace pbvbus::dp {
namespace {

using Bytes = std::vector<std::uint8_t>;

bool all_equal(std::span<const std::uint8_t> b) {
  for (auto v : b)
    if (v != b[0]) return false;
  return true;
}

TEST(ProcessImageConcurrency, SeqlockBufferNeverTears) {
  constexpr int kWriters = 3;
  constexpr int kReaders = 3;
  // A large buffer makes each write long, so that on a loaded 2-core machine readers and
  // writers really do overlap mid-copy (a broken lock is caught within a few hundred writes).
  constexpr int kWrites = 800;
  constexpr std::size_t kLen = 8189;  // not a multiple of the 8-byte word
  ConsistentBuffer buf(kLen);
  std::atomic<bool> done{false};
  std::atomic<int> torn{0};
  std::atomic<long> reads{0};
  std::vector<std::thread> threads;
  for (int w = 0; w < kWriters; ++w) {
    threads.emplace_back([&, w] {
      Bytes v(kLen);
      for (int i = 0; i < kWrites; ++i) {
        std::fill(v.begin(), v.end(), static_cast<std::uint8_t>(w * 80 + i % 80));
        ASSERT_TRUE(buf.write(v));
      }
    });
  }
  for (int r = 0; r < kReaders; ++r) {
    threads.emplace_back([&] {
      Bytes v(kLen);
      do {
        ASSERT_TRUE(buf.read(v));
        if (!all_equal(v)) torn.fetch_add(1);
        reads.fetch_add(1);
      } while (!done.load());
    });
  }
  for (int w = 0; w < kWriters; ++w) threads[static_cast<std::size_t>(w)].join();
  done = true;
  for (std::size_t t = kWriters; t < threads.size(); ++t) threads[t].join();
  EXPECT_EQ(torn.load(), 0);
  EXPECT_GT(reads.load(), 0);
  EXPECT_EQ(buf.generation(), static_cast<std::uint32_t>(kWriters * kWrites));
}

TEST(ProcessImageConcurrency, SlaveModulesConsistentBetweenBusAndDevice) {
  // Module 0: 16 words in, consistent (DF); module 1: 16 words out, consistent (EF); module 2:
  // 16 bytes out + 16 bytes in, consistent (special format C0 8F 8F).
  SlaveConfig cfg;
  cfg.ident = 0x1234;
  cfg.modules = {{{0xDF}, "in"}, {{0xEF}, "out"}, {{0xC0, 0x8F, 0x8F}, "io"}};
  SlaveEngine e(cfg);
  auto& app = e.application();
  const auto& lay = e.layout();
  ASSERT_EQ(lay.inputs, 48u);
  ASSERT_EQ(lay.outputs, 48u);

  auto request = [&](std::uint8_t dsap, const Bytes& data, fdl::Reply& reply) {
    fdl::Indication ind;
    ind.sa = 1;
    ind.da = 10;
    ind.fn = fdl::RequestFn::SrdHigh;
    ind.dsap = dsap;
    ind.ssap = 62;
    ind.data = data;
    reply = fdl::Reply{};
    e.on_request(ind, reply);
  };
  fdl::Reply reply;
  request(kSapSetPrm, {0x80, 0x01, 0x01, 0x00, 0x12, 0x34, 0x00}, reply);
  request(kSapChkCfg, lay.cfg, reply);
  ASSERT_EQ(e.state(), SlaveState::DataExch);

  constexpr int kCycles = 2000;
  std::atomic<bool> done{false};
  std::atomic<int> torn{0};
  std::vector<std::thread> threads;
  // Device-side input writers (two per input module, as a gateway and a device model might be).
  for (int w = 0; w < 2; ++w) {
    for (std::size_t m : {std::size_t{0}, std::size_t{2}}) {
      threads.emplace_back([&, w, m] {
        Bytes v(app.module(m).in_len);
        std::uint8_t n = static_cast<std::uint8_t>(w * 100);
        while (!done.load()) {
          std::fill(v.begin(), v.end(), n++);
          app.write_inputs(m, v);
          std::this_thread::yield();  // 2 cores: leave the bus thread room to run
        }
      });
    }
  }
  // Device-side output readers.
  for (int r = 0; r < 2; ++r) {
    threads.emplace_back([&] {
      Bytes o1(app.module(1).out_len);
      Bytes o2(app.module(2).out_len);
      while (!done.load()) {
        app.read_outputs(1, o1);
        app.read_outputs(2, o2);
        if (!all_equal(o1) || !all_equal(o2)) torn.fetch_add(1);
      }
    });
  }
  // The bus thread: Data_Exchange with whole-module output patterns; every input module in
  // the reply must be whole.
  Bytes out(lay.outputs);
  for (int c = 0; c < kCycles; ++c) {
    std::fill(out.begin(), out.begin() + 32, static_cast<std::uint8_t>(c));
    std::fill(out.begin() + 32, out.end(), static_cast<std::uint8_t>(c * 7));
    fdl::Indication ind;
    ind.sa = 1;
    ind.da = 10;
    ind.fn = fdl::RequestFn::SrdHigh;
    ind.data = out;
    e.on_request(ind, reply);
    ASSERT_EQ(reply.kind, fdl::Reply::Kind::Data);
    ASSERT_EQ(reply.data.size(), 48u);
    const std::span<const std::uint8_t> in(reply.data);
    if (!all_equal(in.subspan(lay.modules[0].in_offset, 32)) ||
        !all_equal(in.subspan(lay.modules[2].in_offset, 16)))
      torn.fetch_add(1);
  }
  done = true;
  for (auto& t : threads) t.join();
  EXPECT_EQ(torn.load(), 0);
  EXPECT_EQ(app.outputs_generation(1), static_cast<std::uint32_t>(kCycles));
}

}  // namespace
}  // namespace pbvbus::dp
