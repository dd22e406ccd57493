// The battery against an outside slave: a Python program behind the pty
// (tests/conformance/data/tiny_slave.py, /usr/bin/python3 + pyserial; skipped without them)
// that implements just enough for STA-01. The conformant version passes; the deliberately broken
// one (Prm_Req missing from the power-on diagnosis) is caught.

#include <gtest/gtest.h>

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <string>

#include "pbvbus/conformance/battery.hpp"
#include "pbvbus/gsd/gsd.hpp"

namespace pbvbus::conformance {
namespace {

bool have_pyserial() {
  return std::system("/usr/bin/python3 -c 'import serial' >/dev/null 2>&1") == 0;
}

BatteryReport run_against_program(bool broken) {
  auto g = devices::load_gsd(std::string(PBVBUS_SOURCE_DIR) + "/examples/gsd/PBVB0A01.gsd");
  EXPECT_TRUE(g.ok());
  DutSpec s;
  s.gsd = std::make_shared<const devices::GsdFile>(*g.file);
  s.gsd_path = "examples/gsd/PBVB0A01.gsd";
  s.address = 3;
  const std::string link = std::string(PBVBUS_BINARY_DIR) + (broken ? "/tiny_slave_broken_pty" : "/tiny_slave_pty");
  std::filesystem::remove(link);
  s.pty_path = link;
  // 1.5 Mbit/s, TSL 300 bit times = 200 us virtual = 0.2 s of wall time at 1/1000: time enough
  // for a Python program to answer.
  s.speed = {1, 1000};
  const std::string cmd = "/usr/bin/python3 " + std::string(PBVBUS_SOURCE_DIR) +
                          "/tests/conformance/data/tiny_slave.py " + link + (broken ? " --broken" : "") +
                          " >/dev/null 2>&1 &";
  EXPECT_EQ(std::system(cmd.c_str()), 0);
  BatteryOptions o;
  o.only = {"STA-01"};
  return run_battery(s, o);
}

TEST(BatteryPty, ConformantProgramPassesStartUpDiag) {
  if (!have_pyserial()) GTEST_SKIP() << "/usr/bin/python3 with pyserial (python3-serial) is not installed";
  const BatteryReport rep = run_against_program(false);
  ASSERT_TRUE(rep.dut_error.empty()) << rep.dut_error;
  ASSERT_EQ(rep.results.size(), 1u);
  EXPECT_EQ(rep.results[0].verdict, Verdict::Pass) << rep.results[0].message;
}

TEST(BatteryPty, BrokenProgramIsCaught) {
  if (!have_pyserial()) GTEST_SKIP() << "/usr/bin/python3 with pyserial (python3-serial) is not installed";
  const BatteryReport rep = run_against_program(true);
  ASSERT_TRUE(rep.dut_error.empty()) << rep.dut_error;
  ASSERT_EQ(rep.results.size(), 1u);
  EXPECT_EQ(rep.results[0].verdict, Verdict::Fail);
  // 02 04 00 FF 0A 01 instead of 02 05 00 FF 0A 01 (Prm_Req = octet 2 bit 0 missing).
  EXPECT_NE(rep.results[0].message.find("expected diag 02 05 00 FF 0A 01, got 02 04 00 FF 0A 01"), std::string::npos)
      << rep.results[0].message;
}

}  // namespace
}  // namespace pbvbus::conformance
