// A paced run with a pty attachment ends cleanly, at the end of its duration and on Ctrl-C
// (SIGINT): exit 0, the whole report on stdout, a capture that the reader and tshark read to
// its end. Once the pty's I/O outlived the runner's io_context and every such run ended with
// SIGSEGV (exit 139), losing the report and the end of the capture.
//
// The test runs the real `pbvbus` binary of the same build as a child process, so in the
// ASan+UBSan build (this file is built into sanitize_integration: *_sanitize_test.cpp) the
// whole command — scenario, simulation, paced runner, pty, capture, report, tear-down — runs
// under the sanitizers, and any report from them makes the exit status non-zero.
#include <fcntl.h>
#include <gtest/gtest.h>
#include <poll.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <fstream>
#include <string>
#include <thread>
#include <vector>

#include "../captures/tshark_helpers.hpp"
#include "pbvbus/captures/pcapng_reader.hpp"

extern char** environ;

namespace {

using namespace std::chrono_literals;

const std::string kBinary = PBVBUS_BINARY_DIR "/bin/pbvbus";

// 187.5 kbit/s, a DP master in OPERATE with one slave, and a MONITOR pty: the scenario of the
// original crash report.
std::string scenario(const std::string& link, const std::string& duration) {
  return (duration.empty() ? std::string() : "duration: \"" + duration + "\"\n") +
         "line { name: \"A\" baud: \"187.5k\" }\n"
         "dp_master { address: 1 line: \"A\" mode: OPERATE }\n"
         "dp_slave { address: 3 line: \"A\" gsd: \"" PBVBUS_SOURCE_DIR
         "/examples/gsd/PBVB0A01.gsd\" master: 1 }\n"
         "serial { line: \"A\" mode: MONITOR link: \"" + link + "\" }\n";
}

struct Child {
  pid_t pid = -1;
  int out = -1;  // its stdout
  int err = -1;  // its stderr
  std::string stdout_text, stderr_text;

  // Reads whatever is available from both pipes, waiting up to `wait`.
  void pump(std::chrono::milliseconds wait) {
    pollfd fds[2] = {{out, POLLIN, 0}, {err, POLLIN, 0}};
    if (::poll(fds, 2, static_cast<int>(wait.count())) <= 0) return;
    char buf[4096];
    for (int i = 0; i < 2; ++i) {
      if (!(fds[i].revents & (POLLIN | POLLHUP))) continue;
      const ssize_t n = ::read(fds[i].fd, buf, sizeof buf);
      if (n > 0) (i == 0 ? stdout_text : stderr_text).append(buf, static_cast<std::size_t>(n));
    }
  }
  // Waits for the exit (reading the pipes meanwhile); kills it after `limit`. -1 if killed.
  int wait_exit(std::chrono::seconds limit) {
    const auto deadline = std::chrono::steady_clock::now() + limit;
    int status = 0;
    for (;;) {
      pump(20ms);
      const pid_t r = ::waitpid(pid, &status, WNOHANG);
      if (r == pid) break;
      if (std::chrono::steady_clock::now() > deadline) {
        ::kill(pid, SIGKILL);
        ::waitpid(pid, &status, 0);
        return -1;
      }
    }
    for (int i = 0; i < 50; ++i) pump(1ms);  // the rest of the pipes
    ::close(out);
    ::close(err);
    if (WIFSIGNALED(status)) return 128 + WTERMSIG(status);
    return WEXITSTATUS(status);
  }
};

Child spawn(const std::vector<std::string>& args) {
  int po[2], pe[2];
  if (::pipe2(po, O_CLOEXEC) != 0 || ::pipe2(pe, O_CLOEXEC) != 0) return {};
  posix_spawn_file_actions_t fa;
  posix_spawn_file_actions_init(&fa);
  posix_spawn_file_actions_adddup2(&fa, po[1], 1);
  posix_spawn_file_actions_adddup2(&fa, pe[1], 2);
  std::vector<char*> argv;
  for (const auto& a : args) argv.push_back(const_cast<char*>(a.c_str()));
  argv.push_back(nullptr);
  Child c;
  if (::posix_spawn(&c.pid, argv[0], &fa, nullptr, argv.data(), environ) != 0) c.pid = -1;
  posix_spawn_file_actions_destroy(&fa);
  ::close(po[1]);
  ::close(pe[1]);
  c.out = po[0];
  c.err = pe[0];
  return c;
}

class PacedPtyTeardown : public ::testing::Test {
 protected:
  void SetUp() override {
    if (::access(kBinary.c_str(), X_OK) != 0) GTEST_SKIP() << kBinary << " is not built";
    const std::string base = std::string(PBVBUS_BINARY_DIR) + "/paced_pty_teardown_" +
                             std::to_string(::getpid()) + "_" +
                             ::testing::UnitTest::GetInstance()->current_test_info()->name();
    m_link = base + ".pty";
    m_scenario = base + ".textproto";
    m_capture = base + ".pcapng";
  }
  void TearDown() override {
    std::remove(m_scenario.c_str());
    std::remove(m_capture.c_str());
  }

