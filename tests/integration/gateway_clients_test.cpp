// End-to-end: `pbvbus run` (the binary, a child process) on a scenario with a gateway, and
// unmodified Debian clients — mbpoll and pymodbus over Modbus TCP and over RTU on the pty,
// python-can over SLCAN (pty and TCP) and socketcand. Each reads an input the slave model
// produces and writes an output that the slave model then sees (docs/gateway-modbus.md).
//
// The station: examples/gsd/PBVB0A04.gsd at address 6 (one module, 32 octets in / 32 out,
// consistent), inputs ECHO (input octet k = output octet k) except input octets 0..1, a constant
// 4660 = 0x1234 written big-endian: octet 0 = 0x12, octet 1 = 0x34. The served master runs no
// test program, so the outputs start at 0 and are only what the client writes.
//   Modbus (unit 6 = the address): input register 0 = octets 0,1 high byte first = 0x1234 =
//   4660; holding register r = output octets 2r, 2r+1; input register r = input octets 2r, 2r+1.
//   CAN (node 6 = the address): TPDO1 = COB-ID 0x180 + 6 = 0x186 with input octets 0..7, so
//   12 34 00 00 00 00 00 00 before any write; RPDO1 = 0x200 + 6 = 0x206 writes output octets 0..7.
// Every client waits (20 s at most, wall clock, only an upper bound) for the slave to reach data
// exchange — until the read gives the constant — then writes, then reads the echo back; the
// final JSON report's dp_slaves[0].outputs shows what the slave received.
#include <arpa/inet.h>
#include <gtest/gtest.h>
#include <netinet/in.h>
#include <signal.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>
#include <fcntl.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <string>
#include <thread>
#include "loopback_support.hpp"

namespace {

using pbvbus::test::shell;
using pbvbus::test::read_file;
using pbvbus::test::free_port;
using pbvbus::test::can_connect;

using namespace std::chrono_literals;

constexpr const char* kPython = "/usr/bin/python3";
const std::string kBinary = PBVBUS_BINARY_DIR "/bin/pbvbus";
const std::string kGsd = PBVBUS_SOURCE_DIR "/examples/gsd/PBVB0A04.gsd";

bool have(const std::string& program) { return shell("command -v " + program + " >/dev/null").first == 0; }
bool python_has(const std::string& module) {
  return ::access(kPython, X_OK) == 0 &&
         shell(std::string(kPython) + " -c 'import " + module + "' >/dev/null").first == 0;
}

/// `pbvbus run scenario --json --quiet` in a temp directory, ended with SIGINT (a user's Ctrl-C).
class PbvbusRun {
 public:
  PbvbusRun() {
    char tmpl[] = "/tmp/pbvbus-gw-XXXXXX";
    dir = ::mkdtemp(tmpl);
    modbus = free_port();
    slcan = free_port();
    socketcand = free_port();
  }
  ~PbvbusRun() {
    stop();
    shell("rm -rf " + dir);
  }

  /// Starts the run; true once every door answers (20 s at most).
  bool start() {
    std::ofstream(dir + "/gw.textproto") << scenario();
    m_pid = ::fork();
    if (m_pid == 0) {
      if (::chdir(dir.c_str()) != 0) ::_exit(127);
      const int out = ::open("report.json", O_WRONLY | O_CREAT | O_TRUNC, 0644);
      const int err = ::open("stderr.txt", O_WRONLY | O_CREAT | O_TRUNC, 0644);
      ::dup2(out, 1);
      ::dup2(err, 2);
      ::execl(kBinary.c_str(), "pbvbus", "run", "gw.textproto", "--json", "--quiet",
              static_cast<char*>(nullptr));
      ::_exit(127);
    }
    const auto deadline = std::chrono::steady_clock::now() + 20s;
    while (std::chrono::steady_clock::now() < deadline) {
      struct stat st;
      if (::lstat((dir + "/ttyMB0").c_str(), &st) == 0 && ::lstat((dir + "/ttyCAN0").c_str(), &st) == 0 &&
          can_connect(modbus) && can_connect(slcan) && can_connect(socketcand))
        return true;
      int status = 0;
      if (::waitpid(m_pid, &status, WNOHANG) == m_pid) {
        m_pid = -1;
        return false;
      }
      std::this_thread::sleep_for(50ms);
    }
    return false;
  }

  /// Ends the run (SIGINT) and returns its JSON report.
  std::string stop() {
    pbvbus::test::end_child(m_pid, true, 20s);
    m_pid = -1;
    return read_file(dir + "/report.json");
  }
  std::string stderr_text() const { return read_file(dir + "/stderr.txt"); }

  /// The final report's outputs of slave 6 as the slave itself received them.
  std::string slave_outputs(const std::string& report) const {
    std::ofstream(dir + "/report.json") << report;
    return shell(std::string(kPython) +
                 " -c 'import json,sys; r=json.load(open(sys.argv[1])); "
                 "print([s[\"outputs\"] for s in r[\"dp_slaves\"] if s[\"address\"]==6][0])' " +
                 dir + "/report.json")
        .second;
  }

