// The capture of examples/multimaster.textproto, read the way an analyzer reads it: taken with
// `pbvbus run --capture` from the default probe (next to master 1, the first station on the
// cable) and checked by tests/integration/check_capture.py, a standalone Python program with its
// own pcapng reader and FDL decoder (it shares no code with pbvbus), then by tshark with the Lua
// dissector. The capture must show what happened on master 1's side of the cable: master 3
// leaves the ring at the cut (2 s) and rejoins after the repair (3 s), and the only collisions
// are the ones that really reach the probe, while the two token holders meet after the repair.
//
// The expectations are bounds derived from the FDL rules and the scenario's bus parameters
// (DP defaults at 1.5 Mbit/s: TSL 300, max TSDR 150, TID1 37 bit times; TTR 30 000; G = 10;
// HSA 126; token pass: 3 attempts in total, docs/fdl-stations.md), worked out below.
#include <gtest/gtest.h>

#include <cstdio>
#include <fstream>
#include <unistd.h>
#include <sstream>
#include <sys/stat.h>

#include "../captures/tshark_helpers.hpp"
#include "pbvbus/captures/pcapng_reader.hpp"
#include "pbvbus/tools/commands.hpp"
#include "pbvbus/scenario/scenario.hpp"

namespace pbvbus::tools {
namespace {

using bus::Ticks;

constexpr const char* kPython = "/usr/bin/python3";
const std::string kScript = PBVBUS_SOURCE_DIR "/tests/integration/check_capture.py";
const std::string kExample = PBVBUS_SOURCE_DIR "/examples/multimaster.textproto";

/// Unique per process: ctest runs every test case as a process of its own, in parallel.
std::string temp_path(const std::string& name) {
  return std::string(PBVBUS_BINARY_DIR) + "/capture_check_test_" + std::to_string(::getpid()) +
         "_" + name;
}

bool have_python() {
  struct stat st;
  return ::stat(kPython, &st) == 0;
}

/// Exact seconds for the script's window arguments: "TICKS/TICKS_PER_SECOND".
std::string s(Ticks t) { return std::to_string(t) + "/" + std::to_string(bus::kTicksPerSecond); }
std::string window(Ticks a, Ticks b) { return s(a) + ":" + s(b); }

/// Runs the checker; returns its exit status and prints its report on failure.
int check(const std::string& pcap, const std::vector<std::string>& args, std::string* report) {
  std::string cmd = std::string(kPython) + " " + test::shell_quote(kScript) + " " +
                    test::shell_quote(pcap);
  for (const auto& a : args) cmd += " " + test::shell_quote(a);
  const test::CommandResult r = test::run_command(cmd);
  *report = r.out + r.err;
  return r.exit_code;
}

/// The bounds, in ticks, from the line's bus parameters.
struct Bounds {
  Ticks longest_frame;  ///< a 255-octet telegram
  Ticks settle;         ///< after the repair: until one token holder is left
  Ticks leave;          ///< after the cut: the last token to master 3
  Ticks rejoin;         ///< after the repair: a token to master 3 again
  std::int64_t rotation_bits;
};

Bounds bounds(const PlanLine& line) {
  const fdl::BusParams& p = line.params;
  const auto bits = [&](std::int64_t b) { return bus::bits_to_ticks(b, line.baud); };
  Bounds b;
  // A telegram is at most 255 octets of 11 bits: a frame damaged by the cut or the repair
  // started at most that long before it.
  const std::int64_t longest = 255 * 11;  // 2805 bit times
  b.longest_frame = bits(longest);
  // The longest message cycle: request and reply of 255 octets, max TSDR between, TID1 after.
  const std::int64_t cycle = 2 * longest + p.max_tsdr + p.tid1();  // 5797 bit times
  // Leaving: after the cut master 2 gets the token within one rotation, at most TTR plus one
  // message cycle per master that holds it late (3 masters); it passes to 3 in 3 attempts
  // (TID1, the 3-octet token, TSL of waiting for 3 to use it, each), then passes to 1 and drops
  // 3 from its LAS. While the cable is cut, 3 cannot answer the GAP polls, so nobody passes to
  // it again: TTR + 3·cycle + 3·(TID1 + 33 + TSL) = 48 501 bit times (32.3 ms).
  b.leave = bits(p.ttr + 3 * cycle + 3 * (p.tid1() + 33 + p.tsl));
  // Settling: after the repair two token holders share the cable (the 1-2 ring and master 3
  // alone). Their frames collide and follow each other without TSYN until one holder hears a
  // valid frame of the other and drops its token (duplicate token); by then each has finished at
  // most the message cycle it was in. If both drop it, the line is silent for at most TTO of the
  // highest master (3: 6·TSL + 2·3·TSL) and a master claims it (DC n n twice). Then one holder
  // is left: cycle + TTO(3) + 2·(33 + TID1) = 9 537 bit times (6.4 ms).
  b.settle = bits(cycle + p.tto(3) + 2 * (33 + p.tid1()));
  // Rejoining: master 3 is found again by GAP polling (it answers "ready to enter the ring" and
  // gets the token at once). Master 2's GAP during the cut is 3..HSA and 0: 125 addresses,
  // one polled per token visit, and a new scan starts G = 10 visits after the last one; so 3 is
  // polled at the latest 125 + 10 visits after the repair. The 1-2 ring's rotation during the
  // cut is exactly (bit times; frames of the scenario, TSDR 11 or 30 for station 11):
  //   master 2: SRD high to 12 (41-octet SD2, reply 41 octets): 451 + 11 + 451 + TID1 37 = 950
  //             SDA to 10 (13-octet SD2, SC):                    143 + 11 + 11 + 37      = 202
  //             GAP poll, nobody there (SD1, then TSL):          66 + 300                = 366
  //             token to 1:                                       33 + 37                 =  70
  //   master 1: SRD to 10 (SD3, reply SD3):                      154 + 11 + 154 + 37     = 356
  //             SRD to 11 (response delay 30):                   154 + 30 + 154 + 37     = 375
  //             token to 2:                                       33 + 37                 =  70
  //   = 2 389 bit times (checked on the capture with --expect-rotation-at-most).
  // The poll, the reply and the token pass take less than one more rotation. With the settling
  // first: settle + (125 + 10 + 1)·2389 bit times = 334 441 bit times (223 ms).
  b.rotation_bits = 950 + 202 + 366 + 70 + 356 + 375 + 70;
  const std::int64_t gap = (p.hsa - 3 + 1) + 1;  // 3..HSA and 0
  b.rejoin = b.settle + bits((gap + p.gap_factor + 1) * b.rotation_bits);
  return b;
}

class CaptureCheck : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    const auto loaded = load_scenario_file(kExample);
    ASSERT_TRUE(loaded.ok());
    s_plan = new ScenarioPlan(*loaded.plan);
    s_pcap = new std::string(temp_path("multimaster.pcapng"));
    std::ostringstream out, err;
    s_rc = cmd_run({kExample, "--capture", *s_pcap, "--quiet"}, out, err);
    s_err = new std::string(err.str());
  }
  static void TearDownTestSuite() {
    std::remove(s_pcap->c_str());
    delete s_plan;
    delete s_pcap;
    delete s_err;
  }
  static ScenarioPlan* s_plan;
  static std::string* s_pcap;
  static std::string* s_err;
  static int s_rc;
};
ScenarioPlan* CaptureCheck::s_plan = nullptr;
std::string* CaptureCheck::s_pcap = nullptr;
std::string* CaptureCheck::s_err = nullptr;
int CaptureCheck::s_rc = -1;