  // Reads the monitor pty for a while, as an analyzer would (so the pty's I/O is busy when
  // the run ends). Returns the octets read.
  std::size_t read_monitor(Child& c, std::chrono::milliseconds how_long) {
    int fd = -1;
    const auto until = std::chrono::steady_clock::now() + how_long;
    std::size_t total = 0;
    while (std::chrono::steady_clock::now() < until) {
      c.pump(5ms);
      if (fd < 0) fd = ::open(m_link.c_str(), O_RDONLY | O_NOCTTY | O_NONBLOCK);
      if (fd < 0) continue;
      char buf[4096];
      const ssize_t n = ::read(fd, buf, sizeof buf);
      if (n > 0) total += static_cast<std::size_t>(n);
    }
    if (fd >= 0) ::close(fd);
    return total;
  }

  // The report and the capture are complete.
  void expect_complete(const Child& c) {
    // The text report ends with the DP part: the slave's line is there.
    EXPECT_NE(c.stdout_text.find("line A"), std::string::npos) << c.stdout_text;
    EXPECT_NE(c.stdout_text.find("slave 3"), std::string::npos) << c.stdout_text;
    pbvbus::captures::PcapngError error;
    const auto cap = pbvbus::captures::read_pcapng_file(m_capture, error);
    ASSERT_TRUE(cap.has_value()) << error.to_string();
    EXPECT_GT(cap->records.size(), 100u);
    // `pbvbus inspect` reads it to its end (exit 2 and an offset if the file were cut short).
    Child inspect = spawn({kBinary, "inspect", m_capture});
    ASSERT_GT(inspect.pid, 0);
    EXPECT_EQ(inspect.wait_exit(std::chrono::seconds(60)), 0) << inspect.stderr_text;
    EXPECT_NE(inspect.stdout_text.find(std::to_string(cap->records.size())), std::string::npos)
        << inspect.stdout_text;
    if (pbvbus::test::tshark_available()) {
      const auto r = pbvbus::test::tshark(m_capture, {"-T", "fields", "-e", "frame.number"});
      EXPECT_EQ(r.exit_code, 0) << r.err;
      EXPECT_EQ(r.err.find("malformed"), std::string::npos) << r.err;
      EXPECT_EQ(r.err.find("cut short"), std::string::npos) << r.err;
      // tshark reads every record to the end of the file.
      std::size_t rows = 0;
      for (char ch : r.out) rows += ch == '\n';
      EXPECT_EQ(rows, cap->records.size());
    }
  }

  std::string m_link, m_scenario, m_capture;
};

TEST_F(PacedPtyTeardown, EndOfDurationExitsZeroWithTheWholeReport) {
  std::ofstream(m_scenario) << scenario(m_link, "1500ms");
  Child c = spawn({kBinary, "run", m_scenario, "--capture", m_capture});
  ASSERT_GT(c.pid, 0);
  EXPECT_GT(read_monitor(c, 1000ms), 0u);
  const int rc = c.wait_exit(60s);
  ASSERT_EQ(rc, 0) << c.stderr_text;
  expect_complete(c);
}

TEST_F(PacedPtyTeardown, CtrlCExitsZeroWithTheWholeReport) {
  std::ofstream(m_scenario) << scenario(m_link, "");  // no duration: runs until interrupted
  Child c = spawn({kBinary, "run", m_scenario, "--capture", m_capture});
  ASSERT_GT(c.pid, 0);
  // SIGINT only once the run has said it is running (its signal handler is in place then).
  const auto deadline = std::chrono::steady_clock::now() + 30s;
  while (c.stderr_text.find("running until interrupted") == std::string::npos &&
         std::chrono::steady_clock::now() < deadline)
    c.pump(20ms);
  ASSERT_NE(c.stderr_text.find("running until interrupted"), std::string::npos) << c.stderr_text;
  EXPECT_GT(read_monitor(c, 800ms), 0u);
  ::kill(c.pid, SIGINT);
  const int rc = c.wait_exit(60s);
  ASSERT_EQ(rc, 0) << c.stderr_text;
  EXPECT_NE(c.stderr_text.find("interrupted at"), std::string::npos) << c.stderr_text;
  expect_complete(c);
}

}  // namespace
