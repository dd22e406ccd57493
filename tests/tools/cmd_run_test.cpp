// `pbvbus run`: argument errors, scenario errors, the text and JSON reports.
#include <gtest/gtest.h>

#include <cstdio>
#include <fstream>
#include <sstream>
#include <string>

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
[[maybe_unused]] std::pair<int, std::string> shell(const std::string& cmd) {
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

}  // namespace
}  // namespace pbvbus::tools
