// The `./pbvbus` launcher passes every subcommand it does not own straight to the program
// (`./pbvbus gsd FILE` once answered "unknown command"); `exec` stays an alias. Runs the
// launcher against this build directory with apt-get skipped, so the build step is a no-op.
#include <gtest/gtest.h>

#include <string>

#include "../captures/tshark_helpers.hpp"

namespace {

using pbvbus::test::run_command;
using pbvbus::test::shell_quote;

std::string launcher(const std::string& args) {
  return "PBVBUS_SKIP_APT=1 PBVBUS_BUILD_DIR=" + shell_quote(PBVBUS_BINARY_DIR) + " " +
         shell_quote(PBVBUS_SOURCE_DIR "/pbvbus") + " " + args;
}

TEST(Launcher, PassesSubcommandsToTheProgram) {
  const auto direct = run_command(launcher("gsd examples/gsd/PBVB0A01.gsd"));
  ASSERT_EQ(direct.exit_code, 0) << direct.err;
  EXPECT_NE(direct.out.find("PBVB0A01"), std::string::npos) << direct.out;
  EXPECT_NE(direct.out.find("0x0A01"), std::string::npos) << direct.out;
  const auto alias = run_command(launcher("exec gsd examples/gsd/PBVB0A01.gsd"));
  ASSERT_EQ(alias.exit_code, 0) << alias.err;
  EXPECT_EQ(alias.out, direct.out);
  const auto inspect = run_command(launcher("inspect --help"));
  EXPECT_EQ(inspect.exit_code, 0) << inspect.err;
  EXPECT_NE(inspect.out.find("usage: pbvbus inspect"), std::string::npos) << inspect.out;
}

TEST(Launcher, UnknownWordsAreTheProgramsToRefuse) {
  const auto r = run_command(launcher("no-such-command"));
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("pbvbus: unknown command 'no-such-command'"), std::string::npos) << r.err;
  const auto help = run_command(launcher("help"));
  EXPECT_EQ(help.exit_code, 0);
  EXPECT_NE(help.out.find("./pbvbus SUBCOMMAND"), std::string::npos) << help.out;
  EXPECT_NE(help.out.find("inspect"), std::string::npos) << help.out;  // the program's list
}

}  // namespace
