// `pbvbus timeline` on a real run of examples/multimaster.textproto (4 s, so the cable cut from
// 2 s to 3 s is in it): the HTML page holds the lane, the frames and the events as JSON that
// parses, its markup nests properly, and the SVG of the window around the cut is well-formed
// XML; bad input and usage exit 2 with one line on stderr and nothing on stdout. A run of
// examples/switched-io.textproto gives the active-channel rows of its switched stations.

#include <sys/wait.h>
#include <unistd.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "pbvbus/captures/pcapng_reader.hpp"
#include "pbvbus/tools/commands.hpp"

namespace pbvbus::tools {
namespace {

namespace fs = std::filesystem;

struct Result {
  int rc;
  std::string out;
  std::string err;
};

Result timeline(const Args& args) {
  std::ostringstream out, err;
  const int rc = cmd_timeline(args, out, err);
  return {rc, out.str(), err.str()};
}

std::string temp_path(const std::string& name) {
  return (fs::temp_directory_path() / ("cmd_timeline_" + std::to_string(::getpid()) + "_" + name))
      .string();
}

std::string read_file(const std::string& path) {
  std::ifstream f(path, std::ios::binary);
  std::stringstream ss;
  ss << f.rdbuf();
  return ss.str();
}

void write_file(const std::string& path, const std::string& data) {
  std::ofstream(path, std::ios::binary) << data;
}

/// Runs `python3 SCRIPT ARGS...` (the script written to a temp file); exit status and stdout.
std::pair<int, std::string> python(const std::string& script, const std::string& args) {
  const std::string py = temp_path("check.py");
  write_file(py, script);
  const std::string exe = fs::exists("/usr/bin/python3") ? "/usr/bin/python3" : "python3";
  std::string out;
  FILE* p = ::popen((exe + " " + py + " " + args + " 2>&1").c_str(), "r");
  if (p == nullptr) return {-1, ""};
  char buf[4096];
  std::size_t n;
  while ((n = std::fread(buf, 1, sizeof buf, p)) > 0) out.append(buf, n);
  const int st = ::pclose(p);
  fs::remove(py);
  return {WIFEXITED(st) ? WEXITSTATUS(st) : -1, out};
}

class CmdTimeline : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    s_capture = temp_path("multimaster.pcapng");
    std::ostringstream out, err;
    const int rc = cmd_run({PBVBUS_SOURCE_DIR "/examples/multimaster.textproto", "--capture",
                            s_capture, "--duration", "4s", "--quiet"},
                           out, err);
    ASSERT_EQ(rc, 0) << err.str();
    captures::PcapngError perr;
    const auto cap = captures::read_pcapng_file(s_capture, perr);
    ASSERT_TRUE(cap) << perr.to_string();
    for (const auto& r : cap->records) {
      if (cap->interfaces[r.interface].name == "A")
        ++s_frames;
      else
        ++s_events;
    }
  }
  static void TearDownTestSuite() { fs::remove(s_capture); }
  void TearDown() override {
    for (const auto& p : m_files) fs::remove(p);
  }
  std::string out_file(const std::string& name) {
    m_files.push_back(temp_path(name));
    return m_files.back();
  }

  static inline std::string s_capture;
  static inline std::size_t s_frames = 0;
  static inline std::size_t s_events = 0;
  std::vector<std::string> m_files;
};

