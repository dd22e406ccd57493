// F3 parameter records of a scenario (prm_record_plan.hpp): the hex octets of `data`, by hand.
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "pbvbus/scenario/prm_record_plan.hpp"

namespace pbvbus::tools {
namespace {

using Bytes = std::vector<std::uint8_t>;

TEST(PrmRecordParser, HexOctets) {
  std::string why;
  EXPECT_EQ(parse_hex_octets("12 34", &why), (Bytes{0x12, 0x34}));
  EXPECT_EQ(parse_hex_octets("1234", &why), (Bytes{0x12, 0x34}));
  EXPECT_EQ(parse_hex_octets(" aB  0f ", &why), (Bytes{0xAB, 0x0F}));
  EXPECT_EQ(parse_hex_octets("", &why), std::nullopt);
  EXPECT_EQ(why, "no octets");
  EXPECT_EQ(parse_hex_octets("   ", &why), std::nullopt);
  EXPECT_EQ(parse_hex_octets("123", &why), std::nullopt);
  EXPECT_EQ(why, "octet at 3 needs two hex digits");
  EXPECT_EQ(parse_hex_octets("1 2", &why), std::nullopt);  // a blank inside an octet
  EXPECT_EQ(why, "octet at 1 needs two hex digits");
  EXPECT_EQ(parse_hex_octets("0x12", &why), std::nullopt);
  EXPECT_EQ(why, "octet at 1 needs two hex digits");
  EXPECT_EQ(parse_hex_octets("G1", &why), std::nullopt);
  EXPECT_EQ(why, "\"G\" at 1 is not a hex digit");
  EXPECT_EQ(parse_hex_octets("12,34", &why), std::nullopt);
  EXPECT_EQ(why, "\",\" at 3 is not a hex digit");
  EXPECT_EQ(parse_hex_octets(std::string("1\0", 2), nullptr), std::nullopt);
  EXPECT_EQ(parse_hex_octets(std::string(480, 'f'), nullptr)->size(), 240u);
}

TEST(PrmRecordParser, PlanRefusesWithoutC1AndTwice) {
  scenario::DpSlave s;
  auto* r = s.add_parameter_record();
  r->set_module_index(0);
  r->set_index(1);
  r->set_data("01");
  std::vector<std::pair<int, std::string>> errs;
  EXPECT_TRUE(plan_prm_records(s, {"A"}, false, errs).empty());
  ASSERT_EQ(errs.size(), 1u);
  EXPECT_EQ(errs[0].first, 0);
  errs.clear();
  *s.add_parameter_record() = *r;
  const auto p = plan_prm_records(s, {"A"}, true, errs);
  EXPECT_EQ(p, (std::vector<DpPrmRecordPlan>{{0, 1, {0x01}}}));
  ASSERT_EQ(errs.size(), 1u);
  EXPECT_EQ(errs[0], (std::pair<int, std::string>{1, "parameter_record: module 0 record 1 is given twice"}));
}

}  // namespace
}  // namespace pbvbus::tools
