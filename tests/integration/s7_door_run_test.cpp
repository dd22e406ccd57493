// End-to-end: `pbvbus run SCENARIO --json --quiet --capture FILE` (the binary, a child process
// in a temp dir, ended with SIGINT like a user's Ctrl-C) with an s7_door on an ephemeral port,
// and nodes7 0.3.18 (npm, unmodified) driven by tests/integration/data/s7_door_run_client.js
// (docs/iso-on-tcp.md, docs/mpi.md "PGs and OPs in a scenario", docs/s7cpu.md "A single CPU in a
// scenario", docs/h-system.md "S7 communication").
//
// 1. A single CPU (X1 on an MPI line, DB 1 of 64 octets) and a door with two routes: rack 0
//    slot 2 straight to the CPU's memory, rack 0 slot 3 across MPI to address 2 through the
//    door's own MPI station. Over each route nodes7 writes DB bytes, an INT, a REAL, a flag
//    byte, an input byte and an output byte, reads them back in one multi-item read and reads
//    a missing DB. An OP on the MPI line reads the two INTs the clients wrote: the final
//    report's last_value shows the clients' values (what a client writes is what others read).
// 2. The capture of that run, read by tshark: on the door's interface tshark's own s7comm
//    decodes the PDUs (setup, write, read with item counts, the missing DB's return code); on
//    the MPI line the shipped dissector (captures/lua/pbvbus.lua) decodes the MPI connection
//    layer (connect E0, confirm D0, connection acks 05, data F1, data ack B0, disconnect 80)
//    and hands the S7 PDU of the MPI route's data messages to s7comm.
// 3. An H-system (S7-400H pair, both CPUs RUN) with a fault-tolerant and a standard connection
//    over CP 443-1s, the door routing rack 0 slot 4 to the fault-tolerant and slot 5 to the
//    standard connection, and the master CPU (rack 0) failing at 3.5 s. Both clients read the
//    DB word written before the failure; the fault-tolerant one keeps reading it from the new
//    master, the standard one loses its connection (nodes7 logs the disconnect, the door
//    counts a route closed).
//
// Skipped with the reason when node or nodes7 (./pbvbus test installs it into BUILD/nodes7) or,
// for the capture, tshark is missing. Every wait is bounded (an upper bound, never asserted).
//
// Decisions (the sources say nothing about a test's set-up):
// - The scenarios' duration (120 s) is only an upper bound: each run ends with SIGINT once the
//   clients are done, so the door stays open for them whatever the machine's speed. The run is
//   paced (it has a door), so virtual time follows the wall clock.
// - The three single-CPU tests share one run per test process (one `pbvbus run`, both clients
//   one after the other, so the capture's order is known); under ctest each test makes its own.
//   After the last client the test waits 1 s (10 periods of the OP's reads) before SIGINT, a
//   margin for the OP's next read, not a timing assertion.
// - The H pair starts faster than its defaults (startup and link-up 500 ms: Redundant at
//   1.145 s) and CPU 0 fails at 3.5 s, so the clients read for about 2 s before the failure.
// - nodes7 0.3.18 takes the door's DR for a bad read answer ("INVALID READ RESPONSE -
//   DISCONNECTING", with the octets) and sees the TCP connection end at once, but returns the
//   pending read (bad, "BAD 255") only when its job timeout runs out; the script sets that
//   timeout to 2 s for the H-system, so the test takes about 6 s.
// - nodes7's item counts on the wire follow its own rules (nodeS7.js): reads of one area and DB
//   with gaps of at most 5 octets are joined into one item, writes never; the expected counts
//   are worked out from those rules below.
#include <arpa/inet.h>
#include <fcntl.h>
#include <gtest/gtest.h>
#include <netinet/in.h>
#include <signal.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "../captures/tshark_helpers.hpp"
#include "loopback_support.hpp"

