// Master-side process image under concurrent access (protocol-facts.md §F): user threads write
// outputs and read inputs (DPWR_DAT / DPRD_DAT) while the bus thread snapshots outputs and
// publishes inputs. Every value a thread sees must be one that was written whole. Writers use
// patterns in which all octets of a unit carry the same counter value, so a torn read shows up
// as two different octets. Built into sanitize_dp, which CI runs under ThreadSanitizer.
#include <gtest/gtest.h>

#include <atomic>
#include <cstdint>
#include <thread>
#include <vector>

#include "pbvbus/dp/master_image.hpp"

namespace pbvbus::dp {
namespace {

SlaveLayout layout_of(std::vector<std::vector<std::uint8_t>> modules) {
  SlaveConfig c;
  c.ident = 0x1234;
  for (auto& m : modules) c.modules.push_back({m, ""});
  SlaveLayout l;
  EXPECT_EQ(build_layout(c, l), "");
  return l;
}

bool uniform(const std::vector<std::uint8_t>& v) {
  for (auto b : v)
    if (b != v[0]) return false;
  return true;
}

TEST(MasterImageConcurrency, OutputsWrittenWholeAndInputsPublishedWhole) {
  // Module 0: 16 bytes in and out, consistent (0xF7 = consistent, words, in+out, 8 words);
  // module 1: 3 bytes out; module 2: 64 bytes in (special format, consistent).
  const SlaveLayout l = layout_of({{0xF7}, {0x22}, {0x40, 0xBF}});
  MasterImage img(l);
  ASSERT_EQ(img.modules(), 3u);
  ASSERT_EQ(img.input_length(), 16u + 64u);
  ASSERT_EQ(img.output_length(), 16u + 3u);

  constexpr int kRounds = 20000;
  std::atomic<bool> stop{false};
  std::atomic<int> torn{0};

  // User writers: one per output module.
  auto writer = [&](std::size_t module) {
    std::vector<std::uint8_t> buf(img.module(module).out_len);
    for (int i = 1; i <= kRounds; ++i) {
      std::fill(buf.begin(), buf.end(), static_cast<std::uint8_t>(i));
      ASSERT_EQ(img.write_outputs(module, buf), ImageAccess::Ok);
    }
  };
  // User readers of inputs: per module and the whole slave.
  auto reader = [&]() {
    std::vector<std::uint8_t> m0(img.module(0).in_len), m2(img.module(2).in_len);
    std::vector<std::uint8_t> all(img.input_length());
    while (!stop.load(std::memory_order_relaxed)) {
      ASSERT_EQ(img.read_inputs(0, m0), ImageAccess::Ok);
      ASSERT_EQ(img.read_inputs(2, m2), ImageAccess::Ok);
      ASSERT_EQ(img.read_all_inputs(all), ImageAccess::Ok);
      if (!uniform(m0) || !uniform(m2) || !uniform(all)) torn.fetch_add(1);
    }
  };

  std::thread w0(writer, 0), w1(writer, 1);
  std::thread r1(reader), r2(reader);

  // The bus thread: snapshot outputs per Data_Exchange, publish one response per cycle.
  std::vector<std::uint8_t> tx(img.output_length());
  std::vector<std::uint8_t> rx(img.input_length());
  for (int i = 1; i <= kRounds; ++i) {
    img.snapshot_outputs(tx);
    for (std::size_t k = 1; k < 16; ++k)
      if (tx[k] != tx[0]) torn.fetch_add(1);
    for (std::size_t k = 17; k < 19; ++k)
      if (tx[k] != tx[16]) torn.fetch_add(1);
    std::fill(rx.begin(), rx.end(), static_cast<std::uint8_t>(i));
    img.publish_inputs(rx);
  }
  w0.join();
  w1.join();
  stop.store(true);
  r1.join();
  r2.join();
  EXPECT_EQ(torn.load(), 0);
  EXPECT_EQ(img.inputs_generation(), static_cast<std::uint32_t>(kRounds));

  // After everything: the last writes are what a snapshot takes.
  img.snapshot_outputs(tx);
  EXPECT_EQ(tx[0], static_cast<std::uint8_t>(kRounds));
  EXPECT_EQ(tx[16], static_cast<std::uint8_t>(kRounds));
}

TEST(MasterImageConcurrency, LengthMustMatchTheModule) {
  const SlaveLayout l = layout_of({{0x10}, {0x21}});
  MasterImage img(l);
  std::vector<std::uint8_t> two(2), one(1);
  EXPECT_EQ(img.write_outputs(1, one), ImageAccess::WrongLength);
  EXPECT_EQ(img.write_outputs(0, one), ImageAccess::WrongLength);  // module 0 has no outputs
  EXPECT_EQ(img.write_outputs(2, two), ImageAccess::NoSuchModule);
  EXPECT_EQ(img.write_outputs(1, two), ImageAccess::Ok);
  EXPECT_EQ(img.read_inputs(0, two), ImageAccess::WrongLength);
  EXPECT_EQ(img.read_inputs(0, one), ImageAccess::Ok);
  EXPECT_EQ(to_string(ImageAccess::WrongLength), "wrong length");
  EXPECT_FALSE(img.data_valid());
}

}  // namespace
}  // namespace pbvbus::dp
