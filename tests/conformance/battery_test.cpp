// The battery on the shipped slave models (examples/gsd/PBVB0A01.gsd first): every test of
// cbat's groups passes the unbroken model; the runner's contracts (selection, exceptions, bad
// DUTs, evidence) hold.

#include <gtest/gtest.h>

#include <fcntl.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <fstream>
#include <set>
#include <string>

#include "pbvbus/conformance/battery.hpp"
#include "pbvbus/gsd/gsd.hpp"

namespace pbvbus::conformance {
namespace {

std::shared_ptr<const devices::GsdFile> load(const std::string& name) {
  auto r = devices::load_gsd(std::string(PBVBUS_SOURCE_DIR) + "/examples/gsd/" + name);
  EXPECT_TRUE(r.ok()) << name;
  if (!r.ok()) return nullptr;
  return std::make_shared<const devices::GsdFile>(*r.file);
}

DutSpec spec_0a01() {
  DutSpec s;
  s.gsd = load("PBVB0A01.gsd");
  s.gsd_path = "examples/gsd/PBVB0A01.gsd";
  s.address = 3;
  return s;
}

std::string failures(const BatteryReport& rep) {
  std::string out;
  for (const auto& r : rep.results)
    if (r.verdict == Verdict::Fail) out += r.id + ": " + r.message + "\n";
  return out;
}

const std::vector<std::string> kCbatGroups = {"Start-up", "Set_Prm", "Chk_Cfg", "Read services", "FCB/FCV"};

TEST(Battery, AllOfCbatsGroupsPassOnTheUnbrokenPbvb0a01Model) {
  BatteryOptions o;
  o.only = kCbatGroups;
  const BatteryReport rep = run_battery(spec_0a01(), o);
  ASSERT_TRUE(rep.dut_error.empty()) << rep.dut_error;
  EXPECT_EQ(failures(rep), "");
  EXPECT_TRUE(rep.passed());
  // Every group has tests; ids are unique.
  std::set<std::string> ids, groups;
  for (const auto& r : rep.results) {
    EXPECT_TRUE(ids.insert(r.id).second) << r.id;
    groups.insert(r.group);
    EXPECT_FALSE(r.requirement.empty()) << r.id;
    if (r.verdict != Verdict::NotApplicable) {
      EXPECT_FALSE(r.evidence.empty()) << r.id;
    }
  }
  EXPECT_EQ(groups.size(), kCbatGroups.size());
  EXPECT_GE(rep.results.size(), 24u);
}

TEST(Battery, Pbvb0a01HasNoWrongUserPrmContent) {
  // PBVB0A01's parameters: Bit(1) 0-1, BitArea(4-5) 0-3, Bit(0) 0-1 — every value of each field
  // is allowed, so PRM-03 is n/a with a reason.
  BatteryOptions o;
  o.only = {"PRM-03"};
  const BatteryReport rep = run_battery(spec_0a01(), o);
  ASSERT_EQ(rep.results.size(), 1u);
  EXPECT_EQ(rep.results[0].verdict, Verdict::NotApplicable);
  EXPECT_NE(rep.results[0].message.find("ExtUserPrmData"), std::string::npos);
}

TEST(Battery, OnlySelectsByIdAndGroup) {
  BatteryOptions o;
  o.only = {"STA-01", "FCB/FCV"};
  const BatteryReport rep = run_battery(spec_0a01(), o);
  ASSERT_FALSE(rep.results.empty());
  EXPECT_EQ(rep.results.front().id, "STA-01");
  for (std::size_t i = 1; i < rep.results.size(); ++i) EXPECT_EQ(rep.results[i].group, "FCB/FCV");
}

TEST(Battery, PowerOnDiagEvidenceIsTheExchange) {
  BatteryOptions o;
  o.only = {"STA-01"};
  const BatteryReport rep = run_battery(spec_0a01(), o);
  ASSERT_EQ(rep.results.size(), 1u);
  const auto& ev = rep.results[0].evidence;
  ASSERT_EQ(ev.size(), 1u);
  // Slave_Diag to 3 from 1: 68 05 05 68 83 81 4D 3C 3E CB 16 (FCS 83+81+4D+3C+3E = 0x1CB).
  EXPECT_EQ(ev[0].request, (std::vector<std::uint8_t>{0x68, 0x05, 0x05, 0x68, 0x83, 0x81, 0x4D, 0x3C,
                                                      0x3E, 0xCB, 0x16}));
  // Reply SD3: A2 81 83 08 3E 3C 02 05 00 FF 0A 01 FCS 16,
  // FCS = 81+83+08+3E+3C+02+05+00+FF+0A+01 = 0x297 → 0x97.
  EXPECT_EQ(ev[0].response, (std::vector<std::uint8_t>{0xA2, 0x81, 0x83, 0x08, 0x3E, 0x3C, 0x02, 0x05,
                                                       0x00, 0xFF, 0x0A, 0x01, 0x97, 0x16}));
}

TEST(Battery, NoGsdIsADutError) {
  DutSpec s;
  const BatteryReport rep = run_battery(s);
  EXPECT_FALSE(rep.dut_error.empty());
  EXPECT_FALSE(rep.passed());
  EXPECT_TRUE(rep.results.empty());
}

TEST(Battery, UnknownModuleIsADutError) {
  DutSpec s = spec_0a01();
  s.modules = {devices::ModuleChoice::named("no such module")};
  const BatteryReport rep = run_battery(s);
  EXPECT_NE(rep.dut_error.find("no such module"), std::string::npos) << rep.dut_error;
}

TEST(Battery, UnsupportedBaudIsADutError) {
  DutSpec s = spec_0a01();
  s.baud = bus::Baud::k31_25;  // PBVB0A01 does not list 31.25 kbit/s
  const BatteryReport rep = run_battery(s);
  EXPECT_NE(rep.dut_error.find("31.25"), std::string::npos) << rep.dut_error;
}

TEST(Battery, RunsAtAnotherSupportedBaud) {
  DutSpec s = spec_0a01();
  s.baud = bus::Baud::k19_2;
  BatteryOptions o;
  o.only = {"Start-up", "FCB/FCV"};
  const BatteryReport rep = run_battery(s, o);
  ASSERT_TRUE(rep.dut_error.empty()) << rep.dut_error;
  EXPECT_EQ(failures(rep), "");
}

}  // namespace
}  // namespace pbvbus::conformance

