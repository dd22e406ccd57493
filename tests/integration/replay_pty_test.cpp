// `pbvbus replay CAPTURE --pty PATH --station ADDR` against a real program: the Python DP slave
// tests/integration/outside_slave.py (PBVB0A01, 16DI/16DO) behind the pty replay creates.
//
// The capture is recorded by the test from tests/data/scenarios/replay-pty.textproto (DP master
// 1, PBVB0A01 at 5, 9.6 kbit/s, 1 s of virtual time: start-up, Data_Exchange, Global_Control,
// GAP polls). The replay runs at --speed 1/20 like the battery's pty tests
// (outside_slave_test.cpp: min TSDR, max TSDR and TSL are 23, 125 and 208 ms of wall time).
//
// Decisions:
// - Who makes the pty: replay does (a PtyStation in station mode at 5, PATH a symlink to it;
//   cmd_replay.cpp run_pty). The program is started FIRST: it polls for PATH every 10 ms
//   (--wait-port, 30 s by default) and so is loaded and opens the pty within ~10 ms of the
//   link appearing, well before the first request goes out (power-on + TSYN = 69 ms of wall
//   time at 1/20). Started after replay, the Python start-up (~0.2 s) could miss the first
//   request (the program flushes pending input on open).
// - Requests to 5 are counted from the capture file itself (a small pcapng reader in Python:
//   SD1/SD2/SD3 with the request bit, DA 5 or 127); replies to 5 likewise (SD1/SD2/SD3 response
//   FCs and SC are not distinguished by DA here: a reply is any response frame with SA 5, plus
//   SC; the scenario has only one slave, so every SC is station 5's).
// - Input data: `--mask inputs`. The model's input counter (devices::SlaveModel) is the number
//   of DP cycles BEFORE the current one (first Data_Exchange answers 00 00), the program's is the
//   number of Data_Exchanges executed INCLUDING the current one (first answers 00 01): every
//   Data_Exchange reply differs in DU octet 1 by one. Measured without the mask: 8 "other data",
//   one per Data_Exchange, nothing else in the data. Masked, the count of masked octets is
//   asserted (the replies with a differing octet).
// - Timing: replay measures TSDR in VIRTUAL time on the replay's line. A program behind a pty
//   answers when the wall clock lets it: its reply enters the line at the virtual time matching
//   the wall time it was read (PtyStation, Interface timing: a response goes out as soon as the
//   line is free), so the measured TSDR is the program's min-TSDR wait plus the pty's, Python's
//   and the scheduler's latency scaled by 1/20. This test found a bug there: run_pty drove the
//   PacedRunner in 1 ms slices, every run_until() re-anchored virtual time to the wall clock,
//   and the program's reply delay shrank (TSDR 7 bit times measured from a program that waits
//   11; the battery had the same bug, fixed in 08dd63a). Fixed in tools/src/cmd_replay.cpp (one
//   run, stopped when the replayer is done); measured since: 11 bit times for most replies, up
//   to ~20 now and then. The window is [min TSDR 11 (default), TSL 100] (--max-tsdr 100): an
//   early reply (the bug) is still a timing difference, while the latency a loaded machine adds
//   beyond max TSDR 60 (125 ms of wall time) is not bus timing and is tolerated up to the slot
//   time; a reply later than TSL is a missing reply anyway. Timing differences: 0, asserted.
// - The second run ends the program with SIGTERM about halfway (8 s into the ~18 s replay): it
//   stops reading, prints its summary (JSON) and exits; the PtyStation keeps its own handle on
//   the pty, so the line goes on and every request after that gets no reply. Exact: all
//   differences are missing replies, matches + missing == compared, and the program's own count
//   of replies sent equals replay's matches (each reply it wrote arrived and matched), exit 1.
// - Helpers (Child, shell(), flatten(), the skip reasons) are outside_slave_test.cpp's, shared
//   through outside_slave_support.hpp.
// - A run of the honest program that differs by missing replies only (the program not scheduled
//   within the slot time on a loaded machine, 208 ms of wall time) is repeated once, as in
//   outside_slave_test.cpp.
// Wall time: two replays of ~18 s each (about 40 s with the recording and start-ups).
#include <gtest/gtest.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <iterator>
#include <iostream>
#include <map>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "outside_slave_support.hpp"

