// Unmodified third-party Modbus clients from Debian against the doors: mbpoll (libmodbus) and
// /usr/bin/python3 with pymodbus 3.0.0 (API `slave=`), each over TCP and over RTU on the pty.
// Each reads registers of the test handler (values set by the test) and writes registers that
// the test then finds in the handler, exact values asserted. The client runs as a child process
// while the test thread drives the paced runner until it exits; a missing program skips the
// test with the reason.

#include <fcntl.h>
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <fstream>
#include <regex>
#include <sstream>
#include <thread>

#include "modbus_test_handler.hpp"

#include "pbvbus/gateways/modbus_rtu_port.hpp"
#include "pbvbus/gateways/modbus_tcp_server.hpp"

namespace pbvbus::gateways {
namespace {

using namespace std::chrono_literals;

constexpr const char* kMbpoll = "/usr/bin/mbpoll";
constexpr const char* kPython = "/usr/bin/python3";

bool have_pymodbus() {
  if (::access(kPython, X_OK) != 0) return false;
  return std::system("/usr/bin/python3 -c 'import pymodbus.client' >/dev/null 2>&1") == 0;
}

struct ChildResult {
  int rc = -1;      ///< exit code, -1 when killed or not started
  std::string out;  ///< stdout + stderr
};

/// Runs argv as a child process (output to a temporary file) while driving the runner until it
/// exits; 30 s of wall time is the generous upper bound, then it is killed.
ChildResult run_child(bus::PacedRunner& runner, const std::vector<std::string>& argv) {
  char tmpl[] = "/tmp/pbvbus-mbclient-XXXXXX";
  const int out = ::mkstemp(tmpl);
  ChildResult r;
  if (out < 0) return r;
  std::fflush(nullptr);
  const pid_t pid = ::fork();
  if (pid == 0) {
    ::dup2(out, STDOUT_FILENO);
    ::dup2(out, STDERR_FILENO);
    std::vector<char*> a;
    for (const auto& s : argv) a.push_back(const_cast<char*>(s.c_str()));
    a.push_back(nullptr);
    ::execv(a[0], a.data());
    ::_exit(127);
  }
  int status = 0;
  bool exited = false;
  test::drive_until(
      runner,
      [&] {
        exited = ::waitpid(pid, &status, WNOHANG) == pid;
        return exited;
      },
      30s);
  if (!exited) {
    ::kill(pid, SIGKILL);
    ::waitpid(pid, &status, 0);
  }
  ::close(out);
  std::ifstream f(tmpl);
  std::stringstream ss;
  ss << f.rdbuf();
  r.out = ss.str();
  ::unlink(tmpl);
  if (exited && WIFEXITED(status)) r.rc = WEXITSTATUS(status);
  return r;
}

/// mbpoll prints one "[n]: \tvalue" line per register read.
std::vector<std::string> mbpoll_values(const std::string& out) {
  std::vector<std::string> v;
  static const std::regex line(R"(\[(\d+)\]:\s+(-?\d+))");
  for (auto it = std::sregex_iterator(out.begin(), out.end(), line); it != std::sregex_iterator();
       ++it)
    v.push_back((*it)[1].str() + "=" + (*it)[2].str());
  return v;
}

class ModbusClients : public ::testing::Test {
 protected:
  bus::Scheduler sched;
  bus::PacedRunner runner{sched};
  test::RegisterFileHandler handler;
};

TEST_F(ModbusClients, MbpollOverTcp) {
  if (::access(kMbpoll, X_OK) != 0) GTEST_SKIP() << "mbpoll is not installed (apt install mbpoll)";
  ModbusTcpServer srv(runner.io_context(), handler, {"127.0.0.1", 0});
  const std::string port = std::to_string(srv.port());
  handler.regs = {555, 1, 2, 3};
  // Read 4 holding registers (FC03) from unit 1 at address 0.
  auto r = run_child(runner, {kMbpoll, "-m", "tcp", "-p", port, "-a", "1", "-t", "4", "-0", "-r",
                              "0", "-c", "4", "-1", "127.0.0.1"});
  ASSERT_EQ(r.rc, 0) << r.out;
  EXPECT_EQ(mbpoll_values(r.out), (std::vector<std::string>{"0=555", "1=1", "2=2", "3=3"}))
      << r.out;
  // Write 3 registers at 10 (FC16).
  r = run_child(runner, {kMbpoll, "-m", "tcp", "-p", port, "-a", "1", "-t", "4", "-0", "-r", "10",
                         "127.0.0.1", "111", "222", "333"});
  ASSERT_EQ(r.rc, 0) << r.out;
  EXPECT_EQ(handler.regs[10], 111);
  EXPECT_EQ(handler.regs[11], 222);
  EXPECT_EQ(handler.regs[12], 333);
  // Unit 9: exception 0x0A -> mbpoll fails with rc 1.
  r = run_child(runner, {kMbpoll, "-m", "tcp", "-p", port, "-a", "9", "-t", "4", "-0", "-r", "0",
                         "-c", "1", "-1", "127.0.0.1"});
  EXPECT_EQ(r.rc, 1) << r.out;
  EXPECT_EQ(srv.stats().exceptions, 1u);
}

TEST_F(ModbusClients, MbpollOverRtuOnThePty) {
  if (::access(kMbpoll, X_OK) != 0) GTEST_SKIP() << "mbpoll is not installed (apt install mbpoll)";
  ModbusRtuPort rtu(runner.io_context(), handler);
  handler.regs[0] = 42;
  handler.regs[1] = 4242;
  auto r = run_child(runner, {kMbpoll, "-m", "rtu", "-b", "115200", "-P", "none", "-a", "1", "-t",
                              "4", "-0", "-r", "0", "-c", "2", "-1", rtu.path()});
  ASSERT_EQ(r.rc, 0) << r.out;
  EXPECT_EQ(mbpoll_values(r.out), (std::vector<std::string>{"0=42", "1=4242"})) << r.out;
  r = run_child(runner, {kMbpoll, "-m", "rtu", "-b", "115200", "-P", "none", "-a", "1", "-t", "4",
                         "-0", "-r", "5", rtu.path(), "77"});
  ASSERT_EQ(r.rc, 0) << r.out;
  EXPECT_EQ(handler.regs[5], 77);
  EXPECT_EQ(rtu.stats().bad_frames, 0u);
}

constexpr const char* kPymodbusScript = R"PY(
import sys
from pymodbus.client import ModbusTcpClient, ModbusSerialClient
if sys.argv[1] == "tcp":
    c = ModbusTcpClient("127.0.0.1", port=int(sys.argv[2]))
else:
    c = ModbusSerialClient(sys.argv[2], baudrate=115200, parity="N")
if not c.connect():
    print("connect failed"); sys.exit(2)
print(c.read_holding_registers(0, 4, slave=1).registers)
c.write_registers(8, [7, 8, 9], slave=1)
c.write_register(12, 0xBEEF, slave=1)
print(c.read_holding_registers(8, 5, slave=1).registers)
r = c.read_holding_registers(0, 1, slave=9)
print(r.isError(), r.exception_code)
r = c.read_holding_registers(0, 1, slave=2)
print(r.isError(), r.exception_code)
c.close()
)PY";

void pymodbus_round(bus::PacedRunner& runner, test::RegisterFileHandler& handler,
                    const std::string& mode, const std::string& where) {
  handler.regs[0] = 555;
  handler.regs[3] = 3;
  const auto r = run_child(runner, {kPython, "-c", kPymodbusScript, mode, where});
  ASSERT_EQ(r.rc, 0) << r.out;
  // Reads: [555, 0, 0, 3]; after FC16 8..10 = 7 8 9 and FC06 12 = BEEF (48879): [7, 8, 9, 0,
  // 48879]; unit 9 -> 0x0A = 10, unit 2 -> 0x0B = 11.
  EXPECT_EQ(r.out, "[555, 0, 0, 3]\n[7, 8, 9, 0, 48879]\nTrue 10\nTrue 11\n");
  EXPECT_EQ(handler.regs[8], 7);
  EXPECT_EQ(handler.regs[10], 9);
  EXPECT_EQ(handler.regs[12], 0xBEEF);
}

TEST_F(ModbusClients, PymodbusOverTcp) {
  if (!have_pymodbus())
    GTEST_SKIP()
        << "/usr/bin/python3 cannot import pymodbus.client (apt install python3-pymodbus "
           "python3-serial-asyncio: pymodbus 3.0.0 imports serial_asyncio, only a Recommends)";
  ModbusTcpServer srv(runner.io_context(), handler, {"127.0.0.1", 0});
  pymodbus_round(runner, handler, "tcp", std::to_string(srv.port()));
  EXPECT_EQ(srv.stats().exceptions, 2u);
}

TEST_F(ModbusClients, PymodbusOverRtuOnThePty) {
  if (!have_pymodbus())
    GTEST_SKIP()
        << "/usr/bin/python3 cannot import pymodbus.client (apt install python3-pymodbus "
           "python3-serial-asyncio: pymodbus 3.0.0 imports serial_asyncio, only a Recommends)";
  ModbusRtuPort rtu(runner.io_context(), handler);
  pymodbus_round(runner, handler, "rtu", rtu.path());
  EXPECT_EQ(rtu.stats().exceptions, 2u);
  EXPECT_EQ(rtu.stats().bad_frames, 0u);
}

}  // namespace
}  // namespace pbvbus::gateways
