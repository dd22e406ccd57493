// Serial attachments in a scenario: a MONITOR pty carries the line's telegrams byte for byte,
// its symlink exists while the Simulation does; a STATION pty puts a program's telegrams on the
// line.
#include <fcntl.h>
#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>

#include <chrono>
#include <thread>

#include "pbvbus/bus/frame_splitter.hpp"
#include "pbvbus/fdl_traffic/fdl_responder.hpp"
#include "pbvbus/fdl/telegram.hpp"
#include "pbvbus/scenario/scenario.hpp"
#include "pbvbus/simulation/simulation.hpp"

namespace pbvbus::tools {
namespace {

std::vector<std::uint8_t> read_all(int fd) {
  std::vector<std::uint8_t> out;
  std::uint8_t buf[4096];
  for (;;) {
    const ssize_t n = ::read(fd, buf, sizeof buf);
    if (n <= 0) break;
    out.insert(out.end(), buf, buf + n);
  }
  return out;
}

TEST(SerialAttachment, MonitorPtyCarriesTheLinesTelegrams) {
  const std::string link = std::string(PBVBUS_BINARY_DIR) + "/serial_test_monitor";
  const auto loaded = parse_scenario(
      "line { name: \"A\" }\n"
      "master { address: 1 line: \"A\" poll { address: [5] length: 2 } }\n"
      "passive_station { address: 5 line: \"A\" response_length: 3 }\n"
      "serial { line: \"A\" mode: MONITOR link: \"" + link + "\" }\n",
      "t");
  ASSERT_TRUE(loaded.ok()) << loaded.errors[0].str();
  std::string path;
  {
    Simulation sim(*loaded.plan);
    ASSERT_EQ(sim.serial_ports().size(), 1u);
    path = sim.serial_ports()[0].path;
    EXPECT_EQ(sim.serial_ports()[0].mode, "monitor");
    EXPECT_EQ(sim.serial_ports()[0].link, link);
    char target[256] = {};
    ASSERT_GT(::readlink(link.c_str(), target, sizeof target - 1), 0);
    EXPECT_EQ(std::string(target), path);
    EXPECT_TRUE(sim.has_external_attachments());

    const int fd = ::open(path.c_str(), O_RDONLY | O_NOCTTY | O_NONBLOCK);
    ASSERT_GE(fd, 0);
    sim.run_until(2 * bus::kTicksPerMs);  // a few hundred octets: fits the pty buffer
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
    const auto bytes = read_all(fd);
    ::close(fd);
    // Every octet belongs to a valid telegram, and they are the ones on the line.
    ASSERT_FALSE(bytes.empty());
    bus::FrameSplitter split;
    std::size_t frames = 0, tokens = 0, srd = 0, replies = 0;
    split.feed(bytes, [&](std::span<const std::uint8_t> f) {
      fdl::Telegram t;
      ASSERT_EQ(fdl::decode(f, t), fdl::DecodeError::None);
      ++frames;
      if (t.type == fdl::FrameType::SD4) ++tokens;
      if (t.is_request() && fdl::fc_request_fn(t.fc) == fdl::RequestFn::SrdLow) ++srd;
      if (!t.is_request() && t.type == fdl::FrameType::SD2 && t.sa == 5) {
        ++replies;
        EXPECT_EQ(t.data.size(), 3u);
      }
    });
    EXPECT_EQ(split.pending(), 0u);
    EXPECT_EQ(frames, sim.stats(0).frames);
    EXPECT_GT(tokens, 0u);
    EXPECT_GT(srd, 0u);
    EXPECT_EQ(replies, srd);
  }
  // The symlink goes with the Simulation.
  struct stat st;
  EXPECT_NE(::lstat(link.c_str(), &st), 0);
}

TEST(SerialAttachment, StationPtyPutsTheProgramsTelegramsOnTheLine) {
  const auto loaded = parse_scenario(
      "line { name: \"A\" }\n"
      "passive_station { address: 5 line: \"A\" response_length: 2 }\n"
      "serial { line: \"A\" mode: STATION address: 2 }\n",
      "t");
  ASSERT_TRUE(loaded.ok()) << loaded.errors[0].str();
  Simulation sim(*loaded.plan);
  const int fd = ::open(sim.serial_ports()[0].path.c_str(), O_RDWR | O_NOCTTY | O_NONBLOCK);
  ASSERT_GE(fd, 0);
  sim.run_until(bus::kTicksPerMs);
  // The program (an external master, address 2) sends SRD_low to 5: 10 05 02 4C FCS 16
  // (FCS = 05 + 02 + 4C = 0x53; protocol-facts.md §B.1).
  const std::uint8_t req[] = {0x10, 0x05, 0x02, 0x4C, 0x53, 0x16};
  ASSERT_EQ(::write(fd, req, sizeof req), static_cast<ssize_t>(sizeof req));
  std::this_thread::sleep_for(std::chrono::milliseconds(20));
  sim.poll_serial();
  sim.run_until(2 * bus::kTicksPerMs);
  std::this_thread::sleep_for(std::chrono::milliseconds(20));
  const auto reply = read_all(fd);
  ::close(fd);
  // Station 5 answers with DL and two octets of counter data (cycle 0): SD2, LE 5,
  // DA 2, SA 5, FC 08, data 00 01, FCS = 02+05+08+00+01 = 0x10.
  EXPECT_EQ(reply, (std::vector<std::uint8_t>{0x68, 0x05, 0x05, 0x68, 0x02, 0x05, 0x08, 0x00,
                                              0x01, 0x10, 0x16}));
  EXPECT_EQ(sim.responder(0, 5)->srd(), 1u);
}

}  // namespace
}  // namespace pbvbus::tools
