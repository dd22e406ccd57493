// The H-system code under ASan+UBSan (built into sanitize_devices, run by the sanitizer build):
// a short seeded H campaign - CPU power/STOP, fibres, F6's two masters, IM, short circuit, DP
// master module, ERROR-SEARCH, OB 121/DEFECTIVE and the operator swap go through HCpuPair,
// HSystemModel, the MasterSystem and the station models once.
#include <gtest/gtest.h>

#include <string>

#include "pbvbus/s7h/h_campaign.hpp"

namespace pbvbus::devices {
namespace {

TEST(HCampaignSanitize, ShortCampaignIsCleanAndCorrect) {
  HCampaignOptions o;
  o.seed = 3;
  o.steps = 40;
  o.gsd_dir = std::string(PBVBUS_SOURCE_DIR) + "/examples/gsd";
  const HCampaignResult r = run_h_campaign(o);
  EXPECT_GE(r.injections(), 40);
  EXPECT_EQ(r.pulses, 0u);
  EXPECT_EQ(r.second_master_frames, 0u);
  for (const auto& m : r.mismatches) ADD_FAILURE() << m;
}

}  // namespace
}  // namespace pbvbus::devices
