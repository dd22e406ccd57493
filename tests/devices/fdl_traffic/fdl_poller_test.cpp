// FdlPoller (traffic-generating initiator user) and FdlResponder (passive-station user).
#include <gtest/gtest.h>

#include "pbvbus/fdl_traffic/fdl_poller.hpp"
#include "pbvbus/fdl_traffic/fdl_responder.hpp"

namespace pbvbus::devices {
namespace {

using fdl::Priority;
using fdl::RequestFn;

TEST(FdlPoller, OffersEachItemOncePerTokenVisitHighFirstByPriority) {
  FdlPoller p({{10, RequestFn::SrdLow, 2}, {11, RequestFn::SrdHigh, 0}, {12, RequestFn::SdaLow, 1}});
  p.on_token(0, 0);
  fdl::Request r;
  ASSERT_TRUE(p.next_request(Priority::High, 0, r));
  EXPECT_EQ(r.da, 11);
  EXPECT_EQ(r.fn, RequestFn::SrdHigh);
  EXPECT_FALSE(p.next_request(Priority::High, 0, r));
  ASSERT_TRUE(p.next_request(Priority::Low, 0, r));
  EXPECT_EQ(r.da, 10);
  EXPECT_EQ(r.data, (std::vector<std::uint8_t>{0, 1}));
  EXPECT_EQ(r.tag, 0u);
  // The hold time ran out here: the next visit starts with the item left over (12).
  p.on_token(100, 100);
  ASSERT_TRUE(p.next_request(Priority::Low, 0, r));
  EXPECT_EQ(r.da, 12);
  EXPECT_EQ(r.fn, RequestFn::SdaLow);
  ASSERT_TRUE(p.next_request(Priority::Low, 0, r));
  EXPECT_EQ(r.da, 10);
  EXPECT_EQ(r.data, (std::vector<std::uint8_t>{1, 2}));  // the data counter moved on
  EXPECT_FALSE(p.next_request(Priority::Low, 0, r));
  EXPECT_EQ(p.tokens(), 2u);
  EXPECT_EQ(p.rotation_times(), (std::vector<bus::Ticks>{100}));  // 0 = first token: no sample
}

TEST(FdlPoller, CountsConfirmations) {
  FdlPoller p({{10, RequestFn::SrdLow, 2}, {11, RequestFn::SdnLow, 1}});
  fdl::Confirmation c;
  c.tag = 0;
  c.result = fdl::Confirmation::Result::Ok;
  const std::uint8_t d[3] = {1, 2, 3};
  c.data = d;
  c.retries = 1;
  p.on_confirmation(c);
  c.result = fdl::Confirmation::Result::NoResponse;
  c.data = {};
  p.on_confirmation(c);
  c.tag = 1;
  c.retries = 0;
  c.result = fdl::Confirmation::Result::Sent;
  p.on_confirmation(c);
  c.tag = 7;  // not ours: ignored
  p.on_confirmation(c);
  EXPECT_EQ(p.stats(0).requests, 2u);
  EXPECT_EQ(p.stats(0).ok, 1u);
  EXPECT_EQ(p.stats(0).no_response, 1u);
  EXPECT_EQ(p.stats(0).retries, 2u);
  EXPECT_EQ(p.stats(0).data_octets, 3u);
  EXPECT_EQ(p.stats(1).sent, 1u);
  EXPECT_EQ(p.total().requests, 3u);
}

TEST(FdlResponder, AnswersSrdWithChangingDataAndSdaWithSc) {
  FdlResponder r(3);
  fdl::Indication ind;
  ind.fn = RequestFn::SrdLow;
  fdl::Reply rep;
  r.on_request(ind, rep);
  EXPECT_EQ(rep.kind, fdl::Reply::Kind::Data);
  EXPECT_EQ(rep.status, fdl::ResponseStatus::DL);
  EXPECT_EQ(rep.data, (std::vector<std::uint8_t>{0, 1, 2}));
  ind.fn = RequestFn::SrdHigh;
  r.on_request(ind, rep);
  EXPECT_EQ(rep.data, (std::vector<std::uint8_t>{1, 2, 3}));
  fdl::Reply sda;
  ind.fn = RequestFn::SdaHigh;
  r.on_request(ind, sda);
  EXPECT_EQ(sda.kind, fdl::Reply::Kind::ShortAck);
  fdl::Reply sdn;
  ind.fn = RequestFn::SdnLow;
  r.on_request(ind, sdn);
  EXPECT_EQ(sdn.kind, fdl::Reply::Kind::None);
  fdl::Reply ident;
  ind.fn = RequestFn::Ident;
  r.on_request(ind, ident);
  EXPECT_EQ(ident.kind, fdl::Reply::Kind::Status);
  EXPECT_EQ(ident.status, fdl::ResponseStatus::RS);
  EXPECT_EQ(r.srd(), 2u);
  EXPECT_EQ(r.sda(), 1u);
  EXPECT_EQ(r.sdn(), 1u);
  EXPECT_EQ(r.other(), 1u);
  FdlResponder empty(0);
  fdl::Reply e;
  ind.fn = RequestFn::SrdLow;
  empty.on_request(ind, e);
  EXPECT_EQ(e.kind, fdl::Reply::Kind::ShortAck);
}

}  // namespace
}  // namespace pbvbus::devices
