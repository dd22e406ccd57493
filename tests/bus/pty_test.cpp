// bus::open_pty / make_pty_link: the one way pbvbus opens pseudo-terminals (pty attachment,
// Modbus RTU and SLCAN doors, replay into a serial port).
#include "pbvbus/bus/pty.hpp"

#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>

#include <array>
#include <cstdlib>
#include <fstream>
#include <string>

namespace pbvbus::bus {
namespace {

struct Closer {
  Pty p;
  ~Closer() {
    if (p.slave >= 0) ::close(p.slave);
    if (p.master >= 0) ::close(p.master);
  }
};

TEST(Pty, RawBothWaysAndOctetsPassUnchanged) {
  Closer c{open_pty()};
  ASSERT_GE(c.p.master, 0);
  ASSERT_GE(c.p.slave, 0);
  EXPECT_EQ(c.p.path.rfind("/dev/pts/", 0), 0u) << c.p.path;
  // CR, LF, 0x7F and 0x03 would be mapped or swallowed by a cooked terminal.
  const std::array<unsigned char, 6> out{0x0D, 0x0A, 0x7F, 0x03, 0x68, 0x16};
  ASSERT_EQ(::write(c.p.master, out.data(), out.size()), 6);
  std::array<unsigned char, 16> in{};
  ssize_t n = 0;
  for (int i = 0; i < 200 && n < 6; ++i) {
    const ssize_t r = ::read(c.p.slave, in.data() + n, in.size() - static_cast<std::size_t>(n));
    if (r > 0) n += r; else ::usleep(1000);
  }
  ASSERT_EQ(n, 6);
  for (std::size_t i = 0; i < 6; ++i) EXPECT_EQ(in[i], out[i]) << i;
}

TEST(Pty, LinkReplacesAStaleLinkButNeverAFile) {
  char dir_tmpl[] = "/tmp/pbvbus-pty-XXXXXX";
  ASSERT_NE(::mkdtemp(dir_tmpl), nullptr);
  const std::string dir = dir_tmpl;
  const std::string link = dir + "/dut";
  Closer c{open_pty()};
  ASSERT_EQ(::symlink("/nonexistent/old", link.c_str()), 0);  // an earlier run's link
  EXPECT_EQ(make_pty_link(c.p.path, link), "");
  char buf[256] = {};
  ASSERT_GT(::readlink(link.c_str(), buf, sizeof buf - 1), 0);
  EXPECT_EQ(std::string(buf), c.p.path);

  const std::string file = dir + "/file";
  std::ofstream(file) << "keep me";
  const std::string e = make_pty_link(c.p.path, file);
  EXPECT_NE(e.find("a file of that name exists"), std::string::npos) << e;
  struct stat st {};
  ASSERT_EQ(::lstat(file.c_str(), &st), 0);
  EXPECT_TRUE(S_ISREG(st.st_mode));
  ::unlink(link.c_str());
  ::unlink(file.c_str());
  ::rmdir(dir.c_str());
}

}  // namespace
}  // namespace pbvbus::bus
