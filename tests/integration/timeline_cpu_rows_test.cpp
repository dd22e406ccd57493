// The CPU rows in `pbvbus timeline` of the built-in default scenario's capture (docs/h-system.md, "a
// timeline of states, roles and events per CPU"; examples/h-system.textproto): the real binary
// runs `pbvbus run --capture X --quiet`, then `pbvbus timeline X -o X.svg` and `-o X.html`, as a
// user would. Both CPUs get a row with their spans and OB ticks; the times are the scenario's
// (its header comment; tests/simulation/h_system_run_test.cpp derives them): startup 1 s, link-up
// 2 s, update W = 145 ms, F5 at 5 s, F1 at 12 s, CPU 0 back at 14 s, run end 18 s.
#include <sys/wait.h>
#include <unistd.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include <gtest/gtest.h>

#include "pbvbus/captures/timeline.hpp"

namespace {

namespace fs = std::filesystem;

const std::string kBinary = PBVBUS_BINARY_DIR "/bin/pbvbus";

std::string quote(const std::string& s) {
  std::string o = "'";
  for (char c : s) o += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return o + "'";
}

/// Exit status of a shell command (-1 if it did not exit normally); its output goes to `out`.
int shell(const std::string& cmd, std::string& out) {
  FILE* p = ::popen((cmd + " 2>&1").c_str(), "r");
  if (p == nullptr) return -1;
  char buf[4096];
  std::size_t n;
  while ((n = std::fread(buf, 1, sizeof buf, p)) > 0) out.append(buf, n);
  const int st = ::pclose(p);
  return WIFEXITED(st) ? WEXITSTATUS(st) : -1;
}

std::string slurp(const fs::path& p) {
  std::ifstream f(p, std::ios::binary);
  std::ostringstream s;
  s << f.rdbuf();
  return s.str();
}

std::size_t count(const std::string& s, const std::string& what) {
  std::size_t n = 0;
  for (auto p = s.find(what); p != std::string::npos; p = s.find(what, p + 1)) ++n;
  return n;
}

/// One run per process (ctest runs every test in its own process, in parallel: per-pid names).
struct Files {
  fs::path dir, capture, svg, html;
  std::string error;
};

const Files& files() {
  static const Files f = [] {
    Files r;
    r.dir = fs::path(PBVBUS_BINARY_DIR) / ("timeline_cpu_rows_" + std::to_string(::getpid()));
    fs::create_directories(r.dir);
    r.capture = r.dir / "h.pcapng";
    r.svg = r.dir / "h.svg";
    r.html = r.dir / "h.html";
    if (!fs::exists(kBinary)) {
      r.error = kBinary + " is missing (build the pbvbus_cli target)";
      return r;
    }
    std::string out;
    if (shell(quote(kBinary) + " run --fast --capture " + quote(r.capture.string()) + " --quiet", out) != 0)
      r.error = "pbvbus run: " + out;
    else if (shell(quote(kBinary) + " timeline " + quote(r.capture.string()) + " -o " +
                       quote(r.svg.string()),
                   out) != 0)
      r.error = "pbvbus timeline -o svg: " + out;
    else if (shell(quote(kBinary) + " timeline " + quote(r.capture.string()) + " -o " +
                       quote(r.html.string()),
                   out) != 0)
      r.error = "pbvbus timeline -o html: " + out;
    return r;
  }();
  return f;
}

class TimelineCpuRows : public ::testing::Test {
 protected:
  void SetUp() override { ASSERT_EQ(files().error, ""); }
  static void TearDownTestSuite() {
    std::error_code ec;
    fs::remove_all(files().dir, ec);
  }
};

TEST_F(TimelineCpuRows, SvgShowsBothCpus) {
  const std::string svg = slurp(files().svg);
  ASSERT_FALSE(svg.empty());
  EXPECT_EQ(count(svg, "<g class=\"cpu-row\""), 2u);
  EXPECT_NE(svg.find("<g class=\"cpu-row\" data-system=\"H-CPU\" data-rack=\"0\">"), std::string::npos);
  EXPECT_NE(svg.find("<g class=\"cpu-row\" data-system=\"H-CPU\" data-rack=\"1\">"), std::string::npos);
  EXPECT_NE(svg.find(">CPU 0 (rack 0)</text>"), std::string::npos);
  EXPECT_NE(svg.find(">CPU 1 (rack 1)</text>"), std::string::npos);
  // CPU 1's first update: UPDATE at 1 s + 2 s of link-up = 3 s, for W = 145 ms, as standby.
  EXPECT_NE(svg.find("<title>CPU 1 (rack 1): UPDATE standby&#10;from 3.000\u2009000\u2009000 s&#10;"
                     "to 3.145\u2009000\u2009000 s (145.000 ms)</title>"),
            std::string::npos);
  // F5 at 5 s: OB 72 (redundant link lost) on CPU 0; F1 at 12 s: OB 72 (master CPU lost) on
  // CPU 1.
  EXPECT_NE(svg.find("<title>5.000\u2009000\u2009000 s OB 72&#10;H-CPU: CPU 0: OB 72 (redundant link lost)</title>"),
            std::string::npos);
  EXPECT_NE(svg.find("<title>12.000\u2009000\u2009000 s OB 72&#10;H-CPU: CPU 1: OB 72 (master CPU lost)</title>"),
            std::string::npos);
  EXPECT_NE(svg.find(">CPU state</text>"), std::string::npos);
}

TEST_F(TimelineCpuRows, ModelOfTheCapture) {
  std::string error;
  const auto tl = pbvbus::captures::read_timeline_file(files().capture.string(), {}, error);
  ASSERT_TRUE(tl.has_value()) << error;
  using pbvbus::captures::CpuStateSpan;
  constexpr std::int64_t kMs = 1'000'000;
  auto find = [&](int rack, std::int64_t start) -> const CpuStateSpan* {
    for (const CpuStateSpan& s : tl->cpu_states)
      if (s.rack == rack && s.start_ns == start) return &s;
    return nullptr;
  };
  // CPU 0: STARTUP as master from power-on (0 s) to RUN at 1 s (startup time 1 s).
  const CpuStateSpan* s = find(0, 0);
  ASSERT_NE(s, nullptr);
  EXPECT_EQ(s->state, 2);  // STARTUP
  EXPECT_EQ(s->role, 1);   // master
  EXPECT_EQ(s->end_ns, 1000 * kMs);
  // CPU 0 returns at 14 s as standby and links up 14 s .. 16 s (link-up 2 s), then UPDATE
  // 16 s .. 16.145 s (W = 145 ms).
  s = find(0, 16000 * kMs);
  ASSERT_NE(s, nullptr);
  EXPECT_EQ(s->state, 5);  // UPDATE
  EXPECT_EQ(s->role, 2);   // standby
  EXPECT_EQ(s->end_ns, 16145 * kMs);
  // Every row ends at the end of the capture (18 s run; last_ns is the latest frame's end or
  // event, at most 18 s).
  for (int rack : {0, 1}) {
    const CpuStateSpan* last = nullptr;
    for (const CpuStateSpan& x : tl->cpu_states)
      if (x.rack == rack) last = &x;
    ASSERT_NE(last, nullptr) << rack;
    EXPECT_EQ(last->end_ns, tl->last_ns);
    EXPECT_EQ(last->state, 3) << rack;  // both in RUN at the end (Redundant from 16.145 s)
  }
  // OB 72 on CPU 0 at 5 s (F5) and on CPU 1 at 12 s (F1).
  int ob72 = 0;
  for (const auto& m : tl->cpu_obs)
    if (m.ob == 72) {
      ++ob72;
      EXPECT_TRUE((m.rack == 0 && m.ts_ns == 5000 * kMs) || (m.rack == 1 && m.ts_ns == 12000 * kMs))
          << m.rack << " " << m.ts_ns;
    }
  EXPECT_EQ(ob72, 2);
}

TEST_F(TimelineCpuRows, HtmlCarriesTheCpuData) {
  const std::string html = slurp(files().html);
  ASSERT_FALSE(html.empty());
  EXPECT_NE(html.find("{\"label\":\"CPU 0 (rack 0)\",\"sys\":\"H-CPU\",\"r\":0,\"s\":[[0,1000000000,2,1],"),
            std::string::npos);
  EXPECT_NE(html.find("{\"label\":\"CPU 1 (rack 1)\",\"sys\":\"H-CPU\",\"r\":1,"), std::string::npos);
}

}  // namespace