namespace pbvbus::conformance {
namespace {

using namespace pbvbus::test_support;
using namespace std::chrono_literals;

const std::string kScenario = PBVBUS_SOURCE_DIR "/tests/data/scenarios/replay-pty.textproto";
constexpr int kDut = 5;
constexpr const char* kSpeed = "1/20";
constexpr const char* kBaud = "9.6k";

/// "path=value" lines of a Python snippet's output.
Flat parse_flat(const std::string& out) {
  Flat m;
  std::istringstream in(out);
  for (std::string line; std::getline(in, line);) {
    const auto eq = line.find('=');
    if (eq != std::string::npos) m[line.substr(0, eq)] = line.substr(eq + 1);
  }
  return m;
}

int num(const Flat& m, const std::string& key) {
  const auto it = m.find(key);
  return it == m.end() ? -1 : std::atoi(it->second.c_str());
}

/// The capture's frames counted by hand: "requests" = SD1/SD2/SD3 with the request bit (FC
/// bit 6) to DA 5 or 127 (DA's extension bit 7 masked), "replies" = responses (request bit 0)
/// with SA 5 plus SC (only station 5 answers in the scenario), "frames" = all frames of the
/// line (interfaces USER0/PROFIBUS_DL; the USER1 event records are not frames).
Flat count_capture(const std::string& file) {
  const auto [rc, out] = shell(
      std::string(kPython) +
      " -c 'import struct,sys\n"
      "d = open(sys.argv[1], \"rb\").read()\n"
      "o = 0; fr = rq = rp = 0; ifs = []\n"
      "while o + 12 <= len(d):\n"
      "  t, n = struct.unpack_from(\"<II\", d, o)\n"
      "  if t == 1: ifs.append(struct.unpack_from(\"<H\", d, o + 8)[0])\n"
      "  if t == 6 and ifs[struct.unpack_from(\"<I\", d, o + 8)[0]] in (147, 257):\n"
      "    cl = struct.unpack_from(\"<I\", d, o + 20)[0]\n"
      "    f = d[o + 28:o + 28 + cl]\n"
      "    if f:\n"
      "      fr += 1\n"
      "      if f[0] == 0xE5: rp += 1\n"
      "      elif f[0] in (0x10, 0x68, 0xA2):\n"
      "        h = 4 if f[0] == 0x68 else 1\n"
      "        da, sa, fc = f[h] & 0x7F, f[h + 1] & 0x7F, f[h + 2]\n"
      "        if fc & 0x40:\n"
      "          rq += da in (5, 127)\n"
      "        else:\n"
      "          rp += sa == 5\n"
      "  if n < 12: break\n"
      "  o += n\n"
      "print(\"frames=%d\" % fr); print(\"requests=%d\" % rq); print(\"replies=%d\" % rp)' " +
      file + " 2>&1");
  EXPECT_EQ(rc, 0) << out;
  return parse_flat(out);
}

struct ReplayRun {
  int rc = -1;
  Flat report;  ///< replay's --json
  std::string err;
  int slave_rc = -1;
  Flat summary;  ///< the program's JSON summary
  std::string slave_err;
};

/// Starts the program (extra options), then `pbvbus replay CAPTURE --pty ...`; with
/// `stop_after` > 0 the program gets SIGTERM that long after the replay started.
ReplayRun run_replay(const std::string& name, const std::string& capture, std::chrono::seconds stop_after) {
  ReplayRun r;
  const std::string base = std::string(PBVBUS_BINARY_DIR) + "/replay_pty_" + name + "_" + std::to_string(::getpid());
  const std::string link = base + ".dut";
  Child slave = Child::spawn({kPython, kSlave, "--port", link, "--address", std::to_string(kDut), "--speed",
                              kSpeed, "--baud", kBaud, "--gsd", kGsd, "--max-time", "300"},
                             base + ".slave");
  if (slave.pid <= 0) {
    ADD_FAILURE() << "cannot start " << kSlave;
    return r;
  }
  Child replay = Child::spawn({kBinary, "replay", capture, "--pty", link, "--station", std::to_string(kDut),
                               "--speed", kSpeed, "--mask", "inputs", "--max-tsdr", "100",
                               "--max-diffs", "100", "--json"},
                              base + ".replay");
  if (replay.pid <= 0) {
    ADD_FAILURE() << "cannot start " << kBinary;
    return r;
  }
  if (stop_after.count() > 0) {
    std::this_thread::sleep_for(stop_after);
    r.slave_rc = slave.stop();
    r.rc = replay.wait(120s);
  } else {
    r.rc = replay.wait(120s);
    r.slave_rc = slave.stop();
  }
  r.report = flatten(replay.out_file);
  r.err = read_file(replay.err_file);
  r.summary = flatten(slave.out_file);
  r.slave_err = read_file(slave.err_file);
  for (const auto& f : {replay.out_file, replay.err_file, slave.out_file, slave.err_file}) std::remove(f.c_str());
  return r;
}

std::string describe(const ReplayRun& r) {
  std::string s = "replay rc " + std::to_string(r.rc) + ", stderr: " + r.err + "\nreport:\n";
  for (const auto& [k, v] : r.report) s += "  " + k + "=" + v + "\n";
  s += "program rc " + std::to_string(r.slave_rc) + ", stderr (tail): " +
       r.slave_err.substr(r.slave_err.size() > 2000 ? r.slave_err.size() - 2000 : 0) + "\n";
  return s;
}

/// Records the capture once per test binary run.
std::string record_capture() {
  const std::string cap = std::string(PBVBUS_BINARY_DIR) + "/replay_pty_" + std::to_string(::getpid()) + ".pcapng";
  const auto [rc, out] = shell(kBinary + " run " + kScenario + " --duration 1s --capture " + cap + " 2>&1");
  EXPECT_EQ(rc, 0) << out;
  return cap;
}

TEST(ReplayPty, HonestPythonSlaveAnswersEveryReplayedRequest) {
  if (const auto why = missing_python(); !why.empty()) GTEST_SKIP() << why;
  if (const auto why = missing_binary(); !why.empty()) GTEST_SKIP() << why;
  const std::string cap = record_capture();
  const Flat counted = count_capture(cap);
  const int requests = num(counted, "requests"), replies = num(counted, "replies");
  ASSERT_GT(requests, 10);
  ASSERT_GT(replies, 5);

  ReplayRun r = run_replay("honest", cap, 0s);
  if (r.rc == 1 && num(r.report, "totals.differences") == num(r.report, "totals.by_kind.missing_reply")) {
    // The program not scheduled within the slot time (208 ms of wall time) on a loaded machine.
    std::cout << "[ retry    ] missing replies only (a loaded machine?): running again\n";
    ::testing::Test::RecordProperty("retried_after_missed_replies", "1");
    r = run_replay("honest_retry", cap, 0s);
  }
  const std::string d = describe(r);
  EXPECT_EQ(r.rc, 0) << d;
  EXPECT_EQ(get(r.report, "schema"), "pbvbus.replay/1") << d;
  EXPECT_EQ(get(r.report, "target"), "5") << d;
  EXPECT_EQ(num(r.report, "totals.recorded_frames"), num(counted, "frames")) << d;
  // Every request to 5 (and broadcast) was sent, every recorded reply compared.
  EXPECT_EQ(num(r.report, "totals.requests_replayed"), requests) << d;
  EXPECT_EQ(num(r.report, "totals.tokens_replayed"), 0) << d;
  EXPECT_EQ(num(r.report, "totals.compared"), replies) << d;
  EXPECT_EQ(num(r.report, "totals.matches"), replies) << d;
  EXPECT_EQ(num(r.report, "totals.differences"), 0) << d;
  for (const char* k : {"missing_reply", "extra_reply", "other_fc", "other_data", "timing"})
    EXPECT_EQ(num(r.report, std::string("totals.by_kind.") + k), 0) << k << "\n" << d;
  EXPECT_EQ(num(r.report, "totals.unusable"), 0) << d;
  EXPECT_EQ(get(r.report, "tsdr_window.0"), "11") << d;
  EXPECT_EQ(get(r.report, "tsdr_window.1"), "100") << d;
  // The inputs mask hid the counter octet of every Data_Exchange reply (see the header).
  EXPECT_EQ(get(r.report, "masks.0.rule"), "inputs") << d;
  EXPECT_EQ(num(r.report, "masks.0.octets_masked"), num(r.summary, "dp.data_exchange")) << d;
  // The program's own view: it heard every request and answered every one that wants a reply.
  EXPECT_EQ(num(r.summary, "fdl.telegrams"), requests) << d;
  EXPECT_EQ(num(r.summary, "fdl.replies"), replies) << d;
  EXPECT_EQ(num(r.summary, "fdl.bad_telegrams"), 0) << d;
  EXPECT_EQ(get(r.summary, "state"), "Data_Exch") << d;
  EXPECT_EQ(get(r.summary, "master"), "1") << d;
  std::remove(cap.c_str());
}

TEST(ReplayPty, ProgramStoppedHalfwayGivesMissingRepliesFromThenOn) {
  if (const auto why = missing_python(); !why.empty()) GTEST_SKIP() << why;
  if (const auto why = missing_binary(); !why.empty()) GTEST_SKIP() << why;
  const std::string cap = record_capture();
  const Flat counted = count_capture(cap);
  const int requests = num(counted, "requests"), replies = num(counted, "replies");

  const ReplayRun r = run_replay("stopped", cap, 8s);
  const std::string d = describe(r);
  EXPECT_EQ(r.rc, 1) << d;
  EXPECT_EQ(r.slave_rc, 0) << d;  // SIGTERM: summary printed, exit 0
  EXPECT_EQ(get(r.summary, "ended"), "killed") << d;
  EXPECT_EQ(num(r.report, "totals.requests_replayed"), requests) << d;
  EXPECT_EQ(num(r.report, "totals.compared"), replies) << d;
  const int matches = num(r.report, "totals.matches");
  const int missing = num(r.report, "totals.by_kind.missing_reply");
  EXPECT_GT(matches, 0) << d;
  EXPECT_GT(missing, 0) << d;
  EXPECT_EQ(matches + missing, replies) << d;
  EXPECT_EQ(num(r.report, "totals.differences"), missing) << d;
  for (const char* k : {"extra_reply", "other_fc", "other_data", "timing"})
    EXPECT_EQ(num(r.report, std::string("totals.by_kind.") + k), 0) << k << "\n" << d;
  // Every reply the program sent before it stopped matched (its own count), and the requests it
  // never read are exactly the ones without a reply: the missing replies are the last ones.
  EXPECT_EQ(num(r.summary, "fdl.replies"), matches) << d;
  EXPECT_LT(num(r.summary, "fdl.telegrams"), requests) << d;
  EXPECT_EQ(num(r.report, "masks.0.octets_masked"), num(r.summary, "dp.data_exchange")) << d;
  long long last = -1;
  for (int i = 0; i < missing; ++i) {
    const std::string p = "differences." + std::to_string(i) + ".";
    EXPECT_EQ(get(r.report, p + "kind"), "missing_reply") << i << "\n" << d;
    EXPECT_EQ(get(r.report, p + "replayed"), "null") << i << "\n" << d;
    const long long t = std::atoll(get(r.report, p + "time_ns").c_str());
    EXPECT_GT(t, last) << i << "\n" << d;
    last = t;
  }
  std::remove(cap.c_str());
}

}  // namespace
}  // namespace pbvbus::conformance
