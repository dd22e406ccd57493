// Unmodified third-party clients against the CAN doors: python-can 4.1 (Debian's
// /usr/bin/python3, interfaces slcan over a pty and over TCP, and socketcand) and can-utils'
// cansend/candump on vcan0 through SocketcanDoor. Each client sends a frame the test's hub port
// must see (exact id and data), and receives a frame the test port sends (exact id and data,
// printed by the client and asserted here). The bus runs paced (Scheduler + PacedRunner) on the
// test thread; each client is a child process. Wall-clock waits are only generous upper bounds.
#include <fcntl.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <gtest/gtest.h>

#include <chrono>
#include <functional>
#include <string>
#include <vector>

#include "can_door_test_support.hpp"
#include "pbvbus/gateways/slcan_door.hpp"
#include "pbvbus/gateways/socketcan_door.hpp"
#include "pbvbus/gateways/socketcand_door.hpp"

extern char** environ;

namespace pbvbus::gateways {
namespace {

using namespace std::chrono_literals;

/// A child process whose stdout and stderr go to a pipe the test reads without blocking.
class Child {
 public:
  explicit Child(const std::vector<std::string>& argv) {
    int p[2];
    if (::pipe2(p, O_CLOEXEC) != 0) return;
    posix_spawn_file_actions_t fa;
    posix_spawn_file_actions_init(&fa);
    posix_spawn_file_actions_adddup2(&fa, p[1], 1);
    posix_spawn_file_actions_adddup2(&fa, p[1], 2);
    std::vector<char*> args;
    for (const auto& a : argv) args.push_back(const_cast<char*>(a.c_str()));
    args.push_back(nullptr);
    if (::posix_spawn(&m_pid, args[0], &fa, nullptr, args.data(), environ) != 0) m_pid = -1;
    posix_spawn_file_actions_destroy(&fa);
    ::close(p[1]);
    m_out = p[0];
    ::fcntl(m_out, F_SETFL, O_NONBLOCK);
  }
  ~Child() {
    if (m_pid > 0 && !m_done) {
      ::kill(m_pid, SIGKILL);
      ::waitpid(m_pid, nullptr, 0);
    }
    if (m_out >= 0) ::close(m_out);
  }
  /// Collects output; true once the child has exited.
  bool poll() {
    char buf[1024];
    for (ssize_t n; (n = ::read(m_out, buf, sizeof buf)) > 0;) m_text.append(buf, static_cast<std::size_t>(n));
    if (m_pid <= 0) return true;
    if (!m_done && ::waitpid(m_pid, &m_status, WNOHANG) == m_pid) m_done = true;
    return m_done;
  }
  bool ok() const { return m_done && WIFEXITED(m_status) && WEXITSTATUS(m_status) == 0; }
  const std::string& output() const { return m_text; }

