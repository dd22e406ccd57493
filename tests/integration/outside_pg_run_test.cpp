// An MPI PG outside pbvbus (issue "MPI and S7", deliverable 6): tests/integration/outside_pg/
// outside_pg.py, a PG written in Python from protocol-facts.md §B, §C and §H without pbvbus's
// code, joins a running scenario's MPI line through a serial STATION pty at MPI address 0,
// connects to the s7_cpu at address 2, reads DB1.DBB0 x 16 over S7 communication and
// disconnects. The bytes it must read were written into DB1 before, over the scenario's S7 door
// (ISO-on-TCP, RFC 1006) by a raw client in this test: octets worked out by hand below, from
// tools-and-formats.md §3.4 and protocol-facts.md §H.4. An OP at address 1 reads DB1.DBW0, so
// the PG joins a real ring of three (0, 1, 2).
//
// Then the run ends with SIGINT (a user's Ctrl-C) and the capture is read by Debian's tshark
// with the shipped dissector (captures/lua/pbvbus.lua, fields pbmpi.*, the S7 PDU by tshark's
// own s7comm; captures/README.md "MPI and S7"): the PG's connect request (E0, 0 -> 2), the
// CPU's confirm (D0), the data messages (F1) of Setup Communication (0xF0) and Read Var (0x04)
// each way with their MPI acks (B0), the Read Var answer's return code 0xFF carrying the
// written bytes, and the PG's disconnect (80).
//
// The run is paced at --speed 1/10 and the PG gets the same --speed (its timeouts scale with
// it): at speed 1 a Python program behind a pty sometimes answers after the CPU's slot time
// (outside_pg.py's docstring: 6 of 45 runs failed at speed 1, none at 1/10). Nothing here is
// timed; the waits are guards that fail the test instead of hanging it.
//
// Decisions where the sources are silent:
//  - DB1 is filled over the door (route `cpu:`, straight into the CPU's memory) before the PG
//    starts, so the PG's read comes after the write whatever the timing; the door's port is a
//    free ephemeral one picked by the test (bind to port 0, release), checked in the report.
//  - The OP's reads are only checked for errors, not for the value: when its last read falls
//    relative to the write depends on the wall-clock pacing.
//  - The PG disconnects before the run ends, so the CPU has exactly the OP's connection open
//    (the PG's disconnect was taken: the FDL acknowledged the frame before the PG exited).
#include <arpa/inet.h>
#include <fcntl.h>
#include <gtest/gtest.h>
#include <netinet/in.h>
#include <netinet/tcp.h>
#include <signal.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <sys/time.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <chrono>
#include <cstdint>
#include <fstream>
#include <iostream>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "../captures/tshark_helpers.hpp"
#include "outside_slave_support.hpp"

#include "pbvbus/tools/commands.hpp"
#include "loopback_support.hpp"

