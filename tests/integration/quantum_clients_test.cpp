// End-to-end: `pbvbus run` (the binary, a child process, paced) on a Quantum Hot Standby pair
// whose primary fails, polled by unmodified Debian Modbus clients — mbpoll and /usr/bin/python3
// pymodbus — over the pair's Modbus TCP door and over RTU on its pty (docs/quantum-hsby.md,
// docs/quantum-hsby-modbus.md "The port/network model").
//
// The scenario: tests/integration/data/quantum_clients.textproto.in, the pair of
// examples/quantum-hsby.textproto with one fault: rack 0 (designation A, the primary) loses
// power at 1.5 s and gets it back at 3 s; 4.5 s in all. Modbus port 1 of both racks is one
// network: the primary answers unit 1, the other rack unit 1 + 128 = 129, swapped at every
// switchover (seed 003 p. 93).
//
// What a client reads, worked out by hand from docs/quantum-hsby.md:
//   - holding register 400012 (PDU address 11, mbpoll -r 12) is the non-transfer area's third
//     register (area 400010..400013), each unit's own status register (seed pp. 78, 81, 95):
//     Modicon bits 15-16 = the two least significant bits = this unit, 01 offline, 10 primary,
//     11 standby; Modicon bit 11 = 0x0020 = the designation switch at B (rack 1), 0 at A (rack 0).
//     So (word & 3) == 2 is a primary, == 3 a standby, and (word & 0x20) tells which rack.
//   - holding register 400100 (PDU address 99, mbpoll -r 100) is logic.counter: + 1 at every
//     primary scan. The standby holds what the last completed transfer carried (the primary's
//     state RAM at the start of that scan), and a transfer in flight at the failure is lost; the
//     new primary's first scan adds 1 before any host can read it. So across the takeover the
//     counter a host reads at unit 1 goes back by at most one scan's step (1), never more, and
//     keeps counting; at any other time it never goes back.
//   - the takeover window: from the failure until the standby's first scan as primary nobody
//     holds address 1. Behind the TCP door (an Ethernet module in front of the network) a
//     request for unit 1 then gets exception 0x0B (gateway target device failed to respond); on
//     the RTU line it goes unanswered (the client's time-out). The window is bounded by the
//     report's takeover time (switchovers[].takeover_ns = at_ns - cause_ns <= one scan,
//     asserted below from the JSON report): these are the only failures allowed at unit 1, and
//     they must lie between the last answer of the old primary (rack A) and the first of the
//     new one (rack B). Before the first answer at all (the run is still starting) errors are
//     only waited through.
//   - unit 129: rack B as standby before the failure; nobody after it (rack A has no power:
//     0x0B over TCP, no answer over RTU); rack A again once it is back (offline for the instant
//     it takes to rejoin, then standby).
// The clients poll from the moment the doors are open until they have seen unit 129 answered by
// rack A as standby again, plus five rounds and until the counter at unit 1 has gone up by two
// more; then the test ends the run (SIGINT; its duration
// is raised to 30 s, an upper bound only) and reads its JSON report. Assertions are on the order
// of what the clients saw, never on wall-clock times.
#include <gtest/gtest.h>
#include <fcntl.h>
#include <signal.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "loopback_support.hpp"

