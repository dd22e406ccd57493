// socketcand parser, encoders and session (socketcand.hpp). Golden elements are written out by
// hand from linux-can/socketcand doc/protocol.md and python-can 4.1's client
// (tools-and-formats.md §2.3); runs under ASan+UBSan (sanitize_gateways).
#include "pbvbus/gateways/socketcand.hpp"

#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "can_door_test_support.hpp"

namespace pbvbus::gateways::socketcand {
namespace {

using can_test::frame;

TEST(SocketcandParse, SendAsPythonCanWritesIt) {
  // python-can: f"< send {id:X} {dlc:X} {' '.join('{:x}')} >".
  Parsed p = parse_element(" send 205 2 aa bb ");
  ASSERT_TRUE(p.command) << p.error;
  EXPECT_EQ(p.command->op, Op::Send);
  EXPECT_EQ(p.command->frame, frame(0x205, false, {0xAA, 0xBB}));
  // "< send 80 0  >" (no data: two spaces): 2 digits and 0x80 <= 0x7FF, so standard — an
  // extended id that small cannot be told apart; 8 digits or a value > 0x7FF is extended.
  p = parse_element(" send 80 0  ");
  ASSERT_TRUE(p.command) << p.error;
  EXPECT_EQ(p.command->frame, frame(0x80, false, {}));
  p = parse_element(" send 00000080 0 ");
  ASSERT_TRUE(p.command) << p.error;
  EXPECT_EQ(p.command->frame, frame(0x80, true, {}));
  p = parse_element(" send 18FF0001 3 1 2 3 ");
  ASSERT_TRUE(p.command) << p.error;
  EXPECT_EQ(p.command->frame, frame(0x18FF0001, true, {1, 2, 3}));
  p = parse_element(" send 800 1 F ");  // 0x800 > 0x7FF with 3 digits: extended (python-can)
  ASSERT_TRUE(p.command) << p.error;
  EXPECT_EQ(p.command->frame, frame(0x800, true, {0x0F}));
}

TEST(SocketcandParse, BadSendsAndUnknownCommandsAreErrors) {
  for (const char* bad : {" send ", " send 123 ", " send 123 2 11 ", " send 123 1 11 22 ",
                          " send 123 9 ", " send 12G 0 ", " send 123 1 100 ",
                          " send 20000000 0 ", " send 123456789 0 ", " frob ", "  ",
                          " open ", " open a b ", " rawmode x "}) {
    const Parsed p = parse_element(bad);
    EXPECT_FALSE(p.command) << bad;
    EXPECT_FALSE(p.error.empty()) << bad;
  }
  for (const char* u : {" controlmode ", " statistics 1000 ", " isotpmode ", " add 1 0 123 0 ",
                        " subscribe 0 0 123 "}) {
    const Parsed p = parse_element(u);
    ASSERT_TRUE(p.command) << u;
    EXPECT_EQ(p.command->op, Op::Unsupported) << u;
  }
}

TEST(SocketcandEncode, FramesWithVirtualTime) {
  // 23.424242 s = 23 s + 424242 us; ticks = 23*3636000000 + 424242*3636.
  const bus::Ticks t = 23 * bus::kTicksPerSecond + 424242 * bus::kTicksPerUs;
  EXPECT_EQ(encode_frame(frame(0x123, false, {0x1A, 0x22, 0x03, 0x44}), t),
            "< frame 123 23.424242 1A220344 >");
  EXPECT_EQ(encode_frame(frame(0x18FF0001, true, {0xAB}), 0), "< frame 18FF0001 0.000000 AB >");
  EXPECT_EQ(encode_frame(frame(0x7, false, {}), bus::kTicksPerUs - 1), "< frame 007 0.000000  >");
  EXPECT_EQ(encode_error("a<b>"), "< error a?b? >");
}

TEST(SocketcandSession, PythonCanHandshakeThenRawFrames) {
  SocketcandSession s("can0");
  std::vector<std::string> replies;
  std::vector<CanFrame> bus;
  EXPECT_EQ(SocketcandSession::greeting(), "< hi >");
  EXPECT_FALSE(s.frame_to_client(frame(0x181, false, {1}), 0));
  s.feed("< open can0 >", replies, bus);
  EXPECT_EQ(s.mode(), SocketcandSession::Mode::Bcm);
  EXPECT_FALSE(s.frame_to_client(frame(0x181, false, {1}), 0));  // BCM mode: no raw frames
  s.feed("< rawmode >", replies, bus);
  ASSERT_EQ(replies, (std::vector<std::string>{"< ok >", "< ok >"}));
  EXPECT_EQ(s.frame_to_client(frame(0x181, false, {1}), 0), " < frame 181 0.000000 01 >");
  // Split across feeds, two spaces for no data, plus an echo.
  s.feed("< send 205 2 aa", replies, bus);
  s.feed(" bb >< send 80 0  >\n< echo >", replies, bus);
  ASSERT_EQ(bus.size(), 2u);
  EXPECT_EQ(bus[0], frame(0x205, false, {0xAA, 0xBB}));
  EXPECT_EQ(bus[1], frame(0x80, false, {}));
  EXPECT_EQ(replies.back(), "< echo >");
  EXPECT_EQ(s.stats().frames_in, 2u);
  EXPECT_EQ(s.stats().errors, 0u);
}

TEST(SocketcandSession, WrongChannelAndSendBeforeOpenAreErrors) {
  SocketcandSession s("can0");
  std::vector<std::string> replies;
  std::vector<CanFrame> bus;
  s.feed("< send 123 0 >< rawmode >< open vcan7 >< bcmmode >", replies, bus);
  ASSERT_EQ(replies.size(), 4u);
  EXPECT_EQ(replies[0], "< error no bus open >");
  EXPECT_EQ(replies[2], "< error could not open bus vcan7 (this door serves can0) >");
  EXPECT_TRUE(bus.empty());
  EXPECT_EQ(s.mode(), SocketcandSession::Mode::Greeted);
}

TEST(SocketcandSession, GarbageAndOverlongElementsAreAnsweredThenClosed) {
  SocketcandSession s;
  std::vector<std::string> replies;
  std::vector<CanFrame> bus;
  s.feed("hello\n", replies, bus);  // one garbage run, one error at once
  ASSERT_EQ(replies.size(), 1u);
  EXPECT_EQ(replies[0], "< error garbage outside an element >");
  s.feed("< open can0 >", replies, bus);  // a valid command resets the row
  EXPECT_EQ(replies.back(), "< ok >");
  // An element of 300 characters: 257th character -> error, rest discarded to its '>'.
  s.feed("<" + std::string(300, 'x') + ">< echo >", replies, bus);
  ASSERT_EQ(replies.size(), 4u);
  EXPECT_EQ(replies[2], "< error element too long >");
  EXPECT_EQ(replies[3], "< echo >");
  EXPECT_FALSE(s.wants_close());
  // Endless garbage: one error at its start and one per further 256 bytes, so 7 * 256 bytes
  // make errors 1 (byte 1) + 7 (bytes 256, 512, ..., 1792) = 8 in a row -> close.
  s.feed(std::string(7 * 256 - 1, 'g'), replies, bus);
  EXPECT_FALSE(s.wants_close());
  s.feed("g", replies, bus);
  EXPECT_TRUE(s.wants_close());
  EXPECT_EQ(s.stats().garbage, 1u + 1u + 8u);
}

TEST(SocketcandSession, TheEighthErrorInARowEndsTheSessionInsideOneFeed) {
  // A 10 000-character element then `< echo >`, all in one feed (one read of the door). Errors:
  // the element is too long at its 257th character, then one more per further 256 characters
  // (up to 39 in all); the 8th in a row must end the session there: exactly 8 error answers,
  // the rest (the echo included) not read at all.
  SocketcandSession s;
  std::vector<std::string> replies;
  std::vector<CanFrame> bus;
  s.feed("<" + std::string(10'000, 'x') + "> < echo >", replies, bus);
  EXPECT_TRUE(s.wants_close());
  ASSERT_EQ(replies.size(), static_cast<std::size_t>(kMaxConsecutiveErrors));
  for (const std::string& r : replies) EXPECT_EQ(r, "< error element too long >");
  EXPECT_EQ(s.stats().errors, 8u);
  // Once closing, nothing more is read: a valid command does not revive the session.
  s.feed("< echo >< open can0 >", replies, bus);
  EXPECT_EQ(replies.size(), 8u);
  EXPECT_TRUE(s.wants_close());
  // Eight invalid elements in one feed, then more: the same, whatever kind of error.
  SocketcandSession t;
  std::vector<std::string> r2;
  t.feed("< a >< b >< c >< d >< e >< f >< g >< h >< i >< echo >", r2, bus);
  EXPECT_TRUE(t.wants_close());
  EXPECT_EQ(r2.size(), 8u);
  EXPECT_EQ(t.stats().elements, 8u);
}

TEST(SocketcandSession, UnsupportedCommandsAreStated) {
  SocketcandSession s;
  std::vector<std::string> replies;
  std::vector<CanFrame> bus;
  s.feed("< open can0 >< statistics 1000 >< controlmode >", replies, bus);
  ASSERT_EQ(replies.size(), 3u);
  EXPECT_EQ(replies[1], "< error statistics is not supported by pbvbus (raw mode only) >");
  EXPECT_EQ(replies[2], "< error controlmode is not supported by pbvbus (raw mode only) >");
}

TEST(SocketcandSession, GarbageBytesNeverThrow) {
  SocketcandSession s;
  std::vector<std::string> replies;
  std::vector<CanFrame> bus;
  std::string junk;
  for (int i = 0; i < 5000; ++i) junk += static_cast<char>((i * 131 + 7) & 0xFF);
  s.feed(junk, replies, bus);
  EXPECT_GT(s.stats().errors, 0u);
}

}  // namespace
}  // namespace pbvbus::gateways::socketcand
