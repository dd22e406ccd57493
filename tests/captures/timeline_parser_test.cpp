// The timeline model (timeline.hpp) on a capture written here from hand-made telegrams at known
// times: lanes, frame kinds, exact start/end ns, idle gaps, token holder spans, DP cycles,
// events, the window; and clear errors, never a crash, for broken files (runs under ASan+UBSan:
// the model parses untrusted files).

#include <gtest/gtest.h>

#include <algorithm>
#include <limits>
#include <random>

#include "capture_fixture.hpp"

#include "pbvbus/bus/tap.hpp"
#include "pbvbus/captures/pcapng_format.hpp"
#include "pbvbus/captures/pcapng_writer.hpp"
#include "pbvbus/captures/timeline.hpp"
#include "pbvbus/captures/timeline_render.hpp"

namespace pbvbus::captures {
namespace {

using test::Bytes;

// Golden telegrams, written by hand. FCS = sum of DA, SA, FC and the data, mod 256.
// Token 2 -> 1 and 1 -> 2 (SD4 DA SA, no FCS).
const Bytes kTok2to1 = {0xDC, 0x01, 0x02};
const Bytes kTok1to2 = {0xDC, 0x02, 0x01};
// SD1 FDL_Status request 1 -> 2: FC 0x49 = request 0x40 | FDL_Status 9.
// FCS = 02 + 01 + 49 = 0x4C.
const Bytes kStatusReq = {0x10, 0x02, 0x01, 0x49, 0x4C, 0x16};
// SD1 response 2 -> 1: FC 0x20 = master ready (2 << 4) | OK. FCS = 01 + 02 + 20 = 0x23.
const Bytes kStatusRes = {0x10, 0x01, 0x02, 0x20, 0x23, 0x16};
// SD2 Data_Exchange 1 -> 10 (SRD_high, FCV, FCB 0: FC 0x5D), no SAPs, outputs AA 55.
// FCS = 0A + 01 + 5D + AA + 55 = 0x167 -> 0x67.
const Bytes kDx1to10 = {0x68, 0x05, 0x05, 0x68, 0x0A, 0x01, 0x5D, 0xAA, 0x55, 0x67, 0x16};
// SD2 response 10 -> 1: FC 0x08 = slave, DL; input 3C. FCS = 01 + 0A + 08 + 3C = 0x4F.
const Bytes kDxRes10to1 = {0x68, 0x04, 0x04, 0x68, 0x01, 0x0A, 0x08, 0x3C, 0x4F, 0x16};
// SD2 Data_Exchange 2 -> 10, FC 0x7D (SRD_high, FCV, FCB 1).
// FCS = 0A + 02 + 7D + AA + 55 = 0x188 -> 0x88.
const Bytes kDx2to10 = {0x68, 0x05, 0x05, 0x68, 0x0A, 0x02, 0x7D, 0xAA, 0x55, 0x88, 0x16};
// SD2 Data_Exchange 1 -> 10, FC 0x7D. FCS = 0A + 01 + 7D + AA + 55 = 0x187 -> 0x87.
const Bytes kDx1to10b = {0x68, 0x05, 0x05, 0x68, 0x0A, 0x01, 0x7D, 0xAA, 0x55, 0x87, 0x16};
// SD2 Slave_Diag request 1 -> 20 (DSAP 60, SSAP 62: not Data_Exchange), FC 0x6D.
// DA 0x94 = 20 | 0x80, SA 0x81 = 1 | 0x80. FCS = 94 + 81 + 6D + 3C + 3E = 0x1FC -> 0xFC.
const Bytes kDiag1to20 = {0x68, 0x05, 0x05, 0x68, 0x94, 0x81, 0x6D, 0x3C, 0x3E, 0xFC, 0x16};
const Bytes kSc = {0xE5};
// A token with SA 127: intact on the wire, but no FDL frame (BadSourceAddress).
const Bytes kTokSa127 = {0xDC, 0x05, 0x7F};

constexpr std::int64_t kT0 = 1'000'000;  // ns: the first frame, 1 ms
constexpr std::int64_t kBit = 2'000;     // ns per bit at 500 kbit/s
constexpr std::int64_t at(std::int64_t bit) { return kT0 + bit * kBit; }

// Line A at 500 kbit/s (every bit time is a whole number of ns), times in bit times from kT0:
//   f0  b0     token 2->1        3 octets  -> b33
//   f1  b66    FDL_Status 1->2   6         -> b132
//   f2  b143   status res 2->1   6         -> b209
//   f3  b242   DX 1->10         11         -> b363
//   f4  b374   DX res 10->1     10         -> b484
//   f5  b517   token 1->2        3         -> b550
//   f6  b583   DX 2->10         11         -> b704   (no answer)
//   f7  b1004  token 2->1        3         -> b1037
//   f8  b1070  DX 1->10         11         -> b1191
//   f9  b1202  SC                1         -> b1213  (answers f8)
//   f10 b1250  token SA 127      3         -> b1283  (bad: decoder)
//   f11 b1300  token 1->2        3         -> b1333  (bad: collision)
//   f12 b1400  Slave_Diag 1->20 11         -> b1521  (no answer; 20 never answers DX)
// Events: cable cut at b600, a note at b1100. Line B (1.5 Mbit/s) after them: SC at 2 ms and a
// token 100 bit times later.
Bytes make_capture() {
  bus::Scheduler sched;
  bus::Line a(sched, "A", bus::Baud::k500);
  bus::Line b(sched, "B", bus::Baud::k1_5M);
  test::MemorySink mem;
  PcapngWriter w(mem.sink());
  const bus::Ticks bit = bus::ticks_per_bit(bus::Baud::k500);  // 7272 ticks = 2000 ns
  const bus::Ticks t0 = bus::kTicksPerMs;
  auto put = [&](const Bytes& bytes, std::int64_t at_bit, std::uint16_t flags = 0) {
    w.on_frame(test::tap_frame(a, bytes, t0 + at_bit * bit, flags));
  };
  put(kTok2to1, 0);
  put(kStatusReq, 66);
  put(kStatusRes, 143);
  put(kDx1to10, 242);
  put(kDxRes10to1, 374);
  put(kTok1to2, 517);
  put(kDx2to10, 583);
  put(kTok2to1, 1004);
  put(kDx1to10b, 1070);
  put(kSc, 1202);
  // File order is not start order: the collision frame comes first.
  put(kTok1to2, 1300, bus::kRxCollision);
  put(kTokSa127, 1250);
  put(kDiag1to20, 1400);
  EventRecord cut;
  cut.category = EventCategory::Line;
  cut.code = static_cast<std::uint16_t>(bus::LineEventKind::CableCut);
  cut.line = 0;
  cut.text = "A: cable cut between 'x' and 'y'";
  w.write_event(t0 + 600 * bit, cut);
  EventRecord note;
  note.category = EventCategory::Note;
  note.text = "a note";
  w.write_event(t0 + 1100 * bit, note);
  const bus::Ticks bit_b = bus::ticks_per_bit(bus::Baud::k1_5M);  // 2424 ticks = 666.67 ns
  w.on_frame(test::tap_frame(b, kSc, 2 * bus::kTicksPerMs));
  w.on_frame(test::tap_frame(b, {0xDC, 0x05, 0x02}, 2 * bus::kTicksPerMs + 100 * bit_b));
  w.flush();
  return mem.data;
}

Timeline build(const Bytes& data, TimelineOptions opts = {}) {
  std::string error;
  auto tl = build_timeline(data, opts, error);
  EXPECT_TRUE(tl.has_value()) << error;
  return tl ? std::move(*tl) : Timeline{};
}

TEST(TimelineModel, LanesAndFrames) {
  const Timeline tl = build(make_capture());
  ASSERT_EQ(tl.lanes.size(), 2u);
  const TimelineLane& A = tl.lanes[0];
  EXPECT_EQ(A.name, "A");
  EXPECT_EQ(A.interface, 0u);
  EXPECT_EQ(A.speed, 500'000u);
  EXPECT_EQ(A.link_type, 147);
  EXPECT_EQ(tl.lanes[1].name, "B");
  EXPECT_EQ(tl.lanes[1].interface, 2u);  // 1 is the events interface
  EXPECT_EQ(tl.lanes[1].speed, 1'500'000u);
  EXPECT_EQ(tl.records, 17u);
  EXPECT_EQ(tl.skipped_interfaces, 0u);
  EXPECT_EQ(tl.bad_event_records, 0u);

  ASSERT_EQ(A.frames.size(), 13u);
  struct Want {
    std::int64_t start_bit, octets;
    FrameKind kind;
  };
  const Want want[] = {{0, 3, FrameKind::Token},       {66, 6, FrameKind::Request},
                       {143, 6, FrameKind::Response},  {242, 11, FrameKind::Request},
                       {374, 10, FrameKind::Response}, {517, 3, FrameKind::Token},
                       {583, 11, FrameKind::Request},  {1004, 3, FrameKind::Token},
                       {1070, 11, FrameKind::Request}, {1202, 1, FrameKind::Sc},
                       {1250, 3, FrameKind::Bad},      {1300, 3, FrameKind::Bad},
                       {1400, 11, FrameKind::Request}};
  for (std::size_t i = 0; i < 13; ++i) {
    SCOPED_TRACE(i);
    const TimelineFrame& f = A.frames[i];
    EXPECT_EQ(f.start_ns, at(want[i].start_bit));
    // octets x 11 bit times x 2000 ns
    EXPECT_EQ(f.end_ns, at(want[i].start_bit + want[i].octets * 11));
    EXPECT_EQ(f.bytes.size(), static_cast<std::size_t>(want[i].octets));
    EXPECT_EQ(f.kind, want[i].kind);
  }
  // Decoded fields.
  EXPECT_TRUE(A.frames[1].decoded);
  EXPECT_EQ(A.frames[1].type, fdl::FrameType::SD1);
  EXPECT_EQ(A.frames[1].da, 2);
  EXPECT_EQ(A.frames[1].sa, 1);
  EXPECT_EQ(A.frames[1].fc, 0x49);
  EXPECT_EQ(A.frames[3].data_len, 2u);
  EXPECT_FALSE(A.frames[3].dsap);
  EXPECT_EQ(A.frames[12].dsap, 60);
  EXPECT_EQ(A.frames[12].ssap, 62);
  // Bad frames: an intact frame the decoder rejects (no error flag), and a collision.
  EXPECT_EQ(A.frames[10].flags, 0u);
  EXPECT_FALSE(A.frames[10].decoded);
  EXPECT_NE(A.frames[10].problem, "");
  EXPECT_NE(A.frames[11].flags & pcapng::kFlagSymbolError, 0u);
  EXPECT_NE(A.frames[11].problem.find("collision"), std::string::npos) << A.frames[11].problem;
  EXPECT_EQ(A.bad_frames, 2u);
  // Idle gaps in ns and bit times since the end of the previous frame.
  EXPECT_FALSE(A.frames[0].idle_ns);
  EXPECT_EQ(A.frames[1].idle_ns, 33 * kBit);
  EXPECT_EQ(A.frames[1].idle_bits, 33);
  EXPECT_EQ(A.frames[2].idle_bits, 11);
  EXPECT_EQ(A.frames[9].idle_bits, 11);
  EXPECT_EQ(A.frames[7].idle_bits, 300);

  // Line B at 1.5 Mbit/s: 11 bit times are 7333.33 ns, rounded down; 33 are exactly 22000.
  const TimelineLane& B = tl.lanes[1];
  ASSERT_EQ(B.frames.size(), 2u);
  EXPECT_EQ(B.frames[0].start_ns, 2'000'000);
  EXPECT_EQ(B.frames[0].end_ns, 2'007'333);
  EXPECT_EQ(B.frames[0].kind, FrameKind::Sc);
  EXPECT_EQ(B.frames[1].start_ns, 2'066'666);  // 100 bits = 66666.67 ns, rounded down
  EXPECT_EQ(B.frames[1].end_ns, 2'066'666 + 22'000);
  EXPECT_EQ(B.frames[1].kind, FrameKind::Token);
  EXPECT_EQ(B.frames[1].idle_bits, 89);  // 59333 ns = 88.9995 bit times

  EXPECT_EQ(tl.first_ns, kT0);
  EXPECT_EQ(tl.last_ns, at(1521));
  EXPECT_EQ(tl.from_ns, kT0);
  EXPECT_EQ(tl.to_ns, at(1521) + 1);
}

TEST(TimelineModel, TokenHolderSpans) {
  const Timeline tl = build(make_capture());
  const auto& spans = tl.lanes[0].token;
  // The bad token (collision) makes no span; the last span runs to the end of the last frame.
  ASSERT_EQ(spans.size(), 3u);
  EXPECT_EQ(spans[0].holder, 1);
  EXPECT_EQ(spans[0].passed_by, 2);
  EXPECT_EQ(spans[0].start_ns, at(33));
  EXPECT_EQ(spans[0].end_ns, at(517));
  EXPECT_EQ(spans[1].holder, 2);
  EXPECT_EQ(spans[1].passed_by, 1);
  EXPECT_EQ(spans[1].start_ns, at(550));
  EXPECT_EQ(spans[1].end_ns, at(1004));
  EXPECT_EQ(spans[2].holder, 1);
  EXPECT_EQ(spans[2].start_ns, at(1037));
  EXPECT_EQ(spans[2].end_ns, at(1521));
  ASSERT_EQ(tl.lanes[1].token.size(), 1u);
  EXPECT_EQ(tl.lanes[1].token[0].holder, 5);
  EXPECT_EQ(tl.lanes[1].token[0].start_ns, 2'088'666);
  EXPECT_EQ(tl.lanes[1].token[0].end_ns, 2'088'666);
}

TEST(TimelineModel, DpCycles) {
  const Timeline tl = build(make_capture());
  const auto& slaves = tl.lanes[0].slaves;
  // 10 answered Data_Exchange; 20 was only sent a Slave_Diag and never answered.
  ASSERT_EQ(slaves.size(), 1u);
  const SlaveCycles& s = slaves[0];
  EXPECT_EQ(s.address, 10);
  ASSERT_EQ(s.polls.size(), 3u);
  EXPECT_EQ(s.polls[0].start_ns, at(242));
  EXPECT_EQ(s.polls[0].master, 1);
  EXPECT_TRUE(s.polls[0].answered);
  EXPECT_FALSE(s.polls[0].cycle_ns);
  EXPECT_EQ(s.polls[1].start_ns, at(583));
  EXPECT_EQ(s.polls[1].master, 2);
  EXPECT_FALSE(s.polls[1].answered);  // master 2 passed the token instead
  EXPECT_EQ(s.polls[1].cycle_ns, 341 * kBit);
  EXPECT_TRUE(s.polls[2].answered);  // by the SC
  EXPECT_EQ(s.polls[2].cycle_ns, 487 * kBit);
  EXPECT_EQ(s.unanswered, 1u);
  EXPECT_EQ(s.cycle.count, 2u);
  EXPECT_EQ(s.cycle.min_ns, 682'000);
  EXPECT_EQ(s.cycle.median_ns, 682'000);
  EXPECT_EQ(s.cycle.max_ns, 974'000);
  EXPECT_EQ(ns_to_bits(s.cycle.max_ns, 500'000), 487);
}

TEST(TimelineModel, Events) {
  const Timeline tl = build(make_capture());
  ASSERT_EQ(tl.events.size(), 2u);
  EXPECT_EQ(tl.events[0].ts_ns, at(600));
  EXPECT_EQ(tl.events[0].style, EventStyle::Fault);
  EXPECT_EQ(tl.events[0].record.category, EventCategory::Line);
  EXPECT_EQ(tl.events[0].record.text, "A: cable cut between 'x' and 'y'");
  EXPECT_EQ(tl.events[0].interface, 1u);
  EXPECT_EQ(tl.events[1].ts_ns, at(1100));
  EXPECT_EQ(tl.events[1].style, EventStyle::Event);
  EXPECT_EQ(tl.events[1].record.text, "a note");
}

TEST(TimelineModel, Window) {
  TimelineOptions o;
  o.from_ns = at(500);
  o.to_ns = at(1100);
  const Timeline tl = build(make_capture(), o);
  EXPECT_EQ(tl.from_ns, at(500));
  EXPECT_EQ(tl.to_ns, at(1100));
  const TimelineLane& A = tl.lanes[0];
  // Frames that overlap [b500, b1100): f5 .. f8 (f4 ends at b484, f9 starts at b1202).
  ASSERT_EQ(A.frames.size(), 4u);
  EXPECT_EQ(A.frames[0].start_ns, at(517));
  EXPECT_EQ(A.frames[3].start_ns, at(1070));
  EXPECT_EQ(A.bad_frames, 0u);
  // Idle gaps and cycle times are those of the whole capture.
  EXPECT_EQ(A.frames[0].idle_bits, 33);
  EXPECT_EQ(A.token.size(), 3u);  // the first span ends at b517, inside the window
  ASSERT_EQ(A.slaves.size(), 1u);
  ASSERT_EQ(A.slaves[0].polls.size(), 2u);
  EXPECT_EQ(A.slaves[0].polls[0].cycle_ns, 341 * kBit);
  EXPECT_EQ(A.slaves[0].unanswered, 1u);
  EXPECT_EQ(A.slaves[0].cycle.count, 2u);
  // Events: the cut is inside, the note at exactly the end is not (the window is half open).
  ASSERT_EQ(tl.events.size(), 1u);
  EXPECT_EQ(tl.events[0].style, EventStyle::Fault);
  // Lane B (2.000 ms .. 2.089 ms) lies inside [2.000 ms, 3.200 ms).
  EXPECT_EQ(tl.lanes[1].frames.size(), 2u);

  // A window between frames is empty but not an error.
  TimelineOptions gap;
  gap.from_ns = at(710);
  gap.to_ns = at(1000);
  const Timeline empty = build(make_capture(), gap);
  EXPECT_TRUE(empty.lanes[0].frames.empty());
  EXPECT_EQ(empty.lanes[0].token.size(), 1u);
  // A window that ends before it starts is an error, also when the end is the capture's.
  std::string error;
  TimelineOptions late;
  late.from_ns = at(5000);
  EXPECT_FALSE(build_timeline(make_capture(), late, error));
  EXPECT_EQ(error, "the window start 0.011000000 s is not before its end 0.004042001 s (the capture "
                   "ends at 0.004042000 s)");
  TimelineOptions bad;
  bad.from_ns = at(600);
  bad.to_ns = at(500);
  EXPECT_FALSE(build_timeline(make_capture(), bad, error));
  EXPECT_NE(error.find("is not before"), std::string::npos) << error;
  TimelineOptions early;
  early.to_ns = 10;
  EXPECT_FALSE(build_timeline(make_capture(), early, error));
  EXPECT_NE(error.find("is not before"), std::string::npos) << error;
}

TEST(TimelineModel, Describe) {
  const Timeline tl = build(make_capture());
  const auto& f = tl.lanes[0].frames;
  EXPECT_EQ(describe(f[0]), "SD4 token 2 \u2192 1");
  EXPECT_EQ(describe(f[1]),
            "SD1 request 1 \u2192 2\nFC 0x49: FDL_Status, FCV=0 FCB=0\nDSAP -, SSAP -\n"
            "6 octets, 0 data octets");
  EXPECT_EQ(describe(f[3]),
            "SD2 request 1 \u2192 10\nFC 0x5D: SRD_high, FCV=1 FCB=0\nDSAP -, SSAP - "
            "(Data_Exchange.req)\n11 octets, 2 data octets");
  EXPECT_EQ(describe(f[4]),
            "SD2 response 10 \u2192 1\nFC 0x08: DL, slave\nDSAP -, SSAP - (Data_Exchange.res)\n"
            "10 octets, 1 data octets");
  EXPECT_EQ(describe(f[9]), "SC short acknowledgement (0xE5)");
  EXPECT_NE(describe(f[12]).find("DSAP 60, SSAP 62 (Slave_Diag.req)"), std::string::npos);
  EXPECT_EQ(describe(f[11]).rfind("BAD FRAME: collision", 0), 0u) << describe(f[11]);
}

TEST(TimelineModel, ParseTime) {
  EXPECT_EQ(parse_time_ns("2s"), 2'000'000'000);
  EXPECT_EQ(parse_time_ns("1500ms"), 1'500'000'000);
  EXPECT_EQ(parse_time_ns("250us"), 250'000);
  EXPECT_EQ(parse_time_ns("250\u00b5s"), 250'000);
  EXPECT_EQ(parse_time_ns("100ns"), 100);
  EXPECT_EQ(parse_time_ns("1.25s"), 1'250'000'000);
  EXPECT_EQ(parse_time_ns(".5ms"), 500'000);
  EXPECT_EQ(parse_time_ns("0s"), 0);
  EXPECT_EQ(parse_time_ns("1.000000001s"), 1'000'000'001);
  EXPECT_EQ(parse_time_ns("1.5000000000s"), 1'500'000'000);  // zeros beyond ns are exact
  EXPECT_EQ(parse_time_ns("9223372036854775807ns"), std::numeric_limits<std::int64_t>::max());
  for (const char* bad : {"", "s", "2", "2 s", "-1s", "+1s", "1.s", "2sec", "1e3ms", "1.0000000001s",
                          "1.5ns", "9223372036854775808ns", "10000000000s", "99999999999999999999999s",
                          "1..2s", "\u00b5s", "2S"}) {
    EXPECT_FALSE(parse_time_ns(bad)) << bad;
  }
}

TEST(TimelineModel, BitArithmetic) {
  EXPECT_EQ(frame_duration_ns(1, 1'500'000), 7'333);
  EXPECT_EQ(frame_duration_ns(3, 1'500'000), 22'000);
  EXPECT_EQ(frame_duration_ns(255, 12'000'000), 233'750);
  EXPECT_EQ(frame_duration_ns(10, 9'600), 11'458'333);
  EXPECT_EQ(frame_duration_ns(5, 0), 0);
  EXPECT_EQ(ns_to_bits(7'333, 1'500'000), 11);
  EXPECT_EQ(ns_to_bits(-7'333, 1'500'000), -11);
  EXPECT_EQ(ns_to_bits(1'000, 500'000), 1);  // half a bit rounds away from zero
  EXPECT_EQ(ns_to_bits(-1'000, 500'000), -1);
  EXPECT_FALSE(ns_to_bits(1'000, 0));
  // 9223372036854775807 ns x 12 Mbit/s = 110680464442257309.7 bit times: no overflow inside.
  EXPECT_EQ(ns_to_bits(std::numeric_limits<std::int64_t>::max(), 12'000'000),
            110'680'464'442'257'310);
}

TEST(TimelineErrors, BrokenFiles) {
  const Bytes good = make_capture();
  std::string error;
  // Truncated in the middle of the last block.
  Bytes cut = good;
  cut.resize(cut.size() - 10);
  EXPECT_FALSE(build_timeline(cut, {}, error));
  EXPECT_EQ(error.rfind("offset ", 0), 0u) << error;
  EXPECT_EQ(error.find("offset 0:"), std::string::npos) << error;
  // Garbage.
  const std::string text = "this is not a pcapng capture, just text\n";
  EXPECT_FALSE(build_timeline(Bytes(text.begin(), text.end()), {}, error));
  EXPECT_EQ(error.rfind("offset 0: ", 0), 0u) << error;
  // Empty.
  EXPECT_FALSE(build_timeline(Bytes{}, {}, error));
  EXPECT_EQ(error, "offset 0: empty file, not a pcapng capture");
  // A section header and nothing else.
  test::MemorySink only_shb;
  {
    PcapngWriter w(only_shb.sink());
    w.flush();
  }
  EXPECT_FALSE(build_timeline(only_shb.data, {}, error));
  EXPECT_EQ(error, "the capture holds no records (no frames and no events)");
  // Events only.
  test::MemorySink only_events;
  {
    PcapngWriter w(only_events.sink());
    w.write_event(0, EventRecord{});
    w.flush();
  }
  EXPECT_FALSE(build_timeline(only_events.data, {}, error));
  EXPECT_NE(error.find("no line interface"), std::string::npos) << error;
  // A missing file.
  EXPECT_FALSE(read_timeline_file("/nonexistent/capture.pcapng", {}, error));
  EXPECT_NE(error.find("cannot open"), std::string::npos) << error;
}

/// Every EPB of `data` (little-endian, as PcapngWriter writes) gets the largest timestamp.
Bytes with_huge_timestamps(Bytes data) {
  auto u32 = [&](std::size_t o) {
    return std::uint32_t{data[o]} | std::uint32_t{data[o + 1]} << 8 | std::uint32_t{data[o + 2]} << 16 |
           std::uint32_t{data[o + 3]} << 24;
  };
  std::size_t pos = 0;
  while (pos + 12 <= data.size()) {
    const std::uint32_t type = u32(pos), len = u32(pos + 4);
    if (len < 12 || pos + len > data.size()) break;
    if (type == pcapng::kBlockEpb) std::fill(data.begin() + static_cast<std::ptrdiff_t>(pos + 12),
                                             data.begin() + static_cast<std::ptrdiff_t>(pos + 20), 0xFF);
    pos += len;
  }
  return data;
}

TEST(TimelineErrors, ExtremeTimestampsStayDefined) {
  std::string error;
  auto tl = build_timeline(with_huge_timestamps(make_capture()), {}, error);
  ASSERT_TRUE(tl) << error;
  const auto kMax = std::numeric_limits<std::int64_t>::max();
  ASSERT_FALSE(tl->lanes[0].frames.empty());
  for (const auto& f : tl->lanes[0].frames) {
    EXPECT_EQ(f.start_ns, kMax);
    EXPECT_EQ(f.end_ns, kMax);
  }
  // Drawing it must not fail either.
  EXPECT_NE(to_html(*tl).find("pbvbus-data"), std::string::npos);
  EXPECT_NE(to_svg(*tl).find("</svg>"), std::string::npos);
}

TEST(TimelineErrors, SeededMutationsNeverCrash) {
  const Bytes good = make_capture();
  std::mt19937 rng(20240611);
  int built = 0;
  for (int round = 0; round < 1500; ++round) {
    Bytes b = good;
    const int edits = 1 + static_cast<int>(rng() % 8);
    for (int e = 0; e < edits; ++e) {
      const std::size_t at_byte = rng() % b.size();
      switch (rng() % 4) {
        case 0:
          b[at_byte] = static_cast<std::uint8_t>(rng());
          break;
        case 1:
          b[at_byte] ^= static_cast<std::uint8_t>(1u << (rng() % 8));
          break;
        case 2:
          b[at_byte] = 0xFF;
          break;
        default:
          b.resize(std::max<std::size_t>(1, at_byte));
          break;
      }
      if (b.empty()) break;
    }
    std::string error;
    TimelineOptions o;
    if (round % 3 == 0) {
      o.from_ns = at(static_cast<std::int64_t>(rng() % 1500));
      o.to_ns = *o.from_ns + static_cast<std::int64_t>(rng() % 100'000) + 1;
    }
    auto tl = build_timeline(b, o, error);
    if (tl) {
      ++built;
      // The drawings of whatever survived must be produced without trouble.
      const std::string svg = to_svg(*tl);
      EXPECT_NE(svg.find("</svg>"), std::string::npos);
      if (round % 10 == 0) {
        const std::string html = to_html(*tl);
        EXPECT_EQ(html.find("</script>", html.find("pbvbus-data\">")),
                  html.find("</script>\n<script>"));
      }
    } else {
      EXPECT_FALSE(error.empty());
    }
  }
  EXPECT_GT(built, 50);
}

TEST(TimelineRender, Utf8AndEscaping) {
  EXPECT_EQ(sanitize_utf8("ok \u00b5s \u2192"), "ok \u00b5s \u2192");
  EXPECT_EQ(sanitize_utf8(std::string("a\xFF" "b", 3)), "a\uFFFDb");
  EXPECT_EQ(sanitize_utf8(std::string("\xC0\xAF", 2)), "\uFFFD\uFFFD");  // overlong '/'
  EXPECT_EQ(sanitize_utf8(std::string("\xED\xA0\x80", 3)), "\uFFFD\uFFFD\uFFFD");  // surrogate
  EXPECT_EQ(sanitize_utf8(std::string("x\x01y\n", 4)), "x\uFFFDy\n");
  EXPECT_EQ(sanitize_utf8(std::string("\xE2\x82", 2)), "\uFFFD\uFFFD");  // cut short

  // Hostile interface names and event texts stay text.
  bus::Scheduler sched;
  bus::Line line(sched, "</script><b>&\"'", bus::Baud::k500);
  test::MemorySink mem;
  PcapngWriter w(mem.sink());
  w.on_frame(test::tap_frame(line, kTok1to2, bus::kTicksPerMs));
  EventRecord e;
  e.text = std::string("</script><script>alert(1)</script>\xFF");
  w.write_event(bus::kTicksPerMs, e);
  w.flush();
  const Timeline tl = build(mem.data);
  const std::string html = to_html(tl);
  EXPECT_EQ(html.find("<b>&"), std::string::npos);
  EXPECT_EQ(html.find("alert(1)</script>"), std::string::npos);
  // Exactly the two script blocks of the page close.
  std::size_t closes = 0;
  for (std::size_t p = html.find("</script>"); p != std::string::npos; p = html.find("</script>", p + 1))
    ++closes;
  EXPECT_EQ(closes, 2u);
  const std::string svg = to_svg(tl);
  EXPECT_NE(svg.find("&lt;/script&gt;&lt;b&gt;&amp;&quot;&#39;"), std::string::npos);
  EXPECT_EQ(svg.find("<b>"), std::string::npos);
}

}  // namespace
}  // namespace pbvbus::captures
