// The progress line of `pbvbus run`: on a terminal, a long run shows virtual time, speed ratio,
// frames and error frames, redrawn in place and erased before the report; with --quiet, or when
// stderr is not a terminal, there is none. Runs the real binary with its stderr on a pty.
#include <fcntl.h>
#include <gtest/gtest.h>
#include <poll.h>
#include <pty.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <regex>
#include <string>
#include <vector>

namespace {

const std::string kBinary = PBVBUS_BINARY_DIR "/bin/pbvbus";

struct Result {
  int status = -1;
  std::string terminal;  // what the program wrote to its stderr (the terminal)
};

// Runs the binary with stdout to /dev/null and stderr on the slave side of a new pty (or on a
// pipe when `tty` is false), collecting what appears there.
Result run(std::vector<std::string> args, bool tty) {
  Result r;
  int master = -1, slave = -1;
  int p[2] = {-1, -1};
  if (tty) {
    if (::openpty(&master, &slave, nullptr, nullptr, nullptr) != 0) return r;
  } else if (::pipe(p) != 0) {
    return r;
  }
  const pid_t pid = ::fork();
  if (pid == 0) {
    const int devnull = ::open("/dev/null", O_WRONLY);
    ::dup2(devnull, 1);
    ::dup2(tty ? slave : p[1], 2);
    std::vector<char*> argv;
    args.insert(args.begin(), kBinary);
    for (auto& a : args) argv.push_back(a.data());
    argv.push_back(nullptr);
    ::execv(kBinary.c_str(), argv.data());
    ::_exit(127);
  }
  const int fd = tty ? master : p[0];
  if (tty) ::close(slave);
  else ::close(p[1]);
  char buf[4096];
  for (;;) {
    pollfd pf{fd, POLLIN, 0};
    if (::poll(&pf, 1, 30000) <= 0) break;
    const ssize_t n = ::read(fd, buf, sizeof buf);
    if (n <= 0) break;  // EIO on the pty master once the child has gone
    r.terminal.append(buf, static_cast<std::size_t>(n));
  }
  ::close(fd);
  int st = 0;
  ::waitpid(pid, &st, 0);
  r.status = WIFEXITED(st) ? WEXITSTATUS(st) : 128 + WTERMSIG(st);
  return r;
}

// A paced run of 1.5 s: the line appears after 1 s of wall time.
const std::vector<std::string> kArgs = {"run", PBVBUS_SOURCE_DIR "/examples/multimaster.textproto",
                                        "--paced", "--duration", "1500ms"};

TEST(ProgressLine, OnATerminalShowsTimeSpeedFramesErrorsThenErasesIt) {
  if (::access(kBinary.c_str(), X_OK) != 0) GTEST_SKIP() << kBinary << " is not built";
  const Result r = run(kArgs, true);
  ASSERT_EQ(r.status, 0) << r.terminal;
  // e.g. "\r1.200 s / 1.500 s virtual, 1x real time, 8949 frames, 0 errors   "
  const std::regex line(
      R"(\r[0-9.]+ m?s / 1\.500 s virtual, [0-9.e+]+x real time, ([0-9]+) frames, 0 errors +)");
  std::smatch m;
  ASSERT_TRUE(std::regex_search(r.terminal, m, line)) << r.terminal;
  EXPECT_GT(std::stoul(m[1]), 1000u);
  // Erased at the end (stdout, where the report goes, is not the terminal here): the last thing
  // on the terminal is a carriage return, blanks at least as wide as the line, a carriage return.
  const std::regex erased(R"(\r( +)\r$)");
  std::smatch e;
  ASSERT_TRUE(std::regex_search(r.terminal, e, erased)) << r.terminal;
  EXPECT_GE(e[1].length(), m[0].length() - 1);
}

TEST(ProgressLine, NoneWithQuietOrWithoutATerminal) {
  if (::access(kBinary.c_str(), X_OK) != 0) GTEST_SKIP() << kBinary << " is not built";
  auto quiet = kArgs;
  quiet.push_back("--quiet");
  const Result q = run(quiet, true);
  ASSERT_EQ(q.status, 0) << q.terminal;
  EXPECT_EQ(q.terminal.find("virtual"), std::string::npos) << q.terminal;
  const Result piped = run(kArgs, false);
  ASSERT_EQ(piped.status, 0) << piped.terminal;
  EXPECT_EQ(piped.terminal.find("virtual"), std::string::npos) << piped.terminal;
  EXPECT_EQ(piped.terminal.find('\r'), std::string::npos) << piped.terminal;
}

}  // namespace
