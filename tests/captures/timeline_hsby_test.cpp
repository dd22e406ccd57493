// The Quantum Hot Standby rows in the timeline model (timeline.hpp "Quantum Hot Standby rows",
// docs/quantum-hsby.md "Captures and timeline"): a capture written here with one line interface
// and hand-made Hsby event records (hsby_event_record) at known times; the state spans per rack
// exactly, the switchover marks with their takeover times, the window, and the rows in the HTML
// data and the SVG.

#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "capture_fixture.hpp"

#include "pbvbus/bus/time.hpp"
#include "pbvbus/captures/hsby_event.hpp"
#include "pbvbus/captures/pcapng_writer.hpp"
#include "pbvbus/captures/timeline.hpp"
#include "pbvbus/captures/timeline_render.hpp"

namespace pbvbus::captures {
namespace {

using test::Bytes;

constexpr std::int64_t kHsMs = 1'000'000;  // ns

// hsby_event.hpp numbers (quantum::CpuState)
constexpr int kHsOff = 0, kHsOffline = 1, kHsPrimary = 2, kHsStandby = 3;

EventRecord hs(HsbyEventKind kind, int rack, int state, std::string text, std::uint64_t takeover = 0) {
  HsbyEventFields f;
  f.kind = kind;
  f.rack = rack;
  f.state = state;
  f.takeover_ns = takeover;
  f.text = std::move(text);
  return hsby_event_record(f);
}

struct HsWriter {
  test::MemorySink mem;
  PcapngWriter w{mem.sink()};
  HsWriter() { w.add_interface("DP_A", "PROFIBUS-DP 1.5 Mbit/s", pcapng::LinkType::User0, 1'500'000); }
  void ms(std::int64_t ms, const EventRecord& e) { w.write_event(ms * bus::kTicksPerMs, e); }
  Bytes done() {
    w.flush();
    return mem.data;
  }
};

using K = HsbyEventKind;

/// The pair "Q" (what QuantumNode writes, shortened):
///   0 ms     rack 0 powered (off), offline, primary at one instant
///   100 ms   rack 1 powered (off) and offline at one instant
///   300 ms   rack 1 offline -> standby
///   1000 ms  a fibre event of the pair (a = b = -1): no span
///   2000 ms  rack 0 primary -> off (power off)
///   2040 ms  rack 1 standby -> primary, then the switchover record (takeover 40 ms)
///   3000 ms  rack 0 powered (off: no change) and offline
///   3200 ms  rack 0 offline -> standby; a key record of rack 0 (standby: no change)
///   4000 ms  a second pair "P": rack 0 primary
///   4500 ms  a switchover record of P rack 0 without a takeover time
///   5000 ms  a note: the end of the capture
Bytes make_hsby_capture() {
  HsWriter c;
  c.ms(0, hs(K::Power, 0, kHsOff, "Q: rack 0: power on"));
  c.ms(0, hs(K::State, 0, kHsOffline, "Q: rack 0: off -> offline (power on)"));
  c.ms(0, hs(K::State, 0, kHsPrimary, "Q: rack 0: offline -> primary (first powered)"));
  c.ms(100, hs(K::Power, 1, kHsOff, "Q: rack 1: power on"));
  c.ms(100, hs(K::State, 1, kHsOffline, "Q: rack 1: off -> offline (power on)"));
  c.ms(300, hs(K::State, 1, kHsStandby, "Q: rack 1: offline -> standby (transfer)"));
  c.ms(1000, hs(K::Fibre, -1, -1, "Q: fibre restored"));
  c.ms(2000, hs(K::State, 0, kHsOff, "Q: rack 0: primary -> off (power off)"));
  c.ms(2040, hs(K::State, 1, kHsPrimary, "Q: rack 1: standby -> primary (takeover)"));
  c.ms(2040, hs(K::Switchover, 1, kHsPrimary, "Q: rack 1: switchover rack 0 -> rack 1", 40'000'000));
  c.ms(3000, hs(K::Power, 0, kHsOff, "Q: rack 0: power on"));
  c.ms(3000, hs(K::State, 0, kHsOffline, "Q: rack 0: off -> offline (power on)"));
  c.ms(3200, hs(K::State, 0, kHsStandby, "Q: rack 0: offline -> standby (transfer)"));
  c.ms(3200, hs(K::Key, 0, kHsStandby, "Q: rack 0: key Run"));
  c.ms(4000, hs(K::State, 0, kHsPrimary, "P: rack 0: offline -> primary (first powered)"));
  c.ms(4500, hs(K::Switchover, 0, kHsPrimary, "P: rack 0: two primaries meet again"));
  EventRecord note;
  note.category = EventCategory::Note;
  note.text = "the end";
  c.ms(5000, note);
  return c.done();
}

Timeline build_hs(const Bytes& data, TimelineOptions opts = {}) {
  std::string error;
  auto tl = build_timeline(data, opts, error);
  EXPECT_TRUE(tl.has_value()) << error;
  return tl ? std::move(*tl) : Timeline{};
}

struct WantHs {
  const char* pair;
  int rack, state;
  std::int64_t start_ms, end_ms;
};

void expect_hs_spans(const Timeline& tl, const std::vector<WantHs>& want) {
  ASSERT_EQ(tl.hsby_states.size(), want.size());
  for (std::size_t i = 0; i < want.size(); ++i) {
    SCOPED_TRACE(i);
    const HsbyStateSpan& s = tl.hsby_states[i];
    EXPECT_EQ(s.pair, want[i].pair);
    EXPECT_EQ(s.rack, want[i].rack);
    EXPECT_EQ(s.state, want[i].state);
    EXPECT_EQ(s.start_ns, want[i].start_ms * kHsMs);
    EXPECT_EQ(s.end_ns, want[i].end_ms * kHsMs);
  }
}

TEST(TimelineHsby, SpansPerRack) {
  const Timeline tl = build_hs(make_hsby_capture());
  EXPECT_EQ(tl.last_ns, 5000 * kHsMs);
  expect_hs_spans(tl, {
                          // P before Q; off and offline at 0 ms last no time and are dropped.
                          {"P", 0, kHsPrimary, 4000, 5000},
                          {"Q", 0, kHsPrimary, 0, 2000},
                          {"Q", 0, kHsOff, 2000, 3000},
                          {"Q", 0, kHsOffline, 3000, 3200},
                          {"Q", 0, kHsStandby, 3200, 5000},
                          {"Q", 1, kHsOffline, 100, 300},
                          {"Q", 1, kHsStandby, 300, 2040},
                          {"Q", 1, kHsPrimary, 2040, 5000},
                      });
  ASSERT_EQ(tl.hsby_switchovers.size(), 2u);
  EXPECT_EQ(tl.hsby_switchovers[0].pair, "P");
  EXPECT_EQ(tl.hsby_switchovers[0].takeover_ns, 0u);
  const HsbySwitchoverMark& m = tl.hsby_switchovers[1];
  EXPECT_EQ(m.pair, "Q");
  EXPECT_EQ(m.rack, 1);
  EXPECT_EQ(m.ts_ns, 2040 * kHsMs);
  EXPECT_EQ(m.takeover_ns, 40'000'000u);
  EXPECT_EQ(m.text, "Q: rack 1: switchover rack 0 -> rack 1");
  // The records stay events: 16 Hsby records and the note.
  EXPECT_EQ(tl.events.size(), 17u);
  EXPECT_EQ(tl.bad_event_records, 0u);
}

TEST(TimelineHsby, WindowKeepsTheSpansThatOverlapIt) {
  TimelineOptions o;
  o.from_ns = 2500 * kHsMs;
  o.to_ns = 3100 * kHsMs;
  const Timeline tl = build_hs(make_hsby_capture(), o);
  expect_hs_spans(tl, {
                          {"Q", 0, kHsOff, 2000, 3000},
                          {"Q", 0, kHsOffline, 3000, 3200},
                          {"Q", 1, kHsPrimary, 2040, 5000},
                      });
  EXPECT_TRUE(tl.hsby_switchovers.empty());  // 2040 ms is before the window
  o.from_ns = 2040 * kHsMs;
  EXPECT_EQ(build_hs(make_hsby_capture(), o).hsby_switchovers.size(), 1u);
}

std::size_t hs_count(const std::string& s, const std::string& what) {
  std::size_t n = 0;
  for (auto p = s.find(what); p != std::string::npos; p = s.find(what, p + 1)) ++n;
  return n;
}

TEST(TimelineHsby, RowsInTheHtmlData) {
  const std::string html = to_html(build_hs(make_hsby_capture()));
  // Two pairs: the labels name them. Spans [start, end, state], switchovers [time, takeover ns,
  // text] in page time (the capture starts at 0); '>' in a text is \u003e in the page's data.
  EXPECT_NE(html.find(",\"hsby\":{\"states\":[\"off\",\"offline\",\"primary\",\"standby\"],\"rows\":["
                      "{\"label\":\"P: Quantum rack 0\",\"pair\":\"P\",\"r\":0,"
                      "\"s\":[[4000000000,5000000000,2]],"
                      "\"sw\":[[4500000000,0,\"P: rack 0: two primaries meet again\"]]},"
                      "{\"label\":\"Q: Quantum rack 0\",\"pair\":\"Q\",\"r\":0,"
                      "\"s\":[[0,2000000000,2],[2000000000,3000000000,0],[3000000000,3200000000,1],"
                      "[3200000000,5000000000,3]],\"sw\":[]},"
                      "{\"label\":\"Q: Quantum rack 1\",\"pair\":\"Q\",\"r\":1,"
                      "\"s\":[[100000000,300000000,1],[300000000,2040000000,3],[2040000000,5000000000,2]],"
                      "\"sw\":[[2040000000,40000000,\"Q: rack 1: switchover rack 0 -\\u003e rack 1\"]]}]}}"),
            std::string::npos)
      << html.substr(html.find(",\"hsby\":"), 1200);
  // The page draws them (its script names the classes).
  EXPECT_NE(html.find("class=\"hsby-span\""), std::string::npos);
  EXPECT_NE(html.find("class=\"hsby-switchover\""), std::string::npos);
}

TEST(TimelineHsby, RowsInTheSvg) {
  const std::string svg = to_svg(build_hs(make_hsby_capture()));
  EXPECT_EQ(hs_count(svg, "<g class=\"hsby-row\""), 3u);
  EXPECT_NE(svg.find("<g class=\"hsby-row\" data-pair=\"Q\" data-rack=\"1\">"), std::string::npos);
  EXPECT_NE(svg.find(">Q: Quantum rack 1</text>"), std::string::npos);
  EXPECT_EQ(hs_count(svg, "class=\"hsby-span\""), 8u);
  // Rack 1 primary from the takeover to the end, green, with its tooltip.
  EXPECT_NE(svg.find("fill=\"#2f9e44\"><title>Q: Quantum rack 1: primary&#10;from "
                     "2.040\u2009000\u2009000 s&#10;to 5.000\u2009000\u2009000 s (2.960000 s)</title>"),
            std::string::npos);
  // The switchover marker with its takeover time; one without a time says so.
  EXPECT_NE(svg.find("<g class=\"hsby-switchover\" data-takeover-ns=\"40000000\">"), std::string::npos);
  EXPECT_NE(svg.find("<title>2.040\u2009000\u2009000 s switchover to rack 1, takeover 40.000 ms&#10;"
                     "Q: rack 1: switchover rack 0 -&gt; rack 1</title>"),
            std::string::npos);
  EXPECT_NE(svg.find("switchover to rack 0, no takeover time"), std::string::npos);
  EXPECT_NE(svg.find(">Quantum rack</text>"), std::string::npos);
}

TEST(TimelineHsby, NoPairNoRows) {
  HsWriter c;
  c.ms(1, hs(K::Fibre, -1, -1, "Q: fibre cut"));
  c.ms(2, hs(K::Key, 0, -1, "Q: rack 0: a record without a state"));
  const Timeline tl = build_hs(c.done());
  EXPECT_TRUE(tl.hsby_states.empty());
  EXPECT_TRUE(tl.hsby_switchovers.empty());
  EXPECT_EQ(to_html(tl).find(",\"hsby\":"), std::string::npos);
  EXPECT_EQ(to_svg(tl).find("hsby-row"), std::string::npos);
}

}  // namespace
}  // namespace pbvbus::captures