namespace pbvbus::conformance {
namespace {

// Each mutant (devices/slave_mutant.hpp) fails exactly the tests of cbat's groups that name it in
// their targets, and no other: a mutant aimed at another group's rule passes all of these.
TEST(Battery, EachMutantFailsExactlyItsTargetedTests) {
  BatteryOptions o;
  o.only = kCbatGroups;
  std::string report;
  for (const auto& info : devices::slave_mutants()) {
    DutSpec s = spec_0a01();
    s.mutant = info.mutant;
    const BatteryReport rep = run_battery(s, o);
    ASSERT_TRUE(rep.dut_error.empty()) << info.name << ": " << rep.dut_error;
    std::set<std::string> failed, targeted;
    for (const auto& r : rep.results)
      if (r.verdict == Verdict::Fail) failed.insert(r.id);
    for (const auto& t : all_tests()) {
      if (std::find(kCbatGroups.begin(), kCbatGroups.end(), t.group) == kCbatGroups.end()) continue;
      if (std::find(t.targets.begin(), t.targets.end(), info.mutant) != t.targets.end()) targeted.insert(t.id);
    }
    if (failed != targeted) {
      report += std::string(info.name) + ": failed {";
      for (const auto& id : failed) report += " " + id;
      report += " } targeted {";
      for (const auto& id : targeted) report += " " + id;
      report += " }\n";
    }
  }
  EXPECT_EQ(report, "");
}

}  // namespace
}  // namespace pbvbus::conformance