// Extracts the JSON data block of the page and checks it against the capture; checks that the
// markup nests (every non-void element closed in order).
constexpr const char* kCheckHtml = R"PY(
import json, sys
from html.parser import HTMLParser
page = open(sys.argv[1], encoding='utf-8').read()
start = page.index('<script type="application/json" id="pbvbus-data">')
start = page.index('>', start) + 1
data = json.loads(page[start:page.index('</script>', start)])
lane = data['lanes'][0]
assert len(data['lanes']) == 1 and lane['name'] == 'A' and lane['speed'] == 1500000, lane['name']
assert len(lane['t']) == len(lane['e']) == int(sys.argv[2]), (len(lane['t']), sys.argv[2])
assert all(d >= 0 for d in lane['t'][1:]), 'frames not in start order'
assert max(lane['e']) < len(data['ent'])
kinds = {data['ent'][e][1] for e in lane['e']}
assert kinds == {0, 1, 2, 3, 4}, kinds
assert all(e[2] < len(data['desc']) and e[3] < len(data['desc']) for e in data['ent'])
assert [s['a'] for s in lane['dx']] == [10, 11, 12, 13, 14], [s['a'] for s in lane['dx']]
assert sorted(set(lane['th'])) == [1, 2, 3]
assert len(lane['tk']) == len(lane['tl']) == len(lane['th']) == len(lane['tp'])
texts = [e[3] for e in data['ev']]
assert len(texts) == int(sys.argv[3]), texts
assert any('cable cut' in t for t in texts) and any('cable repaired' in t for t in texts), texts
styles = {e[1] for e in data['ev']}
assert styles == {'fault', 'repair'}, styles
assert data['view'] == [int(sys.argv[4]), int(sys.argv[5])], data['view']
VOID = {'meta', 'br', 'img', 'input', 'link', 'hr'}
class Nest(HTMLParser):
    def __init__(self):
        super().__init__(); self.stack = []; self.count = 0
    def handle_starttag(self, tag, attrs):
        self.count += 1
        if tag not in VOID: self.stack.append(tag)
    def handle_endtag(self, tag):
        assert self.stack and self.stack[-1] == tag, (tag, self.stack[-3:])
        self.stack.pop()
n = Nest(); n.feed(page); n.close()
assert n.stack == [], n.stack
print('ok', len(lane['t']), len(data['ent']), len(data['desc']))
)PY";

constexpr const char* kCheckSvg = R"PY(
import sys, xml.dom.minidom
doc = xml.dom.minidom.parse(sys.argv[1])
root = doc.documentElement
assert root.tagName == 'svg' and root.getAttribute('xmlns') == 'http://www.w3.org/2000/svg'
lanes = [g for g in doc.getElementsByTagName('g') if g.getAttribute('class') == 'lane']
assert [g.getAttribute('data-lane') for g in lanes] == ['A']
text = ' '.join(t.firstChild.data for t in doc.getElementsByTagName('text') if t.firstChild)
assert 'cable cut' in text and 'DX slave 13' in text and 'token holder' in text, text[:300]
print('ok', len(doc.getElementsByTagName('rect')))
)PY";

TEST_F(CmdTimeline, HtmlOfTheMultimasterRun) {
  ASSERT_GT(s_frames, 20000u);
  EXPECT_EQ(s_events, 10u);  // 8 power-ons, the cut and the repair
  const std::string html = out_file("mm.html");
  const Result r = timeline({s_capture, "-o", html, "--from", "1990ms", "--to", "2.03s"});
  ASSERT_EQ(r.rc, 0) << r.err;
  EXPECT_EQ(r.out, "");
  EXPECT_EQ(r.err, "");
  const std::string page = read_file(html);
  EXPECT_EQ(page.rfind("<!DOCTYPE html>\n", 0), 0u);
  EXPECT_NE(page.find("<title>pbvbus timeline \u2014 "), std::string::npos);
  EXPECT_NE(page.find("<script type=\"application/json\" id=\"pbvbus-data\">{\"v\":1,"),
            std::string::npos);
  EXPECT_NE(page.find("<script>\n(function () {"), std::string::npos);
  EXPECT_NE(page.find("\"name\":\"A\""), std::string::npos);
  EXPECT_NE(page.find("cable cut between 'slave 14' and 'master 3'"), std::string::npos);
  EXPECT_EQ(page.find("http://"), page.find("http://www.w3.org/2000/svg"));  // no network
  EXPECT_EQ(page.find("https://"), std::string::npos);
  EXPECT_LT(page.size(), 2'000'000u) << "a 4 s capture should stay well below 2 MB";
  RecordProperty("html_bytes", std::to_string(page.size()));
  const auto [rc, out] = python(kCheckHtml, html + " " + std::to_string(s_frames) + " " +
                                                std::to_string(s_events) + " 1990000000 2030000000");
  EXPECT_EQ(rc, 0) << out;
  EXPECT_EQ(out.rfind("ok ", 0), 0u) << out;

  // Without -o the same page goes to stdout.
  const Result so = timeline({s_capture});
  ASSERT_EQ(so.rc, 0) << so.err;
  EXPECT_EQ(so.out.rfind("<!DOCTYPE html>", 0), 0u);
  EXPECT_NE(so.out.find("\"view\":[0,"), std::string::npos);
}

