// How much of a long capture the timeline page holds (timeline_window.hpp): which frames are in
// the window for --max-frames with and without --from/--to, the note, and the page built from it.
// The capture is written here with frames at known times on two lanes.

#include <gtest/gtest.h>

#include "capture_fixture.hpp"

#include "pbvbus/captures/pcapng_writer.hpp"
#include "pbvbus/captures/timeline.hpp"
#include "pbvbus/captures/timeline_render.hpp"
#include "pbvbus/captures/timeline_window.hpp"

namespace pbvbus::captures {
namespace {

constexpr std::int64_t kMs = 1'000'000;
constexpr std::int64_t kUs = 1'000;

// Lane A (500 kbit/s): an SC (11 bit times = 22 us) at 1.0, 1.2, ..., 2.8 ms (10 frames).
// Lane B (1.5 Mbit/s): an SC at 1.1, 1.3, ..., 1.9 ms (5 frames).
// In start order over both lanes: A 1.0, B 1.1, A 1.2, B 1.3, A 1.4, B 1.5, A 1.6, B 1.7, A 1.8,
// B 1.9, A 2.0, A 2.2, A 2.4, A 2.6, A 2.8. The capture ends at 2.822 ms (+1 ns).
Timeline whole_capture(const TimelineOptions& opts = {}) {
  bus::Scheduler sched;
  bus::Line a(sched, "A", bus::Baud::k500);
  bus::Line b(sched, "B", bus::Baud::k1_5M);
  test::MemorySink mem;
  PcapngWriter w(mem.sink());
  for (int i = 0; i < 10; ++i)
    w.on_frame(test::tap_frame(a, test::kSc, bus::kTicksPerMs + i * 200 * bus::kTicksPerUs));
  for (int i = 0; i < 5; ++i)
    w.on_frame(test::tap_frame(b, test::kSc, bus::kTicksPerMs + (100 + i * 200) * bus::kTicksPerUs));
  w.flush();
  std::string error;
  auto tl = build_timeline(mem.data, opts, error);
  EXPECT_TRUE(tl) << error;
  return tl ? *tl : Timeline{};
}

TEST(TimelineWindow, SmallCapturesAndNoLimitAreWhole) {
  const Timeline tl = whole_capture();
  ASSERT_EQ(tl.from_ns, 1 * kMs);
  ASSERT_EQ(tl.to_ns, 2822 * kUs + 1);
  for (std::uint64_t max : {0ull, 15ull, 100ull}) {
    const PageWindow w = page_window(tl, std::nullopt, std::nullopt, max);
    EXPECT_FALSE(w.cut) << max;
    EXPECT_EQ(w.frames, 15u);
    EXPECT_EQ(w.total_frames, 15u);
    EXPECT_EQ(w.from_ns, tl.from_ns);
    EXPECT_EQ(w.to_ns, tl.to_ns);
    EXPECT_EQ(page_window_note(tl, w, max), "");
  }
}

TEST(TimelineWindow, FirstFramesFromTheStartOverAllLanes) {
  const Timeline tl = whole_capture();
  // 4 frames: A 1.0, B 1.1, A 1.2, B 1.3; the window ends where the fifth (A 1.4) starts.
  const PageWindow w = page_window(tl, std::nullopt, std::nullopt, 4);
  EXPECT_TRUE(w.cut);
  EXPECT_EQ(w.from_ns, 1 * kMs);
  EXPECT_EQ(w.to_ns, 1400 * kUs);
  EXPECT_EQ(w.frames, 4u);
  EXPECT_EQ(w.total_frames, 15u);
  EXPECT_EQ(page_window_note(tl, w, 4),
            "This page holds the frames of 0.001000 s \u2013 0.001400 s only (the capture: 0.001000 s \u2013 "
            "0.002822 s): 4 of 15 frames (--max-frames 4); events and the rows below the lanes cover the "
            "whole capture. Use --from/--to for another stretch, --max-frames 0 for all.");
  // The page of that window: its frames are exactly those four, and it carries the note.
  TimelineOptions wo;
  wo.from_ns = w.from_ns;
  wo.to_ns = w.to_ns;
  const Timeline part = whole_capture(wo);
  ASSERT_EQ(part.lanes.size(), 2u);
  EXPECT_EQ(part.lanes[0].frames.size(), 2u);
  EXPECT_EQ(part.lanes[1].frames.size(), 2u);
  EXPECT_EQ(part.lanes[0].frames.back().start_ns, 1200 * kUs);
  EXPECT_EQ(part.lanes[1].frames.back().start_ns, 1300 * kUs);
  TimelineHtmlOptions ho;
  ho.note = page_window_note(tl, w, 4);
  const std::string page = to_html(part, ho);
  EXPECT_NE(page.find("<p id=\"note\" class=\"note\"><strong>This page holds the frames of 0.001000 s"),
            std::string::npos);
  EXPECT_NE(page.find("2 lanes \u00b7 4 frames"), std::string::npos);
  EXPECT_EQ(to_html(tl).find("id=\"note\""), std::string::npos);
}

TEST(TimelineWindow, FromAndToChooseTheStretch) {
  const Timeline tl = whole_capture();
  // From 1.5 ms: B 1.5, A 1.6, B 1.7, A 1.8; the fifth is B 1.9.
  PageWindow w = page_window(tl, 1500 * kUs, std::nullopt, 4);
  EXPECT_TRUE(w.cut);
  EXPECT_EQ(w.from_ns, 1500 * kUs);
  EXPECT_EQ(w.to_ns, 1900 * kUs);
  EXPECT_EQ(w.frames, 4u);
  // A frame that started before --from but still runs overlaps the window and counts: from
  // 1.41 ms the A frame of 1.4 ms (to 1.422 ms) is the first.
  w = page_window(tl, 1410 * kUs, std::nullopt, 2);
  EXPECT_EQ(w.to_ns, 1600 * kUs);  // A 1.4, B 1.5; A 1.6 is the third
  EXPECT_EQ(w.frames, 2u);
  // --to within the limit: the window is exactly --from..--to (A 2.2, A 2.4), still a cut.
  w = page_window(tl, 2100 * kUs, 2500 * kUs, 4);
  EXPECT_TRUE(w.cut);
  EXPECT_EQ(w.from_ns, 2100 * kUs);
  EXPECT_EQ(w.to_ns, 2500 * kUs);
  EXPECT_EQ(w.frames, 2u);
  // --to beyond the limit: the limit wins.
  w = page_window(tl, std::nullopt, 2500 * kUs, 3);
  EXPECT_EQ(w.to_ns, 1300 * kUs);
  EXPECT_EQ(w.frames, 3u);
  // An empty stretch gives an empty page, never an inverted window.
  w = page_window(tl, 2900 * kUs, std::nullopt, 3);
  EXPECT_EQ(w.frames, 0u);
  EXPECT_LT(w.from_ns, w.to_ns);
}

}  // namespace
}  // namespace pbvbus::captures