namespace pbvbus::conformance {
namespace {

// An outside DUT whose program never answers: every request times out within TSL of virtual
// time (paced at 1/1 here), the tests fail with "no reply" — no hang, no abort — and the pty
// link exists during the run and is removed afterwards.
TEST(Battery, APtyNoProgramOpensIsADutErrorAfterTheWait) {
  DutSpec s = spec_0a01();
  const std::string link = std::string(PBVBUS_BINARY_DIR) + "/battery_test_pty_unopened";
  std::filesystem::remove(link);
  s.pty_path = link;
  s.speed = {1, 1};
  s.open_wait = std::chrono::milliseconds(300);
  std::vector<std::string> said;
  BatteryOptions o;
  o.only = {"STA-01"};
  o.progress = [&](const std::string& m) { said.push_back(m); };
  const BatteryReport rep = run_battery(s, o);
  EXPECT_NE(rep.dut_error.find("no program opened " + link), std::string::npos) << rep.dut_error;
  EXPECT_TRUE(rep.results.empty());
  ASSERT_FALSE(said.empty());
  EXPECT_NE(said.front().find("waiting up to 300 ms for a program to open " + link), std::string::npos)
      << said.front();
  EXPECT_FALSE(std::filesystem::exists(std::filesystem::symlink_status(link)));
}

TEST(Battery, ASilentProgramIsAnErrorNotAFailAndNeverHangs) {
  // A program that opens the pty and never answers: no test can establish its starting state.
  DutSpec s = spec_0a01();
  const std::string link = std::string(PBVBUS_BINARY_DIR) + "/battery_test_pty";
  std::filesystem::remove(link);
  s.pty_path = link;
  s.speed = {1, 1};
  BatteryOptions o;
  o.only = {"STA-01", "PRM-08"};
  int fd = -1;
  o.progress = [&](const std::string& m) {
    if (fd < 0 && m.find("waiting") != std::string::npos) fd = ::open(link.c_str(), O_RDWR | O_NOCTTY);
  };
  const BatteryReport rep = run_battery(s, o);
  if (fd >= 0) ::close(fd);
  ASSERT_TRUE(rep.dut_error.empty()) << rep.dut_error;
  ASSERT_EQ(rep.results.size(), 2u);
  EXPECT_EQ(rep.results[0].verdict, Verdict::Error);
  EXPECT_NE(rep.results[0].message.find("answers no Slave_Diag at its address 3 (no reply), nor at 100, 101 or 126"),
            std::string::npos)
      << rep.results[0].message;
  // The evidence: the four probes of the start state, this test's only.
  ASSERT_EQ(rep.results[0].evidence.size(), 4u);
  EXPECT_EQ(rep.results[0].evidence[0].note, "start state: Slave_Diag");
  EXPECT_EQ(rep.results[0].evidence[1].note, "start state: is the DUT at 100?");
  EXPECT_FALSE(rep.results[0].timing_not_meaningful);
  // PRM-08 is n/a behind a pty before it needs a session.
  EXPECT_EQ(rep.results[1].verdict, Verdict::NotApplicable);
  EXPECT_TRUE(rep.results[1].timing_not_meaningful);
  EXPECT_FALSE(rep.passed());
  EXPECT_FALSE(std::filesystem::exists(std::filesystem::symlink_status(link)));
}

TEST(Battery, PtyDutNeverOverwritesAFile) {
  DutSpec s = spec_0a01();
  const std::string file = std::string(PBVBUS_BINARY_DIR) + "/battery_test_not_a_link";
  std::ofstream(file) << "x";
  s.pty_path = file;
  const BatteryReport rep = run_battery(s);
  EXPECT_NE(rep.dut_error.find("a file of that name exists"), std::string::npos) << rep.dut_error;
  EXPECT_TRUE(std::filesystem::exists(file));  // never overwritten
}

}  // namespace
}  // namespace pbvbus::conformance
