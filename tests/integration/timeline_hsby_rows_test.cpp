// The Quantum Hot Standby rows in `pbvbus timeline` and the pair's part of `pbvbus inspect`, on a
// real run (docs/quantum-hsby.md "Captures and timeline"): the binary runs a pair with one DP
// slave and two planned faults, `pbvbus run --fast --capture X --quiet`, then `pbvbus timeline X
// -o X.svg` and `-o X.html` and `pbvbus inspect X`, as a user would. No Modbus port (no socket,
// no pty: the test runs beside others).
//
// The times worked out by hand from the scenario below: the scan-time model gives the CPU 434 12
// with this transfer 60 ms (the run report says so; tests/tools/quantum_timing_cmd_test.cpp
// checks the model). Rack 0 powers first (0 s) and is primary, its scans start at 0, 60, ...,
// 1980, 2040 ms; rack 1 powers at 100 ms and becomes standby. Rack 0 loses power at 2000 ms: rack
// 1 takes over at the next scan start, 2040 ms (takeover 40 ms, within one scan). Rack 1's scans
// then start at 2040 + 60 k ms; its key goes to Off Line at 5000 ms, so it hands control over at
// 5040 ms (= 2040 + 50 x 60), takeover 40 ms again, to rack 0 (powered again at 3000 ms).
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

const std::string kQBinary = PBVBUS_BINARY_DIR "/bin/pbvbus";

std::string q_quote(const std::string& s) {
  std::string o = "'";
  for (char c : s) o += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return o + "'";
}

/// Exit status of a shell command (-1 if it did not exit normally); its output goes to `out`.
int q_shell(const std::string& cmd, std::string& out) {
  FILE* p = ::popen((cmd + " 2>&1").c_str(), "r");
  if (p == nullptr) return -1;
  char buf[4096];
  std::size_t n;
  while ((n = std::fread(buf, 1, sizeof buf, p)) > 0) out.append(buf, n);
  const int st = ::pclose(p);
  return WIFEXITED(st) ? WEXITSTATUS(st) : -1;
}

std::string q_slurp(const fs::path& p) {
  std::ifstream f(p, std::ios::binary);
  std::ostringstream s;
  s << f.rdbuf();
  return s.str();
}

std::size_t q_count(const std::string& s, const std::string& what) {
  std::size_t n = 0;
  for (auto p = s.find(what); p != std::string::npos; p = s.find(what, p + 1)) ++n;
  return n;
}

const char* const kQRowsScenario = R"(name: "quantum-rows"
seed: 1
duration: "8s"
line { name: "rio" baud: "1.5M" }
dp_master { address: 1 line: "rio" watchdog: "300ms" }
dp_slave { address: 3 line: "rio" gsd: ")" PBVBUS_SOURCE_DIR R"(/examples/gsd/PBVB0A01.gsd" master: 1 }
quantum_hot_standby {
  name: "Quantum"
  cpu: CPU_434_12
  command_register: "400001"
  non_transfer { start: "400010" length: 4 }
  logic_time: "20ms"
  rack { designation: A power_on_at: "0s" }
  rack { designation: B power_on_at: "100ms" }
  dp {
    line: "rio"
    address: 1
    map { slave: 3 inputs: "300001" outputs: "400100" }
  }
  logic { counter: "400100" }
}
fault { at: "2s" repair_at: "3s" quantum_power_loss { rack: 0 } }
fault { at: "5s" repair_at: "6s" quantum_key { rack: 1 position: OFF_LINE } }
)";

/// One run per process (ctest runs every test in its own process, in parallel: per-pid names).
struct QFiles {
  fs::path dir, capture, svg, html;
  std::string inspect, inspect_json;
  std::string error;
};

const QFiles& q_files() {
  static const QFiles f = [] {
    QFiles r;
    r.dir = fs::path(PBVBUS_BINARY_DIR) / ("timeline_hsby_rows_" + std::to_string(::getpid()));
    fs::create_directories(r.dir);
    const fs::path scenario = r.dir / "q.textproto";
    std::ofstream(scenario) << kQRowsScenario;
    r.capture = r.dir / "q.pcapng";
    r.svg = r.dir / "q.svg";
    r.html = r.dir / "q.html";
    if (!fs::exists(kQBinary)) {
      r.error = kQBinary + " is missing (build the pbvbus target)";
      return r;
    }
    std::string out;
    const std::string cap = q_quote(r.capture.string());
    if (q_shell(q_quote(kQBinary) + " run " + q_quote(scenario.string()) + " --fast --capture " + cap + " --quiet",
                out) != 0)
      r.error = "pbvbus run: " + out;
    else if (q_shell(q_quote(kQBinary) + " timeline " + cap + " -o " + q_quote(r.svg.string()), out) != 0)
      r.error = "pbvbus timeline -o svg: " + out;
    else if (q_shell(q_quote(kQBinary) + " timeline " + cap + " -o " + q_quote(r.html.string()), out) != 0)
      r.error = "pbvbus timeline -o html: " + out;
    else if (q_shell(q_quote(kQBinary) + " inspect " + cap, r.inspect) != 0)
      r.error = "pbvbus inspect: " + r.inspect;
    else if (q_shell(q_quote(kQBinary) + " inspect " + cap + " --json", r.inspect_json) != 0)
      r.error = "pbvbus inspect --json: " + r.inspect_json;
    return r;
  }();
  return f;
}

