#include "pbvbus/quantum/reference.hpp"

#include <gtest/gtest.h>

namespace pbvbus::quantum {
namespace {

TEST(QuantumReference, SixAndFiveDigitForms) {
  EXPECT_EQ(parse_reference("400001"), (Reference{RefType::Register4x, 0}));
  EXPECT_EQ(parse_reference("40001"), (Reference{RefType::Register4x, 0}));
  EXPECT_EQ(parse_reference("000001"), (Reference{RefType::Coil0x, 0}));
  EXPECT_EQ(parse_reference("100016"), (Reference{RefType::Input1x, 15}));
  EXPECT_EQ(parse_reference("365535"), (Reference{RefType::Register3x, 65534}));
  EXPECT_EQ(parse_reference("40012"), (Reference{RefType::Register4x, 11}));
}

TEST(QuantumReference, RefusesWhatNoConfiguratorWrites) {
  for (const char* bad : {"", "4", "4000001", "400000", "465536", "200001", "500001", "4000a1",
                          " 40001", "-40001", "40000"})
    EXPECT_FALSE(parse_reference(bad).has_value()) << bad;
}

TEST(QuantumReference, FormatsTheSixDigitForm) {
  EXPECT_EQ(format_reference(RefType::Register4x, 9007), "409008");
  EXPECT_EQ(format_reference(RefType::Coil0x, 0), "000001");
  EXPECT_EQ(format_reference(RefType::Register3x, 65534), "365535");
  for (std::uint32_t i : {0u, 1u, 999u, 9998u, 65534u})
    EXPECT_EQ(parse_reference(format_reference(RefType::Input1x, i)),
              (Reference{RefType::Input1x, i}));
}

}  // namespace
}  // namespace pbvbus::quantum
