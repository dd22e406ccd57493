// The `pbvbus timeline` page of a multimaster run (4 s, cable cut 2..3 s) in a real browser:
// headless Chromium takes a screenshot (a 1400x900 PNG with many colours, decoded with Python's
// zlib) and dumps the DOM after the page script ran (body data-rendered="1", the lane group, the
// DP cycle table, the fault marker); opened at a window of 150 µs through the URL fragment, the
// page shows a bit-time axis, which it does not at the wide first view. The page of a
// switched-io run (10 s) draws one active-channel row per switched station (docs/redundancy.md), and the
// page of the built-in default scenario (an H system) one row per CPU (docs/h-system.md), and the
// page of a Quantum Hot Standby run one row per rack (docs/quantum-hsby.md).
//
// Skipped, with the reason, when no Chromium is installed (Debian: apt-get install chromium);
// PBVBUS_CHROMIUM may name the browser binary.

#include <sys/wait.h>
#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <regex>
#include <sstream>
#include <string>

#include <gtest/gtest.h>

#include "pbvbus/tools/commands.hpp"

namespace pbvbus::tools {
namespace {

namespace fs = std::filesystem;

std::string find_chromium() {
  if (const char* env = std::getenv("PBVBUS_CHROMIUM"); env && *env) return env;
  const char* path = std::getenv("PATH");
  std::stringstream dirs(path ? path : "/usr/bin:/bin");
  std::string dir;
  while (std::getline(dirs, dir, ':')) {
    for (const char* name : {"chromium", "chromium-browser", "google-chrome"}) {
      const fs::path p = fs::path(dir) / name;
      std::error_code ec;
      if (fs::is_regular_file(p, ec) && ::access(p.c_str(), X_OK) == 0) return p.string();
    }
  }
  return "";
}

/// The drawing in a dumped DOM (the dump also holds the page script, whose templates contain
/// the same markup).
std::string svg_of(const std::string& dom) {
  const auto a = dom.find("<svg id=\"svg\"");
  if (a == std::string::npos) return "";
  const auto b = dom.find("</svg>", a);
  return dom.substr(a, b == std::string::npos ? std::string::npos : b - a);
}

/// Runs a shell command; exit status and stdout.
std::pair<int, std::string> shell(const std::string& cmd) {
  std::string out;
  FILE* p = ::popen(cmd.c_str(), "r");
  if (p == nullptr) return {-1, ""};
  char buf[8192];
  std::size_t n;
  while ((n = std::fread(buf, 1, sizeof buf, p)) > 0) out.append(buf, n);
  const int st = ::pclose(p);
  return {WIFEXITED(st) ? WEXITSTATUS(st) : -1, out};
}

std::string quote(const std::string& s) {
  std::string o = "'";
  for (char c : s) o += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return o + "'";
}

// Width, height and number of distinct RGB colours of an 8-bit RGB/RGBA PNG, standard library
// only.
constexpr const char* kPngColours = R"PY(
import sys, zlib, struct
data = open(sys.argv[1], 'rb').read()
assert data[:8] == b'\x89PNG\r\n\x1a\n', 'not a PNG'
pos = 8; idat = b''; w = h = bpp = 0
while pos < len(data):
    n, typ = struct.unpack('>I4s', data[pos:pos + 8]); body = data[pos + 8:pos + 8 + n]; pos += 12 + n
    if typ == b'IHDR':
        w, h, depth, ctype, _, _, interlace = struct.unpack('>IIBBBBB', body)
        assert depth == 8 and ctype in (2, 6) and interlace == 0, (depth, ctype, interlace)
        bpp = 3 if ctype == 2 else 4
    elif typ == b'IDAT':
        idat += body
raw = zlib.decompress(idat)
stride = w * bpp; prev = bytearray(stride); seen = set(); off = 0
for y in range(h):
    f = raw[off]; line = bytearray(raw[off + 1:off + 1 + stride]); off += 1 + stride
    if f == 1:
        for i in range(bpp, stride): line[i] = (line[i] + line[i - bpp]) & 255
    elif f == 2:
        line = bytearray((a + b) & 255 for a, b in zip(line, prev))
    elif f == 3:
        for i in range(stride):
            left = line[i - bpp] if i >= bpp else 0
            line[i] = (line[i] + ((left + prev[i]) >> 1)) & 255
    elif f == 4:
        for i in range(stride):
            a = line[i - bpp] if i >= bpp else 0; b = prev[i]; c = prev[i - bpp] if i >= bpp else 0
            p = a + b - c; pa = abs(p - a); pb = abs(p - b); pc = abs(p - c)
            line[i] = (line[i] + (a if pa <= pb and pa <= pc else (b if pb <= pc else c))) & 255
    seen.update(bytes(line[i:i + 3]) for i in range(0, stride, bpp))
    prev = line
print(w, h, len(seen))
)PY";

constexpr const char* kNoChromium =
    "chromium is not installed (Debian: apt-get install chromium; or set PBVBUS_CHROMIUM): the "
    "timeline page is not checked in a browser";

class TimelineBrowser : public ::testing::Test {
 protected:
  void SetUp() override {
    if (!start()) GTEST_SKIP() << kNoChromium;
    const std::string capture = (m_dir / "mm.pcapng").string();
    std::ostringstream out, err;
    ASSERT_EQ(cmd_run({PBVBUS_SOURCE_DIR "/examples/multimaster.textproto", "--capture", capture,
                       "--duration", "4s", "--quiet"},
                      out, err),
              0)
        << err.str();
    m_html = (m_dir / "mm.html").string();
    ASSERT_EQ(cmd_timeline({capture, "-o", m_html, "--from", "1990ms", "--to", "2030ms"}, out, err), 0)
        << err.str();
  }
  /// Finds chromium (false without) and makes the temp directory.
  bool start() {
    m_chromium = find_chromium();
    if (m_chromium.empty()) return false;
    m_dir = fs::temp_directory_path() / ("timeline_browser_" + std::to_string(::getpid()));
    fs::create_directories(m_dir);
    return true;
  }
  void TearDown() override {
    std::error_code ec;
    if (!m_dir.empty()) fs::remove_all(m_dir, ec);
  }

