// CpuMemory: sizes, data blocks (a missing DB is its own case), the owner's byte/bit helpers
// (controllers/s7cpu cpu_memory.hpp).
#include "pbvbus/s7cpu/cpu_memory.hpp"

#include <gtest/gtest.h>

namespace pbvbus::s7cpu {
namespace {

TEST(CpuMemory, SizesAreTheOwners) {
  CpuMemory m(CpuMemorySizes{16, 8, 32, 4, 2});
  EXPECT_EQ(m.area(Area::Inputs).size(), 16U);
  EXPECT_EQ(m.area(Area::Outputs).size(), 8U);
  EXPECT_EQ(m.area(Area::Flags).size(), 32U);
  EXPECT_EQ(m.counters().size(), 4U);
  EXPECT_EQ(m.timers().size(), 2U);
}

TEST(CpuMemory, DataBlocks) {
  CpuMemory m;
  EXPECT_FALSE(m.has_db(1));
  EXPECT_FALSE(m.db(1).has_value());
  m.create_db(1, 10);
  ASSERT_TRUE(m.db(1).has_value());
  EXPECT_EQ(m.db(1)->size(), 10U);
  // A DB of size 0 exists (every address in it is out of range), unlike a missing one.
  m.create_db(2, 0);
  EXPECT_TRUE(m.has_db(2));
  EXPECT_TRUE(m.delete_db(2));
  EXPECT_FALSE(m.delete_db(2));
  // Re-creating replaces (zero-filled).
  ASSERT_TRUE(set_byte(*m.db(1), 0, 0x55));
  m.create_db(1, 4);
  EXPECT_EQ(m.db(1)->size(), 4U);
  EXPECT_EQ(get_byte(*m.db(1), 0), 0);
}

TEST(CpuMemory, ByteBitWordDwordHelpersAreBigEndianAndBounded) {
  CpuMemory m(CpuMemorySizes{4, 4, 4, 1, 1});
  auto mb = m.area(Area::Flags);
  EXPECT_TRUE(set_bit(mb, 1, 7, true));
  EXPECT_EQ(mb[1], 0x80);
  EXPECT_EQ(get_bit(mb, 1, 7), true);
  EXPECT_EQ(get_bit(mb, 1, 6), false);
  EXPECT_TRUE(set_bit(mb, 1, 7, false));
  EXPECT_EQ(mb[1], 0x00);
  EXPECT_FALSE(set_bit(mb, 4, 0, true));
  EXPECT_FALSE(set_bit(mb, 0, 8, true));
  EXPECT_FALSE(get_bit(mb, 0, 8).has_value());
  EXPECT_TRUE(set_word(mb, 2, 0x1234));
  EXPECT_EQ(mb[2], 0x12);
  EXPECT_EQ(mb[3], 0x34);
  EXPECT_EQ(get_word(mb, 2), 0x1234);
  EXPECT_FALSE(set_word(mb, 3, 1));
  EXPECT_FALSE(get_word(mb, 3).has_value());
  EXPECT_TRUE(set_dword(mb, 0, 0xDEADBEEF));
  EXPECT_EQ(get_dword(mb, 0), 0xDEADBEEFU);
  EXPECT_EQ(get_byte(mb, 0), 0xDE);
  EXPECT_FALSE(set_dword(mb, 1, 0));
  EXPECT_FALSE(get_byte(mb, 4).has_value());
  EXPECT_FALSE(set_byte(mb, 4, 0));
}

}  // namespace
}  // namespace pbvbus::s7cpu
