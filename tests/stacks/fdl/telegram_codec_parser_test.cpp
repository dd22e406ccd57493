// FDL telegram codec: round trips over every frame type and FC octet, SAP extension chains,
// data-length edges, every DecodeError, the single-bit-flip property and frame_length()
// (protocol-facts.md §B). Expected bytes are written by hand; where a sweep needs many frames
// the test builds them with its own octet sum (sum8), never with the codec's fcs().
#include <gtest/gtest.h>

#include <deque>
#include <set>
#include <string>
#include <vector>

#include "hex.hpp"
#include "pbvbus/fdl/telegram.hpp"
#include "telegram_golden.hpp"

// FrameSpecs below are written with designated initializers that leave the optional SAP,
// segment and data members at their defaults on purpose; g++ -Wextra would flag each one.
#pragma GCC diagnostic ignored "-Wmissing-field-initializers"

namespace pbvbus::fdl {
namespace {

using test::bytes_from_hex;
using test::to_hex;
using Bytes = std::vector<std::uint8_t>;

std::uint8_t sum8(const Bytes& b) {
  unsigned s = 0;
  for (auto x : b) s += x;
  return static_cast<std::uint8_t>(s & 0xFF);
}
Bytes sd1(std::uint8_t da, std::uint8_t sa, std::uint8_t fc) {
  const Bytes body{da, sa, fc};
  return {0x10, da, sa, fc, sum8(body), 0x16};
}
Bytes sd2(const Bytes& body) {
  Bytes f{0x68, static_cast<std::uint8_t>(body.size()), static_cast<std::uint8_t>(body.size()),
          0x68};
  f.insert(f.end(), body.begin(), body.end());
  f.push_back(sum8(body));
  f.push_back(0x16);
  return f;
}

DecodeError dec(const Bytes& b) {
  Telegram t;
  return decode(b, t);
}
DecodeError dec(const char* hex) { return dec(bytes_from_hex(hex)); }

// The returned telegram's data points into `b`, so `b` must outlive it.
Telegram dec_ok(const Bytes& b) {
  Telegram t;
  const DecodeError e = decode(b, t);
  EXPECT_EQ(e, DecodeError::None) << to_string(e) << " for " << to_hex(b);
  return t;
}
// For a temporary frame: keeps it alive until the program ends (a few hundred octets in all).
Telegram dec_ok(Bytes&& b) {
  static std::deque<Bytes> kept;  // deque: push_back leaves earlier elements in place
  kept.push_back(std::move(b));
  return dec_ok(kept.back());
}

// --- function codes ---------------------------------------------------------------------------

TEST(TelegramFc, EveryRequestFunctionWithEveryFcbFcv) {
  const std::set<unsigned> reserved{0x1, 0x2, 0x8, 0xA, 0xB};
  for (unsigned fn = 0; fn < 16; ++fn)
    for (unsigned fcb = 0; fcb < 2; ++fcb)
      for (unsigned fcv = 0; fcv < 2; ++fcv) {
        const auto fc = static_cast<std::uint8_t>(0x40 | fcb << 5 | fcv << 4 | fn);
        SCOPED_TRACE(fc);
        FrameSpec s{.da = 5, .sa = 2, .fc = fc};
        Frame f;
        if (reserved.count(fn)) {
          EXPECT_FALSE(request_fn_valid(fc));
          EXPECT_EQ(encode(s, f), EncodeError::BadFunction);
          EXPECT_TRUE(f.empty());
          EXPECT_EQ(dec(sd1(5, 2, fc)), DecodeError::ReservedFunction);
          continue;
        }
        EXPECT_TRUE(request_fn_valid(fc));
        ASSERT_EQ(encode(s, f), EncodeError::None);
        EXPECT_EQ(to_hex(f.bytes()), to_hex(sd1(5, 2, fc)));
        const Telegram t = dec_ok(Bytes(f.bytes().begin(), f.bytes().end()));
        EXPECT_EQ(t.type, FrameType::SD1);
        EXPECT_EQ(t.fc, fc);
        EXPECT_TRUE(t.is_request());
        EXPECT_EQ(static_cast<unsigned>(fc_request_fn(t.fc)), fn);
        EXPECT_EQ(fc_fcb(t.fc), fcb == 1);
        EXPECT_EQ(fc_fcv(t.fc), fcv == 1);
        EXPECT_EQ(make_request_fc(fc_request_fn(fc), fcv == 1, fcb == 1), fc);
        EXPECT_NE(to_string(fc_request_fn(fc)), "reserved");
      }
}

TEST(TelegramFc, ClockValueIsTheOnlyRequestWithBit7) {
  // FC 0xC0: time event with bit 7 = clock value (§B.3), an unacknowledged broadcast.
  const Bytes cv = bytes_from_hex("68 06 06 68 7F 02 C0 01 02 03 47 16");
  const Telegram t = dec_ok(cv);
  EXPECT_EQ(t.fc, kFcClockValue);
  EXPECT_EQ(t.da, kBroadcast);
  EXPECT_EQ(to_hex(t.data), "01 02 03");
  const std::uint8_t data[] = {1, 2, 3};
  Frame f;
  ASSERT_EQ(encode({.da = 127, .sa = 2, .fc = 0xC0, .data = data}, f), EncodeError::None);
  EXPECT_EQ(to_hex(f.bytes()), to_hex(cv));
  // Bit 7 with FCB/FCV or with any other function is reserved.
  EXPECT_EQ(dec("10 7F 02 D0 51 16"), DecodeError::ReservedFunction);
  EXPECT_EQ(dec("10 05 02 C3 CA 16"), DecodeError::ReservedFunction);
  for (unsigned low = 1; low < 0x40; ++low) {
    const auto fc = static_cast<std::uint8_t>(0xC0 | low);
    EXPECT_EQ(dec(sd1(5, 2, fc)), DecodeError::ReservedFunction) << int(fc);
    Frame g;
    EXPECT_EQ(encode({.da = 5, .sa = 2, .fc = fc}, g), EncodeError::BadFunction);
  }
}

TEST(TelegramFc, EveryResponseStationTypeWithEveryStatus) {
  const std::set<unsigned> valid{0x0, 0x1, 0x2, 0x3, 0x8, 0x9, 0xA, 0xC, 0xD};
  for (unsigned st = 0; st < 4; ++st)
    for (unsigned status = 0; status < 16; ++status) {
      const auto fc = static_cast<std::uint8_t>(st << 4 | status);
      SCOPED_TRACE(fc);
      Frame f;
      const FrameSpec s{.da = 1, .sa = 3, .fc = fc};
      if (!valid.count(status)) {
        EXPECT_FALSE(response_status_valid(fc));
        EXPECT_EQ(dec(sd1(1, 3, fc)), DecodeError::ReservedStatus);
        EXPECT_EQ(encode(s, f), EncodeError::BadFunction);
        continue;
      }
      ASSERT_EQ(encode(s, f), EncodeError::None);
      EXPECT_EQ(to_hex(f.bytes()), to_hex(sd1(1, 3, fc)));
      const Telegram t = dec_ok(sd1(1, 3, fc));
      EXPECT_FALSE(t.is_request());
      EXPECT_EQ(static_cast<unsigned>(fc_station_type(t.fc)), st);
      EXPECT_EQ(static_cast<unsigned>(fc_status(t.fc)), status);
      EXPECT_EQ(make_response_fc(fc_station_type(fc), fc_status(fc)), fc);
      EXPECT_NE(to_string(fc_status(fc)), "reserved");
      // Bit 7 is reserved in a response.
      EXPECT_EQ(dec(sd1(1, 3, static_cast<std::uint8_t>(fc | 0x80))), DecodeError::ReservedStatus);
    }
  EXPECT_EQ(dec("10 02 05 04 0B 16"), DecodeError::ReservedStatus);
  EXPECT_EQ(dec("10 02 05 88 8F 16"), DecodeError::ReservedStatus);
}

TEST(TelegramFc, RoundTripEveryFrameType) {
  const std::uint8_t d8[] = {1, 2, 3, 4, 5, 6, 7, 8};
  const std::uint8_t d2[] = {0xAA, 0x55};
  struct Case {
    FrameType type;
    FrameSpec spec;
    const char* hex;
  } cases[] = {
      {FrameType::SD1, {.da = 3, .sa = 1, .fc = 0x49}, "10 03 01 49 4D 16"},
      {FrameType::SD2, {.da = 10, .sa = 1, .fc = 0x5D, .data = d2}, "68 05 05 68 0A 01 5D AA 55 67 16"},
      {FrameType::SD3, {.da = 10, .sa = 1, .fc = 0x7D, .data = d8},
       "A2 0A 01 7D 01 02 03 04 05 06 07 08 AC 16"},
      // The same 8 octets in an SD2 (what encode() would not choose, but a receiver accepts).
      {FrameType::SD2, {.da = 10, .sa = 1, .fc = 0x7D, .data = d8},
       "68 0B 0B 68 0A 01 7D 01 02 03 04 05 06 07 08 AC 16"},
  };
  for (const Case& c : cases) {
    Frame f;
    ASSERT_EQ(encode_as(c.type, c.spec, f), EncodeError::None);
    EXPECT_EQ(to_hex(f.bytes()), c.hex);
    const Telegram t = dec_ok(bytes_from_hex(c.hex));
    EXPECT_EQ(t.type, c.type);
    Frame again;
    ASSERT_EQ(reencode(t, again), EncodeError::None);
    EXPECT_EQ(to_hex(again.bytes()), c.hex);
  }
  // Token and short acknowledgement.
  EXPECT_EQ(to_hex(encode_token(5, 2).bytes()), "DC 05 02");
  EXPECT_EQ(to_hex(encode_sc().bytes()), "E5");
  Telegram tok = dec_ok(bytes_from_hex("DC 05 02"));
  EXPECT_EQ(tok.type, FrameType::SD4);
  EXPECT_FALSE(tok.is_request());
  Frame f;
  ASSERT_EQ(reencode(tok, f), EncodeError::None);
  EXPECT_EQ(to_hex(f.bytes()), "DC 05 02");
  const Telegram sc = dec_ok(bytes_from_hex("E5"));
  EXPECT_EQ(sc.type, FrameType::SC);
  ASSERT_EQ(reencode(sc, f), EncodeError::None);
  EXPECT_EQ(to_hex(f.bytes()), "E5");
  EXPECT_EQ(encode_as(FrameType::SD4, cases[0].spec, f), EncodeError::WrongFrameType);
  EXPECT_EQ(encode_as(FrameType::SC, cases[0].spec, f), EncodeError::WrongFrameType);
}

TEST(TelegramFc, EveryValidFcInEveryFrameTypeWithAnFc) {
  // Each valid request and response FC octet through SD1, SD2 (1 and 8 data octets) and SD3:
  // encode_as() gives the hand-built frame, decode() returns the same FC and data.
  const Bytes d8{1, 2, 3, 4, 5, 6, 7, 8};
  std::size_t checked = 0;
  for (unsigned v = 0; v < 256; ++v) {
    const auto fc = static_cast<std::uint8_t>(v);
    const bool valid = fc_is_request(fc) ? (request_fn_valid(fc) && (!(fc & 0x80) || fc == 0xC0))
                                         : (!(fc & 0x80) && response_status_valid(fc));
    for (const std::size_t n : {std::size_t{0}, std::size_t{1}, std::size_t{8}}) {
      for (const FrameType type : {FrameType::SD1, FrameType::SD2, FrameType::SD3}) {
        if ((type == FrameType::SD1) != (n == 0) || (type == FrameType::SD3 && n != 8)) continue;
        Bytes want;
        Bytes body{10, 1, fc};
        body.insert(body.end(), d8.begin(), d8.begin() + static_cast<std::ptrdiff_t>(n));
        if (type == FrameType::SD2) {
          want = sd2(body);
        } else {
          want = {type == FrameType::SD1 ? std::uint8_t{0x10} : std::uint8_t{0xA2}};
          want.insert(want.end(), body.begin(), body.end());
          want.push_back(sum8(body));
          want.push_back(0x16);
        }
        Frame f;
        const FrameSpec s{.da = 10, .sa = 1, .fc = fc, .data = std::span(d8).first(n)};
        if (!valid) {
          EXPECT_EQ(encode_as(type, s, f), EncodeError::BadFunction) << int(fc);
          EXPECT_NE(dec(want), DecodeError::None) << to_hex(want);
          continue;
        }
        ASSERT_EQ(encode_as(type, s, f), EncodeError::None) << int(fc);
        EXPECT_EQ(to_hex(f.bytes()), to_hex(want));
        Telegram t;
        ASSERT_EQ(decode(want, t), DecodeError::None) << to_hex(want);
        EXPECT_EQ(t.type, type);
        EXPECT_EQ(t.fc, fc);
        EXPECT_EQ(t.data.size(), n);
        ++checked;
      }
    }
  }
  // 11 request functions x 4 FCB/FCV + clock value, 4 station types x 9 statuses; 4 shapes each
  // (SD1; SD2 with 1 octet; SD2 and SD3 with 8 octets).
  EXPECT_EQ(checked, (11u * 4 + 1 + 4 * 9) * 4);
}

// --- addresses and broadcast ------------------------------------------------------------------

TEST(TelegramAddress, BroadcastOnlyWithSdnOrTimeEvent) {
  EXPECT_EQ(dec_ok(bytes_from_hex("68 04 04 68 7F 02 44 AA 6F 16")).da, 127);  // SDN low
  EXPECT_EQ(dec_ok(bytes_from_hex("68 04 04 68 7F 02 40 AA 6B 16")).da, 127);  // time event
  EXPECT_EQ(dec("10 7F 02 4C CD 16"), DecodeError::BroadcastNotSdn);            // SRD low
  EXPECT_EQ(dec("10 7F 02 08 89 16"), DecodeError::BroadcastNotSdn);            // a response
  for (auto fn : {RequestFn::SdaLow, RequestFn::SdaHigh, RequestFn::Msrd, RequestFn::FdlStatus,
                  RequestFn::SrdLow, RequestFn::SrdHigh, RequestFn::Ident, RequestFn::LsapStatus}) {
    Frame f;
    EXPECT_EQ(encode({.da = 127, .sa = 2, .fc = make_request_fc(fn)}, f), EncodeError::BadAddress);
    EXPECT_EQ(dec(sd1(127, 2, make_request_fc(fn))), DecodeError::BroadcastNotSdn);
  }
  Frame f;
  EXPECT_EQ(encode({.da = 127, .sa = 2, .fc = 0x08}, f), EncodeError::BadAddress);
  EXPECT_EQ(encode({.da = 127, .sa = 2, .fc = 0x46}, f), EncodeError::None);
  EXPECT_EQ(encode({.da = 127, .sa = 2, .fc = 0x44}, f), EncodeError::None);
}

TEST(TelegramAddress, SourceAddressAndRanges) {
  EXPECT_EQ(dec("10 05 7F 49 CD 16"), DecodeError::BadSourceAddress);
  Frame f;
  EXPECT_EQ(encode({.da = 5, .sa = 127, .fc = 0x49}, f), EncodeError::BadAddress);
  EXPECT_EQ(encode({.da = 128, .sa = 1, .fc = 0x49}, f), EncodeError::BadAddress);
  EXPECT_EQ(encode({.da = 126, .sa = 126, .fc = 0x49}, f), EncodeError::None);
  EXPECT_EQ(to_hex(f.bytes()), "10 7E 7E 49 45 16");
}

TEST(TelegramAddress, TokenRules) {
  EXPECT_EQ(dec("DC 7F 02"), DecodeError::BroadcastNotSdn);
  EXPECT_EQ(dec("DC 05 7F"), DecodeError::BadSourceAddress);
  EXPECT_EQ(dec("DC 85 02"), DecodeError::BadExtension);
  EXPECT_EQ(dec("DC 05 82"), DecodeError::BadExtension);
  const Telegram t = dec_ok(bytes_from_hex("DC 00 7E"));
  EXPECT_EQ(t.da, 0);
  EXPECT_EQ(t.sa, 126);
}

// --- SAP extension ----------------------------------------------------------------------------

TEST(TelegramSap, DsapOnly) {
  const char* hex = "68 05 05 68 8A 01 5D 3C 01 25 16";
  const Telegram t = dec_ok(bytes_from_hex(hex));
  EXPECT_EQ(t.dsap, 60);
  EXPECT_FALSE(t.ssap);
  EXPECT_EQ(to_hex(t.data), "01");
  const std::uint8_t d[] = {1};
  Frame f;
  ASSERT_EQ(encode({.da = 10, .sa = 1, .fc = 0x5D, .dsap = 60, .data = d}, f), EncodeError::None);
  EXPECT_EQ(to_hex(f.bytes()), hex);
}

TEST(TelegramSap, SsapOnly) {
  const char* hex = "68 05 05 68 0A 81 5D 3E 01 27 16";
  const Telegram t = dec_ok(bytes_from_hex(hex));
  EXPECT_FALSE(t.dsap);
  EXPECT_EQ(t.ssap, 62);
  EXPECT_EQ(to_hex(t.data), "01");
  const std::uint8_t d[] = {1};
  Frame f;
  ASSERT_EQ(encode({.da = 10, .sa = 1, .fc = 0x5D, .ssap = 62, .data = d}, f), EncodeError::None);
  EXPECT_EQ(to_hex(f.bytes()), hex);
}

TEST(TelegramSap, SegmentOctets) {
  // DA segment 5: DAE = C5 (EXT, segment) then DSAP 3C; SAE = 3E.
  const char* da_seg = "68 06 06 68 8A 81 5D C5 3C 3E A7 16";
  Telegram t = dec_ok(bytes_from_hex(da_seg));
  EXPECT_EQ(t.da_segment, 5);
  EXPECT_EQ(t.dsap, 60);
  EXPECT_FALSE(t.sa_segment);
  EXPECT_EQ(t.ssap, 62);
  EXPECT_TRUE(t.data.empty());
  Frame f;
  ASSERT_EQ(encode({.da = 10, .sa = 1, .fc = 0x5D, .dsap = 60, .ssap = 62, .da_segment = 5}, f),
            EncodeError::None);
  EXPECT_EQ(to_hex(f.bytes()), da_seg);

  // SA segment 7 with one data octet.
  const char* sa_seg = "68 07 07 68 8A 81 5D 3C C7 3E 11 BA 16";
  t = dec_ok(bytes_from_hex(sa_seg));
  EXPECT_EQ(t.dsap, 60);
  EXPECT_FALSE(t.da_segment);
  EXPECT_EQ(t.sa_segment, 7);
  EXPECT_EQ(t.ssap, 62);
  EXPECT_EQ(to_hex(t.data), "11");
  const std::uint8_t d[] = {0x11};
  ASSERT_EQ(encode({.da = 10, .sa = 1, .fc = 0x5D, .dsap = 60, .ssap = 62, .sa_segment = 7,
                    .data = d},
                   f),
            EncodeError::None);
  EXPECT_EQ(to_hex(f.bytes()), sa_seg);

  // Both segments.
  const char* both = "68 07 07 68 8A 81 5D C5 3C C7 3E 6E 16";
  t = dec_ok(bytes_from_hex(both));
  EXPECT_EQ(t.da_segment, 5);
  EXPECT_EQ(t.sa_segment, 7);
  ASSERT_EQ(encode({.da = 10, .sa = 1, .fc = 0x5D, .dsap = 60, .ssap = 62, .da_segment = 5,
                    .sa_segment = 7},
                   f),
            EncodeError::None);
  EXPECT_EQ(to_hex(f.bytes()), both);
}

TEST(TelegramSap, SegmentAfterSapIsAcceptedAndReencodedSegmentFirst) {
  // Documented non-canonical form (telegram.hpp): SAP octet with EXT, then the segment octet.
  // Same octets' sum, so the same FCS.
  struct Case {
    const char* noncanonical;
    const char* canonical;
  } cases[] = {
      {"68 06 06 68 8A 81 5D BC 45 3E A7 16", "68 06 06 68 8A 81 5D C5 3C 3E A7 16"},
      {"68 07 07 68 8A 81 5D 3C BE 47 11 BA 16", "68 07 07 68 8A 81 5D 3C C7 3E 11 BA 16"},
  };
  for (const Case& c : cases) {
    const Telegram a = dec_ok(bytes_from_hex(c.noncanonical));
    const Telegram b = dec_ok(bytes_from_hex(c.canonical));
    EXPECT_EQ(a.dsap, b.dsap);
    EXPECT_EQ(a.ssap, b.ssap);
    EXPECT_EQ(a.da_segment, b.da_segment);
    EXPECT_EQ(a.sa_segment, b.sa_segment);
    EXPECT_EQ(to_hex(a.data), to_hex(b.data));
    Frame f;
    ASSERT_EQ(reencode(a, f), EncodeError::None);
    EXPECT_EQ(to_hex(f.bytes()), c.canonical);
  }
}

TEST(TelegramSap, BadChains) {
  EXPECT_EQ(dec("68 05 05 68 8A 01 5D 45 11 3E 16"), DecodeError::BadExtension);  // segment only
  EXPECT_EQ(dec("68 06 06 68 8A 01 5D BC 3D 11 F2 16"), DecodeError::BadExtension);  // two SAPs
  EXPECT_EQ(dec("68 06 06 68 8A 01 5D C5 46 11 04 16"), DecodeError::BadExtension);  // two segments
  EXPECT_EQ(dec("68 04 04 68 8A 01 5D BC A4 16"), DecodeError::BadExtension);  // EXT past the end
  EXPECT_EQ(dec("10 8A 01 5D E8 16"), DecodeError::BadExtension);  // SD1 has no room for a DAE
  EXPECT_EQ(dec("68 04 04 68 8A 81 5D 3C A4 16"), DecodeError::BadExtension);  // SAE missing
  // Encoder side: out-of-range values and a segment without its SAP.
  Frame f;
  EXPECT_EQ(encode({.da = 1, .sa = 2, .fc = 0x5D, .dsap = 64}, f), EncodeError::BadSap);
  EXPECT_EQ(encode({.da = 1, .sa = 2, .fc = 0x5D, .ssap = 64}, f), EncodeError::BadSap);
  EXPECT_EQ(encode({.da = 1, .sa = 2, .fc = 0x5D, .dsap = 1, .da_segment = 64}, f),
            EncodeError::BadSap);
  EXPECT_EQ(encode({.da = 1, .sa = 2, .fc = 0x5D, .da_segment = 1}, f), EncodeError::BadSap);
  EXPECT_EQ(encode({.da = 1, .sa = 2, .fc = 0x5D, .sa_segment = 1}, f), EncodeError::BadSap);
  EXPECT_TRUE(f.empty());
  EXPECT_EQ(encode({.da = 1, .sa = 2, .fc = 0x5D, .dsap = 63, .ssap = 0}, f), EncodeError::None);
}

// --- data length edges ------------------------------------------------------------------------

Bytes data_of(std::size_t n) {
  Bytes d(n);
  for (std::size_t i = 0; i < n; ++i) d[i] = static_cast<std::uint8_t>(i * 7 + 1);
  return d;
}

TEST(TelegramLength, TypeChosenByOctetsAfterFc) {
  const std::uint8_t d7[] = {1, 2, 3, 4, 5, 6, 7};
  const std::uint8_t d8[] = {1, 2, 3, 4, 5, 6, 7, 8};
  const std::uint8_t d9[] = {1, 2, 3, 4, 5, 6, 7, 8, 9};
  Frame f;
  ASSERT_EQ(encode({.da = 10, .sa = 1, .fc = 0x7D}, f), EncodeError::None);
  EXPECT_EQ(to_hex(f.bytes()), "10 0A 01 7D 88 16");
  ASSERT_EQ(encode({.da = 10, .sa = 1, .fc = 0x7D, .data = d7}, f), EncodeError::None);
  EXPECT_EQ(to_hex(f.bytes()), "68 0A 0A 68 0A 01 7D 01 02 03 04 05 06 07 A4 16");
  ASSERT_EQ(encode({.da = 10, .sa = 1, .fc = 0x7D, .data = d8}, f), EncodeError::None);
  EXPECT_EQ(to_hex(f.bytes()), "A2 0A 01 7D 01 02 03 04 05 06 07 08 AC 16");
  ASSERT_EQ(encode({.da = 10, .sa = 1, .fc = 0x7D, .data = d9}, f), EncodeError::None);
  EXPECT_EQ(to_hex(f.bytes()), "68 0C 0C 68 0A 01 7D 01 02 03 04 05 06 07 08 09 B5 16");
  // Extension octets count: DAE (segment + SAP) + SAE + 5 data = 8 -> SD3.
  ASSERT_EQ(encode({.da = 10, .sa = 1, .fc = 0x7D, .dsap = 60, .ssap = 62, .da_segment = 5,
                    .data = std::span(d8).first(5)},
                   f),
            EncodeError::None);
  EXPECT_EQ(to_hex(f.bytes()), "A2 8A 81 7D C5 3C 3E 01 02 03 04 05 D6 16");
  // SAPs only (DU = 2 octets) -> SD2 with LE 5.
  ASSERT_EQ(encode({.da = 10, .sa = 1, .fc = 0x6D, .dsap = 60, .ssap = 62}, f), EncodeError::None);
  EXPECT_EQ(to_hex(f.bytes()), "68 05 05 68 8A 81 6D 3C 3E F2 16");
}

TEST(TelegramLength, MaximumDuIs246IncludingExtensionOctets) {
  struct Case {
    bool saps, segments;
    std::size_t data;
  } cases[] = {{false, false, 246}, {true, false, 244}, {true, true, 242}};
  for (const Case& c : cases) {
    const Bytes d = data_of(c.data);
    FrameSpec s{.da = 10, .sa = 1, .fc = 0x7D, .data = d};
    if (c.saps) s.dsap = 61, s.ssap = 62;
    if (c.segments) s.da_segment = 1, s.sa_segment = 2;
    Frame f;
    ASSERT_EQ(encode(s, f), EncodeError::None) << c.data;
    ASSERT_EQ(f.len, 255);
    EXPECT_EQ(f.buf[0], 0x68);
    EXPECT_EQ(f.buf[1], 249);  // LE
    EXPECT_EQ(f.buf[2], 249);  // LEr
    EXPECT_EQ(f.buf[254], 0x16);
    Bytes body(f.buf.begin() + 4, f.buf.begin() + 253);
    EXPECT_EQ(f.buf[253], sum8(body));
    const Telegram t = dec_ok(Bytes(f.bytes().begin(), f.bytes().end()));
    EXPECT_EQ(t.data.size(), c.data);
    EXPECT_TRUE(std::equal(t.data.begin(), t.data.end(), d.begin()));
    // One more octet no longer fits.
    const Bytes d1 = data_of(c.data + 1);
    s.data = d1;
    EXPECT_EQ(encode(s, f), EncodeError::DataTooLong);
    EXPECT_TRUE(f.empty());
  }
}

TEST(TelegramLength, DecodeLimitsOfLe) {
  Bytes body{0x0A, 0x01, 0x7D};
  const Bytes d = data_of(246);
  body.insert(body.end(), d.begin(), d.end());
  EXPECT_EQ(dec(sd2(body)), DecodeError::None);  // LE 249
  body.push_back(0);
  EXPECT_EQ(dec(sd2(body)), DecodeError::LengthOutOfRange);  // LE 250
  EXPECT_EQ(dec(sd2({0x0A, 0x01, 0x7D})), DecodeError::LengthOutOfRange);  // LE 3
  EXPECT_EQ(dec("68 00 00 68 00 16"), DecodeError::LengthOutOfRange);
  EXPECT_EQ(dec("68 FF FF 68"), DecodeError::LengthOutOfRange);
}

TEST(TelegramLength, EncodeAsRefusesWhatDoesNotFit) {
  const std::uint8_t d7[] = {1, 2, 3, 4, 5, 6, 7};
  const std::uint8_t d9[] = {1, 2, 3, 4, 5, 6, 7, 8, 9};
  Frame f;
  EXPECT_EQ(encode_as(FrameType::SD3, {.da = 1, .sa = 2, .fc = 0x7D, .data = d7}, f),
            EncodeError::DataTooShort);
  EXPECT_EQ(encode_as(FrameType::SD3, {.da = 1, .sa = 2, .fc = 0x7D, .data = d9}, f),
            EncodeError::DataTooLong);
  EXPECT_EQ(encode_as(FrameType::SD1, {.da = 1, .sa = 2, .fc = 0x7D, .data = d7}, f),
            EncodeError::DataTooLong);
  EXPECT_EQ(encode_as(FrameType::SD1, {.da = 1, .sa = 2, .fc = 0x7D, .dsap = 3}, f),
            EncodeError::DataTooLong);
  EXPECT_EQ(encode_as(FrameType::SD2, {.da = 1, .sa = 2, .fc = 0x7D}, f), EncodeError::DataTooShort);
  EXPECT_TRUE(f.empty());
  // SD2 with one data octet is the shortest SD2 (LE 4).
  const std::uint8_t d1[] = {0x3C};
  ASSERT_EQ(encode_as(FrameType::SD2, {.da = 1, .sa = 10, .fc = 0x08, .data = d1}, f),
            EncodeError::None);
  EXPECT_EQ(to_hex(f.bytes()), "68 04 04 68 01 0A 08 3C 4F 16");
}

// --- every DecodeError ------------------------------------------------------------------------

TEST(TelegramDecodeError, EachValueFromAHandMadeFrame) {
  struct Case {
    const char* hex;
    DecodeError want;
  } cases[] = {
      {"", DecodeError::Empty},
      {"00", DecodeError::UnknownDelimiter},
      {"16 03 01 49 4D 16", DecodeError::UnknownDelimiter},
      {"10 03 01 49 4D", DecodeError::Truncated},
      {"A2 0A 01 7D 01 02 03 04 05 06 07 08 AC", DecodeError::Truncated},
      {"68 05 05", DecodeError::Truncated},
      {"68 05 05 68 8A 81 6D 3C 3E F2", DecodeError::Truncated},
      {"DC 05", DecodeError::Truncated},
      {"10 03 01 49 4D 16 00", DecodeError::TrailingOctets},
      {"E5 E5", DecodeError::TrailingOctets},
      {"DC 05 02 DC", DecodeError::TrailingOctets},
      {"68 05 05 68 8A 81 6D 3C 3E F2 16 16", DecodeError::TrailingOctets},
      {"68 05 06 68 8A 81 6D 3C 3E F2 16", DecodeError::LengthMismatch},
      {"68 03 03 68 0A 01 49 54 16", DecodeError::LengthOutOfRange},
      {"68 05 05 69 8A 81 6D 3C 3E F2 16", DecodeError::BadSecondDelimiter},
      {"10 03 01 49 4C 16", DecodeError::BadFcs},
      {"68 05 05 68 8A 81 6D 3C 3E F3 16", DecodeError::BadFcs},
      {"A2 0A 01 7D 01 02 03 04 05 06 07 08 AD 16", DecodeError::BadFcs},
      {"10 03 01 49 4D 17", DecodeError::BadEndDelimiter},
      {"68 05 05 68 8A 81 6D 3C 3E F2 06", DecodeError::BadEndDelimiter},
      {"10 05 7F 49 CD 16", DecodeError::BadSourceAddress},
      {"10 05 FF 49 4D 16", DecodeError::BadSourceAddress},
      {"68 05 05 68 8A 01 5D 45 11 3E 16", DecodeError::BadExtension},
      {"10 05 02 41 48 16", DecodeError::ReservedFunction},
      {"10 02 05 04 0B 16", DecodeError::ReservedStatus},
      {"10 7F 02 4C CD 16", DecodeError::BroadcastNotSdn},
  };
  std::set<DecodeError> seen;
  for (const Case& c : cases) {
    EXPECT_EQ(dec(c.hex), c.want) << c.hex << ": got " << to_string(dec(c.hex));
    seen.insert(c.want);
  }
  // Every error value except None is exercised, and each has its own message.
  std::set<std::string_view> messages;
  for (unsigned v = 1; v <= static_cast<unsigned>(DecodeError::BroadcastNotSdn); ++v) {
    const auto e = static_cast<DecodeError>(v);
    EXPECT_TRUE(seen.count(e)) << "no case for " << to_string(e);
    EXPECT_NE(to_string(e), "?");
    messages.insert(to_string(e));
  }
  EXPECT_EQ(messages.size(), static_cast<std::size_t>(DecodeError::BroadcastNotSdn));
}

TEST(TelegramDecodeError, EncodeErrorsHaveMessages) {
  std::set<std::string_view> messages;
  for (unsigned v = 0; v <= static_cast<unsigned>(EncodeError::WrongFrameType); ++v) {
    const auto e = static_cast<EncodeError>(v);
    EXPECT_NE(to_string(e), "?");
    messages.insert(to_string(e));
  }
  EXPECT_EQ(messages.size(), static_cast<std::size_t>(EncodeError::WrongFrameType) + 1);
}

// --- properties over the golden frames --------------------------------------------------------

std::vector<Bytes> fcs_frames() {
  std::vector<Bytes> out;
  for (const auto& g : test::kGoldenFrames)
    if (g.type != FrameType::SD4 && g.type != FrameType::SC) out.push_back(bytes_from_hex(g.hex));
  // Plus the longest frame, an SD2 with LE 249.
  Bytes body{0x8A, 0x81, 0x7D, 0x3D, 0x3E};
  const Bytes d = data_of(244);
  body.insert(body.end(), d.begin(), d.end());
  out.push_back(sd2(body));
  return out;
}

TEST(TelegramProperty, NoSingleBitFlipOfAnFcsFrameDecodes) {
  // Every SD1/SD2/SD3 octet is covered: SD, LE/LEr (must agree), SD2's second SD, the summed
  // octets (a flip changes the sum by ±2^k, never 0 mod 256), the FCS itself, ED.
  // Not so for SD4 and SC, which carry no FCS: a flipped address bit in a token gives another
  // valid token (tested below), which is why FDL relies on TSYN, parity and the token-pass check.
  std::size_t flips = 0;
  for (const Bytes& frame : fcs_frames()) {
    ASSERT_EQ(dec(frame), DecodeError::None) << to_hex(frame);
    for (std::size_t i = 0; i < frame.size(); ++i)
      for (int bit = 0; bit < 8; ++bit) {
        Bytes m = frame;
        m[i] = static_cast<std::uint8_t>(m[i] ^ (1u << bit));
        EXPECT_NE(dec(m), DecodeError::None) << to_hex(frame) << " octet " << i << " bit " << bit;
        ++flips;
      }
  }
  EXPECT_GT(flips, 4000u);
}

TEST(TelegramProperty, TokenAddressFlipsCanDecode) {
  // The documented exception: DC 05 02 with DA bit 0 flipped is a valid token to station 4.
  const Telegram t = dec_ok(bytes_from_hex("DC 04 02"));
  EXPECT_EQ(t.da, 4);
  // A flipped SC is no delimiter at all.
  for (int bit = 0; bit < 8; ++bit) {
    const Bytes m{static_cast<std::uint8_t>(0xE5 ^ (1u << bit))};
    EXPECT_EQ(dec(m), DecodeError::UnknownDelimiter) << bit;
  }
}

TEST(TelegramProperty, TruncationsAndAppendedOctetsFail) {
  for (const auto& g : test::kGoldenFrames) {
    const Bytes frame = bytes_from_hex(g.hex);
    for (std::size_t n = 0; n < frame.size(); ++n) {
      const Bytes cut(frame.begin(), frame.begin() + static_cast<std::ptrdiff_t>(n));
      EXPECT_NE(dec(cut), DecodeError::None) << g.name << " cut to " << n;
      // While the frame is incomplete, frame_length says "need more" or the full length.
      const int l = frame_length(cut);
      EXPECT_TRUE(l == 0 || l == static_cast<int>(frame.size())) << g.name << " " << n;
    }
    for (const int extra : {0x00, 0x16, 0xE5, 0xFF}) {
      Bytes longer = frame;
      longer.push_back(static_cast<std::uint8_t>(extra));
      EXPECT_EQ(dec(longer), DecodeError::TrailingOctets) << g.name;
      EXPECT_EQ(frame_length(longer), static_cast<int>(frame.size()));
    }
  }
}

// --- frame_length -----------------------------------------------------------------------------

TEST(TelegramFrameLength, HandWrittenCases) {
  struct Case {
    const char* hex;
    int want;
  } cases[] = {
      {"", 0},
      {"E5", 1},
      {"E5 10", 1},
      {"DC", 3},
      {"10", 6},
      {"A2", 14},
      {"68", 0},
      {"68 05", 0},
      {"68 05 05", 0},
      {"68 05 05 68", 11},
      {"68 05 05 68 8A 81", 11},
      {"68 04 04 68", 10},
      {"68 F9 F9 68", 255},
      {"68 05 06", -1},        // LE != LEr
      {"68 05 06 68", -1},
      {"68 05 05 69", -1},     // bad second delimiter
      {"68 03", -1},           // LE below 4
      {"68 FA", -1},           // LE above 249
      {"68 03 03 68", -1},
      {"00", -1},
      {"16", -1},
      {"FF 10", -1},
  };
  for (const Case& c : cases) EXPECT_EQ(frame_length(bytes_from_hex(c.hex)), c.want) << c.hex;
}

TEST(TelegramFrameLength, SplitsAByteStream) {
  // A serial port delivers frames back to back; frame_length() cuts them apart.
  Bytes stream;
  for (const auto& g : test::kGoldenFrames) {
    const Bytes b = bytes_from_hex(g.hex);
    stream.insert(stream.end(), b.begin(), b.end());
  }
  std::size_t pos = 0, n = 0;
  while (pos < stream.size()) {
    const int l = frame_length(std::span(stream).subspan(pos));
    ASSERT_GT(l, 0);
    EXPECT_EQ(dec(Bytes(stream.begin() + static_cast<std::ptrdiff_t>(pos),
                        stream.begin() + static_cast<std::ptrdiff_t>(pos) + l)),
              DecodeError::None);
    pos += static_cast<std::size_t>(l);
    ++n;
  }
  EXPECT_EQ(pos, stream.size());
  EXPECT_EQ(n, std::size(test::kGoldenFrames));
}

TEST(TelegramMisc, NamesOfEnums) {
  EXPECT_EQ(to_string(FrameType::SD1), "SD1");
  EXPECT_EQ(to_string(FrameType::SD3), "SD3");
  EXPECT_EQ(to_string(FrameType::SC), "SC");
  EXPECT_EQ(to_string(RequestFn::SrdHigh), "SRD_high");
  EXPECT_EQ(to_string(static_cast<RequestFn>(0x8)), "reserved");
  EXPECT_EQ(to_string(ResponseStatus::DH), "DH");
  EXPECT_EQ(to_string(static_cast<ResponseStatus>(0x4)), "reserved");
  EXPECT_EQ(to_string(StationType::MasterInRing), "master in ring");
  EXPECT_EQ(fcs(bytes_from_hex("8A 81 6D 3C 3E")), 0xF2);
  EXPECT_EQ(fcs({}), 0);
}

}  // namespace
}  // namespace pbvbus::fdl