class TimelineHsbyRows : public ::testing::Test {
 protected:
  void SetUp() override { ASSERT_EQ(q_files().error, ""); }
  static void TearDownTestSuite() {
    std::error_code ec;
    fs::remove_all(q_files().dir, ec);
  }
};

constexpr std::int64_t kQMs = 1'000'000;  // ns

TEST_F(TimelineHsbyRows, ModelOfTheCapture) {
  std::string error;
  const auto tl = pbvbus::captures::read_timeline_file(q_files().capture.string(), {}, error);
  ASSERT_TRUE(tl.has_value()) << error;
  using pbvbus::captures::HsbyStateSpan;
  auto find = [&](int rack, std::int64_t start) -> const HsbyStateSpan* {
    for (const HsbyStateSpan& s : tl->hsby_states)
      if (s.rack == rack && s.start_ns == start) return &s;
    return nullptr;
  };
  for (const HsbyStateSpan& s : tl->hsby_states) EXPECT_EQ(s.pair, "Quantum");
  // Rack 0: primary from power-on to the power loss at 2 s, off until 3 s.
  const HsbyStateSpan* s = find(0, 0);
  ASSERT_NE(s, nullptr);
  EXPECT_EQ(s->state, 2);  // primary
  EXPECT_EQ(s->end_ns, 2000 * kQMs);
  s = find(0, 2000 * kQMs);
  ASSERT_NE(s, nullptr);
  EXPECT_EQ(s->state, 0);  // off
  EXPECT_EQ(s->end_ns, 3000 * kQMs);
  // Rack 1: standby from its power-on (offline first, at the same instant: dropped) until the
  // takeover at 2.04 s, primary until its key's handover at 5.04 s.
  s = find(1, 100 * kQMs);
  ASSERT_NE(s, nullptr);
  EXPECT_EQ(s->state, 3);  // standby
  EXPECT_EQ(s->end_ns, 2040 * kQMs);
  s = find(1, 2040 * kQMs);
  ASSERT_NE(s, nullptr);
  EXPECT_EQ(s->state, 2);
  EXPECT_EQ(s->end_ns, 5040 * kQMs);
  // Rack 0 is primary again from 5.04 s to the end of the capture.
  s = find(0, 5040 * kQMs);
  ASSERT_NE(s, nullptr);
  EXPECT_EQ(s->state, 2);
  EXPECT_EQ(s->end_ns, tl->last_ns);
  // Two switchovers, each on the new primary's row, 40 ms each.
  ASSERT_EQ(tl->hsby_switchovers.size(), 2u);
  EXPECT_EQ(tl->hsby_switchovers[0].rack, 0);
  EXPECT_EQ(tl->hsby_switchovers[0].ts_ns, 5040 * kQMs);
  EXPECT_EQ(tl->hsby_switchovers[0].takeover_ns, 40'000'000u);
  EXPECT_EQ(tl->hsby_switchovers[1].rack, 1);
  EXPECT_EQ(tl->hsby_switchovers[1].ts_ns, 2040 * kQMs);
  EXPECT_EQ(tl->hsby_switchovers[1].takeover_ns, 40'000'000u);
}

