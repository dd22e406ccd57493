// `pbvbus timing`: called through the tools library (no process). The figures for
// examples/switched-io.textproto are worked out by hand below from the bus parameters the loader
// derives (read from the plan), and checked in the --json output (parsed by python3) and the
// text; usage errors, a broken scenario, a missing file and a scenario without a DP master
// system.

#include <gtest/gtest.h>

#include <cstdio>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "pbvbus/bus/time.hpp"
#include "pbvbus/tools/commands.hpp"
#include "pbvbus/scenario/scenario.hpp"

namespace pbvbus::tools {
namespace {

struct Result {
  int rc;
  std::string out;
  std::string err;
};

Result run(const Args& args) {
  std::ostringstream out, err;
  const int rc = cmd_timing(args, out, err);
  return {rc, out.str(), err.str()};
}

std::string src(const std::string& rel) {
  return std::string(PBVBUS_SOURCE_DIR) + "/" + rel;
}

std::string write_temp(const std::string& name, const std::string& text) {
  const std::string path = std::string(PBVBUS_BINARY_DIR) + "/cmd_timing_test_" + name;
  std::ofstream(path) << text;
  return path;
}

// Runs a python3 expression on the parsed JSON document `d` and returns what it prints (without
// the final newline); the process fails (and the test with it) if the text is not valid JSON.
std::string python_on_json(const std::string& json, const std::string& expression) {
  static int calls = 0;
  const std::string path = std::string(PBVBUS_BINARY_DIR) + "/cmd_timing_test_" +
                           ::testing::UnitTest::GetInstance()->current_test_info()->name() + "_" +
                           std::to_string(++calls) + ".json";
  std::ofstream(path, std::ios::binary) << json;
  const std::string cmd = "python3 -c \"import json,sys; d=json.load(open(sys.argv[1])); print(" +
                          expression + ")\" " + path;
  std::string result;
  FILE* p = popen(cmd.c_str(), "r");
  if (p == nullptr) return "popen failed";
  char buf[4096];
  for (std::size_t n; (n = std::fread(buf, 1, sizeof buf, p)) > 0;) result.append(buf, n);
  const int status = pclose(p);
  std::remove(path.c_str());
  if (status != 0) return "python3 failed: " + result;
  if (!result.empty() && result.back() == '\n') result.pop_back();
  return result;
}

// Expectations on one JSON document, checked with a single python3 run (each expression
// prints as print() would print it: the values of a tuple separated by spaces).
class JsonChecks {
 public:
  void expect(const std::string& expression, const std::string& expected) {
    m_expr.push_back(expression);
    m_expected.push_back(expected);
  }
  void run(const std::string& json) const {
    std::string all =
        "'\\n'.join(' '.join(str(v) for v in (e if type(e) is tuple else (e,))) for e in [";
    for (std::size_t i = 0; i < m_expr.size(); ++i) all += (i ? ", (" : "(") + m_expr[i] + ")";
    all += "])";
    const std::string got = python_on_json(json, all);
    std::istringstream in(got);
    std::string line;
    for (std::size_t i = 0; i < m_expected.size(); ++i) {
      if (!std::getline(in, line)) line = "<missing: " + got + ">";
      EXPECT_EQ(line, m_expected[i]) << m_expr[i];
    }
  }

