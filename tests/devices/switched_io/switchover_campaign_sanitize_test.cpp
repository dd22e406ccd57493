// The switched-I/O code under ASan+UBSan (built into sanitize_devices, run by the sanitizer
// build): a short seeded fault campaign over the redundant master system and its switched
// stations — every fault kind, repairs, alarms, start-ups and switchovers go through
// redundancy::MasterSystem, RedundantSlave, the dp master/slave engines and the models once.
#include <gtest/gtest.h>

#include <string>

#include "pbvbus/switched_io/switchover_campaign.hpp"

namespace pbvbus::devices {
namespace {

TEST(SwitchoverCampaignSanitize, ShortCampaignIsCleanAndCorrect) {
  CampaignOptions o;
  o.seed = 3;
  o.faults = 40;
  o.gsd_dir = std::string(PBVBUS_SOURCE_DIR) + "/examples/gsd";
  const CampaignResult r = run_campaign(o);
  EXPECT_GE(r.injections(), 40);
  EXPECT_EQ(r.pulses, 0u);
  for (const auto& m : r.mismatches) ADD_FAILURE() << m;
  EXPECT_EQ(r.alarms_lost, 0);
  EXPECT_EQ(r.alarms_duplicated, 0);
}

}  // namespace
}  // namespace pbvbus::devices
