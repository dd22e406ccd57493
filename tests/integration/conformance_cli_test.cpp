// `pbvbus conformance` through the built binary: every shipped GSD's slave model passes with a
// JUnit file that validates (xmllint + a python3 xml.etree structure check); a mutant exits 1 and
// names its failing test; bad input exits 2 with a clear message; --mutation-score prints the
// table.
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <string>
#include <utility>

namespace {

const std::string kBinary = PBVBUS_BINARY_DIR "/bin/pbvbus";
const std::string kGsd = PBVBUS_SOURCE_DIR "/examples/gsd/";

std::pair<int, std::string> run(const std::string& args) {
  std::string out;
  FILE* p = ::popen((kBinary + " " + args + " 2>&1").c_str(), "r");
  if (p == nullptr) return {-1, ""};
  char buf[4096];
  std::size_t n;
  while ((n = std::fread(buf, 1, sizeof buf, p)) > 0) out.append(buf, n);
  const int st = ::pclose(p);
  return {WIFEXITED(st) ? WEXITSTATUS(st) : -1, out};
}

bool have(const char* tool) { return std::system((std::string("command -v ") + tool + " >/dev/null 2>&1").c_str()) == 0; }

/// Structure check of a JUnit file with python3's xml.etree: testsuites → testsuite (name,
/// tests = number of testcases, failures/skipped = their counts) → testcase (classname = the
/// suite's name, name "ID NAME"). Prints "ok N" with the number of testcases.
const char* kJunitCheck = R"PY(
import sys, xml.etree.ElementTree as ET
root = ET.parse(sys.argv[1]).getroot()
assert root.tag == 'testsuites', root.tag
total = 0
for s in root.findall('testsuite'):
    cases = s.findall('testcase')
    assert int(s.get('tests')) == len(cases), s.get('name')
    assert int(s.get('failures')) == sum(1 for c in cases if c.find('failure') is not None)
    assert int(s.get('skipped')) == sum(1 for c in cases if c.find('skipped') is not None)
    for c in cases:
        assert c.get('classname') == s.get('name')
        assert ' ' in c.get('name') and '-' in c.get('name').split(' ')[0]
    total += len(cases)
assert int(root.get('tests')) == total
print('ok', total)
)PY";

std::string check_junit(const std::string& path) {
  if (!have("/usr/bin/python3")) return "skip";
  const std::string script = std::string(PBVBUS_BINARY_DIR) + "/conformance_junit_check.py";
  std::ofstream(script) << kJunitCheck;
  std::string out;
  FILE* p = ::popen(("/usr/bin/python3 " + script + " " + path + " 2>&1").c_str(), "r");
  if (p == nullptr) return "popen failed";
  char buf[512];
  std::size_t n;
  while ((n = std::fread(buf, 1, sizeof buf, p)) > 0) out.append(buf, n);
  ::pclose(p);
  return out;
}

void expect_valid_junit(const std::string& path) {
  if (have("xmllint")) {
    const std::string cmd = "xmllint --noout --schema " PBVBUS_SOURCE_DIR "/tests/data/junit/junit.xsd " + path +
                            " >/dev/null 2>&1";
    EXPECT_EQ(std::system(cmd.c_str()), 0) << path;
  }
  const std::string s = check_junit(path);
  if (s != "skip") {
    EXPECT_EQ(s.rfind("ok ", 0), 0u) << s;
  }
}

struct Model {
  const char* gsd;
  const char* modules;  // extra arguments
};

// The shipped GSDs with the module lists of examples/gateway.textproto (0A01..0A04) and of the
// switched-I/O example (0A10/0A11: one input and one output module, so FCB/Rd_Outp apply).
const Model kModels[] = {
    {"PBVB0A01.gsd", ""},
    {"PBVB0A02.gsd", "--module '8DI DC24V' --module '8DO DC24V/0.5A' --module '2AO U/I 16 bit'"},
    {"PBVB0A03.gsd", "--module '8DI with process alarm' --module '8DO DC24V/0.5A' --module '2AI U/I consistent'"},
    {"PBVB0A04.gsd", ""},
    {"PBVB0A10.gsd", "--module '16DI DC24V' --module '16DO DC24V/0.5A'"},
    {"PBVB0A11.gsd", ""},
};

