// The DP line "rio" of examples/quantum-hsby.textproto across the Quantum pair's takeovers, read
// from `pbvbus run --fast --capture` the way an analyzer reads it (docs/quantum-hsby-dp.md):
// by tests/integration/check_capture.py (standalone, its own pcapng reader and FDL decoder) and
// by Debian's tshark with the shipped Lua dissector; plus the run's own JSON report.
//
// The example (its header): both racks' DP master modules at address 1 on "rio" (1.5 Mbit/s,
// DP defaults: TSL 300, max TSDR 150, TID1 37 bit times), slaves 3, 4, 6, scan 60 ms (the
// scan-time model), slave watchdog 300 ms. Takeovers of the line: 2 s rack 0 loses power (an
// unplanned takeover by rack 1's module), 5 s the primary's key to Off Line and 9 s the
// override with both run bits 0 (planned handovers at the primary's next scan boundary).
//
// Bounds worked out by hand:
//   - A module that loses power stops sending at once; a frame it was sending is cut (the
//     capture flags it). It started at most one longest telegram before the power loss:
//     255 octets x 11 bits = 2805 bit times = 1.87 ms at 1.5 Mbit/s. So the one window where a
//     damaged frame or a timing violation is tolerated is [2 s - 2805 bit times, 2 s]
//     = [2997195/1500000 s, 2 s]. The handovers at 5 s and 9 s cut no power: no window.
//   - The new active module claims the token (DC 01 01, "1>1") after at least
//     TTO(1) = 6 x TSL + 2 x 1 x TSL = 2400 bit times of silence (IEC 61158-4-3; F9/F11, D3 of
//     docs/quantum-hsby-dp.md). The takeover after the power loss comes within one scan (60 ms):
//     the claim lies in [2 s, 2.06 s]. A planned handover's claim follows the switchover (the
//     report's at_ns) after at most the old module's last message cycle (2 x 2805 + 150 + 37 =
//     5797 bit times) and TTO: within at_ns + 8197 bit times (5.465 ms).
//   - The slaves are resumed, not restarted (D6): no Set_Prm (DSAP 61) and no Chk_Cfg (DSAP 62)
//     after the start-up (one each per slave, the first DP cycle), every slave entered
//     Data_Exch once and no watchdog expired (300 ms >> 60 ms + TTO).
#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "../captures/tshark_helpers.hpp"

