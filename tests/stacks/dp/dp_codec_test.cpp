// Shared DP codecs: configuration identifiers (§D.3), Set_Prm layout (§D.2), diagnosis blocks
// (§D.4, §D.5), DP-V1 PDUs (§E). Expected octets written by hand from protocol-facts.md.
#include <gtest/gtest.h>

#include "pbvbus/dp/cfg_identifier.hpp"
#include "pbvbus/dp/diagnosis.hpp"
#include "pbvbus/dp/dpv1_pdu.hpp"
#include "pbvbus/dp/prm.hpp"
#include "pbvbus/dp/process_image.hpp"

namespace pbvbus::dp {
namespace {

using Bytes = std::vector<std::uint8_t>;

TEST(CfgIdentifier, GeneralFormatExamples) {
  std::vector<CfgIdentifier> ids;
  // §D.3 examples: 10 = 1 byte in; 20 = 1 byte out; 13 = 4 bytes in; 31 = 2 in + 2 out;
  // 50 = 1 word in; D7 = 8 words in, consistent; 00 = empty slot.
  ASSERT_EQ(parse_cfg(Bytes{0x10, 0x20, 0x13, 0x31, 0x50, 0xD7, 0x00}, ids, false), CfgError::None);
  ASSERT_EQ(ids.size(), 7u);
  EXPECT_EQ(ids[0].input.bytes(), 1u);
  EXPECT_EQ(ids[0].output.bytes(), 0u);
  EXPECT_EQ(ids[1].output.bytes(), 1u);
  EXPECT_EQ(ids[2].input.bytes(), 4u);
  EXPECT_EQ(ids[3].input.bytes(), 2u);
  EXPECT_EQ(ids[3].output.bytes(), 2u);
  EXPECT_TRUE(ids[4].input.words);
  EXPECT_EQ(ids[4].input.bytes(), 2u);
  EXPECT_TRUE(ids[5].input.consistent);
  EXPECT_EQ(ids[5].input.bytes(), 16u);
  EXPECT_TRUE(ids[6].empty());
  EXPECT_TRUE(ids[6].special);
  const auto t = cfg_totals(ids);
  EXPECT_EQ(t.inputs, 1u + 4 + 2 + 2 + 16);
  EXPECT_EQ(t.outputs, 1u + 2);
  EXPECT_EQ(general_identifier(kCfgInput, 8, true, true), 0xD7);
  EXPECT_EQ(general_identifier(kCfgInput | kCfgOutput, 2), 0x31);
}

TEST(CfgIdentifier, SpecialFormat) {
  std::vector<CfgIdentifier> ids;
  // C2: output + input length octets, 2 manufacturer octets; output 0xBF = consistent, 64
  // bytes; input 0x41 = 2 words.
  ASSERT_EQ(parse_cfg(Bytes{0xC2, 0xBF, 0x41, 0xAA, 0xBB, 0x40, 0x00}, ids, false), CfgError::None);
  ASSERT_EQ(ids.size(), 2u);
  EXPECT_EQ(ids[0].output.bytes(), 64u);
  EXPECT_TRUE(ids[0].output.consistent);
  EXPECT_EQ(ids[0].input.bytes(), 4u);
  EXPECT_TRUE(ids[0].input.words);
  EXPECT_EQ(ids[0].mfr_count, 2);
  EXPECT_EQ(ids[0].mfr[0], 0xAA);
  EXPECT_EQ(ids[0].mfr[1], 0xBB);
  EXPECT_EQ(ids[0].size, 5u);
  EXPECT_EQ(ids[1].offset, 5u);
  EXPECT_EQ(ids[1].input.bytes(), 1u);
  // Count 15 only in Chk_Cfg.
  EXPECT_EQ(parse_cfg(Bytes{0x4F, 0x03}, ids, false), CfgError::MfrSkipInReal);
  EXPECT_EQ(parse_cfg(Bytes{0x4F, 0x03}, ids, true), CfgError::None);
}

TEST(CfgIdentifier, BrokenLists) {
  std::vector<CfgIdentifier> ids;
  EXPECT_EQ(parse_cfg(Bytes{0x40}, ids, false), CfgError::Truncated);
  EXPECT_EQ(parse_cfg(Bytes{0xC0, 0x01}, ids, false), CfgError::Truncated);
  EXPECT_EQ(parse_cfg(Bytes{0x42, 0x01, 0xAA}, ids, false), CfgError::Truncated);
  // 16 x 16 bytes of input = 256 > 244.
  EXPECT_EQ(parse_cfg(Bytes(16, 0x1F), ids, false), CfgError::TooLong);
  EXPECT_EQ(parse_cfg(Bytes{}, ids, false), CfgError::None);
  EXPECT_TRUE(ids.empty());
}

TEST(CfgIdentifier, MatchingByMeaning) {
  std::vector<CfgIdentifier> a, b;
  ASSERT_EQ(parse_cfg(Bytes{0x93}, a, true), CfgError::None);        // 4 bytes in, consistent
  ASSERT_EQ(parse_cfg(Bytes{0x40, 0x83}, b, false), CfgError::None);  // the same, special format
  EXPECT_TRUE(cfg_matches(a[0], b[0]));
  ASSERT_EQ(parse_cfg(Bytes{0x13}, a, true), CfgError::None);
  EXPECT_FALSE(cfg_matches(a[0], b[0]));  // consistency differs
  ASSERT_EQ(parse_cfg(Bytes{0x51}, a, true), CfgError::None);  // 2 words in
  ASSERT_EQ(parse_cfg(Bytes{0x13}, b, false), CfgError::None);  // 4 bytes in
  EXPECT_FALSE(cfg_matches(a[0], b[0]));  // unit differs
  ASSERT_EQ(parse_cfg(Bytes{0x41, 0x03, 0x01}, a, true), CfgError::None);
  ASSERT_EQ(parse_cfg(Bytes{0x41, 0x03, 0x02}, b, false), CfgError::None);
  EXPECT_FALSE(cfg_matches(a[0], b[0]));
  ASSERT_EQ(parse_cfg(Bytes{0x4F, 0x03}, a, true), CfgError::None);
  EXPECT_TRUE(cfg_matches(a[0], b[0]));
}

TEST(Prm, ParseAndEncode) {
  // Appendix 1 Set_Prm DU, DP-V1 variant.
  const Bytes du{0x88, 0x0A, 0x0A, 0x0B, 0x12, 0x34, 0x00, 0x80, 0x00, 0x00};
  PrmView v;
  ASSERT_TRUE(parse_prm(du, v));
  EXPECT_TRUE(v.header.lock_req());
  EXPECT_FALSE(v.header.unlock_req());
  EXPECT_TRUE(v.header.wd_on());
  EXPECT_EQ(v.header.min_tsdr, 11);
  EXPECT_EQ(v.header.ident, 0x1234);
  EXPECT_EQ(v.user_prm.size(), 3u);
  EXPECT_TRUE(v.dpv1().dpv1_enable());
  EXPECT_EQ(encode_prm(v.header, v.user_prm), du);
  EXPECT_FALSE(parse_prm(Bytes{0x88, 0x0A, 0x0A, 0x0B, 0x12, 0x34}, v));
  EXPECT_EQ(watchdog_ticks(10, 10, false), bus::kTicksPerSecond);
  EXPECT_EQ(watchdog_ticks(255, 255, false), 650'250 * bus::kTicksPerMs);
  EXPECT_EQ(watchdog_ticks(10, 10, true), 100 * bus::kTicksPerMs);
  EXPECT_EQ(alarm_mode_limit(0), 1u);
  EXPECT_EQ(alarm_mode_limit(4), 12u);
  EXPECT_EQ(alarm_mode_limit(7), 32u);
}

TEST(Prm, StructuredBlocks) {
  std::vector<PrmBlock> blocks;
  const Bytes two{0x08, 0x02, 0x00, 0x00, 0x02, 0x0C, 0x00, 0x0A, 0x05, 0x81, 0x01, 0x00, 0x33};
  ASSERT_TRUE(split_prm_blocks(two, blocks));
  ASSERT_EQ(blocks.size(), 2u);
  EXPECT_EQ(blocks[0].type, kPrmBlockPrmCmd);
  EXPECT_EQ(blocks[0].data().size(), 4u);
  EXPECT_EQ(blocks[1].type, kPrmBlockUser);
  EXPECT_EQ(blocks[1].slot, 1);
  EXPECT_EQ(blocks[1].data()[0], 0x33);
  EXPECT_FALSE(split_prm_blocks(Bytes{0x03, 0x02, 0x00}, blocks));
  EXPECT_FALSE(split_prm_blocks(Bytes{0x08, 0x02, 0x00, 0x00}, blocks));
  EXPECT_TRUE(split_prm_blocks(Bytes{}, blocks));
}

TEST(Diagnosis, StandardAndBlocksMatchWorkedExample) {
  // §D.5 worked example: 44 00 01 00 | 88 41 21 | 04 10 20 30.
  DiagBuilder d;
  StandardDiag sd;
  sd.status_1 = kDiagExtDiag;
  sd.status_2 = kDiagAlways1 | kDiagWdOn;
  sd.master_add = 1;
  sd.ident = 0x1234;
  d.set_standard(sd);
  const std::uint16_t faulty[] = {8};
  ASSERT_TRUE(d.add_identifier_block(faulty, 24));
  ASSERT_TRUE(d.add_channel({8, 1, ChannelDirection::Input, ChannelType::Bit, 1}));
  ASSERT_TRUE(d.add_device_block(Bytes{0x10, 0x20, 0x30}));
  const Bytes expect{0x08, 0x0C, 0x00, 0x01, 0x12, 0x34, 0x44, 0x00, 0x01,
                     0x00, 0x88, 0x41, 0x21, 0x04, 0x10, 0x20, 0x30};
  EXPECT_EQ(Bytes(d.bytes().begin(), d.bytes().end()), expect);
  StandardDiag back;
  ASSERT_TRUE(StandardDiag::decode(d.bytes(), back));
  EXPECT_EQ(back.ident, 0x1234);
  EXPECT_EQ(back.master_add, 1);
  std::vector<ExtDiagBlock> blocks;
  ASSERT_TRUE(split_ext_diag(d.bytes().subspan(6), blocks));
  ASSERT_EQ(blocks.size(), 3u);
  EXPECT_EQ(blocks[0].kind, kBlockIdentifier);
  EXPECT_EQ(blocks[0].bytes.size(), 4u);
  EXPECT_EQ(blocks[1].kind, kBlockChannel);
  EXPECT_EQ(blocks[2].kind, kBlockDevice);
  EXPECT_EQ(blocks[2].bytes.size(), 4u);
  // Broken: a device block claiming 9 octets with 3 present; a reserved 11xxxxxx header.
  EXPECT_FALSE(split_ext_diag(Bytes{0x09, 0x01, 0x02}, blocks));
  EXPECT_FALSE(split_ext_diag(Bytes{0xC1}, blocks));
  EXPECT_FALSE(split_ext_diag(Bytes{0x00}, blocks));
}

TEST(Diagnosis, AlarmAndStatusPdus) {
  DiagBuilder d;
  // Diagnostic alarm slot 3, Seq_Nr 5, Add_Ack, appears; 2 octets of data.
  ASSERT_TRUE(d.add_alarm(1, 3, alarm_specifier(5, true, AlarmSpec::Appears), Bytes{0xAA, 0xBB}));
  // Module_Status for 5 modules: ok, fault, wrong, none, ok -> 0b11'10'01'00 = E4, 00.
  const ModuleState st[] = {ModuleState::Ok, ModuleState::Fault, ModuleState::WrongModule,
                            ModuleState::NoModule, ModuleState::Ok};
  ASSERT_TRUE(d.add_module_status(st));
  const Bytes ext(d.bytes().begin() + 6, d.bytes().end());
  EXPECT_EQ(ext, (Bytes{0x06, 0x01, 0x03, 0x2D, 0xAA, 0xBB, 0x06, 0x82, 0x00, 0x00, 0xE4, 0x00}));
  EXPECT_EQ(alarm_seq_nr(0x2D), 5);
  EXPECT_EQ(alarm_enable_bit(3), kEnablePullPlugAlarm);
  EXPECT_EQ(alarm_enable_bit(40), kEnableManufacturerAlarm);
  EXPECT_EQ(alarm_enable_bit(7), 0);
}

TEST(Diagnosis, BuilderRespectsMaximum) {
  DiagBuilder d(8);
  EXPECT_FALSE(d.add_channel({0, 0, ChannelDirection::Input, ChannelType::Bit, 1}));
  EXPECT_TRUE(d.overflow());
  EXPECT_EQ(d.size(), 6u);
  EXPECT_TRUE(d.add_device_block(Bytes{0x01}));  // 2 octets fit
  EXPECT_FALSE(d.add_device_block(Bytes(63, 0)));
}

TEST(Dpv1Pdu, RecordRequests) {
  RecordRequest r;
  EXPECT_EQ(parse_record_request(Bytes{0x5E, 0x00, 0x00, 0x40}, r), RecordParse::Ok);
  EXPECT_EQ(r.length, 0x40);
  EXPECT_EQ(parse_record_request(Bytes{0x5E, 0x00, 0x00}, r), RecordParse::TooShort);
  EXPECT_EQ(parse_record_request(Bytes{0x5E, 0x00, 0x00, 0xF1}, r), RecordParse::BadLength);
  EXPECT_EQ(parse_record_request(Bytes{0x5E, 0x00, 0x00, 0x01, 0x00}, r), RecordParse::BadLength);
  EXPECT_EQ(parse_record_request(Bytes{0x5F, 0x01, 0x02, 0x02, 0x11, 0x22}, r), RecordParse::Ok);
  EXPECT_EQ(r.data.size(), 2u);
  EXPECT_EQ(parse_record_request(Bytes{0x5F, 0x01, 0x02, 0x02, 0x11}, r), RecordParse::BadLength);
  const auto neg = negative_response(kFnRead, {kErrorDecodeDpv1, dpv1_err::kInvalidIndex, 0});
  EXPECT_EQ(Bytes(neg.begin(), neg.end()), (Bytes{0xDE, 0x80, 0xB0, 0x00}));
  AlarmAck a;
  EXPECT_TRUE(parse_alarm_ack(Bytes{0x5C, 0x01, 0x02, 0x08}, a));
  EXPECT_EQ(a.type, 2);
  EXPECT_FALSE(parse_alarm_ack(Bytes{0x5E, 0x01, 0x02, 0x08}, a));
}

TEST(Dpv1Pdu, Initiate) {
  const Bytes rq{0x57, 0x00, 0x00, 0x00, 0x01, 0x2C, 0x01, 0x00, 0x00, 0x00,
                 0x12, 0x34, 0x00, 0x02, 0x01, 0x01, 0xAA, 0xBB, 0xCC};
  InitiateRequest ir;
  ASSERT_TRUE(parse_initiate(rq, ir));
  EXPECT_EQ(ir.send_timeout, 300);
  EXPECT_EQ(ir.profile_ident, 0x1234);
  EXPECT_EQ(ir.s_addr.size(), 2u);
  EXPECT_EQ(ir.d_addr.size(), 1u);
  EXPECT_EQ(ir.d_addr[0], 0xCC);
  Bytes shorter(rq.begin(), rq.end() - 1);
  EXPECT_FALSE(parse_initiate(shorter, ir));
  EXPECT_FALSE(parse_initiate(Bytes{0x57, 0x00}, ir));
}

TEST(ConsistentBuffer, SizesAndGenerations) {
  ConsistentBuffer b(3);
  Bytes out(3, 0xEE);
  EXPECT_TRUE(b.read(out));
  EXPECT_EQ(out, (Bytes{0, 0, 0}));
  EXPECT_FALSE(b.write(Bytes{1, 2}));
  EXPECT_TRUE(b.write(Bytes{1, 2, 3}));
  EXPECT_EQ(b.generation(), 1u);
  Bytes small(2);
  EXPECT_FALSE(b.read(small));
  EXPECT_TRUE(b.try_read(out, 1));
  EXPECT_EQ(out, (Bytes{1, 2, 3}));
  b.fill(0x7F);
  EXPECT_EQ(b.generation(), 2u);
  EXPECT_TRUE(b.read(out));
  EXPECT_EQ(out, (Bytes{0x7F, 0x7F, 0x7F}));
  ConsistentBuffer empty(0);
  EXPECT_TRUE(empty.write(Bytes{}));
  EXPECT_TRUE(empty.read(std::span<std::uint8_t>{}));
}

}  // namespace
}  // namespace pbvbus::dp