TEST_F(CaptureCheck, TheBoundsFollowFromTheBusParameters) {
  const Bounds b = bounds(s_plan->lines[0]);
  const Ticks bit = bus::ticks_per_bit(bus::Baud::k1_5M);
  EXPECT_EQ(b.longest_frame / bit, 2805);
  EXPECT_EQ(b.settle / bit, 9537);
  EXPECT_EQ(b.leave / bit, 48501);
  EXPECT_EQ(b.rotation_bits, 2389);
  EXPECT_EQ(b.rejoin / bit, 334441);
}

TEST_F(CaptureCheck, DefaultProbeShowsMaster3LeavingAndRejoiningAndNoFalseCollision) {
  if (!have_python()) GTEST_SKIP() << kPython << " not found";
  ASSERT_EQ(s_rc, 0) << *s_err;
  const PlanLine& line = s_plan->lines[0];
  const Bounds b = bounds(line);
  const Ticks sec = bus::kTicksPerSecond;
  std::string report;
  const int rc = check(
      *s_pcap,
      {"--interface", "A", "--tsl", std::to_string(line.params.tsl), "--min-tsdr",
       std::to_string(line.params.min_tsdr),
       // Tolerated: frames that started before the cut or the repair and were damaged by it,
       // and the meeting of the two token holders after the repair. Nothing else: before the
       // probe, the whole-line capture showed thousands of collisions and token conflicts
       // between 2 s and 3 s.
       "--allow", window(2 * sec - b.longest_frame, 2 * sec),
       "--allow", window(3 * sec - b.longest_frame, 3 * sec + b.settle),  //
       "--expect-clean",
       // Every station, and no phantom (26, 28, 38, ... came from interleaved partitions).
       "--expect-live", "1,2,3,10,11,12,13,14",
       // In the ring before the cut.
       "--expect-token-to", "3@" + window(1 * sec, 2 * sec),
       // Gone: nothing from master 3 reaches master 1's side during the cut, and master 2
       // stops passing it the token within the bound.
       "--expect-silent", "3@" + window(2 * sec, 3 * sec),
       "--expect-no-token-to", "3@" + window(2 * sec + b.leave, 3 * sec),
       "--expect-rotation-at-most",
       "2@" + window(2 * sec + b.leave, 3 * sec) + "=" + std::to_string(b.rotation_bits),
       // Back: a token to 3 from another master after the repair, within the bound, and in the
       // ring for good later.
       "--expect-token-to", "3@" + window(3 * sec, 3 * sec + b.rejoin),
       "--expect-token-to", "3@" + window(4 * sec, 5 * sec)},
      &report);
  EXPECT_EQ(rc, 0) << report;
  // The report names what it found, for the log.
  EXPECT_NE(report.find("live list: 1, 2, 3, 10, 11, 12, 13, 14"), std::string::npos) << report;
  EXPECT_NE(report.find("\nOK\n"), std::string::npos) << report;
}

