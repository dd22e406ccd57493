// MBAP header and RTU framer (modbus_frame.hpp). Runs under ASan+UBSan (sanitize_gateways).
//
// Golden RTU frames: the CRC bytes below were worked out with the bitwise procedure of Modbus
// over Serial Line V1.02 §6.2.2 (reference_crc() in this file is that procedure, written
// independently of the table-driven code under test, and is itself pinned to the spec's worked
// example 02 07 -> CRC 0x1241 in ReferenceCrcFollowsTheSpecExample):
//   01 03 00 00 00 0A -> C5 CD   (the classic read of 10 registers)
//   01 03 00 00 00 02 -> C4 0B
//   01 06 00 05 04 D2 -> 1B 56
//   01 10 00 00 00 02 04 00 07 00 08 -> 43 A8
//   00 06 00 01 00 07 -> 98 19   (broadcast)

#include <gtest/gtest.h>

#include <random>
#include <string>
#include <vector>

#include "hex.hpp"

#include "pbvbus/gateways/modbus_frame.hpp"

namespace pbvbus::gateways {
namespace {

using pbvbus::test::bytes_from_hex;
using pbvbus::test::to_hex;

// §6.2.2: CRC = FFFF; for each octet: CRC ^= octet; 8 times: shift right, if the bit shifted
// out was 1, CRC ^= A001. The result's low byte is sent first.
std::uint16_t reference_crc(const std::vector<std::uint8_t>& b) {
  unsigned crc = 0xFFFF;
  for (auto o : b) {
    crc ^= o;
    for (int i = 0; i < 8; ++i) {
      const bool lsb = crc & 1u;
      crc >>= 1;
      if (lsb) crc ^= 0xA001u;
    }
  }
  return static_cast<std::uint16_t>(crc);
}

TEST(ModbusCrc, ReferenceCrcFollowsTheSpecExample) {
  // Spec example (Appendix "CRC generation"), message 02 07:
  //   FFFF ^ 02 = FFFD; shifts: DFFF CFFE 67FF 93FE 49FF 84FE 427F 813E
  //   813E ^ 07 = 8139; shifts: E09D D04F C826 6413 9208 4904 2482 1241
  // CRC 0x1241, on the wire 41 12.
  EXPECT_EQ(reference_crc({0x02, 0x07}), 0x1241);
  EXPECT_EQ(crc16_modbus(bytes_from_hex("02 07")), 0x1241);
}

TEST(ModbusCrc, GoldenFrames) {
  EXPECT_EQ(crc16_modbus(bytes_from_hex("01 03 00 00 00 0A")), 0xCDC5);
  EXPECT_EQ(crc16_modbus(bytes_from_hex("01 03 00 00 00 02")), 0x0BC4);
  EXPECT_EQ(crc16_modbus(bytes_from_hex("01 06 00 05 04 D2")), 0x561B);
  EXPECT_EQ(crc16_modbus(bytes_from_hex("01 10 00 00 00 02 04 00 07 00 08")), 0xA843);
  EXPECT_EQ(crc16_modbus(bytes_from_hex("00 06 00 01 00 07")), 0x1998);
  EXPECT_EQ(crc16_modbus({}), 0xFFFF);  // nothing processed: the initial value
}

TEST(ModbusCrc, TableMatchesTheBitwiseProcedureOnRandomData) {
  std::mt19937 rng(9);
  for (int n = 0; n < 200; ++n) {
    std::vector<std::uint8_t> b(static_cast<std::size_t>(n));
    for (auto& o : b) o = static_cast<std::uint8_t>(rng());
    EXPECT_EQ(crc16_modbus(b), reference_crc(b)) << to_hex(b);
  }
}

TEST(ModbusRtu, EncodeAppendsCrcLowByteFirst) {
  std::array<std::uint8_t, kModbusRtuMaxAdu> out{};
  const auto pdu = bytes_from_hex("03 00 00 00 0A");
  const std::size_t n = encode_rtu_adu(1, pdu, out);
  EXPECT_EQ(to_hex(std::span(out).first(n)), "01 03 00 00 00 0A C5 CD");
  EXPECT_EQ(encode_rtu_adu(1, {}, out), 0u);
  std::vector<std::uint8_t> big(kModbusMaxPdu + 1, 3);
  EXPECT_EQ(encode_rtu_adu(1, big, out), 0u);
  std::array<std::uint8_t, 7> small{};
  EXPECT_EQ(encode_rtu_adu(1, pdu, small), 0u);  // needs 8
}

TEST(ModbusMbap, DecodesTheGoldenHeader) {
  const auto d = decode_mbap(bytes_from_hex("00 01 00 00 00 06 01 03 00 00 00 02"));
  ASSERT_TRUE(d.ok());
  EXPECT_EQ(d.header, (MbapHeader{1, 0, 6, 1}));
  EXPECT_EQ(d.pdu_len(), 5u);   // LEN 6 = unit + 5 octets of PDU
  EXPECT_EQ(d.adu_len(), 12u);  // 6 octets before UNIT + LEN
}

TEST(ModbusMbap, RejectsWhatIsNotModbus) {
  EXPECT_EQ(decode_mbap(bytes_from_hex("00 01 00 00 00 06")).error, MbapError::Short);
  EXPECT_EQ(decode_mbap(bytes_from_hex("00 01 00 01 00 06 01")).error, MbapError::ProtocolId);
  EXPECT_EQ(decode_mbap(bytes_from_hex("00 01 00 00 00 01 01")).error, MbapError::LengthTooSmall);
  EXPECT_EQ(decode_mbap(bytes_from_hex("00 01 00 00 00 00 01")).error, MbapError::LengthTooSmall);
  EXPECT_EQ(decode_mbap(bytes_from_hex("00 01 00 00 00 FF 01")).error, MbapError::LengthTooLarge);
  EXPECT_EQ(decode_mbap(bytes_from_hex("00 01 00 00 01 00 01")).error, MbapError::LengthTooLarge);
  // The limits themselves are fine: LEN 2 (FC only) and 254 (a 253-octet PDU).
  EXPECT_TRUE(decode_mbap(bytes_from_hex("00 01 00 00 00 02 01")).ok());
  EXPECT_TRUE(decode_mbap(bytes_from_hex("00 01 00 00 00 FE 01")).ok());
  EXPECT_EQ(to_string(MbapError::ProtocolId), "protocol id not 0");
}

TEST(ModbusMbap, EncodeRoundTrips) {
  std::array<std::uint8_t, kModbusTcpMaxAdu> out{};
  const auto pdu = bytes_from_hex("03 04 00 07 00 08");
  const std::size_t n = encode_tcp_adu(0xBEEF, 1, pdu, out);
  // LEN = unit + 6 octets of PDU = 7.
  EXPECT_EQ(to_hex(std::span(out).first(n)), "BE EF 00 00 00 07 01 03 04 00 07 00 08");
  const auto d = decode_mbap(std::span(out).first(n));
  ASSERT_TRUE(d.ok());
  EXPECT_EQ(d.header, (MbapHeader{0xBEEF, 0, 7, 1}));
  for (unsigned tid : {0u, 1u, 0x1234u, 0xFFFFu})
    for (unsigned len = 1; len <= kModbusMaxPdu; len += 23) {
      std::vector<std::uint8_t> p(len, 0x42);
      const std::size_t m = encode_tcp_adu(static_cast<std::uint16_t>(tid), 7, p, out);
      ASSERT_EQ(m, 7 + len);
      const auto e = decode_mbap(std::span(out).first(m));
      ASSERT_TRUE(e.ok());
      EXPECT_EQ(e.header.transaction_id, tid);
      EXPECT_EQ(e.pdu_len(), len);
    }
  EXPECT_EQ(encode_tcp_adu(1, 1, {}, out), 0u);
}

TEST(ModbusRtu, RequestLengthByFunctionCode) {
  EXPECT_EQ(rtu_request_length(bytes_from_hex("01")), 0u);  // FC not here yet
  for (int fc : {1, 2, 3, 4, 5, 6, 8})
    EXPECT_EQ(rtu_request_length(std::vector<std::uint8_t>{1, static_cast<std::uint8_t>(fc)}), 8u);
  EXPECT_EQ(rtu_request_length(bytes_from_hex("01 07")), 4u);
  EXPECT_EQ(rtu_request_length(bytes_from_hex("01 2B")), 7u);
  EXPECT_EQ(rtu_request_length(bytes_from_hex("01 10 00 00 00")), 0u);  // byte count missing
  // FC16 with byte count 4: 7 + 4 + 2 = 13.
  EXPECT_EQ(rtu_request_length(bytes_from_hex("01 10 00 00 00 02 04")), 13u);
  EXPECT_EQ(rtu_request_length(bytes_from_hex("01 0F 00 00 00 0A 02")), 11u);
  // FC23: write byte count at octet 10 (6): 11 + 6 + 2 = 19.
  EXPECT_EQ(rtu_request_length(bytes_from_hex("01 17 00 00 00 01 00 00 00 03 06")), 19u);
  EXPECT_EQ(rtu_request_length(bytes_from_hex("01 17 00 00 00 01 00 00 00 03")), 0u);
  EXPECT_FALSE(rtu_request_length(bytes_from_hex("01 41")).has_value());
}

struct Collected {
  std::vector<std::string> frames;
  RtuFramer::Sink sink() {
    return [this](const RtuFrame& f) {
      frames.push_back(std::to_string(f.unit) + ":" + to_hex(f.pdu) + "|" + to_hex(f.adu));
    };
  }
};

TEST(RtuFramer, WholeFrameAndOctetByOctetGiveTheSameFrame) {
  const auto adu = bytes_from_hex("01 03 00 00 00 0A C5 CD");
  Collected a, b;
  RtuFramer fa, fb;
  fa.feed(adu, a.sink());
  for (auto o : adu) fb.feed(std::span(&o, 1), b.sink());
  const std::vector<std::string> want{"1:03 00 00 00 0A|01 03 00 00 00 0A C5 CD"};
  EXPECT_EQ(a.frames, want);
  EXPECT_EQ(b.frames, want);
  EXPECT_EQ(fa.pending(), 0u);
  EXPECT_EQ(fb.stats().frames, 1u);
}

TEST(RtuFramer, BackToBackFramesOfDifferentLengths) {
  Collected c;
  RtuFramer f;
  f.feed(bytes_from_hex("01 03 00 00 00 02 C4 0B"
                        "01 10 00 00 00 02 04 00 07 00 08 43 A8"
                        "01 06 00 05 04 D2 1B 56"),
         c.sink());
  ASSERT_EQ(c.frames.size(), 3u);
  EXPECT_EQ(c.frames[1], "1:10 00 00 00 02 04 00 07 00 08|01 10 00 00 00 02 04 00 07 00 08 43 A8");
  EXPECT_EQ(c.frames[2], "1:06 00 05 04 D2|01 06 00 05 04 D2 1B 56");
}

TEST(RtuFramer, BadCrcIsDroppedAndTheNextFrameFound) {
  Collected c;
  RtuFramer f;
  // CD -> CE: the first candidate fails its CRC. Resync drops one octet at a time: from "03"
  // on the FC is 00 (unknown), so the rest waits; the next good frame's bytes complete...
  f.feed(bytes_from_hex("01 03 00 00 00 0A C5 CE"), c.sink());
  EXPECT_TRUE(c.frames.empty());
  EXPECT_EQ(f.stats().bad_crc, 1u);
  // ... and silence ends the leftovers (03 00 00 00 0A C5 CE: unknown FC 00, bad CRC).
  f.silence(c.sink());
  EXPECT_EQ(f.pending(), 0u);
  EXPECT_EQ(f.stats().incomplete, 1u);
  f.feed(bytes_from_hex("01 03 00 00 00 02 C4 0B"), c.sink());
  EXPECT_EQ(c.frames, std::vector<std::string>{"1:03 00 00 00 02|01 03 00 00 00 02 C4 0B"});
}

TEST(RtuFramer, GarbageBeforeAFrameIsSkippedWithoutSilence) {
  Collected c;
  RtuFramer f;
  // FF 01: unit FF, FC 01 -> an 8-octet candidate "FF 01 03 00 00 00 0A C5" with a bad CRC;
  // dropping FF leaves the good frame at the head.
  f.feed(bytes_from_hex("FF 01 03 00 00 00 0A C5 CD"), c.sink());
  EXPECT_EQ(c.frames, std::vector<std::string>{"1:03 00 00 00 0A|01 03 00 00 00 0A C5 CD"});
  EXPECT_EQ(f.stats().bad_crc, 1u);
  EXPECT_EQ(f.stats().dropped_octets, 1u);
}

TEST(RtuFramer, UnknownFunctionCodeEndsAtSilence) {
  Collected c;
  RtuFramer f;
  // FC 0x41 has no length rule. CRC of "01 41" by the §6.2.2 procedure (reference_crc):
  const auto body = bytes_from_hex("01 41");
  const std::uint16_t crc = reference_crc(body);
  std::vector<std::uint8_t> adu = body;
  adu.push_back(static_cast<std::uint8_t>(crc & 0xFF));
  adu.push_back(static_cast<std::uint8_t>(crc >> 8));
  f.feed(adu, c.sink());
  EXPECT_TRUE(c.frames.empty());
  EXPECT_EQ(f.pending(), 4u);
  f.silence(c.sink());
  ASSERT_EQ(c.frames.size(), 1u);
  EXPECT_EQ(c.frames[0].substr(0, 5), "1:41|");
  EXPECT_EQ(f.stats().incomplete, 0u);
}

TEST(RtuFramer, SilenceDropsAPartialFrame) {
  Collected c;
  RtuFramer f;
  f.feed(bytes_from_hex("01 03 00 00"), c.sink());
  f.silence(c.sink());
  EXPECT_EQ(f.pending(), 0u);
  EXPECT_EQ(f.stats().incomplete, 1u);
  EXPECT_EQ(f.stats().dropped_octets, 4u);
  f.feed(bytes_from_hex("00 0A C5 CD"), c.sink());  // the rest alone is no frame
  f.silence(c.sink());
  EXPECT_TRUE(c.frames.empty());
}

TEST(RtuFramer, OverlongByteCountResyncs) {
  Collected c;
  RtuFramer f;
  // FC16 with byte count FF: 7 + 255 + 2 = 264 > 256, cannot be a frame -> overlong, drop 01.
  f.feed(bytes_from_hex("01 10 00 00 00 7F FF"), c.sink());
  EXPECT_EQ(f.stats().overlong, 1u);
  f.silence(c.sink());
  f.feed(bytes_from_hex("01 03 00 00 00 0A C5 CD"), c.sink());
  EXPECT_EQ(c.frames.size(), 1u);
}

TEST(RtuFramer, AnUnknownFcStreamNeverGrowsBeyondOneFrame) {
  RtuFramer f;
  Collected c;
  std::vector<std::uint8_t> junk(5000, 0x41);
  f.feed(junk, c.sink());
  EXPECT_LE(f.pending(), kModbusRtuMaxAdu);
  EXPECT_GT(f.stats().overlong, 0u);
  f.silence(c.sink());
  EXPECT_EQ(f.pending(), 0u);
  EXPECT_TRUE(c.frames.empty());
}

TEST(RtuFramer, RandomStreamsNeverDeliverABadCrcAndAlwaysFindTrailingGoodFrames) {
  std::mt19937 rng(42);
  const auto good = bytes_from_hex("01 03 00 00 00 02 C4 0B");
  for (int round = 0; round < 300; ++round) {
    RtuFramer f;
    std::vector<std::uint8_t> s(rng() % 600);
    for (auto& o : s) o = static_cast<std::uint8_t>(rng());
    int delivered = 0;
    bool all_good = true;
    RtuFramer::Sink sink = [&](const RtuFrame& fr) {
      ++delivered;
      const std::vector<std::uint8_t> a(fr.adu.begin(), fr.adu.end() - 2);
      const std::uint16_t crc = reference_crc(a);
      all_good &= fr.adu[fr.adu.size() - 2] == (crc & 0xFF) && fr.adu.back() == (crc >> 8);
      all_good &= fr.pdu.size() + 3 == fr.adu.size() && fr.unit == fr.adu[0];
    };
    // Arbitrary chunking.
    for (std::size_t i = 0; i < s.size();) {
      const std::size_t n = std::min<std::size_t>(s.size() - i, 1 + rng() % 40);
      f.feed(std::span(s).subspan(i, n), sink);
      i += n;
    }
    f.silence(sink);
    EXPECT_TRUE(all_good);
    EXPECT_EQ(f.pending(), 0u);
    const int before = delivered;
    f.feed(good, sink);
    EXPECT_EQ(delivered, before + 1) << "round " << round;
  }
}

}  // namespace
}  // namespace pbvbus::gateways