TEST(ConformanceCli, EveryShippedGsdModelPassesWithValidJunit) {
  for (const Model& m : kModels) {
    const std::string junit = std::string(PBVBUS_BINARY_DIR) + "/conformance_" + m.gsd + ".xml";
    std::remove(junit.c_str());
    const auto [rc, out] = run("conformance --gsd " + kGsd + m.gsd + " " + m.modules + " --junit " + junit);
    EXPECT_EQ(rc, 0) << m.gsd << "\n" << out;
    EXPECT_NE(out.find("\nPASSED\n"), std::string::npos) << out;
    expect_valid_junit(junit);
  }
}

TEST(ConformanceCli, MutantExitsOneAndNamesTheFailingTest) {
  const std::string junit = std::string(PBVBUS_BINARY_DIR) + "/conformance_mutant.xml";
  const auto [rc, out] = run("conformance --gsd " + kGsd + "PBVB0A01.gsd --mutant ignore_fcb --junit " + junit);
  EXPECT_EQ(rc, 1) << out;
  EXPECT_NE(out.find("  FCB-01   fail  Repeat not executed\n"), std::string::npos) << out;
  EXPECT_NE(out.find("mutant ignore_fcb"), std::string::npos) << out;
  expect_valid_junit(junit);
  std::ifstream f(junit);
  std::stringstream ss;
  ss << f.rdbuf();
  EXPECT_NE(ss.str().find("<testcase classname=\"FCB/FCV\" name=\"FCB-01 Repeat not executed\" time=\"0\">\n      <failure"),
            std::string::npos);
}

TEST(ConformanceCli, OnlyAndJson) {
  const auto [rc, out] = run("conformance --gsd " + kGsd + "PBVB0A01.gsd --only STA-01 --json");
  EXPECT_EQ(rc, 0) << out;
  EXPECT_EQ(out.rfind("{\"schema\":\"pbvbus.conformance/1\"", 0), 0u) << out;
  EXPECT_NE(out.find("\"totals\":{\"tests\":1,\"pass\":1,\"fail\":0,\"error\":0,\"na\":0}"), std::string::npos) << out;
}

TEST(ConformanceCli, ScenarioStation) {
  const auto [rc, out] = run("conformance --scenario " PBVBUS_SOURCE_DIR "/examples/dp-basic.textproto --station 4 --only Chk_Cfg");
  EXPECT_EQ(rc, 0) << out;
  EXPECT_NE(out.find("PBVB0A02.gsd"), std::string::npos) << out;
  EXPECT_NE(out.find("\"8DI DC24V\", \"8DO DC24V/0.5A\", \"2AO U/I 16 bit\""), std::string::npos) << out;
}

TEST(ConformanceCli, BadInputExitsTwo) {
  const std::string broken = std::string(PBVBUS_BINARY_DIR) + "/conformance_broken.gsd";
  std::ofstream(broken) << "#Profibus_DP\nGSD_Revision = 5\nIdent_Number = nonsense\n";
  {
    const auto [rc, out] = run("conformance --gsd " + broken);
    EXPECT_EQ(rc, 2) << out;
    EXPECT_NE(out.find("cannot use GSD"), std::string::npos) << out;
  }
  {
    const auto [rc, out] = run("conformance --gsd " + kGsd + "PBVB0A01.gsd --mutant no_such");
    EXPECT_EQ(rc, 2) << out;
    EXPECT_NE(out.find("unknown mutant 'no_such'"), std::string::npos) << out;
  }
  {
    const auto [rc, out] = run("conformance --gsd " + kGsd + "PBVB0A01.gsd --module nope");
    EXPECT_EQ(rc, 2) << out;
    EXPECT_NE(out.find("nope"), std::string::npos) << out;
  }
  {
    const auto [rc, out] = run("conformance --gsd " + kGsd + "PBVB0A01.gsd --only XYZ-99");
    EXPECT_EQ(rc, 2) << out;
  }
  {
    const auto [rc, out] = run("conformance");
    EXPECT_EQ(rc, 2) << out;
  }
}

TEST(ConformanceCli, MutationScoreTableForOneGsd) {
  const auto [rc, out] = run("conformance --mutation-score --gsd " + kGsd + "PBVB0A01.gsd");
  // Killed by this branch's groups at least: ignore_fcb by FCB-01 and FCB-03, accept_wrong_ident
  // by PRM-01. The exit status is 0 only when every mutant is killed (all groups present).
  EXPECT_TRUE(rc == 0 || rc == 1) << out;
  EXPECT_NE(out.find("  ignore_fcb                 killed: FCB-01 FCB-03\n"), std::string::npos) << out;
  EXPECT_NE(out.find("  accept_wrong_ident         killed: PRM-01\n"), std::string::npos) << out;
  EXPECT_NE(out.find("unbroken model passes"), std::string::npos) << out;
}

}  // namespace