TEST_F(CaptureCheck, TheCheckerCatchesWhatItLooksFor) {
  if (!have_python()) GTEST_SKIP() << kPython << " not found";
  ASSERT_EQ(s_rc, 0) << *s_err;
  const Ticks sec = bus::kTicksPerSecond;
  std::string report;
  // Without the tolerance window, the meeting of the two rings after the repair counts.
  EXPECT_EQ(check(*s_pcap, {"--expect-clean"}, &report), 1) << report;
  EXPECT_NE(report.find("overlapping frames (collision) outside the allowed windows"),
            std::string::npos) << report;
  EXPECT_NE(report.find("token-holder conflicts outside"), std::string::npos) << report;
  EXPECT_EQ(check(*s_pcap, {"--expect-live", "1,2,3"}, &report), 1);
  EXPECT_NE(report.find("phantoms [10, 11, 12, 13, 14]"), std::string::npos) << report;
  EXPECT_EQ(check(*s_pcap, {"--expect-token-to", "3@" + window(2 * sec + sec / 10, 3 * sec)},
                  &report),
            1);
  EXPECT_EQ(check(*s_pcap, {"--expect-silent", "1@" + window(2 * sec, 3 * sec)}, &report), 1);
  EXPECT_EQ(check(*s_pcap, {"--expect-rotation-at-most", "2@" + window(2 * sec + sec / 10,
                                                                        3 * sec) + "=2388"},
                  &report),
            1);
  EXPECT_NE(report.find("up to 2389 bit times apart"), std::string::npos) << report;
  EXPECT_EQ(check("/nonexistent.pcapng", {}, &report), 2);
}