 private:
  std::vector<std::string> m_expr, m_expected;
};

std::string ns_of_bits(std::int64_t bits) {
  return std::to_string(bus::ticks_to_ns(bus::bits_to_ticks(bits, bus::Baud::k1_5M)));
}

const std::string kExample = "examples/switched-io.textproto";

TEST(CmdTiming, Help) {
  const Result r = run({"--help"});
  EXPECT_EQ(r.rc, 0);
  EXPECT_NE(r.out.find("usage: pbvbus timing SCENARIO [--json]"), std::string::npos);
  EXPECT_TRUE(r.err.empty());
}

TEST(CmdTiming, UsageErrors) {
  Result r = run({});
  EXPECT_EQ(r.rc, 2);
  EXPECT_NE(r.err.find("usage: pbvbus timing"), std::string::npos);
  r = run({src(kExample), "--check"});
  EXPECT_EQ(r.rc, 2);
  EXPECT_NE(r.err.find("unknown option '--check'"), std::string::npos);
  r = run({src(kExample), src(kExample)});
  EXPECT_EQ(r.rc, 2);
  EXPECT_NE(r.err.find("only one SCENARIO"), std::string::npos);
  EXPECT_TRUE(r.out.empty());
}

TEST(CmdTiming, MissingFile) {
  const Result r = run({src("examples/no-such-scenario.textproto")});
  EXPECT_EQ(r.rc, 2);
  EXPECT_NE(r.err.find("no-such-scenario.textproto"), std::string::npos);
  EXPECT_TRUE(r.out.empty());
}

TEST(CmdTiming, BrokenScenarioGivesFileLineColumn) {
  const std::string path = write_temp("broken.textproto",
                                      "name: \"broken\"\n"
                                      "line { name: \"A\" }\n"
                                      "master { address: 300 line: \"A\" }\n");
  const Result r = run({path, "--json"});
  EXPECT_EQ(r.rc, 2);
  EXPECT_NE(r.err.find(path + ":3:"), std::string::npos) << r.err;
  EXPECT_TRUE(r.out.empty());
  std::remove(path.c_str());
}

TEST(CmdTiming, NoDpMasterSystem) {
  const std::string path = write_temp("plain.textproto",
                                      "name: \"plain\"\n"
                                      "line { name: \"A\" }\n"
                                      "master { address: 1 line: \"A\" }\n"
                                      "master { address: 2 line: \"A\" }\n");
  Result r = run({path});
  EXPECT_EQ(r.rc, 0) << r.err;
  EXPECT_NE(r.out.find("no DP master system in this scenario"), std::string::npos) << r.out;
  r = run({path, "--json"});
  EXPECT_EQ(r.rc, 0) << r.err;
  EXPECT_EQ(python_on_json(r.out, "d['schema'], len(d['redundant_systems']), len(d['dp_masters'])"),
            "pbvbus.timing/1 0 0");
  std::remove(path.c_str());
}

// The worked example: bus parameters as the loader derives them, then the planner's terms by
// hand. b = 11 bit times per octet.
class SwitchedIo : public ::testing::Test {
 protected:
  void SetUp() override {
    const LoadResult l = load_scenario_file(src(kExample));
    ASSERT_TRUE(l.ok());
    const ScenarioPlan& plan = *l.plan;
    ASSERT_EQ(plan.redundant_systems.size(), 1u);
    const RedundancyPlan& rp = plan.redundant_systems[0];
    const fdl::BusParams& p = plan.lines.at(static_cast<std::size_t>(rp.line[0])).params;
    // 1.5 Mbit/s: one bit = 3 636 000 000 / 1 500 000 = 2424 ticks.
    ASSERT_EQ(p.baud, bus::Baud::k1_5M);
    ASSERT_EQ(bus::ticks_per_bit(p.baud), 2424);
    // Loader: max TSDR = max(150 default, GSD MaxTsdr_1.5M: 150 for PBVB0A10/PBVB0A01, 300 for
    // PBVB0A11) = 300; TSL = max(300, 300 + 15) = 315; TID1 = max(TSYN 33 + TSM (2 + 2·1 + 0),
    // min TSDR 11) = 37; TID2 = max(37, max TSDR 300) = 300; one retry.
    ASSERT_EQ(p.max_tsdr, 300u);
    ASSERT_EQ(p.tsl, 315u);
    ASSERT_EQ(p.tid1(), 37u);
    ASSERT_EQ(p.tid2(), 300u);
    ASSERT_EQ(p.max_retry, 1);
    // T_SLAVE_UM from the GSDs: PBVB0A10 Slave_Max_Switch_Over_Time 3 (x 10 ms), PBVB0A11 82.
    ASSERT_EQ(plan.switched.size(), 4u);
    for (const SwitchedPlan& s : plan.switched) {
      ASSERT_TRUE(s.t_slave_um.has_value());
      EXPECT_TRUE(s.t_slave_um_from_gsd);
      EXPECT_EQ(*s.t_slave_um, (s.address == 6 ? 820 : 30) * bus::kTicksPerMs);
    }
    tsl = p.tsl;
    tsdr_max = p.max_tsdr;
    tid1 = p.tid1();
    tid2 = p.tid2();

    // Line DP_A: switched 3, 4, 5 (PBVB0A10, MaxTsdr 150, Max_Diag_Data_Len 64) and 6 (PBVB0A11,
    // MaxTsdr 300, 64), each "16DI" + "16DO" = 2 in / 2 out; one-sided 10 (PBVB0A01, MaxTsdr
    // 150, Max_Diag_Data_Len 8), 2 in / 2 out. DP_B: the same with 11 for 10.
    // Data_Exchange: request 2 outputs → SD2 9 + 2 = 11 octets = 121; reply the same.
    dx_fast = 121 + 150 + 121 + tid1;       // 429
    dx_slow = 121 + tsdr_max + 121 + tid1;  // 579 (station 6, TSDR 300)
    dx_sum = 4 * dx_fast + dx_slow;         // 3, 4, 5, 10 and 6: 2295
    gc = 11 * 13 + tid2;                    // SDN, DU 2 + SAPs → SD2 13 octets: 143 + 300 = 443
    token = 11 * 3 + tid1;                  // 70
    // GAP: unanswered 66 + TSL 315 = 381; answered 66 + 300 + 66 + 37 = 469: the larger.
    gap = std::max<std::int64_t>(66 + tsl, 66 + tsdr_max + 66 + tid1);
    // Diag: request SAPs only (SD2 11 octets = 121); reply 2 + 64 → SD2 75 octets = 825 at TSDR
    // 300 (station 6): 121 + 300 + 825 + 37 = 1283 (slave 10: 121 + 150 + 209 + 37 = 517).
    diag = 121 + tsdr_max + 11 * (9 + 2 + 64) + tid1;
    retry = 121 + tsl;                                // 436
    t_tr = dx_sum + gc + token + gap + diag + retry;  // 4996
    recognition = t_tr + (1 + 1) * (121 + tsl);       // 5868
    // Pure PrmCmd Set_Prm: SD2 29 octets (319), the slave's TSDR, SC (11), TID1.
    prm_fast = 319 + 150 + 11 + tid1;                        // 517
    prm_slow = 319 + tsdr_max + 11 + tid1;                   // 667
    t_dp_um_3 = t_tr + prm_fast + t_tr;                      // 10509
    t_dp_um_6 = t_tr + prm_slow + t_tr;                      // 10659
    t_dp_um_system = t_tr + 3 * prm_fast + prm_slow + t_tr;  // 12210
  }