TEST_F(CmdTimeline, SvgOfTheCut) {
  const std::string svg = out_file("cut.svg");
  const Result r = timeline({s_capture, "-o", svg, "--from", "1995ms", "--to", "2010ms"});
  ASSERT_EQ(r.rc, 0) << r.err;
  const std::string doc = read_file(svg);
  EXPECT_EQ(doc.rfind("<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n<svg ", 0), 0u);
  EXPECT_EQ(doc.substr(doc.size() - 7), "</svg>\n");
  EXPECT_NE(doc.find("1.995\u2009000 s \u2013 2.010\u2009000 s"), std::string::npos);
  const auto [rc, out] = python(kCheckSvg, svg);
  EXPECT_EQ(rc, 0) << out;
  EXPECT_EQ(out.rfind("ok ", 0), 0u) << out;

  // The whole capture aggregated per pixel is a picture of bounded size.
  const std::string all = out_file("all.svg");
  ASSERT_EQ(timeline({s_capture, "-o", all}).rc, 0);
  EXPECT_LT(fs::file_size(all), 1'000'000u);
  const auto [rc2, out2] = python(kCheckSvg, all);
  EXPECT_EQ(rc2, 0) << out2;
}

// The active channel of the switched stations (docs/redundancy.md) in the page of a real run of
// examples/switched-io.textproto (10 s). Every row starts with the station's start-up record
// (DP_A, within the first few ms: the first Set_Prm carries Primary_Request); then 3 goes to
// DP_B at F10 (1 s), 4 at F11 (2 s, no channel 2.3 s .. 2.6 s), 6 at F13 (3.5 s), 5 at F9
// (6.5 s); the short circuit on DP_B (5 s) and the master stop on DP_B (8.5 s) bring everyone
// back to DP_A.
constexpr const char* kCheckActive = R"PY(
import json, sys
page = open(sys.argv[1], encoding='utf-8').read()
start = page.index('<script type="application/json" id="pbvbus-data">')
start = page.index('>', start) + 1
data = json.loads(page[start:page.index('</script>', start)])
names = [L['name'] for L in data['lanes']]
assert names == ['DP_A', 'DP_B'], names
rows = data['ac']
assert [r['a'] for r in rows] == [3, 4, 5, 6], [r['a'] for r in rows]
end = data['span'][1] - 1
def at(s, t):  # lane of the span at time t (s)
    for a, b, lane, line in s:
        if a <= t * 1e9 < b: return lane
    return 'no span'
for r in rows:
    s = r['s']
    assert all(a[1] == b[0] for a, b in zip(s, s[1:])), (r['a'], s)  # no gaps
    assert all(a[2] != b[2] for a, b in zip(s, s[1:])), (r['a'], s)  # merged
    assert all(sp[2] == sp[3] for sp in s), (r['a'], s)              # lane i is line i here
    assert s[-1][1] == end and s[-1][2] == 0, (r['a'], s[-1], end)   # DP_A after 8.5 s
    assert at(s, 7.0) == 1, (r['a'], s)                               # F9: DP_A's master fails
by = {r['a']: r['s'] for r in rows}
for a in (3, 4, 5, 6):  # start-up: DP_A from the first ms
    assert by[a][0][0] < 0.05e9 and by[a][0][2] == 0, (a, by[a][0])
assert 1.0e9 <= by[3][1][0] < 1.1e9 and by[3][1][2] == 1, by[3]
assert 2.0e9 <= by[4][1][0] < 2.1e9 and by[4][1][2] == 1, by[4]
assert at(by[4], 2.2) == 1 and at(by[4], 2.5) == -1 and at(by[4], 2.7) == 1, by[4]
assert 3.5e9 <= by[6][1][0] < 3.6e9 and by[6][1][2] == 1, by[6]
assert 6.5e9 <= by[5][1][0] < 6.6e9 and len(by[5]) == 3, by[5]
for a in (3, 4, 6):
    # F14: the short circuit on DP_B at 5 s
    assert at(by[a], 4.9) == 1 and at(by[a], 5.2) == 0 and at(by[a], 6.0) == 0, (a, by[a])
print('ok', len(rows))
)PY";