TEST_F(TimelineHsbyRows, DpLaneShowsTheModuleChange) {
  // Both racks' DP master modules are station 1 on "rio": one lane, SA 1 before and after the
  // takeover, silent while no module is active (2 s .. 2.04 s), and slave 3 answers again.
  std::string error;
  const auto tl = pbvbus::captures::read_timeline_file(q_files().capture.string(), {}, error);
  ASSERT_TRUE(tl.has_value()) << error;
  ASSERT_EQ(tl->lanes.size(), 1u);
  const auto& lane = tl->lanes[0];
  EXPECT_EQ(lane.name, "rio");
  std::size_t before = 0, during = 0, after = 0;
  for (const auto& f : lane.frames) {
    if (!f.decoded || f.type == pbvbus::fdl::FrameType::SC) continue;
    if (f.start_ns >= 2000 * kQMs && f.start_ns < 2040 * kQMs) ++during;
    if (f.sa != 1 && f.da != 1) continue;
    if (f.start_ns < 2000 * kQMs) ++before;
    if (f.start_ns >= 2040 * kQMs && f.start_ns < 2100 * kQMs) ++after;
  }
  EXPECT_GT(before, 0u);
  EXPECT_EQ(during, 0u);
  EXPECT_GT(after, 0u);
  bool answered_after = false;
  for (const auto& sl : lane.slaves)
    if (sl.address == 3)
      for (const auto& p : sl.polls) answered_after |= p.start_ns >= 2040 * kQMs && p.start_ns < 2100 * kQMs && p.answered;
  EXPECT_TRUE(answered_after);
}

TEST_F(TimelineHsbyRows, SvgShowsBothRacks) {
  const std::string svg = q_slurp(q_files().svg);
  ASSERT_FALSE(svg.empty());
  EXPECT_EQ(q_count(svg, "<g class=\"hsby-row\""), 2u);
  EXPECT_NE(svg.find("<g class=\"hsby-row\" data-pair=\"Quantum\" data-rack=\"0\">"), std::string::npos);
  EXPECT_NE(svg.find("<g class=\"hsby-row\" data-pair=\"Quantum\" data-rack=\"1\">"), std::string::npos);
  EXPECT_NE(svg.find(">Quantum rack 0</text>"), std::string::npos);
  EXPECT_NE(svg.find(">Quantum rack 1</text>"), std::string::npos);
  EXPECT_EQ(q_count(svg, "<g class=\"hsby-switchover\" data-takeover-ns=\"40000000\">"), 2u);
  EXPECT_NE(svg.find("<title>2.040\u2009000\u2009000 s switchover to rack 1, takeover 40.000 ms&#10;"
                     "Quantum: rack 1: switchover rack 0 -&gt; rack 1 (primary power off)"),
            std::string::npos);
  EXPECT_NE(svg.find("<title>Quantum rack 0: off&#10;from 2.000\u2009000\u2009000 s&#10;"
                     "to 3.000\u2009000\u2009000 s (1.000000 s)</title>"),
            std::string::npos);
  EXPECT_NE(svg.find(">Quantum rack</text>"), std::string::npos);
}

TEST_F(TimelineHsbyRows, HtmlCarriesTheRows) {
  const std::string html = q_slurp(q_files().html);
  ASSERT_FALSE(html.empty());
  EXPECT_NE(html.find(",\"hsby\":{\"states\":[\"off\",\"offline\",\"primary\",\"standby\"],\"rows\":["
                      "{\"label\":\"Quantum rack 0\",\"pair\":\"Quantum\",\"r\":0,"
                      "\"s\":[[0,2000000000,2],[2000000000,3000000000,0],"),
            std::string::npos);
  EXPECT_NE(html.find("{\"label\":\"Quantum rack 1\",\"pair\":\"Quantum\",\"r\":1,"
                      "\"s\":[[100000000,2040000000,3],[2040000000,5040000000,2],"),
            std::string::npos);
  EXPECT_NE(html.find("\"sw\":[[2040000000,40000000,\"Quantum: rack 1: switchover rack 0 -\\u003e rack 1"),
            std::string::npos);
}

TEST_F(TimelineHsbyRows, InspectListsTheSwitchovers) {
  const std::string& t = q_files().inspect;
  EXPECT_NE(t.find("Quantum Hot Standby: "), std::string::npos) << t;
  EXPECT_NE(t.find(" records, 2 switchovers\n"), std::string::npos) << t;
  EXPECT_NE(t.find("  2.040000000 s  to rack 1, takeover 40.000 ms: Quantum: rack 1: switchover rack 0 -> "
                   "rack 1 (primary power off)"),
            std::string::npos)
      << t;
  EXPECT_NE(t.find("  5.040000000 s  to rack 0, takeover 40.000 ms: Quantum: rack 0: switchover rack 1 -> "
                   "rack 0 (primary key to Off Line)"),
            std::string::npos)
      << t;
  EXPECT_NE(q_files().inspect_json.find("{\"ts_ns\":2040000000,\"rack\":1,\"takeover_ns\":40000000,"),
            std::string::npos)
      << q_files().inspect_json;
}

}  // namespace