 private:
  pid_t m_pid = -1;
  int m_out = -1;
  int m_status = 0;
  bool m_done = false;
  std::string m_text;
};

/// Runs a program to completion (a few seconds at most) and returns its exit status.
int run_quick(const std::vector<std::string>& argv) {
  Child c(argv);
  const auto end = std::chrono::steady_clock::now() + 30s;
  while (!c.poll() && std::chrono::steady_clock::now() < end) ::usleep(10'000);
  return c.ok() ? 0 : 1;
}

std::string python_can_missing() {
  if (::access("/usr/bin/python3", X_OK) != 0) return "/usr/bin/python3 is not installed";
  if (run_quick({"/usr/bin/python3", "-c", "import can, serial"}) != 0)
    return "python3-can / python3-serial are not installed for /usr/bin/python3";
  return {};
}

/// The shared rig whose test port answers the client's frame 0x205 with `answer`.
struct Rig : can_test::Rig {
  CanFrame answer;  // sent once the client's frame 0x205 has arrived

  explicit Rig(CanFrame reply) : answer(reply) {
    on_frame = [this](const CanFrame& f, bus::Ticks now) {
      if (f.id == 0x205)  // reply on the bus's own time line, not from inside the delivery
        sched.schedule(now, [this] { hub.send(me, answer, sched.now()); });
    };
  }

  /// Runs the bus until the child exits (or a generous bound); returns its output.
  std::string run_client(Child& c) {
    const auto end = std::chrono::steady_clock::now() + 60s;
    while (!c.poll() && std::chrono::steady_clock::now() < end) runner.run_for(5 * bus::kTicksPerMs);
    return c.output();
  }
};

using can_test::frame;

// The client: sends 0x205 [AA BB] (standard) and 0x18FF0001 [01 02 03] (extended), then waits
// (up to 10 s) for the frame with id 0x123 and prints it as "RX <id hex> <data hex>".
constexpr const char* kClientScript = R"PY(
import sys, time, can
kind, channel = sys.argv[1], sys.argv[2]
if kind == 'socketcand':
    bus = can.Bus(interface='socketcand', channel=channel, host=sys.argv[3], port=int(sys.argv[4]))
else:
    bus = can.Bus(interface='slcan', channel=channel, bitrate=500000, sleep_after_open=0.1)
bus.send(can.Message(arbitration_id=0x205, data=[0xAA, 0xBB], is_extended_id=False))
bus.send(can.Message(arbitration_id=0x18FF0001, data=[1, 2, 3], is_extended_id=True))
end = time.time() + 10
while time.time() < end:
    m = bus.recv(0.5)
    if m is not None and m.arbitration_id == 0x123:
        print('RX %X %s' % (m.arbitration_id, m.data.hex().upper()), flush=True)
        break
bus.shutdown()
)PY";

void expect_exchange(Rig& rig, const std::string& out) {
  EXPECT_EQ(rig.seen, (std::vector<CanFrame>{frame(0x205, false, {0xAA, 0xBB}),
                                             frame(0x18FF0001, true, {0x01, 0x02, 0x03})}))
      << out;
  EXPECT_NE(out.find("RX 123 4243"), std::string::npos) << out;
}

TEST(CanClients, PythonCanSlcanOverPty) {
  if (auto why = python_can_missing(); !why.empty()) GTEST_SKIP() << why;
  Rig rig(frame(0x123, false, {0x42, 0x43}));
  SlcanDoor::Options o;
  o.tcp = false;
  SlcanDoor door(rig.runner, rig.hub, o);
  if (auto err = door.open(); !err.empty()) GTEST_SKIP() << "no pty: " << err;
  Child c({"/usr/bin/python3", "-c", kClientScript, "slcan", door.pty_path()});
  const std::string out = rig.run_client(c);
  EXPECT_TRUE(c.ok()) << out;
  expect_exchange(rig, out);
  EXPECT_EQ(door.stats().errors, 0u) << out;
}

TEST(CanClients, PythonCanSlcanOverTcp) {
  if (auto why = python_can_missing(); !why.empty()) GTEST_SKIP() << why;
  Rig rig(frame(0x123, false, {0x42, 0x43}));
  SlcanDoor::Options o;
  o.pty = false;
  SlcanDoor door(rig.runner, rig.hub, o);
  ASSERT_EQ(door.open(), "");
  Child c({"/usr/bin/python3", "-c", kClientScript, "slcan",
           "socket://127.0.0.1:" + std::to_string(door.port())});
  const std::string out = rig.run_client(c);
  EXPECT_TRUE(c.ok()) << out;
  expect_exchange(rig, out);
  EXPECT_EQ(door.stats().clients_total, 1u);
}

TEST(CanClients, PythonCanSocketcand) {
  if (auto why = python_can_missing(); !why.empty()) GTEST_SKIP() << why;
  Rig rig(frame(0x123, false, {0x42, 0x43}));
  SocketcandDoor::Options o;
  o.port = 0;
  SocketcandDoor door(rig.runner, rig.hub, o);
  ASSERT_EQ(door.open(), "");
  Child c({"/usr/bin/python3", "-c", kClientScript, "socketcand", "can0", "127.0.0.1",
           std::to_string(door.port())});
  const std::string out = rig.run_client(c);
  EXPECT_TRUE(c.ok()) << out;
  expect_exchange(rig, out);
  EXPECT_EQ(door.stats().errors, 0u) << out;
}

TEST(CanClients, CansendAndCandumpOnVcan0) {
  Rig rig(frame(0x123, false, {0x42, 0x43}));
  SocketcanDoor door(rig.runner, rig.hub, SocketcanDoor::Options{});
  if (auto err = door.open(); !err.empty())
    GTEST_SKIP() << "SocketcanDoor cannot open vcan0 here (" << err
                 << "); needs a kernel with AF_CAN and `ip link add vcan0 type vcan`";
  for (const char* tool : {"/usr/bin/cansend", "/usr/bin/candump"})
    if (::access(tool, X_OK) != 0) GTEST_SKIP() << tool << " is not installed (can-utils)";
  // candump waits for one frame (-n 1), then cansend puts 0x205 on vcan0; the door carries it
  // to the hub, the test port answers 0x123, and the door writes that to vcan0 for candump.
  Child dump({"/usr/bin/candump", "-L", "-n", "1", "vcan0,123:7FF"});
  rig.runner.run_for(100 * bus::kTicksPerMs);
  Child send({"/usr/bin/cansend", "vcan0", "205#AABB"});
  const std::string out = rig.run_client(dump);
  EXPECT_EQ(rig.seen.at(0), frame(0x205, false, {0xAA, 0xBB}));
  EXPECT_NE(out.find("vcan0 123#4243"), std::string::npos) << out;
}

}  // namespace
}  // namespace pbvbus::gateways