namespace {

using pbvbus::test::free_port;
using pbvbus::test::read_file;
using pbvbus::test::shell;
using namespace std::chrono_literals;

constexpr const char* kQcPython = "/usr/bin/python3";
const std::string kQcBinary = PBVBUS_BINARY_DIR "/bin/pbvbus";
const std::string kQcTemplate = PBVBUS_SOURCE_DIR "/tests/integration/data/quantum_clients.textproto.in";

bool qc_have(const std::string& program) { return shell("command -v " + program + " >/dev/null").first == 0; }
bool qc_python_has(const std::string& module) {
  return ::access(kQcPython, X_OK) == 0 &&
         shell(std::string(kQcPython) + " -c 'import " + module + "' >/dev/null").first == 0;
}

std::string qc_replace_all(std::string s, const std::string& from, const std::string& to) {
  for (std::size_t at = s.find(from); at != std::string::npos; at = s.find(from, at + to.size()))
    s.replace(at, from.size(), to);
  return s;
}

/// `pbvbus run quantum.textproto --json --quiet` (paced: the scenario has Modbus doors) in a
/// temp directory; the JSON report lands in report.json when the run ends (4.5 s).
class QcRun {
 public:
  QcRun() {
    char tmpl[] = "/tmp/pbvbus-qc-XXXXXX";
    dir = ::mkdtemp(tmpl);
    tcp = free_port();
  }
  ~QcRun() {
    kill_run();
    shell("rm -rf " + dir);
  }
  QcRun(const QcRun&) = delete;
  QcRun& operator=(const QcRun&) = delete;

  /// Starts the run; true once the TCP door accepts and the pty link exists (20 s at most).
  /// `duration`: empty for the scenario's 4.5 s, or an upper bound ("30s") for a run that the
  /// test ends with SIGINT (a user's Ctrl-C) once its client has seen everything.
  bool start(const std::string& duration = {}) {
    std::string text = read_file(kQcTemplate);
    text = qc_replace_all(text, "@TCP_PORT@", std::to_string(tcp));
    text = qc_replace_all(text, "@SOURCE_DIR@", PBVBUS_SOURCE_DIR);
    std::ofstream(dir + "/quantum.textproto") << text;
    m_pid = ::fork();
    if (m_pid == 0) {
      if (::chdir(dir.c_str()) != 0) ::_exit(127);
      const int out = ::open("report.json", O_WRONLY | O_CREAT | O_TRUNC, 0644);
      const int err = ::open("stderr.txt", O_WRONLY | O_CREAT | O_TRUNC, 0644);
      ::dup2(out, 1);
      ::dup2(err, 2);
      if (duration.empty())
        ::execl(kQcBinary.c_str(), "pbvbus", "run", "quantum.textproto", "--json", "--quiet",
                static_cast<char*>(nullptr));
      else
        ::execl(kQcBinary.c_str(), "pbvbus", "run", "quantum.textproto", "--json", "--quiet", "--duration",
                duration.c_str(), static_cast<char*>(nullptr));
      ::_exit(127);
    }
    const auto deadline = std::chrono::steady_clock::now() + 20s;
    while (std::chrono::steady_clock::now() < deadline) {
      struct stat st;
      const std::string err = stderr_text();
      if (::lstat((dir + "/ttyQMB1").c_str(), &st) == 0 &&
          err.find("127.0.0.1:" + std::to_string(tcp)) != std::string::npos &&
          pbvbus::test::can_connect(tcp))
        return true;
      int status = 0;
      if (::waitpid(m_pid, &status, WNOHANG) == m_pid) {
        m_pid = -1;
        return false;
      }
      std::this_thread::sleep_for(20ms);
    }
    return false;
  }

  /// Ends the run with SIGINT if `interrupt`, waits for its end (30 s at most) and returns its
  /// JSON report.
  std::string wait_report(bool interrupt = false) {
    pbvbus::test::end_child(m_pid, interrupt, 30s);
    m_pid = -1;
    return read_file(dir + "/report.json");
  }
  std::string stderr_text() const { return read_file(dir + "/stderr.txt"); }

  /// A Python expression over the JSON report `r`, printed.
  std::string json(const std::string& expr) const {
    return shell(std::string(kQcPython) + " -c 'import json,sys; r=json.load(open(sys.argv[1])); print(" +
                 expr + ")' " + dir + "/report.json")
        .second;
  }

  std::string dir;
  std::uint16_t tcp = 0;