namespace {

using pbvbus::test::shell;
using pbvbus::test::read_file;
using pbvbus::test::free_port;
using pbvbus::test::can_connect;

using namespace std::chrono_literals;
namespace ts = pbvbus::test;

constexpr const char* kPython = "/usr/bin/python3";
const std::string kBinary = PBVBUS_BINARY_DIR "/bin/pbvbus";
const std::string kClient = PBVBUS_SOURCE_DIR "/tests/integration/data/s7_door_run_client.js";
const std::string kNodes7 = PBVBUS_BINARY_DIR "/nodes7/node_modules";

/// Why the nodes7 tests cannot run here ("" when they can).
std::string no_nodes7() {
  if (shell("node --version").first != 0) return "node is not installed (Debian: apt-get install nodejs)";
  struct stat st {};
  if (::stat((kNodes7 + "/nodes7/nodeS7.js").c_str(), &st) != 0)
    return "nodes7 0.3.18 is not in " + kNodes7 +
           " (./pbvbus test installs it with npm; npm was unreachable?)";
  if (::access(kPython, X_OK) != 0) return "/usr/bin/python3 is missing (reads the JSON report)";
  return "";
}

/// `pbvbus run scenario.textproto --json --quiet --capture capture.pcapng` in a temp directory.
class PbvbusRun {
 public:
  PbvbusRun() {
    char tmpl[] = "/tmp/pbvbus-s7door-XXXXXX";
    dir = ::mkdtemp(tmpl);
    port = free_port();
  }
  ~PbvbusRun() {
    stop();
    if (!keep) shell("rm -rf '" + dir + "'");
  }
  PbvbusRun(const PbvbusRun&) = delete;
  PbvbusRun& operator=(const PbvbusRun&) = delete;

  /// Starts the run; true once the door accepts TCP connections (20 s at most).
  bool start(const std::string& scenario) {
    std::ofstream(dir + "/scenario.textproto") << scenario;
    m_pid = ::fork();
    if (m_pid == 0) {
      if (::chdir(dir.c_str()) != 0) ::_exit(127);
      const int out = ::open("report.json", O_WRONLY | O_CREAT | O_TRUNC, 0644);
      const int err = ::open("stderr.txt", O_WRONLY | O_CREAT | O_TRUNC, 0644);
      ::dup2(out, 1);
      ::dup2(err, 2);
      ::execl(kBinary.c_str(), "pbvbus", "run", "scenario.textproto", "--json", "--quiet",
              "--capture", "capture.pcapng", static_cast<char*>(nullptr));
      ::_exit(127);
    }
    const auto deadline = std::chrono::steady_clock::now() + 20s;
    while (std::chrono::steady_clock::now() < deadline) {
      if (can_connect(port)) return true;
      int status = 0;
      if (::waitpid(m_pid, &status, WNOHANG) == m_pid) {
        m_pid = -1;
        return false;
      }
      std::this_thread::sleep_for(50ms);
    }
    return false;
  }

  /// Ends the run (SIGINT); the report is then in report.json, the capture in capture.pcapng.
  void stop() {
    pbvbus::test::end_child(m_pid, true, 20s);
    m_pid = -1;
  }

  /// json.dumps(EXPR) with `r` the report (python3's json; an error text when it cannot be read).
  std::string report(const std::string& expr) const {
    std::ofstream(dir + "/query.py") << "import json, sys\nr = json.load(open(sys.argv[1]))\n"
                                     << "print(json.dumps(" << expr << "))\n";
    auto [rc, out] = shell(std::string(kPython) + " '" + dir + "/query.py' '" + dir + "/report.json'");
    if (rc != 0) return "(error: " + out + ")";
    if (!out.empty() && out.back() == '\n') out.pop_back();
    return out;
  }
  std::string stderr_text() const { return read_file(dir + "/stderr.txt"); }
  std::string capture() const { return dir + "/capture.pcapng"; }

