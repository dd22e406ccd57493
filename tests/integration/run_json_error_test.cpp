// `pbvbus run --json` (the binary, a child process) whose start-up fails: stdout must still be
// one JSON object, {"schema":"pbvbus.run.error/1","error":TEXT,"exit_code":N}, and stderr must
// keep its "pbvbus run: TEXT" line. Cases: a gateway door's port is in use (Modbus TCP and
// socketcand; the test holds the port with its own listening socket), a pty link path that is a
// regular file, and a scenario with an error. stdout is parsed by /usr/bin/python3's json.
#include <arpa/inet.h>
#include <gtest/gtest.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <string>

namespace {

constexpr const char* kPython = "/usr/bin/python3";
const std::string kBinary = PBVBUS_BINARY_DIR "/bin/pbvbus";
const std::string kGsd = PBVBUS_SOURCE_DIR "/examples/gsd/PBVB0A04.gsd";

std::string read_file(const std::string& path) {
  std::ifstream f(path);
  return {std::istreambuf_iterator<char>(f), std::istreambuf_iterator<char>()};
}

/// A listening loopback socket on an ephemeral port, held for the test's lifetime.
struct HeldPort {
  HeldPort() {
    fd = ::socket(AF_INET, SOCK_STREAM | SOCK_CLOEXEC, 0);
    sockaddr_in a{};
    a.sin_family = AF_INET;
    a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    socklen_t len = sizeof a;
    if (::bind(fd, reinterpret_cast<sockaddr*>(&a), sizeof a) == 0 && ::listen(fd, 4) == 0 &&
        ::getsockname(fd, reinterpret_cast<sockaddr*>(&a), &len) == 0)
      port = ntohs(a.sin_port);
  }
  ~HeldPort() { ::close(fd); }
  int fd = -1;
  std::uint16_t port = 0;
};

class RunJsonError : public ::testing::Test {
 protected:
  void SetUp() override {
    if (::access(kPython, X_OK) != 0) GTEST_SKIP() << kPython << " is needed to parse the JSON";
    char tmpl[] = "/tmp/pbvbus-jsonerr-XXXXXX";
    dir = ::mkdtemp(tmpl);
  }
  void TearDown() override {
    if (!dir.empty()) std::system(("rm -rf " + dir).c_str());
  }

  /// Runs `pbvbus run s.textproto --json` in `dir` with `scenario`; returns its exit code.
  int run(const std::string& scenario) {
    std::ofstream(dir + "/s.textproto") << scenario;
    const std::string cmd = "cd " + dir + " && " + kBinary +
                            " run s.textproto --json >out.txt 2>err.txt </dev/null";
    const int st = std::system(cmd.c_str());
    return WIFEXITED(st) ? WEXITSTATUS(st) : -1;
  }
  /// stdout parsed by python: "schema|exit_code|error" (or python's complaint).
  std::string parsed_stdout() {
    const std::string cmd = std::string(kPython) +
                            " -c 'import json,sys; d=json.load(open(sys.argv[1])); "
                            "print(d[\"schema\"], d[\"exit_code\"], d[\"error\"], sep=\"|\", end=\"\")' " +
                            dir + "/out.txt 2>&1";
    std::string out;
    FILE* p = ::popen(cmd.c_str(), "r");
    char buf[4096];
    std::size_t n;
    while ((n = std::fread(buf, 1, sizeof buf, p)) > 0) out.append(buf, n);
    ::pclose(p);
    return out;
  }
  std::string stderr_text() const { return read_file(dir + "/err.txt"); }

  /// A paced scenario with one slave and a gateway whose doors are `doors`.
  static std::string with_gateway(const std::string& doors) {
    std::ostringstream s;
    s << "name: \"json-error\"\nduration: \"1s\"\nline { name: \"L\" }\n"
         "dp_master { address: 1 line: \"L\" }\n"
         "dp_slave { address: 6 line: \"L\" gsd: \"" << kGsd << "\" master: 1 }\n"
         "gateway { name: \"gw\" line: \"L\" master: 1\n" << doors << "}\n";
    return s.str();
  }

  /// The JSON error and the stderr line carry the same text, which contains `part`.
  void expect_error(int rc, int want_rc, const std::string& part) {
    EXPECT_EQ(rc, want_rc) << stderr_text();
    const std::string j = parsed_stdout();
    const std::string head = "pbvbus.run.error/1|" + std::to_string(want_rc) + "|";
    ASSERT_EQ(j.rfind(head, 0), 0u) << j << "\nstdout: " << read_file(dir + "/out.txt");
    const std::string error = j.substr(head.size());
    EXPECT_NE(error.find(part), std::string::npos) << error;
    EXPECT_NE(stderr_text().find(error), std::string::npos) << stderr_text();
  }

  std::string dir;
};

TEST_F(RunJsonError, ModbusTcpPortInUse) {
  HeldPort held;
  ASSERT_NE(held.port, 0);
  const std::string where = "127.0.0.1:" + std::to_string(held.port);
  const int rc = run(with_gateway("  modbus_tcp { listen: \"" + where + "\" }\n"));
  expect_error(rc, 1, "modbus_tcp on " + where);
  EXPECT_NE(stderr_text().find("pbvbus run: gateway \"gw\": modbus_tcp on " + where),
            std::string::npos)
      << stderr_text();
}

TEST_F(RunJsonError, SocketcandPortInUse) {
  HeldPort held;
  ASSERT_NE(held.port, 0);
  const std::string where = "127.0.0.1:" + std::to_string(held.port);
  const int rc = run(with_gateway("  can { socketcand { listen: \"" + where + "\" } }\n"));
  expect_error(rc, 1, "socketcand on " + where);
}

TEST_F(RunJsonError, PtyLinkPathIsARegularFile) {
  std::ofstream(dir + "/ttyMB0") << "not a link\n";
  const int rc = run(with_gateway("  modbus_rtu { link: \"ttyMB0\" }\n"));
  expect_error(rc, 1, "cannot link the pty to ttyMB0: a file of that name exists");
  EXPECT_EQ(read_file(dir + "/ttyMB0"), "not a link\n");  // left alone
}

TEST_F(RunJsonError, ScenarioErrorsToo) {
  const int rc = run("name: \"x\"\nduration: \"1s\"\nline { name: \"L\" }\nno_such_field: 1\n");
  expect_error(rc, 2, "no_such_field");
}

}  // namespace