  std::string dir;
  std::uint16_t modbus = 0, slcan = 0, socketcand = 0;

 private:
  std::string scenario() const {
    std::ostringstream s;
    s << "name: \"gw-clients\"\nduration: \"10min\"\nline { name: \"L\" }\n"
         "dp_master { address: 1 line: \"L\" }\n"
         "dp_slave { address: 6 line: \"L\" gsd: \"" << kGsd << "\" master: 1 inputs: ECHO\n"
         "  io { module_index: 0 offset: 0 width: 2 constant { value: 4660 } } }\n"
         "gateway { name: \"gw\" line: \"L\" master: 1\n"
         "  modbus_tcp { listen: \"127.0.0.1:" << modbus << "\" }\n"
         "  modbus_rtu { link: \"ttyMB0\" baud: 115200 }\n"
         "  can { slcan_pty { link: \"ttyCAN0\" } slcan_tcp { listen: \"127.0.0.1:" << slcan
      << "\" }\n        socketcand { listen: \"127.0.0.1:" << socketcand << "\" } } }\n";
    return s.str();
  }
  pid_t m_pid = -1;
};

// 32 output octets as the report prints them, with `a b` at octets 2k, 2k+1.
std::string outputs_with(std::size_t k, const char* a, const char* b) {
  std::string s;
  for (std::size_t i = 0; i < 32; ++i) {
    if (i) s += " ";
    s += i == 2 * k ? a : i == 2 * k + 1 ? b : "00";
  }
  return s + "\n";
}

// ---- mbpoll ---------------------------------------------------------------------------------

/// mbpoll reads input register `r` of unit 6 (hex) until it shows `want` (20 s at most).
std::string mbpoll_until(const std::string& target, int r, const std::string& want) {
  return shell("for i in $(seq 100); do out=$(mbpoll " + target + " -a 6 -t 3:hex -0 -r " +
               std::to_string(r) + " -c 1 -1 2>&1); case \"$out\" in *\"[" + std::to_string(r) +
               "]: \t" + want + "\"*) break;; esac; sleep 0.2; done; echo \"$out\"")
      .second;
}

void mbpoll_test(PbvbusRun& run, const std::string& target) {
  // Read: input register 0 = 0x1234 (the constant).
  EXPECT_NE(mbpoll_until(target, 0, "0x1234").find("[0]: \t0x1234"), std::string::npos);
  // Write holding register 1 = 48879 = 0xBEEF: output octets 2, 3 = BE EF (FC06).
  const auto [rc, out] = shell("mbpoll " + target + " -a 6 -t 4 -0 -r 1 -1 48879");
  EXPECT_EQ(rc, 0) << out;
  // The slave echoes them: input register 1 = 0xBEEF.
  EXPECT_NE(mbpoll_until(target, 1, "0xBEEF").find("[1]: \t0xBEEF"), std::string::npos);
  EXPECT_EQ(run.slave_outputs(run.stop()), outputs_with(1, "BE", "EF")) << run.stderr_text();
}

TEST(GatewayClients, MbpollOverModbusTcp) {
  if (!have("mbpoll")) GTEST_SKIP() << "mbpoll is not installed (Debian: apt-get install mbpoll)";
  PbvbusRun run;
  ASSERT_TRUE(run.start()) << run.stderr_text();
  mbpoll_test(run, "-m tcp -p " + std::to_string(run.modbus) + " 127.0.0.1");
}

TEST(GatewayClients, MbpollOverModbusRtuOnThePty) {
  if (!have("mbpoll")) GTEST_SKIP() << "mbpoll is not installed (Debian: apt-get install mbpoll)";
  PbvbusRun run;
  ASSERT_TRUE(run.start()) << run.stderr_text();
  mbpoll_test(run, "-m rtu -b 115200 -P none " + run.dir + "/ttyMB0");
}

// ---- pymodbus ---------------------------------------------------------------------------------

// Reads input register 0 until 4660, writes holding register 2 = 0xCAFE = 51966 (output octets
// 4, 5 = CA FE, FC06), reads input register 2 until the echo shows it.
constexpr const char* kPymodbus = R"(
import sys, time
def run(c):
    c.connect()
    def ir(a):
        r = c.read_input_registers(a, 1, slave=6)
        return None if r.isError() else r.registers
    end = time.time() + 20
    v = ir(0)
    while v != [4660] and time.time() < end:
        time.sleep(0.1); v = ir(0)
    print('read', v)
    w = c.write_register(2, 0xCAFE, slave=6)
    print('write', not w.isError())
    v = ir(2)
    while v != [51966] and time.time() < end:
        time.sleep(0.1); v = ir(2)
    print('echo', v)
    c.close()
)";