 private:
  void kill_run() {
    if (m_pid > 0) {
      ::kill(m_pid, SIGKILL);
      int status = 0;
      ::waitpid(m_pid, &status, 0);
      m_pid = -1;
    }
  }
  pid_t m_pid = -1;
};

// ---- what the clients saw ----------------------------------------------------------------------

/// One poll: a unit read its status register 400012 (and counter 400100), or failed.
struct QcPoll {
  int unit = 0;
  bool ok = false;
  unsigned status = 0;
  unsigned counter = 0;
  std::string error;
};

/// Lines "U<unit> OK <status> <counter>" (numbers in C syntax: 0x.. or decimal) or
/// "U<unit> ERR <text>".
std::vector<QcPoll> qc_parse(const std::string& out) {
  std::vector<QcPoll> polls;
  std::istringstream in(out);
  std::string line;
  while (std::getline(in, line)) {
    std::istringstream l(line);
    std::string u, what;
    if (!(l >> u >> what) || u.size() < 2 || u[0] != 'U') continue;
    QcPoll p;
    p.unit = std::atoi(u.c_str() + 1);
    if (what == "OK") {
      std::string s, c;
      l >> s >> c;
      p.ok = true;
      p.status = static_cast<unsigned>(std::stoul(s, nullptr, 0));
      p.counter = c.empty() ? 0 : static_cast<unsigned>(std::stoul(c, nullptr, 0));
    } else if (what == "ERR") {
      std::getline(l, p.error);
    } else {
      continue;
    }
    polls.push_back(p);
  }
  return polls;
}

constexpr unsigned kQcPrimary = 2;  // status "10"
constexpr unsigned kQcStandby = 3;  // status "11"
constexpr unsigned kQcOffline = 1;  // status "01"
char qc_rack(unsigned status) { return (status & 0x20) != 0 ? 'B' : 'A'; }

/// Unit 1 across the primary failure: see the file comment. `window_error` is the text the
/// client shows for a request nobody answers (0x0B or a time-out).
void qc_check_unit1(const std::vector<QcPoll>& all, const std::string& window_error, const std::string& out) {
  std::vector<QcPoll> u;
  for (const auto& p : all)
    if (p.unit == 1) u.push_back(p);
  // Skip the start (no answer yet).
  std::size_t i = 0;
  while (i < u.size() && !u[i].ok) ++i;
  ASSERT_LT(i, u.size()) << "unit 1 never answered\n" << out;
  std::size_t last_a = u.size(), first_b = u.size();
  for (std::size_t k = i; k < u.size(); ++k) {
    if (!u[k].ok) continue;
    // Every answer at unit 1 is a primary's.
    EXPECT_EQ(u[k].status & 3, kQcPrimary) << "poll " << k << " status " << u[k].status << "\n" << out;
    if (qc_rack(u[k].status) == 'A') {
      EXPECT_EQ(first_b, u.size()) << "rack A answered unit 1 after rack B (poll " << k << ")\n" << out;
      last_a = k;
    } else if (first_b == u.size()) {
      first_b = k;
    }
  }
  ASSERT_LT(last_a, u.size()) << "rack A never answered unit 1 before the failure\n" << out;
  ASSERT_LT(first_b, u.size()) << "rack B never answered unit 1 after the takeover\n" << out;
  // Failures only inside the takeover window, and of the documented kind.
  for (std::size_t k = i; k < u.size(); ++k) {
    if (u[k].ok) continue;
    EXPECT_TRUE(k > last_a && k < first_b) << "unit 1 failed outside the takeover window (poll " << k
                                           << "): " << u[k].error << "\n" << out;
    EXPECT_NE(u[k].error.find(window_error), std::string::npos) << u[k].error;
  }
  // The counter: never back, except by one scan's step (1) at the takeover; counting on after.
  unsigned prev = 0;
  bool have_prev = false;
  for (std::size_t k = i; k < u.size(); ++k) {
    if (!u[k].ok) continue;
    if (have_prev) {
      if (k == first_b)
        EXPECT_GE(u[k].counter + 1, prev) << "the counter went back by more than one scan at the takeover\n" << out;
      else
        EXPECT_GE(u[k].counter, prev) << "the counter went back at poll " << k << "\n" << out;
    }
    prev = u[k].counter;
    have_prev = true;
  }
  EXPECT_GT(u.back().ok ? u.back().counter : prev, u[first_b].counter) << "no counting after the takeover\n" << out;
}

/// Unit 129: rack B as standby, then nobody (rack A without power), then rack A again (offline
/// for as long as it takes to rejoin, then standby).
void qc_check_unit129(const std::vector<QcPoll>& all, const std::string& window_error, const std::string& out) {
  // The phases in order: 0 start (errors, a rack offline), 1 B standby, 2 unanswered,
  // 3 A offline or standby; the phase never goes back.
  int phase = 0;
  bool saw[4] = {false, false, false, false};
  bool a_standby = false;
  for (const auto& p : all) {
    if (p.unit != 129) continue;
    int now;
    if (!p.ok) {
      now = phase <= 0 ? 0 : 2;
      if (now == 2) {
        EXPECT_NE(p.error.find(window_error), std::string::npos) << p.error;
      }
    } else if (qc_rack(p.status) == 'B') {
      EXPECT_TRUE((p.status & 3) == kQcStandby || ((p.status & 3) == kQcOffline && phase == 0))
          << "unit 129 answered by rack B with status " << p.status << "\n" << out;
      now = (p.status & 3) == kQcStandby ? 1 : 0;
    } else if (phase == 0 && (p.status & 3) == kQcOffline) {
      now = 0;  // rack A powering up at 0 s, before it is primary (not seen so far)
    } else {
      EXPECT_TRUE((p.status & 3) == kQcStandby || (p.status & 3) == kQcOffline)
          << "unit 129 answered by rack A with status " << p.status << "\n" << out;
      a_standby |= (p.status & 3) == kQcStandby;
      EXPECT_FALSE(a_standby && (p.status & 3) == kQcOffline) << "rack A left standby again\n" << out;
      now = 3;
    }
    EXPECT_GE(now, phase) << "unit 129 went back from phase " << phase << " to " << now << "\n" << out;
    phase = std::max(phase, now);
    saw[now] = true;
  }
  EXPECT_TRUE(saw[1]) << "unit 129 never answered by rack B as standby before the failure\n" << out;
  EXPECT_TRUE(saw[2]) << "unit 129 answered throughout the failure\n" << out;
  EXPECT_TRUE(a_standby) << "unit 129 never answered by rack A as standby after its repair\n" << out;
}

/// The run's report of one switchover, rack 0 -> rack 1, within one scan, addresses swapped.
void qc_check_report(QcRun& run) {
  const std::string report = run.wait_report(true);
  ASSERT_FALSE(report.empty()) << run.stderr_text();
  EXPECT_EQ(run.json("len(r[\"quantum\"][0][\"switchovers\"])"), "1\n") << report;
  EXPECT_EQ(run.json("[(s[\"from\"], s[\"to\"]) for s in r[\"quantum\"][0][\"switchovers\"]]"), "[(0, 1)]\n");
  EXPECT_EQ(run.json("r[\"quantum\"][0][\"modbus\"][0][\"conflicts\"]"), "0\n");
}

// ---- mbpoll -------------------------------------------------------------------------------------

/// mbpoll reads holding registers 12..100 (400012 status .. 400100 counter) of unit 1, then
/// register 12 of unit 129, over and over, until it has seen unit 129 answered by rack A as
/// standby (status & 0x23 == 3: this unit 11, designation A), polled five rounds more and seen
/// the counter go up by two since (30 s at most). Time-out 0.3 s.
std::string qc_mbpoll(QcRun& run, const std::string& target) {
  const std::string script =
      "poll() {\n"
      "  out=$(mbpoll " + target + " -a $1 -t 4:hex -r 12 -c $2 -o 0.3 -1 2>&1)\n"
      "  s=$(printf '%s\\n' \"$out\" | sed -n 's/^\\[12\\]:[[:space:]]*//p')\n"
      "  c=$(printf '%s\\n' \"$out\" | sed -n 's/^\\[100\\]:[[:space:]]*//p')\n"
      "  if [ -n \"$s\" ]; then echo \"U$1 OK $s $c\"\n"
      "  else s=; c=; echo \"U$1 ERR $(printf '%s\\n' \"$out\" | grep -i 'fail\\|error\\|timed' | head -1)\"; fi\n"
      "}\n"
      "end=$(( $(date +%s) + 30 )); more=-1; c0=0\n"
      "while [ $(date +%s) -lt $end ]; do\n"
      "  poll 1 89; c1=$c; poll 129 1\n"
      "  if [ \"$more\" -lt 0 ]; then\n"
      "    if [ -n \"$s\" ] && [ $(( s & 0x23 )) = 3 ]; then more=5; c0=$((${c1:-0})); fi\n"
      "  elif [ \"$more\" -gt 0 ]; then more=$((more - 1))\n"
      "  elif [ -n \"$c1\" ] && [ $((c1)) -gt $((c0 + 1)) ]; then break; fi\n"
      "done\n";
  std::ofstream(run.dir + "/poll.sh") << script;
  return shell("sh " + run.dir + "/poll.sh").second;
}

TEST(QuantumClients, MbpollOverModbusTcpAcrossAPrimaryFailure) {
  if (!qc_have("mbpoll")) GTEST_SKIP() << "mbpoll is not installed (Debian: apt-get install mbpoll)";
  QcRun run;
  ASSERT_TRUE(run.start("30s")) << run.stderr_text();
  const std::string out = qc_mbpoll(run, "-m tcp -p " + std::to_string(run.tcp) + " 127.0.0.1");
  const auto polls = qc_parse(out);
  // libmodbus's text for exception 0x0B (EMBXGTAR).
  qc_check_unit1(polls, "Target device failed to respond", out);
  qc_check_unit129(polls, "Target device failed to respond", out);
  qc_check_report(run);
}

TEST(QuantumClients, MbpollOverModbusRtuOnThePtyAcrossAPrimaryFailure) {
  if (!qc_have("mbpoll")) GTEST_SKIP() << "mbpoll is not installed (Debian: apt-get install mbpoll)";
  QcRun run;
  ASSERT_TRUE(run.start("30s")) << run.stderr_text();
  const std::string out = qc_mbpoll(run, "-m rtu -b 19200 -P none " + run.dir + "/ttyQMB1");
  const auto polls = qc_parse(out);
  qc_check_unit1(polls, "timed out", out);
  qc_check_unit129(polls, "timed out", out);
  qc_check_report(run);
}

// ---- pymodbus -----------------------------------------------------------------------------------

// The same polls with pymodbus 3.0 (Debian 12): read_holding_registers(address, count, slave=),
// and the same end (poll returns the status for unit 129, the counter for unit 1). An exception response prints its code; no answer prints "no answer". (Its
// time-out must be a whole number of seconds: 3.0.0rc1 turns 0.3 into no wait at all.)
constexpr const char* kQcPymodbus = R"(
import sys, time
def run(c):
    c.connect()
    def poll(unit, count):
        try:
            r = c.read_holding_registers(11, count, slave=unit)
        except Exception as e:
            print('U%d ERR no answer (%s)' % (unit, type(e).__name__)); return None
        sys.stdout.flush()
        if not r.isError():
            print('U%d OK %d %d' % (unit, r.registers[0], r.registers[-1] if count > 1 else 0))
            return r.registers[-1] if count > 1 else r.registers[0]
        if hasattr(r, 'exception_code'):
            print('U%d ERR exception 0x%02X' % (unit, r.exception_code))
        else:
            print('U%d ERR no answer (%s)' % (unit, r))
        return None
    end = time.time() + 30
    more, n0 = -1, 0
    while time.time() < end:
        n = poll(1, 89)
        s = poll(129, 1)
        if more < 0:
            if s is not None and s & 0x23 == 3:
                more, n0 = 5, n or 0
        elif more > 0:
            more -= 1
        elif n is not None and n > n0 + 1:
            break
    c.close()
)";

