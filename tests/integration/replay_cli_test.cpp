// `pbvbus replay` through the built binary (docs/replay.md): a capture of
// examples/dp-basic.textproto replayed against the same scenario gives 0 differences with
// every request compared, in both pacings; against a mutant station 4 the differences are
// exactly the mutant's; captures with a cut-short frame or a bad FCS are read and reported;
// `--to PTY` delivers the capture's frame octets in order.
//
// The number of requests is counted here independently of the replay code: a request that
// expects a reply is an SD1/SD2/SD3 frame whose FC has the request bit (0x40) and a function
// other than SDN (4, 6) or time event (0), to a DA other than 127 (protocol-facts.md §B.3).
#include <fcntl.h>
#include <poll.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <termios.h>
#include <unistd.h>

#include <gtest/gtest.h>

#include <chrono>
#include <cstdio>
#include <fstream>
#include <iterator>
#include <string>
#include <thread>
#include <vector>

#include "pbvbus/captures/pcapng_reader.hpp"

namespace {

using Bytes = std::vector<std::uint8_t>;

const std::string kBinary = PBVBUS_BINARY_DIR "/bin/pbvbus";
const std::string kScenario = PBVBUS_SOURCE_DIR "/examples/dp-basic.textproto";

std::string temp(const std::string& stem) {
  return std::string(PBVBUS_BINARY_DIR) + "/replay_cli_" + stem + "_" + std::to_string(::getpid());
}

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

Bytes read_all(const std::string& path) {
  std::ifstream f(path, std::ios::binary);
  return Bytes((std::istreambuf_iterator<char>(f)), std::istreambuf_iterator<char>());
}

void write_all(const std::string& path, const Bytes& b) {
  std::ofstream(path, std::ios::binary).write(reinterpret_cast<const char*>(b.data()),
                                              static_cast<std::streamsize>(b.size()));
}

/// The dp-basic capture (300 ms), made once.
const std::string& capture() {
  static const std::string path = [] {
    const std::string p = temp("dp_basic") + ".pcapng";
    const auto [rc, out] = run("run " + kScenario + " --duration 300ms --capture " + p);
    EXPECT_EQ(rc, 0) << out;
    return p;
  }();
  return path;
}

struct Frame {
  Bytes b;
  std::uint64_t offset;
};

std::vector<Frame> line_frames(const Bytes& file) {
  pbvbus::captures::PcapngError err;
  auto cap = pbvbus::captures::read_pcapng(file, err);
  EXPECT_TRUE(cap) << err.to_string();
  std::vector<Frame> v;
  if (!cap) return v;
  for (const auto& r : cap->records)
    if (cap->interfaces[r.interface].link_type == 147) v.push_back({r.bytes, r.offset});
  return v;
}

/// DA, FC of an SD1/SD2/SD3 frame; false for SD4, SC and anything else.
bool da_fc(const Bytes& b, int& da, int& fc) {
  if (b.empty()) return false;
  const std::size_t at = b[0] == 0x68 ? 4 : (b[0] == 0x10 || b[0] == 0xA2) ? 1 : 0;
  if (at == 0 || b.size() < at + 3) return false;
  da = b[at] & 0x7F;
  fc = b[at + 2];
  return true;
}

bool expects_reply(const Bytes& b, int station = -1) {
  int da = 0, fc = 0;
  if (!da_fc(b, da, fc) || !(fc & 0x40)) return false;
  const int fn = fc & 0x0F;
  return da != 127 && fn != 0 && fn != 4 && fn != 6 && (station < 0 || da == station);
}

std::size_t count_requests(int station = -1) {
  std::size_t n = 0;
  for (const auto& f : line_frames(read_all(capture()))) n += expects_reply(f.b, station);
  return n;
}

std::string field(const std::string& json, const std::string& key) {
  const auto at = json.find("\"" + key + "\":");
  if (at == std::string::npos) return "<missing>";
  const auto b = at + key.size() + 3;
  const auto e = json.find_first_of(",}", b);
  return json.substr(b, e - b);
}

TEST(ReplayCli, SameScenarioNoDifferencesBothPacings) {
  const std::size_t n = count_requests();
  ASSERT_GT(n, 100u);  // 300 ms of start-up and Data_Exchange at 1.5 Mbit/s
  for (const char* pacing : {"--fast", "--paced-as-recorded"}) {
    const auto [rc, out] = run("replay " + capture() + " --scenario " + kScenario + " " + pacing + " --json");
    EXPECT_EQ(rc, 0) << pacing << "\n" << out;
    EXPECT_EQ(field(out, "compared"), std::to_string(n)) << pacing;
    EXPECT_EQ(field(out, "matches"), std::to_string(n)) << pacing;
    EXPECT_EQ(field(out, "differences"), "0") << pacing;
    EXPECT_EQ(field(out, "unusable"), "0") << pacing;
    EXPECT_EQ(field(out, "pacing_slips"), "0") << pacing;
  }
  // The text form says so too.
  const auto [rc, text] = run("replay " + capture() + " --scenario " + kScenario);
  EXPECT_EQ(rc, 0);
  EXPECT_NE(text.find("result: no differences\n"), std::string::npos) << text;
}

TEST(ReplayCli, OneStationTarget) {
  const std::size_t n = count_requests(5);
  const auto [rc, out] = run("replay " + capture() + " --scenario " + kScenario + " --station 5 --json");
  EXPECT_EQ(rc, 0) << out;
  EXPECT_EQ(field(out, "compared"), std::to_string(n));
  EXPECT_EQ(field(out, "tokens_replayed"), "0");
}

TEST(ReplayCli, MutantTsdrTooLateIsATimingDifferenceOnEveryReplyOfStation4) {
  // tsdr_too_late answers 20 bit times after the GSD's MaxTsdr (150 at 1.5 Mbit/s): 170 > the
  // line's max TSDR 150, < TSL, so every reply of station 4 is there, on time for the slot
  // time, and late for max TSDR; nothing else changes.
  const std::size_t n4 = count_requests(4);
  ASSERT_GT(n4, 10u);
  const auto [rc, out] = run("replay " + capture() + " --scenario " + kScenario +
                             " --mutant 4:tsdr_too_late --json --max-diffs 1");
  ASSERT_EQ(rc, 1) << out;
  EXPECT_EQ(field(out, "differences"), std::to_string(n4));
  EXPECT_EQ(field(out, "timing"), std::to_string(n4));
  EXPECT_EQ(field(out, "missing_reply"), "0");
  EXPECT_EQ(field(out, "other_data"), "0");
  EXPECT_EQ(field(out, "matches"), std::to_string(count_requests() - n4));
  EXPECT_EQ(field(out, "station"), "4");
  EXPECT_EQ(field(out, "service"), "\"Slave_Diag\"");  // the first request to it
  EXPECT_EQ(field(out, "tsdr_bits"), "170");
}

TEST(ReplayCli, CutShortReplyIsReportedAndNotCompared) {
  Bytes f = read_all(capture());
  const auto frames = line_frames(f);
  // The first Data_Exchange reply of station 3: SD2 with DA 1, SA 3, FC 08 (DL).
  std::size_t k = 0;
  while (k < frames.size() && !(frames[k].b.size() > 7 && frames[k].b[0] == 0x68 &&
                                frames[k].b[4] == 0x01 && frames[k].b[5] == 0x03 && frames[k].b[6] == 0x08))
    ++k;
  ASSERT_LT(k, frames.size());
  const std::uint32_t caplen = static_cast<std::uint32_t>(frames[k].b.size());
  const std::uint32_t orig = caplen + 3;  // EPB +24: original length
  for (int i = 0; i < 4; ++i) f[frames[k].offset + 24 + static_cast<std::size_t>(i)] = static_cast<std::uint8_t>(orig >> (8 * i));
  const std::string p = temp("cut") + ".pcapng";
  write_all(p, f);
  const auto [rc, out] = run("replay " + p + " --scenario " + kScenario + " --json");
  EXPECT_EQ(rc, 0) << out;
  EXPECT_EQ(field(out, "unusable"), "1");
  EXPECT_EQ(field(out, "not_compared_reply_unusable"), "1");
  EXPECT_EQ(field(out, "compared"), std::to_string(count_requests() - 1));
  EXPECT_NE(out.find("\"reason\":\"cut short: " + std::to_string(caplen) + " of " + std::to_string(orig) +
                     " octets captured\""),
            std::string::npos)
      << out;
  ::unlink(p.c_str());
}

TEST(ReplayCli, BadFcsRequestIsReportedAndItsAbsenceShows) {
  Bytes f = read_all(capture());
  const auto frames = line_frames(f);
  // The 20th Data_Exchange request to station 3 (DA 3, SA 1, no SAPs, SRD): its FCS + 1.
  std::size_t k = 0;
  int seen = 0;
  for (; k < frames.size(); ++k) {
    const Bytes& b = frames[k].b;
    if (b.size() > 7 && b[0] == 0x68 && b[4] == 0x03 && b[5] == 0x01 && (b[6] & 0x4F) == 0x4D && ++seen == 20) break;
  }
  ASSERT_LT(k, frames.size());
  f[frames[k].offset + 28 + frames[k].b.size() - 2] ^= 0x01;
  const std::string p = temp("fcs") + ".pcapng";
  write_all(p, f);
  const auto [rc, out] = run("replay " + p + " --scenario " + kScenario + " --json --max-diffs 1");
  // The slave never gets that request: the next one carries the FCB it accepted last, so it
  // repeats its previous reply (FCB rule), and its DP cycle counter lags from then on: station 3's
  // later Data_Exchange replies differ in data. The run goes on; exit 1 for the differences.
  EXPECT_EQ(rc, 1) << out;
  EXPECT_EQ(field(out, "unusable"), "1");
  EXPECT_NE(out.find("\"reason\":\"not a valid telegram: FCS mismatch\""), std::string::npos) << out;
  EXPECT_EQ(field(out, "differences"), field(out, "other_data"));
  EXPECT_EQ(field(out, "station"), "3");
  EXPECT_EQ(field(out, "service"), "\"Data_Exchange\"");
  ::unlink(p.c_str());
}

TEST(ReplayCli, BadInputIsExit2) {
  EXPECT_EQ(run("replay /nonexistent.pcapng --scenario " + kScenario).first, 2);
  const std::string p = temp("garbage") + ".pcapng";
  write_all(p, Bytes(64, 0x41));
  const auto [rc, out] = run("replay " + p + " --scenario " + kScenario);
  EXPECT_EQ(rc, 2);
  EXPECT_NE(out.find("not a pcapng file"), std::string::npos) << out;
  ::unlink(p.c_str());
  EXPECT_EQ(run("replay " + capture() + " --scenario " + kScenario + " --line NOPE").first, 2);
  EXPECT_EQ(run("replay " + capture() + " --scenario " + kScenario + " --mask bogus").first, 2);
}

TEST(ReplayCli, ToPtyDeliversTheFramesInOrder) {
  const Bytes file = read_all(capture());
  Bytes expected;
  for (const auto& fr : line_frames(file)) expected.insert(expected.end(), fr.b.begin(), fr.b.end());
  const std::string link = temp("to_pty");
  ::unlink(link.c_str());
  const pid_t child = ::fork();
  ASSERT_GE(child, 0);
  if (child == 0) {
    const int null = ::open("/dev/null", O_WRONLY);
    ::dup2(null, 1);
    ::execl(kBinary.c_str(), kBinary.c_str(), "replay", capture().c_str(), "--to", link.c_str(), "--speed", "2",
            static_cast<char*>(nullptr));
    ::_exit(127);
  }
  const auto t0 = std::chrono::steady_clock::now();
  int fd = -1;
  while (fd < 0 && std::chrono::steady_clock::now() - t0 < std::chrono::seconds(20)) {
    fd = ::open(link.c_str(), O_RDONLY | O_NOCTTY | O_NONBLOCK);
    if (fd < 0) std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  ASSERT_GE(fd, 0) << "the link never appeared";
  termios t{};
  ::tcgetattr(fd, &t);
  ::cfmakeraw(&t);
  ::tcsetattr(fd, TCSANOW, &t);
  Bytes got;
  int status = 0;
  bool exited = false;
  while (std::chrono::steady_clock::now() - t0 < std::chrono::seconds(30)) {
    pollfd p{fd, POLLIN, 0};
    const int r = ::poll(&p, 1, 100);
    if (r > 0 && (p.revents & POLLIN)) {
      std::uint8_t buf[4096];
      const ssize_t n = ::read(fd, buf, sizeof buf);
      if (n > 0) {
        got.insert(got.end(), buf, buf + n);
        continue;
      }
    }
    if (!exited && ::waitpid(child, &status, WNOHANG) == child) exited = true;
    if (exited && r == 0) break;  // the player is gone and nothing more arrives
    if (r > 0 && (p.revents & (POLLHUP | POLLERR))) {
      if (!exited) ::waitpid(child, &status, 0);
      exited = true;
      break;
    }
  }
  ::close(fd);
  if (!exited) {
    ::kill(child, SIGKILL);
    ::waitpid(child, &status, 0);
  }
  ASSERT_TRUE(exited) << "the player did not finish within 30 s";
  EXPECT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0);
  EXPECT_EQ(got.size(), expected.size());
  EXPECT_TRUE(got == expected);
  std::size_t first = 0;
  while (first < got.size() && first < expected.size() && got[first] == expected[first]) ++first;
  EXPECT_EQ(first, expected.size()) << "first difference at octet " << first;
}

}  // namespace