  std::string dir;
  std::uint16_t port = 0;
  bool keep = false;  ///< leave the directory for a look (a failed test)

 private:
  pid_t m_pid = -1;
};

/// What one run of the client script printed: its `key=value` lines and everything.
struct ClientRun {
  int rc = -1;
  std::map<std::string, std::string> kv;
  std::string all;
  std::string at(const std::string& k) const {
    const auto it = kv.find(k);
    return it == kv.end() ? "(missing " + k + ")" : it->second;
  }
  /// A JSON string value without its quotes.
  std::string text(const std::string& k) const {
    const std::string v = at(k);
    return v.size() >= 2 && v.front() == '"' ? v.substr(1, v.size() - 2) : v;
  }
};

ClientRun run_client(const std::string& args) {
  ClientRun c;
  std::tie(c.rc, c.all) = shell("NODE_PATH='" + kNodes7 + "' node '" + kClient + "' " + args);
  std::istringstream in(c.all);
  for (std::string l; std::getline(in, l);) {
    if (l.empty() || l[0] == '[') continue;  // nodes7's own log lines: "[sec,nsec NAME] text"
    const auto eq = l.find('=');
    if (eq != std::string::npos) c.kv[l.substr(0, eq)] = l.substr(eq + 1);
  }
  return c;
}

// ---- 1 + 2: a single CPU, directly and across MPI ----------------------------------------------

// The OP (MPI address 1) reads the two INTs the clients write: DB1.DBW4 (the direct route's,
// base 0) and DB1.DBW36 (the MPI route's, base 32). The door's MPI station takes the lowest free
// address, 0 (s7_plan.hpp).
std::string single_cpu_scenario(std::uint16_t port) {
  std::ostringstream s;
  s << "name: \"s7-door-run\"\nduration: \"120s\"\n"
       "line { name: \"MPI\" kind: MPI }\n"
       "s7_cpu { name: \"CPU\" mpi_dp { mode: MPI line: \"MPI\" } db { number: 1 size: 64 } }\n"
       "mpi_station { role: OP line: \"MPI\"\n"
       "  read { cpu: 2 item: \"DB1.DBW4\" period: \"100ms\" }\n"
       "  read { cpu: 2 item: \"DB1.DBW36\" period: \"100ms\" } }\n"
       "s7_door { name: \"S7\" listen: \"127.0.0.1:" << port << "\" mpi_line: \"MPI\"\n"
       "  route { rack: 0 slot: 2 cpu: \"CPU\" }\n"
       "  route { rack: 0 slot: 3 mpi_address: 2 } }\n";
  return s.str();
}

/// One run of the single-CPU scenario per test process (the tests below share it; ctest runs
/// each test in a process of its own, then each makes its own run).
struct SingleCpuSession {
  std::string skip;  ///< why the tests cannot run
  bool started = false;
  std::string start_error;
  ClientRun direct, mpi;
  PbvbusRun run;
};

SingleCpuSession* g_session = nullptr;

SingleCpuSession& single_cpu() {
  if (g_session != nullptr) return *g_session;
  g_session = new SingleCpuSession;
  SingleCpuSession& x = *g_session;
  x.skip = no_nodes7();
  if (!x.skip.empty()) return x;
  x.started = x.run.start(single_cpu_scenario(x.run.port));
  if (!x.started) {
    x.start_error = x.run.stderr_text();
    return x;
  }
  const std::string port = std::to_string(x.run.port);
  // rw PORT SLOT BASE FLAG IO: direct at DB1 0.., MB10, IB0/QB0; over MPI at DB1 32.., MB20,
  // IB1/QB1. One after the other, so that the capture's order is known.
  x.direct = run_client("rw " + port + " 2 0 10 0");
  x.mpi = run_client("rw " + port + " 3 32 20 1");
  // The OP reads every 100 ms: give it a few periods after the last write (a margin, not a
  // timing assertion).
  std::this_thread::sleep_for(1s);
  x.run.stop();
  return x;
}

// The shared run's directory (report.json, stderr.txt, capture.pcapng) stays for a look when a
// test failed, and its path is printed; else it goes with the process.
class SessionCleanup : public ::testing::Environment {
 public:
  void TearDown() override {
    if (g_session == nullptr) return;
    g_session->run.keep = !::testing::UnitTest::GetInstance()->Passed();
    if (g_session->run.keep)
      std::fprintf(stderr, "s7_door_run_test: the single-CPU run is in %s\n", g_session->run.dir.c_str());
    delete g_session;
    g_session = nullptr;
  }
};
[[maybe_unused]] ::testing::Environment* const g_cleanup =
    ::testing::AddGlobalTestEnvironment(new SessionCleanup);

/// Keeps a run's directory (printed) when the test that owns it failed.
struct KeepIfFailed {
  PbvbusRun& run;
  ~KeepIfFailed() {
    if (!::testing::Test::HasFailure()) return;
    run.keep = true;
    std::fprintf(stderr, "s7_door_run_test: the run is in %s\n", run.dir.c_str());
  }
};

#define SINGLE_CPU_OR_SKIP(s)                          \
  SingleCpuSession& s = single_cpu();                  \
  if (!s.skip.empty()) GTEST_SKIP() << s.skip;         \
  ASSERT_TRUE(s.started) << "pbvbus run did not open the door: " << s.start_error

// What one rw client must have printed (base 0 or 32, flag byte, I/Q byte).
void expect_rw(const ClientRun& c, int base, int flag, int io) {
  SCOPED_TRACE(c.all);
  ASSERT_EQ(c.rc, 0);
  ASSERT_EQ(c.at("done"), "true");
  const auto db = [base](const char* t, int off) { return "DB1," + std::string(t) + std::to_string(base + off); };
  EXPECT_EQ(c.at("write_bad"), "false");
  EXPECT_EQ(c.at("back_bad"), "false");
  EXPECT_EQ(c.at(db("B", 0) + ".4"), "[17,34,51,68]");          // 11 22 33 44
  EXPECT_EQ(c.at(db("INT", 4)), std::to_string(-1234 - base));  // -1234 / -1266
  EXPECT_EQ(c.at(db("REAL", 8)), base == 0 ? "2.5" : "34.5");
  EXPECT_EQ(c.at("MB" + std::to_string(flag)), std::to_string(0x2A + flag));
  EXPECT_EQ(c.at("IB" + std::to_string(io)), "129");  // 0x81
  EXPECT_EQ(c.at("QB" + std::to_string(io)), std::to_string(0x42 + io));
  // A missing DB: the CPU answers return code 0A (object does not exist, checked in the
  // capture below); nodes7 reports the read as bad and puts its quality text in place of the
  // value, "BAD 255" (docs/iso-on-tcp.md "What nodes7 does with a missing DB").
  EXPECT_EQ(c.at("missing_bad"), "true");
  EXPECT_EQ(c.at("DB9,B0"), "\"BAD 255\"");
}

TEST(S7DoorRun, Nodes7DirectToTheCpu) {
  SINGLE_CPU_OR_SKIP(s);
  expect_rw(s.direct, 0, 10, 0);
  EXPECT_EQ(s.direct.at("rw_attempts"), "1");  // a direct route answers from the start
}

TEST(S7DoorRun, Nodes7AcrossMpiThroughTheDoorsStation) {
  SINGLE_CPU_OR_SKIP(s);
  expect_rw(s.mpi, 32, 20, 1);
}

TEST(S7DoorRun, TheOpReadsWhatTheClientsWrote) {
  SINGLE_CPU_OR_SKIP(s);
  SCOPED_TRACE(s.run.stderr_text());
  // -1234 = 0xFB2E (65536 - 1234 = 64302), -1266 = 0xFB0E (64270), big-endian.
  EXPECT_EQ(s.run.report("[x['item'] + ' ' + x['last_value'] for x in r['s7']['stations'][0]['reads']]"),
            R"(["DB1.DBW4 FB 2E", "DB1.DBW36 FB 0E"])");
  EXPECT_EQ(s.run.report("[(x['role'], x['address'], x['breaks']) for x in r['s7']['stations']]"),
            R"([["OP", 1, 0]])");
  // The door: two clients connected (one CC each) and no route closed under them.
  EXPECT_EQ(s.run.report("[(d['name'], d['connects'], d['connects_refused'], d['routes_closed'], "
                         "d['closed_garbage']) for d in r['s7']['doors']]"),
            R"([["S7", 2, 0, 0, 0]])");
  // The CPU over MPI: the OP's connection and the door's (the direct route uses no MPI).
  EXPECT_EQ(s.run.report("[(c['name'], c['mpi_address'], c['connections_accepted'], "
                         "c['connections_refused']) for c in r['s7']['cpus']]"),
            R"([["CPU", 2, 2, 0]])");
}

// ---- 2: the capture -------------------------------------------------------------------------

using Rows = std::vector<std::vector<std::string>>;

std::string join(const Rows& rows) {
  std::string s;
  for (const auto& r : rows) {
    for (std::size_t i = 0; i < r.size(); ++i) s += (i ? "|" : "") + r[i];
    s += "\n";
  }
  return s;
}

TEST(S7DoorRun, CaptureDecodedByTshark) {
  SINGLE_CPU_OR_SKIP(s);
  if (!ts::tshark_available()) GTEST_SKIP() << ts::kNoTshark;
  const std::string cap = s.run.capture();

  // The door's interface: every S7 PDU both clients exchanged, decoded by tshark's s7comm.
  // ROSCTR 1 = Job, 3 = Ack-Data; function F0 setup, 05 Write Var, 04 Read Var; item count.
  const Rows door = ts::tshark_fields(
      cap, {"s7comm.header.rosctr", "s7comm.param.func", "s7comm.param.itemcount", "s7comm.data.returncode"},
      "frame.interface_name == \"s7door:S7\"");
  SCOPED_TRACE(join(door));
  // Per client, in order (nodes7 0.3.18, nodeS7.js): setup; one Write Var with the six items
  // (writes are never joined: prepareWritePacket); one Read Var of the same six as four items
  // (DB1 bytes 0..3, INT at 4 and REAL at 8 are one item, prepareReadPacket joins items of one
  // area and DB whose gap is at most maxGap 5: DB1 B0..11, MB, IB, QB); the read of DB9 (one
  // item, answered with return code 0A). Return codes FF for every other item; s7comm shows the
  // first octet of each data item of the Write Var job (reserved, 00) as its return code too.
  const Rows one_client = {
      {"1", "0xf0", "", ""},
      {"3", "0xf0", "", ""},
      {"1", "0x05", "6", "0x00,0x00,0x00,0x00,0x00,0x00"},
      {"3", "0x05", "6", "0xff,0xff,0xff,0xff,0xff,0xff"},
      {"1", "0x04", "4", ""},
      {"3", "0x04", "4", "0xff,0xff,0xff,0xff"},
      {"1", "0x04", "1", ""},
      {"3", "0x04", "1", "0x0a"},
  };
  Rows both = one_client;
  both.insert(both.end(), one_client.begin(), one_client.end());
  EXPECT_EQ(join(door), join(both));

  // The MPI line (the shipped dissector), the frames from or to the door's station (address 0;
  // the OP at 1 reads too): connect request E0 from 0 to the CPU (2), confirm D0, the two
  // connection acks 05 (docs/mpi.md), then each S7 PDU of the MPI route in a data message F1
  // that the receiver acknowledges with a data ack B0 before anything else, the CPU's answer its
  // own F1 (protocol-facts.md §H.3), and at the client's end a disconnect request 80 from the
  // door's station. s7comm decodes each F1's S7 PDU: the eight of one client above.
  const Rows mpi = ts::tshark_fields(
      cap, {"pbmpi.pdu", "pbmpi.src", "pbmpi.dst", "s7comm.header.rosctr", "s7comm.param.func",
            "s7comm.param.itemcount"},
      "pbmpi && (pbmpi.src matches \"^0:\" || pbmpi.dst matches \"^0:\")");
  SCOPED_TRACE(join(mpi));
  Rows got;  // PDU type, sender and receiver address (the SAPs are the stations' choice), S7
  for (const auto& r : mpi) {
    ASSERT_EQ(r.size(), 6u);
    const auto addr = [](const std::string& a) { return a.substr(0, a.find(':')); };
    got.push_back({r[0], addr(r[1]), addr(r[2]), r[3], r[4], r[5]});
  }
  Rows want = {{"0xe0", "0", "2", "", "", ""},
               {"0xd0", "2", "0", "", "", ""},
               {"0x05", "0", "2", "", "", ""},
               {"0x05", "2", "0", "", "", ""}};
  for (const auto& r : one_client) {
    const bool job = r[0] == "1";
    const std::string from = job ? "0" : "2", to = job ? "2" : "0";
    want.push_back({"0xf1", from, to, r[0], r[1], r[2]});
    want.push_back({"0xb0", to, from, "", "", ""});
  }
  want.push_back({"0x80", "0", "2", "", "", ""});
  EXPECT_EQ(join(got), join(want));
}

// ---- 3: the H-system, a fault-tolerant and a standard connection across the master's failure --

// Pair defaults but shorter: startup 500 ms, link-up 500 ms, update 75 ms + 0.7 ms x 100 KB =
// 145 ms (docs/h-system.md), so Redundant at 1.145 s; the configured connections are set up then
// (R8). CPU 0 (master) fails at 3.5 s: CPU 1 takes over. "OS" (fault-tolerant, CP 0 of each rack)
// switches path; "PG" (standard, rack 0 CP 0) is lost with its CPU.
std::string h_scenario(std::uint16_t port) {
  std::ostringstream s;
  s << "name: \"s7-door-h\"\nduration: \"120s\"\n"
       "h_system { name: \"H\"\n"
       "  cpu { profile: S7_400H cpu0 { power_on: \"0s\" switch: RUN } cpu1 { power_on: \"0s\" switch: RUN }\n"
       "        startup_time: \"500ms\" link_up_time: \"500ms\"\n"
       "        s7_memory { db { number: 1 size: 16 } } }\n"
       "  cp { rack: 0 index: 0 }\n"
       "  cp { rack: 1 index: 0 }\n"
       "  connection { name: \"OS\" kind: FAULT_TOLERANT cp: 0 }\n"
       "  connection { name: \"PG\" kind: STANDARD rack: 0 cp: 0 } }\n"
       "s7_door { name: \"S7H\" listen: \"127.0.0.1:" << port << "\"\n"
       "  route { rack: 0 slot: 4 h_system: \"H\" connection: \"OS\" }\n"
       "  route { rack: 0 slot: 5 h_system: \"H\" connection: \"PG\" } }\n"
       "fault { at: \"3.5s\" cpu_failure { rack: 0 } }\n";
  return s.str();
}

TEST(S7DoorRun, HSystemFaultTolerantKeepsReadingStandardIsLost) {
  if (const std::string why = no_nodes7(); !why.empty()) GTEST_SKIP() << why;
  PbvbusRun run;
  const KeepIfFailed keep{run};
  ASSERT_TRUE(run.start(h_scenario(run.port))) << run.stderr_text();
  const ClientRun c = run_client("h " + std::to_string(run.port) + " 4 5");
  run.stop();
  SCOPED_TRACE(c.all);
  SCOPED_TRACE(run.stderr_text());
  ASSERT_EQ(c.rc, 0);
  ASSERT_EQ(c.at("done"), "true");
  EXPECT_EQ(c.at("ft_write_bad"), "false");
  // The fault-tolerant connection: only 4321 was ever read, never a bad read, and reads went on
  // after the standard connection (and with it CPU 0) was gone.
  EXPECT_EQ(c.at("ft_values"), R"(["4321"])");
  EXPECT_EQ(c.at("ft_bad"), "0");
  EXPECT_EQ(c.at("ft_reads_after_std_lost"), "5");
  // The standard connection read the same value from CPU 0 until it failed, then lost the
  // connection.
  EXPECT_EQ(c.at("std_values"), R"(["4321"])");
  EXPECT_EQ(c.at("std_lost"), "true");
  EXPECT_NE(c.at("std_lost_after_good_reads"), "0");
  EXPECT_EQ(c.at("std_lost_value"), "\"BAD 255\"");
  // nodes7's own log of the standard connection: the door's DR as it arrived (TPKT length 11,
  // LI 6, DR 80, dst-ref 00 02 = nodes7's own reference from its CR, the door's src-ref, reason
  // 00 = not specified, docs/iso-on-tcp.md "DR reason 0 when the route breaks"), then the end
  // of the TCP connection. nodes7 hands the pending read back bad when its job timeout runs out.
  const std::string std_name = c.text("std_name");
  const auto dr = c.all.find("<Buffer 03 00 00 0b 06 80 00 02 ", c.all.find("std_name="));
  ASSERT_NE(dr, std::string::npos);
  EXPECT_EQ(c.all.substr(dr + 38, 4), "00>\n");  // "<Buffer " + 8 octets "xx " = 8 + 24, src-ref "yy yy " 6
  EXPECT_NE(c.all.find(" " + std_name + "] ISO-on-TCP connection DISCONNECTED."), std::string::npos);
  // The fault-tolerant connection never saw a disconnect before the script dropped it.
  const std::string ft_name = c.text("ft_name");
  const auto dropping = c.all.find("ft_dropping=true");
  ASSERT_NE(dropping, std::string::npos);
  EXPECT_EQ(c.all.substr(0, dropping).find(" " + ft_name + "] ISO-on-TCP connection DISCONNECTED."),
            std::string::npos);
  EXPECT_EQ(c.all.substr(0, dropping).find(" " + ft_name + "] READ TIMEOUT"), std::string::npos);
  // The door: the standard route closed under its client (the only one: every refusal before
  // Redundant is counted apart), the fault-tolerant one did not; the script's refused attempts
  // got a DR at their CR (nodes7 may also have tried to reconnect the standard connection by
  // itself after its reset, refused too: at least).
  EXPECT_EQ(run.report("[(d['name'], d['connects'], d['routes_closed'], d['closed_garbage']) "
                       "for d in r['s7']['doors']]"),
            R"([["S7H", 2, 1, 0]])");
  const int refused_by_script = std::stoi(c.at("ft_attempts")) - 1 + std::stoi(c.at("std_attempts")) - 1;
  EXPECT_EQ(run.report("r['s7']['doors'][0]['connects_refused'] >= " + std::to_string(refused_by_script)),
            "true");
  // The model's connection rows: OS switched to rack 1's CP at the failure, PG lost then.
  EXPECT_EQ(run.report("[(c['name'], c['state'], c['active']) for c in r['h_systems_run'][0]['connections']]"),
            R"([["OS", "established", "CP 443-1 rack 1 CP 0"], ["PG", "lost", ""]])");
  EXPECT_EQ(run.report("[[e['time_ms'] for e in c['events']] for c in r['h_systems_run'][0]['connections']]"),
            "[[1145.0, 3500.0], [1145.0, 3500.0]]");
}

}  // namespace
