// A DP master outside pbvbus (docs/architecture.md "Masters outside pbvbus"): tests/integration/outside_master.py, a small
// but real class-1 master written in Python, runs over a pty against two pbvbus DP slaves that
// name no master. `pbvbus run` runs in a child process (cmd_run after fork(), so the test needs
// no built binary), ends with SIGINT like a user's Ctrl-C, and its JSON report is compared with
// the Python master's own summary.
//
// The Python master writes its next request immediately after reading a reply, a few bit times
// later; at 45.45 kbit/s that is far less than TSYN (33 bit times = 726 us). With the serial
// attachment's INTERFACE timing the attachment holds each request until the line has been idle
// TSYN and nearly every request is answered; with RAW timing the slaves drop the requests that
// follow a reply, the master retries after its timeout, and the report shows the drops.
#include <fcntl.h>
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <iostream>
#include <map>
#include <sstream>
#include <string>
#include <thread>

#include "pbvbus/tools/commands.hpp"
#include "pbvbus/scenario/scenario.hpp"

namespace pbvbus::tools {
namespace {

using namespace std::chrono_literals;

constexpr const char* kPython = "/usr/bin/python3";
const std::string kScript = PBVBUS_SOURCE_DIR "/tests/integration/outside_master.py";

/// Why the test cannot run here, or "" if it can.
std::string missing_python() {
  if (::access(kPython, X_OK) != 0) return std::string(kPython) + " is not installed";
  if (std::system((std::string(kPython) + " -c 'import serial' >/dev/null 2>&1").c_str()) != 0)
    return std::string(kPython) + " has no serial module (Debian: apt-get install python3-serial)";
  return "";
}

/// Runs a command, returns its exit status (-1 if it did not exit) and stdout.
std::pair<int, std::string> shell(const std::string& cmd) {
  std::string out;
  FILE* p = ::popen(cmd.c_str(), "r");
  if (p == nullptr) return {-1, ""};
  char buf[4096];
  std::size_t n;
  while ((n = std::fread(buf, 1, sizeof buf, p)) > 0) out.append(buf, n);
  const int st = ::pclose(p);
  return {WIFEXITED(st) ? WEXITSTATUS(st) : -1, out};
}

std::string read_file(const std::string& path) {
  std::ifstream f(path);
  return {std::istreambuf_iterator<char>(f), std::istreambuf_iterator<char>()};
}

/// A JSON document as "path=value" pairs (path "a.0.b"; strings bare, null, true/false).
using Flat = std::map<std::string, std::string>;
Flat flatten(const std::string& json_file) {
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

std::uint64_t num(const Flat& m, const std::string& key) {
  const auto it = m.find(key);
  if (it == m.end()) {
    ADD_FAILURE() << "no " << key;
    return 0;
  }
  return std::stoull(it->second);
}
std::string str(const Flat& m, const std::string& key) {
  const auto it = m.find(key);
  if (it == m.end()) {
    ADD_FAILURE() << "no " << key;
    return "";
  }
  return it->second;
}

std::string hex(const std::vector<std::uint8_t>& b) {
  std::string s;
  char buf[4];
  for (std::uint8_t x : b) {
    std::snprintf(buf, sizeof buf, "%02X", x);
    s += buf;
  }
  return s.empty() ? "-" : s;
}

struct OutsideRun {
  int pbvbus_status = -1;  ///< waitpid() status
  int master_rc = -1;
  Flat report;  ///< pbvbus run --json
  Flat master;  ///< the Python master's summary
  std::string report_json, master_json, err;
};

/// One run: pbvbus with `timing`, the Python master for `cycles` Data_Exchanges per slave.
OutsideRun run_outside(const std::string& timing, int cycles, double timeout_s) {
  OutsideRun r;
  const std::string base = std::string(PBVBUS_BINARY_DIR) + "/outside_master_" + timing;
  const std::string link = base + ".pty";
  const std::string scenario_file = base + ".textproto";
  const std::string report_file = base + ".report.json";
  const std::string err_file = base + ".err";
  const std::string master_file = base + ".master.json";
  const std::string gsd = PBVBUS_SOURCE_DIR "/examples/gsd/";
  // 45.45 kbit/s: TSYN = 726 us, far longer than the Python master's reaction time, so RAW
  // shows the drops every time and INTERFACE has something to hold.
  const std::string text =
      "name: \"outside master, " + timing + "\"\n"
      "line { name: \"DP\" baud: \"45.45k\" }\n"
      "serial { line: \"DP\" mode: STATION address: 2 timing: " + timing + " link: \"" + link + "\" }\n"
      "dp_slave { address: 3 line: \"DP\" gsd: \"" + gsd + "PBVB0A01.gsd\" }\n"
      "dp_slave { address: 4 line: \"DP\" gsd: \"" + gsd + "PBVB0A02.gsd\"\n"
      "  modules: [\"8DI DC24V\", \"8DO DC24V/0.5A\", \"2AO U/I 16 bit\"] }\n";
  std::ofstream(scenario_file) << text;
  // What a configuration tool gives the master: from the same plan pbvbus builds.
  const auto loaded = parse_scenario(text, scenario_file);
  if (!loaded.ok()) {
    ADD_FAILURE() << loaded.errors.front().str();
    return r;
  }
  std::string slaves;
  for (const auto& s : loaded.plan->dp_slaves) {
    char ident[8];
    std::snprintf(ident, sizeof ident, "0x%04X", s.params.ident);
    slaves += " --slave " + std::to_string(s.address) + ":" + ident + ":" + hex(s.params.user_prm) +
              ":" + hex(s.params.chk_cfg_du()) + ":" + std::to_string(s.inputs) + ":" +
              std::to_string(s.outputs);
  }

  std::cout.flush();
  std::fflush(nullptr);
  ::unlink(link.c_str());
  const pid_t child = ::fork();
  if (child == 0) {
    const int out = ::open(report_file.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    const int err = ::open(err_file.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    ::dup2(out, STDOUT_FILENO);
    ::dup2(err, STDERR_FILENO);
    const int rc = cmd_run({scenario_file, "--json"}, std::cout, std::cerr);
    std::cout.flush();
    std::cerr.flush();
    std::fflush(nullptr);
    ::_exit(rc);
  }
  if (child < 0) {
    ADD_FAILURE() << "fork failed";
    return r;
  }
  auto reap = [&](std::chrono::milliseconds limit) {
    const auto until = std::chrono::steady_clock::now() + limit;
    while (std::chrono::steady_clock::now() < until) {
      int st = 0;
      if (::waitpid(child, &st, WNOHANG) == child) return st;
      std::this_thread::sleep_for(10ms);
    }
    ::kill(child, SIGKILL);
    int st = 0;
    ::waitpid(child, &st, 0);
    ADD_FAILURE() << "pbvbus run did not end within " << limit.count() << " ms; killed";
    return -1;
  };
  // The link appears when the Simulation is built; then the run starts.
  struct stat st;
  const auto until = std::chrono::steady_clock::now() + 10s;
  while (::lstat(link.c_str(), &st) != 0 && std::chrono::steady_clock::now() < until)
    std::this_thread::sleep_for(10ms);
  if (::lstat(link.c_str(), &st) != 0) {
    ADD_FAILURE() << "no pty link " << link << " after 10 s: " << read_file(err_file);
    ::kill(child, SIGKILL);
    ::waitpid(child, nullptr, 0);
    return r;
  }
  char t[32];
  std::snprintf(t, sizeof t, "%.3f", timeout_s);
  const auto [mrc, mout] = shell(std::string(kPython) + " " + kScript + " --port " + link +
                                 " --address 2 --cycles " + std::to_string(cycles) + " --timeout " +
                                 t + " --max-time 40" + slaves);
  r.master_rc = mrc;
  r.master_json = mout;
  // Ctrl-C: the run ends with its report.
  ::kill(child, SIGINT);
  r.pbvbus_status = reap(10s);
  r.report_json = read_file(report_file);
  r.err = read_file(err_file);
  std::ofstream(master_file) << mout;
  r.master = flatten(master_file);
  r.report = flatten(report_file);
  return r;
}

/// A DP-layer count of the slave matches the master's: every request the master got an answer
/// to reached the slave once; a request the slave got but whose reply the master missed (in
/// flight) can make the slave's count higher, by at most the master's unanswered requests.
void expect_count_matches(const Flat& rep, const Flat& mst, int i, const std::string& slave_key,
                          const std::string& master_key) {
  const std::string si = "dp_slaves." + std::to_string(i) + ".";
  const std::string mi = "slaves." + std::to_string(i) + ".";
  const std::uint64_t s = num(rep, si + "requests." + slave_key);
  const std::uint64_t m = num(mst, mi + master_key);
  const std::uint64_t unanswered = num(mst, mi + "sent") - num(mst, mi + "answered");
  EXPECT_GE(s, m) << slave_key << " of slave " << str(rep, si + "address");
  EXPECT_LE(s, m + unanswered) << slave_key << " of slave " << str(rep, si + "address");
}

TEST(OutsideMaster, InterfaceTimingAnswersTheMastersRequests) {
  if (const auto why = missing_python(); !why.empty()) GTEST_SKIP() << why;
  const OutsideRun r = run_outside("INTERFACE", 200, 0.5);
  ASSERT_TRUE(WIFEXITED(r.pbvbus_status)) << "pbvbus run did not exit normally (status "
                                          << r.pbvbus_status << "): " << r.err;
  EXPECT_EQ(WEXITSTATUS(r.pbvbus_status), 0) << r.err;
  ASSERT_EQ(r.master_rc, 0) << r.master_json;
  ASSERT_FALSE(r.report.empty()) << "report: " << r.report_json << "\nstderr: " << r.err;
  const Flat& rep = r.report;
  const Flat& m = r.master;
  EXPECT_EQ(str(m, "completed"), "true");

  // >= 99 % of the master's requests answered.
  const double sent = static_cast<double>(num(m, "requests_sent"));
  const double answered = static_cast<double>(num(m, "requests_answered"));
  const double ratio = answered / sent;
  std::cout << "INTERFACE: " << answered << " of " << sent << " requests answered ("
            << 100.0 * ratio << " %), " << num(m, "retries") << " retries\n";
  ::testing::Test::RecordProperty("answer_ratio_percent", std::to_string(100.0 * ratio));
  EXPECT_GE(ratio, 0.99);

  // The attachment held the requests written too soon; the receivers dropped none.
  EXPECT_EQ(str(rep, "serial.0.timing"), "interface");
  EXPECT_EQ(str(rep, "serial.0.address"), "2");
  EXPECT_EQ(num(rep, "serial.0.frames_in"), num(m, "requests_sent"));
  EXPECT_GT(num(rep, "serial.0.held"), 0u);
  EXPECT_LE(num(rep, "serial.0.hold_max_bits"), 33u);  // at most TSYN after the reply
  EXPECT_EQ(num(rep, "serial.0.receivers_tsyn_drops"), 0u);
  EXPECT_EQ(num(rep, "lines.0.errors.tsyn_drops"), 0u);
  EXPECT_EQ(num(rep, "lines.0.errors.short_idle"), 0u);
  // The line's statistics and live list are what was on the wire.
  EXPECT_EQ(num(rep, "lines.0.requests.SRD_high"), num(m, "requests_sent"));
  EXPECT_EQ(num(rep, "lines.0.errors.retries"), num(m, "retries"));
  EXPECT_EQ(str(rep, "lines.0.live_list.0.address"), "2");
  EXPECT_EQ(str(rep, "lines.0.live_list.0.type"), "master_in_ring");
  EXPECT_EQ(str(rep, "lines.0.live_list.1.address"), "3");
  EXPECT_EQ(str(rep, "lines.0.live_list.1.type"), "slave");
  EXPECT_EQ(str(rep, "lines.0.live_list.2.address"), "4");
  EXPECT_EQ(rep.count("dp_masters.0.address"), 0u);  // no pbvbus master at all

  // Each slave's own view agrees with what the master saw.
  for (int i = 0; i < 2; ++i) {
    const std::string si = "dp_slaves." + std::to_string(i) + ".";
    const std::string mi = "slaves." + std::to_string(i) + ".";
    ASSERT_EQ(str(rep, si + "address"), str(m, mi + "address"));
    EXPECT_EQ(str(rep, si + "master"), "null");
    EXPECT_EQ(str(rep, si + "state"), "Data_Exch");
    EXPECT_EQ(str(rep, si + "owner"), "2");
    EXPECT_EQ(str(rep, si + "inputs"), str(m, mi + "inputs"));
    EXPECT_EQ(str(rep, si + "outputs"), str(m, mi + "outputs"));
    EXPECT_GE(num(m, mi + "data_exchange"), 200u);
    expect_count_matches(rep, m, i, "set_prm", "set_prm");
    expect_count_matches(rep, m, i, "chk_cfg", "chk_cfg");
    expect_count_matches(rep, m, i, "data_exchange", "data_exchange");
    expect_count_matches(rep, m, i, "slave_diag", "slave_diag");
    EXPECT_EQ(num(rep, si + "watchdog_expiries"), 0u);
    EXPECT_EQ(num(rep, si + "refused"), 0u);
    EXPECT_EQ(num(rep, si + "fdl.dropped_tsyn"), 0u);
  }
}

TEST(OutsideMaster, RawTimingShowsTheReceiversTsynDrops) {
  if (const auto why = missing_python(); !why.empty()) GTEST_SKIP() << why;
  const OutsideRun r = run_outside("RAW", 20, 0.1);
  ASSERT_TRUE(WIFEXITED(r.pbvbus_status)) << "pbvbus run did not exit normally (status "
                                          << r.pbvbus_status << "): " << r.err;
  EXPECT_EQ(WEXITSTATUS(r.pbvbus_status), 0) << r.err;
  ASSERT_FALSE(r.report.empty()) << "report: " << r.report_json << "\nstderr: " << r.err;
  const Flat& rep = r.report;
  const Flat& m = r.master;
  EXPECT_EQ(str(rep, "serial.0.timing"), "raw");
  const std::uint64_t drops = num(rep, "lines.0.errors.tsyn_drops");
  std::cout << "RAW: " << num(m, "requests_answered") << " of " << num(m, "requests_sent")
            << " requests answered, " << drops << " dropped by the slaves for lack of TSYN\n";
  ::testing::Test::RecordProperty("tsyn_drops", std::to_string(drops));
  EXPECT_GT(drops, 0u);
  EXPECT_EQ(num(rep, "serial.0.receivers_tsyn_drops"), drops);
  EXPECT_EQ(num(rep, "dp_slaves.0.fdl.dropped_tsyn") + num(rep, "dp_slaves.1.fdl.dropped_tsyn"), drops);
  // On the wire: requests after too short an idle time, left unanswered, and repeated.
  EXPECT_GE(num(rep, "lines.0.errors.short_idle"), drops);
  EXPECT_GE(num(rep, "lines.0.errors.no_response"), drops);
  EXPECT_GT(num(rep, "lines.0.errors.retries"), 0u);
  EXPECT_EQ(num(rep, "lines.0.errors.retries"), num(m, "retries"));
  // The master's retries (after its timeout, the line long idle) still got the slaves going.
  for (int i = 0; i < 2; ++i) {
    const std::string si = "dp_slaves." + std::to_string(i) + ".";
    EXPECT_EQ(str(rep, si + "state"), "Data_Exch");
    EXPECT_EQ(str(rep, si + "inputs"), str(m, "slaves." + std::to_string(i) + ".inputs"));
  }
}

}  // namespace
}  // namespace pbvbus::tools

namespace pbvbus::tools {
namespace {

/// VmRSS of a process in kB, or 0.
long rss_kb(pid_t pid) {
  std::ifstream f("/proc/" + std::to_string(pid) + "/status");
  for (std::string line; std::getline(f, line);)
    if (line.rfind("VmRSS:", 0) == 0) return std::atol(line.c_str() + 6);
  return 0;
}

/// Writes `n` random octets into `path` (blocking, as a careless program would) and closes it.
bool write_garbage(const std::string& path, std::size_t n, unsigned seed) {
  const int fd = ::open(path.c_str(), O_WRONLY | O_NOCTTY | O_CLOEXEC);
  if (fd < 0) return false;
  std::vector<std::uint8_t> junk(64 * 1024);
  std::uint32_t x = seed | 1;
  std::size_t done = 0;
  while (done < n) {
    for (auto& b : junk) {
      x ^= x << 13;
      x ^= x >> 17;
      x ^= x << 5;
      b = static_cast<std::uint8_t>(x);
    }
    std::size_t off = 0;
    const std::size_t want = std::min(junk.size(), n - done);
    while (off < want) {
      const ssize_t w = ::write(fd, junk.data() + off, want - off);
      if (w < 0 && errno == EINTR) continue;
      if (w <= 0) {
        ::close(fd);
        return false;
      }
      off += static_cast<std::size_t>(w);
    }
    done += want;
  }
  ::close(fd);
  return true;
}

// The outside-master example after a garbage flood: 1 MiB of random octets into the station's
// pty, then the README's master (fewer cycles); 8 MiB more, then the README's master again (a
// second master process, the same command a second time). Each master reaches data exchange
// with every slave and completes; pbvbus's memory does not grow with the flood.
TEST(OutsideMaster, GarbageFloodThenTheReadmeMasterTwice) {
  if (const auto why = missing_python(); !why.empty()) GTEST_SKIP() << why;
  const std::string base = std::string(PBVBUS_BINARY_DIR) + "/outside_master_flood";
  const std::string link = base + ".pty", scenario_file = base + ".textproto";
  const std::string report_file = base + ".report.json", err_file = base + ".err";
  // examples/outside-master.textproto with a link of its own.
  std::string text = read_file(PBVBUS_SOURCE_DIR "/examples/outside-master.textproto");
  const auto at = text.find("link: \"/tmp/pbvbus-dp\"");
  ASSERT_NE(at, std::string::npos);
  text.replace(at + 7, 14, link);
  const auto gsd = text.find("gsd: \"gsd/");
  ASSERT_NE(gsd, std::string::npos);
  for (auto p = text.find("\"gsd/"); p != std::string::npos; p = text.find("\"gsd/", p + 1))
    text.replace(p + 1, 4, PBVBUS_SOURCE_DIR "/examples/gsd/");
  std::ofstream(scenario_file) << text;
  std::cout.flush();
  std::fflush(nullptr);
  ::unlink(link.c_str());
  const pid_t child = ::fork();
  if (child == 0) {
    const int out = ::open(report_file.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    const int err = ::open(err_file.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    ::dup2(out, STDOUT_FILENO);
    ::dup2(err, STDERR_FILENO);
    const int rc = cmd_run({scenario_file, "--json"}, std::cout, std::cerr);
    std::cout.flush();
    std::fflush(nullptr);
    ::_exit(rc);
  }
  ASSERT_GT(child, 0);
  struct stat st;
  const auto until = std::chrono::steady_clock::now() + 10s;
  while (::lstat(link.c_str(), &st) != 0 && std::chrono::steady_clock::now() < until)
    std::this_thread::sleep_for(10ms);
  // The README's command (tests/integration/outside_master.py, the example's slaves), 20 cycles.
  const std::string master = std::string(kPython) + " " + kScript + " --port " + link +
                             " --slave 3:0x0A01:12:1121:2:2 --slave 4:0x0A02:0101000202:102061:1:5"
                             " --cycles 20 --max-time 10";
  auto run_master = [&](const std::string& tag) {
    const auto [rc, out] = shell(master);
    std::ofstream(base + "." + tag + ".json") << out;
    EXPECT_EQ(rc, 0) << tag << ": " << out;
    const Flat m = flatten(base + "." + tag + ".json");
    EXPECT_EQ(str(m, "completed"), "true") << tag;
    for (int i = 0; i < 2; ++i)
      EXPECT_GE(num(m, "slaves." + std::to_string(i) + ".data_exchange"), 20u) << tag;
    std::cout << tag << ": " << out;
    return m;
  };
  EXPECT_TRUE(write_garbage(link, 1 << 20, 1));
  run_master("after_1MiB");
  const long rss1 = rss_kb(child);
  EXPECT_TRUE(write_garbage(link, 8 << 20, 2));
  run_master("after_8MiB");
  const long rss8 = rss_kb(child);
  std::cout << "VmRSS after 1 MiB: " << rss1 << " kB, after 8 MiB more: " << rss8 << " kB\n";
  ::kill(child, SIGINT);
  int status = 0;
  ::waitpid(child, &status, 0);
  EXPECT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0) << read_file(err_file);
  ASSERT_GT(rss1, 0);
  // No growth with the flood (it used to be ~1.2 MB per MiB): bounded by the queue, the chunk
  // and the backlog, whatever was written.
  EXPECT_LT(rss8 - rss1, 1024) << "kB";
  const Flat rep = flatten(report_file);
  EXPECT_GE(num(rep, "serial.0.octets_in"), 9u << 20);  // and the masters' requests
  EXPECT_EQ(num(rep, "serial.0.program_opens"), 4u);  // garbage, master, garbage, master
  EXPECT_EQ(num(rep, "serial.0.program_closes"), 4u);
  EXPECT_GT(num(rep, "serial.0.dropped_full"), 0u);
  EXPECT_LE(num(rep, "serial.0.queue_max"), 32u);
  EXPECT_EQ(str(rep, "dp_slaves.0.state"), "Data_Exch");
  EXPECT_EQ(str(rep, "dp_slaves.1.state"), "Data_Exch");
}

}  // namespace
}  // namespace pbvbus::tools
