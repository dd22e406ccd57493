// `pbvbus run`: argument errors, scenario errors, the text and JSON reports.
#include <gtest/gtest.h>

#include <chrono>
#include <cstdio>
#include <fstream>
#include <sstream>
#include <string>
#include <sys/stat.h>
#include <sys/wait.h>

#include "pbvbus/tools/commands.hpp"

namespace pbvbus::tools {
namespace {

struct Result {
  int rc;
  std::string out;
  std::string err;
};

Result run(const Args& args) {
  std::ostringstream out, err;
  const int rc = cmd_run(args, out, err);
  return {rc, out.str(), err.str()};
}

std::string write_temp(const std::string& name, const std::string& text) {
  const std::string path = std::string(PBVBUS_BINARY_DIR) + "/" + name;
  std::ofstream(path) << text;
  return path;
}

/// Runs a shell command, returns its exit status and stdout.
std::pair<int, std::string> shell(const std::string& cmd) {
  std::string out;
  FILE* p = ::popen(cmd.c_str(), "r");
  if (p == nullptr) return {-1, ""};
  char buf[4096];
  std::size_t n;
  while ((n = std::fread(buf, 1, sizeof buf, p)) > 0) out.append(buf, n);
  const int st = ::pclose(p);
  return {WIFEXITED(st) ? WEXITSTATUS(st) : -1, out};
}

TEST(CmdRun, UsageErrorsExitWith2AndAMessage) {
  auto r = run({"--bogus"});
  EXPECT_EQ(r.rc, 2);
  EXPECT_EQ(r.err, "pbvbus run: unknown option '--bogus'\nTry 'pbvbus run --help'.\n");
  EXPECT_TRUE(r.out.empty());

  r = run({"--duration"});
  EXPECT_EQ(r.rc, 2);
  EXPECT_EQ(r.err, "pbvbus run: --duration needs a value, e.g. --duration 5s\nTry 'pbvbus run --help'.\n");

  r = run({"--duration", "5 parsecs"});
  EXPECT_EQ(r.rc, 2);
  EXPECT_EQ(r.err,
            "pbvbus run: bad duration '5 parsecs' (expected a number and a unit: ns, us, ms, s, "
            "min, h)\nTry 'pbvbus run --help'.\n");

  r = run({"--seed", "-3"});
  EXPECT_EQ(r.rc, 2);
  EXPECT_EQ(r.err, "pbvbus run: bad seed '-3' (expected an unsigned integer)\nTry 'pbvbus run --help'.\n");

  r = run({"--seed", "12x"});
  EXPECT_EQ(r.rc, 2);

  r = run({"--fast", "--paced"});
  EXPECT_EQ(r.rc, 2);
  EXPECT_EQ(r.err, "pbvbus run: --fast and --paced exclude each other\nTry 'pbvbus run --help'.\n");

  r = run({"--json", "--capture", "-"});
  EXPECT_EQ(r.rc, 2);
  EXPECT_EQ(r.err,
            "pbvbus run: --json and --capture - both need stdout; write the capture to a file\n"
            "Try 'pbvbus run --help'.\n");

  r = run({"a.textproto", "b.textproto"});
  EXPECT_EQ(r.rc, 2);
  EXPECT_EQ(r.err,
            "pbvbus run: more than one scenario given ('a.textproto' and 'b.textproto')\n"
            "Try 'pbvbus run --help'.\n");
}

TEST(CmdRun, HelpGoesToStdout) {
  const auto r = run({"--help"});
  EXPECT_EQ(r.rc, 0);
  EXPECT_NE(r.out.find("usage: pbvbus run [SCENARIO] [options]"), std::string::npos);
  EXPECT_TRUE(r.err.empty());
}

TEST(CmdRun, ScenarioErrorsArePrintedWithPositions) {
  const std::string path = write_temp("cmd_run_bad.textproto",
                                      "line { name: \"A\" }\nmaster { address: 1 line: \"B\" }\n");
  const auto r = run({path});
  EXPECT_EQ(r.rc, 2);
  EXPECT_EQ(r.err, path + ":2:21: unknown line \"B\"\n");
  const auto missing = run({"/nonexistent/s.textproto"});
  EXPECT_EQ(missing.rc, 2);
  EXPECT_EQ(missing.err, "/nonexistent/s.textproto: cannot read the file: No such file or directory\n");
}

TEST(CmdRun, ScenarioWithoutDurationNeedsOne) {
  const std::string path = write_temp("cmd_run_nodur.textproto",
                                      "line { name: \"A\" }\npassive_station { address: 5 line: \"A\" }\n");
  const auto r = run({path});
  EXPECT_EQ(r.rc, 2);
  EXPECT_EQ(r.err, "pbvbus run: " + path +
                       ": the scenario has no duration; add duration: \"5s\" or use --duration\n");
}

TEST(CmdRun, CaptureThatCannotBeWrittenIsAUsageError) {
  const auto r = run({"--capture", "/nonexistent/dir/x.pcapng", "--duration", "10ms"});
  EXPECT_EQ(r.rc, 2);
  EXPECT_EQ(r.err.rfind("pbvbus run: cannot write the capture /nonexistent/dir/x.pcapng: ", 0), 0u)
      << r.err;
}

// The former built-in default (examples/dp-line.textproto since the H-system became the default).
TEST(CmdRun, DpLineScenarioRunsAndReports) {
  const std::string file = PBVBUS_SOURCE_DIR "/examples/dp-line.textproto";
  const auto r = run({file});
  ASSERT_EQ(r.rc, 0) << r.err;
  EXPECT_TRUE(r.err.empty()) << r.err;
  EXPECT_EQ(r.out.rfind("scenario dp-line (" + file + "), seed 1\nsimulated 2.000 s in ", 0), 0u)
      << r.out;
  // A DP master and an FDL master in one ring; three DP slaves built from the shipped GSDs and
  // one passive FDL station; slave 4's power loss and return are reported by the line and seen
  // by DP master 1 as one station failure and one return with a second start-up.
  EXPECT_NE(r.out.find("  live list:\n    1\tmaster in ring\n    2\tmaster in ring\n"
                       "    3\tslave\n    4\tslave\n    5\tslave\n    20\tslave\n"),
            std::string::npos)
      << r.out;
  EXPECT_NE(r.out.find("  fault at 1.000 s: PROFIBUS_DP_1: power off: 'dp slave 4'\n"
                       "  fault at 1.500 s: PROFIBUS_DP_1: power on: 'dp slave 4'\n"),
            std::string::npos)
      << r.out;
  const auto s4 = r.out.find("  dp slave 4 ");
  ASSERT_NE(s4, std::string::npos) << r.out;
  const auto s4_end = r.out.find("  dp slave 5 ", s4);
  const std::string slave4 = r.out.substr(s4, s4_end - s4);
  EXPECT_NE(slave4.find(": data exchange"), std::string::npos) << slave4;
  EXPECT_NE(slave4.find("start-ups 2, diagnosis reads 4, failures 1, returns 1"), std::string::npos)
      << slave4;
  // The other two slaves never left data exchange.
  for (const char* other : {"  dp slave 3 ", "  dp slave 5 "}) {
    const auto p = r.out.find(other);
    ASSERT_NE(p, std::string::npos) << r.out;
    EXPECT_NE(r.out.find("start-ups 1, diagnosis reads 2, failures 0, returns 0", p), std::string::npos)
        << r.out.substr(p, 600);
  }
}

TEST(CmdRun, QuietKeepsTheReport) {
  // --quiet turns off only the progress line (README): the report is the same as without it.
  const auto q = run({"--quiet", "--duration", "50ms"});
  const auto n = run({"--duration", "50ms"});
  EXPECT_EQ(q.rc, 0);
  ASSERT_EQ(n.rc, 0);
  EXPECT_FALSE(q.out.empty());
  EXPECT_EQ(q.out.substr(0, q.out.find('\n')), n.out.substr(0, n.out.find('\n')));
  EXPECT_NE(q.out.find("live list"), std::string::npos) << q.out;
  EXPECT_TRUE(q.err.empty()) << q.err;
}

TEST(CmdRun, JsonReportIsValidJsonWithTheDocumentedSchema) {
  const auto r = run({PBVBUS_SOURCE_DIR "/examples/multimaster.textproto", "--json", "--seed", "9"});
  ASSERT_EQ(r.rc, 0) << r.err;
  const std::string path = write_temp("cmd_run_report.json", r.out);
  const auto [rc, out] = shell(
      "python3 -c 'import json,sys; d=json.load(open(sys.argv[1])); l=d[\"lines\"][0]; "
      "print(d[\"schema\"], d[\"scenario\"][\"seed\"], d[\"duration_ns\"], l[\"name\"], l[\"baud\"], "
      "[m[\"address\"] for m in l[\"masters\"]], [s[\"address\"] for s in l[\"stations\"]], "
      "[(e[\"address\"], e[\"type\"]) for e in l[\"live_list\"]][:4], len(l[\"faults\"]), "
      "l[\"frames\"][\"total\"] == sum(l[\"frames\"][k] for k in (\"SD1\",\"SD2\",\"SD3\",\"SD4\",\"SC\",\"garbage\")), "
      "l[\"masters\"][0][\"rotation\"][\"median_bits\"] > 0)' " +
      path);
  ASSERT_EQ(rc, 0) << r.out;
  EXPECT_EQ(out,
            "pbvbus.run.report/1 9 5000000000 A 1500000 [1, 2, 3] [10, 11, 12, 13, 14] "
            "[(1, 'master_in_ring'), (2, 'master_in_ring'), (3, 'master_in_ring'), (10, "
            "'slave')] 2 True True\n");
  EXPECT_TRUE(r.err.empty()) << r.err;
}

// A serial attachment makes the run paced by default: virtual time follows the wall clock
// (tolerant: only "not faster than real time" is checked, never an upper bound).
TEST(CmdRun, SerialAttachmentMakesTheRunPaced) {
  const std::string path = write_temp("cmd_run_paced.textproto",
                                      "line { name: \"A\" }\n"
                                      "master { address: 1 line: \"A\" }\n"
                                      "serial { line: \"A\" mode: MONITOR }\n");
  const auto t0 = std::chrono::steady_clock::now();
  const auto r = run({path, "--duration", "200ms", "--json"});
  const auto wall = std::chrono::steady_clock::now() - t0;
  ASSERT_EQ(r.rc, 0) << r.err;
  EXPECT_GE(wall, std::chrono::milliseconds(195));
  EXPECT_NE(r.out.find("\"duration_ns\":200000000,"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("\"serial\":[{\"line\":\"A\",\"mode\":\"monitor\",\"path\":\"/dev/pts/"),
            std::string::npos)
      << r.out;
  // The pty path is announced on stderr before the run.
  EXPECT_EQ(r.err.rfind("serial monitor on line A: /dev/pts/", 0), 0u) << r.err;
  // --fast overrides the default, with a warning.
  const auto f = run({path, "--duration", "200ms", "--fast"});
  EXPECT_EQ(f.rc, 0);
  EXPECT_NE(f.err.find("warning: --fast with serial attachments"), std::string::npos) << f.err;
}

TEST(CmdRun, CaptureToStdoutSendsTheReportToStderr) {
  const std::string exe = PBVBUS_BINARY_DIR "/bin/pbvbus";
  struct stat st;
  if (::stat(exe.c_str(), &st) != 0) GTEST_SKIP() << exe << " not built";
  const std::string pcap = PBVBUS_BINARY_DIR "/cmd_run_stdout.pcapng";
  const std::string errf = PBVBUS_BINARY_DIR "/cmd_run_stdout.err";
  const auto [rc, out] =
      shell(exe + " run --duration 100ms --capture - > " + pcap + " 2> " + errf + "; echo $?");
  EXPECT_EQ(out, "0\n");
  std::ifstream p(pcap, std::ios::binary);
  std::string bytes((std::istreambuf_iterator<char>(p)), std::istreambuf_iterator<char>());
  // A pcapng Section Header Block (0x0A0D0D0A), little-endian byte-order magic 0x1A2B3C4D.
  ASSERT_GE(bytes.size(), 12u);
  EXPECT_EQ(bytes.substr(0, 4), std::string("\x0A\x0D\x0D\x0A", 4));
  EXPECT_EQ(bytes.substr(8, 4), std::string("\x4D\x3C\x2B\x1A", 4));
  std::ifstream e(errf);
  std::string err((std::istreambuf_iterator<char>(e)), std::istreambuf_iterator<char>());
  EXPECT_EQ(err.rfind("scenario h-system (<built-in default>), seed 8\n", 0), 0u) << err;
}

}  // namespace
}  // namespace pbvbus::tools
