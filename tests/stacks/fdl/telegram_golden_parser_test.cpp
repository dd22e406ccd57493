// Golden vectors: every worked frame of protocol-facts.md Appendix 1 (plus the MPI frames of
// §H.2/§H.3) is decoded field by field and encoded again from the hand-written fields; the
// encoder must choose the same frame type (§B.1) and produce the same bytes.
#include <gtest/gtest.h>

#include <cctype>
#include <optional>
#include <string>

#include "hex.hpp"
#include "pbvbus/fdl/telegram.hpp"
#include "telegram_golden.hpp"

namespace pbvbus::fdl {
namespace {

using test::bytes_from_hex;
using test::GoldenFrame;
using test::kGoldenFrames;
using test::to_hex;

std::optional<std::uint8_t> opt(int v) {
  if (v < 0) return std::nullopt;
  return static_cast<std::uint8_t>(v);
}

class Golden : public ::testing::TestWithParam<GoldenFrame> {};

TEST_P(Golden, DecodesEveryField) {
  const GoldenFrame& g = GetParam();
  const auto bytes = bytes_from_hex(g.hex);
  Telegram t;
  ASSERT_EQ(decode(bytes, t), DecodeError::None) << to_string(decode(bytes, t));
  EXPECT_EQ(t.type, g.type);
  EXPECT_EQ(t.da, g.da);
  EXPECT_EQ(t.sa, g.sa);
  EXPECT_EQ(t.fc, g.fc);
  EXPECT_EQ(t.dsap, opt(g.dsap));
  EXPECT_EQ(t.ssap, opt(g.ssap));
  EXPECT_FALSE(t.da_segment);
  EXPECT_FALSE(t.sa_segment);
  EXPECT_EQ(to_hex(t.data), g.data);
  EXPECT_EQ(frame_length(bytes), static_cast<int>(bytes.size()));
}

TEST_P(Golden, EncodesFromTheFieldsToTheSameBytes) {
  const GoldenFrame& g = GetParam();
  Frame f;
  if (g.type == FrameType::SD4) {
    f = encode_token(g.da, g.sa);
  } else if (g.type == FrameType::SC) {
    f = encode_sc();
  } else {
    const auto data = bytes_from_hex(g.data);
    FrameSpec s;
    s.da = g.da;
    s.sa = g.sa;
    s.fc = g.fc;
    s.dsap = opt(g.dsap);
    s.ssap = opt(g.ssap);
    s.data = data;
    ASSERT_EQ(encode(s, f), EncodeError::None);
    EXPECT_EQ(to_hex(f.bytes()), g.hex) << "encode() must pick " << to_string(g.type);
    Frame same_type;
    ASSERT_EQ(encode_as(g.type, s, same_type), EncodeError::None);
    EXPECT_EQ(to_hex(same_type.bytes()), g.hex);
  }
  EXPECT_EQ(to_hex(f.bytes()), g.hex);
}

TEST_P(Golden, FcsIsTheSumOfTheCheckedOctets) {
  const GoldenFrame& g = GetParam();
  const auto b = bytes_from_hex(g.hex);
  // Token and SC carry no FCS (§B.1): their whole length is the delimiter and the addresses.
  if (g.type == FrameType::SD4 || g.type == FrameType::SC) {
    EXPECT_EQ(b.size(), g.type == FrameType::SD4 ? 3u : 1u);
    return;
  }
  const std::size_t first = g.type == FrameType::SD2 ? 4 : 1;
  EXPECT_EQ(fcs(std::span(b).subspan(first, b.size() - first - 2)), b[b.size() - 2]);
}

std::string name_of(const ::testing::TestParamInfo<GoldenFrame>& info) {
  std::string n;
  for (const char* c = info.param.name; *c; ++c)
    n += std::isalnum(static_cast<unsigned char>(*c)) ? *c : '_';
  return std::to_string(info.index) + "_" + n;
}

INSTANTIATE_TEST_SUITE_P(Appendix1, Golden, ::testing::ValuesIn(kGoldenFrames), name_of);

// §B.1's own example, stated separately because it is the rule most easily broken: a Slave_Diag
// reply with 6 octets of diagnosis plus DSAP and SSAP is 8 octets after FC, so it is an SD3.
TEST(GoldenRules, SixOctetDiagnosisGoesOutAsSd3) {
  const std::uint8_t diag[] = {0x02, 0x05, 0x00, 0xFF, 0x12, 0x34};
  FrameSpec s;
  s.da = 1;
  s.sa = 10;
  s.fc = make_response_fc(StationType::Slave, ResponseStatus::DL);
  s.dsap = 62;
  s.ssap = 60;
  s.data = diag;
  Frame f;
  ASSERT_EQ(encode(s, f), EncodeError::None);
  EXPECT_EQ(to_hex(f.bytes()), "A2 81 8A 08 3E 3C 02 05 00 FF 12 34 D9 16");
}

TEST(GoldenRules, FcHelpersMatchTheCommonOctets) {
  // §B.3 "Common FC octets".
  EXPECT_EQ(make_request_fc(RequestFn::FdlStatus), 0x49);
  EXPECT_EQ(make_request_fc(RequestFn::SrdHigh, false, true), 0x6D);
  EXPECT_EQ(make_request_fc(RequestFn::SrdHigh, true, false), 0x5D);
  EXPECT_EQ(make_request_fc(RequestFn::SrdHigh, true, true), 0x7D);
  EXPECT_EQ(make_request_fc(RequestFn::SrdLow), 0x4C);
  EXPECT_EQ(make_request_fc(RequestFn::SrdLow, true, false), 0x5C);
  EXPECT_EQ(make_request_fc(RequestFn::SrdLow, false, true), 0x6C);
  EXPECT_EQ(make_request_fc(RequestFn::SrdLow, true, true), 0x7C);
  EXPECT_EQ(make_request_fc(RequestFn::SdnHigh), 0x46);
  EXPECT_EQ(make_response_fc(StationType::Slave, ResponseStatus::DL), 0x08);
  EXPECT_EQ(make_response_fc(StationType::Slave, ResponseStatus::DH), 0x0A);
  EXPECT_EQ(make_response_fc(StationType::Slave, ResponseStatus::OK), 0x00);
  EXPECT_EQ(make_response_fc(StationType::MasterInRing, ResponseStatus::OK), 0x30);
  EXPECT_EQ(make_response_fc(StationType::MasterReady, ResponseStatus::OK), 0x20);
  EXPECT_EQ(make_response_fc(StationType::MasterNotReady, ResponseStatus::OK), 0x10);
}

}  // namespace
}  // namespace pbvbus::fdl
