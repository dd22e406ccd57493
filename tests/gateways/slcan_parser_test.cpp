// SLCAN parser, encoders and session (slcan.hpp). Golden lines are written out by hand from the
// Lawicel command table (tools-and-formats.md §2.2); runs under ASan+UBSan (sanitize_gateways).
#include "pbvbus/gateways/slcan.hpp"

#include <gtest/gtest.h>

#include <string>
#include <vector>

namespace pbvbus::gateways::slcan {
namespace {

CanFrame frame(std::uint32_t id, bool ext, bool rtr, std::vector<std::uint8_t> data,
               std::uint8_t dlc = 0xFF) {
  CanFrame f;
  f.id = id;
  f.extended = ext;
  f.rtr = rtr;
  f.dlc = dlc == 0xFF ? static_cast<std::uint8_t>(data.size()) : dlc;
  for (std::size_t i = 0; i < data.size(); ++i) f.data[i] = data[i];
  return f;
}

TEST(SlcanParse, FrameCommands) {
  // t 205 2 AA BB: standard id 0x205, DLC 2, data AA BB.
  Parsed p = parse_line("t2052AABB");
  ASSERT_TRUE(p.command) << p.error;
  EXPECT_EQ(p.command->op, Op::Send);
  EXPECT_EQ(p.command->frame, frame(0x205, false, false, {0xAA, 0xBB}));
  // T 18FF0001 3 01 02 03 (python-can's extended send), lower-case hex accepted too.
  p = parse_line("T18ff0001301020a");
  ASSERT_TRUE(p.command) << p.error;
  EXPECT_EQ(p.command->frame, frame(0x18FF0001, true, false, {0x01, 0x02, 0x0A}));
  // r 705 1: RTR, DLC 1, no data characters.
  p = parse_line("r7051");
  ASSERT_TRUE(p.command) << p.error;
  EXPECT_EQ(p.command->frame, frame(0x705, false, true, {}, 1));
  p = parse_line("R000000808");
  ASSERT_TRUE(p.command) << p.error;
  EXPECT_EQ(p.command->frame, frame(0x80, true, true, {}, 8));
  // 8 data bytes: the longest valid command, 1 + 8 + 1 + 16 = 26 characters.
  p = parse_line("T1FFFFFFF81122334455667788");
  ASSERT_TRUE(p.command) << p.error;
  EXPECT_EQ(p.command->frame,
            frame(0x1FFFFFFF, true, false, {0x11, 0x22, 0x33, 0x44, 0x55, 0x66, 0x77, 0x88}));
}

TEST(SlcanParse, BadFramesAreErrors) {
  for (const char* bad : {"t2052AAB",            // one data digit short
                          "t2052AABBCC",         // one byte too many
                          "t2059",               // DLC 9
                          "t800",                // no DLC
                          "t8000",               // id 0x800 > 0x7FF
                          "T200000000",          // id > 0x1FFFFFFF
                          "t20G0",               // not hex
                          "t2052AAZZ",           // data not hex
                          "r70510",              // RTR carries no data
                          "t"}) {
    EXPECT_FALSE(parse_line(bad).command) << bad;
    EXPECT_FALSE(parse_line(bad).error.empty()) << bad;
  }
}

TEST(SlcanParse, OtherCommands) {
  struct Case {
    const char* line;
    Op op;
    std::uint32_t value;
  };
  for (const Case& c : {Case{"", Op::Empty, 0}, Case{"S6", Op::SetBitrate, 6},
                        Case{"S0", Op::SetBitrate, 0}, Case{"S8", Op::SetBitrate, 8},
                        Case{"s031C", Op::SetBtr, 0x031C}, Case{"O", Op::Open, 0},
                        Case{"L", Op::ListenOnly, 0}, Case{"C", Op::Close, 0},
                        Case{"F", Op::ReadFlags, 0}, Case{"V", Op::Version, 0},
                        Case{"v", Op::SoftwareVersion, 0}, Case{"N", Op::SerialNumber, 0},
                        Case{"Z1", Op::Timestamps, 1}, Case{"Z0", Op::Timestamps, 0},
                        Case{"M12345678", Op::AcceptanceCode, 0x12345678},
                        Case{"mFFFFFFFF", Op::AcceptanceMask, 0xFFFFFFFF},
                        Case{"X1", Op::AutoPoll, 1}, Case{"Q2", Op::AutoStart, 2},
                        Case{"U6", Op::UartRate, 6}, Case{"P", Op::PollOne, 0},
                        Case{"A", Op::PollAll, 0}}) {
    const Parsed p = parse_line(c.line);
    ASSERT_TRUE(p.command) << c.line << ": " << p.error;
    EXPECT_EQ(p.command->op, c.op) << c.line;
    EXPECT_EQ(p.command->value, c.value) << c.line;
  }
  for (const char* bad : {"S9", "S", "S66", "s031", "s03XY", "O1", "Z2", "M1234567", "Q3",
                          "U7", "x", "?", "Vx"})
    EXPECT_FALSE(parse_line(bad).command) << bad;
}

TEST(SlcanEncode, FramesAsTheHostReceivesThem) {
  EXPECT_EQ(encode_frame(frame(0x205, false, false, {0xAA, 0xBB})), "t2052AABB\r");
  EXPECT_EQ(encode_frame(frame(0x18FF0001, true, false, {1, 2, 3})), "T18FF00013010203\r");
  EXPECT_EQ(encode_frame(frame(0x7, false, false, {})), "t0070\r");
  EXPECT_EQ(encode_frame(frame(0x705, false, true, {}, 1)), "r7051\r");
  EXPECT_EQ(encode_frame(frame(0x80, true, true, {}, 0)), "R000000800\r");
  // Timestamp 0xEA5F = 59999 ms, the largest.
  EXPECT_EQ(encode_frame(frame(0x123, false, false, {0x01}), 59999), "t123101EA5F\r");
  EXPECT_EQ(serial_reply("PBV1"), "NPBV1\r");
  EXPECT_EQ(serial_reply("7"), "N7000\r");
  EXPECT_EQ(flags_reply(0x08), "F08\r");
}

TEST(SlcanEncode, TimestampIsVirtualMsModulo60000) {
  EXPECT_EQ(timestamp_ms(0), 0);
  EXPECT_EQ(timestamp_ms(1234 * bus::kTicksPerMs + bus::kTicksPerMs - 1), 1234);
  // 61.5 s -> 61500 ms -> 61500 - 60000 = 1500.
  EXPECT_EQ(timestamp_ms(61'500 * bus::kTicksPerMs), 1500);
}

TEST(SlcanEncode, RoundTrip) {
  // Every frame the encoder writes parses back to itself (the host and the adapter share the
  // t/T/r/R syntax).
  for (const CanFrame& f :
       {frame(0x000, false, false, {}), frame(0x7FF, false, false, {1, 2, 3, 4, 5, 6, 7, 8}),
        frame(0x1FFFFFFF, true, false, {0xFF}), frame(0x123, false, true, {}, 4),
        frame(0x0, true, true, {}, 0)}) {
    std::string line = encode_frame(f);
    ASSERT_EQ(line.back(), '\r');
    line.pop_back();
    const Parsed p = parse_line(line);
    ASSERT_TRUE(p.command) << line << ": " << p.error;
    EXPECT_EQ(p.command->frame, f) << line;
  }
}

TEST(SlcanSession, PythonCanInitSequenceSendsAndShutdown) {
  // The bytes python-can 4.1 writes (tools-and-formats.md §2.2): C S6 O O V N, two sends, C.
  SlcanSession s("PBV1");
  std::string reply;
  std::vector<CanFrame> bus;
  s.feed("C\rS6\rO\rO\rV\rN\rt2052AABB\rT18FF00013010203\rC\r", reply, bus);
  EXPECT_EQ(reply, "\r\r\r\rV1013\rNPBV1\rz\rZ\r\r");
  ASSERT_EQ(bus.size(), 2u);
  EXPECT_EQ(bus[0], frame(0x205, false, false, {0xAA, 0xBB}));
  EXPECT_EQ(bus[1], frame(0x18FF0001, true, false, {1, 2, 3}));
  EXPECT_FALSE(s.is_open());
  EXPECT_EQ(s.stats().lines, 9u);
  EXPECT_EQ(s.stats().errors, 0u);
  EXPECT_EQ(s.stats().frames_in, 2u);
}

TEST(SlcanSession, ChannelStateGatesFrames) {
  SlcanSession s;
  std::string reply;
  std::vector<CanFrame> bus;
  const CanFrame f = frame(0x181, false, false, {0x42});
  EXPECT_FALSE(s.frame_to_host(f, 0));  // closed: nothing goes to the host
  s.feed("t1811FF\r", reply, bus);      // closed: sending refused
  EXPECT_EQ(reply, "\a");
  s.feed("L\r", reply, bus);
  EXPECT_EQ(s.frame_to_host(f, 0), "t181142\r");
  s.feed("t1811FF\r", reply, bus);  // listen-only: refused
  s.feed("S6\r", reply, bus);       // bit rate while open: refused
  s.feed("O\rZ1\r", reply, bus);
  // 2.5 s = 2500 ms = 0x09C4.
  EXPECT_EQ(s.frame_to_host(f, 2500 * bus::kTicksPerMs), "t18114209C4\r");
  s.feed("C\r", reply, bus);
  EXPECT_FALSE(s.frame_to_host(f, 0));
  EXPECT_EQ(reply, "\a\r\a\a\r\r\r");
  EXPECT_TRUE(bus.empty());
  EXPECT_EQ(s.stats().errors, 3u);
}

TEST(SlcanSession, OverlongLineIsDiscardedToItsCrAnsweredOnceAndCounted) {
  SlcanSession s;
  std::string reply;
  std::vector<CanFrame> bus;
  // 32 characters is still a line (an invalid one); 33 is overlong. Fed in pieces.
  const std::string l32(32, 'x');
  const std::string l100 = "t205" + std::string(96, 'A');
  s.feed(l32 + "\r", reply, bus);
  s.feed(l100.substr(0, 40), reply, bus);
  s.feed(l100.substr(40) + "\rO\r\n", reply, bus);
  EXPECT_EQ(reply, "\a\a\r");  // the 32-char line, the overlong one, then O still works
  EXPECT_EQ(s.stats().lines, 3u);
  EXPECT_EQ(s.stats().errors, 2u);
  EXPECT_EQ(s.stats().overlong, 1u);
  EXPECT_TRUE(s.is_open());
}

TEST(SlcanSession, FlagsShowAnOverrunOnceAndAreClearedByReading) {
  SlcanSession s;
  std::string reply;
  std::vector<CanFrame> bus;
  s.note_overrun();
  s.feed("F\rF\r", reply, bus);
  EXPECT_EQ(reply, "F08\rF00\r");
}

TEST(SlcanSession, GarbageBytesNeverThrow) {
  SlcanSession s;
  std::string reply;
  std::vector<CanFrame> bus;
  std::string junk;
  for (int i = 0; i < 2000; ++i) junk += static_cast<char>((i * 37) & 0xFF);
  s.feed(junk, reply, bus);
  s.feed("\r", reply, bus);
  EXPECT_GT(s.stats().errors, 0u);
}

}  // namespace
}  // namespace pbvbus::gateways::slcan
