// The conformance reports (report.hpp) on a hand-made BatteryReport: text lines, JSON that a tiny
// parser reads back, JUnit XML that xmllint validates against tests/data/junit/junit.xsd.

#include <gtest/gtest.h>

#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <string>

#include "pbvbus/conformance/report.hpp"
#include "pbvbus/gsd/gsd.hpp"

namespace pbvbus::conformance {
namespace {

constexpr bus::Ticks kBit = bus::ticks_per_bit(bus::Baud::k1_5M);

BatteryReport sample() {
  BatteryReport rep;
  auto g = devices::load_gsd(std::string(PBVBUS_SOURCE_DIR) + "/examples/gsd/PBVB0A01.gsd");
  EXPECT_TRUE(g.ok());
  rep.spec.gsd = std::make_shared<const devices::GsdFile>(*g.file);
  rep.spec.gsd_path = "examples/gsd/PBVB0A01.gsd";
  rep.spec.address = 3;

  TestResult pass;
  pass.id = "STA-01";
  pass.group = "Start-up";
  pass.name = "Power-on diagnosis";
  pass.requirement = "02 05 00 FF";
  rep.results.push_back(pass);

  TestResult fail;
  fail.id = "STA-02";
  fail.group = "Start-up";
  fail.name = "Start-up <sequence> & \"more\"";
  fail.requirement = "req";
  fail.verdict = Verdict::Fail;
  fail.message = "expected SC, got <no reply> & \x01 more";
  Exchange e;
  // FDL Status 1 → 3 (10 03 01 49 4D 16) at 33 bit times, 6 octets → end 99; reply 11 bit times
  // later at 110: 10 01 03 00 04 16.
  e.request = {0x10, 0x03, 0x01, 0x49, 0x4D, 0x16};
  e.request_start = 33 * kBit;
  e.request_end = 99 * kBit;
  e.answered = true;
  e.response = {0x10, 0x01, 0x03, 0x00, 0x04, 0x16};
  e.response_start = 110 * kBit;
  e.response_end = 176 * kBit;
  e.tsdr_bits = 11;
  e.sender = 1;
  e.note = "FDL_Status";
  fail.evidence.push_back(e);
  Exchange none = e;
  none.answered = false;
  none.response.clear();
  none.tsdr_bits = -1;
  none.request_start = 209 * kBit;
  none.note = "Slave_Diag";
  fail.evidence.push_back(none);
  rep.results.push_back(fail);

  TestResult na;
  na.id = "PRM-03";
  na.group = "Set_Prm";
  na.name = "Wrong content";
  na.requirement = "range";
  na.verdict = Verdict::NotApplicable;
  na.message = "no range";
  rep.results.push_back(na);
  return rep;
}

bool contains(const std::string& hay, const std::string& needle) { return hay.find(needle) != std::string::npos; }

TEST(ConformanceReport, TextHasHeaderLinesEvidenceAndTotals) {
  const std::string t = to_text(sample());
  EXPECT_TRUE(contains(t, "examples/gsd/PBVB0A01.gsd (pbvbus CS16 16DI/16DO, ident 0x0A01) at address 3, 1.5M, slave model"));
  EXPECT_TRUE(contains(t, "\nStart-up\n  STA-01   pass  Power-on diagnosis\n")) << t;
  EXPECT_TRUE(contains(t, "  STA-02   fail  Start-up <sequence>")) << t;
  EXPECT_TRUE(contains(t, "      > 33 bt  10 03 01 49 4D 16  (FDL_Status, SA 1)\n")) << t;
  EXPECT_TRUE(contains(t, "      < 110 bt  10 01 03 00 04 16  (TSDR 11 bit times)\n")) << t;
  EXPECT_TRUE(contains(t, "      > 209 bt  10 03 01 49 4D 16  (Slave_Diag, SA 1)\n      < no reply within TSL\n")) << t;
  EXPECT_TRUE(contains(t, "\nSet_Prm\n  PRM-03   n/a   Wrong content\n      n/a: no range\n")) << t;
  EXPECT_TRUE(contains(t, "3 tests: 1 passed, 1 failed, 0 errors, 1 n/a\nFAILED\n")) << t;
}

TEST(ConformanceReport, TextOfAPtyDutNamesTheTimingMeaninglessTests) {
  BatteryReport rep = sample();
  rep.spec.pty_path = "/tmp/dut";
  rep.spec.speed = {1, 1000};
  rep.results[0].timing_not_meaningful = true;
  const std::string t = to_text(rep);
  EXPECT_TRUE(contains(t, "  pty:      /tmp/dut, speed 1/1000\n")) << t;
  EXPECT_TRUE(contains(t, "  timing not meaningful: STA-01\n")) << t;
  EXPECT_TRUE(contains(t, "wall time scaled by --speed")) << t;
}

// --- a tiny JSON reader: enough to prove the output is one well-formed JSON value ------------
struct Json {
  const std::string& s;
  std::size_t i = 0;
  void ws() {
    while (i < s.size() && (s[i] == ' ' || s[i] == '\n' || s[i] == '\r' || s[i] == '\t')) ++i;
  }
  bool lit(const char* w) {
    const std::string t(w);
    if (s.compare(i, t.size(), t) != 0) return false;
    i += t.size();
    return true;
  }
  bool str() {
    if (s[i] != '"') return false;
    for (++i; i < s.size(); ++i) {
      const auto c = static_cast<unsigned char>(s[i]);
      if (c < 0x20) return false;
      if (c == '\\') {
        ++i;
        if (i >= s.size()) return false;
        if (s[i] == 'u') {
          for (int k = 0; k < 4; ++k)
            if (++i >= s.size() || !std::isxdigit(static_cast<unsigned char>(s[i]))) return false;
        } else if (std::string("\"\\/bfnrt").find(s[i]) == std::string::npos) {
          return false;
        }
      } else if (c == '"') {
        ++i;
        return true;
      }
    }
    return false;
  }
  bool num() {
    const std::size_t b = i;
    if (s[i] == '-') ++i;
    while (i < s.size() && (std::isdigit(static_cast<unsigned char>(s[i])) || s[i] == '.' || s[i] == 'e')) ++i;
    return i > b;
  }
  bool value() {
    ws();
    if (i >= s.size()) return false;
    bool ok = false;
    if (s[i] == '{') {
      ++i;
      ws();
      if (s[i] == '}') { ++i; return true; }
      do {
        ws();
        if (!str()) return false;
        ws();
        if (s[i++] != ':') return false;
        if (!value()) return false;
        ws();
      } while (s[i] == ',' && ++i);
      ok = s[i++] == '}';
    } else if (s[i] == '[') {
      ++i;
      ws();
      if (s[i] == ']') { ++i; return true; }
      do {
        if (!value()) return false;
        ws();
      } while (s[i] == ',' && ++i);
      ok = s[i++] == ']';
    } else if (s[i] == '"') {
      ok = str();
    } else {
      ok = lit("true") || lit("false") || lit("null") || num();
    }
    return ok;
  }
  bool document() {
    if (!value()) return false;
    ws();
    return i == s.size();
  }
};

TEST(ConformanceReport, JsonIsWellFormedWithTheDocumentedFields) {
  const std::string j = to_json(sample());
  Json p{j};
  EXPECT_TRUE(p.document()) << "stopped at " << p.i << ": " << j.substr(p.i, 40);
  EXPECT_TRUE(contains(j, "\"schema\":\"pbvbus.conformance/1\""));
  EXPECT_TRUE(contains(j, "\"kind\":\"model\""));
  EXPECT_TRUE(contains(j, "\"ident\":\"0x0A01\""));
  EXPECT_TRUE(contains(j, "\"baud\":\"1.5M\""));
  EXPECT_TRUE(contains(j, "\"passed\":false"));
  EXPECT_TRUE(contains(j, "\"totals\":{\"tests\":3,\"pass\":1,\"fail\":1,\"error\":0,\"na\":1}"));
  EXPECT_TRUE(contains(j, "\"verdict\":\"n/a\""));
  // The control character of the message is escaped, the quotes too.
  EXPECT_TRUE(contains(j, "got <no reply> & \\u0001 more")) << j;
  EXPECT_TRUE(contains(j, "Start-up <sequence> & \\\"more\\\"")) << j;
  EXPECT_TRUE(contains(j, "\"request\":\"10 03 01 49 4D 16\",\"request_start_bits\":33,\"request_end_bits\":99"));
  EXPECT_TRUE(contains(j, "\"response_start_bits\":110,\"tsdr_bits\":11,\"sender\":1"));
  EXPECT_TRUE(contains(j, "\"response_start_bits\":null,\"tsdr_bits\":null"));
  // A broken document is caught by the same reader (the check can fail).
  const std::string broken = j.substr(0, j.size() - 3);
  Json q{broken};
  EXPECT_FALSE(q.document());
}

bool have_xmllint() { return std::system("command -v xmllint >/dev/null 2>&1") == 0; }

int xmllint_validate(const std::string& xml, const std::string& name) {
  const std::string path = std::string(PBVBUS_BINARY_DIR) + "/" + name;
  std::ofstream(path, std::ios::binary) << xml;
  const std::string cmd = "xmllint --noout --schema " + std::string(PBVBUS_SOURCE_DIR) +
                          "/tests/data/junit/junit.xsd " + path + " >/dev/null 2>&1";
  return std::system(cmd.c_str());
}

TEST(ConformanceReport, JunitHasOneSuitePerGroupAndValidates) {
  const std::string x = to_junit(sample());
  EXPECT_TRUE(contains(x, "<testsuites name=\"pbvbus conformance\" tests=\"3\" failures=\"1\" errors=\"0\" skipped=\"1\""));
  EXPECT_TRUE(contains(x, "<testsuite name=\"Start-up\" tests=\"2\" failures=\"1\" errors=\"0\" skipped=\"0\""));
  EXPECT_TRUE(contains(x, "<testsuite name=\"Set_Prm\" tests=\"1\" failures=\"0\" errors=\"0\" skipped=\"1\""));
  EXPECT_TRUE(contains(x, "<testcase classname=\"Start-up\" name=\"STA-01 Power-on diagnosis\""));
  EXPECT_TRUE(contains(x, "name=\"STA-02 Start-up &lt;sequence&gt; &amp; &quot;more&quot;\""));
  EXPECT_TRUE(contains(x, "<failure message=\"expected SC, got &lt;no reply&gt; &amp;  more\""));  // \x01 dropped
  EXPECT_TRUE(contains(x, "> 33 bt  10 03 01 49 4D 16") == false);  // '>' escaped in text
  EXPECT_TRUE(contains(x, "&gt; 33 bt  10 03 01 49 4D 16  (FDL_Status, SA 1)"));
  EXPECT_TRUE(contains(x, "<skipped message=\"no range\"/>"));
  if (!have_xmllint()) GTEST_SKIP() << "xmllint not installed: schema validation skipped";
  EXPECT_EQ(xmllint_validate(x, "conformance_report_test.xml"), 0);
  // The schema rejects a testcase without classname (the validation can fail).
  std::string bad = x;
  bad.replace(bad.find(" classname=\"Start-up\""), 21, "");
  EXPECT_NE(xmllint_validate(bad, "conformance_report_test_bad.xml"), 0);
}

TEST(ConformanceReport, JunitOfADutErrorIsAnError) {
  BatteryReport rep;
  rep.spec.gsd_path = "broken.gsd";
  rep.dut_error = "cannot <parse>";
  const std::string x = to_junit(rep);
  EXPECT_TRUE(contains(x, "errors=\"1\""));
  EXPECT_TRUE(contains(x, "<error message=\"cannot &lt;parse&gt;\""));
  if (!have_xmllint()) GTEST_SKIP() << "xmllint not installed";
  EXPECT_EQ(xmllint_validate(x, "conformance_report_error.xml"), 0);
}

}  // namespace
}  // namespace pbvbus::conformance