namespace pbvbus::tools {
namespace {

using pbvbus::test::free_port;

using namespace std::chrono_literals;
using test_support::Flat;
using test_support::flatten;
using test_support::get;
using test_support::kPython;
using test_support::read_file;
using test_support::shell;
using Bytes = std::vector<std::uint8_t>;
namespace ts = pbvbus::test;

const std::string kPg = PBVBUS_SOURCE_DIR "/tests/integration/outside_pg/outside_pg.py";
constexpr const char* kSpeed = "1/10";

/// What DB1.DBB0..15 hold after the door's Write Var: 16 octets, none of them 00 (the CPU's
/// memory starts at zero) and no two alike, so a shifted or partial read shows.
const Bytes kDb1 = {0x50, 0x47, 0x20, 0x30, 0xA5, 0x5A, 0x01, 0x80,
                    0xFE, 0x7F, 0x11, 0x22, 0x33, 0x44, 0xC3, 0x3C};

// ISO-on-TCP octets, by hand (tools-and-formats.md §3.4; protocol-facts.md §H.4).

/// CR to rack 0 slot 2: TPKT 03 00 00 16 (22 octets); COTP LI 0x11, E0, dst-ref 00 00,
/// src-ref 00 01, class 00; C0 01 0A (TPDU 2^10), C1 02 01 00 (calling TSAP: PG), C2 02 01 02
/// (called TSAP: rack 0, slot 2).
const Bytes kCr = {0x03, 0x00, 0x00, 0x16, 0x11, 0xE0, 0x00, 0x00, 0x00, 0x01, 0x00,
                   0xC0, 0x01, 0x0A, 0xC1, 0x02, 0x01, 0x00, 0xC2, 0x02, 0x01, 0x02};
/// Setup Communication: S7 header 32 01 0000 ref 0001 param 0008 data 0000; F0 00, AmQ calling
/// 0001, called 0001, PDU length 00F0 (240). TPKT 4 + DT 3 + 10 + 8 = 25 = 0x19.
const Bytes kSetup = {0x03, 0x00, 0x00, 0x19, 0x02, 0xF0, 0x80, 0x32, 0x01, 0x00, 0x00, 0x00, 0x01,
                      0x00, 0x08, 0x00, 0x00, 0xF0, 0x00, 0x00, 0x01, 0x00, 0x01, 0x00, 0xF0};
/// Write Var of DB1.DBB0, 16 bytes: header ref 0002, param 000E (14), data 0014 (4 + 16);
/// 05 01 (one item), item 12 0A 10, transport 02 (BYTE), count 0010, DB 0001, area 84,
/// address 00 00 00; data: reserved 00, transport 04 (BYTE/WORD/DWORD, length in bits),
/// 0080 (128 bits), the 16 octets. TPKT 4 + 3 + 10 + 14 + 20 = 51 = 0x33.
Bytes write_db1() {
  Bytes b = {0x03, 0x00, 0x00, 0x33, 0x02, 0xF0, 0x80, 0x32, 0x01, 0x00, 0x00, 0x00,
             0x02, 0x00, 0x0E, 0x00, 0x14, 0x05, 0x01, 0x12, 0x0A, 0x10, 0x02, 0x00,
             0x10, 0x00, 0x01, 0x84, 0x00, 0x00, 0x00, 0x00, 0x04, 0x00, 0x80};
  b.insert(b.end(), kDb1.begin(), kDb1.end());
  return b;
}
/// Its answer: Ack-Data (03), error class/code 00 00, ref 0002, param 0002, data 0001; 05 01;
/// return code FF (success). TPKT 4 + 3 + 12 + 2 + 1 = 22 = 0x16.
const Bytes kWriteOk = {0x03, 0x00, 0x00, 0x16, 0x02, 0xF0, 0x80, 0x32, 0x03, 0x00, 0x00,
                        0x00, 0x02, 0x00, 0x02, 0x00, 0x01, 0x00, 0x00, 0x05, 0x01, 0xFF};

std::string hex(const Bytes& b, const char* sep) {
  std::string s;
  char buf[4];
  for (std::size_t i = 0; i < b.size(); ++i) {
    std::snprintf(buf, sizeof buf, "%02X", b[i]);
    if (i > 0) s += sep;
    s += buf;
  }
  return s;
}

/// A blocking ISO-on-TCP client; reads give up after 20 s so that a broken door fails the test.
class IsoClient {
 public:
  /// Connects to 127.0.0.1:port, trying again until `until` (the door opens when the run has
  /// been built, about when the pty link appears).
  IsoClient(std::uint16_t port, std::chrono::steady_clock::time_point until) {
    for (;;) {
      fd_ = ::socket(AF_INET, SOCK_STREAM | SOCK_CLOEXEC, 0);
      sockaddr_in sa{};
      sa.sin_family = AF_INET;
      sa.sin_port = htons(port);
      sa.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
      timeval tv{20, 0};
      ::setsockopt(fd_, SOL_SOCKET, SO_RCVTIMEO, &tv, sizeof tv);
      ::setsockopt(fd_, SOL_SOCKET, SO_SNDTIMEO, &tv, sizeof tv);
      const int one = 1;
      ::setsockopt(fd_, IPPROTO_TCP, TCP_NODELAY, &one, sizeof one);
      if (::connect(fd_, reinterpret_cast<sockaddr*>(&sa), sizeof sa) == 0) return;
      ::close(fd_);
      fd_ = -1;
      if (std::chrono::steady_clock::now() >= until) return;
      std::this_thread::sleep_for(20ms);
    }
  }
  ~IsoClient() {
    if (fd_ >= 0) ::close(fd_);
  }
  IsoClient(const IsoClient&) = delete;
  IsoClient& operator=(const IsoClient&) = delete;
  bool connected() const { return fd_ >= 0; }