TEST_F(CaptureCheck, TsharkReadsItToTheEndAndFindsNothingMalformedThatWasNotDamaged) {
  if (!test::tshark_available()) GTEST_SKIP() << test::kNoTshark;
  ASSERT_EQ(s_rc, 0) << *s_err;
  captures::PcapngError e;
  auto reader = captures::PcapngReader::open(*s_pcap, e);
  ASSERT_TRUE(reader) << e.to_string();
  captures::PcapngRecord rec;
  std::size_t records = 0;
  while (reader->next(rec)) ++records;
  ASSERT_FALSE(reader->error());
  const auto all = test::tshark_fields(*s_pcap, {"frame.number"});
  EXPECT_EQ(all.size(), records);
  // Malformed packets only where the link layer flagged the frame (collisions at the probe).
  const auto malformed = test::tshark_fields(*s_pcap, {"frame.number"}, "_ws.malformed");
  EXPECT_LT(malformed.size(), 20u);
  const auto unexplained = test::tshark_fields(
      *s_pcap, {"frame.number"}, "_ws.malformed && !(frame.packet_flags & 0xffff0000)");
  EXPECT_TRUE(unexplained.empty()) << unexplained.size() << " malformed packets, first frame "
                                   << unexplained[0][0];
}

TEST(CaptureCheckProbes, TwoProbesOnTheLineShowEachSideOfTheCut) {
  if (!have_python()) GTEST_SKIP() << kPython << " not found";
  // The example with a probe next to master 1 and one next to master 3, beyond the cut.
  std::ifstream in(kExample);
  std::stringstream text;
  text << in.rdbuf() << "capture { line: \"A\" at: 1 }\ncapture { line: \"A\" at: 3 }\n";
  const std::string scenario = temp_path("two_probes.textproto");
  std::ofstream(scenario) << text.str();
  const std::string pcap = temp_path("two_probes.pcapng");
  std::ostringstream out, err;
  ASSERT_EQ(cmd_run({scenario, "--capture", pcap, "--quiet"}, out, err), 0) << err.str();

  captures::PcapngError e;
  auto reader = captures::PcapngReader::open(pcap, e);
  ASSERT_TRUE(reader) << e.to_string();
  captures::PcapngRecord rec;
  std::int64_t last = 0;
  std::size_t out_of_order = 0;
  while (reader->next(rec)) {
    out_of_order += rec.ts_ns < last;
    last = rec.ts_ns;
  }
  EXPECT_EQ(out_of_order, 0u) << "records in start order across both interfaces";
  const auto& ifs = reader->interfaces();
  ASSERT_EQ(ifs.size(), 3u);
  EXPECT_EQ(ifs[0].name, "A@1");
  EXPECT_EQ(ifs[0].description, "PROFIBUS-DP 1.5 Mbit/s, probe at station 1");
  EXPECT_EQ(ifs[1].name, "A@3");
  EXPECT_EQ(ifs[1].description, "PROFIBUS-DP 1.5 Mbit/s, probe at station 3");
  EXPECT_EQ(ifs[2].name, "events");

  const auto loaded = load_scenario_file(scenario);
  ASSERT_TRUE(loaded.ok());
  const Bounds b = bounds(loaded.plan->lines[0]);
  const Ticks sec = bus::kTicksPerSecond;
  const std::string cut = window(2 * sec, 3 * sec);
  std::string report;
  // Next to master 3 during the cut: master 3 alone (it claims the token after TTO and passes
  // it to itself); nobody from the other side is heard; nobody passes it a token.
  std::vector<std::string> args = {
      "--interface", "A@3",
      "--allow", window(2 * sec - b.longest_frame, 2 * sec),
      "--allow", window(3 * sec - b.longest_frame, 3 * sec + b.settle),
      "--expect-clean", "--expect-live", "1,2,3,10,11,12,13,14",
      "--expect-no-token-to", "3@" + cut,
      "--expect-token-to", "3@" + window(3 * sec, 3 * sec + b.rejoin)};
  for (int a : {1, 2, 10, 11, 12, 13, 14}) {
    args.push_back("--expect-silent");
    args.push_back(std::to_string(a) + "@" + cut);
  }
  EXPECT_EQ(check(pcap, args, &report), 0) << report;
  // Next to master 1 it is the default probe's view again.
  EXPECT_EQ(check(pcap, {"--interface", "A@1", "--expect-silent", "3@" + cut, "--allow",
                         window(3 * sec - b.longest_frame, 3 * sec + b.settle), "--expect-clean"},
                  &report),
            0)
      << report;
  std::remove(pcap.c_str());
  std::remove(scenario.c_str());
}

}  // namespace
}  // namespace pbvbus::tools
