// COTP class 0 CR/CC/DT/DR/DC/ER (ISO 8073; tools-and-formats.md §3.2, §3.4; stacks/s7).
#include "pbvbus/s7/cotp.hpp"

#include <gtest/gtest.h>

#include "hex.hpp"

#include "pbvbus/s7/cotp_connect.hpp"
#include "pbvbus/s7/cotp_data.hpp"
#include "pbvbus/s7/cotp_disconnect.hpp"
#include "pbvbus/s7/tpkt.hpp"
#include "pbvbus/s7/tsap.hpp"

namespace pbvbus::s7 {
namespace {

using test::hex;
using Bytes = std::vector<std::uint8_t>;

Bytes bytes(std::span<const std::uint8_t> s) {
  return Bytes(s.begin(), s.end());
}

// The CC a server sends for a CR, TPKT included.
Bytes cc_for(const Bytes& cr_tpdu, std::uint16_t own_ref = 1) {
  const auto cr = decode_connect_request(cr_tpdu);
  EXPECT_TRUE(cr.ok()) << to_string(cr.error);
  Bytes tpdu;
  EXPECT_EQ(append_connect(tpdu, confirm_for(cr.value, own_ref)), Error::None);
  Bytes out;
  EXPECT_EQ(append_tpkt(out, tpdu), Error::None);
  return out;
}

// nodes7 0.3.18's CR (tools-and-formats.md §3.4), without its TPKT header.
const Bytes kNodes7Cr = hex("11 E0 00 00 00 01 00 C0 01 0A C1 02 01 00 C2 02 01 02");
// libnodave's CR for rack 0 slot 2 (§3.2): C1 C2 first, TPDU size 512 (09) last.
const Bytes kLibnodaveCr = hex("11 E0 00 00 00 01 00 C1 02 01 00 C2 02 01 02 C0 01 09");

TEST(CotpConnect, Nodes7ConnectionRequestDecodes) {
  const auto cr = decode_connect_request(kNodes7Cr);
  ASSERT_TRUE(cr.ok()) << to_string(cr.error);
  EXPECT_EQ(cr.value.code, kCotpCr);
  EXPECT_EQ(cr.value.dst_ref, 0x0000);
  EXPECT_EQ(cr.value.src_ref, 0x0001);
  EXPECT_EQ(cr.value.class_option, 0x00);
  EXPECT_EQ(cr.value.tpdu_size_code, 0x0A);
  EXPECT_EQ(tpdu_size_octets(cr.value.tpdu_size_code), 1024u);
  EXPECT_EQ(bytes(cr.value.calling_tsap), hex("01 00"));
  EXPECT_EQ(bytes(cr.value.called_tsap), hex("01 02"));
  const auto called = parse_s7_tsap(cr.value.called_tsap);
  ASSERT_TRUE(called.has_value());
  EXPECT_EQ(*called, (S7Tsap{kTsapPg, 0, 2}));
}

// §3.4: "COTP CC : 03 00 00 16 11 D0 00 01 00 01 00 C0 01 0A C1 02 01 00 C2 02 01 02".
TEST(CotpConnect, ConfirmForNodes7IsTheReferenceCc) {
  EXPECT_EQ(cc_for(kNodes7Cr),
            hex("03 00 00 16 11 D0 00 01 00 01 00 C0 01 0A C1 02 01 00 C2 02 01 02"));
}

// libnodave checks `res == 22`: all three parameters echoed, in our fixed order.
TEST(CotpConnect, ConfirmForLibnodaveIs22OctetsWithAllThreeParameters) {
  const auto cc = cc_for(kLibnodaveCr);
  EXPECT_EQ(cc.size(), 22u);
  EXPECT_EQ(cc, hex("03 00 00 16 11 D0 00 01 00 01 00 C0 01 09 C1 02 01 00 C2 02 01 02"));
  const auto back = decode_connect_confirm(std::span(cc).subspan(4));
  ASSERT_TRUE(back.ok());
  EXPECT_EQ(back.value.dst_ref, 1);
  EXPECT_EQ(back.value.tpdu_size_code, 0x09);
}

TEST(CotpConnect, ConfirmLowersTheTpduSizeToClass0sLargest) {
  const auto cr = hex("11 E0 00 00 00 07 00 C0 01 0D C1 02 01 00 C2 02 01 02");
  const auto d = decode_connect_request(cr);
  ASSERT_TRUE(d.ok());
  const auto cc = confirm_for(d.value, 0x4711);
  EXPECT_EQ(cc.tpdu_size_code, kTpduSizeClass0MaxCode);
  EXPECT_EQ(cc.dst_ref, 7);
  EXPECT_EQ(cc.src_ref, 0x4711);
  EXPECT_EQ(confirm_for(d.value, 1, 0x08).tpdu_size_code, 0x08);
}

TEST(CotpConnect, CrWithoutSizeGetsCcWithoutSize) {
  const auto cr = hex("0E E0 00 00 00 01 00 C1 02 01 00 C2 02 02 01");
  EXPECT_EQ(cc_for(cr), hex("03 00 00 13 0E D0 00 01 00 01 00 C1 02 01 00 C2 02 02 01"));
}

TEST(CotpConnect, UnknownParametersAreSkipped) {
  // C6 (additional option selection) and F0 (preferred max TPDU size) between the known ones.
  const auto cr = hex("18 E0 00 00 00 01 00 C6 01 00 C1 02 01 00 F0 02 00 04 C2 02 01 02 C0 01 0A");
  const auto d = decode_connect_request(cr);
  ASSERT_TRUE(d.ok()) << to_string(d.error);
  EXPECT_EQ(d.value.tpdu_size_code, 0x0A);
  EXPECT_EQ(bytes(d.value.called_tsap), hex("01 02"));
}

TEST(CotpConnect, LongTsapsAreKeptAndEchoed) {
  // A 28-octet called TSAP like libnodave's routing variant (its layout is not interpreted).
  Bytes cr = hex("2B E0 00 00 00 01 00 C1 02 01 00 C2 1C");
  for (int i = 0; i < 28; ++i) cr.push_back(static_cast<std::uint8_t>(i));
  cr.insert(cr.end(), {0xC0, 0x01, 0x0A});
  const auto d = decode_connect_request(cr);
  ASSERT_TRUE(d.ok()) << to_string(d.error);
  EXPECT_EQ(d.value.called_tsap.size(), 28u);
  EXPECT_FALSE(parse_s7_tsap(d.value.called_tsap).has_value());
  Bytes out;
  ASSERT_EQ(append_connect(out, confirm_for(d.value, 1)), Error::None);
  const auto cc = decode_connect_confirm(out);
  ASSERT_TRUE(cc.ok());
  EXPECT_EQ(bytes(cc.value.called_tsap), bytes(d.value.called_tsap));
}

TEST(CotpConnect, CrRoundTripsThroughTheEncoder) {
  const auto d = decode_connect_request(kNodes7Cr);
  ASSERT_TRUE(d.ok());
  Bytes out;
  ASSERT_EQ(append_connect(out, d.value), Error::None);
  EXPECT_EQ(out, kNodes7Cr);
}

struct BadCr {
  const char* name;
  const char* octets;
  Error error;
  std::size_t at;
};

TEST(CotpConnect, EveryDecodeErrorIsNamedWithItsOffset) {
  const BadCr cases[] = {
      {"one octet", "11", Error::CotpTooShort, 1},
      {"LI 0", "00 E0", Error::CotpBadLengthIndicator, 0},
      {"LI 255", "FF E0 00", Error::CotpBadLengthIndicator, 0},
      {"LI past the end", "11 E0 00 00 00 01 00 C0 01 0A", Error::CotpBadLengthIndicator, 0},
      {"a CC", "11 D0 00 00 00 01 00 C0 01 0A C1 02 01 00 C2 02 01 02", Error::CotpUnexpectedType,
       1},
      {"a DT", "02 F0 80", Error::CotpUnexpectedType, 1},
      {"fixed part short", "05 E0 00 00 00 01", Error::CotpBadLengthIndicator, 0},
      {"parameter code only", "07 E0 00 00 00 01 00 C1", Error::CotpParameterTruncated, 7},
      {"parameter value short", "09 E0 00 00 00 01 00 C1 02 01", Error::CotpParameterTruncated, 8},
      {"size of 2 octets", "0A E0 00 00 00 01 00 C0 02 0A 0A", Error::CotpBadParameterLength, 8},
      {"size code 6", "09 E0 00 00 00 01 00 C0 01 06", Error::CotpBadTpduSize, 9},
      {"size code 14", "09 E0 00 00 00 01 00 C0 01 0E", Error::CotpBadTpduSize, 9},
      {"size twice", "0C E0 00 00 00 01 00 C0 01 0A C0 01 0A", Error::CotpDuplicateParameter, 10},
      {"calling twice", "0E E0 00 00 00 01 00 C1 02 01 00 C1 02 01 00",
       Error::CotpDuplicateParameter, 11},
      {"empty TSAP", "08 E0 00 00 00 01 00 C2 00", Error::CotpBadParameterLength, 8},
      {"no called TSAP", "0D E0 00 00 00 01 00 C0 01 0A C1 02 01 00", Error::CotpMissingTsap, 14},
      {"no calling TSAP", "0D E0 00 00 00 01 00 C0 01 0A C2 02 01 02", Error::CotpMissingTsap, 14},
      {"user data after the header", "06 E0 00 00 00 01 00 AA", Error::CotpBadLengthIndicator, 0},
  };
  for (const auto& c : cases) {
    const auto d = decode_connect_request(hex(c.octets));
    EXPECT_EQ(d.error, c.error) << c.name << ": " << to_string(d.error);
    EXPECT_EQ(d.at, c.at) << c.name;
  }
  Bytes tsap33 = hex("29 E0 00 00 00 01 00 C1 21");
  tsap33.resize(tsap33.size() + 33, 0x01);
  EXPECT_EQ(decode_connect_request(tsap33).error, Error::CotpBadParameterLength);
}

TEST(CotpConnect, EncoderRefusesTooLongTsapAndBadSizeAndWritesNothing) {
  const Bytes long_tsap(33, 0x01);
  ConnectTpdu t;
  t.calling_tsap = long_tsap;
  Bytes out;
  EXPECT_EQ(append_connect(out, t), Error::CotpParameterTooLong);
  ConnectTpdu s;
  s.tpdu_size_code = 6;
  EXPECT_EQ(append_connect(out, s), Error::CotpBadTpduSize);
  EXPECT_TRUE(out.empty());
}

TEST(CotpCode, HighNibbleOnlySoCreditBitsDoNotMatter) {
  EXPECT_EQ(cotp_code(hex("06 E3 00 00 00 01 00")).value, kCotpCr);
  EXPECT_EQ(cotp_code(hex("02 F0 80")).value, kCotpDt);
}

TEST(Tsap, RackSlotLayoutAndLimits) {
  EXPECT_EQ(parse_s7_tsap(hex("03 43")), (S7Tsap{kTsapS7Basic, 2, 3}));
  EXPECT_EQ(parse_s7_tsap(hex("02 FF")), (S7Tsap{kTsapOp, 7, 31}));
  EXPECT_EQ(s7_tsap_value(S7Tsap{kTsapPg, 0, 2}), 0x0102);
  EXPECT_EQ(s7_tsap_value(S7Tsap{kTsapS7Basic, 2, 3}), 0x0343);
  EXPECT_FALSE(parse_s7_tsap(hex("01")).has_value());
  EXPECT_FALSE(parse_s7_tsap(hex("01 02 03")).has_value());
}

TEST(CotpData, DecodesEotNumberAndUserData) {
  const auto tpdu = hex("02 F0 80 32 01");  // decoded spans point into it
  const auto d = decode_data(tpdu);
  ASSERT_TRUE(d.ok());
  EXPECT_TRUE(d.value.eot);
  EXPECT_EQ(d.value.number, 0);
  EXPECT_EQ(bytes(d.value.user_data), hex("32 01"));
  const auto more_tpdu = hex("02 F0 05 AA");
  const auto more = decode_data(more_tpdu);
  ASSERT_TRUE(more.ok());
  EXPECT_FALSE(more.value.eot);
  EXPECT_EQ(more.value.number, 5);
  EXPECT_TRUE(decode_data(hex("02 F0 80")).value.user_data.empty());
}

TEST(CotpData, Errors) {
  EXPECT_EQ(decode_data(hex("02")).error, Error::CotpTooShort);
  EXPECT_EQ(decode_data(hex("02 F0")).error, Error::CotpBadLengthIndicator);
  EXPECT_EQ(decode_data(hex("03 F0 80 00")).error, Error::CotpBadLengthIndicator);
  EXPECT_EQ(decode_data(hex("02 E0 80")).error, Error::CotpUnexpectedType);
  EXPECT_EQ(decode_data(hex("02 F1 80")).error, Error::CotpUnexpectedType);
}

// §3.4: the Setup Communication job as sent, TPKT + DT + S7 PDU.
TEST(CotpData, TpktDataFramesOneS7Pdu) {
  const auto pdu = hex("32 01 00 00 00 00 00 08 00 00 F0 00 00 01 00 01 01 E0");
  const auto f = encode_tpkt_data(pdu);
  ASSERT_TRUE(f.ok());
  EXPECT_EQ(f.value,
            hex("03 00 00 19 02 F0 80 32 01 00 00 00 00 00 08 00 00 F0 00 00 01 00 01 01 E0"));
  Bytes dt;
  append_data(dt, pdu, false);
  EXPECT_EQ(dt[2], 0x00);
  const Bytes huge(65530, 0);
  EXPECT_EQ(encode_tpkt_data(huge).error, Error::TpktPayloadTooLarge);
  EXPECT_TRUE(encode_tpkt_data(huge).value.empty());
}

TEST(CotpDisconnect, DrAndDcRoundTrip) {
  Bytes dr;
  append_disconnect_request(dr, 0x0001, 0x0002, dr_reason::kAddressUnknown);
  EXPECT_EQ(dr, hex("06 80 00 01 00 02 03"));
  const auto d = decode_disconnect(dr);
  ASSERT_TRUE(d.ok());
  EXPECT_EQ(d.value.code, kCotpDr);
  EXPECT_EQ(d.value.dst_ref, 1);
  EXPECT_EQ(d.value.src_ref, 2);
  EXPECT_EQ(d.value.reason, dr_reason::kAddressUnknown);
  // Additional information parameter (E0) after the reason is skipped.
  EXPECT_TRUE(decode_disconnect(hex("09 80 00 01 00 02 80 E0 01 00")).ok());

  Bytes dc;
  append_disconnect_confirm(dc, 0x0002, 0x0001);
  EXPECT_EQ(dc, hex("05 C0 00 02 00 01"));
  const auto c = decode_disconnect(dc);
  ASSERT_TRUE(c.ok());
  EXPECT_EQ(c.value.code, kCotpDc);
  EXPECT_EQ(c.value.dst_ref, 2);
}

TEST(CotpDisconnect, Errors) {
  EXPECT_EQ(decode_disconnect(hex("05 80 00 01 00 02")).error, Error::CotpBadLengthIndicator);
  EXPECT_EQ(decode_disconnect(hex("06 C0 00 01 00 02 00")).error, Error::CotpBadLengthIndicator);
  EXPECT_EQ(decode_disconnect(hex("02 F0 80")).error, Error::CotpUnexpectedType);
  EXPECT_EQ(decode_disconnect(hex("06 80 00")).error, Error::CotpBadLengthIndicator);
}

TEST(CotpError, ErCarriesTheRejectedTpdu) {
  Bytes er;
  append_error_tpdu(er, 0x0001, er_cause::kInvalidTpduType, hex("02 F7 80"));
  EXPECT_EQ(er, hex("09 70 00 01 02 C1 03 02 F7 80"));
  const auto e = decode_error_tpdu(er);
  ASSERT_TRUE(e.ok());
  EXPECT_EQ(e.value.dst_ref, 1);
  EXPECT_EQ(e.value.cause, er_cause::kInvalidTpduType);
  EXPECT_EQ(bytes(e.value.invalid_tpdu), hex("02 F7 80"));

  Bytes plain;
  append_error_tpdu(plain, 7, er_cause::kNotSpecified, {});
  EXPECT_EQ(plain, hex("04 70 00 07 00"));
  EXPECT_TRUE(decode_error_tpdu(plain).value.invalid_tpdu.empty());

  const Bytes big(400, 0xEE);
  Bytes capped;
  append_error_tpdu(capped, 1, er_cause::kInvalidParameterValue, big);
  EXPECT_EQ(capped[0], 254);
  EXPECT_EQ(capped.size(), 255u);
  EXPECT_EQ(decode_error_tpdu(capped).value.invalid_tpdu.size(), 248u);
}

TEST(CotpError, Errors) {
  EXPECT_EQ(decode_error_tpdu(hex("03 70 00 01")).error, Error::CotpBadLengthIndicator);
  EXPECT_EQ(decode_error_tpdu(hex("05 70 00 01 02 C1")).error, Error::CotpParameterTruncated);
  EXPECT_EQ(decode_error_tpdu(hex("06 70 00 01 02 C1 02 00")).error, Error::CotpParameterTruncated);
  EXPECT_EQ(decode_error_tpdu(hex("0A 70 00 01 02 C1 01 00 C1 01 00")).error,
            Error::CotpDuplicateParameter);
  EXPECT_EQ(decode_error_tpdu(hex("06 80 00 01 00 02 03")).error, Error::CotpUnexpectedType);
}

}  // namespace
}  // namespace pbvbus::s7
