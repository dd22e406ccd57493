// The battery's request builders and reply reader (conformance/src/groups.hpp). Every frame is
// summed by hand (protocol-facts.md §B.1: FCS = sum of DA..last DU octet mod 256) or taken from
// the worked frames of Appendix 1.

#include <gtest/gtest.h>

#include <vector>

#include "../../conformance/src/groups.hpp"

namespace pbvbus::conformance::detail {
namespace {

using Bytes = std::vector<std::uint8_t>;

TEST(DpRequests, FdlStatusIsSd1WithFc49) {
  // 10 DA SA FC FCS 16: DA 3, SA 1, FC 0x49; FCS = 03 + 01 + 49 = 0x4D (Appendix 1).
  EXPECT_EQ(fdl_status(3, 1), (Bytes{0x10, 0x03, 0x01, 0x49, 0x4D, 0x16}));
}

TEST(DpRequests, SlaveDiagRequestWithSapsAndNoDuIsSd2WithLe5) {
  // DSAP/SSAP and no DU: LE = DA SA FC DSAP SSAP = 5 → SD2 (§B.1, §D.4: LE would be 3 only
  // without SAPs). DA 0x83 (3 | EXT), SA 0x81, FC 0x4D (SRD high 0xD | request 0x40, FCV = FCB
  // = 0), DSAP 0x3C (60), SSAP 0x3E (62); FCS = 83+81+4D+3C+3E = 0x1CB → 0xCB.
  EXPECT_EQ(srd(3, 1, 60, 62, {}),
            (Bytes{0x68, 0x05, 0x05, 0x68, 0x83, 0x81, 0x4D, 0x3C, 0x3E, 0xCB, 0x16}));
}

TEST(DpRequests, FirstFrameSlaveDiagMatchesTheWorkedFrame) {
  // Appendix 1 (✓ S11): master 1 → slave 10, FCV = 0, FCB = 1 → FC 0x6D.
  EXPECT_EQ(srd(10, 1, 60, 62, {}, false, true),
            (Bytes{0x68, 0x05, 0x05, 0x68, 0x8A, 0x81, 0x6D, 0x3C, 0x3E, 0xF2, 0x16}));
}

TEST(DpRequests, SetPrmMatchesTheWorkedFrame) {
  // Appendix 1: lock + WD 10 × 10, min TSDR 11, ident 0x1234, group 0; FCV = 1, FCB = 0 → 0x5D.
  const Bytes du = {0x88, 0x0A, 0x0A, 0x0B, 0x12, 0x34, 0x00};
  EXPECT_EQ(srd(10, 1, 61, 62, du, true, false),
            (Bytes{0x68, 0x0C, 0x0C, 0x68, 0x8A, 0x81, 0x5D, 0x3D, 0x3E, 0x88, 0x0A, 0x0A, 0x0B,
                   0x12, 0x34, 0x00, 0xD0, 0x16}));
}

TEST(DpRequests, DataExchangeWithoutSaps) {
  // Appendix 1: 2 output octets AA 55 to slave 10, FC 0x5D: LE = 3 + 2 = 5;
  // FCS = 0A+01+5D+AA+55 = 0x167 → 0x67.
  const Bytes out = {0xAA, 0x55};
  EXPECT_EQ(srd(10, 1, std::nullopt, std::nullopt, out, true, false),
            (Bytes{0x68, 0x05, 0x05, 0x68, 0x0A, 0x01, 0x5D, 0xAA, 0x55, 0x67, 0x16}));
}

TEST(DpRequests, EightOctetsAfterFcGoAsSd3) {
  // Appendix 1: 8 output octets 01..08, FC 0x7D (FCV = FCB = 1);
  // FCS = 0A+01+7D+(1+..+8 = 0x24) = 0xAC.
  const Bytes out = {1, 2, 3, 4, 5, 6, 7, 8};
  EXPECT_EQ(srd(10, 1, std::nullopt, std::nullopt, out, true, true),
            (Bytes{0xA2, 0x0A, 0x01, 0x7D, 1, 2, 3, 4, 5, 6, 7, 8, 0xAC, 0x16}));
}

TEST(DpRequests, GlobalControlIsSdnHighToBroadcast) {
  // Appendix 1: Clear, broadcast: DA 0xFF (127 | EXT), SA 0x81, FC 0x46 (SDN high),
  // DSAP 3A, SSAP 3E, DU 02 00; FCS = FF+81+46+3A+3E+02+00 = 0x240 → 0x40.
  const Bytes du = {0x02, 0x00};
  EXPECT_EQ(sdn(127, 1, 58, 62, du),
            (Bytes{0x68, 0x07, 0x07, 0x68, 0xFF, 0x81, 0x46, 0x3A, 0x3E, 0x02, 0x00, 0x40, 0x16}));
}

TEST(DpRequests, ImpossibleRequestIsEmpty) {
  // SA 127 is no source address (§B.2): the codec refuses, the helper returns nothing.
  EXPECT_TRUE(srd(3, 127, 60, 62, {}).empty());
}

Exchange answered(Bytes response, std::uint32_t flags = 0) {
  Exchange e;
  e.answered = true;
  e.response = std::move(response);
  e.response_flags = flags;
  return e;
}

TEST(DpRequests, ReplyOfNothingIsNone) {
  const Reply r = reply_of(Exchange{});
  EXPECT_EQ(r.kind, Reply::Kind::None);
  EXPECT_EQ(r.describe(), "no reply");
}

TEST(DpRequests, ReplyOfScIsSc) {
  const Reply r = reply_of(answered({0xE5}));
  EXPECT_EQ(r.kind, Reply::Kind::Sc);
  EXPECT_EQ(r.describe(), "SC");
  EXPECT_FALSE(r.ok_with_data());
}

TEST(DpRequests, ReplyOfDiagSd3) {
  // Appendix 1: the unparameterised diag reply of slave 10 with ident 0x1234.
  const Reply r = reply_of(answered(
      {0xA2, 0x81, 0x8A, 0x08, 0x3E, 0x3C, 0x02, 0x05, 0x00, 0xFF, 0x12, 0x34, 0xD9, 0x16}));
  ASSERT_EQ(r.kind, Reply::Kind::Telegram);
  EXPECT_TRUE(r.ok_with_data());
  EXPECT_EQ(r.fc, 0x08);
  EXPECT_EQ(r.status, fdl::ResponseStatus::DL);
  EXPECT_EQ(r.data, (Bytes{0x02, 0x05, 0x00, 0xFF, 0x12, 0x34}));
  EXPECT_EQ(r.da, 1);
  EXPECT_EQ(r.sa, 10);
  EXPECT_EQ(r.dsap, std::optional<std::uint8_t>(62));
  EXPECT_EQ(r.ssap, std::optional<std::uint8_t>(60));
  EXPECT_EQ(r.describe(), "DL 02 05 00 FF 12 34");
}

TEST(DpRequests, ReplyOfRsSd1) {
  // SD1 RS from slave 3 to master 1: FC 0x03; FCS = 01 + 03 + 03 = 0x07.
  const Reply r = reply_of(answered({0x10, 0x01, 0x03, 0x03, 0x07, 0x16}));
  EXPECT_TRUE(r.rs());
  EXPECT_FALSE(r.ok_with_data());
  EXPECT_EQ(r.describe(), "RS");
}

TEST(DpRequests, ReplyWithBadFcsOrErrorFlagsIsBad) {
  // The FDL status reply with FCS 0x05 instead of 0x04.
  const Reply bad = reply_of(answered({0x10, 0x01, 0x03, 0x00, 0x05, 0x16}));
  EXPECT_EQ(bad.kind, Reply::Kind::Bad);
  EXPECT_NE(bad.error.find("10 01 03 00 05 16"), std::string::npos);
  const Reply noisy = reply_of(answered({0x10, 0x01, 0x03, 0x00, 0x04, 0x16}, bus::kRxParity));
  EXPECT_EQ(noisy.kind, Reply::Kind::Bad);
}

TEST(DpRequests, ARequestFrameIsNoReply) {
  const Reply r = reply_of(answered({0x10, 0x03, 0x01, 0x49, 0x4D, 0x16}));
  EXPECT_EQ(r.kind, Reply::Kind::Bad);
}

}  // namespace
}  // namespace pbvbus::conformance::detail
