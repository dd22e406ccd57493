// The per-Data_Exchange path of the DP slave does not allocate (design.md "Performance":
// station handling avoids per-frame heap allocation). Counts operator new calls made by this
// thread while the engine handles Data_Exchange requests with a reused Reply, as the
// PassiveStation does.
#include <gtest/gtest.h>

#include <cstdlib>
#include <new>

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

}  // namespace
}  // namespace pbvbus::dp
