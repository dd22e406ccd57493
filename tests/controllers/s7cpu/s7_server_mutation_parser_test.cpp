// S7Server never crashes on malformed PDUs: seeded mutations of the golden requests (the
// stacks/s7 decoders' error cases are reached this way too), fed to a session before and after
// Setup Communication. Every answer must itself decode and carry the request's PDU reference.
// Also built into sanitize_controllers_s7cpu (ASan+UBSan).
#include <gtest/gtest.h>

#include <cstdio>
#include <random>

#include "hex.hpp"
#include "pbvbus/s7/s7_pdu.hpp"
#include "pbvbus/s7/s7_read_var.hpp"
#include "pbvbus/s7/s7_szl.hpp"
#include "pbvbus/s7/s7_write_var.hpp"
#include "pbvbus/s7cpu/s7_server.hpp"

namespace pbvbus::s7cpu {
namespace {

using Bytes = std::vector<std::uint8_t>;

std::vector<Bytes> corpus() {
  using test::bytes_from_hex;
  std::vector<Bytes> c{
      bytes_from_hex("32 01 00 00 00 00 00 08 00 00 F0 00 00 01 00 01 01 E0"),
      bytes_from_hex("32 01 00 00 00 01 00 0E 00 00 04 01 12 0A 10 02 00 04 00 01 84 00 00 00"),
      bytes_from_hex("32 01 00 00 00 03 00 0E 00 06 05 01 12 0A 10 04 00 01 00 01 84 00 00 10"
                     " 00 04 00 10 BE EF"),
  };
  const std::vector<s7::VarItem> items{{s7::transport::kBit, 1, 0, s7::area::kFlags, 3},
                                       {s7::transport::kCounter, 2, 0, s7::area::kCounter, 1},
                                       {s7::transport::kTimer, 1, 0, s7::area::kTimer, 0},
                                       {s7::transport::kReal, 1, 1, s7::area::kDataBlock, 32}};
  c.push_back(s7::encode_read_var_request(4, items).value);
  const Bytes one{1}, two{0, 2};
  const std::vector<s7::WriteVarItem> w{
      {items[0], s7::data_transport::kBit, one},
      {items[2], s7::data_transport::kOctetString, two}};
  c.push_back(s7::encode_write_var_request(5, w).value);
  c.push_back(s7::encode_szl_request(6, {1, 0x0011, 0}).value);
  c.push_back(s7::encode_szl_request(7, {1, 0x0424, 0}).value);
  return c;
}

struct Tally {
  int none = 0;
  int refused = 0;
  int served = 0;
};

void check_answer(const Bytes& in, const s7::Encoded& out, Tally& tally) {
  if (!out.ok()) {
    ++tally.none;
    ASSERT_TRUE(out.value.empty());
    return;
  }
  const auto req = s7::decode_s7_pdu(in);
  ASSERT_TRUE(req.ok()) << test::to_hex(in);
  const auto ans = s7::decode_s7_pdu(out.value);
  ASSERT_TRUE(ans.ok()) << test::to_hex(in) << " -> " << test::to_hex(out.value);
  EXPECT_EQ(ans.value.header.pdu_ref, req.value.header.pdu_ref);
  ++(ans.value.header.type == s7::kS7Ack ? tally.refused : tally.served);
}

TEST(S7ServerMutation, NeverCrashesAndAnswersDecode) {
  const auto seeds = corpus();
  std::mt19937 rng(20261128);
  CpuMemory memory(CpuMemorySizes{8, 8, 8, 4, 4});
  memory.create_db(1, 40);
  CpuInfo info;
  S7Server fresh(memory, info);
  S7Server ready(memory, info);
  ASSERT_TRUE(ready.handle(seeds[0]).ok());
  Tally tally;
  for (int i = 0; i < 40000; ++i) {
    Bytes m = seeds[rng() % seeds.size()];
    const int edits = 1 + static_cast<int>(rng() % 4);
    for (int e = 0; e < edits; ++e) {
      switch (rng() % 4) {
        case 0:
          if (!m.empty()) m[rng() % m.size()] = static_cast<std::uint8_t>(rng());
          break;
        case 1:
          if (!m.empty()) m.resize(rng() % m.size());
          break;
        case 2:
          m.push_back(static_cast<std::uint8_t>(rng()));
          break;
        default:
          // Keep the lengths consistent so the function decoders are reached.
          if (m.size() >= 10) {
            const std::size_t header = (m[1] == 2 || m[1] == 3) ? 12 : 10;
            if (m.size() >= header) {
              const std::size_t params = std::min<std::size_t>(rng() % 40, m.size() - header);
              const std::size_t data = m.size() - header - params;
              m[6] = static_cast<std::uint8_t>(params >> 8);
              m[7] = static_cast<std::uint8_t>(params);
              m[8] = static_cast<std::uint8_t>(data >> 8);
              m[9] = static_cast<std::uint8_t>(data);
            }
          }
      }
    }
    check_answer(m, fresh.handle(m), tally);
    check_answer(m, ready.handle(m), tally);
    if (::testing::Test::HasFatalFailure()) return;
  }
  // The mutations reach every outcome: no answer, a refusal, a served function.
  EXPECT_GT(tally.none, 1000);
  EXPECT_GT(tally.refused, 1000);
  EXPECT_GT(tally.served, 1000);
  std::printf("no answer %d, refused %d, served %d\n", tally.none, tally.refused, tally.served);
}

}  // namespace
}  // namespace pbvbus::s7cpu
