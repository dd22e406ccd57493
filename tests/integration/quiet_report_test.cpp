// `pbvbus run --quiet` turns off the progress line only (README "Long runs on a terminal show a
// progress line"; `pbvbus run --help`): the report still prints. Runs the real binary with its
// stderr on a pty (where the progress line would be) and its stdout in a file.
#include <fcntl.h>
#include <gtest/gtest.h>
#include <poll.h>
#include <pty.h>
#include <sys/wait.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

namespace {

const std::string kBinary = PBVBUS_BINARY_DIR "/bin/pbvbus";

struct Result {
  int status = -1;
  std::string terminal;  // stderr, a terminal
  std::string out;       // stdout, a file
};

Result run(std::vector<std::string> args) {
  Result r;
  int master = -1, slave = -1;
  if (::openpty(&master, &slave, nullptr, nullptr, nullptr) != 0) return r;
  const std::string out_path =
      (std::filesystem::temp_directory_path() / ("pbvbus_quiet_" + std::to_string(::getpid()) + ".txt")).string();
  const pid_t pid = ::fork();
  if (pid == 0) {
    const int out = ::open(out_path.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    ::dup2(out, 1);
    ::dup2(slave, 2);
    std::vector<char*> argv;
    args.insert(args.begin(), kBinary);
    for (auto& a : args) argv.push_back(a.data());
    argv.push_back(nullptr);
    ::execv(kBinary.c_str(), argv.data());
    ::_exit(127);
  }
  ::close(slave);
  char buf[4096];
  for (;;) {
    pollfd pf{master, POLLIN, 0};
    if (::poll(&pf, 1, 30000) <= 0) break;
    const ssize_t n = ::read(master, buf, sizeof buf);
    if (n <= 0) break;
    r.terminal.append(buf, static_cast<std::size_t>(n));
  }
  ::close(master);
  int st = 0;
  ::waitpid(pid, &st, 0);
  r.status = WIFEXITED(st) ? WEXITSTATUS(st) : 128 + WTERMSIG(st);
  std::ifstream in(out_path);
  std::stringstream ss;
  ss << in.rdbuf();
  r.out = ss.str();
  std::filesystem::remove(out_path);
  return r;
}

// A paced run of 1.5 s: without --quiet the progress line appears after 1 s of wall time.
const std::vector<std::string> kArgs = {"run", PBVBUS_SOURCE_DIR "/examples/multimaster.textproto",
                                        "--paced", "--duration", "1500ms"};

TEST(QuietRun, TurnsOffOnlyTheProgressLineTheReportStillPrints) {
  if (::access(kBinary.c_str(), X_OK) != 0) GTEST_SKIP() << kBinary << " is not built";
  auto quiet = kArgs;
  quiet.push_back("--quiet");
  const Result q = run(quiet);
  const Result n = run(kArgs);
  ASSERT_EQ(q.status, 0) << q.terminal;
  ASSERT_EQ(n.status, 0) << n.terminal;
  // The progress line: on the terminal without --quiet, not with it.
  EXPECT_NE(n.terminal.find(" virtual, "), std::string::npos) << n.terminal;
  EXPECT_EQ(q.terminal.find(" virtual, "), std::string::npos) << q.terminal;
  // The report: the same sections with and without --quiet.
  ASSERT_FALSE(q.out.empty());
  for (const char* part : {"line A", "live list", "token rotation"}) {
    EXPECT_NE(n.out.find(part), std::string::npos) << part << "\n" << n.out;
    EXPECT_NE(q.out.find(part), std::string::npos) << part << "\n" << q.out;
  }
  EXPECT_EQ(q.out.substr(0, q.out.find('\n')), n.out.substr(0, n.out.find('\n')));
}

TEST(QuietRun, HelpTextSaysSo) {
  if (::access(kBinary.c_str(), X_OK) != 0) GTEST_SKIP() << kBinary << " is not built";
  const Result h = run({"run", "--help"});
  ASSERT_EQ(h.status, 0);
  EXPECT_NE(h.out.find("  --quiet, -q       no progress line on the terminal (the report still prints)\n"),
            std::string::npos)
      << h.out;
}

}  // namespace