std::string qc_pymodbus(QcRun& run, const std::string& client) {
  std::ofstream(run.dir + "/client.py") << kQcPymodbus << client << "\n";
  return shell(std::string(kQcPython) + " " + run.dir + "/client.py").second;
}

TEST(QuantumClients, PymodbusOverModbusTcpAcrossAPrimaryFailure) {
  if (!qc_python_has("pymodbus")) GTEST_SKIP() << "/usr/bin/python3 has no pymodbus (python3-pymodbus)";
  QcRun run;
  ASSERT_TRUE(run.start("30s")) << run.stderr_text();
  const std::string out = qc_pymodbus(
      run, "from pymodbus.client import ModbusTcpClient\nrun(ModbusTcpClient('127.0.0.1', port=" +
               std::to_string(run.tcp) + ", timeout=1))");
  const auto polls = qc_parse(out);
  qc_check_unit1(polls, "exception 0x0B", out);
  qc_check_unit129(polls, "exception 0x0B", out);
  qc_check_report(run);
}

TEST(QuantumClients, PymodbusOverModbusRtuOnThePtyAcrossAPrimaryFailure) {
  if (!qc_python_has("pymodbus")) GTEST_SKIP() << "/usr/bin/python3 has no pymodbus (python3-pymodbus)";
  if (!qc_python_has("serial")) GTEST_SKIP() << "/usr/bin/python3 has no serial (python3-serial)";
  QcRun run;
  ASSERT_TRUE(run.start("30s")) << run.stderr_text();
  const std::string out = qc_pymodbus(
      run, "from pymodbus.client import ModbusSerialClient\nrun(ModbusSerialClient('" + run.dir +
               "/ttyQMB1', baudrate=19200, parity='N', timeout=1))");
  const auto polls = qc_parse(out);
  qc_check_unit1(polls, "no answer", out);
  qc_check_unit129(polls, "no answer", out);
  qc_check_report(run);
}

