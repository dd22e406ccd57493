// The CPU rows of an H system in the timeline model (timeline.hpp "CPU rows", docs/h-system.md): a
// capture written here with one line interface and hand-made Cpu event records
// (cpu_event_record) at known times; the (state, role) spans per CPU exactly, the OB marks, the
// window, and the rows in the HTML data and the SVG.

#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "capture_fixture.hpp"

#include "pbvbus/bus/time.hpp"
#include "pbvbus/captures/cpu_event.hpp"
#include "pbvbus/captures/pcapng_writer.hpp"
#include "pbvbus/captures/timeline.hpp"
#include "pbvbus/captures/timeline_render.hpp"

namespace pbvbus::captures {
namespace {

using test::Bytes;

constexpr std::int64_t kMs = 1'000'000;  // ns
constexpr std::int64_t kUs = 1'000;      // ns

// cpu_event.hpp numbers (devices::CpuState, CpuRole)
constexpr std::uint8_t kOff = 0, kStop = 1, kStartup = 2, kRun = 3, kLinkUp = 4, kUpdate = 5,
                       kHold = 6;
constexpr int kNone = 0, kMaster = 1, kStandby = 2;

EventRecord state(int rack, int role, std::uint8_t from, std::uint8_t to, std::string text) {
  CpuEventFields f;
  f.kind = CpuEventKind::State;
  f.rack = rack;
  f.role = role;
  f.from = from;
  f.to = to;
  f.text = std::move(text);
  return cpu_event_record(f);
}

EventRecord role(int rack, int from, int to, std::string text) {
  CpuEventFields f;
  f.kind = CpuEventKind::Role;
  f.rack = rack;
  f.role = to;
  f.from = static_cast<std::uint8_t>(from);
  f.to = static_cast<std::uint8_t>(to);
  f.text = std::move(text);
  return cpu_event_record(f);
}

EventRecord ob(int rack, int role_after, std::uint8_t number, std::uint16_t id,
               std::uint8_t reason, std::string text) {
  CpuEventFields f;
  f.kind = CpuEventKind::Ob;
  f.rack = rack;
  f.role = role_after;
  f.ob = number;
  f.event_id = id;
  f.reason = reason;
  f.text = std::move(text);
  return cpu_event_record(f);
}

EventRecord mode(int master_rack, std::uint8_t from, std::uint8_t to, std::string text) {
  CpuEventFields f;
  f.kind = CpuEventKind::SystemMode;
  f.rack = master_rack;
  f.role = kMaster;
  f.from = from;
  f.to = to;
  f.text = std::move(text);
  return cpu_event_record(f);
}

struct Writer {
  test::MemorySink mem;
  PcapngWriter w{mem.sink()};
  Writer() { w.add_interface("DP_A", "PROFIBUS-DP 1.5 Mbit/s", pcapng::LinkType::User0, 1'500'000); }
  void at(bus::Ticks t, const EventRecord& e) { w.write_event(t, e); }
  void ms(std::int64_t ms, const EventRecord& e) { at(ms * bus::kTicksPerMs, e); }
  Bytes done() {
    w.flush();
    return mem.data;
  }
};

/// The H system "H-CPU" (as the default scenario's start-up, shortened):
///   0 ms      CPU 0 STOP -> STARTUP (master), CPU 1 OFF -> STOP (no role); a Role record of
///             CPU 0 before its first State record (passed over)
///   1000 ms   CPU 0 STARTUP -> RUN (master), system mode Solo; CPU 1 STOP -> LINK-UP (standby)
///   3000 ms   CPU 1 LINK-UP -> UPDATE
///   3145.25 ms CPU 1 UPDATE -> RUN (standby)
///   5000 ms   OB 72 on CPU 0 (redundant link lost); CPU 1 RUN -> STOP (still standby), then
///             role standby -> none at the same instant
///   6000 ms   CPU 1 role none -> none (no change)
///   7000 ms   OB 85 W#16#39C4 for both CPUs (a = -1)
///   8000 ms   CPU 0 RUN -> HOLD -> RUN at one instant (the HOLD span has no length)
///   9000 ms   OB 121 on rack 2 and a Role record of rack 3: neither has a State record
///   10000 ms  a note: the end of the capture
Bytes make_capture() {
  Writer c;
  c.ms(0, role(0, kNone, kMaster, "H-CPU: CPU 0: role none -> master"));
  c.ms(0, state(0, kMaster, kStop, kStartup, "H-CPU: CPU 0: STOP -> STARTUP"));
  c.ms(0, state(1, kNone, kOff, kStop, "H-CPU: CPU 1: OFF -> STOP"));
  c.ms(1000, state(0, kMaster, kStartup, kRun, "H-CPU: CPU 0: STARTUP -> RUN"));
  c.ms(1000, mode(0, 1, 2, "H-CPU: system mode Startup -> Solo"));
  c.ms(1000, state(1, kStandby, kStop, kLinkUp, "H-CPU: CPU 1: STOP -> LINK-UP"));
  c.ms(3000, state(1, kStandby, kLinkUp, kUpdate, "H-CPU: CPU 1: LINK-UP -> UPDATE"));
  // 3145 ms + 250 µs in ticks: 3145 * 3 636 000 + 250 * 3636 = 11 435 220 000 + 909 000.
  c.at(3145 * bus::kTicksPerMs + 250 * bus::kTicksPerUs,
       state(1, kStandby, kUpdate, kRun, "H-CPU: CPU 1: UPDATE -> RUN"));
  c.ms(5000, ob(0, kMaster, 72, 0, 5, "H-CPU: CPU 0: OB 72 (redundant link lost)"));
  c.ms(5000, state(1, kStandby, kRun, kStop, "H-CPU: CPU 1: RUN -> STOP"));
  c.ms(5000, role(1, kStandby, kNone, "H-CPU: CPU 1: role standby -> none"));
  c.ms(6000, role(1, kNone, kNone, "H-CPU: CPU 1: role none -> none"));
  c.ms(7000, ob(-1, kNone, 85, 0x39C4, 0, "H-CPU: CPU 0+1: OB 85 W#16#39C4 station 11"));
  c.ms(8000, state(0, kMaster, kRun, kHold, "H-CPU: CPU 0: RUN -> HOLD"));
  c.ms(8000, state(0, kMaster, kHold, kRun, "H-CPU: CPU 0: HOLD -> RUN"));
  c.ms(9000, ob(2, kMaster, 121, 0x2522, 0, "H-CPU: CPU 2: OB 121"));
  c.ms(9000, role(3, kNone, kMaster, "H-CPU: CPU 3: role none -> master"));
  EventRecord note;
  note.category = EventCategory::Note;
  note.text = "the end";
  c.ms(10000, note);
  return c.done();
}

Timeline build(const Bytes& data, TimelineOptions opts = {}) {
  std::string error;
  auto tl = build_timeline(data, opts, error);
  EXPECT_TRUE(tl.has_value()) << error;
  return tl ? std::move(*tl) : Timeline{};
}

struct WantSpan {
  const char* system;
  int rack, state, role;
  std::int64_t start_ns, end_ns;
};

void expect_spans(const Timeline& tl, const std::vector<WantSpan>& want) {
  ASSERT_EQ(tl.cpu_states.size(), want.size());
  for (std::size_t i = 0; i < want.size(); ++i) {
    SCOPED_TRACE(i);
    const CpuStateSpan& s = tl.cpu_states[i];
    EXPECT_EQ(s.system, want[i].system);
    EXPECT_EQ(s.rack, want[i].rack);
    EXPECT_EQ(s.state, want[i].state);
    EXPECT_EQ(s.role, want[i].role);
    EXPECT_EQ(s.start_ns, want[i].start_ns);
    EXPECT_EQ(s.end_ns, want[i].end_ns);
  }
}

struct WantOb {
  int rack;
  std::int64_t ts_ns;
  int ob;
  std::uint16_t id;
  int reason;
  const char* text;
};

void expect_obs(const Timeline& tl, const std::vector<WantOb>& want) {
  ASSERT_EQ(tl.cpu_obs.size(), want.size());
  for (std::size_t i = 0; i < want.size(); ++i) {
    SCOPED_TRACE(i);
    const CpuObMark& m = tl.cpu_obs[i];
    EXPECT_EQ(m.system, "H-CPU");
    EXPECT_EQ(m.rack, want[i].rack);
    EXPECT_EQ(m.ts_ns, want[i].ts_ns);
    EXPECT_EQ(m.ob, want[i].ob);
    EXPECT_EQ(m.event_id, want[i].id);
    EXPECT_EQ(m.reason, want[i].reason);
    EXPECT_EQ(m.text, want[i].text);
  }
}

// 3145 ms + 250 µs = 3 145 250 000 ns.
constexpr std::int64_t kUpdateEnd = 3145 * kMs + 250 * kUs;

TEST(TimelineCpu, NamesOfTheNumbers) {
  EXPECT_EQ(cpu_state_name(0), "OFF");
  EXPECT_EQ(cpu_state_name(3), "RUN");
  EXPECT_EQ(cpu_state_name(4), "LINK-UP");
  EXPECT_EQ(cpu_state_name(7), "ERROR-SEARCH");
  EXPECT_EQ(cpu_state_name(9), "SYNCUP");
  EXPECT_EQ(cpu_state_name(10), "state 10");
  EXPECT_EQ(cpu_state_name(-1), "state -1");
  EXPECT_EQ(cpu_role_name(0), "none");
  EXPECT_EQ(cpu_role_name(1), "master");
  EXPECT_EQ(cpu_role_name(2), "standby");
  EXPECT_EQ(cpu_role_name(3), "role 3");
  EXPECT_EQ(cpu_system_mode_name(2), "Solo");
  EXPECT_EQ(cpu_system_mode_name(5), "Redundant");
  EXPECT_EQ(cpu_system_mode_name(8), "mode 8");
}

TEST(TimelineCpu, SpansPerCpu) {
  const Timeline tl = build(make_capture());
  EXPECT_EQ(tl.last_ns, 10000 * kMs);
  expect_spans(tl, {
                       // CPU 0: the Role record at 0 ms before its first State record changes
                       // nothing; HOLD at 8000 ms lasts 0 ns and is dropped, and RUN master
                       // goes on in one span to the end of the capture.
                       {"H-CPU", 0, kStartup, kMaster, 0, 1000 * kMs},
                       {"H-CPU", 0, kRun, kMaster, 1000 * kMs, 10000 * kMs},
                       // CPU 1: STOP standby at 5000 ms is replaced by STOP none at the same
                       // instant; the role record at 6000 ms changes nothing.
                       {"H-CPU", 1, kStop, kNone, 0, 1000 * kMs},
                       {"H-CPU", 1, kLinkUp, kStandby, 1000 * kMs, 3000 * kMs},
                       {"H-CPU", 1, kUpdate, kStandby, 3000 * kMs, kUpdateEnd},
                       {"H-CPU", 1, kRun, kStandby, kUpdateEnd, 5000 * kMs},
                       {"H-CPU", 1, kStop, kNone, 5000 * kMs, 10000 * kMs},
                   });
  // OB 85 for both CPUs is a mark on each row; rack 2's OB 121 has no row.
  expect_obs(tl, {
                     {0, 5000 * kMs, 72, 0, 5, "H-CPU: CPU 0: OB 72 (redundant link lost)"},
                     {0, 7000 * kMs, 85, 0x39C4, 0, "H-CPU: CPU 0+1: OB 85 W#16#39C4 station 11"},
                     {1, 7000 * kMs, 85, 0x39C4, 0, "H-CPU: CPU 0+1: OB 85 W#16#39C4 station 11"},
                 });
  // The records stay events as well: 18 records, all decoded.
  EXPECT_EQ(tl.events.size(), 18u);
  EXPECT_EQ(tl.bad_event_records, 0u);
}

TEST(TimelineCpu, WindowKeepsTheSpansThatOverlapIt) {
  TimelineOptions o;
  o.from_ns = 2000 * kMs;
  o.to_ns = 5000 * kMs;
  const Timeline tl = build(make_capture(), o);
  // STARTUP and STOP end at 1000 ms, before the window; STOP none starts at its end (excluded).
  expect_spans(tl, {
                       {"H-CPU", 0, kRun, kMaster, 1000 * kMs, 10000 * kMs},
                       {"H-CPU", 1, kLinkUp, kStandby, 1000 * kMs, 3000 * kMs},
                       {"H-CPU", 1, kUpdate, kStandby, 3000 * kMs, kUpdateEnd},
                       {"H-CPU", 1, kRun, kStandby, kUpdateEnd, 5000 * kMs},
                   });
  EXPECT_TRUE(tl.cpu_obs.empty());  // OB 72 at 5000 ms is at the window's end: outside

  o.from_ns = 5000 * kMs;
  o.to_ns = 7000 * kMs;
  const Timeline t2 = build(make_capture(), o);
  expect_spans(t2, {
                       {"H-CPU", 0, kRun, kMaster, 1000 * kMs, 10000 * kMs},
                       {"H-CPU", 1, kStop, kNone, 5000 * kMs, 10000 * kMs},
                   });
  expect_obs(t2, {{0, 5000 * kMs, 72, 0, 5, "H-CPU: CPU 0: OB 72 (redundant link lost)"}});
}

TEST(TimelineCpu, TwoSystemsAndUnknownNumbers) {
  // Two pairs' rack 0 are two rows; a text without a system name gives system "". A state and
  // a role outside the enums keep their numbers; a Cpu record of an unknown kind is no mark.
  Writer c;
  c.ms(1, state(0, kMaster, kStop, kStartup, "H-A: CPU 0: STOP -> STARTUP"));
  c.ms(2, state(0, kStandby, kStop, kLinkUp, "H-B: CPU 0: STOP -> LINK-UP"));
  c.ms(3, state(1, 5, kStop, 12, "CPU 1: STOP -> ?"));
  EventRecord odd = ob(0, kMaster, 72, 0, 0, "H-A: CPU 0: kind 7");
  odd.code = 7;
  c.ms(4, odd);
  c.ms(5, ob(0, kMaster, 72, 0, 1, "H-B: CPU 0: OB 72 (master CPU lost)"));
  c.ms(6, role(0, kStandby, kMaster, "H-B: CPU 0: role standby -> master"));
  const Timeline tl = build(c.done());
  EXPECT_EQ(tl.last_ns, 6 * kMs);
  expect_spans(tl, {
                       {"", 1, 12, 5, 3 * kMs, 6 * kMs},
                       {"H-A", 0, kStartup, kMaster, 1 * kMs, 6 * kMs},
                       {"H-B", 0, kLinkUp, kStandby, 2 * kMs, 6 * kMs},
                       // the role record at the last instant: a span of no length, kept
                       {"H-B", 0, kLinkUp, kMaster, 6 * kMs, 6 * kMs},
                   });
  ASSERT_EQ(tl.cpu_obs.size(), 1u);
  EXPECT_EQ(tl.cpu_obs[0].system, "H-B");
  EXPECT_EQ(tl.cpu_obs[0].ts_ns, 5 * kMs);
  const std::string svg = to_svg(tl);
  EXPECT_NE(svg.find(">CPU 1 (rack 1)</text>"), std::string::npos);
  EXPECT_NE(svg.find(">H-A: CPU 0 (rack 0)</text>"), std::string::npos);
  EXPECT_NE(svg.find(">H-B: CPU 0 (rack 0)</text>"), std::string::npos);
  EXPECT_NE(svg.find("data-state=\"state 12\" data-role=\"role 5\""), std::string::npos);
  const std::string html = to_html(tl);
  EXPECT_NE(html.find("{\"label\":\"H-B: CPU 0 (rack 0)\",\"sys\":\"H-B\",\"r\":0,"
                      "\"s\":[[2000000,6000000,4,2],[6000000,6000000,4,1]],"
                      "\"ob\":[[5000000,72,0,1,\"H-B: CPU 0: OB 72 (master CPU lost)\"]]}"),
            std::string::npos);
}

TEST(TimelineCpu, NoStateRecordsNoRows) {
  Writer c;
  c.ms(1, ob(0, kMaster, 72, 0, 0, "H-CPU: CPU 0: OB 72"));
  c.ms(2, role(0, kNone, kMaster, "H-CPU: CPU 0: role none -> master"));
  const Timeline tl = build(c.done());
  EXPECT_TRUE(tl.cpu_states.empty());
  EXPECT_TRUE(tl.cpu_obs.empty());
  EXPECT_NE(to_html(tl).find(",\"rows\":[]},\"ac\":[]}"), std::string::npos);
  const std::string svg = to_svg(tl);
  EXPECT_EQ(svg.find("cpu-row"), std::string::npos);
  EXPECT_EQ(svg.find("CPU state"), std::string::npos);
}

std::size_t count(const std::string& s, const std::string& what) {
  std::size_t n = 0;
  for (auto p = s.find(what); p != std::string::npos; p = s.find(what, p + 1)) ++n;
  return n;
}

TEST(TimelineCpu, RowsInTheHtmlData) {
  const Timeline tl = build(make_capture());
  const std::string html = to_html(tl);
  // Page times are the capture's (it starts at 0): spans [start, end, state, role], OB marks
  // [time, ob, event id (0x39C4 = 14788), reason, text].
  EXPECT_NE(html.find(",\"cpu\":{\"states\":[\"OFF\",\"STOP\",\"STARTUP\",\"RUN\",\"LINK-UP\","
                      "\"UPDATE\",\"HOLD\",\"ERROR-SEARCH\",\"DEFECTIVE\",\"SYNCUP\"],"
                      "\"roles\":[\"none\",\"master\",\"standby\"],\"rows\":["
                      "{\"label\":\"CPU 0 (rack 0)\",\"sys\":\"H-CPU\",\"r\":0,"
                      "\"s\":[[0,1000000000,2,1],[1000000000,10000000000,3,1]],"
                      "\"ob\":[[5000000000,72,0,5,\"H-CPU: CPU 0: OB 72 (redundant link lost)\"],"
                      "[7000000000,85,14788,0,\"H-CPU: CPU 0+1: OB 85 W#16#39C4 station 11\"]]},"
                      "{\"label\":\"CPU 1 (rack 1)\",\"sys\":\"H-CPU\",\"r\":1,"
                      "\"s\":[[0,1000000000,1,0],[1000000000,3000000000,4,2],"
                      "[3000000000,3145250000,5,2],[3145250000,5000000000,3,2],"
                      "[5000000000,10000000000,1,0]],"
                      "\"ob\":[[7000000000,85,14788,0,\"H-CPU: CPU 0+1: OB 85 W#16#39C4 station 11\"]]}"
                      "]},\"ac\":[]}"),
            std::string::npos)
      << html.substr(html.find(",\"cpu\":"), 1200);
}

TEST(TimelineCpu, RowsInTheSvg) {
  const Timeline tl = build(make_capture());
  const std::string svg = to_svg(tl);
  EXPECT_EQ(count(svg, "<g class=\"cpu-row\""), 2u);
  EXPECT_NE(svg.find("<g class=\"cpu-row\" data-system=\"H-CPU\" data-rack=\"0\">"),
            std::string::npos);
  EXPECT_NE(svg.find("<g class=\"cpu-row\" data-system=\"H-CPU\" data-rack=\"1\">"),
            std::string::npos);
  // One system: the labels do not name it.
  EXPECT_NE(svg.find(">CPU 0 (rack 0)</text>"), std::string::npos);
  EXPECT_NE(svg.find(">CPU 1 (rack 1)</text>"), std::string::npos);
  EXPECT_EQ(count(svg, "class=\"cpu-span\""), 7u);
  EXPECT_EQ(count(svg, "<g class=\"cpu-ob\""), 3u);
  EXPECT_EQ(count(svg, "<g class=\"cpu-ob\" data-ob=\"85\">"), 2u);
  // The RUN master span of CPU 0 (1 s .. 10 s), green, with its tooltip; wide enough (9 s of
  // 10 s in 1372 px) for its label.
  EXPECT_NE(svg.find("data-state=\"RUN\" data-role=\"master\""), std::string::npos);
  EXPECT_NE(svg.find("fill=\"#2f9e44\"><title>CPU 0 (rack 0): RUN master&#10;from "
                     "1.000\u2009000\u2009000 s&#10;to 10.000\u2009000\u2009000 s (9.000000 s)"
                     "</title>"),
            std::string::npos);
  EXPECT_NE(svg.find(">RUN master</text>"), std::string::npos);
  // A standby's span is lighter.
  EXPECT_NE(svg.find("data-state=\"UPDATE\" data-role=\"standby\""), std::string::npos);
  EXPECT_NE(svg.find("fill=\"#1971c2\" fill-opacity=\"0.6\"><title>CPU 1 (rack 1): UPDATE standby"),
            std::string::npos);
  // OB 72's tick: its number and the record's text.
  EXPECT_NE(svg.find(">72</text><title>5.000\u2009000\u2009000 s OB 72&#10;H-CPU: CPU 0: OB 72 "
                     "(redundant link lost)</title></g>"),
            std::string::npos);
  EXPECT_NE(svg.find(">CPU state</text>"), std::string::npos);
}

}  // namespace
}  // namespace pbvbus::captures