  /// Sends one TPKT and returns the door's answer (one whole TPKT; empty if the door closed).
  Bytes exchange(const Bytes& tpkt) {
    std::size_t done = 0;
    while (done < tpkt.size()) {
      const ssize_t n = ::send(fd_, tpkt.data() + done, tpkt.size() - done, MSG_NOSIGNAL);
      if (n <= 0) return {};
      done += static_cast<std::size_t>(n);
    }
    Bytes h = recv(4);
    if (h.size() < 4) return {};
    const std::size_t len = (std::size_t{h[2]} << 8) | h[3];
    if (len <= 4) return h;
    const Bytes rest = recv(len - 4);
    h.insert(h.end(), rest.begin(), rest.end());
    return h;
  }

 private:
  Bytes recv(std::size_t n) {
    Bytes b(n);
    std::size_t got = 0;
    while (got < n) {
      const ssize_t r = ::recv(fd_, b.data() + got, n - got, 0);
      if (r < 0 && errno == EINTR) continue;
      if (r <= 0) break;
      got += static_cast<std::size_t>(r);
    }
    b.resize(got);
    return b;
  }
  int fd_ = -1;
};

/// One run, shared by the tests below when they run in one process (it takes a few seconds of
/// wall time). ctest runs each test in a process of its own, possibly at the same time, so a
/// run's files (pty link, scenario, report, capture) are named after the test that made it.
struct PgRun {
  std::string skip;  ///< why the run could not be made here, or ""
  int pbvbus_status = -1;
  int pg_rc = -1;
  Bytes cc, setup_answer, write_answer;
  std::uint16_t door_port = 0;
  Flat report, pg;
  std::string report_json, pg_json, err, capture;
  double wall_s = 0;
};

PgRun make_run(const std::string& tag) {
  PgRun r;
  if (const auto why = test_support::missing_python(); !why.empty()) {
    r.skip = why;
    return r;
  }
  const auto t0 = std::chrono::steady_clock::now();
  const std::string base = std::string(PBVBUS_BINARY_DIR) + "/outside_pg_run_" + tag;
  const std::string link = base + ".pty", scenario_file = base + ".textproto";
  const std::string report_file = base + ".report.json", err_file = base + ".err";
  const std::string pg_file = base + ".pg.json";
  r.capture = base + ".pcapng";
  r.door_port = free_port();
  // PG 0 (the pty), OP 1, CPU 2: the MPI defaults (protocol-facts.md §H.1).
  const std::string port = std::to_string(r.door_port);
  std::string text = "name: \"outside PG over the pty\"\n";
  text += "line { name: \"MPI\" kind: MPI }\n";
  text += "s7_cpu { name: \"CPU\" mpi_dp { mode: MPI line: \"MPI\" } db { number: 1 size: 64 } }\n";
  text += "mpi_station { role: OP line: \"MPI\"\n";
  text += "  read { cpu: 2 item: \"DB1.DBW0\" period: \"100ms\" } }\n";
  text += "serial { line: \"MPI\" mode: STATION address: 0 timing: INTERFACE\n";
  text += "  link: \"" + link + "\" }\n";
  text += "s7_door { name: \"S7\" listen: \"127.0.0.1:" + port + "\"\n";
  text += "  route { rack: 0 slot: 2 cpu: \"CPU\" } }\n";
  std::ofstream(scenario_file) << text;

  std::cout.flush();
  std::fflush(nullptr);
  ::unlink(link.c_str());
  ::unlink(r.capture.c_str());
  const pid_t child = ::fork();
  if (child == 0) {
    const int out = ::open(report_file.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    const int err = ::open(err_file.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    ::dup2(out, STDOUT_FILENO);
    ::dup2(err, STDERR_FILENO);
    const int rc = cmd_run({scenario_file, "--speed", kSpeed, "--capture", r.capture, "--json"},
                           std::cout, std::cerr);
    std::cout.flush();
    std::cerr.flush();
    std::fflush(nullptr);
    ::_exit(rc);
  }
  if (child < 0) {
    ADD_FAILURE() << "fork failed";
    return r;
  }
  auto end_run = [&] {
    // Ctrl-C: the run ends with its report and closes the capture.
    ::kill(child, SIGINT);
    const auto until = std::chrono::steady_clock::now() + 10s;
    int st = 0;
    while (std::chrono::steady_clock::now() < until) {
      if (::waitpid(child, &st, WNOHANG) == child) {
        r.pbvbus_status = st;
        break;
      }
      std::this_thread::sleep_for(10ms);
    }
    if (r.pbvbus_status == -1) {
      ::kill(child, SIGKILL);
      ::waitpid(child, nullptr, 0);
      ADD_FAILURE() << "pbvbus run did not end within 10 s of SIGINT; killed";
    }
    r.report_json = read_file(report_file);
    r.err = read_file(err_file);
    r.report = flatten(report_file);
    r.wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  };
  // The link appears when the Simulation is built; then the run starts.
  struct stat st;
  const auto until = std::chrono::steady_clock::now() + 10s;
  while (::lstat(link.c_str(), &st) != 0 && std::chrono::steady_clock::now() < until)
    std::this_thread::sleep_for(10ms);
  if (::lstat(link.c_str(), &st) != 0) {
    ADD_FAILURE() << "no pty link " << link << " after 10 s: " << read_file(err_file);
    end_run();
    return r;
  }
  {
    // DB1.DBB0..15 := kDb1 through the door, before the PG starts.
    IsoClient c(r.door_port, std::chrono::steady_clock::now() + 10s);
    if (!c.connected()) {
      ADD_FAILURE() << "cannot connect to the S7 door on 127.0.0.1:" << r.door_port;
      end_run();
      return r;
    }
    r.cc = c.exchange(kCr);
    r.setup_answer = c.exchange(kSetup);
    r.write_answer = c.exchange(write_db1());
  }
  const auto [rc, out] = shell(std::string(kPython) + " " + kPg + " --port " + link +
                               " --address 0 --cpu 2 --db 1 --start 0 --length " +
                               std::to_string(kDb1.size()) + " --speed " + kSpeed);
  r.pg_rc = rc;
  r.pg_json = out;
  std::ofstream(pg_file) << out;
  r.pg = flatten(pg_file);
  end_run();
  return r;
}

const PgRun& the_run() {
  static const PgRun run =
      make_run(::testing::UnitTest::GetInstance()->current_test_info()->name());
  return run;
}

/// The run, or a skip / failure of the calling test when there is none.
#define REQUIRE_RUN(r)                                                                     \
  const PgRun& r = the_run();                                                              \
  if (!r.skip.empty()) GTEST_SKIP() << r.skip;                                             \
  ASSERT_TRUE(WIFEXITED(r.pbvbus_status))                                                  \
      << "pbvbus run did not exit normally (status " << r.pbvbus_status << "): " << r.err; \
  ASSERT_FALSE(r.report.empty()) << "report: " << r.report_json << "\nstderr: " << r.err

TEST(OutsidePgRun, ThePgReadsWhatTheDoorWroteIntoDb1) {
  REQUIRE_RUN(r);
  std::cout << "wall time of the run: " << r.wall_s << " s; PG: " << r.pg_json;
  ::testing::Test::RecordProperty("wall_time_s", std::to_string(r.wall_s));
  EXPECT_EQ(WEXITSTATUS(r.pbvbus_status), 0) << r.err;
  // The door: CC (TPDU class 0, the CR's parameters echoed), Setup answered with PDU 240, the
  // Write Var acknowledged (return code FF).
  ASSERT_EQ(r.cc.size(), 22u) << hex(r.cc, " ");
  EXPECT_EQ(r.cc[5], 0xD0);
  ASSERT_EQ(r.setup_answer.size(), 27u) << hex(r.setup_answer, " ");
  EXPECT_EQ(r.setup_answer[8], 0x03);  // Ack-Data
  EXPECT_EQ(r.setup_answer[25], 0x00);
  EXPECT_EQ(r.setup_answer[26], 0xF0);  // PDU length 240
  EXPECT_EQ(r.write_answer, kWriteOk) << hex(r.write_answer, " ");

  // The PG: connected to CPU 2, PDU size 240 negotiated, the 16 bytes read, disconnected.
  ASSERT_EQ(r.pg_rc, 0) << r.pg_json;
  const Flat& pg = r.pg;
  EXPECT_EQ(get(pg, "ok"), "true");
  EXPECT_EQ(get(pg, "connected"), "true");
  EXPECT_EQ(get(pg, "disconnected"), "true");
  EXPECT_EQ(get(pg, "address"), "0");
  EXPECT_EQ(get(pg, "cpu"), "2");
  EXPECT_EQ(get(pg, "pdu_size"), "240");
  EXPECT_EQ(get(pg, "bytes_read"), std::to_string(kDb1.size()));
  EXPECT_EQ(get(pg, "data"), hex(kDb1, " "));
  EXPECT_EQ(get(pg, "error"), "null");
  EXPECT_EQ(get(pg, "reads"), "1");  // 16 bytes: one Read Var job
  EXPECT_EQ(get(pg, "refused"), "0");

  // pbvbus's side: the CPU accepted the PG's and the OP's connections; the PG's is closed
  // again (the OP's stays open); the door took CR, Setup and Write Var.
  const Flat& rep = r.report;
  EXPECT_EQ(get(rep, "s7.cpus.0.name"), "CPU");
  EXPECT_EQ(get(rep, "s7.cpus.0.mpi_address"), "2");
  EXPECT_GE(std::stoul(get(rep, "s7.cpus.0.connections_accepted")), 2u);
  EXPECT_EQ(get(rep, "s7.cpus.0.connections_refused"), "0");
  EXPECT_EQ(get(rep, "s7.cpus.0.connections_open"), "1");
  EXPECT_EQ(get(rep, "s7.doors.0.port"), std::to_string(r.door_port));
  EXPECT_EQ(get(rep, "s7.doors.0.connects"), "1");
  EXPECT_EQ(get(rep, "s7.doors.0.jobs"), "2");  // Setup Communication, Write Var
  EXPECT_EQ(get(rep, "s7.doors.0.answers"), "2");
  EXPECT_EQ(get(rep, "s7.stations.0.role"), "OP");
  EXPECT_EQ(get(rep, "s7.stations.0.reads.0.errors"), "0");
  // The attachment passed every telegram the PG wrote; no receiver dropped one for lack of TSYN.
  EXPECT_EQ(get(rep, "serial.0.address"), "0");
  EXPECT_EQ(get(rep, "serial.0.timing"), "interface");
  EXPECT_EQ(get(rep, "serial.0.frames_in"), get(pg, "frames_sent"));
  EXPECT_EQ(get(rep, "serial.0.receivers_tsyn_drops"), "0");
  EXPECT_EQ(get(rep, "serial.0.program_opens"), "1");
  EXPECT_EQ(get(rep, "lines.0.errors.tsyn_drops"), "0");
}

/// tshark's hex of a bytes field, upper case, without separators.
std::string bare_hex(std::string s) {
  s.erase(std::remove(s.begin(), s.end(), ':'), s.end());
  for (char& c : s) c = static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
  return s;
}

TEST(OutsidePgRun, TheCaptureShowsThePgsConnectionDecoded) {
  if (!ts::tshark_available()) GTEST_SKIP() << ts::kNoTshark;
  REQUIRE_RUN(r);
  ASSERT_EQ(r.pg_rc, 0) << r.pg_json;
  // The MPI frames between the PG (0) and the CPU (2), in capture order.
  enum { kSa, kDa, kPdu, kNr, kRosctr, kFunc, kRet, kPduLen, kItems, kS7 };
  const auto rows = ts::tshark_fields(
      r.capture,
      {"pbfdl.sa", "pbfdl.da", "pbmpi.pdu", "pbmpi.msg_nr", "s7comm.header.rosctr",
       "s7comm.param.func", "s7comm.data.returncode", "s7comm.param.pdu_length",
       "s7comm.param.itemcount", "pbmpi.s7_pdu"},
      "pbmpi && ((pbfdl.sa == 0 && pbfdl.da == 2) || (pbfdl.sa == 2 && pbfdl.da == 0))");
  ASSERT_FALSE(rows.empty()) << "no MPI frames between 0 and 2 in " << r.capture;
  for (const auto& row : rows) ASSERT_EQ(row.size(), 10u);
  /// The index of the first row at or after `from` that `match` accepts.
  auto find = [&](std::size_t from, auto match) -> std::optional<std::size_t> {
    for (std::size_t i = from; i < rows.size(); ++i)
      if (match(rows[i])) return i;
    return std::nullopt;
  };
  auto is = [](const char* sa, const char* da, const char* pdu) {
    return [=](const std::vector<std::string>& row) {
      return row[kSa] == sa && row[kDa] == da && row[kPdu] == pdu;
    };
  };
  auto data = [&](const char* sa, const char* da, const char* rosctr, const char* func) {
    return [=](const std::vector<std::string>& row) {
      return is(sa, da, "0xf1")(row) && row[kRosctr] == rosctr && row[kFunc] == func;
    };
  };
  std::string all;
  for (const auto& row : rows)
    all += row[kSa] + ">" + row[kDa] + " " + row[kPdu] + " " + row[kFunc] + " " + row[kRet] + "\n";

  // §H.3: connect request from the PG to the CPU's SAP 0, the CPU's confirm, the acks.
  const auto cr = find(0, is("0", "2", "0xe0"));
  ASSERT_TRUE(cr) << all;
  const auto cc = find(*cr, is("2", "0", "0xd0"));
  ASSERT_TRUE(cc) << all;
  // Setup Communication: the PG's job (PDU 240) and the CPU's Ack-Data (240).
  const auto setup = find(*cc, data("0", "2", "1", "0xf0"));
  ASSERT_TRUE(setup) << all;
  EXPECT_EQ(rows[*setup][kPduLen], "240");
  EXPECT_EQ(rows[*setup][kNr], "0");                       // the PG's first data message
  ASSERT_TRUE(find(*setup, is("2", "0", "0xb0"))) << all;  // the CPU's MPI ack
  const auto setup_ack = find(*setup, data("2", "0", "3", "0xf0"));
  ASSERT_TRUE(setup_ack) << all;
  EXPECT_EQ(rows[*setup_ack][kPduLen], "240");
  ASSERT_TRUE(find(*setup_ack, is("0", "2", "0xb0"))) << all;  // the PG's MPI ack
  // Read Var: one item; the answer's return code FF and the 16 bytes written over the door.
  const auto read = find(*setup_ack, data("0", "2", "1", "0x04"));
  ASSERT_TRUE(read) << all;
  EXPECT_EQ(rows[*read][kItems], "1");
  EXPECT_EQ(rows[*read][kNr], "1");
  const auto answer = find(*read, data("2", "0", "3", "0x04"));
  ASSERT_TRUE(answer) << all;
  EXPECT_EQ(rows[*answer][kItems], "1");
  EXPECT_EQ(rows[*answer][kRet], "0xff");
  const std::string s7 = bare_hex(rows[*answer][kS7]);
  const std::string want = hex(kDb1, "");
  ASSERT_GE(s7.size(), want.size()) << s7;
  EXPECT_EQ(s7.substr(s7.size() - want.size()), want);
  const auto answer_ack = find(*answer, is("0", "2", "0xb0"));
  ASSERT_TRUE(answer_ack) << all;
  // The PG's disconnect request.
  EXPECT_TRUE(find(*answer_ack, is("0", "2", "0x80"))) << all;
  // Neither side sent a data message the dissector could not hand to s7comm.
  const auto undecoded = ts::tshark_fields(r.capture, {"frame.number"}, "pbmpi.s7_undecoded");
  EXPECT_TRUE(undecoded.empty()) << undecoded.size() << " undecoded data messages";
}

}  // namespace
}  // namespace pbvbus::tools
