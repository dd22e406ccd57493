// The runner's addressing check of every reply (conformance/src/reply_addressing.cpp;
// protocol-facts.md §B.2: a response mirrors its request). Every frame is summed by hand
// (§B.1: FCS = sum of DA..last DU octet mod 256).

#include <gtest/gtest.h>

#include <vector>

#include "../../conformance/src/groups.hpp"

namespace pbvbus::conformance::detail {
namespace {

using Bytes = std::vector<std::uint8_t>;

// Get_Cfg, master 1 -> slave 5: SD2, DA 85 (5 | EXT), SA 81, FC 4D, DSAP 3B (59), SSAP 3E (62);
// FCS = 85+81+4D+3B+3E = 0x1CC -> CC.
const Bytes kGetCfg = {0x68, 0x05, 0x05, 0x68, 0x85, 0x81, 0x4D, 0x3B, 0x3E, 0xCC, 0x16};
// Data_Exchange, master 1 -> slave 5, default SAP, outputs A5 5A: FCS = 05+01+4D+A5+5A = 0x152.
const Bytes kDataExchange = {0x68, 0x05, 0x05, 0x68, 0x05, 0x01, 0x4D, 0xA5, 0x5A, 0x52, 0x16};

Exchange made(const Bytes& request, const Bytes& response) {
  // Every frame here is well formed, so an empty answer of the check means "mirrored", never
  // "could not decode".
  fdl::Telegram t;
  EXPECT_EQ(fdl::decode(request, t), fdl::DecodeError::None);
  if (response.size() > 1) {
    EXPECT_EQ(fdl::decode(response, t), fdl::DecodeError::None);
  }
  Exchange e;
  e.request = request;
  e.answered = true;
  e.response = response;
  e.note = "the request";
  return e;
}

TEST(ReplyAddressing, MirroredGetCfgReplyPasses) {
  // DL (FC 08), DSAP 3E = the request's SSAP, SSAP 3B = its DSAP, DU 11 21:
  // FCS = 81+85+08+3E+3B+11+21 = 0x1B9 -> B9.
  const Bytes ok = {0x68, 0x07, 0x07, 0x68, 0x81, 0x85, 0x08, 0x3E, 0x3B, 0x11, 0x21, 0xB9, 0x16};
  EXPECT_EQ(reply_addressing_fault(made(kGetCfg, ok)), "");
}

TEST(ReplyAddressing, SapsNotSwappedAreAFault) {
  // The same reply with DSAP 3B, SSAP 3E (the request's, not mirrored); the same sum, FCS B9.
  const Bytes bad = {0x68, 0x07, 0x07, 0x68, 0x81, 0x85, 0x08, 0x3B, 0x3E, 0x11, 0x21, 0xB9, 0x16};
  const std::string why = reply_addressing_fault(made(kGetCfg, bad));
  EXPECT_NE(why.find("DSAP 59, SSAP 62 (expected DSAP 62 = the request's SSAP, SSAP 59 = the "
                     "request's DSAP)"),
            std::string::npos)
      << why;
}

TEST(ReplyAddressing, WrongDestinationIsAFault) {
  // RS as SD1 to DA 2 instead of 1: 10 02 05 03, FCS = 02+05+03 = 0A.
  const Bytes bad = {0x10, 0x02, 0x05, 0x03, 0x0A, 0x16};
  const std::string why = reply_addressing_fault(made(kGetCfg, bad));
  EXPECT_NE(why.find("DA 2 (expected 1 = the request's SA)"), std::string::npos) << why;
}

TEST(ReplyAddressing, ShortRsWithoutSapsIsAllowed) {
  // RS (SAP not activated) as SD1 cannot carry SAPs: 10 01 05 03, FCS = 01+05+03 = 09.
  EXPECT_EQ(reply_addressing_fault(made(kGetCfg, {0x10, 0x01, 0x05, 0x03, 0x09, 0x16})), "");
}

TEST(ReplyAddressing, DataWithoutSapsToASapRequestIsAFault) {
  // DL with DU 11 21 but no extension octets: 68 05 05 68 01 05 08 11 21, FCS = 0x40.
  const Bytes bad = {0x68, 0x05, 0x05, 0x68, 0x01, 0x05, 0x08, 0x11, 0x21, 0x40, 0x16};
  const std::string why = reply_addressing_fault(made(kGetCfg, bad));
  EXPECT_NE(why.find("no SAPs on a reply with data"), std::string::npos) << why;
}

TEST(ReplyAddressing, DataExchangeReplyCarriesNoSaps) {
  // Inputs 00 01 without SAPs: FCS = 01+05+08+00+01 = 0F -> passes.
  EXPECT_EQ(reply_addressing_fault(made(
                kDataExchange, {0x68, 0x05, 0x05, 0x68, 0x01, 0x05, 0x08, 0x00, 0x01, 0x0F, 0x16})),
            "");
  // The same inputs with DSAP 3E, SSAP 3B: FCS = 81+85+08+3E+3B+00+01 = 0x188 -> 88.
  const Bytes bad = {0x68, 0x07, 0x07, 0x68, 0x81, 0x85, 0x08, 0x3E, 0x3B, 0x00, 0x01, 0x88, 0x16};
  const std::string why = reply_addressing_fault(made(kDataExchange, bad));
  EXPECT_NE(why.find("expected none: the request used the default SAP"), std::string::npos) << why;
}

TEST(ReplyAddressing, ShortConfirmationAndNoReplyHaveNothingToCheck) {
  EXPECT_EQ(reply_addressing_fault(made(kGetCfg, {0xE5})), "");
  Exchange none = made(kGetCfg, {});
  none.answered = false;
  EXPECT_EQ(reply_addressing_fault(none), "");
}

}  // namespace
}  // namespace pbvbus::conformance::detail
