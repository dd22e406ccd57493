// A small Hot Standby campaign on the DP line in the sanitizer builds (hsby_campaign.hpp): 120
// injections over every fault kind, three slaves, nothing found by the observer.
#include <gtest/gtest.h>

#include "pbvbus/quantum/hsby_campaign.hpp"

namespace pbvbus::quantum {
namespace {

TEST(HsbyCampaignSanitize, SmallCampaignFindsNothing) {
  HsbyCampaignOptions o;
  o.seed = 3;
  o.steps = 120;
  const HsbyCampaignResult r = run_hsby_campaign(o);
  EXPECT_TRUE(r.clean()) << r.summary();
  EXPECT_GE(r.injections(), 120);
  EXPECT_EQ(r.switchovers, r.expected_switchovers);
  EXPECT_GT(r.slave_samples, 0u);
}

}  // namespace
}  // namespace pbvbus::quantum
