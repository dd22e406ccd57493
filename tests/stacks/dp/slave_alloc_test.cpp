// The per-Data_Exchange path of the DP slave does not allocate (design.md "Performance":
// station handling avoids per-frame heap allocation). Counts operator new calls made by this
// thread while the engine handles Data_Exchange requests with a reused Reply, as the
// PassiveStation does.
#include <gtest/gtest.h>

#include <cstdlib>
#include <new>

#include "pbvbus/dp/master.hpp"
#include "pbvbus/dp/slave_engine.hpp"

namespace {
thread_local bool t_counting = false;
thread_local long t_allocations = 0;
}  // namespace

// Replacing the global allocation functions with malloc/free is legal; GCC cannot tell.
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wmismatched-new-delete"
void* operator new(std::size_t n) {
  if (t_counting) ++t_allocations;
  if (void* p = std::malloc(n == 0 ? 1 : n)) return p;
  throw std::bad_alloc();
}
void operator delete(void* p) noexcept { std::free(p); }
void operator delete(void* p, std::size_t) noexcept { std::free(p); }
#pragma GCC diagnostic pop

namespace pbvbus::dp {
namespace {

TEST(SlaveAllocation, DataExchangeDoesNotAllocate) {
  SlaveConfig cfg;
  cfg.ident = 0x1234;
  cfg.modules = {{{0xDF}, "32 in"}, {{0xEF}, "32 out"}, {{0x31}, "2+2"}};
  cfg.features.sync = cfg.features.freeze = true;
  SlaveEngine e(cfg);
  fdl::Reply reply;
  auto request = [&](std::optional<std::uint8_t> dsap, std::span<const std::uint8_t> data,
                     std::uint8_t da = 10, fdl::RequestFn fn = fdl::RequestFn::SrdHigh) {
    fdl::Indication ind;
    ind.sa = 1;
    ind.da = da;
    ind.fn = fn;
    ind.dsap = dsap;
    if (dsap) ind.ssap = 62;
    ind.data = data;
    reply.kind = fdl::Reply::Kind::Status;
    reply.status = fdl::ResponseStatus::RS;
    e.on_request(ind, reply);
  };
  const std::uint8_t prm[] = {0xB8, 0x0A, 0x0A, 0x0B, 0x12, 0x34, 0x00};
  request(kSapSetPrm, prm);
  request(kSapChkCfg, e.layout().cfg);
  ASSERT_EQ(e.state(), SlaveState::DataExch);
  std::vector<std::uint8_t> out(e.layout().outputs, 0x5A);
  std::vector<std::uint8_t> in(2, 0x11);
  request(std::nullopt, out);  // warm-up: the Reply's buffer takes its size
  ASSERT_EQ(reply.data.size(), e.layout().inputs);

  const std::uint8_t freeze[] = {0x08, 0x00};
  t_counting = true;
  for (int i = 0; i < 1000; ++i) {
    out[0] = static_cast<std::uint8_t>(i);
    e.application().write_inputs(2, in);
    request(std::nullopt, out);
    if (i == 500) request(kSapGlobalControl, freeze, 127, fdl::RequestFn::SdnHigh);
  }
  t_counting = false;
  EXPECT_EQ(t_allocations, 0);
  EXPECT_TRUE(e.freeze_mode());
  EXPECT_EQ(reply.status, fdl::ResponseStatus::DL);
}

// The hot-standby master's shadow (master_hsby.cpp) runs for every frame on the line: following
// the active master's Data_Exchange cycles does not allocate either. (Here because this file
// holds the binary's replacement of operator new.)
TEST(SlaveAllocation, StandbyMasterShadowDoesNotAllocate) {
  SlaveParams sp;
  sp.address = 10;
  sp.ident = 0x1234;
  sp.modules = {{{0xDF}, "32 in"}, {{0xEF}, "32 out"}};
  MasterParams mp;
  mp.standby = true;
  Master m(mp, {sp});
  m.on_power_on(0);
  std::vector<std::uint8_t> out(32, 0x5A), in(32, 0x11);
  fdl::Telegram req;
  req.type = fdl::FrameType::SD2;
  req.da = 10;
  req.sa = 1;
  req.fc = fdl::make_request_fc(fdl::RequestFn::SrdHigh, true, true);
  req.data = out;
  fdl::Telegram rsp;
  rsp.type = fdl::FrameType::SD2;
  rsp.da = 1;
  rsp.sa = 10;
  rsp.fc = fdl::make_response_fc(fdl::StationType::Slave, fdl::ResponseStatus::DL);
  rsp.data = in;
  fdl::Telegram token;
  token.type = fdl::FrameType::SD4;
  token.da = 1;
  token.sa = 1;
  m.on_observed(1, req);
  m.on_observed(2, rsp);
  ASSERT_TRUE(m.shadow_in_dx(10));
  t_counting = true;
  for (int i = 0; i < 1000; ++i) {
    out[0] = static_cast<std::uint8_t>(i);
    m.on_observed(10 * i + 3, req);
    m.on_observed(10 * i + 4, rsp);
    m.on_observed(10 * i + 5, token);
  }
  t_counting = false;
  EXPECT_EQ(t_allocations, 0);
  EXPECT_EQ(m.hsby_stats().dx_observed, 1001u);
  std::vector<std::uint8_t> got(32);
  ASSERT_EQ(m.image(10).read_outputs(1, got), ImageAccess::Ok);
  EXPECT_EQ(got[0], static_cast<std::uint8_t>(999));
}

}  // namespace
}  // namespace pbvbus::dp
