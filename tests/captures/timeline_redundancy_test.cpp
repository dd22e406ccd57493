// The active channel of switched stations in the timeline model (timeline.hpp, docs/redundancy.md): a
// capture written here with two line interfaces and hand-made Redundancy event records at known
// times; the spans per station exactly (start, end, line, lane), the mapping of line indices to
// lanes, the window, and the rows in the HTML data and the SVG.

#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "capture_fixture.hpp"

#include "pbvbus/captures/pcapng_writer.hpp"
#include "pbvbus/captures/timeline.hpp"
#include "pbvbus/captures/timeline_render.hpp"

namespace pbvbus::captures {
namespace {

using test::Bytes;

constexpr std::int64_t kMs = 1'000'000;  // ns

// redundancy::SystemEvent::Kind
constexpr std::uint16_t kLoss = 0, kFailure = 2, kReturn = 3, kSwitchover = 6;

EventRecord red(std::uint16_t code, int station, int line, std::string text) {
  EventRecord e;
  e.category = EventCategory::Redundancy;
  e.code = code;
  e.line = line;
  e.a = station;
  e.b = line;
  e.value = code == kSwitchover ? 0 : 0x73A3;
  e.text = std::move(text);
  return e;
}

struct Writer {
  test::MemorySink mem;
  PcapngWriter w{mem.sink()};
  void event(std::int64_t ms, const EventRecord& e) { w.write_event(ms * bus::kTicksPerMs, e); }
  Bytes done() {
    w.flush();
    return mem.data;
  }
};

/// Two lines DP_A, DP_B; stations 3 and 6 start on line 0 at 5 ms, 3 switches to line 1 at
/// 1000 ms, 6 fails at 2000 ms and comes back (start-up) on line 1 at 2600 ms; the capture ends
/// with a note at 3000 ms.
Bytes make_capture() {
  Writer c;
  c.w.add_interface("DP_A", "PROFIBUS-DP 1.5 Mbit/s", pcapng::LinkType::User0, 1'500'000);
  c.w.add_interface("DP_B", "PROFIBUS-DP 1.5 Mbit/s", pcapng::LinkType::User0, 1'500'000);
  c.event(5, red(kSwitchover, 3, 0, "switchover of switched station 3 to line DP_A (start-up)"));
  c.event(5, red(kSwitchover, 6, 0, "switchover of switched station 6 to line DP_A (start-up)"));
  c.event(1000, red(kLoss, 3, 0, "OB 70 W#16#73A3 redundancy loss: switched station 3, line DP_A"));
  c.event(1000,
          red(kSwitchover, 3, 1, "switchover of switched station 3 to line DP_B (channel failure)"));
  c.event(2000, red(kFailure, 6, 1, "OB 86 W#16#39C4 station failure: switched station 6, line DP_B"));
  // A one-sided slave's failure and the master system's events make no row.
  c.event(2100, red(kFailure, 10, 0, "OB 86 W#16#39C4 station failure: slave 10, line DP_A"));
  c.event(2200, red(4, -1, 1, "OB 86 W#16#39C3 master system failure, line DP_B"));
  c.event(2600, red(kReturn, 6, 1, "OB 86 W#16#38C4 station return: switched station 6, line DP_B"));
  c.event(2600, red(kSwitchover, 6, 1, "switchover of switched station 6 to line DP_B (start-up)"));
  EventRecord note;
  note.category = EventCategory::Note;
  note.text = "the end";
  c.event(3000, note);
  return c.done();
}

Timeline build(const Bytes& data, TimelineOptions opts = {}) {
  std::string error;
  auto tl = build_timeline(data, opts, error);
  EXPECT_TRUE(tl.has_value()) << error;
  return tl ? std::move(*tl) : Timeline{};
}

struct Want {
  int station, line, lane;
  std::int64_t start_ns, end_ns;
};

void expect_spans(const Timeline& tl, const std::vector<Want>& want) {
  ASSERT_EQ(tl.active_channels.size(), want.size());
  for (std::size_t i = 0; i < want.size(); ++i) {
    SCOPED_TRACE(i);
    const ActiveChannelSpan& s = tl.active_channels[i];
    EXPECT_EQ(s.station, want[i].station);
    EXPECT_EQ(s.line, want[i].line);
    EXPECT_EQ(s.line_lane, want[i].lane);
    EXPECT_EQ(s.start_ns, want[i].start_ns);
    EXPECT_EQ(s.end_ns, want[i].end_ns);
  }
}

TEST(TimelineActiveChannel, SpansPerStation) {
  const Timeline tl = build(make_capture());
  ASSERT_EQ(tl.lanes.size(), 2u);
  EXPECT_EQ(tl.last_ns, 3000 * kMs);
  expect_spans(tl, {
                       {3, 0, 0, 5 * kMs, 1000 * kMs},
                       {3, 1, 1, 1000 * kMs, 3000 * kMs},
                       {6, 0, 0, 5 * kMs, 2000 * kMs},
                       {6, -1, -1, 2000 * kMs, 2600 * kMs},
                       {6, 1, 1, 2600 * kMs, 3000 * kMs},
                   });
}

TEST(TimelineActiveChannel, WindowKeepsTheSpansThatOverlapIt) {
  TimelineOptions o;
  o.from_ns = 1500 * kMs;
  o.to_ns = 2500 * kMs;
  const Timeline tl = build(make_capture(), o);
  expect_spans(tl, {
                       {3, 1, 1, 1000 * kMs, 3000 * kMs},
                       {6, 0, 0, 5 * kMs, 2000 * kMs},
                       {6, -1, -1, 2000 * kMs, 2600 * kMs},
                   });
}

TEST(TimelineActiveChannel, LineIndicesNameLanesByTheLineEvents) {
  // Line 0 has two probes (DP_A@3, DP_A@6), line 1 one; a Line event names line 1 "DP_B".
  // Station 4 starts with no channel (its first record is a failure), goes to line 1, back to
  // the same line (one span), and to line 5, which has no lane.
  Writer c;
  c.w.add_interface("DP_A@3", "probe at station 3", pcapng::LinkType::User0, 1'500'000);
  c.w.add_interface("DP_A@6", "probe at station 6", pcapng::LinkType::User0, 1'500'000);
  c.w.add_interface("DP_B", "PROFIBUS-DP 1.5 Mbit/s", pcapng::LinkType::User0, 1'500'000);
  EventRecord power;
  power.category = EventCategory::Line;
  power.code = static_cast<std::uint16_t>(bus::LineEventKind::PowerOn);
  power.line = 1;
  power.a = 0;
  power.text = "DP_B: power on 'master 1'";
  c.event(0, power);
  c.event(1, red(kFailure, 4, 0, "station failure"));
  c.event(10, red(kSwitchover, 4, 1, "switchover to DP_B (start-up)"));
  c.event(20, red(kSwitchover, 4, 1, "switchover to DP_B (again)"));
  c.event(30, red(kSwitchover, 4, 0, "switchover to DP_A"));
  // Two records at one instant: the first one's zero-length span is dropped.
  c.event(40, red(kFailure, 4, 0, "station failure"));
  c.event(40, red(kSwitchover, 4, 5, "switchover to line 5"));
  c.event(50, red(kFailure, 4, 5, "station failure"));
  const Timeline tl = build(c.done());
  ASSERT_EQ(tl.lanes.size(), 3u);
  expect_spans(tl, {
                       {4, -1, -1, 1 * kMs, 10 * kMs},
                       {4, 1, 2, 10 * kMs, 30 * kMs},
                       {4, 0, 0, 30 * kMs, 40 * kMs},
                       {4, 5, -1, 40 * kMs, 50 * kMs},
                       {4, -1, -1, 50 * kMs, 50 * kMs},
                   });
}

TEST(TimelineActiveChannel, NoSwitchedStationsNoRows) {
  Writer c;
  c.w.add_interface("A", "", pcapng::LinkType::User0, 500'000);
  c.event(1, red(kFailure, 10, 0, "station failure"));
  const Timeline tl = build(c.done());
  EXPECT_TRUE(tl.active_channels.empty());
  EXPECT_NE(to_html(tl).find(",\"ac\":[]}"), std::string::npos);
  EXPECT_EQ(to_svg(tl).find("active-channel"), std::string::npos);
}

TEST(TimelineActiveChannel, RowsInTheHtmlDataAndTheSvg) {
  const Timeline tl = build(make_capture());
  const std::string html = to_html(tl);
  // Page times are the capture's (it starts near 0): [start, end, lane, line].
  EXPECT_NE(html.find(",\"ac\":[{\"a\":3,\"s\":[[5000000,1000000000,0,0],[1000000000,3000000000,1,1]]},"
                      "{\"a\":6,\"s\":[[5000000,2000000000,0,0],[2000000000,2600000000,-1,-1],"
                      "[2600000000,3000000000,1,1]]}]}"),
            std::string::npos);
  const std::string svg = to_svg(tl);
  EXPECT_NE(svg.find("<g class=\"active-channel\" data-station=\"3\">"), std::string::npos);
  EXPECT_NE(svg.find("<g class=\"active-channel\" data-station=\"6\">"), std::string::npos);
  EXPECT_NE(svg.find(">station 3 active</text>"), std::string::npos);
  std::size_t spans = 0;
  for (auto p = svg.find("class=\"ac-span\""); p != std::string::npos;
       p = svg.find("class=\"ac-span\"", p + 1))
    ++spans;
  EXPECT_EQ(spans, 5u);
  EXPECT_NE(svg.find("fill=\"url(#achatch)\"><title>station 6 active channel: none"),
            std::string::npos);
}

}  // namespace
}  // namespace pbvbus::captures