void pymodbus_test(PbvbusRun& run, const std::string& client) {
  std::ofstream(run.dir + "/client.py") << kPymodbus << client << "\n";
  const auto [rc, out] = shell(std::string(kPython) + " " + run.dir + "/client.py");
  EXPECT_EQ(rc, 0) << out;
  EXPECT_NE(out.find("read [4660]"), std::string::npos) << out;
  EXPECT_NE(out.find("write True"), std::string::npos) << out;
  EXPECT_NE(out.find("echo [51966]"), std::string::npos) << out;
  EXPECT_EQ(run.slave_outputs(run.stop()), outputs_with(2, "CA", "FE")) << run.stderr_text();
}

TEST(GatewayClients, PymodbusOverModbusTcp) {
  if (!python_has("pymodbus")) GTEST_SKIP() << "/usr/bin/python3 has no pymodbus (python3-pymodbus)";
  PbvbusRun run;
  ASSERT_TRUE(run.start()) << run.stderr_text();
  pymodbus_test(run, "from pymodbus.client import ModbusTcpClient\nrun(ModbusTcpClient('127.0.0.1', port=" +
                         std::to_string(run.modbus) + "))");
}

TEST(GatewayClients, PymodbusOverModbusRtuOnThePty) {
  if (!python_has("pymodbus")) GTEST_SKIP() << "/usr/bin/python3 has no pymodbus (python3-pymodbus)";
  if (!python_has("serial")) GTEST_SKIP() << "/usr/bin/python3 has no serial (python3-serial)";
  PbvbusRun run;
  ASSERT_TRUE(run.start()) << run.stderr_text();
  pymodbus_test(run, "from pymodbus.client import ModbusSerialClient\nrun(ModbusSerialClient('" +
                         run.dir + "/ttyMB0', baudrate=115200, parity='N'))");
}

// ---- python-can -------------------------------------------------------------------------------

// Waits for TPDO1 of node 6 (0x186), sends RPDO1 (0x206) = 00 00 AB CD 00 00 00 00 (output
// octets 2, 3 = AB CD), waits for a TPDO1 with the echo: 12 34 AB CD 00 00 00 00.
constexpr const char* kPythonCan = R"(
import time, can
def run(bus):
    end = time.time() + 20
    first = None
    while first is None and time.time() < end:
        m = bus.recv(0.5)
        # (python-can 4.1's socketcand backend marks every received frame extended)
        if m is not None and m.arbitration_id == 0x186:
            first = m
    print('first', first.data.hex() if first else None, first.dlc if first else None)
    bus.send(can.Message(arbitration_id=0x206, is_extended_id=False,
                         data=[0, 0, 0xAB, 0xCD, 0, 0, 0, 0]))
    after = None
    while after is None and time.time() < end:
        m = bus.recv(0.5)
        if m is not None and m.arbitration_id == 0x186 and bytes(m.data[2:4]) == b'\xab\xcd':
            after = m
    print('after', after.data.hex() if after else None)
    bus.shutdown()
)";

void python_can_test(PbvbusRun& run, const std::string& bus) {
  std::ofstream(run.dir + "/client.py") << kPythonCan << "run(can.Bus(" << bus << "))\n";
  const auto [rc, out] = shell(std::string(kPython) + " " + run.dir + "/client.py");
  EXPECT_EQ(rc, 0) << out;
  EXPECT_NE(out.find("first 1234000000000000 8"), std::string::npos) << out;
  EXPECT_NE(out.find("after 1234abcd00000000"), std::string::npos) << out;
  EXPECT_EQ(run.slave_outputs(run.stop()), outputs_with(1, "AB", "CD")) << run.stderr_text();
}

TEST(GatewayClients, PythonCanOverSlcanOnThePty) {
  if (!python_has("can")) GTEST_SKIP() << "/usr/bin/python3 has no can (python3-can)";
  PbvbusRun run;
  ASSERT_TRUE(run.start()) << run.stderr_text();
  python_can_test(run, "interface='slcan', channel='" + run.dir +
                           "/ttyCAN0', bitrate=500000, sleep_after_open=0.1");
}

TEST(GatewayClients, PythonCanOverSlcanTcp) {
  if (!python_has("can")) GTEST_SKIP() << "/usr/bin/python3 has no can (python3-can)";
  PbvbusRun run;
  ASSERT_TRUE(run.start()) << run.stderr_text();
  python_can_test(run, "interface='slcan', channel='socket://127.0.0.1:" + std::to_string(run.slcan) +
                           "', bitrate=500000, sleep_after_open=0.1");
}

TEST(GatewayClients, PythonCanOverSocketcand) {
  if (!python_has("can")) GTEST_SKIP() << "/usr/bin/python3 has no can (python3-can)";
  PbvbusRun run;
  ASSERT_TRUE(run.start()) << run.stderr_text();
  python_can_test(run, "interface='socketcand', channel='can0', host='127.0.0.1', port=" +
                           std::to_string(run.socketcand));
}

}  // namespace
