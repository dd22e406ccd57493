#include "pbvbus/bus/pty.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <termios.h>
#include <unistd.h>

#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <system_error>

namespace pbvbus::bus {

namespace {
[[noreturn]] void throw_errno(const std::string& what) {
  throw std::system_error(errno, std::generic_category(), what);
}
}  // namespace

Pty open_pty() {
  Pty p;
  p.master = ::posix_openpt(O_RDWR | O_NOCTTY | O_CLOEXEC);
  if (p.master < 0) throw_errno("posix_openpt");
  try {
    if (::grantpt(p.master) != 0) throw_errno("grantpt");
    if (::unlockpt(p.master) != 0) throw_errno("unlockpt");
    char name[128];
    if (::ptsname_r(p.master, name, sizeof name) != 0) throw_errno("ptsname_r");
    p.path = name;
    p.slave = ::open(name, O_RDWR | O_NOCTTY | O_CLOEXEC | O_NONBLOCK);
    if (p.slave < 0) throw_errno("open pty slave " + p.path);
    termios tio{};
    if (::tcgetattr(p.slave, &tio) != 0) throw_errno("tcgetattr " + p.path);
    ::cfmakeraw(&tio);  // 8 bits, no echo, no line editing, no CR/LF mapping
    tio.c_cc[VMIN] = 1;
    tio.c_cc[VTIME] = 0;
    if (::tcsetattr(p.slave, TCSANOW, &tio) != 0) throw_errno("tcsetattr " + p.path);
    const int fl = ::fcntl(p.master, F_GETFL);
    if (fl < 0 || ::fcntl(p.master, F_SETFL, fl | O_NONBLOCK) != 0) throw_errno("fcntl O_NONBLOCK");
  } catch (...) {
    if (p.slave >= 0) ::close(p.slave);
    ::close(p.master);
    throw;
  }
  return p;
}

std::string make_pty_link(const std::string& target, const std::string& link) {
  struct stat st {};
  if (::lstat(link.c_str(), &st) == 0) {
    if (!S_ISLNK(st.st_mode)) return "cannot link the pty to " + link + ": a file of that name exists";
    ::unlink(link.c_str());
  }
  if (::symlink(target.c_str(), link.c_str()) != 0)
    return "cannot link the pty to " + link + ": " + std::strerror(errno);
  return {};
}

}  // namespace pbvbus::bus
