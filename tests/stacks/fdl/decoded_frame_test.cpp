// fdl::decode_once() and the bus::FrameMemo slot (docs/architecture.md "Decode once per frame"):
// a view is decoded once, a different view of the same octets is not taken for it, and without
// a memo the caller's scratch is used.

#include <gtest/gtest.h>

#include <array>
#include <cstdint>
#include <span>

#include "pbvbus/bus/frame_memo.hpp"
#include "pbvbus/fdl/decoded_frame.hpp"
#include "pbvbus/fdl/telegram.hpp"

namespace pbvbus::fdl {
namespace {

Frame request() {
  FrameSpec s;
  s.da = 5;
  s.sa = 1;
  s.fc = make_request_fc(RequestFn::SrdHigh, true, true);
  static const std::array<std::uint8_t, 4> data{1, 2, 3, 4};
  s.data = data;
  Frame f;
  EXPECT_EQ(encode(s, f), EncodeError::None);
  return f;
}

TEST(DecodedFrame, SameViewIsDecodedOnce) {
  const Frame f = request();
  bus::FrameMemo memo;
  DecodedFrame a, b;
  const DecodedFrame& first = decode_once(f.bytes(), &memo, a);
  const DecodedFrame& second = decode_once(f.bytes(), &memo, b);
  EXPECT_EQ(&first, &second);  // the memo's entry, not either scratch
  EXPECT_NE(&first, &a);
  ASSERT_TRUE(first.ok());
  EXPECT_EQ(first.telegram.da, 5);
  EXPECT_EQ(first.telegram.sa, 1);
  EXPECT_EQ(first.telegram.data.size(), 4u);
  EXPECT_EQ(first.telegram.data.data(), f.bytes().data() + 7);  // points into the frame
}

TEST(DecodedFrame, AShorterViewIsNotTakenForTheWholeFrame) {
  const Frame f = request();
  bus::FrameMemo memo;
  DecodedFrame scratch;
  ASSERT_TRUE(decode_once(f.bytes(), &memo, scratch).ok());
  const auto partial = f.bytes().first(5);  // a frame cut short for some receivers
  const DecodedFrame& p = decode_once(partial, &memo, scratch);
  EXPECT_EQ(p.error, DecodeError::Truncated);
  // And the whole frame again is decoded again (the slot now holds the partial view).
  EXPECT_TRUE(decode_once(f.bytes(), &memo, scratch).ok());
}

TEST(DecodedFrame, ClearedSlotDecodesAgain) {
  Frame f = request();
  bus::FrameMemo memo;
  DecodedFrame scratch;
  ASSERT_TRUE(decode_once(f.bytes(), &memo, scratch).ok());
  f.buf[7] ^= 0xFF;  // garbled in place, as a collision does; the line then clears the slot
  memo.clear();
  EXPECT_EQ(decode_once(f.bytes(), &memo, scratch).error, DecodeError::BadFcs);
}

TEST(DecodedFrame, AnotherOwnersEntryIsNotTaken) {
  const Frame f = request();
  bus::FrameMemo memo;
  static const char other_owner = 0;
  memo.store(&other_owner, f.bytes());
  DecodedFrame scratch;
  EXPECT_TRUE(decode_once(f.bytes(), &memo, scratch).ok());
  EXPECT_EQ(memo.find(&other_owner, f.bytes()), nullptr);
}

TEST(DecodedFrame, WithoutMemoTheScratchIsUsed) {
  const Frame f = request();
  DecodedFrame scratch;
  const DecodedFrame& d = decode_once(f.bytes(), nullptr, scratch);
  EXPECT_EQ(&d, &scratch);
  EXPECT_TRUE(d.ok());
}

}  // namespace
}  // namespace pbvbus::fdl