// ---- the JSON report ----------------------------------------------------------------------------

// One switchover, rack 0 -> rack 1, caused by the power loss at 1.5 s, taken over within one
// scan (takeover_scans <= 1, takeover_ns = at_ns - cause_ns <= scan_time_ns: the bound of the
// window in which unit 1 has no holder); Modbus port 1: rack 0 at 1 and rack 1 at 129 before,
// rack 0 nowhere (no power: 0) and rack 1 at 1 after.
TEST(QuantumClients, JsonReportShowsTheSwitchoverAndTheSwappedAddresses) {
  QcRun run;
  ASSERT_TRUE(run.start()) << run.stderr_text();
  const std::string report = run.wait_report();
  ASSERT_FALSE(report.empty()) << run.stderr_text();
  const std::string q = "r[\"quantum\"][0]";
  const std::string s = q + "[\"switchovers\"][0]";
  EXPECT_EQ(run.json("len(" + q + "[\"switchovers\"])"), "1\n") << report;
  EXPECT_EQ(run.json(s + "[\"from\"], " + s + "[\"to\"]"), "0 1\n");
  EXPECT_EQ(run.json(s + "[\"cause_ns\"]"), "1500000000\n");
  EXPECT_EQ(run.json(s + "[\"takeover_scans\"] <= 1"), "True\n") << run.json(s + "[\"takeover_scans\"]");
  EXPECT_EQ(run.json(s + "[\"at_ns\"] - " + s + "[\"cause_ns\"] == " + s + "[\"takeover_ns\"]"), "True\n");
  EXPECT_EQ(run.json(s + "[\"takeover_ns\"] <= " + q + "[\"scan_time_ns\"]"), "True\n")
      << run.json(s + "[\"takeover_ns\"], " + q + "[\"scan_time_ns\"]");
  EXPECT_EQ(run.json(s + "[\"modbus\"]"), "[{'port': 1, 'before': [1, 129], 'after': [0, 1]}]\n");
}

}  // namespace