TEST_F(CmdTimeline, ActiveChannelsOfTheSwitchedIoRun) {
  const std::string capture = out_file("switched.pcapng");
  std::ostringstream out, err;
  ASSERT_EQ(cmd_run({PBVBUS_SOURCE_DIR "/examples/switched-io.textproto", "--capture", capture,
                     "--quiet"},
                    out, err),
            0)
      << err.str();
  const std::string html = out_file("switched.html");
  const Result r = timeline({capture, "-o", html});
  ASSERT_EQ(r.rc, 0) << r.err;
  const std::string page = read_file(html);
  EXPECT_NE(page.find(",\"ac\":[{\"a\":3,\"s\":[["), std::string::npos);
  const auto [rc, py] = python(kCheckActive, html);
  EXPECT_EQ(rc, 0) << py;
  EXPECT_EQ(py, "ok 4\n");

  // The static picture has the four rows too.
  const std::string svg = out_file("switched.svg");
  ASSERT_EQ(timeline({capture, "-o", svg}).rc, 0);
  const std::string doc = read_file(svg);
  for (const char* st : {"3", "4", "5", "6"}) {
    EXPECT_NE(doc.find(std::string("<g class=\"active-channel\" data-station=\"") + st + "\">"),
              std::string::npos)
        << st;
    EXPECT_NE(doc.find(std::string(">station ") + st + " active</text>"), std::string::npos) << st;
  }
}

TEST_F(CmdTimeline, BadInputExits2) {
  auto expect_error = [&](const Args& args, const std::string& err_start) {
    SCOPED_TRACE(err_start);
    const Result r = timeline(args);
    EXPECT_EQ(r.rc, 2);
    EXPECT_EQ(r.out, "");
    EXPECT_EQ(r.err.rfind(err_start, 0), 0u) << r.err;
    EXPECT_EQ(r.err.back(), '\n');
  };
  const std::string garbage = out_file("garbage.pcapng");
  write_file(garbage, "this is not a capture\n");
  expect_error({garbage}, "pbvbus timeline: " + garbage + ": offset 0: ");
  const std::string empty = out_file("empty.pcapng");
  write_file(empty, "");
  expect_error({empty}, "pbvbus timeline: " + empty + ": offset 0: empty file, not a pcapng capture");
  const std::string cut = out_file("cut.pcapng");
  std::string data = read_file(s_capture);
  write_file(cut, data.substr(0, data.size() / 2 + 3));
  expect_error({cut}, "pbvbus timeline: " + cut + ": offset ");
  expect_error({s_capture + ".missing"}, "pbvbus timeline: " + s_capture + ".missing: offset 0: cannot open");
  expect_error({s_capture, "--from", "3s", "--to", "2s"},
               "pbvbus timeline: --from 3.000000000 s is not before --to 2.000000000 s");
  expect_error({s_capture, "--from", "10s"},
               "pbvbus timeline: " + s_capture + ": the window start 10.000000000 s is not before");
  expect_error({s_capture, "-o", out_file("late.svg"), "--from", "10s"},
               "pbvbus timeline: " + s_capture + ": the window start 10.000000000 s is not before");
  expect_error({s_capture, "--from", "2 seconds"}, "pbvbus timeline: bad time '2 seconds' for --from");
  expect_error({s_capture, "--to", "-1s"}, "pbvbus timeline: bad time '-1s' for --to");
  expect_error({s_capture, "--from"}, "pbvbus timeline: --from needs a time");
  expect_error({s_capture, "-o", "x.png"}, "pbvbus timeline: cannot tell the output type of 'x.png'");
  expect_error({s_capture, "-o"}, "pbvbus timeline: -o needs a file name");
  expect_error({s_capture, "--json"}, "pbvbus timeline: unknown option '--json'");
  expect_error({}, "pbvbus timeline: no capture file given");
  expect_error({s_capture, s_capture}, "pbvbus timeline: more than one capture given");
  expect_error({s_capture, "-o", "/nonexistent/dir/x.html"}, "pbvbus timeline: cannot write /nonexistent/dir/x.html");
  // No output file is left behind by a failed run.
  for (const auto& p : m_files) {
    if (p.find("late.svg") != std::string::npos) {
      EXPECT_FALSE(fs::exists(p)) << p;
    }
  }
}

TEST_F(CmdTimeline, Help) {
  const Result r = timeline({"--help"});
  EXPECT_EQ(r.rc, 0);
  EXPECT_EQ(r.out.rfind("usage: pbvbus timeline CAPTURE [-o FILE.html|FILE.svg] [--from T] [--to T] [--max-frames N]\n", 0), 0u);
}

}  // namespace
}  // namespace pbvbus::tools