  /// Chromium headless with a private profile; `what` is --screenshot=FILE or --dump-dom.
  std::pair<int, std::string> chromium(const std::string& what, const std::string& url) {
    const std::string cmd = "timeout 120 " + quote(m_chromium) +
                            " --headless --disable-gpu --no-sandbox --hide-scrollbars"
                            " --user-data-dir=" + quote((m_dir / "profile").string()) +
                            " --window-size=1400,900 " + what + " " + quote(url) + " 2>/dev/null";
    return shell(cmd);
  }

  std::string m_chromium;
  fs::path m_dir;
  std::string m_html;
};

TEST_F(TimelineBrowser, ScreenshotIsAPicture) {
  const std::string png = (m_dir / "shot.png").string();
  chromium("--screenshot=" + quote(png), "file://" + m_html);
  ASSERT_TRUE(fs::exists(png)) << "chromium wrote no screenshot";
  EXPECT_GT(fs::file_size(png), 20'000u);
  const std::string py = (m_dir / "png.py").string();
  std::ofstream(py) << kPngColours;
  const std::string python = fs::exists("/usr/bin/python3") ? "/usr/bin/python3" : "python3";
  const auto [rc, out] = shell(python + " " + quote(py) + " " + quote(png) + " 2>&1");
  ASSERT_EQ(rc, 0) << out;
  int w = 0, h = 0, colours = 0;
  std::istringstream(out) >> w >> h >> colours;
  EXPECT_EQ(w, 1400);
  EXPECT_EQ(h, 900);
  // A blank or unstyled page has a handful of colours; lanes, legend and anti-aliased text
  // give hundreds.
  EXPECT_GT(colours, 200) << out;
  // The README's picture is this screenshot: PBVBUS_UPDATE_DOCS=1 writes it there.
  if (const char* u = std::getenv("PBVBUS_UPDATE_DOCS"); u && std::string(u) == "1")
    fs::copy_file(png, PBVBUS_SOURCE_DIR "/docs/img/timeline-multimaster.png",
                  fs::copy_options::overwrite_existing);
}

TEST_F(TimelineBrowser, ScriptDrawsTheLanes) {
  const auto [rc, dom] = chromium("--dump-dom", "file://" + m_html);
  ASSERT_EQ(rc, 0);
  ASSERT_NE(dom.find("<body"), std::string::npos) << dom.substr(0, 500);
  EXPECT_NE(dom.find("data-rendered=\"1\""), std::string::npos) << "the page script did not run";
  EXPECT_NE(dom.find("data-lanes=\"1\""), std::string::npos);
  EXPECT_NE(dom.find("<g class=\"lane\" data-lane=\"A\""), std::string::npos);
  std::smatch m;
  ASSERT_TRUE(std::regex_search(dom, m, std::regex("data-frames-drawn=\"(\\d+)\"")));
  EXPECT_GT(std::stoi(m[1].str()), 100);  // 40 ms of a busy 1.5 Mbit/s line
  for (const char* slave : {"10", "11", "12", "13", "14"})
    EXPECT_NE(dom.find(std::string("<tr data-slave=\"") + slave + "\">"), std::string::npos) << slave;
  EXPECT_NE(svg_of(dom).find("cable cut between 'slave 14' and 'master 3'</text>"), std::string::npos);
  EXPECT_NE(dom.find("view 1.990\u2009000 s \u2013 2.030\u2009000 s"), std::string::npos);
  // The wide view has no bit-time axis yet, only the hint.
  const std::string svg = svg_of(dom);
  EXPECT_NE(svg.find("<g class=\"lane\" data-lane=\"A\""), std::string::npos);
  EXPECT_NE(svg.find("class=\"bit-axis-hint\""), std::string::npos);
  EXPECT_EQ(svg.find("class=\"bit-tick\""), std::string::npos);
}

TEST_F(TimelineBrowser, BitTimeAxisAtHighZoom) {
  // 150 µs = 225 bit times at 1.5 Mbit/s, just after the cut.
  const auto [rc, dom] = chromium("--dump-dom", "file://" + m_html + "#v=2000900000,2001050000");
  ASSERT_EQ(rc, 0);
  EXPECT_NE(dom.find("data-rendered=\"1\""), std::string::npos);
  const std::string svg = svg_of(dom);
  ASSERT_NE(svg, "");
  EXPECT_EQ(svg.find("class=\"bit-axis-hint\""), std::string::npos);
  std::size_t ticks = 0;
  for (auto p = svg.find("class=\"bit-tick\""); p != std::string::npos;
       p = svg.find("class=\"bit-tick\"", p + 1))
    ++ticks;
  EXPECT_GE(ticks, 5u);
  // Frames this wide carry their labels: the token passes 2 -> 3 that master 3 no longer takes.
  EXPECT_NE(svg.find("tok 2\u21923</text>"), std::string::npos);
}

/// The page of a run of examples/switched-io.textproto (10 s).
class TimelineBrowserSwitched : public TimelineBrowser {
 protected:
  void SetUp() override {
    if (!start()) GTEST_SKIP() << kNoChromium;
    const std::string capture = (m_dir / "sw.pcapng").string();
    std::ostringstream out, err;
    ASSERT_EQ(cmd_run({PBVBUS_SOURCE_DIR "/examples/switched-io.textproto", "--capture", capture,
                       "--quiet"},
                      out, err),
              0)
        << err.str();
    m_html = (m_dir / "sw.html").string();
    ASSERT_EQ(cmd_timeline({capture, "-o", m_html}, out, err), 0) << err.str();
  }
};

std::size_t count(const std::string& s, const std::string& what) {
  std::size_t n = 0;
  for (auto p = s.find(what); p != std::string::npos; p = s.find(what, p + 1)) ++n;
  return n;
}

TEST_F(TimelineBrowserSwitched, ScriptDrawsTheActiveChannelRows) {
  const auto [rc, dom] = chromium("--dump-dom", "file://" + m_html);
  ASSERT_EQ(rc, 0);
  EXPECT_NE(dom.find("data-rendered=\"1\""), std::string::npos) << "the page script did not run";
  EXPECT_NE(dom.find("data-active-rows=\"4\""), std::string::npos);
  const std::string svg = svg_of(dom);
  ASSERT_NE(svg, "");
  EXPECT_EQ(count(svg, "<g class=\"active-channel\" data-station="), 4u);
  for (const char* st : {"3", "4", "5", "6"}) {
    EXPECT_NE(svg.find(std::string("<g class=\"active-channel\" data-station=\"") + st + "\">"),
              std::string::npos)
        << st;
    EXPECT_NE(svg.find(std::string(">station ") + st + " active</text>"), std::string::npos) << st;
  }
  // Spans on both lines, in their lanes' colours, and station 4's time without a channel
  // (2.3 s .. 2.6 s) hatched; the first view is the whole run, so every span is drawn.
  const std::size_t a = count(svg, "class=\"ac-span\" data-line=\"0\" data-lane=\"DP_A\" ");
  const std::size_t b = count(svg, "class=\"ac-span\" data-line=\"1\" data-lane=\"DP_B\" ");
  const std::size_t none = count(svg, "class=\"ac-span\" data-line=\"-1\" data-lane=\"\" ");
  EXPECT_GE(a, 4u);
  EXPECT_GE(b, 4u);
  EXPECT_GE(none, 1u);
  EXPECT_EQ(count(svg, "class=\"ac-span\""), a + b + none);
  EXPECT_EQ(count(svg, "fill=\"url(#achatch)\""), none);
  EXPECT_EQ(count(svg, "fill=\"#1c7ed6\"><title>STATION "), a);  // DP_A's colour
  // The legend names the lanes' colours.
  EXPECT_NE(dom.find("<b>active channel</b>"), std::string::npos);
}

/// The page of a run of the built-in default scenario (examples/h-system.textproto, 18 s).
class TimelineBrowserH : public TimelineBrowser {
 protected:
  void SetUp() override {
    if (!start()) GTEST_SKIP() << kNoChromium;
    const std::string capture = (m_dir / "h.pcapng").string();
    std::ostringstream out, err;
    ASSERT_EQ(cmd_run({"--fast", "--capture", capture, "--quiet"}, out, err), 0) << err.str();
    m_html = (m_dir / "h.html").string();
    ASSERT_EQ(cmd_timeline({capture, "-o", m_html}, out, err), 0) << err.str();
  }
};

TEST_F(TimelineBrowserH, ScriptDrawsTheCpuRows) {
  const auto [rc, dom] = chromium("--dump-dom", "file://" + m_html);
  ASSERT_EQ(rc, 0);
  EXPECT_NE(dom.find("data-rendered=\"1\""), std::string::npos) << "the page script did not run";
  EXPECT_NE(dom.find("data-cpu-rows=\"2\""), std::string::npos);
  const std::string svg = svg_of(dom);
  ASSERT_NE(svg, "");
  EXPECT_EQ(count(svg, "<g class=\"cpu-row\" data-system="), 2u);
  for (const char* rack : {"0", "1"}) {
    EXPECT_NE(svg.find(std::string("<g class=\"cpu-row\" data-system=\"H-CPU\" data-rack=\"") + rack +
                       "\">"),
              std::string::npos)
        << rack;
    EXPECT_NE(svg.find(std::string(">CPU ") + rack + " (rack " + rack + ")</text>"), std::string::npos)
        << rack;
  }
  // The first view is the whole run: every span and OB mark is drawn, and the page counts them.
  std::smatch m;
  ASSERT_TRUE(std::regex_search(dom, m, std::regex("data-cpu-spans-drawn=\"(\\d+)\"")));
  const std::size_t spans = std::stoul(m[1].str());
  EXPECT_GE(spans, 10u);  // each CPU: at least STARTUP/STOP, LINK-UP, UPDATE, RUN
  EXPECT_EQ(count(svg, "class=\"cpu-span\""), spans);
  // Both CPUs are RUN master at some time (CPU 0 until 12 s, CPU 1 after F1).
  EXPECT_GE(count(svg, "class=\"cpu-span\" data-state=\"RUN\" data-role=\"master\""), 2u);
  ASSERT_TRUE(std::regex_search(dom, m, std::regex("data-cpu-obs-drawn=\"(\\d+)\"")));
  EXPECT_EQ(count(svg, "<g class=\"cpu-ob\""), std::stoul(m[1].str()));
  // OB 72 at F5 (CPU 0) and F1 (CPU 1).
  EXPECT_EQ(count(svg, "<g class=\"cpu-ob\" data-ob=\"72\">"), 2u);
  EXPECT_NE(dom.find("<b>CPU state</b>"), std::string::npos);
}

/// The page of a Quantum Hot Standby pair (rack 0 loses power at 2 s; rack 1 takes over).
class TimelineBrowserQ : public TimelineBrowser {
 protected:
  void SetUp() override {
    if (!start()) GTEST_SKIP() << kNoChromium;
    const std::string scenario = (m_dir / "q.textproto").string();
    std::ofstream(scenario)
        << "name: \"q\"\nseed: 1\nduration: \"4s\"\nline { name: \"rio\" baud: \"1.5M\" }\n"
           "dp_master { address: 1 line: \"rio\" watchdog: \"300ms\" }\n"
           "dp_slave { address: 3 line: \"rio\" gsd: \"" PBVBUS_SOURCE_DIR "/examples/gsd/PBVB0A01.gsd\" master: 1 }\n"
           "quantum_hot_standby { name: \"Quantum\" cpu: CPU_434_12 logic_time: \"20ms\"\n"
           "  rack { designation: A power_on_at: \"0s\" } rack { designation: B power_on_at: \"100ms\" }\n"
           "  dp { line: \"rio\" address: 1 map { slave: 3 inputs: \"300001\" outputs: \"400100\" } } }\n"
           "fault { at: \"2s\" repair_at: \"3s\" quantum_power_loss { rack: 0 } }\n";
    const std::string capture = (m_dir / "q.pcapng").string();
    std::ostringstream out, err;
    ASSERT_EQ(cmd_run({scenario, "--fast", "--capture", capture, "--quiet"}, out, err), 0) << err.str();
    m_html = (m_dir / "q.html").string();
    ASSERT_EQ(cmd_timeline({capture, "-o", m_html}, out, err), 0) << err.str();
  }
};

TEST_F(TimelineBrowserQ, ScriptDrawsTheQuantumRows) {
  const auto [rc, dom] = chromium("--dump-dom", "file://" + m_html);
  ASSERT_EQ(rc, 0);
  EXPECT_NE(dom.find("data-rendered=\"1\""), std::string::npos) << "the page script did not run";
  EXPECT_NE(dom.find("data-hsby-rows=\"2\""), std::string::npos);
  const std::string svg = svg_of(dom);
  ASSERT_NE(svg, "");
  for (const char* rack : {"0", "1"}) {
    EXPECT_NE(svg.find(std::string("<g class=\"hsby-row\" data-pair=\"Quantum\" data-rack=\"") + rack + "\">"),
              std::string::npos)
        << rack;
    EXPECT_NE(svg.find(std::string(">Quantum rack ") + rack + "</text>"), std::string::npos) << rack;
  }
  // The first view is the whole run: every span and the switchover are drawn and counted.
  std::smatch m;
  ASSERT_TRUE(std::regex_search(dom, m, std::regex("data-hsby-spans-drawn=\"(\\d+)\"")));
  const std::size_t spans = std::stoul(m[1].str());
  EXPECT_GE(spans, 4u);  // rack 0: primary, off, ...; rack 1: standby, primary
  EXPECT_EQ(count(svg, "class=\"hsby-span\""), spans);
  EXPECT_GE(count(svg, "class=\"hsby-span\" data-state=\"primary\""), 2u);  // both racks, in turn
  EXPECT_NE(dom.find("data-hsby-switchovers-drawn=\"1\""), std::string::npos);
  EXPECT_EQ(count(svg, "<g class=\"hsby-switchover\" data-takeover-ns=\"40000000\">"), 1u);
  EXPECT_NE(dom.find("<b>Quantum rack</b>"), std::string::npos);
}

}  // namespace
}  // namespace pbvbus::tools
