#pragma once
// What the TCP door tests under descriptor exhaustion share: DescriptorSqueeze lowers this
// process's RLIMIT_NOFILE just above the descriptors in use and fills every free one, so the
// door's next accept() fails with EMFILE, as in a run under `ulimit -n 1024` with ~1020 clients
// connected; release() frees some, the destructor all (and the limit). thread_cpu() is the
// calling thread's CPU time: the bus and the door run on the test thread, so a door that spins
// on a failing accept() shows there, whatever other processes load the machine.
//
// Safe in the test process: the door and the bus run on the test thread and open nothing while
// squeezed except through accept(); client sockets are made from freed descriptors on purpose.
#include <dirent.h>
#include <fcntl.h>
#include <sys/resource.h>
#include <time.h>
#include <unistd.h>

#include <chrono>
#include <cstddef>
#include <cstdlib>
#include <vector>

namespace pbvbus::gateways::test {

class DescriptorSqueeze {
 public:
  DescriptorSqueeze() {
    ::getrlimit(RLIMIT_NOFILE, &m_old);
    // The limit just above the highest descriptor open now: filling it takes a few dozen
    // descriptors, not the tens of thousands a generous limit allows.
    int highest = 2;
    if (DIR* d = ::opendir("/proc/self/fd")) {
      while (const dirent* e = ::readdir(d)) highest = std::max(highest, std::atoi(e->d_name));
      ::closedir(d);
    }
    rlimit r = m_old;
    r.rlim_cur = static_cast<rlim_t>(highest + 16);
    ok = ::setrlimit(RLIMIT_NOFILE, &r) == 0;
    for (;;) {
      const int fd = ::open("/dev/null", O_RDONLY | O_CLOEXEC);
      if (fd < 0) break;  // EMFILE: every descriptor the limit allows is taken
      m_fillers.push_back(fd);
    }
    ok = ok && !m_fillers.empty();
  }
  ~DescriptorSqueeze() { unsqueeze(); }
  DescriptorSqueeze(const DescriptorSqueeze&) = delete;
  DescriptorSqueeze& operator=(const DescriptorSqueeze&) = delete;

  /// Frees `n` descriptors (for the test's own client sockets).
  void release(std::size_t n) {
    for (; n > 0 && !m_fillers.empty(); --n) {
      ::close(m_fillers.back());
      m_fillers.pop_back();
    }
  }
  /// Frees every descriptor and restores the limit.
  void unsqueeze() {
    release(m_fillers.size());
    ::setrlimit(RLIMIT_NOFILE, &m_old);
  }

  bool ok = false;

 private:
  rlimit m_old{};
  std::vector<int> m_fillers;
};

/// CPU time the calling thread has used.
inline std::chrono::nanoseconds thread_cpu() {
  timespec ts{};
  ::clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return std::chrono::seconds(ts.tv_sec) + std::chrono::nanoseconds(ts.tv_nsec);
}

}  // namespace pbvbus::gateways::test