  std::int64_t tsl = 0, tsdr_max = 0, tid1 = 0, tid2 = 0;
  std::int64_t dx_fast = 0, dx_slow = 0, dx_sum = 0, gc = 0, token = 0, gap = 0, diag = 0,
               retry = 0;
  std::int64_t t_tr = 0, recognition = 0, prm_fast = 0, prm_slow = 0;
  std::int64_t t_dp_um_3 = 0, t_dp_um_6 = 0, t_dp_um_system = 0;
};

TEST_F(SwitchedIo, HandArithmetic) {
  // The literal figures, so that a change of the loader's derivation shows here too.
  EXPECT_EQ(dx_sum, 2295);
  EXPECT_EQ(gap, 469);
  EXPECT_EQ(diag, 1283);
  EXPECT_EQ(t_tr, 4996);
  EXPECT_EQ(recognition, 5868);
  EXPECT_EQ(t_dp_um_3, 10509);
  EXPECT_EQ(t_dp_um_6, 10659);
  EXPECT_EQ(t_dp_um_system, 12210);
}

TEST_F(SwitchedIo, JsonFigures) {
  const Result r = run({src(kExample), "--json"});
  ASSERT_EQ(r.rc, 0) << r.err;
  EXPECT_TRUE(r.err.empty()) << r.err;
  JsonChecks json;
  json.expect(
      "d['schema'], d['scenario']['name'], len(d['redundant_systems']), len(d['dp_masters'])",
      "pbvbus.timing/1 switched-io 1 0");
  const std::string sys = "d['redundant_systems'][0]";
  json.expect(sys + "['name'], " + sys + "['bus_params']['tsl'], " + sys +
                  "['bus_params']['max_tsdr'], " + sys + "['bus_params']['tid1'], " + sys +
                  "['bus_params']['tid2']",
              "H-DP 1 315 300 37 300");
  for (int side = 0; side < 2; ++side) {
    const std::string line = sys + "['lines'][" + std::to_string(side) + "]";
    json.expect(line + "['name'], " + line + "['side'], " + line + "['master'], " +
                    "[s['address'] for s in " + line + "['slaves']]",
                side == 0 ? "DP_A A 1 [10, 3, 4, 5, 6]" : "DP_B B 1 [3, 4, 5, 6, 11]");
    json.expect(
        "' '.join(str(x) for x in [" + line + "['dx_bits'], " + line +
            "['global_control']['bits'], " + line + "['token']['bits'], " + line +
            "['gap']['bits'], " + line + "['diag']['bits'], " + line + "['retry']['bits'], " +
            line + "['t_tr_bits'], " + line + "['recognition_bits']])",
        std::to_string(dx_sum) + " " + std::to_string(gc) + " " + std::to_string(token) + " " +
            std::to_string(gap) + " " + std::to_string(diag) + " " + std::to_string(retry) + " " +
            std::to_string(t_tr) + " " + std::to_string(recognition));
    json.expect(line + "['t_tr_ns'], " + line + "['recognition_ns']",
                ns_of_bits(t_tr) + " " + ns_of_bits(recognition));
    // The parts of the answered GAP poll: FDL Status 66, TSDR 300, reply 66, TID1 37.
    json.expect("' '.join(str(" + line +
                    "['gap'][k]) for k in ['request_bits', "
                    "'tsdr_bits', 'response_bits', 'idle_bits'])",
                "66 300 66 37");
  }
  // Station 3: T_SLAVE_UM 30 ms from the GSD; either line failing gives the same bound:
  // recognition 5868 + T_DP_UM 10509 = 16377 bits = 39 697 848 ticks, + 30 ms (109 080 000
  // ticks) = 148 777 848 ticks = 40 918 000 ns.
  const bus::Ticks bound3 =
      bus::bits_to_ticks(recognition + t_dp_um_3, bus::Baud::k1_5M) + 30 * bus::kTicksPerMs;
  EXPECT_EQ(bound3, 148'777'848);
  const std::string st3 = sys + "['stations'][0]";
  json.expect(st3 + "['address'], " + st3 + "['t_slave_um_ns'], " + st3 + "['t_slave_um_source']",
              "3 30000000 gsd");
  json.expect(
      "' '.join(str(f['bound_ns']) + '/' + str(f['t_dp_um_bits']) + '/' + f['line'] + "
      "'>' + f['to'] for f in " +
          st3 + "['failing'])",
      std::to_string(bus::ticks_to_ns(bound3)) + "/10509/DP_A>DP_B " +
          std::to_string(bus::ticks_to_ns(bound3)) + "/10509/DP_B>DP_A");
  json.expect(st3 + "['worst_ns']", std::to_string(bus::ticks_to_ns(bound3)));
  json.expect(st3 + "['prm_cmd']['bits']", std::to_string(prm_fast));
  // Station 6: recognition 5868 + T_DP_UM 10659 = 16527 bits = 40 061 448 ticks, + 820 ms
  // (2 981 520 000 ticks) = 3 021 581 448 ticks.
  const bus::Ticks bound6 =
      bus::bits_to_ticks(recognition + t_dp_um_6, bus::Baud::k1_5M) + 820 * bus::kTicksPerMs;
  EXPECT_EQ(bound6, 3'021'581'448);
  const std::string st6 = sys + "['stations'][3]";
  json.expect(st6 + "['address'], " + st6 + "['t_slave_um_ns'], " + st6 +
                  "['t_slave_um_source'], " + st6 + "['worst_ns']",
              "6 820000000 gsd " + std::to_string(bus::ticks_to_ns(bound6)));
  // System: a whole line lost. Short circuit: T_TR 4996 + T_DP_UM_system 12210 = 17206 bits =
  // 41 707 344 ticks, + the slowest station's 820 ms = 3 023 227 344 ticks. Master stop:
  // 12210 bits = 29 597 040 ticks + 820 ms = 3 011 117 040 ticks.
  const bus::Ticks sys_short =
      bus::bits_to_ticks(t_tr + t_dp_um_system, bus::Baud::k1_5M) + 820 * bus::kTicksPerMs;
  const bus::Ticks sys_stop =
      bus::bits_to_ticks(t_dp_um_system, bus::Baud::k1_5M) + 820 * bus::kTicksPerMs;
  EXPECT_EQ(sys_short, 3'023'227'344);
  EXPECT_EQ(sys_stop, 3'011'117'040);
  for (int lost = 0; lost < 2; ++lost) {
    const std::string s = sys + "['system'][" + std::to_string(lost) + "]";
    json.expect("' '.join(str(" + s +
                    "[k]) for k in ['lost', 'to', 'recognition_ns', "
                    "'t_dp_um_system_bits', 'max_t_slave_um_ns', 'slowest_station', "
                    "'bound_short_circuit_ns', 'bound_master_stop_ns'])",
                std::string(lost == 0 ? "DP_A DP_B " : "DP_B DP_A ") + ns_of_bits(t_tr) +
                    " 12210 820000000 6 " + std::to_string(bus::ticks_to_ns(sys_short)) + " " +
                    std::to_string(bus::ticks_to_ns(sys_stop)));
  }
  json.expect("type(" + sys + "['notes']).__name__", "list");
  json.run(r.out);
}

TEST_F(SwitchedIo, Text) {
  const Result r = run({src(kExample)});
  ASSERT_EQ(r.rc, 0) << r.err;
  EXPECT_TRUE(r.err.empty()) << r.err;
  auto has = [&](const std::string& s) { return r.out.find(s) != std::string::npos; };
  EXPECT_TRUE(
      has("Redundant DP master system \"H-DP 1\": line A DP_A (DP master 1), line B DP_B (DP "
          "master 1)"))
      << r.out;
  EXPECT_TRUE(has(
      "bus parameters (line DP_A, 1.5M): TSL 315, min TSDR 11, max TSDR 300, TID1 37, TID2 300"));
  // T_TR 4996 bits = 12 110 304 ticks = 3330.666 us; recognition 5868 bits = 3912.000 us.
  EXPECT_TRUE(has("T_TR")) << r.out;
  EXPECT_TRUE(has("4996  3330.666")) << r.out;
  EXPECT_TRUE(has("5868  3912.000")) << r.out;
  // Station 3: bound 40.918 ms (T_SLAVE_UM 30 ms from the GSD); station 6: 831.018 ms;
  // system: 831.470 ms (short circuit), 828.140 ms (master stop).
  EXPECT_TRUE(has("30.000 ms  gsd")) << r.out;
  EXPECT_TRUE(has("820.000 ms  gsd")) << r.out;
  EXPECT_TRUE(has("40.918 ms")) << r.out;
  EXPECT_TRUE(has("831.018 ms")) << r.out;
  EXPECT_TRUE(has("slowest station: 6, T_SLAVE_UM 820.000 ms")) << r.out;
  EXPECT_TRUE(has("831.470 ms")) << r.out;
  EXPECT_TRUE(has("828.140 ms")) << r.out;
}

TEST(CmdTiming, PlainDpMaster) {
  // One dp_master outside any redundant system, one PBVB0A01 slave (2 in / 2 out, MaxTsdr 150).
  const std::string path = write_temp("plain-dp.textproto",
                                      "name: \"plain-dp\"\n"
                                      "line { name: \"DP\" }\n"
                                      "dp_master { address: 1 line: \"DP\" }\n"
                                      "dp_slave { address: 10 line: \"DP\" gsd: \"" +
                                          src("examples/gsd/PBVB0A01.gsd") + "\" master: 1 }\n");
  const Result r = run({path, "--json"});
  ASSERT_EQ(r.rc, 0) << r.err;
  // Defaults at 1.5M with max TSDR 150: TSL 300, TID1 37, TID2 150.
  // DX 121 + 150 + 121 + 37 = 429; GC 143 + 150 = 293; token 70; GAP max(66 + 300, 66 + 150 +
  // 66 + 37 = 319) = 366; diag 121 + 150 + 11·(9 + 2 + 8) + 37 = 517; retry 121 + 300 = 421.
  // T_TR = 429 + 293 + 70 + 366 + 517 + 421 = 2096; recognition 2096 + 2·421 = 2938.
  EXPECT_EQ(
      python_on_json(r.out,
                     "len(d['redundant_systems']), d['dp_masters'][0]['address'], "
                     "d['dp_masters'][0]['line']['name'], d['dp_masters'][0]['line']['t_tr_bits'], "
                     "d['dp_masters'][0]['line']['recognition_bits']"),
      "0 1 DP 2096 2938");
  // The planner's remarks about the (empty) line B are not shown.
  EXPECT_EQ(
      python_on_json(
          r.out, "[n for n in d['dp_masters'][0]['notes'] if 'line B' in n or 'switched' in n]"),
      "[]");
  const Result t = run({path});
  ASSERT_EQ(t.rc, 0);
  EXPECT_NE(t.out.find("DP master 1 on line DP (not redundant)"), std::string::npos) << t.out;
  EXPECT_EQ(t.out.find("switched stations"), std::string::npos) << t.out;
  std::remove(path.c_str());
}

}  // namespace
}  // namespace pbvbus::tools