namespace {

namespace qcap_ts = pbvbus::test;

constexpr const char* kQcapPython = "/usr/bin/python3";
const std::string kQcapBinary = PBVBUS_BINARY_DIR "/bin/pbvbus";
const std::string kQcapChecker = PBVBUS_SOURCE_DIR "/tests/integration/check_capture.py";
const std::string kQcapExample = PBVBUS_SOURCE_DIR "/examples/quantum-hsby.textproto";

/// The example run once per process (ctest runs each test in its own process, in parallel):
/// a temp directory with q.pcapng and report.json.
struct QcapRun {
  std::string dir;
  int rc = -1;
  std::string err;
};

std::string g_qcap_dir;  // this process's run, removed at the end if every test passed

class QcapCleanup : public ::testing::Environment {
 public:
  void TearDown() override {
    if (!g_qcap_dir.empty() && ::testing::UnitTest::GetInstance()->Passed())
      qcap_ts::run_command("rm -rf " + qcap_ts::shell_quote(g_qcap_dir));
  }
};
[[maybe_unused]] ::testing::Environment* const g_qcap_cleanup =
    ::testing::AddGlobalTestEnvironment(new QcapCleanup);

const QcapRun& qcap() {
  static const QcapRun r = [] {
    QcapRun out;
    char tmpl[] = "/tmp/pbvbus-qcap-XXXXXX";
    out.dir = ::mkdtemp(tmpl);
    g_qcap_dir = out.dir;
    const auto res = qcap_ts::run_command(
        "cd " + qcap_ts::shell_quote(out.dir) + " && " + qcap_ts::shell_quote(kQcapBinary) + " run " +
        qcap_ts::shell_quote(kQcapExample) + " --fast --quiet --capture q.pcapng --json > report.json");
    out.rc = res.exit_code;
    out.err = res.err;
    return out;
  }();
  return r;
}

bool qcap_have_python() { return ::access(kQcapPython, X_OK) == 0; }

/// A Python expression over the JSON document in `file` (bound to `r`), printed.
std::string qcap_json(const std::string& file, const std::string& expr) {
  return qcap_ts::run_command(std::string(kQcapPython) + " -c " +
                              qcap_ts::shell_quote("import json,sys; r=json.load(open(sys.argv[1])); print(" +
                                                   expr + ")") +
                              " " + qcap_ts::shell_quote(file))
      .out;
}

// ---- the independent checker -------------------------------------------------------------------

TEST(QuantumCapture, CheckerFindsNoViolationAndSeesTheClaims) {
  if (!qcap_have_python()) GTEST_SKIP() << "no /usr/bin/python3";
  const QcapRun& r = qcap();
  ASSERT_EQ(r.rc, 0) << r.err;
  const std::string pcap = r.dir + "/q.pcapng";
  const std::string json = r.dir + "/check.json";
  const auto res = qcap_ts::run_command(std::string(kQcapPython) + " " + qcap_ts::shell_quote(kQcapChecker) +
                                        " " + qcap_ts::shell_quote(pcap) +
                                        " --interface rio --expect-clean --expect-live 1,3,4,6"
                                        " --allow 2997195/1500000:2 --json > " +
                                        qcap_ts::shell_quote(json));
  EXPECT_EQ(res.exit_code, 0) << qcap_json(json, "r[\"failures\"], r[\"flagged\"], r[\"timing\"]") << res.err;
  // The one damaged frame: the power loss at 2 s cut it, inside the window.
  EXPECT_EQ(qcap_json(json, "len(r[\"flagged\"]), all(x[\"allowed\"] for x in r[\"flagged\"])"), "1 True\n");
  EXPECT_EQ(qcap_json(json, "len(r[\"timing\"]), len(r[\"overlaps\"]), len(r[\"token_conflicts\"])"), "0 0 0\n");
  // Three claims, one per takeover of the line, each 1>1 after at least TTO(1) = 2400 bit times.
  EXPECT_EQ(qcap_json(json, "[c[\"token\"] for c in r[\"claims\"]]"), "['1>1', '1>1', '1>1']\n");
  EXPECT_EQ(qcap_json(json, "all(c[\"idle_bits\"] >= 2400 for c in r[\"claims\"])"), "True\n")
      << qcap_json(json, "r[\"claims\"]");
  // The power loss: the claim within one scan (60 ms) of it.
  EXPECT_EQ(qcap_json(json, "2 <= float(r[\"claims\"][0][\"t\"]) <= 2.06"), "True\n") << qcap_json(json, "r[\"claims\"]");
  // The planned handovers: after the cause, by the switchover + 8197 bit times (5.465 ms).
  const std::string report = r.dir + "/report.json";
  const std::string at =
      qcap_json(report, "[(s[\"cause_ns\"], s[\"at_ns\"]) for s in r[\"quantum\"][0][\"switchovers\"]][:3]");
  const std::string cmd = "[c for c, (cause, at) in zip(r[\"claims\"], " + at.substr(0, at.size() - 1) +
                          ") if not (cause <= float(c[\"t\"]) * 1e9 <= at + 5465000)]";
  EXPECT_EQ(qcap_json(json, cmd), "[]\n") << at << qcap_json(json, "r[\"claims\"]");
}

// ---- tshark with the pbvbus dissector ----------------------------------------------------------

TEST(QuantumCapture, TsharkShowsTheClaimAndTheSlavesResumedAtThePowerLoss) {
  if (!qcap_ts::tshark_available()) GTEST_SKIP() << qcap_ts::kNoTshark;
  const QcapRun& r = qcap();
  ASSERT_EQ(r.rc, 0) << r.err;
  // One pass (the file holds 23 s of a busy line): the power loss's surroundings, and every
  // Set_Prm and Chk_Cfg of the run.
  const auto rows = qcap_ts::tshark_fields(
      r.dir + "/q.pcapng",
      {"frame.time_relative", "pbfdl.type", "pbfdl.sa", "pbfdl.da", "pbfdl.dsap", "pbfdl.service", "pbfdl.fcs_ok"},
      "frame.interface_name == \"rio\" && ((frame.time_relative >= 1.99 && frame.time_relative < 2.1) || "
      "pbfdl.dsap == 61 || pbfdl.dsap == 62)");
  ASSERT_FALSE(rows.empty());
  for (const auto& row : rows) ASSERT_EQ(row.size(), 7u);
  // Start-up parameterisation only: one Set_Prm (DSAP 61) and one Chk_Cfg (62) per slave, all
  // in the first 100 ms (the first DP cycle after power-on).
  std::vector<std::string> prm, cfg;
  for (const auto& row : rows) {
    // (DSAP 62 is also the master's SAP in Slave_Diag responses: requests from SA 1 only.)
    if ((row[4] != "61" && row[4] != "62") || row[2] != "1") continue;
    EXPECT_LT(std::atof(row[0].c_str()), 0.1) << "a slave parameterised again at " << row[0] << ": " << row[5];
    (row[4] == "61" ? prm : cfg).push_back(row[3]);
  }
  EXPECT_EQ(prm, (std::vector<std::string>{"3", "4", "6"}));
  EXPECT_EQ(cfg, (std::vector<std::string>{"3", "4", "6"}));
  // Around the power loss at 2 s: SA 1 sends until it, then nothing at all is heard (a cut
  // frame that started before 2 s aside) until the token claim 1>1, within one scan (60 ms).
  double claim = -1;
  for (const auto& row : rows) {
    const double t = std::atof(row[0].c_str());
    if (t < 2.0) continue;
    if (row[1] == "SD4" && row[2] == "1" && row[3] == "1") {
      claim = t;
      break;
    }
    ADD_FAILURE() << "a frame before the claim, after the power loss: " << row[0] << " " << row[1] << " SA "
                  << row[2] << " DA " << row[3];
  }
  ASSERT_GE(claim, 2.0) << "no token claim SA=1 DA=1 after the power loss";
  EXPECT_LE(claim, 2.06);
  bool sa1_before = false;
  for (const auto& row : rows) {
    const double t = std::atof(row[0].c_str());
    if (t < 2.0 && row[2] == "1" && row[6] == "1") sa1_before = true;
  }
  EXPECT_TRUE(sa1_before) << "no intact frame from SA 1 just before the power loss";
  // After the claim: Data_Exchange requests from 1 to 3, 4 and 6, each answered.
  std::vector<std::string> dx_to, dx_from;
  for (const auto& row : rows) {
    const double t = std::atof(row[0].c_str());
    if (t <= claim || t > claim + 0.06) continue;
    if (row[5].rfind("Data_Exchange.req", 0) == 0 && row[2] == "1") dx_to.push_back(row[3]);
    if (row[5].rfind("Data_Exchange.res", 0) == 0 && row[3] == "1") dx_from.push_back(row[2]);
  }
  ASSERT_GE(dx_to.size(), 3u);
  EXPECT_EQ(std::vector<std::string>(dx_to.begin(), dx_to.begin() + 3), (std::vector<std::string>{"3", "4", "6"}));
  ASSERT_GE(dx_from.size(), 3u);
  EXPECT_EQ(std::vector<std::string>(dx_from.begin(), dx_from.begin() + 3), (std::vector<std::string>{"3", "4", "6"}));
}

// ---- the run report ----------------------------------------------------------------------------

TEST(QuantumCapture, ReportShowsEverySlaveStayedInDataExchange) {
  if (!qcap_have_python()) GTEST_SKIP() << "no /usr/bin/python3";
  const QcapRun& r = qcap();
  ASSERT_EQ(r.rc, 0) << r.err;
  const std::string report = r.dir + "/report.json";
  EXPECT_EQ(qcap_json(report, "[(s[\"address\"], s[\"state\"], s[\"watchdog_expiries\"], s[\"data_exch_entries\"]) "
                              "for s in r[\"dp_slaves\"]]"),
            "[(3, 'Data_Exch', 0, 1), (4, 'Data_Exch', 0, 1), (6, 'Data_Exch', 0, 1)]\n");
  // Three takeovers of the line (2 s, 5 s, 9 s), three slaves resumed each time, none restarted.
  EXPECT_EQ(qcap_json(report, "r[\"quantum\"][0][\"dp\"][\"takeovers\"], r[\"quantum\"][0][\"dp\"][\"resumed\"], "
                              "r[\"quantum\"][0][\"dp\"][\"restarted\"]"),
            "3 9 0\n");
}

}  // namespace
