#pragma once
// Helpers shared by the tests that run tests/integration/outside_slave.py (the Python DP slave)
// behind a pty: outside_slave_test.cpp (the conformance battery against it) and
// replay_pty_test.cpp (pbvbus replay --pty against it). Moved here unchanged from
// outside_slave_test.cpp: the program's and the binary's paths, why a test must skip
// (missing_python(), missing_binary()), a child process with its output in files (Child), a
// shell command's output (shell()) and a JSON file as "path=value" pairs (flatten(), get()).
#include <fcntl.h>
#include <gtest/gtest.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <iterator>
#include <map>
#include <sstream>
#include <string>
#include <thread>
#include <utility>
#include <vector>

extern char** environ;

namespace pbvbus::test_support {

using namespace std::chrono_literals;

inline constexpr const char* kPython = "/usr/bin/python3";
inline const std::string kSlave = PBVBUS_SOURCE_DIR "/tests/integration/outside_slave.py";
inline const std::string kGsd = PBVBUS_SOURCE_DIR "/examples/gsd/PBVB0A01.gsd";

/// Why the test cannot run here, or "" if it can.
inline std::string missing_python() {
  if (::access(kPython, X_OK) != 0) return std::string(kPython) + " is not installed";
  if (std::system((std::string(kPython) + " -c 'import serial' >/dev/null 2>&1").c_str()) != 0)
    return std::string(kPython) + " has no serial module (Debian: apt-get install python3-serial)";
  return "";
}

inline std::string read_file(const std::string& path) {
  std::ifstream f(path);
  return {std::istreambuf_iterator<char>(f), std::istreambuf_iterator<char>()};
}

/// A child process with stdout and stderr in files.
struct Child {
  pid_t pid = -1;
  std::string out_file, err_file;

  static Child spawn(const std::vector<std::string>& args, const std::string& base) {
    Child c;
    c.out_file = base + ".out";
    c.err_file = base + ".err";
    posix_spawn_file_actions_t fa;
    posix_spawn_file_actions_init(&fa);
    posix_spawn_file_actions_addopen(&fa, 1, c.out_file.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    posix_spawn_file_actions_addopen(&fa, 2, c.err_file.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    std::vector<char*> argv;
    for (const auto& a : args) argv.push_back(const_cast<char*>(a.c_str()));
    argv.push_back(nullptr);
    if (::posix_spawn(&c.pid, argv[0], &fa, nullptr, argv.data(), environ) != 0) c.pid = -1;
    posix_spawn_file_actions_destroy(&fa);
    return c;
  }
  /// Waits for the exit up to `limit` (then SIGKILL). Exit status, or -1 if killed/signalled.
  int wait(std::chrono::seconds limit) {
    if (pid <= 0) return -1;
    const auto until = std::chrono::steady_clock::now() + limit;
    int st = 0;
    while (std::chrono::steady_clock::now() < until) {
      if (::waitpid(pid, &st, WNOHANG) == pid) {
        pid = -1;
        return WIFEXITED(st) ? WEXITSTATUS(st) : -1;
      }
      std::this_thread::sleep_for(20ms);
    }
    ::kill(pid, SIGKILL);
    ::waitpid(pid, &st, 0);
    pid = -1;
    ADD_FAILURE() << "child did not end within " << limit.count() << " s; killed";
    return -1;
  }
  /// SIGTERM (the program prints its summary and exits), then waits up to `limit`; SIGKILL
  /// after that. Returns the exit status, 128 + the signal that ended it, or -1 if it had to be
  /// killed.
  int stop(std::chrono::seconds limit = 10s) {
    if (pid <= 0) return -1;
    ::kill(pid, SIGTERM);
    const auto until = std::chrono::steady_clock::now() + limit;
    int st = 0;
    while (std::chrono::steady_clock::now() < until) {
      if (::waitpid(pid, &st, WNOHANG) == pid) {
        pid = -1;
        if (WIFSIGNALED(st)) return 128 + WTERMSIG(st);
        return WIFEXITED(st) ? WEXITSTATUS(st) : -1;
      }
      std::this_thread::sleep_for(10ms);
    }
    ::kill(pid, SIGKILL);
    ::waitpid(pid, &st, 0);
    pid = -1;
    return -1;
  }
  ~Child() { stop(1s); }
};

inline const std::string kBinary = PBVBUS_BINARY_DIR "/bin/pbvbus";

/// Runs a shell command; its exit status (-1 if it did not exit) and stdout.
inline std::pair<int, std::string> shell(const std::string& cmd) {
  std::string out;
  FILE* p = ::popen(cmd.c_str(), "r");
  if (p == nullptr) return {-1, ""};
  char buf[4096];
  std::size_t n;
  while ((n = std::fread(buf, 1, sizeof buf, p)) > 0) out.append(buf, n);
  const int st = ::pclose(p);
  return {WIFEXITED(st) ? WEXITSTATUS(st) : -1, out};
}

/// A JSON document as "path=value" pairs ("tests.3.evidence.0.request"; strings bare).
using Flat = std::map<std::string, std::string>;
inline Flat flatten(const std::string& json_file) {
  const auto [rc, out] = shell(
      std::string(kPython) +
      " -c 'import json,sys\n"
      "def f(p, v):\n"
      "  if isinstance(v, dict):\n"
      "    [f(p + [str(k)], x) for k, x in v.items()]\n"
      "  elif isinstance(v, list):\n"
      "    [f(p + [str(i)], x) for i, x in enumerate(v)]\n"
      "  else:\n"
      "    print(\".\".join(p) + \"=\" + (json.dumps(v) if v is None or isinstance(v, bool) else str(v)))\n"
      "f([], json.load(open(sys.argv[1])))' " +
      json_file);
  Flat m;
  if (rc != 0) return m;
  std::istringstream in(out);
  for (std::string line; std::getline(in, line);) {
    const auto eq = line.find('=');
    if (eq != std::string::npos) m[line.substr(0, eq)] = line.substr(eq + 1);
  }
  return m;
}

inline std::string get(const Flat& m, const std::string& key) {
  const auto it = m.find(key);
  return it == m.end() ? "<missing " + key + ">" : it->second;
}

/// Why the test cannot run here (pbvbus not built), or "" if it can.
inline std::string missing_binary() {
  return ::access(kBinary.c_str(), X_OK) == 0 ? "" : kBinary + " is not built (build the pbvbus_cli target)";
}

}  // namespace pbvbus::test_support
